//! A batch: N episodes stepped side by side, across cores, each starting its next episode when
//! one ends. Observations live in one flat row-major buffer (`N x observation_size`) and each
//! environment's step in one small record, so a binding hands them over as arrays with no object
//! per environment. The vectorised Python environment and DQN's actors are both this type.
//!
//! Every environment's episodes and random numbers follow from their seeds, and seeds are handed
//! out in environment order, so a batch steps the same bits on any number of threads.

use crate::geometry::Point;
use crate::run::shaping::Shaper;
use crate::run::RunError;
use crate::sim::{stream, Action, Episode, Pose, Rng, Status, Stream, Worlds, PREFETCH_STAGES};
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, PoisonError};
use std::time::Duration;

/// Environments per parallel task: enough work to outweigh handing it to a thread.
const MIN_PER_TASK: usize = 16;

/// Most environments in one parallel task (a run stepped in order, see [`Lanes::for_each`]).
const RUN: usize = 64;

/// Longest the calling thread waits awake for the pool's last runs (a run of [`RUN`]
/// environments takes about 20 us).
const SPIN: Duration = Duration::from_micros(100);

/// Longest the pool's threads stay awake after a step for the next one, before rayon lets them
/// sleep: a caller stepping in a loop (Python's glue between two steps of 1024 environments is
/// tens of microseconds) then finds them awake, instead of waking them with a system call and
/// stepping alone until they run again (tens of microseconds on a virtual machine). They stay
/// only when the caller came back within this time of its last step, reset or restart, so a
/// caller that works longer between calls (training a network, say) does not have them spin
/// beside it in vain.
const LINGER: Duration = Duration::from_micros(200);

/// When an environment whose episode ended starts the next one.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Autoreset {
    /// On the following step, which ignores its action and reports the new episode's start with
    /// reward 0 (Gymnasium's next-step autoreset).
    NextStep,
    /// At once, in the step that ended it: the buffer shows the new episode's first observation
    /// and [`Batch::final_observations`] the last one of the episode that ended.
    SameStep,
    /// Never: the caller restarts ended environments with [`Batch::restart`]; stepping one
    /// before that is refused ([`RunError::Ended`]).
    Disabled,
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
    /// Threads that step the environments, the calling thread among them (0: `RAYON_NUM_THREADS`
    /// where set, else all cores).
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
    /// The episode's (current) goal.
    pub goal: Point,
    /// Steps taken in the episode so far.
    pub steps: u32,
    /// Steps of the episode so far that collided with a wall or a static obstacle.
    pub collisions: u32,
    /// Steps of the episode so far with contact between the robot and a moving obstacle (`None`
    /// when the scene has none).
    pub dynamic_collisions: Option<u32>,
    /// Summed reward of the episode so far, as given (with `reward.shaping`, the shaped one).
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
            goal: episode.goal(),
            steps: episode.steps(),
            collisions: episode.collisions(),
            dynamic_collisions: episode.dynamic_metrics().map(|m| m.collisions),
            total_reward: episode.total_reward(),
            reset: false,
        }
    }

    /// The record of `episode` just started: what a reset reports.
    pub fn start(episode: &Episode) -> Self {
        Self {
            reset: true,
            ..Self::of(episode, None, 0.0, false)
        }
    }
}

/// One environment: its episode, the random stream a policy may draw from, and the shaping of
/// its reward when the configuration asks for it.
struct Env {
    episode: Option<Episode>,
    rng: Rng,
    next_seed: u64,
    shaper: Option<Shaper>,
}

/// N environments stepped together.
pub struct Batch {
    worlds: Worlds,
    options: BatchOptions,
    lanes: Lanes,
    next_seed: u64,
}

/// A run of environments with their observation rows, final-observation rows and step records.
struct Run<'a> {
    envs: &'a mut [Env],
    obs: &'a mut [f32],
    last: &'a mut [f32],
    out: &'a mut [EnvStep],
}

/// The environments and their rows in the flat buffers, apart from what a step only reads.
struct Lanes {
    /// The threads that step beside the calling thread (`None`: it steps alone).
    pool: Option<rayon::ThreadPool>,
    /// Whether the calling thread may wait awake for the pool's last runs: not when there are
    /// more threads than cores, where the thread it waits for may not be running.
    spin: bool,
    /// How many steps (or restarts) have begun on the pool: a pool thread lingering after one
    /// (see [`LINGER`]) stops as soon as the next begins.
    begun: Arc<AtomicU64>,
    /// When the caller's last step, reset or restart ended.
    ended: Option<std::time::Instant>,
    /// Whether the caller came back within [`LINGER`] of that: the pool's threads linger after
    /// this call's runs only then.
    quick: bool,
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
        // The calling thread steps too, so the pool holds one thread fewer than asked for. All
        // cores means rayon's own default: `RAYON_NUM_THREADS` where set, else every core.
        let cores = std::thread::available_parallelism().map_or(1, usize::from);
        let threads = match options.threads {
            0 => std::env::var("RAYON_NUM_THREADS")
                .ok()
                .and_then(|v| v.trim().parse::<usize>().ok())
                .filter(|&t| t > 0)
                .unwrap_or(cores),
            t => t,
        };
        let pool = (threads > 1)
            .then(|| {
                rayon::ThreadPoolBuilder::new()
                    .num_threads(threads - 1)
                    .build()
                    .map_err(|e| RunError::Threads(e.to_string()))
            })
            .transpose()?;
        let observation_size = worlds.config().observation_size();
        Ok(Self {
            worlds,
            options: BatchOptions { envs: n, ..options },
            lanes: Lanes {
                pool,
                spin: threads <= cores,
                begun: Arc::new(AtomicU64::new(0)),
                ended: None,
                quick: false,
                envs: (0..n)
                    .map(|_| Env {
                        episode: None,
                        rng: stream(0, Stream::Policy),
                        next_seed: 0,
                        shaper: None,
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
        self.call(|batch| batch.reset_all(seed))
    }

    /// Runs `f`, one of the caller's calls (step, reset, restart), noting when the caller came
    /// and went: whether the pool's threads linger after its runs follows from that (see
    /// [`LINGER`]).
    fn call<T>(&mut self, f: impl FnOnce(&mut Self) -> T) -> T {
        self.lanes.arrive();
        let result = f(self);
        self.lanes.ended = Some(std::time::Instant::now());
        result
    }

    /// [`Batch::reset`] between the caller's coming and going.
    fn reset_all(&mut self, seed: u64) -> Result<(), RunError> {
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

    /// Starts afresh the environments `which` selects (one flag per environment): each with its
    /// seed from `seeds` (one per environment) when given, else with its next one (the seed an
    /// automatic reset would have given it). The others are left as they are. An environment's
    /// later episodes follow from the seed it starts with, in the batch's seed order.
    pub fn restart(&mut self, which: &[bool], seeds: &[Option<u64>]) -> Result<(), RunError> {
        self.call(|batch| batch.restart_some(which, seeds))
    }

    /// [`Batch::restart`] between the caller's coming and going.
    fn restart_some(&mut self, which: &[bool], seeds: &[Option<u64>]) -> Result<(), RunError> {
        let n = self.lanes.envs.len();
        for (what, given) in [("reset flags", which.len()), ("seeds", seeds.len())] {
            if given != n {
                return Err(RunError::Count {
                    what,
                    given,
                    envs: n,
                });
            }
        }
        let stride = self.stride();
        let mut next = self.next_seed;
        for ((env, &on), &seed) in self.lanes.envs.iter_mut().zip(which).zip(seeds) {
            if !on {
                continue;
            }
            match (seed, stride) {
                (Some(s), _) => env.next_seed = s,
                (None, Some(_)) => {}
                (None, None) => {
                    env.next_seed = next;
                    next = next.wrapping_add(1);
                }
            }
        }
        self.next_seed = next;
        let worlds = &self.worlds;
        self.lanes.for_each(|i, env, obs, _, out| {
            if which[i] {
                Self::start(worlds, stride, env, obs, out)
            } else {
                Ok(())
            }
        })
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
        self.call(|batch| batch.step_all(choose))
    }

    /// [`Batch::step`] between the caller's coming and going (it may run the environments more
    /// than once: to start missing episodes, to step, to restart ended ones).
    fn step_all(
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
        let autoreset = self.options.autoreset;
        if autoreset == Autoreset::Disabled {
            let ended = self.lanes.envs.iter().position(|e| {
                e.episode
                    .as_ref()
                    .is_some_and(|episode| episode.status().is_done())
            });
            if let Some(env) = ended {
                return Err(RunError::Ended { env });
            }
        }
        let (worlds, stride) = (&self.worlds, self.stride());
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
            *out = match env.shaper.as_mut() {
                Some(shaper) => {
                    let shaped = shaper.step(episode, reward);
                    EnvStep {
                        total_reward: shaper.total(),
                        ..EnvStep::of(episode, Some(action), shaped, collided)
                    }
                }
                None => EnvStep::of(episode, Some(action), reward, collided),
            };
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
        let world = worlds.world(seed);
        let episode = world
            .episode(seed)
            .map_err(|source| RunError::Episode { seed, source })?;
        obs.copy_from_slice(episode.observation());
        *out = EnvStep::start(&episode);
        env.shaper = Shaper::start(world, &episode);
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

    /// How the batch runs.
    pub fn options(&self) -> &BatchOptions {
        &self.options
    }

    /// The worlds episodes run in.
    pub fn worlds(&self) -> &Worlds {
        &self.worlds
    }
}

impl Drop for Lanes {
    /// Ends a pool thread's lingering (see [`LINGER`]) at once.
    fn drop(&mut self) {
        self.begun.fetch_add(1, Ordering::Release);
    }
}

impl Lanes {
    /// Notes whether the caller came back within [`LINGER`] of its last call's end.
    fn arrive(&mut self) {
        self.quick = self.ended.is_some_and(|t| t.elapsed() < LINGER);
    }

    /// Runs `f` on every environment with its index, observation row, final-observation row and
    /// step record, in runs of [`MIN_PER_TASK`] to [`RUN`] environments: the calling thread
    /// takes runs one after another, and so do the pool's threads once they wake (without a
    /// pool, or for a small batch, too little work to wake another thread for, the calling
    /// thread steps every environment as one run). The calling thread starts
    /// at once instead of waiting for the pool to wake and then for it to finish. The first
    /// error in environment order wins.
    fn for_each(
        &mut self,
        f: impl Fn(usize, &mut Env, &mut [f32], &mut [f32], &mut EnvStep) -> Result<(), RunError> + Sync,
    ) -> Result<(), RunError> {
        let d = self.observation_size;
        let n = self.envs.len();
        let Some(pool) = self.pool.as_ref().filter(|_| n > MIN_PER_TASK) else {
            let all = Run {
                envs: &mut self.envs,
                obs: &mut self.observations,
                last: &mut self.final_observations,
                out: &mut self.steps,
            };
            let first = all.step(0, d, &f);
            return first.map_or(Ok(()), |(_, e)| Err(e));
        };
        let helpers = pool.current_num_threads();
        // Runs short enough that every thread gets a few, long enough that the environments
        // asked for ahead at a run's start are few.
        let len = (n / (4 * (helpers + 1))).clamp(MIN_PER_TASK, RUN);
        let runs: Vec<(usize, Run<'_>)> = self
            .envs
            .chunks_mut(len)
            .zip(self.observations.chunks_mut(len * d))
            .zip(self.final_observations.chunks_mut(len * d))
            .zip(self.steps.chunks_mut(len))
            .map(|(((envs, obs), last), out)| Run {
                envs,
                obs,
                last,
                out,
            })
            .enumerate()
            .collect();
        let total = runs.len();
        let queue = Mutex::new(runs.into_iter());
        let done = AtomicUsize::new(0);
        let first: Mutex<Option<(usize, RunError)>> = Mutex::new(None);
        let work = || loop {
            let next = queue.lock().unwrap_or_else(PoisonError::into_inner).next();
            let Some((r, run)) = next else {
                return;
            };
            let failed = run.step(r * len, d, &f);
            if let Some((i, e)) = failed {
                let mut slot = first.lock().unwrap_or_else(PoisonError::into_inner);
                if slot.as_ref().is_none_or(|(j, _)| i < *j) {
                    *slot = Some((i, e));
                }
            }
            done.fetch_add(1, Ordering::Release);
        };
        let (spin, begun) = (self.spin, &self.begun);
        let quick = self.quick;
        pool.in_place_scope(|s| {
            // No more helpers than runs beyond the caller's first: the scope waits for each.
            for _ in 0..helpers.min(total.saturating_sub(1)) {
                s.spawn(|_| work());
            }
            // Ends the threads' lingering after the last step: they take up these runs at once.
            begun.fetch_add(1, Ordering::Release);
            work();
            if !spin {
                return;
            }
            // The runs left are under way on the pool: wait for them awake, for at most
            // [`SPIN`] (a few runs' time), rather than sleep and be woken (tens of microseconds
            // on a virtual machine).
            let clock = std::time::Instant::now();
            while done.load(Ordering::Acquire) < total && clock.elapsed() < SPIN {
                std::hint::spin_loop();
            }
        });
        if spin && quick {
            // Keeps the pool's threads awake for the next step, for at most [`LINGER`].
            let step = begun.load(Ordering::Acquire);
            for _ in 0..helpers {
                let begun = Arc::clone(begun);
                pool.spawn(move || {
                    let clock = std::time::Instant::now();
                    while begun.load(Ordering::Acquire) == step && clock.elapsed() < LINGER {
                        std::hint::spin_loop();
                    }
                });
            }
        }
        let first = first.into_inner().unwrap_or_else(PoisonError::into_inner);
        first.map_or(Ok(()), |(_, e)| Err(e))
    }
}

impl Run<'_> {
    /// [`Lanes::for_each`] over this run of environments (from environment `base`, `d` values
    /// an observation row), in order, asking for each environment's memory a few environments
    /// ahead (see [`Episode::prefetch`]): a thousand scenes do not fit the caches, and a step
    /// would otherwise wait on each link of the chain from the episode to the boxes near its
    /// robot in turn.
    fn step(
        self,
        base: usize,
        d: usize,
        f: &(impl Fn(usize, &mut Env, &mut [f32], &mut [f32], &mut EnvStep) -> Result<(), RunError>
              + Sync),
    ) -> Option<(usize, RunError)> {
        let Self {
            envs,
            obs,
            last,
            out,
        } = self;
        let mut first = None;
        for j in 0..envs.len() {
            for stage in 0..PREFETCH_STAGES {
                if let Some(e) = envs
                    .get(j + PREFETCH_STAGES - stage)
                    .and_then(|e| e.episode.as_ref())
                {
                    e.prefetch(stage);
                }
            }
            let row = j * d..(j + 1) * d;
            let result = f(
                base + j,
                &mut envs[j],
                &mut obs[row.clone()],
                &mut last[row],
                &mut out[j],
            );
            if let (Err(e), None) = (result, &first) {
                first = Some((base + j, e));
            }
        }
        first
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::SimConfig;
    use crate::sim::{DiscreteAction, Scenes};

    fn batch(envs: usize, threads: usize, autoreset: Autoreset) -> Batch {
        let mut c = SimConfig::default();
        c.episode.max_steps = 30;
        let worlds = Worlds::new(c.validate().unwrap(), Scenes::MazePerSeed);
        let options = BatchOptions {
            envs,
            threads,
            autoreset,
            seed_order: SeedOrder::Strided,
        };
        Batch::new(worlds, options).unwrap()
    }

    fn actions(n: usize, t: usize) -> Vec<Action> {
        (0..n)
            .map(|i| DiscreteAction::from_index((i + t) % 3).unwrap().into())
            .collect()
    }

    /// Every (seed, steps, reward, status) a batch reports over `steps` steps of a fixed pattern,
    /// restarting ended environments by hand when automatic resets are disabled.
    fn trace(b: &mut Batch, steps: usize) -> Vec<(u64, u32, u64, Status, bool)> {
        let n = b.len();
        let mut out = Vec::new();
        for t in 0..steps {
            b.step_actions(&actions(n, t)).unwrap();
            out.extend(
                b.steps()
                    .iter()
                    .map(|s| (s.seed, s.steps, s.reward.to_bits(), s.status, s.reset)),
            );
            if b.options.autoreset == Autoreset::Disabled {
                let ended: Vec<bool> = b.steps().iter().map(|s| s.status.is_done()).collect();
                if ended.contains(&true) {
                    b.restart(&ended, &vec![None; n]).unwrap();
                }
            }
        }
        out
    }

    #[test]
    fn restarting_by_hand_plays_the_episodes_same_step_autoreset_plays() {
        let mut same = batch(5, 1, Autoreset::SameStep);
        let mut off = batch(5, 1, Autoreset::Disabled);
        same.reset(7).unwrap();
        off.reset(7).unwrap();
        let (a, b) = (trace(&mut same, 200), trace(&mut off, 200));
        assert!(a.iter().any(|s| s.3.is_done()), "some episode ends");
        assert_eq!(a, b);
        assert_eq!(same.observations(), off.observations());
    }

    #[test]
    fn stepping_an_ended_environment_without_autoreset_is_refused_and_steps_nothing() {
        let mut b = batch(3, 1, Autoreset::Disabled);
        b.reset(0).unwrap();
        let mut t = 0;
        while !b.steps().iter().any(|s| s.status.is_done()) {
            b.step_actions(&actions(3, t)).unwrap();
            t += 1;
        }
        let env = b.steps().iter().position(|s| s.status.is_done()).unwrap();
        let before = b.steps().to_vec();
        assert_eq!(b.step_actions(&actions(3, t)), Err(RunError::Ended { env }));
        assert_eq!(b.steps(), &before[..]);
    }

    #[test]
    fn restart_gives_chosen_environments_their_seeds_and_leaves_the_others() {
        let mut b = batch(4, 1, Autoreset::NextStep);
        b.reset(100).unwrap();
        b.step_actions(&actions(4, 0)).unwrap();
        let kept = b.steps()[1];
        b.restart(&[true, false, true, false], &[Some(55), None, None, None])
            .unwrap();
        let s = b.steps();
        assert_eq!((s[0].seed, s[0].reset), (55, true));
        assert_eq!(s[1], kept);
        // Environment 2 had seed 102: its next one is 4 later.
        assert_eq!((s[2].seed, s[2].reset), (106, true));
        assert_eq!(b.episode(0).unwrap().steps(), 0);
        assert_eq!(b.episode(1).unwrap().steps(), 1);
        assert_eq!(
            b.restart(&[true; 3], &[None; 4]),
            Err(RunError::Count {
                what: "reset flags",
                given: 3,
                envs: 4
            })
        );
    }

    #[test]
    fn every_environment_is_visited_once_and_the_least_failing_index_wins() {
        // Threads 0 (all cores) to 3; 40 environments make three runs, fewer than the threads.
        for (envs, threads) in [(300, 1), (300, 2), (300, 3), (300, 0), (40, 3)] {
            let mut b = batch(envs, threads, Autoreset::NextStep);
            let visits: Vec<std::sync::atomic::AtomicUsize> =
                (0..envs).map(|_| Default::default()).collect();
            let result = b.lanes.for_each(|i, _, obs, last, _| {
                assert_eq!((obs.len(), last.len()), (18, 18));
                visits[i].fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                // Failures in several runs, the least of them not in the first run.
                match i % 37 == 5 && i > 50 {
                    true => Err(RunError::Ended { env: i }),
                    false => Ok(()),
                }
            });
            let expected = if envs > 79 {
                Err(RunError::Ended { env: 79 })
            } else {
                Ok(())
            };
            assert_eq!(result, expected, "{envs} environments, {threads} threads");
            assert!(visits
                .iter()
                .all(|v| v.load(std::sync::atomic::Ordering::Relaxed) == 1));
        }
    }

    #[test]
    fn a_batch_steps_the_same_bits_on_one_and_two_threads() {
        let run = |threads| {
            let mut b = batch(40, threads, Autoreset::SameStep);
            b.reset(3).unwrap();
            let t = trace(&mut b, 60);
            (t, b.observations().to_vec())
        };
        assert_eq!(run(1), run(2));
    }
}
