//! A run directory: what an evaluation writes (the sequence that runs an evaluation into it is
//! [`crate::job`]'s). The plan `run.json` first; `episodes.csv` and `timing.csv` (`robots.csv` for teams) row by row in seed order as
//! episodes finish, under partial names until the end; the manifest `summary.json` at the end;
//! trajectory pictures (`png/`) and step logs (`steps/`) as each episode finishes. A run stopped
//! short can be finished by another process ([`RunWriter::resume`]), and a lock keeps two runs
//! out of one directory.
//!
//! Everything here is deterministic given the records except `timing.csv`, which holds the wall
//! times, so `episodes.csv` is byte-identical whatever the thread count.

mod episode_files;
mod rows;
mod writer;

use crate::config::ValidConfig;
use crate::eval::{EpisodeRecord, EvalOptions, Outcome, RunResult, Summary};
use crate::io::atomic::OutputError;
pub use crate::io::block_run::{BlockRun, EpisodeRows};
use crate::io::figures::{self, FIGURES_FILE};
use crate::io::manifest::{ManifestError, RunManifest, RunPlan, SCHEMA_VERSION};
use crate::io::partial::partial_path;
use crate::scene::map::MapSource;
use crate::sim::SceneSpec;
pub use rows::{episode_header, episode_row, metric_cells, timing_row, Layout, TIMING_COLUMNS};
pub(crate) use rows::{joined, start_goal_cells, START_GOAL_COLUMNS};
use std::path::{Path, PathBuf};
pub use writer::RunWriter;
pub(crate) use writer::{finish, Streams};

/// Which episodes get a trajectory picture.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pictures {
    /// The first N seeds of the range.
    First(u64),
    /// Every episode that did not succeed.
    Failures,
    /// Every episode.
    All,
}

impl std::str::FromStr for Pictures {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "failures" => Ok(Self::Failures),
            "all" => Ok(Self::All),
            n => n
                .parse()
                .map(Self::First)
                .map_err(|_| format!("{n:?}: expected a number, `failures` or `all`")),
        }
    }
}

impl std::fmt::Display for Pictures {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Pictures::First(n) => write!(f, "{n}"),
            Pictures::Failures => f.write_str("failures"),
            Pictures::All => f.write_str("all"),
        }
    }
}

impl Pictures {
    /// Whether any episode may get one (`--png 0` asks for none: no folder is made for it).
    pub fn any(self) -> bool {
        self != Pictures::First(0)
    }

    /// Whether `record` gets a picture, in a run whose seeds start at `first_seed`.
    pub fn wants(self, record: &EpisodeRecord, first_seed: u64) -> bool {
        self.wants_seed(record.seed, record.outcome, first_seed)
    }

    /// Whether the episode of `seed`, which ended as `outcome`, gets a picture.
    pub fn wants_seed(self, seed: u64, outcome: Outcome, first_seed: u64) -> bool {
        match self {
            Pictures::All => true,
            Pictures::Failures => outcome != Outcome::Success,
            Pictures::First(n) => seed.wrapping_sub(first_seed) < n,
        }
    }
}

/// What a run writes beside its run files.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RunFiles {
    /// Trajectory pictures in `png/`, for the episodes this chooses.
    pub pictures: Option<Pictures>,
    /// Step logs in `steps/`.
    pub steps: bool,
    /// Animations in `gif/` (written by the caller; the directory is made and cleared here).
    pub gifs: bool,
}

/// The run files written row by row while a run goes on (their partial names until the end).
const RUN_FILES: [&str; 4] = ["episodes.csv", "timing.csv", "robots.csv", FIGURES_FILE];

/// A run that cannot be resumed.
#[derive(Debug, thiserror::Error)]
pub enum ResumeError {
    /// The directory holds no run stopped short.
    #[error("cannot resume {}: {why}", dir.display())]
    NoRun {
        /// The directory.
        dir: PathBuf,
        /// Why not.
        why: String,
    },
    /// The run is complete: nothing to do.
    #[error("the run in {} is already complete ({episodes} episodes); nothing to resume", dir.display())]
    Complete {
        /// The directory.
        dir: PathBuf,
        /// Its episodes.
        episodes: usize,
    },
    /// The plan cannot be read, or is of another schema or ronap version.
    #[error("cannot resume: {0}")]
    Plan(#[from] ManifestError),
    /// The directory cannot be locked or its files read.
    #[error(transparent)]
    Output(#[from] OutputError),
}

/// What a run is, for its manifest: the policy's name and where its episodes took place.
#[derive(Clone, Debug)]
pub struct RunInfo {
    /// The policy as named to the front end.
    pub policy: String,
    /// Where episodes take place.
    pub scenes: SceneSpec,
    /// What the map file was read as, for runs on a map.
    pub map: Option<MapSource>,
}

impl RunInfo {
    /// The run a plan describes.
    pub fn of(plan: &RunPlan) -> Self {
        Self {
            policy: plan.policy.clone(),
            scenes: plan.scenes.clone(),
            map: plan.map.clone(),
        }
    }
}

/// The headers of a lone robot's run files, in the order of [`RUN_FILES`].
pub(crate) fn lone_headers(layout: Layout) -> [Option<Vec<String>>; 4] {
    let strings = |h: &[&str]| Some(h.iter().map(|c| c.to_string()).collect());
    [
        strings(&episode_header(layout)),
        strings(&TIMING_COLUMNS),
        None,
        Some(figures::lone_columns(layout.metrics)),
    ]
}

/// Reads the exact figures of the first `done` episodes of the run in `dir` into `add`.
pub(crate) fn restore(
    dir: &Path,
    done: usize,
    add: &mut dyn FnMut(&csv::StringRecord) -> Result<(), String>,
) -> Result<(), OutputError> {
    let path = partial_path(&dir.join(FIGURES_FILE));
    let path = if path.exists() {
        path
    } else {
        dir.join(FIGURES_FILE)
    };
    let bad = |message: String| OutputError::Format {
        path: path.clone(),
        message,
    };
    let mut reader = csv::ReaderBuilder::new()
        .flexible(true)
        .from_path(&path)
        .map_err(|e| bad(e.to_string()))?;
    let mut row = csv::StringRecord::new();
    for k in 0..done {
        let line = k + 2;
        match reader.read_record(&mut row) {
            Ok(true) => add(&row).map_err(|m| bad(format!("row {line}: {m}")))?,
            Ok(false) => return Err(bad(format!("ends before row {line}"))),
            Err(e) => return Err(bad(format!("row {line}: {e}"))),
        }
    }
    Ok(())
}

pub(crate) fn manifest(
    config: &ValidConfig,
    options: &EvalOptions,
    info: &RunInfo,
    result: &RunResult,
    summary: &Summary,
) -> RunManifest {
    RunManifest {
        schema_version: SCHEMA_VERSION,
        ronap_version: env!("CARGO_PKG_VERSION").to_string(),
        model_version: crate::MODEL_VERSION,
        policy: info.policy.clone(),
        seed_start: options.seeds.first().unwrap_or(0),
        seeds_requested: options.seeds.len() as u64,
        threads: options.threads,
        scenes: info.scenes.clone(),
        map: info.map.clone(),
        interrupted: result.cancelled,
        error: result.error.as_ref().map(|e| e.to_string()),
        summary: summary.clone(),
        team: None,
        config: config.as_sim_config().clone(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::{Evaluator, Seeds};
    use crate::io::manifest::PLAN_FILE;
    use crate::policy::Builtin;
    use crate::sim::Scenes;
    use std::sync::atomic::AtomicBool;

    fn setting() -> (ValidConfig, Evaluator, RunInfo) {
        let mut c = crate::SimConfig::default();
        c.episode.max_steps = 120;
        let config = c.validate().unwrap();
        let evaluator = Evaluator::new(config.clone(), Scenes::MazePerSeed);
        let info = RunInfo {
            policy: "apf".into(),
            scenes: SceneSpec::MazePerSeed,
            map: None,
        };
        (config, evaluator, info)
    }

    fn options(start: u64, count: u64) -> EvalOptions {
        EvalOptions {
            seeds: Seeds::Range { start, count },
            threads: 2,
            ..EvalOptions::default()
        }
    }

    /// The rows of seeds `start..start + count`, evaluated on their own (a block elsewhere).
    fn block(evaluator: &Evaluator, start: u64, count: u64) -> Vec<EpisodeRows> {
        let result = evaluator
            .run(
                &Builtin::Apf,
                &options(start, count),
                &AtomicBool::new(false),
                &|_| {},
            )
            .unwrap();
        result
            .records
            .iter()
            .map(|r| EpisodeRows::of(r, Layout::default()))
            .collect()
    }

    fn without_timing(m: &RunManifest) -> Summary {
        Summary {
            wall_time_s: 0.0,
            steps_per_second: 0.0,
            ..m.summary.clone()
        }
    }

    #[test]
    fn a_run_written_from_blocks_equals_one_run() {
        let (config, evaluator, info) = setting();
        let tmp = tempfile::tempdir().unwrap();
        let (one, blocks) = (tmp.path().join("one"), tmp.path().join("blocks"));
        let writer = RunWriter::create(&one, RunFiles::default(), 0, false).unwrap();
        // The whole run as the job layer writes it, for the blocks to be held to.
        let request = crate::job::RunRequest {
            evaluator: &evaluator,
            options: &options(0, 30),
            info: &info,
            writer: Some(writer),
            cancel: &AtomicBool::new(false),
        };
        let whole = crate::job::evaluate_into(request, &Builtin::Apf, &|_| {}, &|_| false).unwrap();
        let writer = RunWriter::create(&blocks, RunFiles::default(), 0, false).unwrap();
        let mut run = BlockRun::create(writer, &config, &options(0, 30), &info).unwrap();
        for start in [0, 12, 24] {
            run.add(&block(&evaluator, start, (30 - start).min(12)))
                .unwrap();
        }
        let manifest = run.finish(1.0).unwrap();
        let read = |dir: &Path, name: &str| std::fs::read(dir.join(name)).unwrap();
        assert_eq!(read(&one, "episodes.csv"), read(&blocks, "episodes.csv"));
        assert_eq!(read(&one, PLAN_FILE), read(&blocks, PLAN_FILE));
        assert_eq!(without_timing(&whole.manifest), without_timing(&manifest));
        assert!(!blocks.join(FIGURES_FILE).exists());
        assert!(!partial_path(&blocks.join("episodes.csv")).exists());
    }

    #[test]
    fn a_new_run_clears_an_earlier_runs_episode_files_and_nothing_else() {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path().join("run");
        let stale = [
            "png/seed-000001-success.png",
            "steps/seed-000001.csv",
            "steps/seed-000001-top.gif",
            "gif/seed-000001-success.gif",
        ];
        let kept = ["steps/notes.txt", "png/mine.png", "other.csv"];
        for f in stale.iter().chain(&kept) {
            let path = dir.join(f);
            std::fs::create_dir_all(path.parent().unwrap()).unwrap();
            std::fs::write(path, b"x").unwrap();
        }
        let writer = RunWriter::create(&dir, RunFiles::default(), 0, true).unwrap();
        // Nothing goes before the new run's first episode...
        for f in stale.iter().chain(&kept) {
            assert!(dir.join(f).exists(), "{f} removed before the first episode");
        }
        // ...which makes the directory ready.
        writer.make_ready().unwrap();
        drop(writer);
        for f in stale {
            assert!(!dir.join(f).exists(), "{f} left");
        }
        for f in kept {
            assert!(dir.join(f).exists(), "{f} removed");
        }
    }

    #[test]
    fn rows_out_of_order_are_refused_and_a_stopped_block_run_resumes() {
        let (config, evaluator, info) = setting();
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path().join("run");
        let writer = RunWriter::create(&dir, RunFiles::default(), 5, false).unwrap();
        let mut run = BlockRun::create(writer, &config, &options(5, 20), &info).unwrap();
        let e = run.add(&block(&evaluator, 15, 5)).unwrap_err();
        assert!(
            e.to_string()
                .contains("rows of seed 15 came where seed 5 is next"),
            "{e}"
        );
        run.add(&block(&evaluator, 5, 10)).unwrap();
        assert_eq!(
            run.remaining(),
            Seeds::Range {
                start: 15,
                count: 10
            }
        );
        // Stopped short (the driver killed): the finished rows stay, partial.
        let stopped = run.finish(1.0).unwrap();
        assert!(stopped.interrupted);
        // A new run there would throw them away: refused, naming what shows it stopped short.
        let refused = RunWriter::create(&dir, RunFiles::default(), 5, false).unwrap_err();
        assert!(
            matches!(&refused, OutputError::StoppedShort { why, .. } if why.contains("interrupted")),
            "{refused}"
        );
        let (writer, plan) = RunWriter::resume(&dir).unwrap();
        assert_eq!(writer.done(), 10);
        let info = RunInfo::of(&plan);
        let mut run = BlockRun::create(writer, &config, &options(5, 20), &info).unwrap();
        run.add(&block(&evaluator, 15, 10)).unwrap();
        let resumed = run.finish(1.0).unwrap();
        let whole = tmp.path().join("whole");
        let mut run = BlockRun::create(
            RunWriter::create(&whole, RunFiles::default(), 5, false).unwrap(),
            &config,
            &options(5, 20),
            &info,
        )
        .unwrap();
        run.add(&block(&evaluator, 5, 20)).unwrap();
        let manifest = run.finish(1.0).unwrap();
        assert_eq!(
            std::fs::read(dir.join("episodes.csv")).unwrap(),
            std::fs::read(whole.join("episodes.csv")).unwrap()
        );
        assert_eq!(without_timing(&resumed), without_timing(&manifest));
    }
}
