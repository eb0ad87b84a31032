//! `ronap run`: evaluate a policy over many seeded episodes and write what happened, as it
//! happens; `--resume` finishes a run stopped short.

use crate::args::{fraction, policy_factory, seed, warn_if_not_held_out, EvalArgs};
use crate::output::cancel_on_ctrl_c;
use anyhow::{bail, Context, Result};
use clap::Args;
use ronap_core::eval::{EvalOptions, Evaluator, Recording, Seeds};
use ronap_core::io::{OutputError, Pictures, ResumeError, RunFiles, RunInfo, RunWriter, PLAN_FILE};
use ronap_core::job::{evaluate_into, evaluate_team_into, RunRequest};
use ronap_core::policy::PolicyFactory;
use ronap_core::scene::MapSource;
use ronap_core::sim::SceneSpec;
use ronap_core::{Scenes, ValidConfig};
use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

/// Arguments of `ronap run`.
#[derive(Args, Debug)]
pub struct RunArgs {
    /// Policy to evaluate: apf (the paper's potential field, Algorithm 3), geodesic (shortest-path
    /// follower, no local minima), geodesic-wait (geodesic that waits for moving obstacles ahead),
    /// orca (ORCA along the geodesic path: avoids what moves; [orca] settings), social-force,
    /// dwa, random, coordinated (a scenario's [[robots]] planned together: no deadlocks,
    /// infeasible tasks named),
    /// mlp:FILE.safetensors (a trained network, e.g.
    /// mlp:policies/bc.safetensors; append @argmax or @sample:T to override its decision rule), or
    /// py:FILE.py:FUNCTION (a Python function: observation in, action 0/1/2 out; run with
    /// $RONAP_PYTHON or python3).
    #[arg(long, value_name = "NAME", required_unless_present = "resume")]
    policy: Option<String>,
    #[command(flatten)]
    eval: EvalArgs,
    /// Output directory [default: runs/<policy>-<UTC time>]. episodes.csv and timing.csv are
    /// written as episodes finish (as *.partial until the run ends), so memory stays flat and a
    /// killed run keeps its finished episodes; one run at a time per directory.
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
    /// Write into --out even if it holds a finished run (replaced once this run's first episode
    /// is done), a run stopped short, or other files (kept; only a run's own files are replaced).
    #[arg(long)]
    force: bool,
    /// Finish the run in DIR that was stopped short (killed, Ctrl-C, disk full) with the settings
    /// it was started with (DIR/run.json), running only the seeds it had not finished; the
    /// results are the same as an uninterrupted run's. Run it from the directory the run was
    /// started in (policy and map paths are read from there). Takes no other flag.
    #[arg(long, value_name = "DIR", exclusive = true)]
    resume: Option<PathBuf>,
    /// Also write each episode's steps to steps/seed-<seed>.csv (the data-log format); a team
    /// writes one per robot, steps/seed-<seed>-robot-<k>.csv.
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
    /// Also write an HTML player of episodes to html/seed-<seed>-<outcome>.html, chosen as
    /// --png chooses pictures: the first N seeds of the run, `failures` (every episode that did
    /// not succeed) or `all`. Each is one self-contained page (no network) to play, pause, step
    /// and scrub the episode, follow a robot, show the laser, the obstacles' tracks and the
    /// step's observation, action and reward (ronap replay --html makes one from a step log)
    /// [default: none].
    #[arg(long, allow_negative_numbers = true, value_name = "N|failures|all")]
    html: Option<Pictures>,
    /// For a py: policy, run N episodes side by side and call the function once for all of
    /// those waiting for an action, with an (n, observation size) array (n up to N), expecting n
    /// actions: the same episodes as unbatched, with far fewer calls (0: one call per step). On a
    /// team scenario: N team episodes under way, each step of each one a single call for all its
    /// robots that run the function.
    #[arg(long, allow_negative_numbers = true, value_name = "N", default_value_t = 0, value_parser = clap::value_parser!(u16))]
    batch: u16,
    /// Exit with code 1 when the success rate is below this fraction (a gate for CI).
    #[arg(long, allow_negative_numbers = true, value_name = "F", value_parser = fraction)]
    min_success: Option<f64>,
}

/// Runs `ronap run`.
pub fn run(args: RunArgs) -> Result<ExitCode> {
    if let Some(dir) = &args.resume {
        return resume(dir);
    }
    // Everything that can be wrong with the input is checked before anything is written.
    let (config, scenes, map) = args.eval.episodes.resolve()?;
    let policy = args.policy.clone().unwrap_or_default();
    let seeds = args.eval.seeds.range()?;
    let job = Job {
        out_dir: match &args.out {
            Some(d) => d.clone(),
            None => default_out_dir(&policy),
        },
        policy,
        seeds,
        threads: args.eval.threads.count(),
        info_scenes: args.eval.episodes.scenes.spec(&config),
        map,
        png: args.png,
        log_steps: args.log_steps,
        gif: args.gif,
        html: args.html,
        min_success: args.min_success,
        batch: usize::from(args.batch),
        force: args.force,
    };
    if job.batch > 0 && !job.policy.starts_with("py:") {
        bail!(
            "--batch {}: batches are for py:FILE:FUNCTION policies; {} runs in Rust already",
            job.batch,
            job.policy
        );
    }
    let scenario = args.eval.episodes.sim.scenario.as_deref();
    let run = if config.team_size() > 0 {
        run_team(job, config, scenes, None)
    } else {
        run_lone(job, config, scenes, None)
    };
    run.map_err(|e| crate::args::sim::locate_in_scenario(e, scenario))
}

/// A run as asked for, by flags or by a resumed run's plan.
struct Job {
    policy: String,
    seeds: Seeds,
    threads: usize,
    info_scenes: SceneSpec,
    map: Option<MapSource>,
    out_dir: PathBuf,
    png: Option<Pictures>,
    log_steps: bool,
    gif: Vec<u64>,
    /// The episodes that get an HTML player.
    html: Option<Pictures>,
    min_success: Option<f64>,
    /// Episodes a py: policy decides for at once (0: one at a time).
    batch: usize,
    /// Replace what `out_dir` holds.
    force: bool,
}

impl Job {
    /// The first and last seeds, for messages.
    fn span(&self) -> (u64, u64) {
        let first = self.seeds.first().unwrap_or(0);
        let last = self
            .seeds
            .get(self.seeds.len().saturating_sub(1))
            .unwrap_or(first);
        (first, last)
    }

    /// What `ronap run` keeps in the plan beyond the core's fields, for `--resume`.
    fn front_end(&self) -> serde_json::Value {
        let mut front = serde_json::json!({ "gif": self.gif, "min_success": self.min_success, "batch": self.batch });
        // Only a run with players names them, so other runs' plans stay as they were.
        if let Some(html) = self.html {
            front["html"] = serde_json::Value::String(html.to_string());
        }
        front
    }

    /// What every run sets up once its episodes can start: its writer (`writer` taken up again,
    /// or a new one animating the `--gif` seeds' steps as they finish), Ctrl-C, and a progress
    /// bar counting the episodes left (`what`, after `prefix`).
    fn begin(
        &self,
        writer: Option<RunWriter>,
        what: &str,
        prefix: String,
    ) -> Result<(RunWriter, Arc<AtomicBool>, indicatif::ProgressBar)> {
        let (first, last) = self.span();
        if let Some(s) = self.gif.iter().find(|&&s| s < first || s > last) {
            bail!("--gif {s}: not one of this run's seeds ({first}..={last})");
        }
        let writer = match writer {
            Some(w) => w,
            None => self.writer(RunFiles {
                pictures: self.png,
                steps: self.log_steps,
                gifs: false,
            })?,
        };
        let writer = writer.animating(self.gif.clone())?.playing(self.html)?;
        let done = writer.done() as u64;
        let cancel = cancel_on_ctrl_c("finishing running episodes and writing what is done");
        let bar = crate::output::progress_bar(
            self.seeds.len() as u64 - done,
            &format!("{{prefix}} {{wide_bar}} {{pos}}/{{len}} {what}, {{per_sec}}, eta {{eta}}"),
            prefix,
        );
        Ok((writer, cancel, bar))
    }

    /// Runs `evaluate` (one robot's episodes or a team's) on the request of this run's seeds of
    /// `evaluator` on `threads` workers, into `writer`, stopped when `cancel` is set.
    fn evaluate<T>(
        &self,
        evaluator: &Evaluator,
        threads: usize,
        writer: RunWriter,
        cancel: &AtomicBool,
        evaluate: impl FnOnce(RunRequest<'_>) -> T,
    ) -> T {
        let options = EvalOptions {
            seeds: self.seeds.clone(),
            threads,
            recording: Recording::default(),
            steps_of: Vec::new(),
        };
        let info = RunInfo {
            policy: self.policy.clone(),
            scenes: self.info_scenes.clone(),
            map: self.map.clone(),
        };
        evaluate(RunRequest {
            evaluator,
            options: &options,
            info: &info,
            writer: Some(writer),
            cancel,
        })
    }

    /// How the run ended, as the exit says it: a write error or a failed episode (an error
    /// saying what is kept), an interruption (130, with the way to finish), a success rate
    /// (`rate`, of `what`) below `--min-success` (1), else success.
    fn end(
        &self,
        write_error: Option<OutputError>,
        error: Option<&ronap_core::run::RunError>,
        cancelled: bool,
        (episodes, what, rate): (usize, &str, f64),
    ) -> Result<ExitCode> {
        if let Some(e) = write_error {
            return Err(stopped_writing(e, &self.out_dir));
        }
        if let Some(e) = error {
            bail!("run stopped: {e} (the {episodes} finished episodes are saved)");
        }
        if cancelled {
            println!(
                "interrupted: {episodes} of {} episodes finished and saved (ronap run --resume {} \
                 finishes the run)",
                self.seeds.len(),
                self.out_dir.display()
            );
            return Ok(ExitCode::from(130));
        }
        if let Some(min) = self.min_success {
            if rate < min {
                eprintln!(
                    "ronap run: {what} {:.1}% is below --min-success {:.1}%",
                    100.0 * rate,
                    100.0 * min
                );
                return Ok(ExitCode::from(1));
            }
        }
        Ok(ExitCode::SUCCESS)
    }

    /// The writer of a new run into `out_dir`.
    fn writer(&self, files: RunFiles) -> Result<RunWriter> {
        let dir = &self.out_dir;
        let first = self.seeds.first().unwrap_or(0);
        let writer = match RunWriter::create(dir, files, first, self.force) {
            Ok(w) => w,
            Err(e) => return Err(refusal(e, dir, "--out")),
        };
        Ok(writer.with_front_end(self.front_end()))
    }
}

/// The error of an output directory `dir` (given with `flag`) that cannot be written, with the
/// ways on when it was refused for what it holds.
pub(crate) fn refusal(e: OutputError, dir: &Path, flag: &str) -> anyhow::Error {
    let resume = format!("ronap run --resume {} finishes it, ", dir.display());
    refused(e, dir, flag, &resume)
}

/// [`refusal`] for `ronap compare`, whose runs are not resumed.
pub(crate) fn refusal_without_resume(e: OutputError, dir: &Path) -> anyhow::Error {
    refused(e, dir, "--out", "")
}

fn refused(e: OutputError, dir: &Path, flag: &str, resume: &str) -> anyhow::Error {
    match e {
        e @ OutputError::StoppedShort { .. } => {
            anyhow::anyhow!("{e}: {resume}--force replaces it, or choose another {flag}")
        }
        e @ OutputError::Finished { .. } => {
            anyhow::anyhow!("{e}: --force replaces it, or choose another {flag}")
        }
        e @ OutputError::NotARun { .. } => anyhow::anyhow!(
            "{e}: --force writes there anyway (keeping those files), or choose another {flag}"
        ),
        e => anyhow::Error::from(e)
            .context(format!("cannot prepare output directory {}", dir.display())),
    }
}

/// `ronap run --resume DIR`: the run in `dir`, rebuilt from its plan, finished.
fn resume(dir: &Path) -> Result<ExitCode> {
    let (writer, plan) = match RunWriter::resume(dir) {
        Ok(w) => w,
        Err(e @ ResumeError::Complete { .. }) => {
            println!("ronap run: {e}");
            return Ok(ExitCode::SUCCESS);
        }
        Err(e) => return Err(e.into()),
    };
    let plan_path = dir.join(PLAN_FILE);
    let (config, scenes) = plan.setting(&plan_path)?;
    let bad = |field: &str, value: &serde_json::Value| {
        anyhow::anyhow!(
            "cannot resume: {}: `front_end.{field}` = {value} is not what ronap run writes",
            plan_path.display()
        )
    };
    let front = &plan.front_end;
    let gif = match front.get("gif") {
        None | Some(serde_json::Value::Null) => Vec::new(),
        Some(v) => serde_json::from_value(v.clone()).map_err(|_| bad("gif", v))?,
    };
    let min_success = match front.get("min_success") {
        None | Some(serde_json::Value::Null) => None,
        Some(v) => Some(v.as_f64().ok_or_else(|| bad("min_success", v))?),
    };
    let batch = match front.get("batch") {
        None | Some(serde_json::Value::Null) => 0,
        Some(v) => v
            .as_u64()
            .and_then(|b| usize::try_from(b).ok())
            .ok_or_else(|| bad("batch", v))?,
    };
    let html = match front.get("html") {
        None | Some(serde_json::Value::Null) => None,
        Some(v) => Some(
            v.as_str()
                .and_then(|t| t.parse::<Pictures>().ok())
                .ok_or_else(|| bad("html", v))?,
        ),
    };
    let png = plan
        .pictures
        .as_deref()
        .map(str::parse)
        .transpose()
        .map_err(|e: String| {
            anyhow::anyhow!("cannot resume: {}: `pictures`: {e}", plan_path.display())
        })?;
    let job = Job {
        policy: plan.policy.clone(),
        seeds: plan.seeds(),
        threads: plan.threads,
        info_scenes: plan.scenes.clone(),
        map: plan.map.clone(),
        out_dir: dir.to_path_buf(),
        png,
        log_steps: plan.steps,
        gif,
        html,
        min_success,
        batch,
        force: false,
    };
    eprintln!(
        "ronap run: resuming {}: {} of {} episodes were done",
        dir.display(),
        writer.done(),
        job.seeds.len()
    );
    if config.team_size() > 0 {
        run_team(job, config, scenes, Some(writer))
    } else {
        run_lone(job, config, scenes, Some(writer))
    }
}

/// A lone robot's run, new (`writer` `None`) or resumed.
fn run_lone(
    job: Job,
    config: ValidConfig,
    scenes: Scenes,
    writer: Option<RunWriter>,
) -> Result<ExitCode> {
    let (factory, threads) = match job.policy.strip_prefix("py:") {
        // A batch of N is N episodes under way, a worker each.
        Some(spec) if job.batch > 0 => {
            let batched = crate::py_policy::PyPolicyFactory::new(spec)
                .and_then(|f| f.batched(job.batch))
                .map_err(anyhow::Error::msg)?;
            (Box::new(batched) as Box<dyn PolicyFactory>, job.batch)
        }
        _ => (policy_factory(&job.policy, &config)?, job.threads),
    };
    warn_if_not_held_out(&job.policy, factory.as_ref(), &job.seeds);
    let evaluator = Evaluator::new(config.clone(), scenes);
    let (first, last) = job.span();
    // A scene with no room for a start and goal fails the same way for every seed: say so now.
    evaluator
        .worlds()
        .check_start(first)
        .with_context(|| format!("cannot start episodes in this scene (seed {first})"))?;
    let (writer, cancel, bar) =
        job.begin(writer, "episodes", format!("ronap run {}", job.policy))?;
    let evaluation = job.evaluate(&evaluator, threads, writer, &cancel, |request| {
        evaluate_into(request, factory.as_ref(), &|_| bar.inc(1), &|_| false)
    })?;
    bar.finish_and_clear();
    let (result, summary) = (&evaluation.result, &evaluation.summary);

    let mut stdout = std::io::stdout().lock();
    writeln!(
        stdout,
        "ronap run: policy {}, seeds {first}..{last}, {}",
        job.policy,
        if job.batch > 0 {
            format!("batches of up to {} episodes", job.batch)
        } else {
            crate::output::counted(job.threads as u64, "thread")
        }
    )?;
    write!(stdout, "{}", summary.table())?;
    writeln!(stdout, "outputs in {}", job.out_dir.display())?;
    drop(stdout);
    job.end(
        evaluation.write_error,
        result.error.as_ref(),
        result.cancelled,
        (summary.episodes, "success rate", summary.success_rate),
    )
}

/// `ronap run` of a scenario with `[[robots]]`: team episodes, each robot driven by its entry's
/// policy (or `--policy`); `episodes.csv` holds a row per team episode, `robots.csv` a row per
/// robot, and `--log-steps` a step log per robot (`steps/seed-SEED-robot-K.csv`).
fn run_team(
    job: Job,
    config: ValidConfig,
    scenes: Scenes,
    writer: Option<RunWriter>,
) -> Result<ExitCode> {
    let mut policies = crate::args::TeamPolicies::new(&config, &job.policy)?;
    // A batch of N is N team episodes under way, each step of each one a call for its robots.
    let threads = if job.batch > 0 {
        policies = policies.batched(&job.policy)?;
        job.batch
    } else {
        job.threads
    };
    let names = policies.names.clone();
    let (first, last) = job.span();
    let evaluator = Evaluator::new(config.clone(), scenes);
    // A team that cannot be placed fails the same way for every seed: say so before writing.
    ronap_core::sim::Team::new(&config, &evaluator.worlds().team(first), first)
        .with_context(|| format!("cannot start team episodes in this scene (seed {first})"))?;
    let (writer, cancel, bar) = job.begin(
        writer,
        "team episodes",
        format!("ronap run {} robots", names.len()),
    )?;
    let evaluation = job.evaluate(&evaluator, threads, writer, &cancel, |request| {
        evaluate_team_into(request, &policies, &|_| bar.inc(1), &|_| false)
    })?;
    bar.finish_and_clear();
    let mut stdout = std::io::stdout().lock();
    writeln!(
        stdout,
        "ronap run: {} ({}), seeds {first}..{last}, {}",
        crate::output::counted(names.len() as u64, "robot"),
        summary_of_names(&names),
        if job.batch > 0 {
            format!("{threads} team episodes at once, one call a step for the robots of each")
        } else {
            crate::output::counted(threads as u64, "thread")
        }
    )?;
    write!(stdout, "{}", evaluation.team.table())?;
    writeln!(stdout, "per robot:")?;
    write!(stdout, "{}", evaluation.summary.table())?;
    writeln!(stdout, "outputs in {}", job.out_dir.display())?;
    drop(stdout);
    let team = &evaluation.team;
    job.end(
        evaluation.write_error,
        evaluation.result.error.as_ref(),
        evaluation.result.cancelled,
        (team.episodes, "team success rate", team.team_success_rate),
    )
}

/// The error of a run whose files could not be written (a full disk, a read-only directory):
/// what is kept, and how to go on (space to free only when the disk is full).
fn stopped_writing(e: ronap_core::io::OutputError, dir: &Path) -> anyhow::Error {
    use ronap_core::io::OutputError;
    let full = matches!(&e, OutputError::Io { source, .. }
        if source.kind() == std::io::ErrorKind::StorageFull);
    let fix = if full {
        "free some space"
    } else {
        "fix the cause"
    };
    if let OutputError::Episodes { .. } = &e {
        // The run itself is whole; pictures, step logs or GIFs are missing.
        return anyhow::Error::new(e).context(format!(
            "the run finished and its results are in {}, but some of its per-episode files are \
             missing",
            dir.display()
        ));
    }
    let plan = dir.join(ronap_core::io::PLAN_FILE);
    let next = if plan.exists() {
        format!(
            "the finished episodes are kept in {}; {fix}, then ronap run --resume {}",
            dir.display(),
            dir.display()
        )
    } else {
        format!("nothing was written; {fix}, then run again")
    };
    anyhow::Error::new(e).context(format!("run stopped: {next}"))
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
