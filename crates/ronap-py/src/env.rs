//! One environment: an episode at a time, stepped from Python; its robot is a team of one on the
//! core `MultiEnv` shares ([`TeamEnv`]).

use crate::conv::{self, Config};
use crate::errors::{self, ActionError};
use crate::team_env::TeamEnv;
use numpy::{PyArray1, PyArray3};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// What `Env.step` returns: observation, reward, terminated, truncated and info.
type Stepped<'py> = (
    Bound<'py, PyArray1<f32>>,
    f64,
    bool,
    bool,
    Bound<'py, PyDict>,
);

/// One RoNAP environment.
#[pyclass(module = "ronap._ronap")]
pub struct Env {
    core: TeamEnv,
    /// Robots of the configuration's `[[robots]]` (0 for the one robot it drives; a team is
    /// refused at reset, as `VecEnv` refuses it).
    team: usize,
}

#[pymethods]
impl Env {
    /// An environment under `config`, with the keyword options of [`TeamEnv::new`]
    /// (`maze_seed`, `map_path`, `continuous`).
    #[new]
    #[pyo3(signature = (config, **options))]
    fn new(config: &Config, options: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
        Ok(Self {
            core: TeamEnv::new("Env", config.valid(), options)?,
            team: config.valid().team_size(),
        })
    }

    /// Starts the episode of `seed`; returns (observation, info).
    fn reset<'py>(
        &mut self,
        py: Python<'py>,
        seed: u64,
    ) -> PyResult<(Bound<'py, PyArray1<f32>>, Bound<'py, PyDict>)> {
        if self.team > 0 {
            let e = ronap_core::sim::EpisodeError::Team { robots: self.team };
            return Err(errors::scene(format!("seed {seed}: {e}")));
        }
        let team = self.core.reset(py, seed)?;
        let robot = team.robot(0);
        let obs = PyArray1::from_slice(py, robot.observation());
        let info = conv::info(py, robot, false)?;
        Ok((obs, info))
    }

    /// The full value of each dimension of a normalised continuous action: `[v_max px,
    /// w_max deg]`, `[v_max, vy_max, w_max]` for an omnidirectional robot, `[v_max, steer_max
    /// deg]` for a car-like one.
    #[getter]
    fn action_scale(&self) -> Vec<f64> {
        self.core.config().robot.action_scale()
    }

    /// Takes one step; returns (observation, reward, terminated, truncated, info).
    fn step<'py>(&mut self, py: Python<'py>, action: &Bound<'py, PyAny>) -> PyResult<Stepped<'py>> {
        let chosen = self
            .core
            .action(0, action)
            .map_err(|why| ActionError::new_err(format!("action {action}: {why}")))?;
        let s = self.core.step(py, &[Some(chosen)])?;
        let robot = s.team.robot(0);
        let (terminated, truncated) = conv::ends(robot.status());
        Ok((
            PyArray1::from_slice(py, robot.observation()),
            s.rewards[0],
            terminated,
            truncated,
            conv::info(py, robot, s.collided[0])?,
        ))
    }

    /// The picture of the current state: `view` is "top" (whole scene, path so far) or
    /// "first_person" (the paper's rotating view); `scale` is pixels per px for "top" and the
    /// side in pixels for "first_person".
    fn render<'py>(
        &self,
        py: Python<'py>,
        view: &str,
        scale: f64,
    ) -> PyResult<Bound<'py, PyArray3<u8>>> {
        let team = self.core.team("render")?;
        let top = |scale| self.core.top_view(team, scale);
        conv::render(py, team.robot(0), &top, view, scale)
    }

    /// Length of the observation: beams + 1.
    #[getter]
    fn observation_size(&self) -> usize {
        self.core.config().observation_size()
    }
}
