//! The weights file: safetensors tensors `layers.{i}.weight` / `layers.{i}.bias` and string
//! metadata (the format is described in [`crate::policy::mlp`]).

use crate::policy::mlp::network::{Activation, DecisionRule, Layer, Mlp, FORMAT};
use crate::sim::SeedRanges;
use nalgebra::{DMatrix, DVector};
use safetensors::tensor::{Dtype, TensorView};
use safetensors::SafeTensors;
use std::path::{Path, PathBuf};

/// Metadata keys that record seeds a network was trained and chosen on.
const SEEDS_KEYS: [&str; 2] = ["training_seeds", "validation_seeds"];

/// A weights file that cannot be used.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum MlpError {
    /// The file could not be read.
    #[error("cannot read {}: {message}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
    /// The file is not a valid ronap MLP.
    #[error("{}: {message}", path.display())]
    Invalid {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
}

impl Mlp {
    /// Reads a weights file.
    pub fn load(path: &Path) -> Result<Self, MlpError> {
        let bytes = crate::bounded::read(path, crate::bounded::WEIGHTS_LIMIT).map_err(|e| {
            MlpError::Io {
                path: path.to_path_buf(),
                message: e.to_string(),
            }
        })?;
        Self::from_bytes(&bytes).map_err(|message| MlpError::Invalid {
            path: path.to_path_buf(),
            message,
        })
    }

    /// Parses the bytes of a weights file.
    pub fn from_bytes(bytes: &[u8]) -> Result<Self, String> {
        let (_, header) = SafeTensors::read_metadata(bytes)
            .map_err(|e| format!("not a safetensors file ({e})"))?;
        let metadata = header.metadata().clone().unwrap_or_default();
        match metadata.get("format").map(String::as_str) {
            Some(FORMAT) => {}
            Some(other) => {
                return Err(format!(
                    "metadata format = {other:?}; this ronap reads {FORMAT:?}"
                ))
            }
            None => return Err(format!("metadata has no format (expected {FORMAT:?})")),
        }
        let activation_name = metadata
            .get("activation")
            .ok_or("metadata has no activation")?;
        let activation = Activation::parse(activation_name).ok_or_else(|| {
            format!(
                "metadata activation = {activation_name:?} (expected relu, tanh, rrelu or \
                 leaky_relu:SLOPE)"
            )
        })?;
        let tensors =
            SafeTensors::deserialize(bytes).map_err(|e| format!("not a safetensors file ({e})"))?;
        let names: Vec<String> = tensors.names().into_iter().map(String::from).collect();
        let count = (0..)
            .take_while(|i| names.contains(&format!("layers.{i}.weight")))
            .count();
        if count == 0 {
            return Err("missing tensor layers.0.weight".into());
        }
        let mut layers = Vec::with_capacity(count);
        for i in 0..count {
            let weight_name = format!("layers.{i}.weight");
            let bias_name = format!("layers.{i}.bias");
            let w = tensors
                .tensor(&weight_name)
                .map_err(|_| format!("missing tensor {weight_name}"))?;
            let b = tensors
                .tensor(&bias_name)
                .map_err(|_| format!("missing tensor {bias_name}"))?;
            let (rows, cols) = match w.shape() {
                [r, c] => (*r, *c),
                s => return Err(format!("{weight_name} has shape {s:?}; expected [out, in]")),
            };
            if b.shape() != [rows] {
                return Err(format!(
                    "{bias_name} has shape {:?}; expected [{rows}]",
                    b.shape()
                ));
            }
            let weight = DMatrix::from_row_slice(rows, cols, &floats(&w, &weight_name)?);
            let bias = DVector::from_vec(floats(&b, &bias_name)?);
            layers.push(Layer { weight, bias });
        }
        if let Some(extra) = names.iter().find(|n| {
            !(0..count)
                .any(|i| **n == format!("layers.{i}.weight") || **n == format!("layers.{i}.bias"))
        }) {
            return Err(format!(
                "unexpected tensor {extra} (layers are numbered from 0 without gaps)"
            ));
        }
        if let Some(d) = metadata.get("decision") {
            if DecisionRule::parse(d).is_none() {
                return Err(format!(
                    "metadata decision = {d:?} (expected argmax or sample:TEMPERATURE)"
                ));
            }
        }
        for key in SEEDS_KEYS {
            if let Some(text) = metadata.get(key) {
                SeedRanges::parse(text).map_err(|e| format!("metadata {key} = {text:?}: {e}"))?;
            }
        }
        let mlp = Self::new(layers, activation, metadata.clone())?;
        if let Some(size) = metadata.get("observation_size") {
            if size.parse::<usize>().ok() != Some(mlp.inputs()) {
                return Err(format!(
                    "metadata observation_size = {size:?} but layers.0.weight takes {} inputs",
                    mlp.inputs()
                ));
            }
        }
        Ok(mlp)
    }

    /// The seeds the network was trained and chosen on, as its metadata records them
    /// (`training_seeds`, `validation_seeds`; none for a file that records neither).
    pub fn seeds_seen(&self) -> SeedRanges {
        let mut seen = SeedRanges::default();
        for key in SEEDS_KEYS {
            if let Some(ranges) = self
                .metadata
                .get(key)
                .and_then(|t| SeedRanges::parse(t).ok())
            {
                seen.extend(ranges);
            }
        }
        seen
    }

    /// The file's bytes.
    pub fn to_bytes(&self) -> Result<Vec<u8>, String> {
        let mut data: Vec<(String, Vec<usize>, Vec<u8>)> = Vec::new();
        for (i, l) in self.layers.iter().enumerate() {
            // nalgebra stores columns first; the file holds rows first.
            let rows: Vec<f32> = l.weight.transpose().iter().copied().collect();
            data.push((
                format!("layers.{i}.weight"),
                vec![l.weight.nrows(), l.weight.ncols()],
                rows.iter().flat_map(|v| v.to_le_bytes()).collect(),
            ));
            data.push((
                format!("layers.{i}.bias"),
                vec![l.bias.len()],
                l.bias.iter().flat_map(|v| v.to_le_bytes()).collect(),
            ));
        }
        let views = data
            .iter()
            .map(|(name, shape, bytes)| {
                TensorView::new(Dtype::F32, shape.clone(), bytes)
                    .map(|v| (name.clone(), v))
                    .map_err(|e| e.to_string())
            })
            .collect::<Result<Vec<_>, _>>()?;
        safetensors::serialize(views, Some(self.metadata.clone())).map_err(|e| e.to_string())
    }
}

fn floats(t: &TensorView<'_>, name: &str) -> Result<Vec<f32>, String> {
    if t.dtype() != Dtype::F32 {
        return Err(format!("{name} is {:?}; expected F32", t.dtype()));
    }
    Ok(t.data()
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect())
}
