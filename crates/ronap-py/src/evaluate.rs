//! `evaluate()`: the batch evaluator with a built-in policy or a Python callable.

use crate::env::scenes_for;
use crate::errors;
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use ronap_core::evaluate::{Evaluator, Recording};
use ronap_core::policy::{Decision, Policy, PolicyError, PolicyFactory};
use ronap_core::report::Pictures;
use ronap_core::summary::Summary;
use ronap_core::{Action, DiscreteAction, Episode, World};
use std::sync::atomic::AtomicBool;

/// A Python callable as a policy: observation (a float32 array) in, action out.
struct PyPolicy {
    callable: Py<PyAny>,
    continuous: bool,
}

/// Reads what a Python policy returned.
fn action_from(value: &Bound<'_, PyAny>, continuous: bool) -> Result<Action, String> {
    if continuous {
        let pair: Vec<f64> = value
            .extract()
            .map_err(|_| format!("returned {value}, expected (v, w)"))?;
        return match pair[..] {
            [v, w_deg] if v.is_finite() && w_deg.is_finite() => Ok(Action::Continuous { v, w_deg }),
            _ => Err(format!(
                "returned {value}, expected two finite numbers (v, w)"
            )),
        };
    }
    if let Ok(i) = value.extract::<i64>() {
        return usize::try_from(i)
            .ok()
            .and_then(DiscreteAction::from_index)
            .map(Action::from)
            .ok_or_else(|| format!("returned {i}, expected 0 (LEFT), 1 (AHEAD) or 2 (RIGHT)"));
    }
    match value.extract::<f64>() {
        Ok(x) if x.is_nan() => {
            Err("returned NaN, expected 0 (LEFT), 1 (AHEAD) or 2 (RIGHT)".into())
        }
        _ => Err(format!(
            "returned {value}, expected 0 (LEFT), 1 (AHEAD) or 2 (RIGHT)"
        )),
    }
}

impl Policy for PyPolicy {
    fn reset(&mut self, _world: &World, _episode: &Episode) -> Result<(), PolicyError> {
        Ok(())
    }

    fn act(&mut self, episode: &Episode) -> Result<Decision, PolicyError> {
        Python::with_gil(|py| {
            let obs = PyArray1::from_slice(py, episode.observation());
            let value = self.callable.call1(py, (obs,)).map_err(|e| {
                PolicyError::Failed(format!(
                    "raised {}",
                    e.value(py)
                        .repr()
                        .map_or_else(|_| e.to_string(), |r| r.to_string())
                ))
            })?;
            let robot = &episode.config().robot;
            action_from(value.bind(py), self.continuous)
                .map(|a| match a {
                    // Continuous policies answer in [-1, 1], as NavEnv's action space.
                    Action::Continuous { v, w_deg } => Action::Continuous {
                        v: v * robot.max_linear_speed_px,
                        w_deg: w_deg * robot.max_angular_speed_deg,
                    },
                    other => other,
                })
                .map(Decision::Act)
                .map_err(PolicyError::Failed)
        })
    }
}

struct PyPolicyFactory {
    callable: Py<PyAny>,
    continuous: bool,
    name: String,
}

impl PolicyFactory for PyPolicyFactory {
    fn make(&self) -> Result<Box<dyn Policy>, PolicyError> {
        let callable = Python::with_gil(|py| self.callable.clone_ref(py));
        Ok(Box::new(PyPolicy {
            callable,
            continuous: self.continuous,
        }))
    }

    fn name(&self) -> String {
        self.name.clone()
    }
}

/// A JSON value as a Python object.
fn to_py(py: Python<'_>, v: &serde_json::Value) -> PyResult<PyObject> {
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
                .map(|x| to_py(py, x))
                .collect::<PyResult<Vec<_>>>()?,
        )?
        .into_any()
        .unbind(),
        Value::Object(o) => {
            let d = PyDict::new(py);
            for (k, x) in o {
                d.set_item(k, to_py(py, x)?)?;
            }
            d.into_any().unbind()
        }
    })
}

/// Runs `policy` (a built-in name or a callable) over `seeds`; returns {"summary": ...,
/// "episodes": [...]} with the figures and rows `ronap run` reports, and writes its files into
/// `out` when given.
#[pyfunction]
#[pyo3(signature = (policy, seeds, config_json, maze_seed = None, map_path = None, threads = 0, continuous = false, out = None, png = None, log_steps = false))]
#[allow(clippy::too_many_arguments)]
pub fn evaluate<'py>(
    py: Python<'py>,
    policy: &Bound<'py, PyAny>,
    seeds: Vec<u64>,
    config_json: &str,
    maze_seed: Option<u64>,
    map_path: Option<&str>,
    threads: usize,
    continuous: bool,
    out: Option<std::path::PathBuf>,
    png: Option<String>,
    log_steps: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let config = crate::parse_config(config_json)?;
    if seeds.is_empty() {
        return Err(errors::ConfigError::new_err(
            "seeds is empty: give at least one seed",
        ));
    }
    let factory: Box<dyn PolicyFactory> = if let Ok(name) = policy.extract::<String>() {
        let observation_size = config.laser.beams as usize + 1;
        ronap_core::policy::factory(&name, observation_size)
            .map_err(|e| errors::ConfigError::new_err(e.to_string()))?
    } else if policy.is_callable() {
        let name = policy
            .getattr("__name__")
            .and_then(|n| n.extract::<String>())
            .unwrap_or_else(|_| "python".into());
        Box::new(PyPolicyFactory {
            callable: policy.clone().unbind(),
            continuous,
            name,
        })
    } else {
        return Err(errors::ConfigError::new_err(format!(
            "policy {policy}: expected a built-in policy name or a callable (observation -> action)"
        )));
    };
    let png_choice: Option<Pictures> = png
        .as_deref()
        .map(str::parse)
        .transpose()
        .map_err(|e| errors::ConfigError::new_err(format!("png = {e}")))?;
    if let Some(dir) = &out {
        for sub in [
            Some(""),
            png.as_ref().map(|_| "png"),
            log_steps.then_some("steps"),
        ]
        .into_iter()
        .flatten()
        {
            std::fs::create_dir_all(dir.join(sub)).map_err(|e| {
                errors::OutputError::new_err(format!(
                    "cannot create {}: {e}",
                    dir.join(sub).display()
                ))
            })?;
        }
    }
    let scenes = scenes_for(&config, maze_seed, map_path)?;
    let evaluator = Evaluator::new(config.clone(), scenes);
    let first = seeds[0];
    let recording = Recording {
        trajectory: out.is_some() && png_choice.is_some(),
        steps: out.is_some() && log_steps,
    };
    let write_errors = std::sync::Mutex::new(Vec::<String>::new());
    let cancel = AtomicBool::new(false);
    let result = py
        .allow_threads(|| {
            let on_record = |r: &ronap_core::evaluate::EpisodeRecord| {
                let Some(dir) = &out else { return };
                let picture = png_choice.is_some_and(|p| p.wants(r, first));
                if let Err(e) = ronap_core::report::write_episode_files(dir, r, picture, log_steps)
                {
                    if let Ok(mut all) = write_errors.lock() {
                        all.push(e.to_string());
                    }
                }
            };
            evaluator.run(
                factory.as_ref(),
                &seeds,
                threads,
                recording,
                &cancel,
                &on_record,
            )
        })
        .map_err(|e| errors::PolicyError::new_err(e.to_string()))?;
    let summary = Summary::new(&result.records, result.wall_time_s);
    if let Some(dir) = &out {
        let meta = serde_json::json!({
            "policy": factory.name(),
            "seed_start": first,
            "seeds_requested": seeds.len(),
            "threads": threads,
        });
        ronap_core::report::write_run(
            dir,
            meta.as_object().cloned().unwrap_or_default(),
            &config,
            &result,
            &summary,
        )
        .map_err(|e| errors::OutputError::new_err(e.to_string()))?;
    }
    if let Some(e) = write_errors.into_inner().unwrap_or_default().first() {
        return Err(errors::OutputError::new_err(e.clone()));
    }
    if let Some(e) = &result.error {
        return Err(match e {
            ronap_core::evaluate::RunError::Episode { .. } => errors::scene(e),
            _ => errors::PolicyError::new_err(e.to_string()),
        });
    }
    let d = PyDict::new(py);
    d.set_item(
        "summary",
        to_py(py, &serde_json::to_value(&summary).unwrap_or_default())?,
    )?;
    let rows = PyList::empty(py);
    for r in &result.records {
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
        rows.append(row)?;
    }
    d.set_item("episodes", rows)?;
    Ok(d)
}
