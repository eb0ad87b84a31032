//! Networks in ronap's weights file, from Python: written from plain arrays (what
//! `ronap.export_policy` and `ronap.import_torch` take out of torch models and files) and run on
//! a batch of observations, so an export can be checked against the framework it came from.

use crate::errors;
use numpy::{PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use ronap_core::io::save_network;
use ronap_core::policy::{Activation, Layer, Mlp, Scratch};
use std::collections::HashMap;
use std::path::PathBuf;

/// Writes the network of `weights[i]` (`out x in`, PyTorch's `nn.Linear` layout) and `biases[i]`
/// with `activation` after every layer but the last, and `metadata`, to `path` (atomically).
/// A network ronap cannot run (shapes that do not chain, not 3 outputs, a non-finite weight, an
/// unknown activation) raises `ConfigError` saying what is wrong.
#[pyfunction]
pub fn write_mlp(
    path: PathBuf,
    weights: Vec<PyReadonlyArray2<'_, f32>>,
    biases: Vec<PyReadonlyArray1<'_, f32>>,
    activation: &str,
    metadata: HashMap<String, String>,
) -> PyResult<()> {
    let act = Activation::parse(activation).ok_or_else(|| {
        errors::ConfigError::new_err(format!(
            "activation {activation:?}: expected relu, tanh, rrelu or leaky_relu:SLOPE"
        ))
    })?;
    if weights.len() != biases.len() {
        return Err(errors::ConfigError::new_err(format!(
            "{} weight matrices and {} bias vectors",
            weights.len(),
            biases.len()
        )));
    }
    let layers = weights
        .iter()
        .zip(&biases)
        .map(|(w, b)| {
            let w = w.as_array();
            let (rows, cols) = w.dim();
            let values: Vec<f32> = w.iter().copied().collect();
            Layer {
                weight: nalgebra::DMatrix::from_row_slice(rows, cols, &values),
                bias: nalgebra::DVector::from_iterator(
                    b.as_array().len(),
                    b.as_array().iter().copied(),
                ),
            }
        })
        .collect();
    let mlp = Mlp::new(layers, act, metadata)
        .map_err(|e| errors::ConfigError::new_err(format!("{}: {e}", path.display())))?;
    save_network(&path, &mlp).map_err(errors::output)
}

/// The outputs (one row of 3 per observation) of the network in weights file `path` for each row
/// of `observations`, as the `mlp:` policy computes them.
#[pyfunction]
pub fn mlp_outputs<'py>(
    py: Python<'py>,
    path: PathBuf,
    observations: PyReadonlyArray2<'py, f32>,
) -> PyResult<Bound<'py, PyArray2<f32>>> {
    let mlp = Mlp::load(&path).map_err(|e| errors::ConfigError::new_err(e.to_string()))?;
    let obs = observations.as_array();
    if obs.ncols() != mlp.inputs() {
        return Err(errors::ConfigError::new_err(format!(
            "observations of {} values for a network of {} inputs ({})",
            obs.ncols(),
            mlp.inputs(),
            path.display()
        )));
    }
    // Every row at once (the same bits as one at a time, a few rows sharing each weight).
    let rows: Vec<f32> = obs.iter().copied().collect();
    let n = obs.nrows();
    let out = mlp
        .forward_rows_into(&rows, n, &mut Scratch::default())
        .to_vec();
    PyArray1::from_vec(py, out).reshape([n, 3])
}
