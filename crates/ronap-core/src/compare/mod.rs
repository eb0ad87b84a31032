//! Comparisons, above `io`: several policies on the same seeds and scenes, with paired
//! statistics (which differences are real), pictures and a report a person reads. Uses every
//! layer below it.
//!
//! Each policy's episodes are an ordinary run directory (`DIR/runs/<policy>/`), the same files
//! `ronap run` writes, so each can be replayed or reused; a run given for reuse must have been made
//! with the same configuration, scenes and seeds. The figures are deterministic: the bootstrap
//! draws from a fixed seed.
//!
//! The files are private: what other crates use is re-exported here, so a file can move without
//! breaking anyone.

mod difficulty;
mod disagreements;
mod report;
mod result;
mod reuse;
mod stats;

use crate::config::{OnCollision, ValidConfig};
use crate::eval::{EvalOptions, Evaluator, Recording};
use crate::io::{ManifestError, OutputError, RunFiles, RunInfo, RunManifest, RunWriter};
use crate::job::{evaluate_into, evaluate_team_into, RunRequest};
use crate::policy::{PolicyError, PolicyFactory, TeamPolicyFactory};
use crate::scene::map::MapSource;
use crate::sim::SceneSpec;
pub use difficulty::{Bin, Difficulty, Figure};
use disagreements::disagreement_sheet;
pub use disagreements::disagreements;
use rayon::prelude::*;
pub use report::Table;
pub use result::{BinResult, Breakdown, Comparison, PairResult, PolicyResult, SeedResult};
use reuse::read_run;
use stats::ALPHA;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

/// The seed of the bootstrap's generator: the intervals are the same on every run.
pub const BOOTSTRAP_SEED: u64 = 0x5eed_b007;

/// One policy to compare.
pub struct Contender {
    /// The policy as named to the front end (`apf`, `mlp:policies/bc.safetensors`...).
    pub name: String,
    /// Makes it.
    pub factory: Box<dyn PolicyFactory>,
    /// Makes the team policy a team scenario (`[[robots]]`) runs under this contender's name
    /// (the robots of entries without a policy of their own driven by `factory`'s).
    pub team: Option<Box<dyn TeamPolicyFactory>>,
    /// A run directory of this policy to read instead of running it again.
    pub reuse: Option<PathBuf>,
}

/// How a comparison runs.
#[derive(Clone, Debug)]
pub struct CompareOptions {
    /// The episode seeds, the same for every policy.
    pub seeds: Vec<u64>,
    /// Worker threads (0: all cores).
    pub threads: usize,
    /// Also compute each seed's difficulty and break results down by it.
    pub by_difficulty: bool,
    /// Bins per difficulty figure.
    pub difficulty_bins: usize,
    /// Bootstrap resamples for the paired intervals.
    pub resamples: usize,
    /// Seeds in the contact sheet of disagreements.
    pub sheet_rows: usize,
    /// Most seeds to write a side-by-side player of (`players/`), the most disagreeing first;
    /// `None`: every seed where the policies' successes differ.
    pub players: Option<usize>,
    /// Write into an output directory that holds a comparison or other files (an earlier
    /// comparison's runs and report are replaced; other files kept).
    pub replace: bool,
}

impl Default for CompareOptions {
    fn default() -> Self {
        Self {
            seeds: Vec::new(),
            threads: 0,
            by_difficulty: false,
            difficulty_bins: 3,
            resamples: 10_000,
            sheet_rows: 6,
            players: None,
            replace: false,
        }
    }
}

/// What a comparison is, for its files: where episodes took place and how to run it again.
#[derive(Clone, Debug)]
pub struct CompareInfo {
    /// Where episodes take place.
    pub scenes: SceneSpec,
    /// What the map file was read as, for runs on a map.
    pub map: Option<MapSource>,
    /// The command that reproduces the comparison, for the report.
    pub command: String,
}

/// Why a comparison could not be made.
#[derive(Debug, thiserror::Error)]
pub enum CompareError {
    /// Fewer than two policies, or no seeds.
    #[error("{0}")]
    Input(String),
    /// A run given for reuse cannot be read.
    #[error("--run {}: {source}", dir.display())]
    Manifest {
        /// The run directory.
        dir: PathBuf,
        /// Why (boxed: it is large, and rare).
        source: Box<ManifestError>,
    },
    /// A run given for reuse does not match this comparison.
    #[error("--run {}: {message}", dir.display())]
    Mismatch {
        /// The run directory.
        dir: PathBuf,
        /// What differs.
        message: String,
    },
    /// A policy could not be made.
    #[error("policy {policy}: {source}")]
    Policy {
        /// The policy.
        policy: String,
        /// Why.
        source: PolicyError,
    },
    /// A policy's run stopped on a failing episode; its finished episodes are in `dir`.
    #[error("policy {policy}: {message} (its finished episodes are saved in {})", dir.display())]
    Run {
        /// The policy.
        policy: String,
        /// The error.
        message: String,
        /// Its run directory.
        dir: PathBuf,
    },
    /// Interrupted; the runs finished so far are saved.
    #[error("interrupted; the finished episodes are saved in {}", dir.display())]
    Cancelled {
        /// Where the runs are.
        dir: PathBuf,
    },
    /// An output file could not be written.
    #[error(transparent)]
    Output(#[from] OutputError),
}

/// What counts as a success under `config`, in words (named in every comparison output).
pub fn success_rule(config: &ValidConfig) -> String {
    let e = &config.episode;
    let collisions = match config.robot.on_collision {
        OnCollision::Revert => "collisions are reverted and counted, and do not end it",
        OnCollision::Terminate => "a collision ends it as a failure",
    };
    let reward = e
        .reward_min
        .map(|r| format!("; a summed reward down to {r} ends it as a failure"))
        .unwrap_or_default();
    let robot = format!(
        "the robot's centre comes within {} px of the goal within {} steps ({collisions}{reward}; a policy that gives up fails)",
        e.goal_tolerance_px, e.max_steps
    );
    match config.team_size() {
        0 => format!("success = {robot}"),
        n => format!(
            "team success = each of the {n} robots reaches its goals, where a robot's success = \
             {robot}; a deadlock fails the team"
        ),
    }
}

/// Short, unique, file-safe labels for policy names: `mlp:policies/bc.safetensors` -> `bc`, and
/// `-2`, `-3`... for repeats.
pub fn labels(names: &[String]) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    for name in names {
        let base = name.split('@').next().unwrap_or(name);
        let base = base.rsplit(['/', ':']).next().unwrap_or(base);
        let base = base.strip_suffix(".safetensors").unwrap_or(base);
        let base = base.strip_suffix(".py").unwrap_or(base);
        let mut base: String = base
            .chars()
            .map(|c| {
                if c.is_ascii_alphanumeric() || c == '-' || c == '_' || c == '.' {
                    c
                } else {
                    '_'
                }
            })
            .collect();
        if base.is_empty() || base.starts_with('.') {
            base.insert_str(0, "policy");
        }
        let label = (1..)
            .map(|k| {
                if k == 1 {
                    base.clone()
                } else {
                    format!("{base}-{k}")
                }
            })
            .find(|l| !out.contains(l))
            .unwrap_or(base);
        out.push(label);
    }
    out
}

/// The policies of a comparison: `names`, each paired with the run in `runs` that recorded it
/// (read from each run's `summary.json`); a run of a policy not in `names` adds it. Fails when a
/// run's summary cannot be read.
pub fn with_runs(
    names: &[String],
    runs: &[PathBuf],
) -> Result<Vec<(String, Option<PathBuf>)>, CompareError> {
    let mut out: Vec<(String, Option<PathBuf>)> = names.iter().map(|n| (n.clone(), None)).collect();
    for dir in runs {
        let manifest = RunManifest::read(&dir.join("summary.json")).map_err(|source| {
            CompareError::Manifest {
                dir: dir.clone(),
                source: Box::new(source),
            }
        })?;
        match out
            .iter_mut()
            .find(|(n, reuse)| *n == manifest.policy && reuse.is_none())
        {
            Some((_, reuse)) => *reuse = Some(dir.clone()),
            None => out.push((manifest.policy, Some(dir.clone()))),
        }
    }
    Ok(out)
}

/// Progress of a comparison, for a front end's bar.
#[derive(Clone, Copy, Debug)]
pub enum Progress<'a> {
    /// Policy `index` started running `episodes` episodes.
    Running {
        /// Which policy.
        index: usize,
        /// Its label.
        label: &'a str,
        /// How many episodes.
        episodes: usize,
    },
    /// An episode of the running policy finished.
    Episode,
    /// Difficulty figures are being computed for `seeds` seeds.
    Difficulty {
        /// How many.
        seeds: usize,
    },
    /// Pictures and the report are being drawn.
    Report,
}

/// A comparison to make, and where its files go (the use-case's request, as a run's
/// [`crate::job::RunRequest`]).
pub struct CompareRequest<'a> {
    /// The episodes' configuration and scenes.
    pub evaluator: &'a Evaluator,
    /// The policies to compare (at least two), each run or read from a finished run.
    pub contenders: &'a [Contender],
    /// The seeds, threads and the statistics' settings.
    pub options: &'a CompareOptions,
    /// What the report records: the scenes, the map, the command.
    pub info: &'a CompareInfo,
    /// The comparison's directory (`None`: figures only, no files).
    pub out: Option<&'a Path>,
    /// Set (Ctrl-C, a signal) to stop between episodes, keeping the runs that finished.
    pub cancel: &'a AtomicBool,
}

/// Runs (or reads) every contender on `options.seeds` and compares them; with `out`, writes the
/// runs to `out/runs/<label>/` and the comparison's files to `out`.
pub fn compare(
    request: CompareRequest<'_>,
    progress: &(dyn Fn(Progress) + Sync),
) -> Result<Comparison, CompareError> {
    let CompareRequest {
        evaluator,
        contenders,
        options,
        info,
        out,
        cancel,
    } = request;
    if contenders.len() < 2 {
        return Err(CompareError::Input(format!(
            "{} polic{} given: a comparison needs at least two",
            contenders.len(),
            if contenders.len() == 1 { "y" } else { "ies" }
        )));
    }
    let seeds = &options.seeds;
    let (Some(&first), Some(&last)) = (seeds.first(), seeds.last()) else {
        return Err(CompareError::Input("no seeds: give at least one".into()));
    };
    let mut sorted = seeds.clone();
    sorted.sort_unstable();
    if let Some(w) = sorted.windows(2).find(|w| w[0] == w[1]) {
        return Err(CompareError::Input(format!(
            "seed {} is given twice: each seed is one pair of episodes",
            w[0]
        )));
    }
    if options.resamples < stats::MIN_RESAMPLES {
        return Err(CompareError::Input(format!(
            "resamples = {}: the bootstrap needs at least {}",
            options.resamples,
            stats::MIN_RESAMPLES
        )));
    }
    if options.difficulty_bins == 0 {
        return Err(CompareError::Input(
            "bins = 0: results need at least one bin".into(),
        ));
    }
    let config = evaluator.config();
    if config.team_size() > 0 {
        if let Some(c) = contenders.iter().find(|c| c.team.is_none()) {
            return Err(CompareError::Input(format!(
                "policy {}: no team policy was given for this team scenario",
                c.name
            )));
        }
    }
    let names: Vec<String> = contenders.iter().map(|c| c.name.clone()).collect();
    let labels = labels(&names);
    // Every reused run is checked before anything runs or is written.
    let mut reused: Vec<Option<(PathBuf, RunManifest, Vec<SeedResult>)>> = Vec::new();
    for c in contenders {
        reused.push(match &c.reuse {
            Some(dir) => {
                let (manifest, rows) = read_run(evaluator, dir, &c.name, info, &options.seeds)?;
                Some((dir.clone(), manifest, rows))
            }
            None => None,
        });
    }
    if let Some(dir) = out {
        // A fresh run never writes into a run being reused.
        let canonical = |p: &Path| std::fs::canonicalize(p).ok();
        for (c, label) in contenders.iter().zip(&labels) {
            let target = canonical(&dir.join("runs").join(label));
            let taken = contenders
                .iter()
                .filter_map(|o| o.reuse.as_deref())
                .find(|r| c.reuse.is_none() && target.is_some() && canonical(r) == target);
            if let Some(r) = taken {
                return Err(CompareError::Input(format!(
                    "--run {}: policy {} would be run into that directory; give another --out",
                    r.display(),
                    c.name
                )));
            }
        }
        if !options.replace {
            report::check_empty(dir)?;
        }
        let runs = dir.join("runs");
        std::fs::create_dir_all(&runs).map_err(|source| OutputError::Io { path: runs, source })?;
    }
    let setting = Setting {
        evaluator,
        options,
        info,
        out,
        cancel,
        progress,
    };
    let mut policies = Vec::new();
    for (index, (c, reuse)) in contenders.iter().zip(reused).enumerate() {
        let label = labels[index].clone();
        let result = match reuse {
            Some((dir, manifest, seeds)) => PolicyResult {
                name: c.name.clone(),
                label,
                run_dir: Some(dir),
                reused: true,
                summary: manifest.summary,
                team: manifest.team,
                seeds,
            },
            None => match run_one(&setting, c, &label, index) {
                Ok(r) => r,
                Err(e) => {
                    // A comparison replaced (`replace`) that stops here has replaced some of
                    // the earlier one's runs: its report goes too, so the directory never shows
                    // a report of runs that are not there.
                    if let (Some(dir), true) = (out, options.replace) {
                        let _ = report::remove_earlier(dir);
                    }
                    return Err(e);
                }
            },
        };
        policies.push(result);
    }
    let difficulty = if options.by_difficulty {
        progress(Progress::Difficulty {
            seeds: options.seeds.len(),
        });
        difficulties(evaluator, &options.seeds, options.threads)
    } else {
        Vec::new()
    };
    let pairs = pairs(&policies, options.resamples);
    let by_difficulty = options.by_difficulty.then(|| {
        Figure::ALL
            .iter()
            .map(|&f| breakdown(&policies, &difficulty, f, options.difficulty_bins))
            .collect()
    });
    let comparison = Comparison {
        ronap_version: env!("CARGO_PKG_VERSION").to_string(),
        success_rule: success_rule(config),
        scenes: info.scenes.to_string(),
        seed_start: first,
        seed_count: seeds.len(),
        seed_last: last,
        seeds_contiguous: seeds.windows(2).all(|w| w[0].checked_add(1) == Some(w[1])),
        policies,
        pairs,
        by_difficulty,
        difficulty,
        command: info.command.clone(),
        config: config.clone(),
    };
    if let Some(dir) = out {
        progress(Progress::Report);
        let sheet = disagreement_sheet(evaluator, contenders, &comparison, options.sheet_rows)?;
        report::remove_earlier(dir)?;
        let players =
            disagreements::write_players(evaluator, contenders, &comparison, dir, options.players)?;
        report::write_all(dir, &comparison, sheet.as_ref(), &players)?;
    }
    Ok(comparison)
}

/// What every contender of a comparison runs in: the episodes, the options, where runs go, the
/// cancel flag and who hears the progress.
struct Setting<'a> {
    evaluator: &'a Evaluator,
    options: &'a CompareOptions,
    info: &'a CompareInfo,
    out: Option<&'a Path>,
    cancel: &'a AtomicBool,
    progress: &'a (dyn Fn(Progress) + Sync),
}

/// A contender's run directory refused: one holding a finished run was left by an earlier
/// comparison into this --out that stopped short (one that finished is refused before any run),
/// so the error says how to use it.
fn earlier_run(e: OutputError, policy: &str) -> CompareError {
    match e {
        OutputError::Finished { dir, .. } => CompareError::Input(format!(
            "{} holds the finished run of an earlier comparison into this --out that stopped \
             short: give --run {} in place of --policy {policy} to reuse it, or --force to run \
             it again",
            dir.display(),
            dir.display()
        )),
        e => e.into(),
    }
}

/// Runs contender `c` (the `index`-th) into `out/runs/<label>` (when there is an `out`).
fn run_one(
    setting: &Setting<'_>,
    c: &Contender,
    label: &str,
    index: usize,
) -> Result<PolicyResult, CompareError> {
    let (evaluator, options, info) = (setting.evaluator, setting.options, setting.info);
    let (out, cancel, progress) = (setting.out, setting.cancel, setting.progress);
    let dir = out.map(|d| d.join("runs").join(label));
    let writer = dir
        .as_deref()
        .map(|d| {
            RunWriter::create(d, RunFiles::default(), options.seeds[0], options.replace)
                .map_err(|e| earlier_run(e, &c.name))
        })
        .transpose()?;
    progress(Progress::Running {
        index,
        label,
        episodes: options.seeds.len(),
    });
    let eval_options = EvalOptions {
        seeds: options.seeds.clone().into(),
        threads: options.threads,
        recording: Recording::default(),
        steps_of: Vec::new(),
    };
    let run_info = RunInfo {
        policy: c.name.clone(),
        scenes: info.scenes.clone(),
        map: info.map.clone(),
    };
    let request = RunRequest {
        evaluator,
        options: &eval_options,
        info: &run_info,
        writer,
        cancel,
    };
    if let (Some(team), true) = (&c.team, evaluator.config().team_size() > 0) {
        return run_team(setting, c, team.as_ref(), label, request);
    }
    let evaluation = evaluate_into(
        request,
        c.factory.as_ref(),
        &|_| progress(Progress::Episode),
        &|_| true,
    )
    .map_err(|source| policy_error(c, source))?;
    let seeds = evaluation.result.records.iter().map(SeedResult::of);
    RunEnding {
        write_error: evaluation.write_error,
        error: evaluation.result.error.as_ref(),
        cancelled: evaluation.result.cancelled,
        summary: evaluation.summary,
        team: None,
        seeds: seeds.collect(),
    }
    .into_result(c, label, dir, out)
}

/// The comparison's error when contender `c`'s policy could not be made or run.
fn policy_error(c: &Contender, source: PolicyError) -> CompareError {
    CompareError::Policy {
        policy: c.name.clone(),
        source,
    }
}

/// How a contender's run ended, lone or team, and its figures.
struct RunEnding<'a> {
    write_error: Option<OutputError>,
    error: Option<&'a crate::run::RunError>,
    cancelled: bool,
    summary: crate::eval::Summary,
    team: Option<crate::eval::TeamSummary>,
    /// Each seed's figures, in seed order.
    seeds: Vec<SeedResult>,
}

impl RunEnding<'_> {
    /// Contender `c`'s result (labelled `label`, its run in `dir`, under `out`), or the
    /// comparison's error when the run did not finish every seed: its files could not be
    /// written, an episode failed, or it was interrupted.
    fn into_result(
        self,
        c: &Contender,
        label: &str,
        dir: Option<PathBuf>,
        out: Option<&Path>,
    ) -> Result<PolicyResult, CompareError> {
        if let Some(e) = self.write_error {
            return Err(e.into());
        }
        if let Some(e) = self.error {
            return Err(CompareError::Run {
                policy: c.name.clone(),
                message: e.to_string(),
                dir: dir.unwrap_or_default(),
            });
        }
        if self.cancelled {
            return Err(CompareError::Cancelled {
                dir: out.map(|d| d.join("runs")).unwrap_or_default(),
            });
        }
        Ok(PolicyResult {
            name: c.name.clone(),
            label: label.to_string(),
            run_dir: dir,
            reused: false,
            summary: self.summary,
            team: self.team,
            seeds: self.seeds,
        })
    }
}

/// Runs contender `c` of a team comparison with `team`, its team policy, as `request` asks: the
/// paired figures are the team's (a seed's success is the team's success).
fn run_team(
    setting: &Setting<'_>,
    c: &Contender,
    team: &dyn TeamPolicyFactory,
    label: &str,
    request: RunRequest<'_>,
) -> Result<PolicyResult, CompareError> {
    let dir = request.writer.as_ref().map(|w| w.dir().to_path_buf());
    // Each seed's figures, in seed order (the records themselves are not kept).
    let seeds = std::cell::RefCell::new(Vec::new());
    let evaluation = evaluate_team_into(
        request,
        team,
        &|_| (setting.progress)(Progress::Episode),
        &|r| {
            seeds.borrow_mut().push(SeedResult::of_team(r));
            false
        },
    )
    .map_err(|source| policy_error(c, source))?;
    RunEnding {
        write_error: evaluation.write_error,
        error: evaluation.result.error.as_ref(),
        cancelled: evaluation.result.cancelled,
        summary: evaluation.summary,
        team: Some(evaluation.team),
        seeds: seeds.into_inner(),
    }
    .into_result(c, label, dir, setting.out)
}

/// Every seed's difficulty (a team's: [`Difficulty::of_team`]), in seed order, computed on
/// `threads` threads.
fn difficulties(evaluator: &Evaluator, seeds: &[u64], threads: usize) -> Vec<Option<Difficulty>> {
    let of = |&s: &u64| match evaluator.config().team_size() {
        0 => Difficulty::of(&evaluator.world(s), s),
        _ => Difficulty::of_team(evaluator, s),
    };
    match rayon::ThreadPoolBuilder::new().num_threads(threads).build() {
        Ok(pool) => pool.install(|| seeds.par_iter().map(of).collect()),
        Err(_) => seeds.iter().map(of).collect(),
    }
}

/// The paired statistics of every pair of policies.
fn pairs(policies: &[PolicyResult], resamples: usize) -> Vec<PairResult> {
    let mut out = Vec::new();
    for i in 0..policies.len() {
        for j in i + 1..policies.len() {
            let (a, b) = (&policies[i], &policies[j]);
            let both = a.seeds.iter().zip(&b.seeds);
            let a_only = both
                .clone()
                .filter(|(x, y)| x.success() && !y.success())
                .count() as u64;
            let b_only = both
                .clone()
                .filter(|(x, y)| !x.success() && y.success())
                .count() as u64;
            let success: Vec<f64> = both
                .clone()
                .map(|(x, y)| f64::from(u8::from(x.success())) - f64::from(u8::from(y.success())))
                .collect();
            let spl: Vec<f64> = both.map(|(x, y)| x.spl - y.spl).collect();
            let seed = BOOTSTRAP_SEED ^ ((i as u64) << 32 | j as u64);
            let (success_diff, success_diff_ci95) =
                stats::bootstrap_mean95(&success, resamples, seed);
            let (spl_diff, spl_diff_ci95) = stats::bootstrap_mean95(&spl, resamples, seed + 1);
            out.push(PairResult {
                a: a.label.clone(),
                b: b.label.clone(),
                success_diff,
                success_diff_ci95,
                a_only,
                b_only,
                mcnemar_p: stats::mcnemar_exact(a_only, b_only),
                holm_p: 1.0,
                spl_diff,
                spl_diff_ci95,
                verdict: String::new(),
            });
        }
    }
    let p: Vec<f64> = out.iter().map(|p| p.mcnemar_p).collect();
    for (pair, holm) in out.iter_mut().zip(stats::holm(&p)) {
        pair.holm_p = holm;
        pair.verdict = verdict(pair);
    }
    out
}

/// A pair's result in a few words: which policy is better in success and in SPL where the
/// difference is significant, "not significant" where it is not, and "too few seeds" where the
/// test could not have found a difference.
fn verdict(p: &PairResult) -> String {
    let success = if p.a_only + p.b_only < stats::min_discordant() {
        "too few discordant seeds"
    } else if p.holm_p < ALPHA {
        if p.success_diff > 0.0 {
            &p.a
        } else {
            &p.b
        }
    } else {
        "not significant"
    };
    let spl = match p.spl_diff_ci95 {
        None => "too few seeds",
        Some([lo, _]) if lo > 0.0 => &p.a,
        Some([_, hi]) if hi < 0.0 => &p.b,
        Some(_) => "not significant",
    };
    format!("success: {success}; SPL: {spl}")
}

/// Results broken down into bins of figure `by`.
fn breakdown(
    policies: &[PolicyResult],
    difficulty: &[Option<Difficulty>],
    by: Figure,
    bins: usize,
) -> Breakdown {
    let values: Vec<Option<f64>> = difficulty
        .iter()
        .map(|d| d.and_then(|d| d.figure(by)))
        .collect();
    let cut = difficulty::bins(&values, bins, by);
    let binned: usize = cut.iter().map(|b| b.members.len()).sum();
    let bins = cut
        .into_iter()
        .map(|bin| {
            let n = bin.members.len();
            let mut result = BinResult {
                seeds: n,
                success_rate: Vec::new(),
                success_ci95: Vec::new(),
                spl: Vec::new(),
                bin,
            };
            for p in policies {
                let rows: Vec<&SeedResult> =
                    result.bin.members.iter().map(|&i| &p.seeds[i]).collect();
                let k = rows.iter().filter(|r| r.success()).count();
                result.success_rate.push(k as f64 / n.max(1) as f64);
                result.success_ci95.push(crate::eval::wilson95(k, n));
                result
                    .spl
                    .push(rows.iter().map(|r| r.spl).sum::<f64>() / n.max(1) as f64);
            }
            result
        })
        .collect();
    Breakdown {
        figure: by,
        bins,
        unbinned: values.len() - binned,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_are_short_and_unique() {
        let names: Vec<String> = [
            "apf",
            "mlp:policies/bc.safetensors",
            "mlp:other/bc.safetensors@argmax",
            "py:scripts/p.py:act",
            "apf",
        ]
        .iter()
        .map(|s| s.to_string())
        .collect();
        assert_eq!(labels(&names), ["apf", "bc", "bc-2", "act", "apf-2"]);
    }

    #[test]
    fn the_success_rule_names_the_tolerance_and_the_limit() {
        let rule = success_rule(&ValidConfig::default());
        assert!(
            rule.contains("10 px") && rule.contains("2000 steps"),
            "{rule}"
        );
    }
}
