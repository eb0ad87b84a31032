//! Learned policies: a multilayer perceptron read from a safetensors file and run with nalgebra,
//! no ML framework at inference.
//!
//! # The file
//! Tensors, all `F32`, for layers `i = 0..n`:
//! - `layers.{i}.weight`, shape `[out_i, in_i]` (PyTorch's `nn.Linear` layout, `y = W x + b`);
//! - `layers.{i}.bias`, shape `[out_i]`.
//!
//! `in_0` is the observation size, `in_{i+1} = out_i`, and the last layer has 3 outputs, one per
//! action in the order LEFT, AHEAD, RIGHT (Q-values or logits: the policy takes the largest).
//! The hidden activation, applied after every layer but the last, and the rest are metadata
//! (string to string, as safetensors allows):
//! - `format`: `ronap-mlp/1`;
//! - `activation`: `relu`, `tanh`, `leaky_relu:SLOPE`, or `rrelu` (the paper's RReLU; at inference
//!   it is a leaky ReLU of slope `(1/8 + 1/3) / 2`, PyTorch's evaluation mode);
//! - `observation`: the observation layout, [`OBSERVATION_LAYOUT`] for SPEC.md's 18 values;
//! - `observation_size`: the number of inputs;
//! - optional, for people: `output` (`q_values` or `logits`), `command` (what trained it),
//!   `trained` (a description of the training data or run).

use super::{Decision, Policy, PolicyError, PolicyFactory};
use crate::episode::Episode;
use crate::robot::DiscreteAction;
use crate::world::World;
use nalgebra::{DMatrix, DVector};
use safetensors::tensor::{Dtype, TensorView};
use safetensors::SafeTensors;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// The `format` metadata value this version reads and writes.
pub const FORMAT: &str = "ronap-mlp/1";
/// The `observation` metadata value for SPEC.md's observation.
pub const OBSERVATION_LAYOUT: &str = "laser_0/range,...,laser_16/range,direction/360";
/// Slope of RReLU at inference: the mean of its default bounds 1/8 and 1/3.
pub const RRELU_SLOPE: f32 = (1.0 / 8.0 + 1.0 / 3.0) / 2.0;

/// The observation layout for a laser of `beams` beams.
pub fn observation_layout(beams: usize) -> String {
    if beams == 17 {
        OBSERVATION_LAYOUT.to_string()
    } else {
        format!(
            "laser_0/range,...,laser_{}/range,direction/360",
            beams.saturating_sub(1)
        )
    }
}

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

/// A hidden-layer activation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Activation {
    /// max(0, x).
    Relu,
    /// tanh(x).
    Tanh,
    /// x for x >= 0, slope * x below.
    LeakyRelu(f32),
}

impl Activation {
    /// Parses the `activation` metadata value.
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "relu" => Some(Self::Relu),
            "tanh" => Some(Self::Tanh),
            "rrelu" => Some(Self::LeakyRelu(RRELU_SLOPE)),
            _ => s
                .strip_prefix("leaky_relu:")
                .and_then(|v| v.parse::<f32>().ok())
                .filter(|v| v.is_finite())
                .map(Self::LeakyRelu),
        }
    }

    /// The metadata value.
    pub fn name(self) -> String {
        match self {
            Self::Relu => "relu".into(),
            Self::Tanh => "tanh".into(),
            Self::LeakyRelu(s) if s == RRELU_SLOPE => "rrelu".into(),
            Self::LeakyRelu(s) => format!("leaky_relu:{s}"),
        }
    }

    fn apply(self, v: &mut DVector<f32>) {
        match self {
            Self::Relu => v.apply(|x| *x = x.max(0.0)),
            Self::Tanh => v.apply(|x| *x = x.tanh()),
            Self::LeakyRelu(s) => v.apply(|x| {
                if *x < 0.0 {
                    *x *= s;
                }
            }),
        }
    }
}

/// One layer, `y = W x + b`.
#[derive(Clone, Debug, PartialEq)]
pub struct Layer {
    /// Weights, `out x in`.
    pub weight: DMatrix<f32>,
    /// Bias, `out`.
    pub bias: DVector<f32>,
}

/// A multilayer perceptron: observation in, one value per action out.
#[derive(Clone, Debug, PartialEq)]
pub struct Mlp {
    /// The layers, input first.
    pub layers: Vec<Layer>,
    /// Activation after every layer but the last.
    pub activation: Activation,
    /// Metadata carried in the file (`format`, `activation` and `observation_size` included).
    pub metadata: HashMap<String, String>,
}

impl Mlp {
    /// An MLP from its layers; checks that the shapes chain and the weights are finite.
    pub fn new(
        layers: Vec<Layer>,
        activation: Activation,
        mut metadata: HashMap<String, String>,
    ) -> Result<Self, String> {
        let first = layers.first().ok_or("the network has no layers")?;
        let inputs = first.weight.ncols();
        for (i, l) in layers.iter().enumerate() {
            if l.bias.len() != l.weight.nrows() {
                return Err(format!(
                    "layers.{i}.bias has {} values for {} outputs",
                    l.bias.len(),
                    l.weight.nrows()
                ));
            }
            if i > 0 && l.weight.ncols() != layers[i - 1].weight.nrows() {
                return Err(format!(
                    "layers.{i}.weight takes {} inputs but layers.{} gives {}",
                    l.weight.ncols(),
                    i - 1,
                    layers[i - 1].weight.nrows()
                ));
            }
            if let Some(bad) = l
                .weight
                .iter()
                .chain(l.bias.iter())
                .find(|v| !v.is_finite())
            {
                return Err(format!("layer {i} has a non-finite weight ({bad})"));
            }
        }
        let outputs = layers[layers.len() - 1].weight.nrows();
        if outputs != DiscreteAction::ALL.len() {
            return Err(format!(
                "the last layer has {outputs} outputs; a policy needs 3 (LEFT, AHEAD, RIGHT)"
            ));
        }
        metadata.insert("format".into(), FORMAT.into());
        metadata.insert("activation".into(), activation.name());
        metadata.insert("observation_size".into(), inputs.to_string());
        metadata
            .entry("observation".into())
            .or_insert_with(|| observation_layout(inputs.saturating_sub(1)));
        Ok(Self {
            layers,
            activation,
            metadata,
        })
    }

    /// The `decision` metadata's rule, argmax when absent.
    pub fn decision_rule(&self) -> DecisionRule {
        self.metadata
            .get("decision")
            .and_then(|d| DecisionRule::parse(d))
            .unwrap_or(DecisionRule::Argmax)
    }

    /// Number of inputs.
    pub fn inputs(&self) -> usize {
        self.layers[0].weight.ncols()
    }

    /// The network's outputs for `observation`.
    pub fn forward(&self, observation: &[f32]) -> DVector<f32> {
        let mut x = DVector::from_column_slice(observation);
        let last = self.layers.len() - 1;
        for (i, l) in self.layers.iter().enumerate() {
            let mut y = l.bias.clone();
            y.gemv(1.0, &l.weight, &x, 1.0);
            if i < last {
                self.activation.apply(&mut y);
            }
            x = y;
        }
        x
    }

    /// The action with the largest output (the first of equals).
    pub fn action(&self, observation: &[f32]) -> DiscreteAction {
        let out = self.forward(observation);
        let mut best = 0;
        for i in 1..out.len() {
            if out[i] > out[best] {
                best = i;
            }
        }
        DiscreteAction::ALL[best]
    }

    /// Reads a weights file.
    pub fn load(path: &Path) -> Result<Self, MlpError> {
        let bytes = std::fs::read(path).map_err(|e| MlpError::Io {
            path: path.to_path_buf(),
            message: e.to_string(),
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

/// How a policy turns the network's outputs into an action.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum DecisionRule {
    /// The action with the largest output.
    Argmax,
    /// An action drawn from softmax(outputs / temperature), from the episode's policy stream:
    /// a classifier's probabilities, taken at their word.
    Sample {
        /// Softmax temperature, > 0.
        temperature: f32,
    },
}

impl DecisionRule {
    /// Parses the `decision` metadata value: `argmax` or `sample:TEMPERATURE`.
    pub fn parse(s: &str) -> Option<Self> {
        if s == "argmax" {
            return Some(Self::Argmax);
        }
        s.strip_prefix("sample:")
            .and_then(|t| t.parse::<f32>().ok())
            .filter(|t| t.is_finite() && *t > 0.0)
            .map(|temperature| Self::Sample { temperature })
    }

    /// The metadata value.
    pub fn name(self) -> String {
        match self {
            Self::Argmax => "argmax".into(),
            Self::Sample { temperature } => format!("sample:{temperature}"),
        }
    }
}

/// The MLP as a policy.
#[derive(Clone, Debug)]
pub struct MlpPolicy {
    mlp: Arc<Mlp>,
    rule: DecisionRule,
    rng: crate::rng::Rng,
}

impl MlpPolicy {
    /// A policy running `mlp` with its file's decision rule.
    pub fn new(mlp: Arc<Mlp>) -> Self {
        let rule = mlp.decision_rule();
        Self {
            mlp,
            rule,
            rng: crate::rng::stream(0, crate::rng::Stream::Policy),
        }
    }
}

impl Policy for MlpPolicy {
    fn reset(&mut self, _world: &World, episode: &Episode) -> Result<(), PolicyError> {
        let size = episode.observation().len();
        if size != self.mlp.inputs() {
            return Err(PolicyError::Failed(format!(
                "the network takes {} inputs but the episode's observation has {size} \
                 ({} laser beams + direction)",
                self.mlp.inputs(),
                size - 1
            )));
        }
        self.rng = crate::rng::stream(episode.seed(), crate::rng::Stream::Policy);
        Ok(())
    }

    fn act(&mut self, episode: &Episode) -> Result<Decision, PolicyError> {
        let observation = episode.observation();
        let action = match self.rule {
            DecisionRule::Argmax => self.mlp.action(observation),
            DecisionRule::Sample { temperature } => {
                let out = self.mlp.forward(observation);
                let top = out.max();
                let weights: Vec<f32> = out
                    .iter()
                    .map(|v| ((v - top) / temperature).exp())
                    .collect();
                let mut u = rand::Rng::random::<f32>(&mut self.rng) * weights.iter().sum::<f32>();
                let mut pick = weights.len() - 1;
                for (i, w) in weights.iter().enumerate() {
                    if u < *w {
                        pick = i;
                        break;
                    }
                    u -= w;
                }
                DiscreteAction::ALL[pick]
            }
        };
        Ok(Decision::Act(action.into()))
    }
}

/// Makes [`MlpPolicy`]s sharing one loaded network.
#[derive(Clone, Debug)]
pub struct MlpFactory {
    mlp: Arc<Mlp>,
    name: String,
}

impl MlpFactory {
    /// Loads `path` and checks it fits observations of `observation_size` values.
    pub fn load(path: &Path, observation_size: usize) -> Result<Self, MlpError> {
        let mlp = Mlp::load(path)?;
        if mlp.inputs() != observation_size {
            return Err(MlpError::Invalid {
                path: path.to_path_buf(),
                message: format!(
                    "the network takes {} inputs (metadata observation: {:?}) but this \
                     configuration's observation has {observation_size} ({} laser beams + \
                     direction)",
                    mlp.inputs(),
                    mlp.metadata.get("observation").map_or("", String::as_str),
                    observation_size - 1
                ),
            });
        }
        Ok(Self {
            mlp: Arc::new(mlp),
            name: format!("mlp:{}", path.display()),
        })
    }

    /// The same network with `rule` instead of the file's decision rule.
    pub fn with_rule(mut self, rule: DecisionRule) -> Self {
        let mut mlp = (*self.mlp).clone();
        mlp.metadata.insert("decision".into(), rule.name());
        self.mlp = Arc::new(mlp);
        self.name = format!("{}@{}", self.name, rule.name());
        self
    }

    /// The network.
    pub fn mlp(&self) -> &Arc<Mlp> {
        &self.mlp
    }
}

impl PolicyFactory for MlpFactory {
    fn make(&self) -> Result<Box<dyn Policy>, PolicyError> {
        Ok(Box::new(MlpPolicy::new(self.mlp.clone())))
    }

    fn name(&self) -> String {
        self.name.clone()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tiny() -> Mlp {
        let l0 = Layer {
            weight: DMatrix::from_fn(4, 18, |r, c| ((r * 18 + c) as f32 * 0.37).sin()),
            bias: DVector::from_fn(4, |r, _| r as f32 * 0.1 - 0.2),
        };
        let l1 = Layer {
            weight: DMatrix::from_fn(3, 4, |r, c| ((r * 4 + c) as f32 * 1.3).cos()),
            bias: DVector::from_vec(vec![0.0, 0.5, -0.5]),
        };
        Mlp::new(
            vec![l0, l1],
            Activation::LeakyRelu(RRELU_SLOPE),
            HashMap::new(),
        )
        .unwrap()
    }

    #[test]
    fn round_trips_and_computes_by_hand() {
        let m = tiny();
        let back = Mlp::from_bytes(&m.to_bytes().unwrap()).unwrap();
        assert_eq!(back, m);
        assert_eq!(back.metadata["activation"], "rrelu");
        assert_eq!(back.metadata["observation"], OBSERVATION_LAYOUT);
        let x: Vec<f32> = (0..18).map(|i| i as f32 / 18.0).collect();
        // By hand, row-major as in the file.
        let mut h = [0f32; 4];
        for (r, hr) in h.iter_mut().enumerate() {
            let mut s = r as f32 * 0.1 - 0.2;
            for (c, xc) in x.iter().enumerate() {
                s += ((r * 18 + c) as f32 * 0.37).sin() * xc;
            }
            *hr = if s < 0.0 { s * RRELU_SLOPE } else { s };
        }
        let out = back.forward(&x);
        for r in 0..3 {
            let mut s = [0.0, 0.5, -0.5][r];
            for (c, hc) in h.iter().enumerate() {
                s += ((r * 4 + c) as f32 * 1.3).cos() * hc;
            }
            assert!((out[r] - s).abs() < 1e-5, "{} vs {s}", out[r]);
        }
    }

    #[test]
    fn bad_files_say_what_is_wrong() {
        let m = tiny();
        let mut nan = m.clone();
        nan.layers[1].weight[(0, 0)] = f32::NAN;
        let e = Mlp::from_bytes(&nan.to_bytes().unwrap()).unwrap_err();
        assert!(e.contains("non-finite"), "{e}");

        let mut wrong = m.clone();
        wrong.layers[1].weight = DMatrix::zeros(3, 5);
        assert!(Mlp::from_bytes(&wrong.to_bytes().unwrap())
            .unwrap_err()
            .contains("layers.1.weight takes 5 inputs but layers.0 gives 4"));

        let mut missing = m.clone();
        missing.layers.pop();
        let e = Mlp::from_bytes(&missing.to_bytes().unwrap()).unwrap_err();
        assert!(e.contains("4 outputs"), "{e}");

        let e = Mlp::from_bytes(b"not a file").unwrap_err();
        assert!(e.contains("not a safetensors file"), "{e}");

        let mut meta = m.clone();
        meta.metadata.insert("activation".into(), "swish".into());
        let e = Mlp::from_bytes(&meta.to_bytes().unwrap()).unwrap_err();
        assert!(e.contains("swish"), "{e}");
    }

    #[test]
    fn a_missing_bias_is_named() {
        let m = tiny();
        let bytes = m.to_bytes().unwrap();
        let t = SafeTensors::deserialize(&bytes).unwrap();
        let views: Vec<(String, TensorView<'_>)> = t
            .tensors()
            .into_iter()
            .filter(|(n, _)| n != "layers.1.bias")
            .collect();
        let cut = safetensors::serialize(views, Some(m.metadata.clone())).unwrap();
        assert_eq!(
            Mlp::from_bytes(&cut).unwrap_err(),
            "missing tensor layers.1.bias"
        );
    }
}
