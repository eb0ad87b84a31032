//! Every conversion between Python and Rust values: the validated configuration (which crosses
//! the boundary once, as a [`Config`] object), scenario files and dicts (a [`Scenario`], the base
//! a configuration's keyword arguments override), scenes, actions, info dictionaries, images and
//! JSON values.

use crate::errors;
use numpy::{PyArray1, PyArray3, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use ronap_core::config::{ConfigFile, RobotConfig};
use ronap_core::scene::MapSource;
use ronap_core::sim::{SceneSpec, Scenes};
use ronap_core::{Action, DiscreteAction, Episode, SimConfig, Status, ValidConfig};
use serde_json::{Map, Value};
use std::path::{Path, PathBuf};

/// A scenario: the configuration a TOML file or a dict sets (every unset field at its default),
/// not yet checked, since keyword arguments may still override it. A file keeps its text, so a
/// bad value it sets is named by file and line.
#[pyclass(module = "ronap._ronap", frozen)]
pub struct Scenario {
    config: SimConfig,
    file: Option<ConfigFile>,
}

#[pymethods]
impl Scenario {
    /// Reads a scenario file (TOML, the CLI's `--scenario`); a map scene's file is taken relative
    /// to it. An unreadable file, an unknown key or a wrong type raises `ConfigError` naming the
    /// file, line, key and value.
    #[staticmethod]
    fn read(path: PathBuf) -> PyResult<Self> {
        let file =
            ConfigFile::read(&path).map_err(|e| errors::ConfigError::new_err(e.to_string()))?;
        let config = file
            .parse()
            .map_err(|e| errors::ConfigError::new_err(e.to_string()))?;
        Ok(Self {
            config,
            file: Some(file),
        })
    }

    /// A scenario from JSON text nested like the TOML file (`{"scene": {"kind": "warehouse"},
    /// "moving": [{"count": 5}]}`); a map scene's file stays relative to the current directory.
    /// An unknown key or a wrong type raises `ConfigError` naming the key and value.
    #[staticmethod]
    fn from_json(json: &str) -> PyResult<Self> {
        let value: Value = serde_json::from_str(json)
            .map_err(|e| errors::ConfigError::new_err(format!("scenario: {e}")))?;
        let config = sim_config(value)
            .map_err(|e| errors::ConfigError::new_err(format!("scenario: {e}")))?;
        Ok(Self { config, file: None })
    }

    /// The complete configuration the scenario sets, as JSON text.
    #[getter]
    fn json(&self) -> String {
        serde_json::to_string(&self.config).unwrap_or_default()
    }

    /// The scenario file, or None for a dict.
    #[getter]
    fn path(&self) -> Option<PathBuf> {
        self.file.as_ref().map(|f| f.path().to_path_buf())
    }
}

/// A checked configuration: made once from the JSON of the Python-side dict, then handed to
/// environments and the evaluator as it is.
#[pyclass(module = "ronap._ronap", frozen)]
pub struct Config {
    valid: ValidConfig,
    /// The scenario file the configuration was built on, if any.
    file: Option<ConfigFile>,
}

#[pymethods]
impl Config {
    /// Reads a configuration from JSON text (nested like the TOML file), fills in every default
    /// and checks it; a bad field raises `ConfigError` naming it. `scenario` is the scenario the
    /// JSON was built on (its values, then the keyword arguments): a bad value that came from a
    /// scenario file is named by file and line.
    #[new]
    #[pyo3(signature = (json, scenario = None))]
    fn new(json: &str, scenario: Option<&Scenario>) -> PyResult<Self> {
        let value: Value =
            serde_json::from_str(json).map_err(|e| errors::ConfigError::new_err(e.to_string()))?;
        let sim = sim_config(value).map_err(errors::ConfigError::new_err)?;
        let valid = sim
            .clone()
            .validate()
            .map_err(|e| errors::ConfigError::new_err(invalid(e, &sim, scenario)))?;
        let file = scenario.and_then(|s| s.file.clone());
        Ok(Self { valid, file })
    }

    /// `path:line` of the scenario file's `[[moving]]` or `[[crowd]]` field an error message
    /// names, if the file sets it (for errors found once the scene is built).
    fn line_of(&self, message: &str) -> Option<String> {
        self.file.as_ref().and_then(|f| f.line_of(message))
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

/// A configuration from a JSON value nested like the TOML file. An unknown key or a wrong type is
/// an error naming the key (`maze.cols`, `moving[0].motion`) and the value.
fn sim_config(value: Value) -> Result<SimConfig, String> {
    serde_json::from_value(value.clone())
        .map_err(|e| culprit(&value).unwrap_or_else(|| e.to_string()))
}

/// The first key of `value` that a configuration does not take, as `key = value: why`: each
/// section, each field and each array entry is read on its own until one fails.
fn culprit(value: &Value) -> Option<String> {
    let Value::Object(top) = value else {
        return Some(format!(
            "{value}: expected a dict of sections (`{{\"maze\": {{\"cols\": 5}}}}`)"
        ));
    };
    for (section, v) in top {
        let probe = |inner: Value| {
            let mut m = Map::new();
            m.insert(section.clone(), inner);
            serde_json::from_value::<SimConfig>(Value::Object(m)).err()
        };
        // The section itself: an unknown name, or a table where an array belongs (or the reverse).
        let empty = match v {
            Value::Object(_) => Value::Object(Map::new()),
            Value::Array(_) => Value::Array(Vec::new()),
            other => other.clone(),
        };
        if let Some(e) = probe(empty) {
            return Some(format!("{section} = {v}: {e}"));
        }
        let one = |field: &String, x: &Value| {
            let mut m = Map::new();
            m.insert(field.clone(), x.clone());
            Value::Object(m)
        };
        match v {
            Value::Object(fields) => {
                for (field, x) in fields {
                    if let Some(e) = probe(one(field, x)) {
                        return Some(format!("{section}.{field} = {x}: {e}"));
                    }
                }
            }
            Value::Array(items) => {
                for (i, item) in items.iter().enumerate() {
                    // An obstacle's fields depend on its shape, so it is read whole.
                    if let (Value::Object(fields), "moving") = (item, section.as_str()) {
                        for (field, x) in fields {
                            if let Some(e) = probe(Value::Array(vec![one(field, x)])) {
                                return Some(format!("{section}[{i}].{field} = {x}: {e}"));
                            }
                        }
                    }
                    if let Some(e) = probe(Value::Array(vec![item.clone()])) {
                        return Some(format!("{section}[{i}] = {item}: {e}"));
                    }
                }
            }
            _ => {}
        }
        if let Some(e) = probe(v.clone()) {
            return Some(format!("{section} = {v}: {e}"));
        }
    }
    None
}

/// The message of a validation error of `sim`, built on `scenario`: a value the scenario file
/// set is named by file and line (as `ronap run --scenario` does), one a scenario dict set is
/// said to come from the scenario; a value from the keyword arguments is named as it is.
fn invalid(e: ronap_core::ConfigError, sim: &SimConfig, scenario: Option<&Scenario>) -> String {
    let Some(scenario) = scenario else {
        return e.to_string();
    };
    let ronap_core::ConfigError::OutOfRange { field, .. } = &e else {
        return e.to_string();
    };
    let pointer = format!(
        "/{}",
        field.replace('[', "/").replace(']', "").replace('.', "/")
    );
    let (ours, theirs) = (
        serde_json::to_value(sim).unwrap_or_default(),
        serde_json::to_value(&scenario.config).unwrap_or_default(),
    );
    if ours.pointer(&pointer) != theirs.pointer(&pointer) {
        return e.to_string();
    }
    let Some(file) = &scenario.file else {
        return format!("scenario: {e}");
    };
    let overridden = *sim != scenario.config;
    match file.locate(e) {
        located @ ronap_core::ConfigError::File { .. } => located.to_string(),
        other if overridden => format!(
            "invalid configuration from scenario {} and keyword arguments: {other}",
            file.path().display()
        ),
        other => format!("{}: {other}", file.path().display()),
    }
}

/// Where episodes take place: the configuration's `[scene]` (a maze or warehouse per seed, one
/// of them, or a map file), unless `maze_seed` (one scene of that seed) or `map_path` overrides
/// it, as the CLI's `--maze-seed` and `--map` override a scenario's.
pub fn scenes(
    config: &ValidConfig,
    maze_seed: Option<u64>,
    map_path: Option<&str>,
) -> PyResult<(SceneSpec, Scenes, Option<MapSource>)> {
    let spec = SceneSpec::resolve(&config.scene, maze_seed, map_path.map(Path::new));
    let (scenes, source) = spec.load(config).map_err(errors::scene)?;
    Ok((spec, scenes, source))
}

/// What an action must be, for messages.
const DISCRETE: &str = "expected 0 (LEFT), 1 (AHEAD) or 2 (RIGHT)";

/// Reads an action: a discrete index (0 LEFT, 1 AHEAD, 2 RIGHT) or, given the robot of a
/// `continuous` environment, its continuous command of finite numbers (`(v, w)`, or `(vx, vy,
/// w)` and `(v, steer)` for omnidirectional and car-like robots). The error says what was
/// expected and is prefixed by the caller.
pub fn action(
    value: &Bound<'_, PyAny>,
    continuous: Option<&RobotConfig>,
) -> Result<Action, String> {
    if let Some(robot) = continuous {
        let n = robot.action_size();
        let names = robot.continuous_names();
        let what = || format!("expected {n} finite numbers {names}");
        let values: Vec<f64> = value.extract().map_err(|_| what())?;
        return ronap_core::sim::continuous_action(robot, &values).ok_or_else(what);
    }
    if value.is_instance_of::<pyo3::types::PyBool>()
        || value
            .get_type()
            .name()
            .is_ok_and(|n| n == "bool_" || n == "bool")
    {
        return Err(format!("{DISCRETE}, not a bool"));
    }
    // An integer, or a whole float (what a network's argmax often is).
    let index = match value.extract::<i64>() {
        Ok(i) => Some(i),
        Err(_) => value
            .extract::<f64>()
            .ok()
            .filter(|x| x.fract() == 0.0 && x.abs() < 1e15)
            .map(|x| x as i64),
    };
    index.and_then(discrete).ok_or_else(|| DISCRETE.to_string())
}

/// The discrete action of index `i` (0 LEFT, 1 AHEAD, 2 RIGHT), if it is one.
pub fn discrete(i: i64) -> Option<Action> {
    usize::try_from(i)
        .ok()
        .and_then(DiscreteAction::from_index)
        .map(Action::from)
}

/// The action a Python policy returned, or what is wrong with it (`returned X, expected ...`).
pub fn policy_action(
    value: &Bound<'_, PyAny>,
    continuous: Option<&RobotConfig>,
) -> Result<Action, String> {
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
    d.set_item("return", episode.total_reward())?;
    if let Some(dynamic) = episode.dynamic_metrics() {
        d.set_item("dynamic_collisions", dynamic.collisions)?;
    }
    Ok(d)
}

/// `episode` drawn as `view` asks: "top" (the whole scene as `top(scale)` draws it, `scale`
/// pixels per px) or "first_person" (the paper's rotating view, `scale` pixels a side).
pub fn render<'py>(
    py: Python<'py>,
    episode: &ronap_core::Episode,
    top: &dyn Fn(f64) -> image::RgbImage,
    view: &str,
    scale: f64,
) -> PyResult<Bound<'py, PyArray3<u8>>> {
    let img = match view {
        "top" => top(scale),
        "first_person" => ronap_core::render::first_person(episode, scale as u32),
        other => {
            return Err(crate::errors::ConfigError::new_err(format!(
                "render view {other:?}: expected \"top\" or \"first_person\""
            )))
        }
    };
    image(py, img)
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
    metrics: &[ronap_core::eval::MetricKind],
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
    // Among moving obstacles, the columns `episodes.csv` gains.
    if let Some(d) = r.dynamic {
        row.set_item("dynamic_collisions", d.collisions)?;
        let clearance = d.min_clearance_px.is_finite().then_some(d.min_clearance_px);
        row.set_item("min_clearance_px", clearance)?;
        let near = f64::from(d.near_steps) / f64::from(r.steps.max(1));
        row.set_item("near_moving_fraction", near)?;
    }
    // The metrics asked for beyond these (`[metrics]`), each under its column's name.
    for (k, v) in metrics.iter().zip(&r.metrics) {
        row.set_item(k.column.name, v.filter(|v| v.is_finite()))?;
    }
    Ok(row)
}
