//! `ronap replay`: a logged episode as an animated GIF, from above or first-person, or as an
//! HTML player (`--html`).
//!
//! The log gives the actions; the run's `summary.json` gives the configuration and the scenes;
//! the model steps the actions again from the episode's start and every logged pose is checked
//! against it ([`ronap_core::render::animate`] says why this beats drawing the logged numbers or
//! re-running the policy).

use crate::args::{count, positive};
use anyhow::{bail, Context, Result};
use clap::Args;
use ronap_core::eval::Evaluator;
use ronap_core::io::{read_steps, RunManifest};
use ronap_core::job::{play_lone, play_team, replay_team, single_page, RobotLog};
use ronap_core::render::{animate, GifOptions, View};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Arguments of `ronap replay`.
#[derive(Args, Debug)]
pub struct ReplayArgs {
    /// A step log that `ronap run --log-steps` wrote: RUN_DIR/steps/seed-<seed>.csv, or for a
    /// team any robot's RUN_DIR/steps/seed-<seed>-robot-<k>.csv (the episode's other robots'
    /// logs beside it are read too).
    #[arg(value_name = "STEPS_CSV")]
    steps: PathBuf,
    /// The run's summary.json, which holds its configuration and scenes [default: summary.json in
    /// the directory above steps/].
    #[arg(long, value_name = "FILE")]
    summary: Option<PathBuf>,
    /// What each frame shows: `top` (the whole scene with the path so far) or `first` (the
    /// paper's first-person view; of a team, the view of the robot whose log is given).
    #[arg(long, value_name = "top|first", default_value = "top", value_parser = view)]
    view: View,
    /// A frame every N steps (the first and last states always get one).
    #[arg(long, allow_negative_numbers = true, value_name = "N", default_value_t = 1, value_parser = count)]
    stride: u64,
    /// Top view: picture pixels per scene px, at most 4.
    #[arg(long, allow_negative_numbers = true, value_name = "F", default_value_t = 0.4, value_parser = scale)]
    scale: f64,
    /// First-person view: side of the square picture, pixels.
    #[arg(long, allow_negative_numbers = true, value_name = "PX", default_value_t = 240, value_parser = clap::value_parser!(u32).range(16..=2048))]
    size: u32,
    /// Frames per second, 1 to 50 (the last frame stays 1.5 s before the animation loops).
    #[arg(long, allow_negative_numbers = true, value_name = "N", default_value_t = 20, value_parser = clap::value_parser!(u32).range(1..=50))]
    fps: u32,
    /// The GIF to write [default: beside the log, named after it: seed-<seed>-top.gif or
    /// seed-<seed>-first.gif; for a team, seed-<seed>-team-top.gif or
    /// seed-<seed>-robot-<k>-first.gif].
    #[arg(long, value_name = "FILE")]
    out: Option<PathBuf>,
    /// Write an HTML player of the episode to FILE (ending in .html) instead of a GIF: one
    /// self-contained page (no network) to play, pause, step and scrub the episode (space and
    /// the arrow keys), follow a robot (f), show the laser rays, the obstacles' tracks and each
    /// step's observation, action, reward and collision.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["out", "view", "stride", "scale", "size", "fps"])]
    html: Option<PathBuf>,
}

fn view(s: &str) -> Result<View, String> {
    s.parse()
}

/// Parses a picture scale: a positive number of pixels per px, at most 4.
fn scale(s: &str) -> Result<f64, String> {
    let v = positive(s)?;
    if v <= 4.0 {
        Ok(v)
    } else {
        Err("must be at most 4 (pixels per scene px)".into())
    }
}

/// The animation options of the flags.
pub fn options(view: View, stride: u64, scale: f64, size: u32, fps: u32) -> GifOptions {
    GifOptions {
        view,
        stride: u32::try_from(stride).unwrap_or(u32::MAX),
        scale,
        size_px: size,
        frame_delay_cs: (100.0 / f64::from(fps.max(1))).round().max(2.0) as u16,
        ..GifOptions::default()
    }
}

/// Runs `ronap replay`.
pub fn run(args: ReplayArgs) -> Result<ExitCode> {
    if args.steps.is_dir() {
        // The first log there, as an example (a team's are seed-SEED-robot-K.csv).
        let mut logs: Vec<_> = std::fs::read_dir(&args.steps)
            .into_iter()
            .flatten()
            .flatten()
            .map(|e| e.path())
            .filter(|p| p.extension().is_some_and(|e| e == "csv"))
            .collect();
        logs.sort();
        let example = logs.first().map_or_else(
            || String::from("a step log (ronap run --log-steps writes them)"),
            |p| format!("such as {}", p.display()),
        );
        bail!(
            "{}: is a directory; give one step log, {example}",
            args.steps.display()
        );
    }
    if let Some(summary) = args.summary.as_ref().filter(|p| p.is_dir()) {
        bail!(
            "--summary {}: is a directory; give the run's summary file, such as {}",
            summary.display(),
            summary.join("summary.json").display()
        );
    }
    let steps = read_steps(&args.steps)?;
    let summary = match &args.summary {
        Some(p) => p.clone(),
        None => {
            let dir = args.steps.parent().unwrap_or(Path::new("."));
            let run_dir = match dir.file_name() {
                Some(name) if name == "steps" => dir.parent().unwrap_or(Path::new(".")),
                _ => dir,
            };
            run_dir.join("summary.json")
        }
    };
    let manifest = RunManifest::read(&summary)
        .context("replay needs the run's configuration (pass --summary FILE)")?;
    if manifest.model_version != ronap_core::MODEL_VERSION {
        bail!(
            "{}: the run was recorded under model version {}, this ronap runs model version {}: \
             its episodes do not replay the same (run it again with this ronap)",
            summary.display(),
            manifest.model_version,
            ronap_core::MODEL_VERSION
        );
    }
    let (config, scenes) = manifest
        .setting(&summary)
        .context("replay needs the run's configuration (pass --summary FILE)")?;
    if let Some(html) = &args.html {
        if html.extension().and_then(|e| e.to_str()) != Some("html") {
            bail!("--html {}: the file name must end in .html", html.display());
        }
    }
    let out = args.out.clone().unwrap_or_else(|| {
        // A team's logs are one per robot; its top view is the team's: seed-<seed>-team-top.gif.
        let stem = args.steps.with_extension("");
        let name = stem
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let name = match name.rsplit_once("-robot-") {
            Some((seed, _)) if config.team_size() > 0 && args.view == View::TopDown => {
                format!("{seed}-team")
            }
            _ => name,
        };
        stem.with_file_name(format!("{name}-{}.gif", args.view.name()))
    });
    if out.extension().and_then(|e| e.to_str()) != Some("gif") {
        bail!("--out {}: the file name must end in .gif", out.display());
    }
    // A team robot that never acted has a log of no rows: its name still gives the seed.
    let named_seed = args
        .steps
        .file_name()
        .and_then(|n| n.to_str())
        .and_then(|n| n.strip_prefix("seed-"))
        .and_then(|n| n.split_once("-robot-"))
        .and_then(|(seed, _)| seed.parse::<u64>().ok());
    let Some(seed) = steps.first().map(|s| s.seed).or(named_seed) else {
        bail!(
            "{}: the log has no steps: nothing to replay",
            args.steps.display()
        );
    };
    let evaluator = Evaluator::new(config, scenes);
    if let Some(html) = &args.html {
        return write_player(&evaluator, &args.steps, &steps, seed, html);
    }
    let options = options(args.view, args.stride, args.scale, args.size, args.fps);
    if evaluator.config().team_size() > 0 {
        let logs = team_logs(&args.steps, seed)?;
        // The first-person view is the given log's robot's.
        let options = GifOptions {
            follow: robot_of(&args.steps).unwrap_or(0),
            ..options
        };
        let animation = replay_team(&evaluator, seed, &logs, &options)
            .with_context(|| format!("cannot replay {}", args.steps.display()))?;
        ronap_core::io::write_atomic(&out, |w| w.write_all(&animation.bytes))?;
        writeln!(
            std::io::stdout().lock(),
            "{}: seed {seed}, {} robots, {} steps, {} frames of {} x {} (stride {}), {:.0} KB",
            out.display(),
            logs.len(),
            animation.steps,
            animation.frames,
            animation.size.0,
            animation.size.1,
            args.stride,
            animation.bytes.len() as f64 / 1024.0
        )?;
        return Ok(ExitCode::SUCCESS);
    }
    let episode = evaluator
        .worlds()
        .episode(seed)
        .with_context(|| format!("cannot start the episode of seed {seed}"))?;
    let actions: Vec<_> = steps.iter().map(|s| s.action).collect();
    let poses: Vec<_> = steps.iter().map(|s| s.pose).collect();
    let animation = animate(episode, &actions, Some(&poses), &options)
        .with_context(|| format!("cannot replay {}", args.steps.display()))?;
    ronap_core::io::write_atomic(&out, |w| w.write_all(&animation.bytes))?;
    let mut stdout = std::io::stdout().lock();
    writeln!(
        stdout,
        "{}: seed {seed}, {} steps, {} frames of {} x {} ({} view, stride {}), {:.0} KB",
        out.display(),
        animation.steps,
        animation.frames,
        animation.size.0,
        animation.size.1,
        args.view.name(),
        args.stride,
        animation.bytes.len() as f64 / 1024.0
    )?;
    Ok(ExitCode::SUCCESS)
}

/// `ronap replay --html`: the player of the episode of `seed` whose log (`steps`, read from
/// `log`) and, for a team, its other robots' logs beside it, written to `html`.
fn write_player(
    evaluator: &Evaluator,
    log: &Path,
    steps: &[ronap_core::io::LoggedStep],
    seed: u64,
    html: &Path,
) -> Result<ExitCode> {
    let trace = if evaluator.config().team_size() > 0 {
        let logs = team_logs(log, seed)?;
        play_team(evaluator, seed, &logs)
            .with_context(|| format!("cannot replay {}", log.display()))?
    } else {
        let episode = evaluator
            .worlds()
            .episode(seed)
            .with_context(|| format!("cannot start the episode of seed {seed}"))?;
        play_lone(episode, steps).with_context(|| format!("cannot replay {}", log.display()))?
    };
    let (robots, frames) = (trace.robots(), trace.frames());
    let page = single_page(trace).map_err(anyhow::Error::msg)?;
    ronap_core::io::write_atomic(html, |w| w.write_all(&page))
        .with_context(|| format!("cannot write the player to {}", html.display()))?;
    writeln!(
        std::io::stdout().lock(),
        "{}: seed {seed}, {}, {} steps, {:.0} KB",
        html.display(),
        crate::output::counted(robots as u64, "robot"),
        frames.saturating_sub(1),
        page.len() as f64 / 1024.0
    )?;
    Ok(ExitCode::SUCCESS)
}

/// The robot whose log `path` is, from its name `seed-<seed>-robot-<k>.csv`.
fn robot_of(path: &Path) -> Option<usize> {
    let stem = path.file_stem()?.to_str()?;
    stem.rsplit_once("-robot-")?.1.parse().ok()
}

/// Every robot's log of the team episode of `seed` whose robot log `one` is: the files
/// `seed-<seed>-robot-<k>.csv` beside it, robot `k` each.
fn team_logs(one: &Path, seed: u64) -> Result<Vec<RobotLog>> {
    let dir = one
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let prefix = format!("seed-{seed:06}-robot-");
    let mut logs = Vec::new();
    let entries =
        std::fs::read_dir(dir).with_context(|| format!("cannot list {}", dir.display()))?;
    for entry in entries {
        let entry = entry.with_context(|| format!("cannot list {}", dir.display()))?;
        let name = entry.file_name();
        let Some(robot) = name
            .to_str()
            .and_then(|n| n.strip_prefix(&prefix))
            .and_then(|n| n.strip_suffix(".csv"))
            .and_then(|k| k.parse::<usize>().ok())
        else {
            continue;
        };
        let steps = read_steps(&entry.path())?;
        if let Some(other) = steps.iter().find(|s| s.seed != seed) {
            bail!(
                "{}: a row of seed {} in the log of seed {seed}",
                entry.path().display(),
                other.seed
            );
        }
        logs.push(RobotLog { robot, steps });
    }
    if logs.is_empty() {
        bail!(
            "{}: a team run's step logs are named {prefix}<k>.csv, one per robot",
            one.display()
        );
    }
    logs.sort_by_key(|l| l.robot);
    Ok(logs)
}
