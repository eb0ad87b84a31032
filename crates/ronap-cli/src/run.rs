//! `ronap run`: evaluate a policy over many seeded episodes and write what happened.

use crate::policies::policy_factory;
use crate::sim_args::{cancel_on_ctrl_c, count, fraction, seed, SceneArgs, SimArgs, ThreadArgs};
use anyhow::{bail, Context, Result};
use clap::Args;
use ronap_core::evaluate::{EpisodeRecord, Evaluator, Recording};
use ronap_core::report::{self, Pictures};
use ronap_core::summary::Summary;
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
    scenes: SceneArgs,
    #[command(flatten)]
    sim: SimArgs,
    /// Steps before a time-out [default: 2000].
    #[arg(long, allow_negative_numbers = true, value_name = "N", value_parser = clap::value_parser!(u32).range(1..))]
    max_steps: Option<u32>,
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

/// `2026-11-21T10:31:05Z` style UTC parts from the system clock.
pub fn utc_now() -> (i64, u32, u32, u32, u32, u32) {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs() as i64);
    let (days, rem) = (secs.div_euclid(86_400), secs.rem_euclid(86_400));
    // Howard Hinnant's civil-from-days.
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = (doy - (153 * mp + 2) / 5 + 1) as u32;
    let month = if mp < 10 { mp + 3 } else { mp - 9 } as u32;
    let year = yoe + era * 400 + i64::from(month <= 2);
    (
        year,
        month,
        day,
        (rem / 3600) as u32,
        (rem / 60 % 60) as u32,
        (rem % 60) as u32,
    )
}

/// Runs `ronap run`.
pub fn run(args: RunArgs) -> Result<ExitCode> {
    // Everything that can be wrong with the input is checked before anything is written.
    let config = args.sim.config_with(|sim| {
        if let Some(n) = args.max_steps {
            sim.episode.max_steps = n;
        }
    })?;
    let factory = policy_factory(&args.policy, &config)?;
    let (scenes, map_source) = args.scenes.scenes(&config)?;
    let evaluator = Evaluator::new(config.clone(), scenes);
    let first = args.seed_start;
    let end = first.checked_add(args.seeds).with_context(|| {
        format!(
            "--seed-start {first} --seeds {}: the seed range passes 2^64",
            args.seeds
        )
    })?;
    if let Some(s) = args.gif.iter().find(|&&s| s < first || s >= end) {
        bail!(
            "--gif {s}: not one of this run's seeds ({first}..={})",
            end - 1
        );
    }
    // A scene with no room for a start and goal fails the same way for every seed: say so now.
    evaluator
        .world(first)
        .episode(first)
        .with_context(|| format!("cannot start episodes in this scene (seed {first})"))?;
    let threads = args.threads.count();
    let out_dir = match &args.out {
        Some(d) => d.clone(),
        None => {
            let (y, mo, d, h, mi, s) = utc_now();
            // A py:dir/file.py:act policy names its directory after the function.
            let name: String = args
                .policy
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
            let base = format!("runs/{name}-{y:04}{mo:02}{d:02}-{h:02}{mi:02}{s:02}");
            // Two runs started in the same second get their own directories.
            (1..)
                .map(|k| {
                    if k == 1 {
                        PathBuf::from(&base)
                    } else {
                        PathBuf::from(format!("{base}-{k}"))
                    }
                })
                .find(|p| !p.exists())
                .unwrap_or_else(|| PathBuf::from(base))
        }
    };
    std::fs::create_dir_all(&out_dir)
        .with_context(|| format!("cannot create output directory {}", out_dir.display()))?;
    remove_stale_files(&out_dir)?;
    if args.png.is_some() {
        std::fs::create_dir_all(out_dir.join("png"))
            .with_context(|| format!("cannot create {}/png", out_dir.display()))?;
    }
    if !args.gif.is_empty() {
        std::fs::create_dir_all(out_dir.join("gif"))
            .with_context(|| format!("cannot create {}/gif", out_dir.display()))?;
    }
    if args.log_steps {
        std::fs::create_dir_all(out_dir.join("steps"))
            .with_context(|| format!("cannot create {}/steps", out_dir.display()))?;
    }

    let cancel = cancel_on_ctrl_c("finishing running episodes and writing what is done");
    let bar = crate::output::progress_bar(
        args.seeds,
        "{prefix} {wide_bar} {pos}/{len} episodes, {per_sec}, eta {eta}",
        format!("ronap run {}", args.policy),
    );

    let png = args.png;
    let wants_png = |r: &EpisodeRecord| png.is_some_and(|p| p.wants(r, first));
    let recording = Recording {
        trajectory: png.is_some(),
        steps: args.log_steps,
    };
    let write_errors = std::sync::Mutex::new(Vec::<String>::new());
    let on_record = |r: &EpisodeRecord| {
        if let Err(e) = report::write_episode_files(&out_dir, r, wants_png(r), args.log_steps) {
            if let Ok(mut all) = write_errors.lock() {
                all.push(e.to_string());
            }
        }
        bar.inc(1);
    };
    let seeds: Vec<u64> = (first..end).collect();
    let result = evaluator.run(
        factory.as_ref(),
        &seeds,
        threads,
        recording,
        &cancel,
        &on_record,
    )?;
    bar.finish_and_clear();

    let summary = Summary::new(&result.records, result.wall_time_s);
    let scenes = args.scenes.describe();
    let meta = serde_json::json!({
        "policy": args.policy,
        "seed_start": first,
        "seeds_requested": args.seeds,
        "scenes": scenes,
        "maze_seed": args.scenes.maze_seed,
        "map_file": args.scenes.map,
        "map": map_source,
        "threads": threads,
    });
    let meta = meta.as_object().cloned().unwrap_or_default();
    report::write_run(&out_dir, meta, &config, &result, &summary)?;
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
        end - 1
    )?;
    write!(stdout, "{}", summary.table())?;
    writeln!(stdout, "outputs in {}", out_dir.display())?;
    for note in gif_notes {
        eprintln!("ronap run: {note}");
    }
    let write_errors = write_errors.into_inner().unwrap_or_default();
    if let Some(e) = write_errors.first() {
        bail!(
            "{} output file(s) could not be written; first: {e}",
            write_errors.len()
        );
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
    let episode = evaluator.world(seed).episode(seed)?;
    let actions: Vec<_> = rerun.step_log.iter().map(|s| s.action).collect();
    let options = ronap_core::animation::GifOptions::default();
    let animation = ronap_core::animation::animate(episode, &actions, None, &options)
        .with_context(|| format!("--gif {seed}"))?;
    let path = out_dir
        .join("gif")
        .join(format!("seed-{seed:06}-{}.gif", rerun.outcome.name()));
    ronap_core::output::write_atomic(&path, |w| w.write_all(&animation.bytes))?;
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

/// Removes the per-episode files an earlier run left in `dir` (`png/seed-*.png`,
/// `steps/seed-*.csv`, `gif/seed-*.gif`), so a reused output directory shows only this run. Nothing else is touched.
fn remove_stale_files(dir: &std::path::Path) -> Result<()> {
    for (sub, ext) in [("png", ".png"), ("steps", ".csv"), ("gif", ".gif")] {
        let Ok(entries) = std::fs::read_dir(dir.join(sub)) else {
            continue;
        };
        for entry in entries.flatten() {
            let name = entry.file_name();
            let name = name.to_string_lossy();
            if name.starts_with("seed-") && name.ends_with(ext) {
                std::fs::remove_file(entry.path())
                    .with_context(|| format!("cannot remove old {}", entry.path().display()))?;
            }
        }
    }
    Ok(())
}
