//! Every conversion between Python and Rust values: the validated configuration (which crosses
//! the boundary once, as a [`Config`] object), scenes, actions, info dictionaries, images and
//! JSON values.

use crate::errors;
use numpy::{PyArray1, PyArray3, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use ronap_core::scene::map::MapSource;
use ronap_core::sim::world::{SceneSpec, Scenes};
use ronap_core::{Action, DiscreteAction, Episode, SimConfig, Status, ValidConfig};
use std::path::Path;

/// A checked configuration: made once from the JSON of the Python-side dict, then handed to
/// environments and the evaluator as it is.
#[pyclass(module = "ronap._ronap", frozen)]
pub struct Config {
    valid: ValidConfig,
}

#[pymethods]
impl Config {
    /// Reads a configuration from JSON text (nested like the TOML file), fills in every default
    /// and checks it; a bad field raises `ConfigError` naming it.
    #[new]
    fn new(json: &str) -> PyResult<Self> {
        let sim: SimConfig =
            serde_json::from_str(json).map_err(|e| errors::ConfigError::new_err(e.to_string()))?;
        let valid = sim
            .validate()
            .map_err(|e| errors::ConfigError::new_err(e.to_string()))?;
        Ok(Self { valid })
    }

    /// The complete configuration as JSON text.
    #[getter]
    fn json(&self) -> String {
        serde_json::to_string(self.valid.as_sim_config()).unwrap_or_default()
    }

    /// Length of one observation: laser beams + 1.
    #[getter]
    fn observation_size(&self) -> usize {
        self.valid.observation_size()
    }
}

impl Config {
    /// The validated configuration.
    pub fn valid(&self) -> &ValidConfig {
        &self.valid
    }
}

/// Where episodes take place: a map file, one maze, or a maze per seed.
pub fn scenes(
    config: &ValidConfig,
    maze_seed: Option<u64>,
    map_path: Option<&str>,
) -> PyResult<(SceneSpec, Scenes, Option<MapSource>)> {
    let spec = SceneSpec::from_options(maze_seed, map_path.map(Path::new));
    let (scenes, source) = spec.load(config).map_err(errors::scene)?;
    Ok((spec, scenes, source))
}

/// What an action must be, for messages.
const DISCRETE: &str = "expected 0 (LEFT), 1 (AHEAD) or 2 (RIGHT)";

/// Reads an action: a discrete index (0 LEFT, 1 AHEAD, 2 RIGHT) or, when `continuous`, a pair
/// `(v, w)` of finite numbers. The error says what was expected and is prefixed by the caller.
pub fn action(value: &Bound<'_, PyAny>, continuous: bool) -> Result<Action, String> {
    if continuous {
        let pair: Vec<f64> = value
            .extract()
            .map_err(|_| "expected two numbers (v, w)".to_string())?;
        return match pair[..] {
            [v, w_deg] if v.is_finite() && w_deg.is_finite() => Ok(Action::Continuous { v, w_deg }),
            _ => Err("expected two finite numbers (v, w)".into()),
        };
    }
    match value.extract::<i64>() {
        Ok(i) => usize::try_from(i)
            .ok()
            .and_then(DiscreteAction::from_index)
            .map(Action::from)
            .ok_or_else(|| DISCRETE.to_string()),
        Err(_) => Err(DISCRETE.to_string()),
    }
}

/// The action a Python policy returned, or what is wrong with it (`returned X, expected ...`).
pub fn policy_action(value: &Bound<'_, PyAny>, continuous: bool) -> Result<Action, String> {
    action(value, continuous).map_err(|why| {
        let shown = match value.extract::<f64>() {
            Ok(x) if x.is_nan() => "NaN".to_string(),
            _ => value.to_string(),
        };
        format!("returned {shown}, {why}")
    })
}

/// Whether a status ends the episode as terminated (the MDP ended) or truncated (time-out).
pub fn ends(status: Status) -> (bool, bool) {
    (status.is_terminated(), status.is_truncated())
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

/// An RGB image as an (height, width, 3) uint8 array.
pub fn image(py: Python<'_>, img: image::RgbImage) -> PyResult<Bound<'_, PyArray3<u8>>> {
    let (w, h) = img.dimensions();
    PyArray1::from_vec(py, img.into_raw()).reshape([h as usize, w as usize, 3])
}

/// A JSON value as a Python object.
pub fn json(py: Python<'_>, v: &serde_json::Value) -> PyResult<PyObject> {
    use serde_json::Value;
    Ok(match v {
        Value::Null => py.None(),
        Value::Bool(b) => b.into_pyobject(py)?.to_owned().into_any().unbind(),
        Value::Number(n) => match (n.as_u64(), n.as_i64(), n.as_f64()) {
            (Some(u), _, _) => u.into_pyobject(py)?.into_any().unbind(),
            (_, Some(i), _) => i.into_pyobject(py)?.into_any().unbind(),
            (_, _, f) => f.unwrap_or(f64::NAN).into_pyobject(py)?.into_any().unbind(),
        },
        Value::String(s) => s.into_pyobject(py)?.into_any().unbind(),
        Value::Array(a) => PyList::new(
            py,
            a.iter()
                .map(|x| json(py, x))
                .collect::<PyResult<Vec<_>>>()?,
        )?
        .into_any()
        .unbind(),
        Value::Object(o) => {
            let d = PyDict::new(py);
            for (k, x) in o {
                d.set_item(k, json(py, x)?)?;
            }
            d.into_any().unbind()
        }
    })
}

/// An episode record as the row dictionary `evaluate` returns.
pub fn record<'py>(
    py: Python<'py>,
    r: &ronap_core::eval::EpisodeRecord,
) -> PyResult<Bound<'py, PyDict>> {
    let row = PyDict::new(py);
    row.set_item("seed", r.seed)?;
    row.set_item("outcome", r.outcome.name())?;
    row.set_item("steps", r.steps)?;
    row.set_item("collisions", r.collisions)?;
    row.set_item("path_length_px", r.path_length_px)?;
    row.set_item("shortest_px", r.shortest_px)?;
    row.set_item("spl", r.spl)?;
    row.set_item("return", r.total_reward)?;
    row.set_item("start", (r.start.x, r.start.y, r.start.z_deg))?;
    row.set_item("goal", (r.goal.x, r.goal.y))?;
    row.set_item("end", (r.end.x, r.end.y, r.end.z_deg))?;
    row.set_item("reason", r.reason.clone())?;
    row.set_item("wall_time_s", r.wall_time_s)?;
    Ok(row)
}
