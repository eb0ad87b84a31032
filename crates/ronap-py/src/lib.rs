//! `ronap._ronap`: the Python extension. Thin wrappers over ronap-core: a single environment, a
//! batch of environments stepped in parallel with the GIL released (the core's `Batch`), the
//! core's evaluator with built-in or Python policies, and maze pictures as numpy arrays. Every
//! Python <-> Rust conversion is in `conv.rs`, every exception in `errors.rs`.
//!
//! The Python package `ronap` (python/ronap) builds the Gymnasium classes on these.

mod conv;
mod env;
mod errors;
mod evaluate;
mod kwargs;
mod mlp;
mod multi_env;
mod orca;
mod team_env;
mod vec_env;

use conv::{Config, Scenario};
use numpy::PyArray3;
use pyo3::prelude::*;
use ronap_core::SimConfig;

/// The default configuration as JSON text.
#[pyfunction]
fn default_config_json() -> String {
    serde_json::to_string(&SimConfig::default()).unwrap_or_default()
}

/// The maze of `seed` as an RGB picture (white floor, black walls), `scale` pixels per px.
#[pyfunction]
#[pyo3(signature = (seed, config, scale = 1.0))]
fn maze_image<'py>(
    py: Python<'py>,
    seed: u64,
    config: &Config,
    scale: f64,
) -> PyResult<Bound<'py, PyArray3<u8>>> {
    let img = maze_picture(seed, config, scale)?;
    conv::image(py, img)
}

fn maze_picture(seed: u64, config: &Config, scale: f64) -> PyResult<image::RgbImage> {
    if !(scale.is_finite() && scale > 0.0 && scale <= 16.0) {
        return Err(errors::ConfigError::new_err(format!(
            "scale = {scale}: must be between 0 and 16"
        )));
    }
    let scene = ronap_core::sim::maze_scene(config.valid(), seed);
    Ok(ronap_core::render::Canvas::new(&scene, scale).into_image())
}

/// The first and last seed of a named split (`test`, `validation`, `train`).
#[pyfunction]
fn split_range(name: &str) -> PyResult<(u64, u64)> {
    let split = ronap_core::sim::Split::parse(name).map_err(errors::ConfigError::new_err)?;
    Ok((*split.range().start(), *split.range().end()))
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
    m.add_class::<Config>()?;
    m.add_class::<Scenario>()?;
    m.add_class::<env::Env>()?;
    m.add_class::<vec_env::VecEnv>()?;
    m.add_class::<evaluate::PyBlockRun>()?;
    m.add_class::<multi_env::MultiEnv>()?;
    m.add_class::<multi_env::VecMultiEnv>()?;
    m.add_function(wrap_pyfunction!(default_config_json, m)?)?;
    m.add_function(wrap_pyfunction!(split_range, m)?)?;
    m.add_function(wrap_pyfunction!(maze_image, m)?)?;
    m.add_function(wrap_pyfunction!(builtin_policies, m)?)?;
    m.add_function(wrap_pyfunction!(evaluate::evaluate, m)?)?;
    m.add_function(wrap_pyfunction!(evaluate::compare, m)?)?;
    m.add_function(wrap_pyfunction!(evaluate::check_policy, m)?)?;
    m.add_function(wrap_pyfunction!(mlp::write_mlp, m)?)?;
    m.add_function(wrap_pyfunction!(mlp::mlp_outputs, m)?)?;
    m.add_function(wrap_pyfunction!(orca::orca_step, m)?)?;
    let [r, g, b] = ronap_core::render::WALL.0;
    m.add("WALL_RGB", (r, g, b))?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
