//! One environment: an episode at a time, stepped from Python.

use crate::conv::{self, Config};
use crate::errors::{self, ActionError};
use numpy::{PyArray1, PyArray3};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use ronap_core::run::Shaper;
use ronap_core::sim::Worlds;
use ronap_core::{Episode, Point};

/// One RoNAP environment.
/// What `Env.step` returns: observation, reward, terminated, truncated and info.
type Stepped<'py> = (
    Bound<'py, PyArray1<f32>>,
    f64,
    bool,
    bool,
    Bound<'py, PyDict>,
);

#[pyclass(module = "ronap._ronap")]
pub struct Env {
    worlds: Worlds,
    episode: Option<Episode>,
    /// The shaping of the episode's reward, under `reward.shaping`.
    shaper: Option<Shaper>,
    path: Vec<Point>,
    continuous: bool,
}

#[pymethods]
impl Env {
    /// An environment under `config`; `maze_seed` fixes one maze for every episode and
    /// `map_path` uses an image or ROS map instead of mazes.
    #[new]
    #[pyo3(signature = (config, maze_seed = None, map_path = None, continuous = false))]
    fn new(
        config: &Config,
        maze_seed: Option<u64>,
        map_path: Option<&str>,
        continuous: bool,
    ) -> PyResult<Self> {
        let (_, scenes, _) = conv::scenes(config.valid(), maze_seed, map_path)?;
        Ok(Self {
            worlds: Worlds::new(config.valid().clone(), scenes),
            episode: None,
            shaper: None,
            path: Vec::new(),
            continuous,
        })
    }

    /// Starts the episode of `seed`; returns (observation, info).
    fn reset<'py>(
        &mut self,
        py: Python<'py>,
        seed: u64,
    ) -> PyResult<(Bound<'py, PyArray1<f32>>, Bound<'py, PyDict>)> {
        let world = self.worlds.world(seed);
        let episode = world
            .episode(seed)
            .map_err(|e| errors::scene(format!("seed {seed}: {e}")))?;
        self.shaper = Shaper::start(world, &episode);
        self.path = vec![episode.pose().position()];
        let obs = PyArray1::from_slice(py, episode.observation());
        let info = conv::info(py, &episode, false)?;
        self.episode = Some(episode);
        Ok((obs, info))
    }

    /// The full value of each dimension of a normalised continuous action: `[v_max px,
    /// w_max deg]`, `[v_max, vy_max, w_max]` for an omnidirectional robot, `[v_max, steer_max
    /// deg]` for a car-like one.
    #[getter]
    fn action_scale(&self) -> Vec<f64> {
        self.worlds.config().robot.action_scale()
    }

    /// Takes one step; returns (observation, reward, terminated, truncated, info).
    fn step<'py>(&mut self, py: Python<'py>, action: &Bound<'py, PyAny>) -> PyResult<Stepped<'py>> {
        let robot = &self.worlds.config().robot;
        let action = conv::action(action, self.continuous.then_some(robot))
            .map_err(|why| ActionError::new_err(format!("action {action}: {why}")))?;
        let episode = self
            .episode
            .as_mut()
            .ok_or_else(|| errors::RonapError::new_err("step() before reset()"))?;
        let r = episode.step(action);
        let (mut reward, collided, status) = (r.reward, r.collided, r.status);
        if let Some(shaper) = self.shaper.as_mut() {
            reward = shaper.step(episode, reward);
        }
        self.path.push(episode.pose().position());
        let (terminated, truncated) = conv::ends(status);
        Ok((
            PyArray1::from_slice(py, episode.observation()),
            reward,
            terminated,
            truncated,
            conv::info(py, episode, collided)?,
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
        let episode = self
            .episode
            .as_ref()
            .ok_or_else(|| errors::RonapError::new_err("render() before reset()"))?;
        conv::render(py, episode, &self.path, view, scale)
    }

    /// Length of the observation: beams + 1.
    #[getter]
    fn observation_size(&self) -> usize {
        self.worlds.config().observation_size()
    }
}
