//! Deep Q-learning (the paper's Algorithm 1): epsilon-greedy episodes on the SPEC reward, a
//! replay memory, mini-batches, a target network refreshed every F updates, mean-squared loss.
//!
//! The environment side runs `envs` episodes side by side, stepped on every core with the core's
//! nalgebra copy of the network (refreshed after each update); the updates run in candle. Each
//! episode's exploration draws from its own seed's policy stream and the replay memory fills in
//! environment order, so a run is the same on any number of threads.
//!
//! An episode that [`Status::is_terminated`] (success, a collision under `on_collision =
//! terminate`, the summed reward reaching `reward_min`) gets target `y = r`, as Algorithm 1 has
//! it. A time-out also ends the episode but is not a property of the state, so its target still
//! bootstraps (`y = r + gamma max Q_target`), as time limits should.

use crate::net::{batch, Net, TrainActivation};
use crate::LearnError;
use candle_core::{Device, Tensor, D};
use candle_nn::optim::Optimizer;
use rand::{Rng as _, SeedableRng};
use rand_chacha::ChaCha8Rng;
use ronap_core::eval::Evaluator;
use ronap_core::policy::mlp::Mlp;
use ronap_core::run::batch::{Autoreset, Batch, BatchOptions, SeedOrder};
use ronap_core::{Action, DiscreteAction, Status};
use std::collections::{HashMap, VecDeque};

/// Training settings.
#[derive(Clone, Debug, PartialEq)]
pub struct DqnOptions {
    /// Hidden layer widths.
    pub hidden: Vec<usize>,
    /// Hidden activation.
    pub activation: TrainActivation,
    /// Adam's learning rate.
    pub learning_rate: f64,
    /// Discount gamma.
    pub gamma: f64,
    /// Transitions per update (B).
    pub batch: usize,
    /// Replay memory size (D), transitions; the oldest go first.
    pub replay_capacity: usize,
    /// Updates between target-network refreshes (F).
    pub target_update: usize,
    /// Exploration at the start.
    pub epsilon_start: f64,
    /// Exploration at the end of the decay.
    pub epsilon_end: f64,
    /// Environment steps over which epsilon falls linearly.
    pub epsilon_decay_steps: u64,
    /// Episodes run side by side.
    pub envs: usize,
    /// Environment steps in all.
    pub steps: u64,
    /// Updates after each round of `envs` environment steps.
    pub updates_per_round: usize,
    /// Transitions in memory before updates start.
    pub warmup: usize,
    /// Use the online network to choose the next action in the target (Double DQN).
    pub double: bool,
    /// Seed of the initial weights and the replay sampling.
    pub seed: u64,
    /// Episode seeds are `seed_start`, `seed_start + 1`, ...: keep them apart from evaluation seeds.
    pub seed_start: u64,
}

impl Default for DqnOptions {
    fn default() -> Self {
        Self {
            hidden: vec![128, 128],
            activation: TrainActivation::Relu,
            learning_rate: 5e-4,
            gamma: 0.99,
            batch: 128,
            replay_capacity: 200_000,
            target_update: 1000,
            epsilon_start: 1.0,
            epsilon_end: 0.05,
            epsilon_decay_steps: 300_000,
            envs: 32,
            steps: 1_000_000,
            updates_per_round: 1,
            warmup: 5_000,
            double: true,
            seed: 0,
            seed_start: 1_000_000,
        }
    }
}

/// How training stood at a report.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DqnReport {
    /// Environment steps so far.
    pub steps: u64,
    /// Finished episodes so far.
    pub episodes: u64,
    /// Mean return of the last (up to) 100 finished episodes (0 before any has finished).
    pub mean_return: f64,
    /// Success rate of the last (up to) 100 finished episodes.
    pub success_rate: f64,
    /// Current exploration rate.
    pub epsilon: f64,
    /// Mean loss since the last report (NaN before updates start).
    pub loss: f64,
}

/// The replay memory: a ring of transitions.
struct Replay {
    width: usize,
    capacity: usize,
    observations: Vec<f32>,
    next_observations: Vec<f32>,
    actions: Vec<u32>,
    rewards: Vec<f32>,
    terminal: Vec<f32>,
    next: usize,
}

impl Replay {
    fn new(width: usize, capacity: usize) -> Self {
        Self {
            width,
            capacity,
            observations: Vec::new(),
            next_observations: Vec::new(),
            actions: Vec::new(),
            rewards: Vec::new(),
            terminal: Vec::new(),
            next: 0,
        }
    }

    fn len(&self) -> usize {
        self.actions.len()
    }

    fn push(&mut self, t: &Transition) {
        let w = self.width;
        if self.len() < self.capacity {
            self.observations.extend_from_slice(&t.observation);
            self.next_observations
                .extend_from_slice(&t.next_observation);
            self.actions.push(t.action);
            self.rewards.push(t.reward);
            self.terminal.push(f32::from(u8::from(t.terminal)));
        } else {
            let i = self.next;
            self.observations[i * w..(i + 1) * w].copy_from_slice(&t.observation);
            self.next_observations[i * w..(i + 1) * w].copy_from_slice(&t.next_observation);
            self.actions[i] = t.action;
            self.rewards[i] = t.reward;
            self.terminal[i] = f32::from(u8::from(t.terminal));
        }
        self.next = (self.next + 1) % self.capacity;
    }

    /// A random mini-batch: observations, actions, rewards, next observations, terminal flags.
    fn sample(
        &self,
        n: usize,
        rng: &mut ChaCha8Rng,
    ) -> Result<(Tensor, Tensor, Tensor, Tensor, Tensor), LearnError> {
        let w = self.width;
        let mut o = Vec::with_capacity(n * w);
        let mut o2 = Vec::with_capacity(n * w);
        let (mut a, mut r, mut t) = (Vec::new(), Vec::new(), Vec::new());
        for _ in 0..n {
            let i = rng.random_range(0..self.len());
            o.extend_from_slice(&self.observations[i * w..(i + 1) * w]);
            o2.extend_from_slice(&self.next_observations[i * w..(i + 1) * w]);
            a.push(self.actions[i]);
            r.push(self.rewards[i]);
            t.push(self.terminal[i]);
        }
        let cpu = &Device::Cpu;
        Ok((
            batch(o, w)?,
            Tensor::from_vec(a, (n, 1), cpu)?,
            Tensor::from_vec(r, n, cpu)?,
            batch(o2, w)?,
            Tensor::from_vec(t, n, cpu)?,
        ))
    }
}

struct Transition {
    observation: Vec<f32>,
    action: u32,
    reward: f32,
    next_observation: Vec<f32>,
    terminal: bool,
}

/// The mean of `count` losses summing to `sum`; NaN for none.
fn mean_loss(sum: f64, count: usize) -> f64 {
    if count > 0 {
        sum / count as f64
    } else {
        f64::NAN
    }
}

/// Trains a Q-network on episodes from `evaluator`. `on_report` hears every `report_every`
/// environment steps and at the end; returning `false` stops training. `threads` is the number
/// of environment workers (0: all cores). Returns the network with `metadata` added to its file's.
pub fn train(
    evaluator: &Evaluator,
    options: &DqnOptions,
    threads: usize,
    metadata: HashMap<String, String>,
    report_every: u64,
    on_report: &mut dyn FnMut(&DqnReport) -> bool,
) -> Result<Mlp, LearnError> {
    let mut batch = Batch::new(
        evaluator.worlds().clone(),
        BatchOptions {
            envs: options.envs.max(1),
            threads,
            autoreset: Autoreset::SameStep,
            seed_order: SeedOrder::InOrder,
        },
    )?;
    batch.reset(options.seed_start)?;
    let width = batch.observation_size();
    let mut rng = ChaCha8Rng::seed_from_u64(options.seed);
    let online = Net::policy(width, &options.hidden, options.activation, &mut rng)?;
    let target = Net::policy(width, &options.hidden, options.activation, &mut rng)?;
    target.copy_from(&online)?;
    let mut optimiser = online.adam(options.learning_rate)?;
    let mut acting = online.to_mlp(HashMap::new())?;
    let mut replay = Replay::new(width, options.replay_capacity.max(options.batch));
    let mut recent: VecDeque<(f64, bool)> = VecDeque::with_capacity(100);
    let (mut steps, mut episodes, mut updates) = (0u64, 0u64, 0usize);
    let (mut loss_sum, mut loss_count) = (0.0, 0usize);
    let mut next_report = report_every.max(1);
    let gamma = options.gamma;
    let epsilon_at = |steps: u64| {
        let f = (steps as f64 / options.epsilon_decay_steps.max(1) as f64).min(1.0);
        options.epsilon_start + f * (options.epsilon_end - options.epsilon_start)
    };
    let report = |steps, episodes, recent: &VecDeque<(f64, bool)>, loss: f64| {
        let n = recent.len().max(1) as f64;
        DqnReport {
            steps,
            episodes,
            mean_return: recent.iter().map(|r| r.0).sum::<f64>() / n,
            success_rate: recent.iter().filter(|r| r.1).count() as f64 / n,
            epsilon: epsilon_at(steps),
            loss,
        }
    };
    while steps < options.steps {
        let epsilon = epsilon_at(steps);
        let before = batch.observations().to_vec();
        // Epsilon-greedy, exploring from the episode seed's policy stream.
        batch.step(&|_, episode, rng| {
            let action = if rng.random::<f64>() < epsilon {
                DiscreteAction::ALL[rng.random_range(0..3)]
            } else {
                acting.action(episode.observation())
            };
            Action::from(action)
        })?;
        for (i, s) in batch.steps().iter().enumerate() {
            let done = s.status.is_done();
            let next = if done {
                batch.final_observations()
            } else {
                batch.observations()
            };
            let row = i * width..(i + 1) * width;
            replay.push(&Transition {
                observation: before[row.clone()].to_vec(),
                action: s.action.and_then(Action::discrete).map_or(0, |a| a as u32),
                reward: s.reward as f32,
                next_observation: next[row].to_vec(),
                terminal: s.status.is_terminated(),
            });
            steps += 1;
            if done {
                episodes += 1;
                if recent.len() == 100 {
                    recent.pop_front();
                }
                recent.push_back((s.total_reward, s.status == Status::Success));
            }
        }
        if replay.len() >= options.warmup.max(options.batch) {
            for _ in 0..options.updates_per_round {
                let (o, a, r, o2, terminal) = replay.sample(options.batch, &mut rng)?;
                let next_q = target.forward(&o2, None)?.detach();
                let best_next = if options.double {
                    let choice = online
                        .forward(&o2, None)?
                        .detach()
                        .argmax_keepdim(D::Minus1)?;
                    next_q.gather(&choice, D::Minus1)?.squeeze(D::Minus1)?
                } else {
                    next_q.max(D::Minus1)?
                };
                let y = (r + (best_next * terminal.affine(-gamma, gamma)?)?)?.detach();
                let q = online
                    .forward(&o, None)?
                    .gather(&a, D::Minus1)?
                    .squeeze(D::Minus1)?;
                let loss = candle_nn::loss::mse(&q, &y)?;
                optimiser.backward_step(&loss)?;
                let l = f64::from(loss.to_scalar::<f32>()?);
                if !l.is_finite() {
                    return Err(LearnError::Diverged(format!(
                        "the loss became {l} after {updates} updates; lower the learning rate"
                    )));
                }
                loss_sum += l;
                loss_count += 1;
                updates += 1;
                if updates % options.target_update.max(1) == 0 {
                    target.copy_from(&online)?;
                }
            }
            acting = online.to_mlp(HashMap::new())?;
        }
        if steps >= next_report {
            next_report += report_every.max(1);
            let loss = mean_loss(loss_sum, loss_count);
            (loss_sum, loss_count) = (0.0, 0);
            if !on_report(&report(steps, episodes, &recent, loss)) {
                break;
            }
        }
    }
    // The last stretch, unless a report just covered it.
    if next_report - report_every.max(1) < steps {
        let loss = mean_loss(loss_sum, loss_count);
        on_report(&report(steps, episodes, &recent, loss));
    }
    online.to_mlp(metadata)
}

#[cfg(test)]
mod tests {
    use super::*;
    use ronap_core::sim::world::Scenes;
    use ronap_core::SimConfig;

    /// A small open room where the goal is always in reach: DQN must learn to head for it.
    fn open_room() -> Evaluator {
        let mut c = SimConfig::default();
        c.maze.cols = 2;
        c.maze.rows = 2;
        c.maze.loops = 1.0;
        c.episode.min_goal_distance_px = 60.0;
        c.episode.max_steps = 200;
        Evaluator::new(c.validate().unwrap(), Scenes::MazePerSeed)
    }

    #[test]
    fn same_network_on_any_thread_count() {
        let options = DqnOptions {
            hidden: vec![16],
            steps: 2_000,
            warmup: 256,
            batch: 32,
            envs: 8,
            ..DqnOptions::default()
        };
        let run = |threads| {
            train(
                &open_room(),
                &options,
                threads,
                HashMap::new(),
                1000,
                &mut |_| true,
            )
            .unwrap()
            .layers
        };
        // Bit for bit: the layers' f32 weights compare exactly.
        assert_eq!(run(1), run(2));
    }
}
