//! One environment: an episode at a time, stepped from Python.

use crate::errors::{self, ActionError};
use numpy::{PyArray1, PyArray3, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use ronap_core::evaluate::{Evaluator, Scenes};
use ronap_core::{Action, DiscreteAction, Episode, Point, Status, ValidConfig};
use std::sync::Arc;

/// Where episodes happen: a maze per seed, one maze, or a map file.
pub fn scenes_for(
    config: &ValidConfig,
    maze_seed: Option<u64>,
    map_path: Option<&str>,
) -> PyResult<Scenes> {
    Ok(match (map_path, maze_seed) {
        (Some(path), _) => {
            let reach = ronap_core::episode::reach_px(config);
            let (scene, _) = ronap_core::map::load(std::path::Path::new(path), &config.map, reach)
                .map_err(errors::scene)?;
            Scenes::Fixed(Arc::new(scene))
        }
        (None, Some(seed)) => Scenes::Maze(seed),
        (None, None) => Scenes::MazePerSeed,
    })
}

/// An RGB image as an (height, width, 3) uint8 array.
pub fn image_to_array(py: Python<'_>, img: image::RgbImage) -> PyResult<Bound<'_, PyArray3<u8>>> {
    let (w, h) = img.dimensions();
    PyArray1::from_vec(py, img.into_raw()).reshape([h as usize, w as usize, 3])
}

/// Whether a status ends the episode as terminated (the MDP ended) or truncated (time-out).
pub fn ends(status: Status) -> (bool, bool) {
    match status {
        Status::Running => (false, false),
        Status::TimeOut => (false, true),
        Status::Success | Status::Collision | Status::RewardMin => (true, false),
    }
}

/// Reads a discrete action index (0 LEFT, 1 AHEAD, 2 RIGHT) or a continuous `(v, w)` pair.
pub fn parse_action(action: &Bound<'_, PyAny>, continuous: bool) -> PyResult<Action> {
    if continuous {
        let pair: Vec<f64> = action.extract().map_err(|_| {
            ActionError::new_err(format!("action {action}: expected two numbers (v, w)"))
        })?;
        match pair[..] {
            [v, w_deg] if v.is_finite() && w_deg.is_finite() => Ok(Action::Continuous { v, w_deg }),
            _ => Err(ActionError::new_err(format!(
                "action {action}: expected two finite numbers (v, w)"
            ))),
        }
    } else {
        let index: i64 = action.extract().map_err(|_| {
            ActionError::new_err(format!(
                "action {action}: expected 0 (LEFT), 1 (AHEAD) or 2 (RIGHT)"
            ))
        })?;
        usize::try_from(index)
            .ok()
            .and_then(DiscreteAction::from_index)
            .map(Action::from)
            .ok_or_else(|| {
                ActionError::new_err(format!(
                    "action {index}: expected 0 (LEFT), 1 (AHEAD) or 2 (RIGHT)"
                ))
            })
    }
}

/// The info dictionary of an episode's current state.
pub fn info<'py>(
    py: Python<'py>,
    episode: &Episode,
    collided: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let pose = episode.pose();
    d.set_item("distance", episode.distance_px())?;
    d.set_item("collided", collided)?;
    d.set_item("success", episode.status() == Status::Success)?;
    d.set_item("pose", (pose.x, pose.y, pose.z_deg))?;
    d.set_item("goal", (episode.goal().x, episode.goal().y))?;
    d.set_item("status", episode.status().name())?;
    d.set_item("steps", episode.steps())?;
    d.set_item("collisions", episode.collisions())?;
    d.set_item("seed", episode.seed())?;
    Ok(d)
}

/// One RoNAP environment.
#[pyclass(module = "ronap._ronap")]
pub struct Env {
    evaluator: Evaluator,
    episode: Option<Episode>,
    path: Vec<Point>,
    continuous: bool,
}

#[pymethods]
impl Env {
    /// An environment under `config_json`; `maze_seed` fixes one maze for every episode and
    /// `map_path` uses an image or ROS map instead of mazes.
    #[new]
    #[pyo3(signature = (config_json, maze_seed = None, map_path = None, continuous = false))]
    fn new(
        config_json: &str,
        maze_seed: Option<u64>,
        map_path: Option<&str>,
        continuous: bool,
    ) -> PyResult<Self> {
        let config = crate::parse_config(config_json)?;
        let scenes = scenes_for(&config, maze_seed, map_path)?;
        Ok(Self {
            evaluator: Evaluator::new(config, scenes),
            episode: None,
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
        let episode = self
            .evaluator
            .world(seed)
            .episode(seed)
            .map_err(errors::scene)?;
        self.path = vec![episode.pose().position()];
        let obs = PyArray1::from_slice(py, episode.observation());
        let info = info(py, &episode, false)?;
        self.episode = Some(episode);
        Ok((obs, info))
    }

    /// Takes one step; returns (observation, reward, terminated, truncated, info).
    #[allow(clippy::type_complexity)]
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        action: &Bound<'py, PyAny>,
    ) -> PyResult<(
        Bound<'py, PyArray1<f32>>,
        f64,
        bool,
        bool,
        Bound<'py, PyDict>,
    )> {
        let action = parse_action(action, self.continuous)?;
        let episode = self
            .episode
            .as_mut()
            .ok_or_else(|| errors::RonapError::new_err("step() before reset()"))?;
        let r = episode.step(action);
        let (reward, collided, status) = (r.reward, r.collided, r.status);
        self.path.push(episode.pose().position());
        let (terminated, truncated) = ends(status);
        Ok((
            PyArray1::from_slice(py, episode.observation()),
            reward,
            terminated,
            truncated,
            info(py, episode, collided)?,
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
        let img = match view {
            "top" => ronap_core::render::top_down(episode, &self.path, scale),
            "first_person" => ronap_core::render::first_person(episode, scale as u32),
            other => {
                return Err(errors::ConfigError::new_err(format!(
                    "render view {other:?}: expected \"top\" or \"first_person\""
                )))
            }
        };
        image_to_array(py, img)
    }

    /// Length of the observation: beams + 1.
    #[getter]
    fn observation_size(&self) -> usize {
        self.evaluator.config().laser.beams as usize + 1
    }

    /// The configuration in force, as JSON text.
    #[getter]
    fn config_json(&self) -> String {
        serde_json::to_string(self.evaluator.config().as_sim_config()).unwrap_or_default()
    }
}
