//! The trainable network: the same multilayer perceptron as the core's [`Mlp`], as candle
//! variables, with conversions both ways.

use crate::LearnError;
use candle_core::{DType, Device, Tensor, Var};
use candle_nn::optim::{AdamW, Optimizer, ParamsAdamW};
use nalgebra::{DMatrix, DVector};
use rand::Rng as _;
use rand_chacha::ChaCha8Rng;
use ronap_core::policy::{Activation, Layer, Mlp};
use std::collections::HashMap;

/// Bounds of RReLU's random negative slope in training (PyTorch's defaults).
const RRELU_BOUNDS: (f32, f32) = (1.0 / 8.0, 1.0 / 3.0);

/// How a hidden activation behaves in training.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TrainActivation {
    /// max(0, x).
    Relu,
    /// tanh(x).
    Tanh,
    /// Leaky ReLU with a fixed slope.
    LeakyRelu(f32),
    /// The paper's randomised leaky ReLU: a slope drawn per value from U(1/8, 1/3) in training,
    /// their mean at inference.
    Rrelu,
}

impl TrainActivation {
    /// Parses `relu`, `tanh`, `rrelu` or `leaky_relu:SLOPE`.
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "relu" => Some(Self::Relu),
            "tanh" => Some(Self::Tanh),
            "rrelu" => Some(Self::Rrelu),
            _ => match Activation::parse(s)? {
                Activation::LeakyRelu(a) => Some(Self::LeakyRelu(a)),
                _ => None,
            },
        }
    }

    /// The activation the saved network uses.
    pub fn inference(self) -> Activation {
        match self {
            Self::Relu => Activation::Relu,
            Self::Tanh => Activation::Tanh,
            Self::LeakyRelu(a) => Activation::LeakyRelu(a),
            Self::Rrelu => Activation::LeakyRelu(ronap_core::policy::RRELU_SLOPE),
        }
    }
}

/// A multilayer perceptron of candle variables, optionally with a dueling head (Wang et al.
/// 2016): a value output `V` beside the last layer's advantages `A`, giving
/// `Q = V + A - mean(A)`. Both heads are linear in the last hidden layer, so a dueling network
/// folds into a plain one ([`Net::layers`]) and runs as the core's [`Mlp`].
#[derive(Debug)]
pub struct Net {
    weights: Vec<Var>,
    biases: Vec<Var>,
    /// The dueling head's value layer (weight `1 x hidden`, bias), if any.
    value: Option<(Var, Var)>,
    activation: TrainActivation,
}

impl Net {
    /// A network of layer `sizes` (inputs first, outputs last) initialised as PyTorch's
    /// `nn.Linear` does, U(-1/sqrt(in), 1/sqrt(in)), from `rng`.
    pub fn new(
        sizes: &[usize],
        activation: TrainActivation,
        rng: &mut ChaCha8Rng,
    ) -> Result<Self, LearnError> {
        let mut layers = Vec::new();
        for pair in sizes.windows(2) {
            let (n_in, n_out) = (pair[0], pair[1]);
            let k = 1.0 / (n_in as f32).sqrt();
            let weight = DMatrix::from_fn(n_out, n_in, |_, _| rng.random_range(-k..k));
            let bias = DVector::from_fn(n_out, |_, _| rng.random_range(-k..k));
            layers.push(Layer { weight, bias });
        }
        Self::from_layers(&layers, activation)
    }

    /// A policy network for observations `width` wide: `hidden` layers, then one output per
    /// action (LEFT, AHEAD, RIGHT).
    pub fn policy(
        width: usize,
        hidden: &[usize],
        activation: TrainActivation,
        rng: &mut ChaCha8Rng,
    ) -> Result<Self, LearnError> {
        let mut sizes = vec![width];
        sizes.extend(hidden);
        sizes.push(3);
        Self::new(&sizes, activation, rng)
    }

    /// [`Net::policy`] with a dueling head: the value layer is drawn after the others.
    pub fn dueling_policy(
        width: usize,
        hidden: &[usize],
        activation: TrainActivation,
        rng: &mut ChaCha8Rng,
    ) -> Result<Self, LearnError> {
        let mut net = Self::policy(width, hidden, activation, rng)?;
        let n_in = hidden.last().copied().unwrap_or(width);
        let k = 1.0 / (n_in as f32).sqrt();
        let w: Vec<f32> = (0..n_in).map(|_| rng.random_range(-k..k)).collect();
        let b = vec![rng.random_range(-k..k)];
        net.value = Some((
            Var::from_tensor(&Tensor::from_vec(w, (1, n_in), &Device::Cpu)?)?,
            Var::from_tensor(&Tensor::from_vec(b, 1, &Device::Cpu)?)?,
        ));
        Ok(net)
    }

    /// Adam (no weight decay) over every variable, at `learning_rate`.
    pub fn adam(&self, learning_rate: f64) -> Result<AdamW, LearnError> {
        Ok(AdamW::new(
            self.vars(),
            ParamsAdamW {
                lr: learning_rate,
                weight_decay: 0.0,
                ..ParamsAdamW::default()
            },
        )?)
    }

    /// The trainable copy of `mlp`'s layers.
    pub fn from_layers(layers: &[Layer], activation: TrainActivation) -> Result<Self, LearnError> {
        let mut weights = Vec::new();
        let mut biases = Vec::new();
        for l in layers {
            let rows: Vec<f32> = l.weight.transpose().iter().copied().collect();
            let w = Tensor::from_vec(rows, (l.weight.nrows(), l.weight.ncols()), &Device::Cpu)?;
            let b = Tensor::from_vec(l.bias.iter().copied().collect(), l.bias.len(), &Device::Cpu)?;
            weights.push(Var::from_tensor(&w)?);
            biases.push(Var::from_tensor(&b)?);
        }
        Ok(Self {
            weights,
            biases,
            value: None,
            activation,
        })
    }

    /// Every trainable variable.
    pub fn vars(&self) -> Vec<Var> {
        self.weights
            .iter()
            .zip(&self.biases)
            .chain(self.value.as_ref().map(|(w, b)| (w, b)))
            .flat_map(|(w, b)| [w.clone(), b.clone()])
            .collect()
    }

    /// Outputs for a batch `x` (`rows x inputs`). With `noise` (training), RReLU draws its slopes
    /// from it; without, every activation is its inference form.
    pub fn forward(
        &self,
        x: &Tensor,
        noise: Option<&mut ChaCha8Rng>,
    ) -> Result<Tensor, LearnError> {
        let mut x = x.clone();
        let last = self.weights.len() - 1;
        let mut noise = noise;
        for (i, (w, b)) in self.weights.iter().zip(&self.biases).enumerate() {
            let hidden = x;
            x = hidden
                .matmul(&w.as_tensor().t()?)?
                .broadcast_add(b.as_tensor())?;
            if i == last {
                if let Some((vw, vb)) = &self.value {
                    let v = hidden
                        .matmul(&vw.as_tensor().t()?)?
                        .broadcast_add(vb.as_tensor())?;
                    x = x.broadcast_sub(&x.mean_keepdim(1)?)?.broadcast_add(&v)?;
                }
                break;
            }
            x = match (self.activation, noise.as_deref_mut()) {
                (TrainActivation::Relu, _) => x.relu()?,
                (TrainActivation::Tanh, _) => x.tanh()?,
                (TrainActivation::Rrelu, Some(rng)) => {
                    let n = x.elem_count();
                    let slopes: Vec<f32> = (0..n)
                        .map(|_| rng.random_range(RRELU_BOUNDS.0..RRELU_BOUNDS.1))
                        .collect();
                    let slopes = Tensor::from_vec(slopes, x.shape(), &Device::Cpu)?;
                    (x.relu()? + x.minimum(0f32)?.mul(&slopes)?)?
                }
                (act, _) => {
                    let slope = match act.inference() {
                        Activation::LeakyRelu(s) => s,
                        _ => 0.0,
                    };
                    (x.relu()? + x.minimum(0f32)?.affine(f64::from(slope), 0.0)?)?
                }
            };
        }
        Ok(x)
    }

    /// Copies `other`'s weights into this network (a target network refresh).
    pub fn copy_from(&self, other: &Net) -> Result<(), LearnError> {
        for (a, b) in self.vars().iter().zip(other.vars()) {
            a.set(&b.as_tensor().copy()?)?;
        }
        Ok(())
    }

    /// Moves this network's weights a fraction `tau` of the way to `other`'s (Polyak averaging,
    /// a soft target-network update).
    pub fn blend_from(&self, other: &Net, tau: f64) -> Result<(), LearnError> {
        for (a, b) in self.vars().iter().zip(other.vars()) {
            let mixed = ((a.as_tensor() * (1.0 - tau))? + (b.as_tensor() * tau)?)?;
            a.set(&mixed)?;
        }
        Ok(())
    }

    /// The layers as the core's nalgebra layers.
    /// A dueling head is folded into the last layer: row `i` becomes
    /// `w_V + w_A,i - mean_j w_A,j` (and the bias alike), which gives the same Q-values.
    pub fn layers(&self) -> Result<Vec<Layer>, LearnError> {
        let mut out = Vec::new();
        for (w, b) in self.weights.iter().zip(&self.biases) {
            out.push(layer(w, b)?);
        }
        if let (Some((vw, vb)), Some(last)) = (&self.value, out.last_mut()) {
            let value = layer(vw, vb)?;
            let mean_w = last.weight.row_mean();
            let mean_b = last.bias.mean();
            for i in 0..last.weight.nrows() {
                let row = value.weight.row(0) + last.weight.row(i) - &mean_w;
                last.weight.set_row(i, &row);
                last.bias[i] += value.bias[0] - mean_b;
            }
        }
        Ok(out)
    }

    /// The network for inference, with `metadata` for its file.
    pub fn to_mlp(&self, metadata: HashMap<String, String>) -> Result<Mlp, LearnError> {
        Mlp::new(self.layers()?, self.activation.inference(), metadata).map_err(LearnError::Network)
    }
}

/// The nalgebra layer of weight `w` (`out x in`) and bias `b`.
fn layer(w: &Var, b: &Var) -> Result<Layer, LearnError> {
    let (rows, cols) = w.as_tensor().dims2()?;
    let values: Vec<f32> = w.as_tensor().flatten_all()?.to_vec1()?;
    let bias: Vec<f32> = b.as_tensor().to_vec1()?;
    Ok(Layer {
        weight: DMatrix::from_row_slice(rows, cols, &values),
        bias: DVector::from_vec(bias),
    })
}

/// A `rows x width` batch tensor from row-major values.
pub fn batch(values: Vec<f32>, width: usize) -> Result<Tensor, LearnError> {
    let rows = values.len() / width.max(1);
    Ok(Tensor::from_vec(values, (rows, width), &Device::Cpu)?)
}

/// Index of the largest value of each row of `outputs`.
pub fn argmax_rows(outputs: &Tensor) -> Result<Vec<u32>, LearnError> {
    Ok(outputs.argmax(1)?.to_dtype(DType::U32)?.to_vec1()?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    /// Checks `net`'s candle outputs for the 18-wide rows of `x` against `mlp`'s, to 1e-5.
    fn assert_agree(net: &Net, mlp: &Mlp, x: &[f32], what: &str) {
        let out: Vec<Vec<f32>> = net
            .forward(&batch(x.to_vec(), 18).unwrap(), None)
            .unwrap()
            .to_vec2()
            .unwrap();
        for (row, o) in out.iter().enumerate() {
            let expect = mlp.forward(&x[row * 18..(row + 1) * 18]);
            for (a, b) in o.iter().zip(expect.iter()) {
                assert!((a - b).abs() < 1e-5, "{what}: {a} vs {b}");
            }
        }
    }

    #[test]
    fn candle_and_nalgebra_agree() {
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        for act in [
            TrainActivation::Relu,
            TrainActivation::Tanh,
            TrainActivation::Rrelu,
            TrainActivation::LeakyRelu(0.05),
        ] {
            let net = Net::new(&[18, 16, 8, 3], act, &mut rng).unwrap();
            let mlp = net.to_mlp(HashMap::new()).unwrap();
            let x: Vec<f32> = (0..36).map(|i| (i as f32 * 0.7).sin()).collect();
            assert_agree(&net, &mlp, &x, &format!("{act:?}"));
        }
    }

    #[test]
    fn a_dueling_network_folds_into_a_plain_one() {
        let mut rng = ChaCha8Rng::seed_from_u64(2);
        let net = Net::dueling_policy(18, &[16, 8], TrainActivation::Relu, &mut rng).unwrap();
        let mlp = net.to_mlp(HashMap::new()).unwrap();
        assert_eq!(mlp.layers.len(), 3);
        // Q = V + A - mean(A), folded into the last layer.
        let x: Vec<f32> = (0..54).map(|i| (i as f32 * 0.3).cos()).collect();
        assert_agree(&net, &mlp, &x, "dueling");
        // The value head is trained: its variables are among the network's.
        assert_eq!(net.vars().len(), 8);
    }
}
