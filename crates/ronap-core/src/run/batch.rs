//! A batch: N episodes stepped side by side, across cores, each starting its next episode when
//! one ends. Observations live in one flat row-major buffer (`N x observation_size`) and each
//! environment's step in one small record, so a binding hands them over as arrays with no object
//! per environment. The vectorised Python environment and DQN's actors are both this type.
//!
//! Every environment's episodes and random numbers follow from their seeds, and seeds are handed
//! out in environment order, so a batch steps the same bits on any number of threads.

use crate::run::RunError;
use crate::sim::episode::{Episode, Status};
use crate::sim::rng::{stream, Rng, Stream};
use crate::sim::robot::{Action, Pose};
use crate::sim::world::Worlds;
use rayon::prelude::*;

/// Environments per parallel task: enough work to outweigh handing it to a thread.
const MIN_PER_TASK: usize = 16;

/// When an environment whose episode ended starts the next one.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Autoreset {
    /// On the following step, which ignores its action and reports the new episode's start with
    /// reward 0 (Gymnasium's next-step autoreset).
    NextStep,
    /// At once, in the step that ended it: the buffer shows the new episode's first observation
    /// and [`Batch::final_observations`] the last one of the episode that ended.
    SameStep,
}

/// Which seed an environment's next episode gets, in a batch reset with seed `base` over `n`
/// environments.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SeedOrder {
    /// Environment `i`'s `k`-th episode has seed `base + i + k n`.
    Strided,
    /// Episodes take `base, base + 1, ...` in the order they start (environment order within a
    /// step).
    InOrder,
}

/// How a batch runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BatchOptions {
    /// Number of environments (at least 1).
    pub envs: usize,
    /// Worker threads (0: all cores).
    pub threads: usize,
    /// When finished episodes restart.
    pub autoreset: Autoreset,
    /// Which seeds new episodes get.
    pub seed_order: SeedOrder,
}

/// One environment's latest reset or step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct EnvStep {
    /// The seed of the episode the step belongs to (the one that ended, for a step that ended it).
    pub seed: u64,
    /// The action taken (`None` for a reset).
    pub action: Option<Action>,
    /// The step's reward (0 for a reset).
    pub reward: f64,
    /// The episode's status after the step.
    pub status: Status,
    /// Whether the step's motion would have touched an obstacle.
    pub collided: bool,
    /// Distance to the goal after the step, px.
    pub distance_px: f64,
    /// Pose after the step.
    pub pose: Pose,
    /// Steps taken in the episode so far.
    pub steps: u32,
    /// Summed reward of the episode so far.
    pub total_reward: f64,
    /// Whether this was a reset: the environment started a new episode and did not step.
    pub reset: bool,
}

impl EnvStep {
    fn of(episode: &Episode, action: Option<Action>, reward: f64, collided: bool) -> Self {
        Self {
            seed: episode.seed(),
            action,
            reward,
            status: episode.status(),
            collided,
            distance_px: episode.distance_px(),
            pose: episode.pose(),
            steps: episode.steps(),
            total_reward: episode.total_reward(),
            reset: false,
        }
    }

    fn start(episode: &Episode) -> Self {
        Self {
            reset: true,
            ..Self::of(episode, None, 0.0, false)
        }
    }
}

/// One environment: its episode and the random stream a policy may draw from.
struct Env {
    episode: Option<Episode>,
    rng: Rng,
    next_seed: u64,
}

/// N environments stepped together.
pub struct Batch {
    worlds: Worlds,
    options: BatchOptions,
    lanes: Lanes,
    next_seed: u64,
}

/// One environment with its observation row, final-observation row and step record.
type Lane<'a> = (
    ((&'a mut Env, &'a mut [f32]), &'a mut [f32]),
    &'a mut EnvStep,
);

/// The environments and their rows in the flat buffers, apart from what a step only reads.
struct Lanes {
    pool: rayon::ThreadPool,
    envs: Vec<Env>,
    observation_size: usize,
    observations: Vec<f32>,
    final_observations: Vec<f32>,
    steps: Vec<EnvStep>,
}

impl Batch {
    /// A batch of `options.envs` environments in `worlds`, none started yet.
    pub fn new(worlds: Worlds, options: BatchOptions) -> Result<Self, RunError> {
        let n = options.envs.max(1);
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(options.threads)
            .build()
            .map_err(|e| RunError::Threads(e.to_string()))?;
        let observation_size = worlds.config().observation_size();
        Ok(Self {
            worlds,
            options: BatchOptions { envs: n, ..options },
            lanes: Lanes {
                pool,
                envs: (0..n)
                    .map(|_| Env {
                        episode: None,
                        rng: stream(0, Stream::Policy),
                        next_seed: 0,
                    })
                    .collect(),
                observation_size,
                observations: vec![0.0; n * observation_size],
                final_observations: vec![0.0; n * observation_size],
                steps: vec![EnvStep::default(); n],
            },
            next_seed: 0,
        })
    }

    /// Starts every environment afresh: environment `i` gets seed `seed + i`.
    pub fn reset(&mut self, seed: u64) -> Result<(), RunError> {
        let n = self.lanes.envs.len() as u64;
        for (i, env) in self.lanes.envs.iter_mut().enumerate() {
            env.next_seed = seed.wrapping_add(i as u64);
            env.episode = None;
        }
        self.next_seed = seed.wrapping_add(n);
        let (worlds, stride) = (&self.worlds, self.stride());
        self.lanes
            .for_each(|_, env, obs, _, out| Self::start(worlds, stride, env, obs, out))
    }

    /// How far apart an environment's episode seeds are: `n` for [`SeedOrder::Strided`].
    fn stride(&self) -> Option<u64> {
        (self.options.seed_order == SeedOrder::Strided).then_some(self.lanes.envs.len() as u64)
    }

    /// Steps every environment: `choose(i, episode, rng)` gives environment `i`'s action for its
    /// episode's current state, drawing any randomness from `rng` (the episode seed's policy
    /// stream). Environments waiting for a next-step reset start their next episode instead.
    pub fn step(
        &mut self,
        choose: &(dyn Fn(usize, &Episode, &mut Rng) -> Action + Sync),
    ) -> Result<(), RunError> {
        if self.lanes.envs.iter().any(|e| e.episode.is_none()) {
            // Nothing started yet (no reset): start what is missing, as a reset with the seeds
            // the environments hold.
            let (worlds, stride) = (&self.worlds, self.stride());
            self.lanes
                .for_each(|_, env, obs, _, out| match env.episode {
                    None => Self::start(worlds, stride, env, obs, out),
                    Some(_) => Ok(()),
                })?;
        }
        let (worlds, stride) = (&self.worlds, self.stride());
        let autoreset = self.options.autoreset;
        self.lanes.for_each(|i, env, obs, last, out| {
            let Some(episode) = env.episode.as_mut() else {
                return Ok(());
            };
            if autoreset == Autoreset::NextStep && episode.status().is_done() {
                return Self::start(worlds, stride, env, obs, out);
            }
            let action = choose(i, episode, &mut env.rng);
            let r = episode.step(action);
            let (reward, collided) = (r.reward, r.collided);
            obs.copy_from_slice(r.observation);
            *out = EnvStep::of(episode, Some(action), reward, collided);
            if autoreset == Autoreset::SameStep && out.status.is_done() {
                last.copy_from_slice(obs);
                if stride.is_some() {
                    Self::start(worlds, stride, env, obs, &mut EnvStep::default())?;
                }
            }
            Ok(())
        })?;
        if autoreset == Autoreset::SameStep && stride.is_none() {
            self.restart_in_order()?;
        }
        Ok(())
    }

    /// Steps every environment with its action from `actions` (one per environment).
    pub fn step_actions(&mut self, actions: &[Action]) -> Result<(), RunError> {
        if actions.len() != self.lanes.envs.len() {
            return Err(RunError::ActionCount {
                given: actions.len(),
                envs: self.lanes.envs.len(),
            });
        }
        self.step(&|i, _, _| actions[i])
    }

    /// Starts the episodes that ended in this step, seeds given out in environment order.
    fn restart_in_order(&mut self) -> Result<(), RunError> {
        let mut next = self.next_seed;
        let mut restart = vec![false; self.lanes.envs.len()];
        let lanes = &mut self.lanes;
        for ((env, out), flag) in lanes.envs.iter_mut().zip(&lanes.steps).zip(&mut restart) {
            if out.status.is_done() && !out.reset {
                env.next_seed = next;
                next = next.wrapping_add(1);
                *flag = true;
            }
        }
        self.next_seed = next;
        let worlds = &self.worlds;
        self.lanes.for_each(|i, env, obs, _, _| {
            if restart[i] {
                Self::start(worlds, None, env, obs, &mut EnvStep::default())
            } else {
                Ok(())
            }
        })
    }

    /// Starts `env`'s next episode into its observation row and step record; with a `stride`, the
    /// one after it will be `stride` seeds later.
    fn start(
        worlds: &Worlds,
        stride: Option<u64>,
        env: &mut Env,
        obs: &mut [f32],
        out: &mut EnvStep,
    ) -> Result<(), RunError> {
        let seed = env.next_seed;
        let episode = worlds
            .episode(seed)
            .map_err(|source| RunError::Episode { seed, source })?;
        obs.copy_from_slice(episode.observation());
        *out = EnvStep::start(&episode);
        env.rng = stream(seed, Stream::Policy);
        env.episode = Some(episode);
        if let Some(n) = stride {
            env.next_seed = seed.wrapping_add(n);
        }
        Ok(())
    }

    /// Observations, one row of [`Batch::observation_size`] values per environment.
    pub fn observations(&self) -> &[f32] {
        &self.lanes.observations
    }

    /// With [`Autoreset::SameStep`]: the last observation of each episode that ended in the
    /// latest step (the rows of the others are stale).
    pub fn final_observations(&self) -> &[f32] {
        &self.lanes.final_observations
    }

    /// Each environment's latest reset or step.
    pub fn steps(&self) -> &[EnvStep] {
        &self.lanes.steps
    }

    /// Environment `i`'s current episode, once started.
    pub fn episode(&self, i: usize) -> Option<&Episode> {
        self.lanes.envs.get(i).and_then(|e| e.episode.as_ref())
    }

    /// Number of environments.
    pub fn len(&self) -> usize {
        self.lanes.envs.len()
    }

    /// Whether the batch has no environments (never: it has at least one).
    pub fn is_empty(&self) -> bool {
        self.lanes.envs.is_empty()
    }

    /// Length of one observation.
    pub fn observation_size(&self) -> usize {
        self.lanes.observation_size
    }

    /// The worlds episodes run in.
    pub fn worlds(&self) -> &Worlds {
        &self.worlds
    }
}

impl Lanes {
    /// Runs `f` on every environment with its index, observation row, final-observation row and
    /// step record: on the calling thread for a small batch (too little work to wake another
    /// thread for), else on the pool. The first error in environment order wins.
    fn for_each(
        &mut self,
        f: impl Fn(usize, &mut Env, &mut [f32], &mut [f32], &mut EnvStep) -> Result<(), RunError> + Sync,
    ) -> Result<(), RunError> {
        let d = self.observation_size;
        let n = self.envs.len();
        let one = |(i, (((env, obs), last), out)): (usize, Lane<'_>)| f(i, env, obs, last, out);
        let results: Vec<Result<(), RunError>> = if n <= MIN_PER_TASK {
            self.envs
                .iter_mut()
                .zip(self.observations.chunks_mut(d))
                .zip(self.final_observations.chunks_mut(d))
                .zip(self.steps.iter_mut())
                .enumerate()
                .map(one)
                .collect()
        } else {
            self.pool.install(|| {
                self.envs
                    .par_iter_mut()
                    .zip(self.observations.par_chunks_mut(d))
                    .zip(self.final_observations.par_chunks_mut(d))
                    .zip(self.steps.par_iter_mut())
                    .enumerate()
                    .with_min_len(MIN_PER_TASK)
                    .map(one)
                    .collect()
            })
        };
        results.into_iter().collect()
    }
}
