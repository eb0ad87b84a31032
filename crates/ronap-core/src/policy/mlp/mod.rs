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
//! - `observation`: the observation layout, [`network::OBSERVATION_LAYOUT`] for the 18 values of
//!   docs/model.md "Observation";
//! - `observation_size`: the number of inputs;
//! - optional, for people: `output` (`q_values` or `logits`), `command` (what trained it),
//!   `trained` (a description of the training data or run).

mod file;
mod network;

pub use file::MlpError;
pub use network::{observation_layout, Activation, DecisionRule, Layer, Mlp, Scratch, RRELU_SLOPE};

use crate::policy::{Decision, Policy, PolicyError, PolicyFactory};
use crate::sim::{DiscreteAction, Episode, SeedRanges, World};
use std::path::Path;
use std::sync::Arc;

/// How many episodes an [`MlpPolicy`] decides for together when the evaluator runs them side by
/// side: its rows go through the network four at a time, each weight loaded once for the four.
/// A single observation's pass is bound by reading the weights (79 KB for the shipped network,
/// more than the first-level cache) from the second-level cache.
pub const SIDE_BY_SIDE: usize = 16;

/// The MLP as a policy.
#[derive(Clone, Debug)]
pub struct MlpPolicy {
    mlp: Arc<Mlp>,
    rule: DecisionRule,
    rng: crate::sim::Rng,
    scratch: Scratch,
    /// Each lane's policy stream, when episodes run side by side.
    lane_rngs: Vec<crate::sim::Rng>,
    /// The lanes' observations, a row each.
    rows: Vec<f32>,
}

impl MlpPolicy {
    /// A policy running `mlp` with its file's decision rule.
    pub fn new(mlp: Arc<Mlp>) -> Self {
        let rule = mlp.decision_rule();
        Self {
            mlp,
            rule,
            rng: crate::sim::stream(0, crate::sim::Stream::Policy),
            scratch: Scratch::default(),
            lane_rngs: Vec::new(),
            rows: Vec::new(),
        }
    }

    /// Checks that `episode`'s observation fits the network.
    fn check(&self, episode: &Episode) -> Result<(), PolicyError> {
        let size = episode.observation().len();
        if size != self.mlp.inputs() {
            return Err(PolicyError::Failed(format!(
                "the network takes {} inputs but the episode's observation has {size} values \
                 (laser.beams, team.neighbours and observation.history set it)",
                self.mlp.inputs(),
            )));
        }
        Ok(())
    }
}

/// The action `rule` picks from the network's `outputs`, drawing from `rng` when it samples.
fn choose(rule: DecisionRule, outputs: &[f32], rng: &mut crate::sim::Rng) -> DiscreteAction {
    match rule {
        DecisionRule::Argmax => DiscreteAction::ALL[network::argmax(outputs)],
        DecisionRule::Sample { temperature } => {
            let top = outputs.iter().copied().fold(f32::NEG_INFINITY, f32::max);
            // A network has one output per action (checked when it is made).
            let mut weights = [0f32; DiscreteAction::ALL.len()];
            for (w, v) in weights.iter_mut().zip(outputs) {
                *w = ((v - top) / temperature).exp();
            }
            let mut u = rand::Rng::random::<f32>(rng) * weights.iter().sum::<f32>();
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
    }
}

impl Policy for MlpPolicy {
    fn reset(&mut self, _world: &World, episode: &Episode) -> Result<(), PolicyError> {
        self.check(episode)?;
        self.rng = crate::sim::stream(episode.seed(), crate::sim::Stream::Policy);
        Ok(())
    }

    fn act(&mut self, episode: &Episode) -> Result<Decision, PolicyError> {
        let outputs = self
            .mlp
            .forward_into(episode.observation(), &mut self.scratch);
        Ok(Decision::Act(
            choose(self.rule, outputs, &mut self.rng).into(),
        ))
    }

    fn reset_lane(
        &mut self,
        lane: usize,
        _world: &World,
        episode: &Episode,
    ) -> Result<(), PolicyError> {
        self.check(episode)?;
        if self.lane_rngs.len() <= lane {
            self.lane_rngs.resize_with(lane + 1, || {
                crate::sim::stream(0, crate::sim::Stream::Policy)
            });
        }
        self.lane_rngs[lane] = crate::sim::stream(episode.seed(), crate::sim::Stream::Policy);
        Ok(())
    }

    fn act_lanes(
        &mut self,
        episodes: &[(usize, &Episode)],
        decisions: &mut Vec<Decision>,
    ) -> Result<(), (usize, PolicyError)> {
        self.rows.clear();
        for (_, episode) in episodes {
            self.rows.extend_from_slice(episode.observation());
        }
        let width = DiscreteAction::ALL.len();
        let outputs = self
            .mlp
            .forward_rows_into(&self.rows, episodes.len(), &mut self.scratch);
        for (k, ((lane, _), row)) in episodes.iter().zip(outputs.chunks_exact(width)).enumerate() {
            let rng = self.lane_rngs.get_mut(*lane).ok_or_else(|| {
                (
                    k,
                    PolicyError::Failed(format!("lane {lane} was never reset")),
                )
            })?;
            decisions.push(Decision::Act(choose(self.rule, row, rng).into()));
        }
        Ok(())
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
                     configuration's observation has {observation_size} values (laser.beams, \
                     team.neighbours and observation.history set it): run it with the \
                     configuration it was trained with",
                    mlp.inputs(),
                    mlp.metadata.get("observation").map_or("", String::as_str),
                ),
            });
        }
        Ok(Self {
            mlp: Arc::new(mlp),
            name: format!("mlp:{}", path.display()),
        })
    }

    /// Policies running `mlp` (a network in memory), named `name`.
    pub fn new(mlp: Mlp, name: impl Into<String>) -> Self {
        Self {
            mlp: Arc::new(mlp),
            name: name.into(),
        }
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

    fn side_by_side(&self) -> usize {
        SIDE_BY_SIDE
    }

    fn seeds_seen(&self) -> SeedRanges {
        self.mlp.seeds_seen()
    }
}

#[cfg(test)]
mod tests {
    use super::network::OBSERVATION_LAYOUT;
    use super::*;
    use nalgebra::{DMatrix, DVector};
    use safetensors::tensor::TensorView;
    use safetensors::SafeTensors;
    use std::collections::HashMap;

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

    /// The forward pass as it was written with nalgebra's `gemv`, for comparison.
    fn gemv_forward(m: &Mlp, observation: &[f32]) -> Vec<f32> {
        let mut x = DVector::from_column_slice(observation);
        for (i, l) in m.layers.iter().enumerate() {
            let mut y = l.bias.clone();
            y.gemv(1.0, &l.weight, &x, 1.0);
            if i + 1 < m.layers.len() {
                let mut v: Vec<f32> = y.iter().copied().collect();
                m.activation.apply(&mut v);
                y = DVector::from_vec(v);
            }
            x = y;
        }
        x.iter().copied().collect()
    }

    /// A network of layer widths `sizes` (inputs first) with random weights and biases.
    fn random_mlp(
        rng: &mut rand_chacha::ChaCha8Rng,
        sizes: &[usize],
        activation: Activation,
    ) -> Mlp {
        use rand::Rng;
        let layers = sizes
            .windows(2)
            .map(|w| Layer {
                weight: DMatrix::from_fn(w[1], w[0], |_, _| rng.random_range(-0.5..0.5)),
                bias: DVector::from_fn(w[1], |_, _| rng.random_range(-0.1..0.1)),
            })
            .collect();
        Mlp::new(layers, activation, HashMap::new()).unwrap()
    }

    #[test]
    fn the_allocation_free_pass_gives_gemvs_bits() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
        // The shipped network's shape, random weights, each activation.
        let sizes = [18, 64, 128, 64, 32, 8, 3];
        for activation in [
            Activation::Relu,
            Activation::Tanh,
            Activation::LeakyRelu(RRELU_SLOPE),
        ] {
            let m = random_mlp(&mut rng, &sizes, activation);
            let mut scratch = Scratch::default();
            for _ in 0..200 {
                let x: Vec<f32> = (0..18).map(|_| rng.random_range(0.0..1.0)).collect();
                let want = gemv_forward(&m, &x);
                let got = m.forward_into(&x, &mut scratch);
                let bits = |v: &[f32]| v.iter().map(|f| f.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(got), bits(&want));
            }
        }
    }

    #[test]
    fn rows_together_give_each_rows_own_bits() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(2);
        // The shipped shape, and shapes whose widths leave every kind of remainder (lanes of
        // 4 and 8, a part of a vector, a single output), and a network of no inputs (its
        // biases alone).
        let shapes: [&[usize]; 4] = [
            &[18, 64, 128, 64, 32, 8, 3],
            &[5, 17, 1, 23, 3],
            &[33, 40, 9, 16, 3],
            &[0, 20, 3],
        ];
        for sizes in shapes {
            let m = random_mlp(&mut rng, sizes, Activation::LeakyRelu(RRELU_SLOPE));
            let (ins, outs) = (sizes[0], *sizes.last().unwrap());
            let (mut one, mut many) = (Scratch::default(), Scratch::default());
            for rows in [0, 1, 2, 3, 4, 5, 6, 7, 8, 10, 13] {
                let x: Vec<f32> = (0..rows * ins)
                    .map(|_| rng.random_range(-1.0..1.0))
                    .collect();
                let got = m.forward_rows_into(&x, rows, &mut many).to_vec();
                assert_eq!(got.len(), rows * outs);
                for r in 0..rows {
                    let want = m.forward_into(&x[r * ins..(r + 1) * ins], &mut one);
                    let bits = |v: &[f32]| v.iter().map(|f| f.to_bits()).collect::<Vec<_>>();
                    assert_eq!(
                        bits(&got[r * outs..(r + 1) * outs]),
                        bits(want),
                        "{sizes:?}, {rows} rows, row {r}"
                    );
                }
            }
        }
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
