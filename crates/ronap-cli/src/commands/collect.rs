//! `ronap collect`: record (observation, action) rows for behaviour cloning, labelled by an expert
//! planner or by a person at the keys (`--human`, the paper's Collect Data screen), in the
//! data-log format.

use crate::args::named_policy;
use crate::args::{count, seed, WorkArgs};
use crate::output::cancel_on_ctrl_c;
use anyhow::{bail, Context, Result};
use clap::{Args, ValueEnum};
use ronap_core::collect::{collect, Collection, Posing};
use ronap_core::eval::Evaluator;
use ronap_core::io::{write_atomic, DataLogWriter};
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::atomic::Ordering;

/// How the robot gets from one recorded state to the next.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum Mode {
    /// The paper's Collect Data mode: after each action, jump to a random free pose facing roughly
    /// towards the goal.
    Repose,
    /// Keep driving (the expert, or --driver) and label every state the robot passes.
    Drive,
}

/// Arguments of `ronap collect`.
#[derive(Args, Debug)]
#[command(group(clap::ArgGroup::new("labeller").required(true).args(["expert", "human"])))]
pub struct CollectArgs {
    /// The expert that labels each state with its action: geodesic (the shortest-path planner).
    #[arg(long, value_name = "PLANNER")]
    expert: Option<String>,
    /// A person labels each state in the terminal (the paper's Collect Data screen): left / up /
    /// right arrows for LEFT / AHEAD / RIGHT, the down arrow to re-arm them after each action, m
    /// for the whole scene, q to quit. Rows are written as they are taken.
    #[arg(long, conflicts_with_all = ["driver", "threads"])]
    human: bool,
    /// Number of rows to record.
    #[arg(long, allow_negative_numbers = true, value_name = "N", default_value_t = 10_000, value_parser = count)]
    samples: u64,
    /// Rows per episode (each episode is one seed: a maze, a goal); then the next seed.
    #[arg(long, allow_negative_numbers = true, value_name = "N", default_value_t = 100, value_parser = count)]
    per_episode: u64,
    /// How the robot moves between rows.
    #[arg(long, value_enum, default_value_t = Mode::Repose)]
    mode: Mode,
    /// With --mode drive: the policy that drives while the expert labels (DAgger: a learned
    /// policy visits its own mistakes), e.g. mlp:policies/bc.safetensors [default: the expert].
    #[arg(long, value_name = "POLICY")]
    driver: Option<String>,
    /// First seed; episode i has seed seed-start + i.
    #[arg(long, allow_negative_numbers = true, value_name = "SEED", default_value_t = 1_000_000, value_parser = seed)]
    seed_start: u64,
    #[command(flatten)]
    work: WorkArgs,
    /// Output CSV [default: <user>_<YYYYmmddHHMMSS>.csv].
    #[arg(long, value_name = "FILE")]
    out: Option<PathBuf>,
    /// Replace --out if it exists (once the rows are recorded; not with --human) [default:
    /// refuse, before recording].
    #[arg(long)]
    force: bool,
    /// User name for the default file name [default: $USER or `user` with --human,
    /// expert-<PLANNER> otherwise].
    #[arg(long, value_name = "NAME")]
    user: Option<String>,
}

/// `<user>_<YYYYmmddHHMMSS>.csv`, the paper's data-log name, in local-free UTC.
pub fn default_log_name(user: &str) -> PathBuf {
    let (y, mo, d, h, mi, s) = crate::output::utc_now();
    PathBuf::from(format!("{user}_{y:04}{mo:02}{d:02}{h:02}{mi:02}{s:02}.csv"))
}

/// Runs `ronap collect`.
pub fn run(args: CollectArgs) -> Result<ExitCode> {
    if args.human {
        return run_human(args);
    }
    let expert = args.expert.clone().unwrap_or_default();
    if expert != "geodesic" {
        bail!("--expert {expert:?}: unknown expert (expected geodesic)");
    }
    let (config, scenes) = args.work.resolve_with(|_| {})?;
    let driver = match (&args.driver, args.mode) {
        (Some(_), Mode::Repose) => bail!("--driver needs --mode drive"),
        (Some(name), Mode::Drive) => Some(named_policy("--driver", name, &config)?),
        (None, _) => None,
    };
    let evaluator = Evaluator::new(config.clone(), scenes);
    let first = args.seed_start;
    evaluator
        .worlds()
        .check_start(first)
        .with_context(|| format!("cannot start episodes in this scene (seed {first})"))?;
    let out = args.out.clone().unwrap_or_else(|| {
        default_log_name(args.user.as_deref().unwrap_or(&format!("expert-{expert}")))
    });
    crate::output::check_out_file(&out, args.force, "rows.csv")?;
    let posing = match args.mode {
        Mode::Repose => Posing::Repose,
        Mode::Drive => Posing::Drive,
    };
    let threads = args.work.threads.count();
    let cancel = cancel_on_ctrl_c("writing the rows recorded so far");
    let bar = crate::output::progress_bar(
        args.samples,
        "{prefix} {wide_bar} {pos}/{len} rows, {per_sec}, eta {eta}",
        "ronap collect".into(),
    );
    let beams = config.laser.beams as usize;
    let mut rows = 0usize;
    let mut episodes = 0usize;
    let mut failure = None;
    let clock = std::time::Instant::now();
    // The rows go to a temporary file renamed into place at the end, so an error never leaves a
    // half-written log; Ctrl-C stops between episodes and keeps every row recorded.
    write_atomic(&out, |w| {
        let mut log = DataLogWriter::new(std::io::BufWriter::new(w), beams)?;
        let mut io_error = None;
        let request = Collection {
            evaluator: &evaluator,
            per_episode: args.per_episode as usize,
            max_samples: args.samples as usize,
            posing,
            driver: driver.as_deref(),
            threads,
            cancel: &cancel,
        };
        let result = collect(&request, first..u64::MAX, &mut |_, samples| {
            for s in samples {
                if let Err(e) = log.write(s) {
                    io_error = Some(e);
                    return false;
                }
            }
            episodes += 1;
            rows += samples.len();
            bar.inc(samples.len() as u64);
            true
        });
        if let Some(e) = io_error {
            return Err(e);
        }
        if let Err(e) = result {
            failure = Some(e);
        }
        log.into_inner().flush()
    })?;
    bar.finish_and_clear();
    let mut stdout = std::io::stdout().lock();
    writeln!(
        stdout,
        "ronap collect: {} from {} (seeds {first}..{}), expert {}, mode {}, {:.1} s",
        crate::output::counted(rows as u64, "row"),
        crate::output::counted(episodes as u64, "episode"),
        first + episodes.saturating_sub(1) as u64,
        expert,
        match args.mode {
            Mode::Repose => "repose",
            Mode::Drive => "drive",
        },
        clock.elapsed().as_secs_f64()
    )?;
    writeln!(stdout, "wrote {}", out.display())?;
    if let Some(e) = failure {
        bail!("collection stopped: {e} (the {rows} rows recorded are saved)");
    }
    if cancel.load(Ordering::Relaxed) {
        writeln!(stdout, "interrupted: {rows} of {} rows saved", args.samples)?;
        return Ok(ExitCode::from(130));
    }
    if rows < args.samples as usize {
        // Only the seeds running out ends a collection short without an error.
        bail!(
            "--seed-start {first} --samples {}: the seeds ran out below 2^64 - 1 after {rows} rows \
             (the rows recorded are saved); start lower",
            args.samples
        );
    }
    Ok(ExitCode::SUCCESS)
}

/// Runs `ronap collect --human`.
fn run_human(args: CollectArgs) -> Result<ExitCode> {
    if args.mode == Mode::Drive {
        bail!("--human records in the paper's re-posing mode: --mode drive is for --expert");
    }
    let (config, scenes) = args.work.resolve_with(|_| {})?;
    let user = args
        .user
        .clone()
        .unwrap_or_else(crate::tui::collect::default_user);
    if args.force {
        bail!(
            "--force with --human: a session at the keys never replaces a data log; give \
             another --out"
        );
    }
    let out = args.out.clone().unwrap_or_else(|| default_log_name(&user));
    crate::output::check_out_file(&out, false, "rows.csv")?;
    crate::tui::collect::run(crate::tui::collect::Setting {
        evaluator: Evaluator::new(config, scenes),
        seed_start: args.seed_start,
        per_episode: args.per_episode,
        samples: args.samples,
        out,
        user,
    })
}
