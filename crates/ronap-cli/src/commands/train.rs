//! `ronap train bc|dqn`: train a policy network and write it as a safetensors weights file.

use crate::args::{count, fraction, seed, WorkArgs};
use anyhow::{bail, Context, Result};
use clap::{Args, Subcommand};
use indicatif::ProgressBar;
use ronap_core::config::Shaping;
use ronap_core::eval::{Evaluator, Seeds};
use ronap_core::io::{
    read_data_log, save_network, Curves, DataLogFormat, DataSet, OutputError, TrainingLog,
};
use ronap_core::policy::{observation_layout, DecisionRule, Mlp};
use ronap_core::sim::{SeedRanges, Split};
use ronap_learn::bc::{self, BcOptions};
use ronap_learn::dqn::{self, DqnOptions, Loss, Priorities, Validation};
use ronap_learn::net::TrainActivation;
use std::collections::HashMap;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};

/// Arguments of `ronap train`.
#[derive(Args, Debug)]
pub struct TrainArgs {
    #[command(subcommand)]
    algorithm: Algorithm,
}

#[derive(Subcommand, Debug)]
enum Algorithm {
    /// Behaviour cloning (the paper's Algorithm 2): fit a classifier to logged (observation,
    /// action) rows; prints training and test accuracy per epoch.
    #[command(
        mut_arg("hidden", |a| with_default(a, "64,128,64,32,8 (the original's)")),
        mut_arg("activation", |a| with_default(a, "rrelu")),
        mut_arg("lr", |a| with_default(a, "0.0008 (the original's)")),
        mut_arg("decision", |a| with_default(a, "sample:2 (on class scores)")),
    )]
    Bc(BcArgs),
    /// Deep Q-learning (the paper's Algorithm 1) on the model's reward, episodes on every core;
    /// prints returns and success rate as it trains.
    #[command(
        mut_arg("hidden", |a| with_default(a, "128,128")),
        mut_arg("activation", |a| with_default(a, "relu")),
        mut_arg("lr", |a| with_default(a, "0.0005")),
        mut_arg("decision", |a| with_default(a, "sample:0.3 (on Q-values, a larger scale)")),
    )]
    Dqn(Box<DqnArgs>),
}

/// `arg` with its trainer's `default` added to its help: the flags both trainers share
/// ([`NetArgs`]) default differently in each.
fn with_default(arg: clap::Arg, default: &str) -> clap::Arg {
    let help = arg.get_help().map(ToString::to_string).unwrap_or_default();
    arg.help(format!("{help} [default: {default}]"))
}

/// Flags both algorithms share.
#[derive(Args, Debug)]
struct NetArgs {
    /// Hidden layer widths, comma-separated.
    #[arg(long, value_name = "N,N,...", value_parser = widths)]
    hidden: Option<Widths>,
    /// Hidden activation: relu, tanh, rrelu (the paper's) or leaky_relu:SLOPE.
    #[arg(long, value_name = "NAME", value_parser = activation)]
    activation: Option<TrainActivation>,
    /// Adam's learning rate.
    #[arg(long, allow_negative_numbers = true, value_name = "LR", value_parser = crate::args::positive)]
    lr: Option<f64>,
    /// Seed of the initial weights and of every random choice in training.
    #[arg(long, allow_negative_numbers = true, value_name = "SEED", default_value_t = 0, value_parser = seed)]
    seed: u64,
    /// How `ronap run` turns the outputs into an action, saved in the file: argmax, or
    /// sample:TEMPERATURE (draw from softmax(outputs / TEMPERATURE)). A reactive policy that
    /// samples does not loop for ever where argmax would.
    #[arg(long, value_name = "RULE", value_parser = decision)]
    decision: Option<DecisionRule>,
    /// Weights file to write (safetensors).
    #[arg(long, value_name = "FILE")]
    out: PathBuf,
    /// Replace --out if it exists (once training is done) [default: refuse, before training].
    #[arg(long)]
    force: bool,
}

/// Arguments of `ronap train bc`.
#[derive(Args, Debug)]
struct BcArgs {
    /// Data log(s) to train on: ronap's (`ronap collect`) or the original RoNAP's CSV rows; give
    /// --data more than once to join files.
    #[arg(long, value_name = "FILE", required = true)]
    data: Vec<PathBuf>,
    #[command(flatten)]
    net: NetArgs,
    /// Passes over the training rows.
    #[arg(long, allow_negative_numbers = true, value_name = "N", default_value_t = 20, value_parser = count)]
    epochs: u64,
    /// Rows per mini-batch.
    #[arg(long, allow_negative_numbers = true, value_name = "N", default_value_t = 256, value_parser = count)]
    batch: u64,
    /// Fraction of rows to train on, above 0; the rest are the test split (none at 1).
    #[arg(long, allow_negative_numbers = true, value_name = "F", default_value_t = 0.8, value_parser = crate::args::share)]
    train_fraction: f64,
    /// Laser range, px: ronap's rows hold readings in px, the network sees them over this range
    /// (the laser's d_max).
    #[arg(long, allow_negative_numbers = true, value_name = "PX", default_value_t = 50.0, value_parser = crate::args::positive)]
    laser_range: f64,
}

/// Arguments of `ronap train dqn`.
#[derive(Args, Debug)]
struct DqnArgs {
    #[command(flatten)]
    net: NetArgs,
    /// Environment steps in all.
    #[arg(long, allow_negative_numbers = true, value_name = "N", default_value_t = 1_000_000, value_parser = count)]
    steps: u64,
    /// Episodes run side by side.
    #[arg(long, allow_negative_numbers = true, value_name = "N", default_value_t = 32, value_parser = count)]
    envs: u64,
    /// Transitions per update (B).
    #[arg(long, allow_negative_numbers = true, value_name = "N", default_value_t = 128, value_parser = count)]
    batch: u64,
    /// Replay memory size (D), transitions.
    #[arg(long, allow_negative_numbers = true, value_name = "N", default_value_t = 200_000, value_parser = count)]
    replay: u64,
    /// Updates between target-network refreshes (F).
    #[arg(long, allow_negative_numbers = true, value_name = "N", default_value_t = 1000, value_parser = count)]
    target_update: u64,
    /// Soft target updates: after every update the target network moves this fraction of the
    /// way to the online one, instead of a full copy every --target-update updates (0: off).
    #[arg(long, allow_negative_numbers = true, value_name = "TAU", default_value_t = 0.0, value_parser = fraction)]
    target_tau: f64,
    /// Discount gamma.
    #[arg(long, allow_negative_numbers = true, value_name = "G", default_value_t = 0.99, value_parser = fraction)]
    gamma: f64,
    /// Final exploration rate epsilon (it falls linearly from 1).
    #[arg(long, allow_negative_numbers = true, value_name = "E", default_value_t = 0.05, value_parser = fraction)]
    epsilon_end: f64,
    /// Environment steps over which epsilon falls.
    #[arg(long, allow_negative_numbers = true, value_name = "N", default_value_t = 300_000, value_parser = count)]
    epsilon_decay: u64,
    /// Updates after each round of --envs steps.
    #[arg(long, allow_negative_numbers = true, value_name = "N", default_value_t = 1, value_parser = count)]
    updates_per_round: u64,
    /// How progress is paid: none (the paper's straight-line term) or geodesic (potential-based
    /// shaping along the geodesic distance, with the discount --gamma; keeps the optimal policy)
    /// [default: the configuration's reward.shaping, none].
    #[arg(long, value_name = "KIND", value_parser = shaping)]
    shaping: Option<Shaping>,
    /// The discount of the shaping term, gamma in F = gamma Phi(s') - Phi(s): at --gamma the
    /// optimal policy is exactly kept; 1 pays plain geodesic progress, which adds a small cost for
    /// every step away from the goal [default: --gamma].
    #[arg(long, allow_negative_numbers = true, value_name = "G", value_parser = fraction)]
    shaping_gamma: Option<f64>,
    /// Steps summed in a target before bootstrapping (n-step returns; 1: Algorithm 1's).
    #[arg(long, allow_negative_numbers = true, value_name = "N", default_value_t = 3, value_parser = clap::value_parser!(u64).range(1..=100))]
    n_step: u64,
    /// A dueling head (value + advantages); the saved file is a plain network all the same.
    #[arg(long, value_name = "BOOL", default_value_t = true, action = clap::ArgAction::Set)]
    dueling: bool,
    /// Double-DQN targets (the online network picks the next action, the target network values it).
    #[arg(long, value_name = "BOOL", default_value_t = true, action = clap::ArgAction::Set)]
    double: bool,
    /// Loss on the TD error: huber or mse (Algorithm 1's).
    #[arg(long, value_name = "KIND", default_value = "huber", value_parser = loss)]
    loss: Loss,
    /// Largest norm of the gradient; larger ones are scaled down (0: no clipping).
    #[arg(long, allow_negative_numbers = true, value_name = "X", default_value_t = 10.0, value_parser = crate::args::non_negative)]
    grad_clip: f64,
    /// Learning rate at the end of training as a fraction of --lr, reached linearly (1: constant).
    #[arg(long, allow_negative_numbers = true, value_name = "F", default_value_t = 0.1, value_parser = fraction)]
    lr_end: f64,
    /// Prioritised replay (proportional, importance-weighted; beta rises to 1 over training).
    #[arg(long, value_name = "BOOL", default_value_t = false, action = clap::ArgAction::Set)]
    prioritized: bool,
    /// Prioritised replay: how strongly priorities skew sampling.
    #[arg(long, allow_negative_numbers = true, value_name = "A", default_value_t = 0.6, value_parser = fraction)]
    priority_alpha: f64,
    /// Prioritised replay: the importance-weight exponent at the start.
    #[arg(long, allow_negative_numbers = true, value_name = "B", default_value_t = 0.4, value_parser = fraction)]
    priority_beta: f64,
    /// Evaluate the network every N environment steps on the validation seeds, under the
    /// training configuration (its --max-steps), and keep the best one (0: keep the last).
    #[arg(
        long,
        allow_negative_numbers = true,
        value_name = "N",
        default_value_t = 50_000
    )]
    eval_every: u64,
    /// Validation episodes per evaluation.
    #[arg(long, allow_negative_numbers = true, value_name = "N", default_value_t = 200, value_parser = count)]
    eval_seeds: u64,
    /// Step limit of the validation episodes [default: the training episodes' (--max-steps)];
    /// give the limit the policy will be evaluated under (2000 for the paper's scene) to keep the
    /// network that does best there.
    #[arg(long, allow_negative_numbers = true, value_name = "N", value_parser = clap::value_parser!(u32).range(1..))]
    eval_max_steps: Option<u32>,
    /// First validation seed: keep the range apart from training and test seeds.
    #[arg(long, allow_negative_numbers = true, value_name = "SEED", default_value_t = 500_000, value_parser = seed)]
    eval_seed_start: u64,
    /// First training episode seed (episodes use seed-start, seed-start + 1, ...); keep the range
    /// apart from evaluation seeds.
    #[arg(long, allow_negative_numbers = true, value_name = "SEED", default_value_t = 1_000_000, value_parser = seed)]
    seed_start: u64,
    /// Steps before a training episode times out [default: the configuration's, 2000].
    #[arg(long, allow_negative_numbers = true, value_name = "N", value_parser = clap::value_parser!(u32).range(1..))]
    max_steps: Option<u32>,
    /// Print a progress line every N environment steps.
    #[arg(long, allow_negative_numbers = true, value_name = "N", default_value_t = 50_000, value_parser = count)]
    report_every: u64,
    #[command(flatten)]
    work: WorkArgs,
}

/// Layer widths from the command line.
#[derive(Clone, Debug)]
struct Widths(Vec<usize>);

fn widths(s: &str) -> Result<Widths, String> {
    s.split(',')
        .map(|w| {
            w.trim()
                .parse::<usize>()
                .ok()
                .filter(|&n| (1..=4096).contains(&n))
                .ok_or_else(|| format!("{w:?} is not a layer width from 1 to 4096"))
        })
        .collect::<Result<Vec<_>, _>>()
        .map(Widths)
}

fn decision(s: &str) -> Result<DecisionRule, String> {
    DecisionRule::parse(s).ok_or_else(|| format!("{s:?}: expected argmax or sample:TEMPERATURE"))
}

fn shaping(s: &str) -> Result<Shaping, String> {
    match s {
        "none" => Ok(Shaping::None),
        "geodesic" => Ok(Shaping::Geodesic),
        _ => Err(format!("{s:?}: expected none or geodesic")),
    }
}

fn loss(s: &str) -> Result<Loss, String> {
    match s {
        "huber" => Ok(Loss::Huber),
        "mse" => Ok(Loss::Mse),
        _ => Err(format!("{s:?}: expected huber or mse")),
    }
}

fn activation(s: &str) -> Result<TrainActivation, String> {
    TrainActivation::parse(s)
        .ok_or_else(|| format!("{s:?}: expected relu, tanh, rrelu or leaky_relu:SLOPE"))
}

/// Runs `ronap train`.
pub fn run(args: TrainArgs) -> Result<ExitCode> {
    match args.algorithm {
        Algorithm::Bc(a) => train_bc(a),
        Algorithm::Dqn(a) => train_dqn(*a),
    }
}

/// Prints a progress line above the bar, or straight to stdout (flushed, for logs and pipes)
/// when there is no bar.
fn show(progress: &ProgressBar, stdout: &mut impl Write, line: &str) {
    if progress.is_hidden() {
        let _ = writeln!(stdout, "{line}").and_then(|()| stdout.flush());
    } else {
        progress.println(line);
    }
}

/// The weights file's metadata beyond the network itself: what the outputs are, the decision
/// rule, the command line that trained it and a description of the training.
fn metadata(output: &str, decision: DecisionRule, trained: String) -> HashMap<String, String> {
    HashMap::from([
        ("output".to_string(), output.to_string()),
        ("decision".to_string(), decision.name()),
        (
            "command".to_string(),
            std::env::args().collect::<Vec<_>>().join(" "),
        ),
        ("trained".to_string(), trained),
    ])
}

/// Notes on stderr when training or validation seeds leave the split meant for them.
fn note_split(seeds: &SeedRanges, split: Split, what: &str) {
    let outside: Vec<String> = seeds
        .0
        .iter()
        .filter(|r| Split::of(*r.start()) != split || Split::of(*r.end()) != split)
        .map(|r| SeedRanges(vec![r.clone()]).to_string())
        .collect();
    if !outside.is_empty() {
        eprintln!(
            "note: {what}: seeds {} are not all in the {split} split ({}..={}); scores on the \
             test split stay held out only if training never sees it",
            outside.join(","),
            split.range().start(),
            split.range().end()
        );
    }
}

/// The end of a training run, however it stopped.
struct Finished<'a> {
    mlp: &'a Mlp,
    out: &'a Path,
    log: &'a TrainingLog,
    /// Why writing the training log stopped training, if it did.
    log_error: Option<OutputError>,
    /// A line to print once the weights are saved.
    summary: Option<String>,
    /// Set by Ctrl-C: training stopped early.
    cancel: &'a AtomicBool,
}

impl Finished<'_> {
    /// Saves the network (unless its log could not be written), says what was written, and
    /// gives the exit code: 130 after Ctrl-C.
    fn write(self, stdout: &mut impl Write) -> Result<ExitCode> {
        if let Some(e) = self.log_error {
            return Err(anyhow::Error::new(e).context("writing the training log; training stopped"));
        }
        save_network(self.out, self.mlp)?;
        if let Some(line) = self.summary {
            writeln!(stdout, "{line}")?;
        }
        writeln!(
            stdout,
            "wrote {} (curves: {}, {})",
            self.out.display(),
            self.log.csv_path().display(),
            self.log.png_path().display()
        )?;
        Ok(if self.cancel.load(Ordering::Relaxed) {
            ExitCode::from(130)
        } else {
            ExitCode::SUCCESS
        })
    }
}

fn train_bc(args: BcArgs) -> Result<ExitCode> {
    crate::output::check_out_file(&args.net.out, args.net.force, "policy.safetensors")?;
    let range = args.laser_range;
    let mut data: Option<DataSet> = None;
    let mut described = Vec::new();
    for path in &args.data {
        let (d, format) =
            read_data_log(path, range).with_context(|| format!("--data {}", path.display()))?;
        described.push(format!(
            "{} ({} rows, {} format, {} skipped)",
            path.display(),
            d.len(),
            match format {
                DataLogFormat::Ronap => "ronap",
                DataLogFormat::Original => "original RoNAP",
            },
            d.skipped
        ));
        match &mut data {
            None => data = Some(d),
            Some(all) => {
                if all.width != d.width {
                    bail!(
                        "{}: rows have {} laser readings but {} had {}",
                        path.display(),
                        d.width - 1,
                        args.data[0].display(),
                        all.width - 1
                    );
                }
                all.observations.extend_from_slice(&d.observations);
                all.actions.extend_from_slice(&d.actions);
                all.skipped += d.skipped;
                all.seeds.extend(d.seeds);
            }
        }
    }
    let Some(data) = data else {
        bail!("--data: no file given");
    };
    let defaults = BcOptions::default();
    let options = BcOptions {
        hidden: args.net.hidden.map_or(defaults.hidden, |w| w.0),
        activation: args.net.activation.unwrap_or(defaults.activation),
        learning_rate: args.net.lr.unwrap_or(defaults.learning_rate),
        batch: args.batch as usize,
        epochs: args.epochs as usize,
        train_fraction: args.train_fraction,
        seed: args.net.seed,
    };
    let counts = data.action_counts();
    let mut stdout = std::io::stdout().lock();
    for d in &described {
        writeln!(stdout, "data: {d}")?;
    }
    writeln!(
        stdout,
        "ronap train bc: {} rows (LEFT {}, AHEAD {}, RIGHT {}; {} skipped), {:.0}% to train, network {}-{}-3 {}",
        data.len(),
        counts[0],
        counts[1],
        counts[2],
        data.skipped,
        100.0 * options.train_fraction,
        data.width,
        options.hidden.iter().map(ToString::to_string).collect::<Vec<_>>().join("-"),
        options.activation.inference().name(),
    )?;
    writeln!(
        stdout,
        "{:>6} {:>10} {:>10} {:>10}",
        "epoch", "loss", "train acc", "test acc"
    )?;
    let per_epoch =
        (data.len() as f64 * options.train_fraction).ceil() as u64 / args.batch.max(1) + 1;
    let progress = crate::output::progress_bar(
        per_epoch * args.epochs,
        "{prefix} {wide_bar} {pos}/{len} batches, eta {eta}",
        "ronap train bc".into(),
    );
    let cancel =
        crate::output::cancel_on_ctrl_c("stopping after this batch and saving the network");
    let mut metadata = metadata(
        "logits",
        args.net
            .decision
            .unwrap_or(DecisionRule::Sample { temperature: 2.0 }),
        format!("behaviour cloning on {}", described.join(", ")),
    );
    let seeds = data.seed_ranges();
    if !seeds.is_empty() {
        note_split(&seeds, Split::Train, "the data's episode seeds");
        metadata.insert("training_seeds".into(), seeds.to_string());
    }
    let mut log = TrainingLog::new(
        &args.net.out,
        format!("ronap train bc: {}", args.net.out.display()),
        &["epoch", "loss", "train_accuracy", "test_accuracy"],
        &[
            Curves {
                label: "accuracy",
                columns: &[
                    ("test_accuracy", "test accuracy"),
                    ("train_accuracy", "training accuracy"),
                ],
                range: Some((0.0, 1.0)),
            },
            Curves {
                label: "loss",
                columns: &[("loss", "training loss (cross-entropy)")],
                range: None,
            },
        ],
    );
    let mut log_error = None;
    let (mlp, reports) = bc::train(
        &data,
        &options,
        metadata,
        &mut |_| {
            progress.inc(1);
            !cancel.load(Ordering::Relaxed)
        },
        &mut |r| {
            let line = format!(
                "{:>6} {:>10.4} {:>10} {:>10}",
                r.epoch,
                r.loss,
                percent(r.train_accuracy),
                percent(r.test_accuracy)
            );
            show(&progress, &mut stdout, &line);
            if let Err(e) = log.push(vec![
                r.epoch as f64,
                r.loss,
                r.train_accuracy,
                r.test_accuracy,
            ]) {
                log_error = Some(e);
                return false;
            }
            true
        },
    )?;
    progress.finish_and_clear();
    let last = reports.last().map(|last| {
        format!(
            "final: train accuracy {}, test accuracy {}",
            percent(last.train_accuracy),
            percent(last.test_accuracy)
        )
    });
    let finished = Finished {
        mlp: &mlp,
        out: &args.net.out,
        log: &log,
        log_error,
        summary: last,
        cancel: &cancel,
    };
    finished.write(&mut stdout)
}

fn train_dqn(args: DqnArgs) -> Result<ExitCode> {
    crate::output::check_out_file(&args.net.out, args.net.force, "policy.safetensors")?;
    let (config, scenes) = args.work.resolve_with(|sim| {
        if let Some(n) = args.max_steps {
            sim.episode.max_steps = n;
        }
        if let Some(kind) = args.shaping {
            sim.reward.shaping = kind;
        }
        // Shaping keeps the optimal policy exactly at the learner's own discount.
        sim.reward.shaping_gamma = args.shaping_gamma.unwrap_or(args.gamma);
    })?;
    let evaluator = Evaluator::new(config, scenes);
    evaluator
        .world(args.seed_start)
        .episode(args.seed_start)
        .with_context(|| {
            format!(
                "cannot start episodes in this scene (seed {})",
                args.seed_start
            )
        })?;
    let defaults = DqnOptions::default();
    let decision = args
        .net
        .decision
        .unwrap_or(DecisionRule::Sample { temperature: 0.3 });
    let options = DqnOptions {
        hidden: args.net.hidden.map_or(defaults.hidden, |w| w.0),
        activation: args.net.activation.unwrap_or(defaults.activation),
        learning_rate: args.net.lr.unwrap_or(defaults.learning_rate),
        gamma: args.gamma,
        batch: args.batch as usize,
        replay_capacity: args.replay as usize,
        target_update: args.target_update as usize,
        target_tau: (args.target_tau > 0.0).then_some(args.target_tau),
        epsilon_start: 1.0,
        epsilon_end: args.epsilon_end,
        epsilon_decay_steps: args.epsilon_decay,
        envs: args.envs as usize,
        steps: args.steps,
        updates_per_round: args.updates_per_round as usize,
        warmup: defaults.warmup,
        double: args.double,
        n_step: args.n_step as usize,
        dueling: args.dueling,
        loss: args.loss,
        grad_clip: (args.grad_clip > 0.0).then_some(args.grad_clip),
        lr_end_fraction: args.lr_end,
        prioritized: args.prioritized.then_some(Priorities {
            alpha: args.priority_alpha,
            beta_start: args.priority_beta,
        }),
        validation: (args.eval_every > 0).then_some(Validation {
            every: args.eval_every,
            seeds: Seeds::Range {
                start: args.eval_seed_start,
                count: args.eval_seeds,
            },
            decision,
            max_steps: args.eval_max_steps,
        }),
        seed: args.net.seed,
        seed_start: args.seed_start,
    };
    let threads = args.work.threads.count();
    let mut stdout = std::io::stdout().lock();
    writeln!(
        stdout,
        "ronap train dqn: {} steps, {} episodes side by side on {threads} thread{}, network {}-{}-3",
        options.steps,
        options.envs,
        if threads == 1 { "" } else { "s" },
        args.work.sim.config()?.observation_size(),
        options
            .hidden
            .iter()
            .map(ToString::to_string)
            .collect::<Vec<_>>()
            .join("-"),
    )?;
    writeln!(
        stdout,
        "{:>10} {:>9} {:>12} {:>9} {:>8} {:>10} {:>10}",
        "steps", "episodes", "mean return", "success", "epsilon", "loss", "validation"
    )?;
    let progress = crate::output::progress_bar(
        args.steps,
        "{prefix} {wide_bar} {pos}/{len} steps, {per_sec}, eta {eta}",
        "ronap train dqn".into(),
    );
    let cancel = crate::output::cancel_on_ctrl_c("stopping and saving the network");
    let mut metadata = metadata(
        "q_values",
        decision,
        format!(
            "DQN, {} environment steps, episode seeds from {}",
            args.steps, args.seed_start
        ),
    );
    let training = SeedRanges(vec![args.seed_start..=u64::MAX]);
    note_split(&training, Split::Train, "--seed-start");
    metadata.insert("training_seeds".into(), training.to_string());
    if options.validation.is_some() {
        let last = args
            .eval_seed_start
            .saturating_add(args.eval_seeds.saturating_sub(1));
        let chosen = SeedRanges(vec![args.eval_seed_start..=last]);
        note_split(&chosen, Split::Validation, "--eval-seed-start");
        metadata.insert("validation_seeds".into(), chosen.to_string());
    }
    let history = evaluator.config().observation.history;
    if history > 1 {
        let layout = observation_layout(evaluator.config().laser.beams as usize);
        metadata.insert(
            "observation".into(),
            format!(
                "{history} frames of {layout}, newest first, then the last {} actions as \
                 LEFT,AHEAD,RIGHT one-hot, newest first (observation.history = {history})",
                history - 1
            ),
        );
    }
    let mut log = TrainingLog::new(
        &args.net.out,
        format!("ronap train dqn: {}", args.net.out.display()),
        &[
            "steps",
            "episodes",
            "mean_return",
            "success_rate",
            "epsilon",
            "loss",
            "learning_rate",
            "validation_success",
        ],
        &[
            Curves {
                label: "mean return",
                columns: &[("mean_return", "training return (last 100 episodes)")],
                range: None,
            },
            Curves {
                label: "success rate",
                columns: &[
                    ("validation_success", "validation success (the saved rule)"),
                    ("success_rate", "training success (last 100 episodes)"),
                    ("epsilon", "epsilon"),
                ],
                range: Some((0.0, 1.0)),
            },
        ],
    );
    let mut log_error = None;
    let mut last_steps = 0;
    let mlp = dqn::train(
        &evaluator,
        &options,
        threads,
        metadata,
        args.report_every,
        &mut |r| {
            progress.inc(r.steps - last_steps);
            last_steps = r.steps;
            // Figures that do not exist yet (no finished episode, no update) show as "-".
            let (mean_return, success) = if r.episodes == 0 {
                ("-".to_string(), "-".to_string())
            } else {
                (
                    format!("{:.2}", r.mean_return),
                    format!("{:.1}%", 100.0 * r.success_rate),
                )
            };
            let loss = if r.loss.is_nan() {
                "-".to_string()
            } else {
                format!("{:.4}", r.loss)
            };
            let validation = if r.validation_success.is_nan() {
                "-".to_string()
            } else {
                format!("{:.1}%", 100.0 * r.validation_success)
            };
            let line = format!(
                "{:>10} {:>9} {mean_return:>12} {success:>9} {:>8.3} {loss:>10} {validation:>10}",
                r.steps, r.episodes, r.epsilon,
            );
            show(&progress, &mut stdout, &line);
            let nan_before_first = |v: f64| if r.episodes == 0 { f64::NAN } else { v };
            if let Err(e) = log.push(vec![
                r.steps as f64,
                r.episodes as f64,
                nan_before_first(r.mean_return),
                nan_before_first(r.success_rate),
                r.epsilon,
                r.loss,
                r.learning_rate,
                r.validation_success,
            ]) {
                log_error = Some(e);
                return false;
            }
            !cancel.load(Ordering::Relaxed)
        },
    )?;
    progress.finish_and_clear();
    let finished = Finished {
        mlp: &mlp,
        out: &args.net.out,
        log: &log,
        log_error,
        summary: mlp
            .metadata
            .get("validation")
            .map(|v| format!("validation: {v}")),
        cancel: &cancel,
    };
    finished.write(&mut stdout)
}

/// An accuracy as a percentage, `-` where there was nothing to measure it on (no test split).
fn percent(accuracy: f64) -> String {
    if accuracy.is_nan() {
        "-".into()
    } else {
        format!("{:.1}%", 100.0 * accuracy)
    }
}
