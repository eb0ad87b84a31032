//! A batch: N environments stepped side by side, across cores, each starting its next episode
//! when one ends, in one of Gymnasium's three autoreset modes. One engine for the two kinds of
//! environment (its [`Lane`]): a lone robot's ([`Batch`], the vectorised Python environment and
//! DQN's actors) and a team's ([`TeamBatch`], the vectorised multi-robot environment). Both get
//! the same seeds, restarts, autoreset modes and threads from it.
//!
//! Observations live in one flat row-major buffer (`N x R x observation_size`: R rows an
//! environment, one for a lone robot, one per robot for a team) and each row's step in one small
//! record, so a binding hands them over as arrays with no object per environment.
//!
//! Every environment's episodes and random numbers follow from their seeds, and seeds are handed
//! out in environment order, so a batch steps the same bits on any number of threads.

mod lone;
mod team;

pub use lone::{Batch, EnvStep, Lone};
pub use team::{RobotStep, TeamBatch, Teams};

use crate::run::RunError;
use crate::sim::{Worlds, PREFETCH_STAGES};
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, PoisonError};
use std::time::Duration;

/// Rows (robots) per parallel task: enough work to outweigh handing it to a thread.
const MIN_PER_TASK: usize = 16;

/// Most rows in one parallel task (a run stepped in order, see [`Lanes::for_each`]).
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

/// What a batch steps in each environment: a lone robot's episode ([`Lone`]) or a team's
/// ([`Teams`]). The batch hands out their seeds, restarts them and spreads them over threads; a
/// kind starts an episode and says where it stands (its step is the kind's own method of
/// [`BatchOf`], with what the caller gives it).
pub trait Lane: Send + Sized {
    /// What a reset or step reports for each of an environment's rows.
    type Record: Copy + Default + Send + std::fmt::Debug;

    /// The environment before its first episode, in a batch of `worlds`.
    fn idle(worlds: &Worlds) -> Self;

    /// Rows an environment of `worlds` takes (its robots), and the values in a row.
    fn shape(worlds: &Worlds) -> (usize, usize);

    /// Starts the episode of `seed` in `worlds`, writing its observation rows and records.
    fn start(
        &mut self,
        worlds: &Worlds,
        seed: u64,
        obs: &mut [f32],
        out: &mut [Self::Record],
    ) -> Result<(), RunError>;

    /// Whether an episode has started.
    fn started(&self) -> bool;

    /// Whether its episode is over (every robot done).
    fn done(&self) -> bool;

    /// Asks for the memory the next step reads, stage by stage: a batch calls each stage a few
    /// environments ahead of the one it steps.
    fn prefetch(&self, _stage: usize) {}
}

/// One environment: its kind's state and where its next seed comes from.
struct Env<E> {
    lane: E,
    next_seed: u64,
    /// Its episode ended in the latest step (it was stepped, not started, in it).
    just_ended: bool,
    /// Its episode started in the latest call (a reset, a restart or an automatic reset).
    fresh: bool,
}

impl<E: Lane> Env<E> {
    /// Starts the next episode into its rows; with a `stride`, the one after it will be `stride`
    /// seeds later.
    fn start(
        &mut self,
        worlds: &Worlds,
        stride: Option<u64>,
        obs: &mut [f32],
        out: &mut [E::Record],
    ) -> Result<(), RunError> {
        let seed = self.next_seed;
        self.lane.start(worlds, seed, obs, out)?;
        self.fresh = true;
        if let Some(n) = stride {
            self.next_seed = seed.wrapping_add(n);
        }
        Ok(())
    }
}

/// N environments of kind `E` stepped together: a [`Batch`] of lone robots or a [`TeamBatch`].
pub struct BatchOf<E: Lane> {
    worlds: Worlds,
    options: BatchOptions,
    lanes: Lanes<E>,
    next_seed: u64,
}

/// A run of environments with their observation rows, final-observation rows and step records.
struct Run<'a, E: Lane> {
    envs: &'a mut [Env<E>],
    obs: &'a mut [f32],
    last: &'a mut [f32],
    out: &'a mut [E::Record],
}

/// The environments and their rows in the flat buffers, apart from what a step only reads.
struct Lanes<E: Lane> {
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
    envs: Vec<Env<E>>,
    /// Rows an environment takes.
    rows: usize,
    observation_size: usize,
    observations: Vec<f32>,
    final_observations: Vec<f32>,
    steps: Vec<E::Record>,
}

impl<E: Lane> BatchOf<E> {
    /// A batch of `options.envs` environments in `worlds`, none started yet (for a
    /// [`TeamBatch`], a configuration without `[[robots]]` makes each the lone robot's team of
    /// one).
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
        let (rows, observation_size) = E::shape(&worlds);
        Ok(Self {
            lanes: Lanes {
                pool,
                spin: threads <= cores,
                begun: Arc::new(AtomicU64::new(0)),
                ended: None,
                quick: false,
                envs: (0..n)
                    .map(|_| Env {
                        lane: E::idle(&worlds),
                        next_seed: 0,
                        just_ended: false,
                        fresh: false,
                    })
                    .collect(),
                rows,
                observation_size,
                observations: vec![0.0; n * rows * observation_size],
                final_observations: vec![0.0; n * rows * observation_size],
                steps: vec![E::Record::default(); n * rows],
            },
            worlds,
            options: BatchOptions { envs: n, ..options },
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

    /// [`BatchOf::reset`] between the caller's coming and going.
    fn reset_all(&mut self, seed: u64) -> Result<(), RunError> {
        let n = self.lanes.envs.len() as u64;
        for (i, env) in self.lanes.envs.iter_mut().enumerate() {
            env.next_seed = seed.wrapping_add(i as u64);
            env.lane = E::idle(&self.worlds);
            env.just_ended = false;
        }
        self.next_seed = seed.wrapping_add(n);
        let (worlds, stride) = (&self.worlds, self.stride());
        self.lanes
            .for_each(|_, env, obs, _, out| env.start(worlds, stride, obs, out))
    }

    /// Starts afresh the environments `which` selects (one flag per environment): each with its
    /// seed from `seeds` (one per environment) when given, else with its next one (the seed an
    /// automatic reset would have given it). The others are left as they are. An environment's
    /// later episodes follow from the seed it starts with, in the batch's seed order.
    pub fn restart(&mut self, which: &[bool], seeds: &[Option<u64>]) -> Result<(), RunError> {
        self.call(|batch| batch.restart_some(which, seeds))
    }

    /// [`BatchOf::restart`] between the caller's coming and going.
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
            env.fresh = false;
            if which[i] {
                env.just_ended = false;
                env.start(worlds, stride, obs, out)
            } else {
                Ok(())
            }
        })
    }

    /// How far apart an environment's episode seeds are: `n` for [`SeedOrder::Strided`].
    fn stride(&self) -> Option<u64> {
        (self.options.seed_order == SeedOrder::Strided).then_some(self.lanes.envs.len() as u64)
    }

    /// One step of every environment, `step(i, lane, obs, out)` stepping environment `i` (its
    /// observation rows and records) as its kind does (a step cannot fail), with the batch's
    /// autoreset around it:
    /// environments never started start first, and environments whose episode ended start their
    /// next one on the following step, in the same step or never, as the batch is set.
    fn step_each(
        &mut self,
        step: impl Fn(usize, &mut E, &mut [f32], &mut [E::Record]) + Sync,
    ) -> Result<(), RunError> {
        if self.lanes.envs.iter().any(|e| !e.lane.started()) {
            // Nothing started yet (no reset): start what is missing, as a reset with the seeds
            // the environments hold.
            let (worlds, stride) = (&self.worlds, self.stride());
            self.lanes
                .for_each(|_, env, obs, _, out| match env.lane.started() {
                    false => env.start(worlds, stride, obs, out),
                    true => Ok(()),
                })?;
        }
        let autoreset = self.options.autoreset;
        if autoreset == Autoreset::Disabled {
            if let Some(env) = self.lanes.envs.iter().position(|e| e.lane.done()) {
                return Err(RunError::Ended { env });
            }
        }
        let (worlds, stride, rows) = (&self.worlds, self.stride(), self.lanes.rows);
        self.lanes.for_each(|i, env, obs, last, out| {
            env.just_ended = false;
            env.fresh = false;
            if autoreset == Autoreset::NextStep && env.lane.done() {
                return env.start(worlds, stride, obs, out);
            }
            step(i, &mut env.lane, obs, out);
            let ended = env.lane.done();
            if autoreset == Autoreset::SameStep && ended {
                last.copy_from_slice(obs);
                if stride.is_some() {
                    // The records keep the step that ended the episode.
                    with_spare(rows, |spare| env.start(worlds, stride, obs, spare))?;
                }
            }
            env.just_ended = ended;
            Ok(())
        })?;
        if autoreset == Autoreset::SameStep && self.stride().is_none() {
            self.restart_in_order()?;
        }
        Ok(())
    }

    /// Starts the episodes that ended in this step, seeds given out in environment order.
    fn restart_in_order(&mut self) -> Result<(), RunError> {
        let mut next = self.next_seed;
        for env in self.lanes.envs.iter_mut().filter(|e| e.just_ended) {
            env.next_seed = next;
            next = next.wrapping_add(1);
        }
        self.next_seed = next;
        let (worlds, rows) = (&self.worlds, self.lanes.rows);
        self.lanes.for_each(|_, env, obs, _, _| {
            if env.just_ended {
                with_spare(rows, |spare| env.start(worlds, None, obs, spare))
            } else {
                Ok(())
            }
        })
    }

    /// Whether environment `i`'s episode ended in the latest step (under
    /// [`Autoreset::SameStep`] it has restarted since, its last observations in
    /// [`BatchOf::final_observations`]); false once a reset or restart started it afresh.
    pub fn ended(&self, i: usize) -> bool {
        self.lanes.envs.get(i).is_some_and(|e| e.just_ended)
    }

    /// Whether same-step autoreset restarted environment `i` in the latest step: its episode
    /// ended there, its last observations are in [`BatchOf::final_observations`], and its rows
    /// show the next episode's start while its records keep the step that ended the last.
    pub fn restarted(&self, i: usize) -> bool {
        self.options.autoreset == Autoreset::SameStep && self.ended(i)
    }

    /// Whether environment `i`'s episode started in the latest call: a reset, a restart that
    /// chose it, or an automatic reset.
    pub fn was_reset(&self, i: usize) -> bool {
        self.lanes.envs.get(i).is_some_and(|e| e.fresh)
    }

    /// Environment `i`'s state, when it exists.
    fn lane(&self, i: usize) -> Option<&E> {
        self.lanes.envs.get(i).map(|e| &e.lane)
    }

    /// Observations, [`BatchOf::rows`] rows of [`BatchOf::observation_size`] values per environment
    /// (a team robot's row is zeros past its own observation's length).
    pub fn observations(&self) -> &[f32] {
        &self.lanes.observations
    }

    /// With [`Autoreset::SameStep`]: the last observation of each episode that ended in the
    /// latest step (the rows of the others are stale).
    pub fn final_observations(&self) -> &[f32] {
        &self.lanes.final_observations
    }

    /// Each row's latest reset or step: environment `i`'s row `k` at `i R + k`.
    pub fn steps(&self) -> &[E::Record] {
        &self.lanes.steps
    }

    /// Number of environments.
    pub fn len(&self) -> usize {
        self.lanes.envs.len()
    }

    /// Whether the batch has no environments (never: it has at least one).
    pub fn is_empty(&self) -> bool {
        self.lanes.envs.is_empty()
    }

    /// Rows an environment takes: 1 for a lone robot, its robots for a team.
    pub fn rows(&self) -> usize {
        self.lanes.rows
    }

    /// Length of an observation row.
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

/// Runs `f` with `rows` records for a start whose own are not kept (an episode restarted in the
/// step that ended the one before: the step's records stay), on the stack for up to 8 rows.
fn with_spare<R: Default + Copy, T>(rows: usize, f: impl FnOnce(&mut [R]) -> T) -> T {
    if rows <= 8 {
        f(&mut [R::default(); 8][..rows])
    } else {
        f(&mut vec![R::default(); rows])
    }
}

impl<E: Lane> Drop for Lanes<E> {
    /// Ends a pool thread's lingering (see [`LINGER`]) at once.
    fn drop(&mut self) {
        self.begun.fetch_add(1, Ordering::Release);
    }
}

impl<E: Lane> Lanes<E> {
    /// Notes whether the caller came back within [`LINGER`] of its last call's end.
    fn arrive(&mut self) {
        self.quick = self.ended.is_some_and(|t| t.elapsed() < LINGER);
    }

    /// Runs `f` on every environment with its index, observation rows, final-observation rows
    /// and step records, in runs of [`MIN_PER_TASK`] to [`RUN`] rows (at least one environment):
    /// the calling thread takes runs one after another, and so do the pool's threads once they
    /// wake (without a pool, or for a small batch, too little work to wake another thread for,
    /// the calling thread steps every environment as one run). The calling thread starts
    /// at once instead of waiting for the pool to wake and then for it to finish. The first
    /// error in environment order wins.
    fn for_each(
        &mut self,
        f: impl Fn(usize, &mut Env<E>, &mut [f32], &mut [f32], &mut [E::Record]) -> Result<(), RunError>
            + Sync,
    ) -> Result<(), RunError> {
        let (rows, d) = (self.rows, self.observation_size);
        let n = self.envs.len();
        let Some(pool) = self.pool.as_ref().filter(|_| n * rows > MIN_PER_TASK) else {
            let all = Run {
                envs: &mut self.envs,
                obs: &mut self.observations,
                last: &mut self.final_observations,
                out: &mut self.steps,
            };
            let first = all.step(0, rows, d, &f);
            return first.map_or(Ok(()), |(_, e)| Err(e));
        };
        let helpers = pool.current_num_threads();
        // Runs short enough that every thread gets a few, long enough that the environments
        // asked for ahead at a run's start are few.
        let len = (n / (4 * (helpers + 1))).clamp(MIN_PER_TASK.div_ceil(rows), (RUN / rows).max(1));
        let runs: Vec<(usize, Run<'_, E>)> = self
            .envs
            .chunks_mut(len)
            .zip(self.observations.chunks_mut(len * rows * d))
            .zip(self.final_observations.chunks_mut(len * rows * d))
            .zip(self.steps.chunks_mut(len * rows))
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
            let failed = run.step(r * len, rows, d, &f);
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

impl<E: Lane> Run<'_, E> {
    /// [`Lanes::for_each`] over this run of environments (from environment `base`, `rows` rows
    /// of `d` values an environment), in order, asking for each environment's memory a few
    /// environments ahead (see [`Lane::prefetch`]): a thousand scenes do not fit the caches, and
    /// a step would otherwise wait on each link of the chain from the episode to the boxes near
    /// its robot in turn.
    fn step(
        self,
        base: usize,
        rows: usize,
        d: usize,
        f: &(impl Fn(
            usize,
            &mut Env<E>,
            &mut [f32],
            &mut [f32],
            &mut [E::Record],
        ) -> Result<(), RunError>
              + Sync),
    ) -> Option<(usize, RunError)> {
        let Self {
            envs,
            obs,
            last,
            out,
        } = self;
        let mut first = None;
        let w = rows * d;
        for j in 0..envs.len() {
            for stage in 0..PREFETCH_STAGES {
                if let Some(e) = envs.get(j + PREFETCH_STAGES - stage) {
                    e.lane.prefetch(stage);
                }
            }
            let row = j * w..(j + 1) * w;
            let result = f(
                base + j,
                &mut envs[j],
                &mut obs[row.clone()],
                &mut last[row],
                &mut out[j * rows..(j + 1) * rows],
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
    use crate::sim::{Action, Status};
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
