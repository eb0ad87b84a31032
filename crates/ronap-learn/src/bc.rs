//! Behaviour cloning (the paper's Algorithm 2): a classifier from observation to the expert's
//! action, trained with cross-entropy and Adam on mini-batches, reported on a held-out split.

use crate::net::{argmax_rows, batch, Net, TrainActivation};
use crate::LearnError;
use candle_core::{Device, Tensor};
use candle_nn::optim::Optimizer;
use rand::seq::SliceRandom;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use ronap_core::io::DataSet;
use ronap_core::policy::Mlp;
use std::collections::HashMap;

/// Training settings. The defaults are the original's network and optimiser, with more data per
/// batch (see the fields).
#[derive(Clone, Debug, PartialEq)]
pub struct BcOptions {
    /// Hidden layer widths (the original: 64, 128, 64, 32, 8).
    pub hidden: Vec<usize>,
    /// Hidden activation (the original: RReLU).
    pub activation: TrainActivation,
    /// Adam's learning rate (the original: 0.0008).
    pub learning_rate: f64,
    /// Rows per mini-batch (the original: 10).
    pub batch: usize,
    /// Passes over the training rows (the original: 1000).
    pub epochs: usize,
    /// Fraction of rows to train on; the rest are the test split (the original: 0.8).
    pub train_fraction: f64,
    /// Seed of the split, the initial weights, the batch order and RReLU's slopes.
    pub seed: u64,
}

impl Default for BcOptions {
    fn default() -> Self {
        Self {
            hidden: vec![64, 128, 64, 32, 8],
            activation: TrainActivation::Rrelu,
            learning_rate: 0.0008,
            batch: 10,
            epochs: 1000,
            train_fraction: 0.8,
            seed: 0,
        }
    }
}

/// How training stood after an epoch.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EpochReport {
    /// 1-based epoch.
    pub epoch: usize,
    /// Mean cross-entropy over the epoch's batches.
    pub loss: f64,
    /// Accuracy on the training rows (inference mode).
    pub train_accuracy: f64,
    /// Accuracy on the test rows; NaN when there are none.
    pub test_accuracy: f64,
}

/// Rows of `data` at `rows` as a tensor of observations and one of action indices.
fn gather(data: &DataSet, rows: &[usize]) -> Result<(Tensor, Tensor), LearnError> {
    let mut x = Vec::with_capacity(rows.len() * data.width);
    let mut y = Vec::with_capacity(rows.len());
    for &r in rows {
        x.extend_from_slice(data.observation(r));
        y.push(u32::from(data.actions[r]));
    }
    Ok((
        batch(x, data.width)?,
        Tensor::from_vec(y, rows.len(), &Device::Cpu)?,
    ))
}

/// Fraction of `rows` whose argmax output is the recorded action.
fn accuracy(net: &Net, data: &DataSet, rows: &[usize]) -> Result<f64, LearnError> {
    if rows.is_empty() {
        return Ok(f64::NAN);
    }
    let mut right = 0usize;
    for chunk in rows.chunks(8192) {
        let (x, _) = gather(data, chunk)?;
        let predicted = argmax_rows(&net.forward(&x, None)?)?;
        right += predicted
            .iter()
            .zip(chunk)
            .filter(|(p, &r)| **p == u32::from(data.actions[r]))
            .count();
    }
    Ok(right as f64 / rows.len() as f64)
}

/// Trains a classifier on `data`. `on_epoch` hears after every epoch (and `on_batch` after every
/// batch, with the batches done so far); either returning `false` stops training there. Returns
/// the network, with `metadata` added to its file's, and the epoch reports.
pub fn train(
    data: &DataSet,
    options: &BcOptions,
    metadata: HashMap<String, String>,
    on_batch: &mut dyn FnMut(usize) -> bool,
    on_epoch: &mut dyn FnMut(&EpochReport) -> bool,
) -> Result<(Mlp, Vec<EpochReport>), LearnError> {
    if data.len() < 2 {
        return Err(LearnError::Data(format!(
            "{} usable rows; need at least 2",
            data.len()
        )));
    }
    let mut rng = ChaCha8Rng::seed_from_u64(options.seed);
    let mut rows: Vec<usize> = (0..data.len()).collect();
    rows.shuffle(&mut rng);
    let n_train = ((data.len() as f64 * options.train_fraction).round() as usize).min(data.len());
    if n_train == 0 {
        return Err(LearnError::Data(format!(
            "train_fraction {} of {} rows leaves no row to train on",
            options.train_fraction,
            data.len()
        )));
    }
    let (train_rows, test_rows) = rows.split_at(n_train);
    let mut train_rows = train_rows.to_vec();

    let net = Net::policy(data.width, &options.hidden, options.activation, &mut rng)?;
    let mut optimiser = net.adam(options.learning_rate)?;
    let mut reports = Vec::new();
    let mut batches = 0usize;
    'epochs: for epoch in 1..=options.epochs {
        train_rows.shuffle(&mut rng);
        let mut loss_sum = 0.0;
        let mut count = 0usize;
        for chunk in train_rows.chunks(options.batch.max(1)) {
            let (x, y) = gather(data, chunk)?;
            let logits = net.forward(&x, Some(&mut rng))?;
            let loss = candle_nn::loss::cross_entropy(&logits, &y)?;
            optimiser.backward_step(&loss)?;
            loss_sum += f64::from(loss.to_scalar::<f32>()?);
            count += 1;
            batches += 1;
            if !on_batch(batches) {
                break 'epochs;
            }
        }
        let report = EpochReport {
            epoch,
            loss: loss_sum / count.max(1) as f64,
            train_accuracy: accuracy(&net, data, &train_rows)?,
            test_accuracy: accuracy(&net, data, test_rows)?,
        };
        if !report.loss.is_finite() {
            return Err(LearnError::Diverged(format!(
                "the loss became {} in epoch {epoch}; lower the learning rate",
                report.loss
            )));
        }
        reports.push(report);
        if !on_epoch(&report) {
            break;
        }
    }
    Ok((net.to_mlp(metadata)?, reports))
}

#[cfg(test)]
mod tests {
    use super::*;
    use ronap_core::sim::DiscreteAction;

    /// A rule an MLP can learn: turn towards the goal unless it is ahead.
    fn rule_data(n: usize, seed: u64) -> DataSet {
        use rand::Rng as _;
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut data = DataSet::new(18);
        for _ in 0..n {
            let mut o: Vec<f32> = (0..17).map(|_| rng.random_range(0.0..1.0)).collect();
            let direction: f32 = rng.random_range(0.0..1.0);
            o.push(direction);
            let action = if !(0.05..=0.95).contains(&direction) {
                DiscreteAction::Ahead
            } else if direction < 0.5 {
                DiscreteAction::Left
            } else {
                DiscreteAction::Right
            };
            data.push(&o, action);
        }
        data
    }

    #[test]
    fn learns_a_rule_well_beyond_chance() {
        let data = rule_data(3000, 1);
        let options = BcOptions {
            hidden: vec![32, 32],
            activation: TrainActivation::Relu,
            learning_rate: 0.01,
            batch: 64,
            epochs: 15,
            ..BcOptions::default()
        };
        let (mlp, reports) = train(&data, &options, HashMap::new(), &mut |_| true, &mut |_| {
            true
        })
        .unwrap();
        let last = reports.last().unwrap();
        assert!(last.test_accuracy > 0.9, "{last:?}");
        // The saved network agrees with the trained one on fresh rows.
        let fresh = rule_data(500, 2);
        let right = (0..fresh.len())
            .filter(|&i| mlp.action(fresh.observation(i)) as u8 == fresh.actions[i])
            .count();
        assert!(right > 450, "{right} of 500");
    }
}

#[cfg(test)]
mod expert_data {
    use super::*;
    use ronap_core::collect::{collect, Collection, Posing};
    use ronap_core::eval::Evaluator;
    use ronap_core::{Scenes, SimConfig};
    use std::sync::atomic::AtomicBool;

    #[test]
    fn beats_the_majority_class_on_held_out_expert_rows() {
        // Re-posed rows (the paper's mode): no class dominates, unlike rows along expert paths,
        // which are two-thirds AHEAD.
        let evaluator = Evaluator::new(
            SimConfig::default().validate().unwrap(),
            Scenes::MazePerSeed,
        );
        let mut data = DataSet::new(18);
        let cancel = AtomicBool::new(false);
        let request = Collection {
            evaluator: &evaluator,
            per_episode: 500,
            max_samples: 6000,
            posing: Posing::Repose,
            driver: None,
            threads: 0,
            cancel: &cancel,
        };
        collect(&request, 1_000_000.., &mut |_, samples| {
            for s in samples {
                data.push(&s.observation(50.0), s.action);
            }
            true
        })
        .unwrap();
        assert_eq!(data.len(), 6000);
        let majority = *data.action_counts().iter().max().unwrap() as f64 / data.len() as f64;
        let options = BcOptions {
            hidden: vec![64, 64],
            activation: TrainActivation::Relu,
            learning_rate: 0.003,
            batch: 64,
            epochs: 30,
            ..BcOptions::default()
        };
        let (_, reports) = train(&data, &options, HashMap::new(), &mut |_| true, &mut |_| {
            true
        })
        .unwrap();
        let test = reports.last().unwrap().test_accuracy;
        assert!(
            test > majority + 0.05,
            "test accuracy {test:.3} vs majority class {majority:.3}"
        );
    }
}
