//! A batch of environments stepped together in Rust, across cores, with the GIL released.
//!
//! Results come back as numpy arrays, one row per environment, with no Python object per
//! environment. Environments reset themselves on the step after their episode ends (Gymnasium's
//! next-step autoreset): that step ignores the action and returns the new episode's first
//! observation with reward 0. Environment `i`'s `k`-th episode has seed `base + i + k * n`, where
//! `base` is the seed given to `reset` and `n` the number of environments.

use crate::env::{ends, scenes_for};
use crate::errors;
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::prelude::*;
use ronap_core::evaluate::Evaluator;
use ronap_core::{DiscreteAction, Episode, EpisodeError, Status};

/// Environments per parallel task: enough work to outweigh handing it to a thread.
const MIN_PER_TASK: usize = 16;

struct Slot {
    episode: Option<Episode>,
    next_seed: u64,
    needs_reset: bool,
}

#[derive(Clone, Copy, Default)]
struct Out {
    reward: f64,
    terminated: bool,
    truncated: bool,
    collided: bool,
    success: bool,
    distance: f64,
    pose: [f64; 3],
}

/// Many RoNAP environments stepped together.
#[pyclass(module = "ronap._ronap")]
pub struct VecEnv {
    evaluator: Evaluator,
    slots: Vec<Slot>,
    pool: rayon::ThreadPool,
    obs_size: usize,
    obs: Vec<f32>,
    outs: Vec<Out>,
}

impl VecEnv {
    /// Runs `f` on every environment with its observation row, output and action: on the calling
    /// thread for a small batch (too little work to wake another thread for), else on the pool.
    fn for_each_env(
        &mut self,
        actions: &[usize],
        f: impl Fn(&Evaluator, &mut Slot, &mut [f32], &mut Out, usize) -> Result<(), EpisodeError>
            + Sync,
    ) -> Result<(), EpisodeError> {
        let (evaluator, d) = (&self.evaluator, self.obs_size);
        let one = |(((slot, obs), out), &a): (((&mut Slot, &mut [f32]), &mut Out), &usize)| {
            f(evaluator, slot, obs, out, a)
        };
        if self.slots.len() <= MIN_PER_TASK {
            self.slots
                .iter_mut()
                .zip(self.obs.chunks_mut(d))
                .zip(self.outs.iter_mut())
                .zip(actions.iter())
                .try_for_each(one)
        } else {
            self.pool.install(|| {
                self.slots
                    .par_iter_mut()
                    .zip(self.obs.par_chunks_mut(d))
                    .zip(self.outs.par_iter_mut())
                    .zip(actions.par_iter())
                    .with_min_len(MIN_PER_TASK)
                    .try_for_each(one)
            })
        }
    }

    fn start(
        evaluator: &Evaluator,
        slot: &mut Slot,
        n: u64,
        obs: &mut [f32],
        out: &mut Out,
    ) -> Result<(), EpisodeError> {
        let seed = slot.next_seed;
        slot.next_seed = seed.wrapping_add(n);
        let episode = evaluator.world(seed).episode(seed)?;
        obs.copy_from_slice(episode.observation());
        *out = Out {
            distance: episode.distance_px(),
            pose: [episode.pose().x, episode.pose().y, episode.pose().z_deg],
            ..Out::default()
        };
        slot.episode = Some(episode);
        slot.needs_reset = false;
        Ok(())
    }

    fn arrays<'py>(&self, py: Python<'py>) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyDict>)> {
        let n = self.slots.len();
        let obs = PyArray1::from_slice(py, &self.obs).reshape([n, self.obs_size])?;
        let infos = PyDict::new(py);
        let column = |f: &dyn Fn(&Out) -> f64| PyArray1::from_iter(py, self.outs.iter().map(f));
        let flags = |f: &dyn Fn(&Out) -> bool| PyArray1::from_iter(py, self.outs.iter().map(f));
        infos.set_item("distance", column(&|o| o.distance))?;
        infos.set_item("collided", flags(&|o| o.collided))?;
        infos.set_item("success", flags(&|o| o.success))?;
        let poses: Vec<f64> = self.outs.iter().flat_map(|o| o.pose).collect();
        infos.set_item("pose", PyArray1::from_vec(py, poses).reshape([n, 3])?)?;
        Ok((obs.into_any(), infos))
    }
}

#[pymethods]
impl VecEnv {
    /// `num_envs` environments under `config_json` (see `Env`), stepped on `threads` threads
    /// (0: all cores).
    #[new]
    #[pyo3(signature = (num_envs, config_json, maze_seed = None, map_path = None, threads = 0))]
    fn new(
        num_envs: usize,
        config_json: &str,
        maze_seed: Option<u64>,
        map_path: Option<&str>,
        threads: usize,
    ) -> PyResult<Self> {
        if num_envs == 0 {
            return Err(errors::ConfigError::new_err(
                "num_envs = 0: must be at least 1",
            ));
        }
        let config = crate::parse_config(config_json)?;
        let obs_size = config.laser.beams as usize + 1;
        let scenes = scenes_for(&config, maze_seed, map_path)?;
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .map_err(|e| {
                errors::RonapError::new_err(format!("cannot start worker threads: {e}"))
            })?;
        Ok(Self {
            evaluator: Evaluator::new(config, scenes),
            slots: (0..num_envs)
                .map(|_| Slot {
                    episode: None,
                    next_seed: 0,
                    needs_reset: true,
                })
                .collect(),
            pool,
            obs_size,
            obs: vec![0.0; num_envs * obs_size],
            outs: vec![Out::default(); num_envs],
        })
    }

    /// Starts every environment: environment `i` gets seed `seed + i`. Returns (observations,
    /// infos).
    fn reset<'py>(
        &mut self,
        py: Python<'py>,
        seed: u64,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyDict>)> {
        let n = self.slots.len() as u64;
        for (i, slot) in self.slots.iter_mut().enumerate() {
            slot.next_seed = seed.wrapping_add(i as u64);
        }
        let actions = vec![0; self.slots.len()];
        py.allow_threads(|| {
            self.for_each_env(&actions, |evaluator, slot, obs, out, _| {
                Self::start(evaluator, slot, n, obs, out)
            })
        })
        .map_err(errors::scene)?;
        self.arrays(py)
    }

    /// Steps every environment with `actions` (one index per environment: 0 LEFT, 1 AHEAD,
    /// 2 RIGHT). Returns (observations, rewards, terminations, truncations, infos).
    #[allow(clippy::type_complexity)]
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        actions: PyReadonlyArray1<'py, i64>,
    ) -> PyResult<(
        Bound<'py, PyAny>,
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray1<bool>>,
        Bound<'py, PyArray1<bool>>,
        Bound<'py, PyDict>,
    )> {
        let actions = actions.as_slice()?;
        let n = self.slots.len();
        if actions.len() != n {
            return Err(errors::ActionError::new_err(format!(
                "{} actions for {n} environments",
                actions.len()
            )));
        }
        if let Some((i, a)) = actions
            .iter()
            .enumerate()
            .find(|(_, &a)| !(0..3).contains(&a))
        {
            return Err(errors::ActionError::new_err(format!(
                "action {a} for environment {i}: expected 0 (LEFT), 1 (AHEAD) or 2 (RIGHT)"
            )));
        }
        let actions: Vec<usize> = actions.iter().map(|&a| a as usize).collect();
        let n64 = n as u64;
        let step_one =
            |evaluator: &Evaluator, slot: &mut Slot, obs: &mut [f32], out: &mut Out, a: usize| {
                if slot.needs_reset || slot.episode.is_none() {
                    return Self::start(evaluator, slot, n64, obs, out);
                }
                let Some(episode) = slot.episode.as_mut() else {
                    return Ok(());
                };
                let r = episode.step(DiscreteAction::ALL[a]);
                let (terminated, truncated) = ends(r.status);
                *out = Out {
                    reward: r.reward,
                    terminated,
                    truncated,
                    collided: r.collided,
                    success: r.status == Status::Success,
                    distance: r.distance_px,
                    pose: [r.pose.x, r.pose.y, r.pose.z_deg],
                };
                obs.copy_from_slice(r.observation);
                slot.needs_reset = r.status.is_done();
                Ok(())
            };
        py.allow_threads(|| self.for_each_env(&actions, step_one))
            .map_err(errors::scene)?;
        let rewards = PyArray1::from_iter(py, self.outs.iter().map(|o| o.reward));
        let terminated = PyArray1::from_iter(py, self.outs.iter().map(|o| o.terminated));
        let truncated = PyArray1::from_iter(py, self.outs.iter().map(|o| o.truncated));
        let (obs, infos) = self.arrays(py)?;
        Ok((obs, rewards, terminated, truncated, infos))
    }

    /// Number of environments.
    #[getter]
    fn num_envs(&self) -> usize {
        self.slots.len()
    }

    /// Length of one observation.
    #[getter]
    fn observation_size(&self) -> usize {
        self.obs_size
    }
}
