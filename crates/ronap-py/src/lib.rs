//! `ronap._ronap`: the Python extension. Thin wrappers over ronap-core: a single environment, a
//! batch of environments stepped in parallel with the GIL released, the batch evaluator with
//! built-in or Python policies, and maze pictures as numpy arrays.
//!
//! The Python package `ronap` (python/ronap) builds the Gymnasium classes on these.

mod env;
mod errors;
mod evaluate;
mod vec_env;

use numpy::{PyArray2, PyArray3, PyArrayMethods};
use pyo3::prelude::*;
use ronap_core::{SimConfig, ValidConfig};

/// Reads a configuration from JSON text (nested like the TOML file) and checks it.
pub(crate) fn parse_config(json: &str) -> PyResult<ValidConfig> {
    let sim: SimConfig =
        serde_json::from_str(json).map_err(|e| errors::ConfigError::new_err(e.to_string()))?;
    sim.validate()
        .map_err(|e| errors::ConfigError::new_err(e.to_string()))
}

/// The default configuration as JSON text.
#[pyfunction]
fn default_config_json() -> String {
    serde_json::to_string(&SimConfig::default()).unwrap_or_default()
}

/// Checks a configuration (JSON text) and returns it complete, with every default filled in.
#[pyfunction]
fn validate_config_json(json: &str) -> PyResult<String> {
    let config = parse_config(json)?;
    Ok(serde_json::to_string(config.as_sim_config()).unwrap_or_default())
}

/// The maze of `seed` as an occupancy array (rows from the top, like the picture): True where a
/// wall is, one entry per `1 / scale` px.
#[pyfunction]
#[pyo3(signature = (seed, config_json, scale = 1.0))]
fn maze_occupancy<'py>(
    py: Python<'py>,
    seed: u64,
    config_json: &str,
    scale: f64,
) -> PyResult<Bound<'py, PyArray2<bool>>> {
    let img = maze_picture(seed, config_json, scale)?;
    let (w, h) = img.dimensions();
    let data: Vec<bool> = img
        .pixels()
        .map(|p| p.0 == ronap_core::render::WALL.0)
        .collect();
    numpy::PyArray1::from_vec(py, data).reshape([h as usize, w as usize])
}

/// The maze of `seed` as an RGB picture (white floor, black walls), `scale` pixels per px.
#[pyfunction]
#[pyo3(signature = (seed, config_json, scale = 1.0))]
fn maze_image<'py>(
    py: Python<'py>,
    seed: u64,
    config_json: &str,
    scale: f64,
) -> PyResult<Bound<'py, PyArray3<u8>>> {
    let img = maze_picture(seed, config_json, scale)?;
    env::image_to_array(py, img)
}

fn maze_picture(seed: u64, config_json: &str, scale: f64) -> PyResult<image::RgbImage> {
    if !(scale.is_finite() && scale > 0.0 && scale <= 16.0) {
        return Err(errors::ConfigError::new_err(format!(
            "scale = {scale}: must be between 0 and 16"
        )));
    }
    let config = parse_config(config_json)?;
    let scene = ronap_core::episode::maze_scene(&config, seed);
    Ok(ronap_core::render::Canvas::new(&scene, scale).into_image())
}

/// The built-in policies: (name, description).
#[pyfunction]
fn builtin_policies() -> Vec<(&'static str, &'static str)> {
    ronap_core::policy::Builtin::ALL
        .iter()
        .map(|(_, name, about)| (*name, *about))
        .collect()
}

/// The module.
#[pymodule]
fn _ronap(m: &Bound<'_, PyModule>) -> PyResult<()> {
    errors::register(m)?;
    m.add_class::<env::Env>()?;
    m.add_class::<vec_env::VecEnv>()?;
    m.add_function(wrap_pyfunction!(default_config_json, m)?)?;
    m.add_function(wrap_pyfunction!(validate_config_json, m)?)?;
    m.add_function(wrap_pyfunction!(maze_occupancy, m)?)?;
    m.add_function(wrap_pyfunction!(maze_image, m)?)?;
    m.add_function(wrap_pyfunction!(builtin_policies, m)?)?;
    m.add_function(wrap_pyfunction!(evaluate::evaluate, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
