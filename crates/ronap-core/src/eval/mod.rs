//! Evaluation, above `run`: a policy over many seeded episodes, in parallel, with honest metrics;
//! the records it keeps and the summary it gives. Uses every layer up to `run`.
//!
//! Each episode is independent and decided by its seed alone, so records are the same whatever
//! the thread count; they come back in seed order. A shared cancel flag stops the run between
//! episodes (Ctrl-C in the CLI) and keeps every finished record.
//!
//! The files are private: what other crates use is re-exported here (`pub use`), and what the
//! layers above use beside it, `pub(crate) use`, so a file can move without breaking anyone.

pub(crate) mod metric;
mod ordered;
mod record;
mod recorder;
mod side_by_side;
mod summary;
mod team;

// The metrics beyond the standard columns, aliased here as the evaluator has kinds of its own.
pub use metric::{
    kinds as metric_kinds, Column as MetricColumn, End as MetricEnd, Kind as MetricKind, Metric,
    MetricMean, Other as MetricOther, View as MetricView,
};
pub use record::{EpisodeRecord, InTeam, Outcome, Recording, StepLog};
pub use summary::{AmongRobots, Figures, MovingSummary, Summary, Tally};
pub use team::{
    Flow, RobotFigures, RobotLook, TeamFigures, TeamPicture, TeamRecord, TeamRunResult,
    TeamSummary, TeamTally,
};

// For the layers above only.
pub(crate) use summary::wilson95;
pub(crate) use team::team_outcome;

use crate::config::ValidConfig;
use crate::policy::{Policy, PolicyError, PolicyFactory};
use crate::run::RunError;
use crate::sim::{Scenes, SeedRanges, World, Worlds};
use ordered::{run_in_order, Ordered, Window};
use recorder::Recorder;
use side_by_side::SideBySide;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;
use std::time::Instant;

/// The seeds of an evaluation, in the order its records come back: a range (held as two numbers
/// however long) or a list.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Seeds {
    /// `count` seeds from `start`.
    Range {
        /// The first seed.
        start: u64,
        /// How many.
        count: u64,
    },
    /// These seeds.
    List(Vec<u64>),
}

impl Default for Seeds {
    fn default() -> Self {
        Self::List(Vec::new())
    }
}

impl From<Vec<u64>> for Seeds {
    fn from(seeds: Vec<u64>) -> Self {
        Self::List(seeds)
    }
}

impl Seeds {
    /// How many.
    pub fn len(&self) -> usize {
        match self {
            Self::Range { count, .. } => usize::try_from(*count).unwrap_or(usize::MAX),
            Self::List(v) => v.len(),
        }
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The `i`-th seed.
    pub fn get(&self, i: usize) -> Option<u64> {
        match self {
            Self::Range { start, count } => {
                let i = i as u64;
                (i < *count).then(|| start.wrapping_add(i))
            }
            Self::List(v) => v.get(i).copied(),
        }
    }

    /// The first seed.
    pub fn first(&self) -> Option<u64> {
        self.get(0)
    }

    /// The seeds after the first `n`.
    pub fn after(&self, n: usize) -> Seeds {
        match self {
            Self::Range { start, count } => {
                let n = (n as u64).min(*count);
                Self::Range {
                    start: start.wrapping_add(n),
                    count: count - n,
                }
            }
            Self::List(v) => Self::List(v.get(n..).unwrap_or_default().to_vec()),
        }
    }

    /// Every seed, in order.
    pub fn iter(&self) -> impl Iterator<Item = u64> + '_ {
        (0..self.len()).filter_map(|i| self.get(i))
    }

    /// How many of these seeds lie in `ranges`, and the first of them.
    pub fn overlap(&self, ranges: &SeedRanges) -> (u64, Option<u64>) {
        match self {
            Self::Range { start, count } => ranges.overlap_range(*start, *count),
            Self::List(v) => ranges.overlap_list(v.iter().copied()),
        }
    }
}

/// A warning for a run of `policy` (by name) over `seeds` when some of them are among the seeds
/// it was trained or chosen on (`seen`): its scores on them are not held out.
pub fn held_out_warning(policy: &str, seen: &SeedRanges, seeds: &Seeds) -> Option<String> {
    let (count, first) = seeds.overlap(seen);
    let first = first?;
    Some(format!(
        "{count} of this run's {} seeds (the first: {first}) are among those {policy} was trained \
         or chosen on ({seen}): its scores on them are not held out (the test split, seeds \
         0..=499999, is)",
        seeds.len()
    ))
}

/// What an evaluation runs: which seeds, on how many threads, keeping what.
#[derive(Clone, Debug, Default)]
pub struct EvalOptions {
    /// The episode seeds, in the order records come back.
    pub seeds: Seeds,
    /// Worker threads (0: all cores).
    pub threads: usize,
    /// What to keep of each episode beyond its figures.
    pub recording: Recording,
    /// Seeds whose every step is kept whatever `recording` says (the episodes a run animates).
    pub steps_of: Vec<u64>,
}

impl EvalOptions {
    /// What to keep of episode `seed`.
    pub fn recording_of(&self, seed: u64) -> Recording {
        let mut r = self.recording;
        r.steps |= self.steps_of.contains(&seed);
        r
    }
}

/// What an evaluation produced: every finished record (a lone robot's [`EpisodeRecord`], a
/// team's [`TeamRecord`]) in seed order, and how it stopped.
#[derive(Debug)]
pub struct Runs<R> {
    /// Finished episodes, in seed order.
    pub records: Vec<R>,
    /// Whether the cancel flag stopped the run before every seed ran.
    pub cancelled: bool,
    /// The first error (in seed order), if an episode failed; the run stopped at it.
    pub error: Option<RunError>,
    /// Wall time of the whole run, seconds.
    pub wall_time_s: f64,
}

/// A lone robot's evaluation.
pub type RunResult = Runs<EpisodeRecord>;

impl<R> Runs<R> {
    /// Every record `stream` hands its sink, kept, and how the stream ended.
    fn collect(
        stream: impl FnOnce(&mut dyn FnMut(R) -> bool) -> Result<RunEnd, PolicyError>,
    ) -> Result<Self, PolicyError> {
        let mut records = Vec::new();
        let end = stream(&mut |r| {
            records.push(r);
            true
        })?;
        Ok(Self {
            records,
            cancelled: end.cancelled,
            error: end.error,
            wall_time_s: end.wall_time_s,
        })
    }
}

/// A batch evaluation's setting: the configuration and where episodes take place.
pub struct Evaluator {
    worlds: Worlds,
}

impl Evaluator {
    /// An evaluator of episodes in `scenes` under `config`.
    pub fn new(config: ValidConfig, scenes: Scenes) -> Self {
        Self {
            worlds: Worlds::new(config, scenes),
        }
    }

    /// The configuration.
    pub fn config(&self) -> &ValidConfig {
        self.worlds.config()
    }

    /// Where episodes take place.
    pub fn scenes(&self) -> &Scenes {
        self.worlds.scenes()
    }

    /// The worlds of the episodes.
    pub fn worlds(&self) -> &Worlds {
        &self.worlds
    }

    /// The world of episode `seed`.
    pub fn world(&self, seed: u64) -> Arc<World> {
        self.worlds.world(seed)
    }

    /// Runs `options.seeds` with policies from `factory`, keeping every record (stripped of its
    /// trajectory and steps) in seed order: [`Evaluator::stream`] into a vector.
    pub fn run(
        &self,
        factory: &dyn PolicyFactory,
        options: &EvalOptions,
        cancel: &AtomicBool,
        on_record: &(dyn Fn(&EpisodeRecord) + Sync),
    ) -> Result<RunResult, PolicyError> {
        Runs::collect(|sink| self.stream(factory, options, cancel, on_record, sink))
    }

    /// Runs `options.seeds` with policies from `factory`. Each record goes to `on_finish` as
    /// soon as its episode ends (from a worker thread, in any order), then, stripped of its
    /// trajectory and steps, to `sink` in seed order on the calling thread; `sink` returning
    /// `false` stops the run. Memory stays flat however many seeds: workers run at most a
    /// `Window` of episodes ahead of the next record `sink` is waiting for. Setting `cancel`
    /// stops the run between episodes; the episodes under way finish and are handed on, so what
    /// `sink` saw is always the first seeds of `options.seeds`. A factory whose policies decide for
    /// several episodes at once ([`PolicyFactory::side_by_side`]) has each worker step that many
    /// side by side, in blocks of seeds (`side_by_side`): the same records, and the cancel flag
    /// then stops the run between blocks.
    pub fn stream(
        &self,
        factory: &dyn PolicyFactory,
        options: &EvalOptions,
        cancel: &AtomicBool,
        on_finish: &(dyn Fn(&EpisodeRecord) + Sync),
        sink: &mut dyn FnMut(EpisodeRecord) -> bool,
    ) -> Result<RunEnd, PolicyError> {
        let lanes = factory.side_by_side();
        if lanes > 1 {
            let side_by_side = SideBySide {
                evaluator: self,
                factory,
                options,
                lanes,
                on_finish,
            };
            return side_by_side.stream(cancel, sink);
        }
        // Policies are made at most once per worker and handed from episode to episode, so a
        // costly policy (a Python process, a loaded network) is set up `threads` times, not once
        // per seed.
        let work = |policy: &mut Option<Box<dyn Policy>>, i: usize| {
            let policy = match policy {
                Some(p) => p,
                None => policy.insert(factory.make().map_err(Failure::Policy)?),
            };
            // `i` is below `options.seeds.len()`, the number of jobs.
            let seed = options.seeds.get(i).unwrap_or_default();
            let mut record = self
                .run_episode(policy.as_mut(), seed, options.recording_of(seed))
                .map_err(Failure::Run)?;
            on_finish(&record);
            record.strip();
            Ok(record)
        };
        stream_seeds(options, cancel, &work, sink)
    }
}

/// Runs job `i` for each seed `i` of `options` (`work(state, i)`, `state` the worker's own) on
/// `options.threads` workers, at most a [`Window`] ahead of `sink`, which takes the results in
/// seed order; how the run ended.
pub(crate) fn stream_seeds<S, R: Send>(
    options: &EvalOptions,
    cancel: &AtomicBool,
    work: &ordered::Job<'_, S, R, Failure>,
    sink: &mut dyn FnMut(R) -> bool,
) -> Result<RunEnd, PolicyError> {
    let clock = Instant::now();
    let pool = worker_pool(options.threads)?;
    let count = options.seeds.len();
    let window = Window::for_threads(pool.current_num_threads());
    let ended = run_in_order(&pool, count, window, cancel, work, sink);
    RunEnd::of(ended, count, clock)
}

/// How a streamed evaluation ended; its records went to the sink.
#[derive(Debug)]
pub struct RunEnd {
    /// Episodes handed to the sink: the first `episodes` seeds.
    pub episodes: usize,
    /// Whether the cancel flag (or the sink) stopped the run before every seed ran.
    pub cancelled: bool,
    /// The error of the first failed episode in seed order; the run stopped at it.
    pub error: Option<RunError>,
    /// Wall time of the run, seconds.
    pub wall_time_s: f64,
}

impl RunEnd {
    pub(crate) fn of(
        ended: Ordered<Failure>,
        count: usize,
        clock: Instant,
    ) -> Result<Self, PolicyError> {
        let error = match ended.failed {
            Some((_, Failure::Policy(e))) => return Err(e),
            Some((_, Failure::Run(e))) => Some(e),
            None => None,
        };
        Ok(Self {
            episodes: ended.handed,
            cancelled: error.is_none() && ended.handed < count,
            error,
            wall_time_s: clock.elapsed().as_secs_f64(),
        })
    }
}

/// Why a worker's episode gave no record.
pub(crate) enum Failure {
    /// The policy could not be made.
    Policy(PolicyError),
    /// The episode failed.
    Run(RunError),
}

/// The worker threads of an evaluation (0: all cores).
pub(crate) fn worker_pool(threads: usize) -> Result<rayon::ThreadPool, PolicyError> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| PolicyError::Failed(format!("cannot start worker threads: {e}")))
}
