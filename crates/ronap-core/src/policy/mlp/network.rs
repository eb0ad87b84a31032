//! The network: layers, activations and the forward pass, with nalgebra; and how its outputs
//! become an action ([`DecisionRule`]).

use crate::sim::DiscreteAction;
use nalgebra::{DMatrix, DVector};
use std::collections::HashMap;

/// The `format` metadata value this version reads and writes.
pub const FORMAT: &str = "ronap-mlp/1";
/// The `observation` metadata value for the observation of docs/model.md "Observation".
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

    /// Applies the activation to every value.
    #[inline(always)]
    pub(crate) fn apply(self, v: &mut [f32]) {
        match self {
            Self::Relu => v.iter_mut().for_each(|x| *x = x.max(0.0)),
            Self::Tanh => v.iter_mut().for_each(|x| *x = x.tanh()),
            // A select rather than a branch: the sign of a hidden unit is a coin toss to the
            // branch predictor, and the select vectorises.
            Self::LeakyRelu(s) => v
                .iter_mut()
                .for_each(|x| *x = if *x < 0.0 { *x * s } else { *x }),
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
        DVector::from_column_slice(self.forward_into(observation, &mut Scratch::default()))
    }

    /// The network's outputs for `observation`, computed in `scratch` (no allocation once it
    /// has grown to the widest layer). Each layer adds the weights' columns, scaled by the
    /// inputs, to the bias in input order: the same sums, bit for bit, as nalgebra's `gemv`,
    /// in a loop the compiler vectorises over the outputs.
    pub fn forward_into<'s>(&self, observation: &[f32], scratch: &'s mut Scratch) -> &'s [f32] {
        let Scratch { x, y } = scratch;
        x.clear();
        x.extend_from_slice(observation);
        crate::geometry::WIDEST.dispatch(ForwardRows {
            mlp: self,
            rows: 1,
            x,
            y,
        });
        x
    }

    /// The network's outputs for `rows` observations at once: `observations` holds `rows` rows
    /// of [`Mlp::inputs`] values, and the result as many rows of outputs, each row bit for bit
    /// what [`Mlp::forward_into`] gives for it. Rows go through in fours, so each weight loaded
    /// serves four sums, and a block of outputs goes through every row before the next block,
    /// so its weights stay in the first-level cache (on the development machine, 680-715 ns a
    /// row for sixteen rows against 970-1000 ns for one observation alone).
    ///
    /// # Panics
    /// If `observations` does not hold `rows` rows of [`Mlp::inputs`] values.
    pub fn forward_rows_into<'s>(
        &self,
        observations: &[f32],
        rows: usize,
        scratch: &'s mut Scratch,
    ) -> &'s [f32] {
        assert_eq!(
            observations.len(),
            rows * self.inputs(),
            "{rows} rows of {} inputs",
            self.inputs()
        );
        let Scratch { x, y } = scratch;
        x.clear();
        x.extend_from_slice(observations);
        crate::geometry::WIDEST.dispatch(ForwardRows {
            mlp: self,
            rows,
            x,
            y,
        });
        x
    }

    /// The action with the largest output (the first of equals).
    pub fn action(&self, observation: &[f32]) -> DiscreteAction {
        self.action_into(observation, &mut Scratch::default())
    }

    /// [`Mlp::action`], computed in `scratch`.
    pub fn action_into(&self, observation: &[f32], scratch: &mut Scratch) -> DiscreteAction {
        DiscreteAction::ALL[argmax(self.forward_into(observation, scratch))]
    }
}

/// The index of the largest of `outputs` (the first of equals; 0 for none).
pub(crate) fn argmax(outputs: &[f32]) -> usize {
    let mut best = 0;
    for i in 1..outputs.len() {
        if outputs[i] > outputs[best] {
            best = i;
        }
    }
    best
}

/// The layers of [`Mlp::forward_rows_into`] (and of [`Mlp::forward_into`], one row), compiled
/// once per instruction set (pulp picks the widest the processor has, AVX-512 included: on the
/// development machine's AMD EPYC, sixteen rows 3-4% faster than under AVX2, 6-11% with
/// [`add_narrow`]; the same bits):
/// `x` holds `rows` rows of input and, at the end, of output. A single row goes through
/// [`add_columns`], whose blocks of up to eight vectors suit one row best; more go through
/// [`add_rows`].
struct ForwardRows<'a> {
    mlp: &'a Mlp,
    rows: usize,
    x: &'a mut Vec<f32>,
    y: &'a mut Vec<f32>,
}

impl pulp::WithSimd for ForwardRows<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, simd: S) {
        let Self { mlp, rows, x, y } = self;
        let last = mlp.layers.len() - 1;
        for (i, l) in mlp.layers.iter().enumerate() {
            let (ins, outs) = (l.weight.ncols(), l.weight.nrows());
            y.clear();
            for _ in 0..rows {
                y.extend_from_slice(l.bias.as_slice());
            }
            let weights = l.weight.as_slice();
            if rows == 1 {
                add_columns(simd, y, x, weights, outs);
            } else {
                add_rows(simd, y, x, Weights { weights, ins, outs }, rows);
            }
            if i < last {
                mlp.activation.apply(y);
            }
            std::mem::swap(x, y);
        }
    }
}

/// [`add_columns`] for the `rows` rows of the row-major `x` (`ins` values a row) into those of
/// `y` (`outs` a row), every output's sum in the same order as [`add_columns`] (so the same
/// bits). Block by block of outputs (two vectors, then one), each block for every row in turn,
/// four rows at a time: each weight loaded serves four rows, and a block's weights (a few
/// kilobytes) stay in the first-level cache for all the rows.
#[inline(always)]
fn add_rows<S: pulp::Simd>(simd: S, y: &mut [f32], x: &[f32], layer: Weights, rows: usize) {
    let lanes = S::F32_LANES;
    let outs = layer.outs;
    let mut o = 0;
    while o + 2 * lanes <= outs {
        each_group(rows, |r, n| match n {
            4 => add_block::<S, 4, 2>(simd, y, x, layer, r, o),
            3 => add_block::<S, 3, 2>(simd, y, x, layer, r, o),
            2 => add_block::<S, 2, 2>(simd, y, x, layer, r, o),
            _ => add_block::<S, 1, 2>(simd, y, x, layer, r, o),
        });
        o += 2 * lanes;
    }
    while o + lanes <= outs {
        each_group(rows, |r, n| match n {
            4 => add_block::<S, 4, 1>(simd, y, x, layer, r, o),
            3 => add_block::<S, 3, 1>(simd, y, x, layer, r, o),
            2 => add_block::<S, 2, 1>(simd, y, x, layer, r, o),
            _ => add_block::<S, 1, 1>(simd, y, x, layer, r, o),
        });
        o += lanes;
    }
    // What is left of each row (less than a vector): eight outputs at a time, then the rest.
    while o < outs {
        let w = (outs - o).min(NARROW);
        each_group(rows, |r, n| match w {
            8 => add_narrow::<8>(y, x, layer, r..r + n, o),
            7 => add_narrow::<7>(y, x, layer, r..r + n, o),
            6 => add_narrow::<6>(y, x, layer, r..r + n, o),
            5 => add_narrow::<5>(y, x, layer, r..r + n, o),
            4 => add_narrow::<4>(y, x, layer, r..r + n, o),
            3 => add_narrow::<3>(y, x, layer, r..r + n, o),
            2 => add_narrow::<2>(y, x, layer, r..r + n, o),
            _ => add_narrow::<1>(y, x, layer, r..r + n, o),
        });
        o += w;
    }
}

/// Most outputs [`add_narrow`] takes at once.
const NARROW: usize = 8;

/// The `W` outputs from `o` of the rows `rows` (at most four), for what is left of a layer after
/// its whole vectors (all of a layer narrower than one: eight outputs under AVX-512, three for
/// the last layer): the rows' sums side by side, `W` to a row, in the same order as
/// [`add_columns`] (so the same bits), which the compiler vectorises over the `W` outputs. A row
/// at a time, each output's sum would be one chain of dependent adds.
#[inline(always)]
fn add_narrow<const W: usize>(
    y: &mut [f32],
    x: &[f32],
    layer: Weights,
    rows: std::ops::Range<usize>,
    o: usize,
) {
    let Weights { weights, ins, outs } = layer;
    let mut acc = [[0.0f32; W]; 4];
    for (a, r) in acc.iter_mut().zip(rows.clone()) {
        a.copy_from_slice(&y[r * outs + o..r * outs + o + W]);
    }
    let xs: [&[f32]; 4] = std::array::from_fn(|k| {
        let r = (rows.start + k).min(rows.end - 1);
        &x[r * ins..(r + 1) * ins]
    });
    for (j, column) in weights.chunks_exact(outs).take(ins).enumerate() {
        let w: &[f32; W] = column[o..o + W].try_into().expect("W weights");
        for (a, xk) in acc.iter_mut().zip(&xs) {
            let xj = xk[j];
            for (a, &w) in a.iter_mut().zip(w) {
                *a += xj * w;
            }
        }
    }
    for (a, r) in acc.iter().zip(rows) {
        y[r * outs + o..r * outs + o + W].copy_from_slice(a);
    }
}

/// A layer's column-major weights (column j holds the weights from input j) and its shape.
#[derive(Clone, Copy)]
struct Weights<'a> {
    weights: &'a [f32],
    ins: usize,
    outs: usize,
}

/// Calls `f(first, count)` for the rows `0..rows` in groups of four (the last group smaller).
#[inline(always)]
fn each_group(rows: usize, mut f: impl FnMut(usize, usize)) {
    let mut r = 0;
    while r < rows {
        let n = (rows - r).min(4);
        f(r, n);
        r += n;
    }
}

/// Adds the columns to the `V` vectors of outputs from `o` of the `R` rows from `r`: every
/// output's sum kept in a register across the inputs, each weight loaded once for the `R` rows.
#[inline(always)]
fn add_block<S: pulp::Simd, const R: usize, const V: usize>(
    simd: S,
    y: &mut [f32],
    x: &[f32],
    layer: Weights,
    r: usize,
    o: usize,
) {
    let Weights { weights, ins, outs } = layer;
    let n = V * S::F32_LANES;
    let xs: [&[f32]; R] = std::array::from_fn(|k| &x[(r + k) * ins..(r + k + 1) * ins]);
    let mut acc = [[simd.splat_f32s(0.0); V]; R];
    for (k, a) in acc.iter_mut().enumerate() {
        let row = (r + k) * outs + o;
        a.copy_from_slice(&S::as_simd_f32s(&y[row..row + n]).0[..V]);
    }
    // `take(ins)` tells the compiler every `j` is within each row (no bounds check).
    for (j, column) in weights.chunks_exact(outs).take(ins).enumerate() {
        let (w, _) = S::as_simd_f32s(&column[o..o + n]);
        for (a, xk) in acc.iter_mut().zip(&xs) {
            let xj = simd.splat_f32s(xk[j]);
            for (a, &w) in a.iter_mut().zip(w) {
                *a = simd.add_f32s(*a, simd.mul_f32s(xj, w));
            }
        }
    }
    for (k, a) in acc.iter().enumerate() {
        let row = (r + k) * outs + o;
        S::as_mut_simd_f32s(&mut y[row..row + n]).0[..V].copy_from_slice(a);
    }
}

/// `y += W x` for the column-major `weights` (column j holds the weights from input j), adding
/// the columns in input order. Outputs go in blocks of vectors held in registers across all the
/// inputs (8 vectors, then 4, 2, 1, then one output at a time), so each weight is loaded once
/// and each output stored once. Every output's sum keeps the same order, and multiplies and adds
/// stay separate (no fused multiply-add), so every instruction set gives the same bits.
#[inline(always)]
fn add_columns<S: pulp::Simd>(simd: S, y: &mut [f32], x: &[f32], weights: &[f32], outputs: usize) {
    // One row: `x` is its inputs and `y` its outputs.
    let mut o = 0;
    let layer = Weights {
        weights,
        ins: x.len(),
        outs: outputs,
    };
    while o + 8 * S::F32_LANES <= outputs {
        add_block::<S, 1, 8>(simd, y, x, layer, 0, o);
        o += 8 * S::F32_LANES;
    }
    // Four at once where they fit: each output's sum is a chain of dependent adds, so fewer
    // than about four vectors side by side wait on the adder's latency.
    while o + 4 * S::F32_LANES <= outputs {
        add_block::<S, 1, 4>(simd, y, x, layer, 0, o);
        o += 4 * S::F32_LANES;
    }
    while o + 2 * S::F32_LANES <= outputs {
        add_block::<S, 1, 2>(simd, y, x, layer, 0, o);
        o += 2 * S::F32_LANES;
    }
    while o + S::F32_LANES <= outputs {
        add_block::<S, 1, 1>(simd, y, x, layer, 0, o);
        o += S::F32_LANES;
    }
    for o in o..outputs {
        let mut acc = y[o];
        for (&xj, column) in x.iter().zip(weights.chunks_exact(outputs)) {
            acc += xj * column[o];
        }
        y[o] = acc;
    }
}

/// Buffers for [`Mlp::forward_into`], reused from step to step.
#[derive(Clone, Debug, Default)]
pub struct Scratch {
    x: Vec<f32>,
    y: Vec<f32>,
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
