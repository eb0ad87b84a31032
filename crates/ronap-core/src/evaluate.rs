//! The batch evaluator: a policy over many seeded episodes, in parallel, with honest metrics.
//!
//! Each episode is independent and decided by its seed alone, so records are the same whatever
//! the thread count; they come back in seed order. A shared cancel flag stops the run between
//! episodes (Ctrl-C in the CLI) and keeps every finished record.

use crate::config::ValidConfig;
use crate::episode::{EpisodeError, Status};
use crate::geometry::Point;
use crate::policy::{Decision, Policy, PolicyError, PolicyFactory};
use crate::robot::{Action, DiscreteAction, Pose};
use crate::scene::Scene;
use crate::world::World;
use rayon::prelude::*;
use serde::Serialize;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Instant;

/// How an episode ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Outcome {
    /// Reached the goal.
    Success,
    /// Ran out of steps.
    Timeout,
    /// The policy gave up (trapped, oscillating, no path).
    Stuck,
    /// Collided with `on_collision = terminate`.
    Collision,
    /// The summed reward fell to `reward_min`.
    RewardMin,
}

impl Outcome {
    /// The name in logs and tables.
    pub fn name(self) -> &'static str {
        match self {
            Outcome::Success => "success",
            Outcome::Timeout => "timeout",
            Outcome::Stuck => "stuck",
            Outcome::Collision => "collision",
            Outcome::RewardMin => "reward_min",
        }
    }
}

/// Where episodes take place.
#[derive(Clone, Debug)]
pub enum Scenes {
    /// Each seed gets its own maze, generated from the seed.
    MazePerSeed,
    /// One maze, from this seed, for every episode.
    Maze(u64),
    /// One given scene (an image map) for every episode.
    Fixed(Arc<Scene>),
}

/// An evaluation that could not run or was cut short by an error.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum RunError {
    /// An episode could not start.
    #[error("seed {seed}: {source}")]
    Episode {
        /// The episode seed.
        seed: u64,
        /// What went wrong.
        source: EpisodeError,
    },
    /// The policy failed.
    #[error("seed {seed}, step {step}: policy failed: {source}")]
    Policy {
        /// The episode seed.
        seed: u64,
        /// The step at which it failed (0: while resetting).
        step: u32,
        /// What went wrong.
        source: PolicyError,
    },
    /// The policy returned an action that is not finite.
    #[error("seed {seed}, step {step}: policy returned an invalid action {action:?}")]
    InvalidAction {
        /// The episode seed.
        seed: u64,
        /// The step.
        step: u32,
        /// The action.
        action: Action,
    },
}

/// One logged step (SPEC "Data log").
#[derive(Clone, Debug, PartialEq)]
pub struct StepLog {
    /// Step number, from 1.
    pub step: u32,
    /// Pose before the action.
    pub pose: Pose,
    /// Laser readings before the action, px.
    pub readings: Vec<f64>,
    /// Bearing to the goal theta, degrees.
    pub bearing_deg: f64,
    /// Distance to the goal D, px.
    pub distance_px: f64,
    /// Goal direction relative to the heading, degrees.
    pub direction_deg: f64,
    /// The action taken.
    pub action: Action,
    /// Whether it collided.
    pub collided: bool,
    /// Its reward.
    pub reward: f64,
}

/// What to keep of each episode beyond its figures.
#[derive(Clone, Copy, Debug, Default)]
pub struct Recording {
    /// The poses (for trajectory pictures).
    pub trajectory: bool,
    /// Every step (for data logs).
    pub steps: bool,
}

/// One finished episode.
#[derive(Clone, Debug)]
pub struct EpisodeRecord {
    /// The seed.
    pub seed: u64,
    /// How it ended.
    pub outcome: Outcome,
    /// Why the policy gave up, for [`Outcome::Stuck`].
    pub reason: Option<String>,
    /// Steps taken.
    pub steps: u32,
    /// Steps that collided.
    pub collisions: u32,
    /// Distance driven, px.
    pub path_length_px: f64,
    /// Shortest collision-free path length from start to within epsilon of the goal, px (`None`
    /// when the goal is unreachable).
    pub shortest_px: Option<f64>,
    /// Success weighted by path length: `shortest / max(shortest, driven)` on success, else 0.
    pub spl: f64,
    /// Summed reward.
    pub total_reward: f64,
    /// Wall time of the episode (setup, planning and stepping), seconds.
    pub wall_time_s: f64,
    /// Start pose.
    pub start: Pose,
    /// Goal.
    pub goal: Point,
    /// Final pose.
    pub end: Pose,
    /// Final laser readings, px.
    pub last_readings: Vec<f64>,
    /// Poses from start to end, when recorded.
    pub trajectory: Vec<Pose>,
    /// Steps, when recorded.
    pub step_log: Vec<StepLog>,
    /// The world the episode ran in; dropped by [`EpisodeRecord::strip`], since a per-seed world
    /// holds its scene and grids.
    pub world: Option<Arc<World>>,
}

impl EpisodeRecord {
    /// Drops the recorded trajectory, steps and world (after they have been written out).
    pub fn strip(&mut self) {
        self.trajectory = Vec::new();
        self.step_log = Vec::new();
        self.world = None;
    }
}

/// A batch evaluation's setting.
pub struct Evaluator {
    config: ValidConfig,
    scenes: Scenes,
    shared: Option<Arc<World>>,
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

impl Evaluator {
    /// An evaluator of episodes in `scenes` under `config`.
    pub fn new(config: ValidConfig, scenes: Scenes) -> Self {
        let shared = match &scenes {
            Scenes::MazePerSeed => None,
            Scenes::Maze(seed) => Some(Arc::new(World::maze(config.clone(), *seed))),
            Scenes::Fixed(scene) => Some(Arc::new(World::new(config.clone(), scene.clone()))),
        };
        Self {
            config,
            scenes,
            shared,
        }
    }

    /// The configuration.
    pub fn config(&self) -> &ValidConfig {
        &self.config
    }

    /// Where episodes take place.
    pub fn scenes(&self) -> &Scenes {
        &self.scenes
    }

    /// The world of episode `seed`.
    pub fn world(&self, seed: u64) -> Arc<World> {
        match &self.shared {
            Some(w) => w.clone(),
            None => Arc::new(World::maze(self.config.clone(), seed)),
        }
    }

    /// Runs the episode of `seed` with `policy`.
    pub fn run_episode(
        &self,
        policy: &mut dyn Policy,
        seed: u64,
        recording: Recording,
    ) -> Result<EpisodeRecord, RunError> {
        let clock = Instant::now();
        let world = self.world(seed);
        let mut episode = world
            .episode(seed)
            .map_err(|source| RunError::Episode { seed, source })?;
        policy
            .reset(&world, &episode)
            .map_err(|source| RunError::Policy {
                seed,
                step: 0,
                source,
            })?;
        let mut trajectory = Vec::new();
        let mut step_log = Vec::new();
        if recording.trajectory {
            trajectory.push(episode.pose());
        }
        let mut reason = None;
        while !episode.status().is_done() {
            let step = episode.steps() + 1;
            let decision =
                policy
                    .act(&episode)
                    .map_err(|source| RunError::Policy { seed, step, source })?;
            let action = match decision {
                Decision::Act(a) => a,
                Decision::GiveUp(why) => {
                    reason = Some(why);
                    break;
                }
            };
            if let Action::Continuous { v, w_deg } = action {
                if !v.is_finite() || !w_deg.is_finite() {
                    return Err(RunError::InvalidAction { seed, step, action });
                }
            }
            let before = recording.steps.then(|| {
                (
                    episode.pose(),
                    episode.readings().to_vec(),
                    episode.bearing_deg(),
                    episode.distance_px(),
                    episode.direction_deg(),
                )
            });
            let r = episode.step(action);
            let (collided, reward, pose) = (r.collided, r.reward, r.pose);
            if let Some((pose, readings, bearing_deg, distance_px, direction_deg)) = before {
                step_log.push(StepLog {
                    step,
                    pose,
                    readings,
                    bearing_deg,
                    distance_px,
                    direction_deg,
                    action,
                    collided,
                    reward,
                });
            }
            if recording.trajectory {
                trajectory.push(pose);
            }
        }
        let outcome = match episode.status() {
            Status::Success => Outcome::Success,
            Status::TimeOut => Outcome::Timeout,
            Status::Collision => Outcome::Collision,
            Status::RewardMin => Outcome::RewardMin,
            Status::Running => Outcome::Stuck,
        };
        // The shortest path is only needed to score a success, and costs more than a random
        // policy's whole episode, so failures are not charged for it.
        let tolerance = self.config.episode.goal_tolerance_px;
        let shortest_px = (outcome == Outcome::Success)
            .then(|| world.shortest_path_px(episode.start().position(), episode.goal()))
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
            step_log,
            world: Some(world),
        })
    }

    /// Runs `seeds` on `threads` threads (0: all cores) with policies from `factory`. Each record
    /// goes to `on_record` as soon as its episode ends (from a worker thread), then is stripped of
    /// its trajectory and steps. Setting `cancel` stops the run between episodes.
    pub fn run(
        &self,
        factory: &dyn PolicyFactory,
        seeds: &[u64],
        threads: usize,
        recording: Recording,
        cancel: &AtomicBool,
        on_record: &(dyn Fn(&EpisodeRecord) + Sync),
    ) -> Result<RunResult, PolicyError> {
        let clock = Instant::now();
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .map_err(|e| PolicyError::Failed(format!("cannot start worker threads: {e}")))?;
        let first_policy_error: Mutex<Option<PolicyError>> = Mutex::new(None);
        // Policies are made at most once per worker and handed from episode to episode, so a
        // costly policy (a Python process, a loaded network) is set up `threads` times, not once
        // per seed.
        let idle: Mutex<Vec<Box<dyn Policy>>> = Mutex::new(Vec::new());
        let results: Vec<Option<Result<EpisodeRecord, RunError>>> = pool.install(|| {
            seeds
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
                    let result =
                        self.run_episode(policy.as_mut(), seed, recording)
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

/// The name of a discrete action, or `v=..;w=..` for a continuous one.
pub fn action_name(action: &Action) -> String {
    match action {
        Action::Discrete(a) => a.name().to_string(),
        Action::Continuous { v, w_deg } => format!("v={v};w={w_deg}"),
    }
}

/// The discrete action of an [`Action`], if it is one.
pub fn discrete(action: &Action) -> Option<DiscreteAction> {
    match action {
        Action::Discrete(a) => Some(*a),
        Action::Continuous { .. } => None,
    }
}
