//! Evaluation, above `run`: a policy over many seeded episodes, in parallel, with honest metrics;
//! the records it keeps and the summary it gives. Uses every layer up to `run`.
//!
//! Each episode is independent and decided by its seed alone, so records are the same whatever
//! the thread count; they come back in seed order. A shared cancel flag stops the run between
//! episodes (Ctrl-C in the CLI) and keeps every finished record.

pub mod record;
pub mod summary;
pub mod team;

pub use record::{EpisodeRecord, Outcome, Recording, StepLog};
pub use summary::Summary;
pub use team::{RobotRecord, TeamRecord, TeamRunResult, TeamSummary};

use crate::config::ValidConfig;
use crate::plan::shortest_path_px;
use crate::policy::{Policy, PolicyError, PolicyFactory};
use crate::run::rollout::Rollout;
use crate::run::RunError;
use crate::sim::world::{Scenes, World, Worlds};
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Instant;

/// What an evaluation runs: which seeds, on how many threads, keeping what.
#[derive(Clone, Debug, Default)]
pub struct EvalOptions {
    /// The episode seeds, in the order records come back.
    pub seeds: Vec<u64>,
    /// Worker threads (0: all cores).
    pub threads: usize,
    /// What to keep of each episode beyond its figures.
    pub recording: Recording,
}

/// What an evaluation produced: every finished record in seed order, and how it stopped.
#[derive(Debug)]
pub struct RunResult {
    /// Finished episodes, in seed order.
    pub records: Vec<EpisodeRecord>,
    /// Whether the cancel flag stopped the run before every seed ran.
    pub cancelled: bool,
    /// The first error (in seed order), if an episode failed; the run stopped at it.
    pub error: Option<RunError>,
    /// Wall time of the whole run, seconds.
    pub wall_time_s: f64,
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

    /// Runs the episode of `seed` with `policy`.
    pub fn run_episode(
        &self,
        policy: &mut dyn Policy,
        seed: u64,
        recording: Recording,
    ) -> Result<EpisodeRecord, RunError> {
        let clock = Instant::now();
        let mut rollout = Rollout::start(self.world(seed), seed, policy)?;
        let mut trajectory = Vec::new();
        let mut step_log = Vec::new();
        let mut tracks = Vec::new();
        let record_tracks = |e: &crate::sim::episode::Episode, tracks: &mut Vec<_>| {
            if let Some(movers) = e.movers() {
                movers.record(tracks);
            }
        };
        if recording.trajectory {
            trajectory.push(rollout.episode().pose());
            record_tracks(rollout.episode(), &mut tracks);
        }
        while let Some(action) = rollout.decide(policy)? {
            let before = recording.steps.then(|| {
                let e = rollout.episode();
                (
                    e.pose(),
                    e.readings().to_vec(),
                    e.bearing_deg(),
                    e.distance_px(),
                    e.direction_deg(),
                )
            });
            let s = rollout.take(action);
            if let Some((pose, readings, bearing_deg, distance_px, direction_deg)) = before {
                step_log.push(StepLog {
                    step: s.step,
                    pose,
                    readings,
                    bearing_deg,
                    distance_px,
                    direction_deg,
                    action,
                    collided: s.collided,
                    reward: s.reward,
                });
            }
            if recording.trajectory {
                trajectory.push(s.pose);
                record_tracks(rollout.episode(), &mut tracks);
            }
        }
        let (world, episode, reason) = rollout.into_parts();
        let outcome = Outcome::of(episode.status());
        // The shortest path is only needed to score a success, and costs more than a random
        // policy's whole episode, so failures are not charged for it.
        let tolerance = self.config().episode.goal_tolerance_px;
        let shortest_px = (outcome == Outcome::Success)
            .then(|| shortest_path_px(&world, episode.start().position(), episode.goal()))
            .flatten()
            .map(|l| (l - tolerance).max(0.0));
        let path_length_px = episode.path_length_px();
        let spl = match shortest_px {
            Some(l) if outcome == Outcome::Success => {
                if path_length_px > 0.0 {
                    l / l.max(path_length_px)
                } else {
                    1.0
                }
            }
            _ => 0.0,
        };
        Ok(EpisodeRecord {
            seed,
            outcome,
            reason,
            steps: episode.steps(),
            collisions: episode.collisions(),
            path_length_px,
            shortest_px,
            spl,
            total_reward: episode.total_reward(),
            wall_time_s: clock.elapsed().as_secs_f64(),
            start: episode.start(),
            goal: episode.goal(),
            end: episode.pose(),
            last_readings: episode.readings().to_vec(),
            trajectory,
            mover_tracks: tracks,
            dynamic: episode.dynamic_metrics(),
            step_log,
            world: Some(world),
        })
    }

    /// Runs `options.seeds` with policies from `factory`. Each record goes to `on_record` as soon
    /// as its episode ends (from a worker thread), then is stripped of its trajectory and steps.
    /// Setting `cancel` stops the run between episodes.
    pub fn run(
        &self,
        factory: &dyn PolicyFactory,
        options: &EvalOptions,
        cancel: &AtomicBool,
        on_record: &(dyn Fn(&EpisodeRecord) + Sync),
    ) -> Result<RunResult, PolicyError> {
        let clock = Instant::now();
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(options.threads)
            .build()
            .map_err(|e| PolicyError::Failed(format!("cannot start worker threads: {e}")))?;
        let first_policy_error: Mutex<Option<PolicyError>> = Mutex::new(None);
        // Policies are made at most once per worker and handed from episode to episode, so a
        // costly policy (a Python process, a loaded network) is set up `threads` times, not once
        // per seed.
        let idle: Mutex<Vec<Box<dyn Policy>>> = Mutex::new(Vec::new());
        let results: Vec<Option<Result<EpisodeRecord, RunError>>> = pool.install(|| {
            options
                .seeds
                .par_iter()
                .with_max_len(1)
                .map(|&seed| {
                    if cancel.load(Ordering::Relaxed) {
                        return None;
                    }
                    let reused = idle.lock().ok().and_then(|mut v| v.pop());
                    let mut policy = match reused.map_or_else(|| factory.make(), Ok) {
                        Ok(p) => p,
                        Err(e) => {
                            cancel.store(true, Ordering::Relaxed);
                            if let Ok(mut slot) = first_policy_error.lock() {
                                slot.get_or_insert(e);
                            }
                            return None;
                        }
                    };
                    let result = self
                        .run_episode(policy.as_mut(), seed, options.recording)
                        .map(|mut record| {
                            on_record(&record);
                            record.strip();
                            record
                        });
                    if result.is_err() {
                        cancel.store(true, Ordering::Relaxed);
                    }
                    if let Ok(mut v) = idle.lock() {
                        v.push(policy);
                    }
                    Some(result)
                })
                .collect()
        });
        if let Some(e) = first_policy_error.into_inner().ok().flatten() {
            return Err(e);
        }
        let mut records = Vec::with_capacity(results.len());
        let mut error = None;
        let mut cancelled = false;
        for r in results {
            match r {
                Some(Ok(record)) => records.push(record),
                Some(Err(e)) => {
                    error.get_or_insert(e);
                }
                None => cancelled = true,
            }
        }
        Ok(RunResult {
            records,
            cancelled: cancelled && error.is_none(),
            error,
            wall_time_s: clock.elapsed().as_secs_f64(),
        })
    }
}
