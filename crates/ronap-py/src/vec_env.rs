//! A batch of environments stepped together in Rust, across cores, with the GIL released: the
//! core's [`Batch`] with Gymnasium's next-step autoreset, its flat buffers handed over as numpy
//! arrays with no Python object per environment. Environment `i`'s `k`-th episode has seed
//! `base + i + k * n`, where `base` is the seed given to `reset` and `n` the number of
//! environments.

use crate::conv::{self, Config};
use crate::errors;
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use ronap_core::run::batch::{Autoreset, Batch, BatchOptions, EnvStep, SeedOrder};
use ronap_core::sim::world::Worlds;
use ronap_core::{Action, Status};

/// Many RoNAP environments stepped together.
#[pyclass(module = "ronap._ronap")]
pub struct VecEnv {
    batch: Batch,
}

impl VecEnv {
    fn arrays<'py>(&self, py: Python<'py>) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyDict>)> {
        let (n, d) = (self.batch.len(), self.batch.observation_size());
        let obs = PyArray1::from_slice(py, self.batch.observations()).reshape([n, d])?;
        let steps = self.batch.steps();
        let infos = PyDict::new(py);
        let column = |f: &dyn Fn(&EnvStep) -> f64| PyArray1::from_iter(py, steps.iter().map(f));
        let flags = |f: &dyn Fn(&EnvStep) -> bool| PyArray1::from_iter(py, steps.iter().map(f));
        infos.set_item("distance", column(&|s| s.distance_px))?;
        infos.set_item("collided", flags(&|s| s.collided))?;
        infos.set_item(
            "success",
            flags(&|s| !s.reset && s.status == Status::Success),
        )?;
        let poses: Vec<f64> = steps
            .iter()
            .flat_map(|s| [s.pose.x, s.pose.y, s.pose.z_deg])
            .collect();
        infos.set_item("pose", PyArray1::from_vec(py, poses).reshape([n, 3])?)?;
        Ok((obs.into_any(), infos))
    }
}

#[pymethods]
impl VecEnv {
    /// `num_envs` environments under `config`, stepped on `threads` threads (0: all cores).
    #[new]
    #[pyo3(signature = (num_envs, config, maze_seed = None, map_path = None, threads = 0))]
    fn new(
        num_envs: usize,
        config: &Config,
        maze_seed: Option<u64>,
        map_path: Option<&str>,
        threads: usize,
    ) -> PyResult<Self> {
        if num_envs == 0 {
            return Err(errors::ConfigError::new_err(
                "num_envs = 0: must be at least 1",
            ));
        }
        let (_, scenes, _) = conv::scenes(config.valid(), maze_seed, map_path)?;
        let options = BatchOptions {
            envs: num_envs,
            threads,
            autoreset: Autoreset::NextStep,
            seed_order: SeedOrder::Strided,
        };
        let batch = Batch::new(Worlds::new(config.valid().clone(), scenes), options)
            .map_err(|e| errors::RonapError::new_err(e.to_string()))?;
        Ok(Self { batch })
    }

    /// Starts every environment: environment `i` gets seed `seed + i`. Returns (observations,
    /// infos).
    fn reset<'py>(
        &mut self,
        py: Python<'py>,
        seed: u64,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyDict>)> {
        py.allow_threads(|| self.batch.reset(seed))
            .map_err(|e| errors::run(&e))?;
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
        let n = self.batch.len();
        if actions.len() != n {
            return Err(errors::ActionError::new_err(format!(
                "{} actions for {n} environments",
                actions.len()
            )));
        }
        let actions = actions
            .iter()
            .enumerate()
            .map(|(i, &a)| {
                conv::discrete(a).ok_or_else(|| {
                    errors::ActionError::new_err(format!(
                        "action {a} for environment {i}: expected 0 (LEFT), 1 (AHEAD) or \
                             2 (RIGHT)"
                    ))
                })
            })
            .collect::<PyResult<Vec<Action>>>()?;
        py.allow_threads(|| self.batch.step_actions(&actions))
            .map_err(|e| errors::run(&e))?;
        let steps = self.batch.steps();
        let rewards = PyArray1::from_iter(py, steps.iter().map(|s| s.reward));
        let terminated = PyArray1::from_iter(py, steps.iter().map(|s| s.status.is_terminated()));
        let truncated = PyArray1::from_iter(py, steps.iter().map(|s| s.status.is_truncated()));
        let (obs, infos) = self.arrays(py)?;
        Ok((obs, rewards, terminated, truncated, infos))
    }

    /// Number of environments.
    #[getter]
    fn num_envs(&self) -> usize {
        self.batch.len()
    }

    /// Length of one observation.
    #[getter]
    fn observation_size(&self) -> usize {
        self.batch.observation_size()
    }
}
