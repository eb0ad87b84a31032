//! `ronap run`: evaluate a policy over many seeded episodes and write what happened.

use crate::args::{count, fraction, policy_factory, seed, seed_range, EpisodeArgs, ThreadArgs};
use crate::output::cancel_on_ctrl_c;
use anyhow::{bail, Context, Result};
use clap::Args;
use ronap_core::eval::{EpisodeRecord, EvalOptions, Evaluator, Recording};
use ronap_core::io::run_dir::{evaluate_into, Pictures, RunFiles, RunInfo, RunWriter};
use std::io::Write as _;
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `ronap run`.
#[derive(Args, Debug)]
pub struct RunArgs {
    /// Policy to evaluate: apf (the paper's potential field, Algorithm 3), geodesic (shortest-path
    /// follower, no local minima), random, mlp:FILE.safetensors (a trained network, e.g.
    /// mlp:policies/bc.safetensors; append @argmax or @sample:T to override its decision rule), or
    /// py:FILE.py:FUNCTION (a Python function: observation in, action 0/1/2 out; run with
    /// $RONAP_PYTHON or python3).
    #[arg(long, value_name = "NAME")]
    policy: String,
    /// Number of episodes; episode i has seed seed-start + i.
    #[arg(long, allow_negative_numbers = true, value_name = "N", default_value_t = 1000, value_parser = count)]
    seeds: u64,
    /// First seed.
    #[arg(long, allow_negative_numbers = true, value_name = "SEED", default_value_t = 0, value_parser = seed)]
    seed_start: u64,
    #[command(flatten)]
    threads: ThreadArgs,
    #[command(flatten)]
    episodes: EpisodeArgs,
    /// Output directory [default: runs/<policy>-<UTC time>].
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
    /// Also write each episode's steps to steps/seed-<seed>.csv (the data-log format).
    #[arg(long)]
    log_steps: bool,
    /// Trajectory pictures in png/: the first N seeds, `failures` or `all` [default: none].
    #[arg(long, allow_negative_numbers = true, value_name = "N|failures|all")]
    png: Option<Pictures>,
    /// Also write an animated GIF of this seed's episode (top view, every step) to
    /// gif/seed-<seed>-<outcome>.gif; repeat for more seeds, each within the run's seeds (other
    /// views and strides: `--log-steps` and `ronap replay`) [default: none].
    #[arg(long, allow_negative_numbers = true, value_name = "SEED", value_parser = seed)]
    gif: Vec<u64>,
    /// Exit with code 1 when the success rate is below this fraction (a gate for CI).
    #[arg(long, allow_negative_numbers = true, value_name = "F", value_parser = fraction)]
    min_success: Option<f64>,
}

/// Runs `ronap run`.
pub fn run(args: RunArgs) -> Result<ExitCode> {
    // Everything that can be wrong with the input is checked before anything is written.
    let (config, scenes, map_source) = args.episodes.resolve()?;
    if config.team_size() > 0 {
        return run_team(args, config, scenes, map_source);
    }
    let factory = policy_factory(&args.policy, &config)?;
    let evaluator = Evaluator::new(config.clone(), scenes);
    let first = args.seed_start;
    let seeds = seed_range(first, args.seeds)?;
    check_gif_seeds(&args.gif, first, args.seeds)?;
    // A scene with no room for a start and goal fails the same way for every seed: say so now.
    evaluator
        .worlds()
        .check_start(first)
        .with_context(|| format!("cannot start episodes in this scene (seed {first})"))?;
    let threads = args.threads.count();
    let out_dir = match &args.out {
        Some(d) => d.clone(),
        None => default_out_dir(&args.policy),
    };
    let files = RunFiles {
        pictures: args.png,
        steps: args.log_steps,
        gifs: !args.gif.is_empty(),
    };
    let writer = RunWriter::create(&out_dir, files, first)
        .with_context(|| format!("cannot prepare output directory {}", out_dir.display()))?;

    let cancel = cancel_on_ctrl_c("finishing running episodes and writing what is done");
    let bar = crate::output::progress_bar(
        args.seeds,
        "{prefix} {wide_bar} {pos}/{len} episodes, {per_sec}, eta {eta}",
        format!("ronap run {}", args.policy),
    );
    let options = EvalOptions {
        seeds,
        threads,
        recording: Recording::default(),
    };
    let info = RunInfo {
        policy: args.policy.clone(),
        scenes: args.episodes.scenes.spec(&config),
        map: map_source,
    };
    let evaluation = evaluate_into(
        &evaluator,
        factory.as_ref(),
        &options,
        &info,
        Some(writer),
        &cancel,
        &|_| bar.inc(1),
    )?;
    bar.finish_and_clear();
    let (result, summary) = (&evaluation.result, &evaluation.summary);
    let mut gif_notes = Vec::new();
    for &seed in &args.gif {
        if let Some(record) = result.records.iter().find(|r| r.seed == seed) {
            gif_notes.extend(write_gif(&evaluator, factory.as_ref(), record, &out_dir)?);
        }
    }

    let mut stdout = std::io::stdout().lock();
    writeln!(
        stdout,
        "ronap run: policy {}, seeds {first}..{}, {threads} threads",
        args.policy,
        first + args.seeds - 1
    )?;
    write!(stdout, "{}", summary.table())?;
    writeln!(stdout, "outputs in {}", out_dir.display())?;
    for note in gif_notes {
        eprintln!("ronap run: {note}");
    }
    if let Some(e) = evaluation.write_error {
        return Err(e.into());
    }
    if let Some(e) = &result.error {
        bail!(
            "run stopped: {e} (the {} finished episodes are saved)",
            result.records.len()
        );
    }
    if result.cancelled {
        writeln!(
            stdout,
            "interrupted: {} of {} episodes finished and saved",
            result.records.len(),
            args.seeds
        )?;
        return Ok(ExitCode::from(130));
    }
    if let Some(min) = args.min_success {
        if summary.success_rate < min {
            eprintln!(
                "ronap run: success rate {:.1}% is below --min-success {:.1}%",
                100.0 * summary.success_rate,
                100.0 * min
            );
            return Ok(ExitCode::from(1));
        }
    }
    Ok(ExitCode::SUCCESS)
}

/// `ronap run` of a scenario with `[[robots]]`: team episodes, each robot driven by its entry's
/// policy (or `--policy`); `episodes.csv` holds a row per team episode, `robots.csv` a row per
/// robot.
fn run_team(
    args: RunArgs,
    config: ronap_core::ValidConfig,
    scenes: ronap_core::Scenes,
    map_source: Option<ronap_core::scene::map::MapSource>,
) -> Result<ExitCode> {
    if args.log_steps {
        bail!(
            "--log-steps does not log team runs yet; run without it (robots.csv holds every \
             robot's figures, --gif SEED animates an episode)"
        );
    }
    let mut names = Vec::new();
    let mut factories: Vec<Box<dyn ronap_core::policy::PolicyFactory>> = Vec::new();
    let mut of_robot = Vec::new();
    let mut k = 0;
    for entry in &config.robots {
        let name = entry.policy.clone().unwrap_or_else(|| args.policy.clone());
        let factory = policy_factory(&name, &config.team_robot(k))
            .with_context(|| format!("[[robots]] entry with robot {k}"))?;
        factories.push(factory);
        for _ in 0..entry.count {
            names.push(name.clone());
            of_robot.push(factories.len() - 1);
            k += 1;
        }
    }
    let factories_per_robot: Vec<&dyn ronap_core::policy::PolicyFactory> =
        of_robot.iter().map(|&i| factories[i].as_ref()).collect();
    let first = args.seed_start;
    let seeds = seed_range(first, args.seeds)?;
    check_gif_seeds(&args.gif, first, args.seeds)?;
    let evaluator = Evaluator::new(config.clone(), scenes);
    let threads = args.threads.count();
    // A team that cannot be placed fails the same way for every seed: say so before writing.
    ronap_core::sim::team::Team::new(&config, &evaluator.worlds().team(first), first)
        .with_context(|| format!("cannot start team episodes in this scene (seed {first})"))?;
    let out_dir = args
        .out
        .clone()
        .unwrap_or_else(|| default_out_dir(&args.policy));
    std::fs::create_dir_all(&out_dir)
        .with_context(|| format!("cannot prepare output directory {}", out_dir.display()))?;
    let cancel = cancel_on_ctrl_c("finishing running episodes and writing what is done");
    let bar = crate::output::progress_bar(
        args.seeds,
        "{prefix} {wide_bar} {pos}/{len} team episodes, {per_sec}, eta {eta}",
        format!("ronap run {} robots", names.len()),
    );
    let options = EvalOptions {
        seeds,
        threads,
        recording: Recording::default(),
    };
    let info = RunInfo {
        policy: args.policy.clone(),
        scenes: args.episodes.scenes.spec(&config),
        map: map_source,
    };
    let evaluation = ronap_core::io::run_dir::evaluate_team_into(
        &evaluator,
        &factories_per_robot,
        &names,
        &options,
        &info,
        Some(&out_dir),
        args.png,
        &cancel,
        &|_| bar.inc(1),
    )?;
    bar.finish_and_clear();
    let mut stdout = std::io::stdout().lock();
    writeln!(
        stdout,
        "ronap run: {} robots ({}), seeds {first}..{}, {threads} threads",
        names.len(),
        summary_of_names(&names),
        first + args.seeds - 1
    )?;
    write!(stdout, "{}", evaluation.team.table())?;
    writeln!(stdout, "per robot:")?;
    write!(stdout, "{}", evaluation.summary.table())?;
    let mut gif_notes = Vec::new();
    for &seed in &args.gif {
        if let Some(record) = evaluation.result.records.iter().find(|r| r.seed == seed) {
            gif_notes.extend(write_team_gif(
                &evaluator,
                &factories_per_robot,
                &names,
                record,
                &out_dir,
            )?);
        }
    }
    writeln!(stdout, "outputs in {}", out_dir.display())?;
    for note in gif_notes {
        eprintln!("ronap run: {note}");
    }
    if let Some(e) = evaluation.write_error {
        return Err(e.into());
    }
    if let Some(e) = &evaluation.result.error {
        bail!(
            "run stopped: {e} (the {} finished episodes are saved)",
            evaluation.result.records.len()
        );
    }
    if evaluation.result.cancelled {
        return Ok(ExitCode::from(130));
    }
    if let Some(min) = args.min_success {
        if evaluation.team.team_success_rate < min {
            eprintln!(
                "ronap run: team success rate {:.1}% is below --min-success {:.1}%",
                100.0 * evaluation.team.team_success_rate,
                100.0 * min
            );
            return Ok(ExitCode::from(1));
        }
    }
    Ok(ExitCode::SUCCESS)
}

/// `8 x geodesic` or `4 x apf, 4 x geodesic`: the policies of a team, counted.
fn summary_of_names(names: &[String]) -> String {
    let mut counted: Vec<(&str, usize)> = Vec::new();
    for n in names {
        match counted.iter_mut().find(|(m, _)| *m == n.as_str()) {
            Some((_, c)) => *c += 1,
            None => counted.push((n, 1)),
        }
    }
    counted
        .iter()
        .map(|(n, c)| format!("{c} x {n}"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// Runs the episode of `record` again with a fresh policy, recording its steps, and writes its
/// animation to `gif/`. Returns a note when the re-run differs from `record` (a policy that is not
/// deterministic), since the GIF then shows the re-run.
fn write_gif(
    evaluator: &Evaluator,
    factory: &dyn ronap_core::policy::PolicyFactory,
    record: &EpisodeRecord,
    out_dir: &std::path::Path,
) -> Result<Option<String>> {
    let seed = record.seed;
    let mut policy = factory.make()?;
    let recording = Recording {
        trajectory: false,
        steps: true,
    };
    let rerun = evaluator
        .run_episode(policy.as_mut(), seed, recording)
        .with_context(|| format!("--gif {seed}: cannot run the episode again"))?;
    let episode = evaluator.worlds().episode(seed)?;
    let actions: Vec<_> = rerun.step_log.iter().map(|s| s.action).collect();
    let options = ronap_core::render::gif::GifOptions::default();
    let animation = ronap_core::render::gif::animate(episode, &actions, None, &options)
        .with_context(|| format!("--gif {seed}"))?;
    let path = out_dir
        .join("gif")
        .join(format!("seed-{seed:06}-{}.gif", rerun.outcome.name()));
    ronap_core::io::atomic::write_atomic(&path, |w| w.write_all(&animation.bytes))?;
    Ok(
        (rerun.steps != record.steps || rerun.outcome != record.outcome).then(|| {
            format!(
                "--gif {seed}: the policy is not deterministic; the GIF shows a re-run ({} steps, \
                 {}), episodes.csv the run ({} steps, {})",
                rerun.steps,
                rerun.outcome.name(),
                record.steps,
                record.outcome.name()
            )
        }),
    )
}

/// Refuses a `--gif` seed outside the run's `count` seeds from `first` (a range already
/// checked not to pass 2^64).
fn check_gif_seeds(gif: &[u64], first: u64, count: u64) -> Result<()> {
    let last = first.saturating_add(count.saturating_sub(1));
    if let Some(s) = gif.iter().find(|&&s| s < first || s > last || count == 0) {
        bail!("--gif {s}: not one of this run's seeds ({first}..={last})");
    }
    Ok(())
}

/// Runs team episode `record.seed` again with fresh policies and writes its animation to
/// `gif/`. Returns a note when the re-run differs from `record` (a policy that is not
/// deterministic), since the GIF then shows the re-run.
fn write_team_gif(
    evaluator: &Evaluator,
    factories: &[&dyn ronap_core::policy::PolicyFactory],
    names: &[String],
    record: &ronap_core::eval::TeamRecord,
    out_dir: &std::path::Path,
) -> Result<Option<String>> {
    let seed = record.seed;
    let mut policies = factories
        .iter()
        .map(|f| f.make())
        .collect::<Result<Vec<_>, _>>()?;
    // About 500 pixels along the scene's longer side.
    let scene_side = evaluator
        .worlds()
        .team(seed)
        .first()
        .map_or(1000.0, |w| w.scene().width().max(w.scene().height()));
    let options = ronap_core::render::gif::GifOptions {
        scale: (500.0 / scene_side).clamp(0.1, 4.0),
        ..Default::default()
    };
    let (animation, rerun) =
        ronap_core::render::team::animate_team(evaluator, &mut policies, names, seed, &options)
            .with_context(|| format!("--gif {seed}"))?;
    let dir = out_dir.join("gif");
    std::fs::create_dir_all(&dir).with_context(|| format!("cannot make {}", dir.display()))?;
    let path = dir.join(format!("seed-{seed:06}-{}.gif", rerun.outcome.name()));
    ronap_core::io::atomic::write_atomic(&path, |w| w.write_all(&animation.bytes))?;
    Ok(
        (rerun.steps != record.steps || rerun.outcome != record.outcome).then(|| {
            format!(
                "--gif {seed}: a policy is not deterministic; the GIF shows a re-run ({} steps, \
                 {}), episodes.csv the run ({} steps, {})",
                rerun.steps,
                rerun.outcome.name(),
                record.steps,
                record.outcome.name()
            )
        }),
    )
}

/// `runs/<policy>-<UTC time>`, with `-2`, `-3`... when a run started in the same second has it.
fn default_out_dir(policy: &str) -> PathBuf {
    let (y, mo, d, h, mi, s) = crate::output::utc_now();
    // A py:dir/file.py:act policy names its directory after the function.
    let name: String = policy
        .rsplit(['/', ':'])
        .next()
        .unwrap_or("policy")
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect();
    crate::output::unused_dir(format!(
        "runs/{name}-{y:04}{mo:02}{d:02}-{h:02}{mi:02}{s:02}"
    ))
}
