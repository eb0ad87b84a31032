//! Deep Q-learning (the paper's Algorithm 1): epsilon-greedy episodes on the model's reward, a
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
//!
//! On top of Algorithm 1's shape, each an option: n-step returns (the discounted rewards of up
//! to n steps, then `gamma^n max Q_target` of where they led, cut short where the episode ends),
//! Double-DQN targets, a dueling head, the Huber loss, clipping of the gradient's norm, a linear
//! learning-rate decay, prioritised replay (Schaul et al. 2016: proportional, with importance
//! weights) and validation on held-out seeds that keeps the best network.

use crate::net::{Net, TrainActivation};
use crate::replay::{NStep, Replay};
use crate::LearnError;
use candle_core::backprop::GradStore;
use candle_core::{Var, D};
use candle_nn::optim::Optimizer;
use rand::{Rng as _, SeedableRng};
use rand_chacha::ChaCha8Rng;
use ronap_core::eval::{EvalOptions, Evaluator, Outcome, Recording, Seeds};
use ronap_core::policy::{DecisionRule, Mlp, MlpFactory};
use ronap_core::run::{Autoreset, Batch, BatchOptions, SeedOrder};
use ronap_core::{Action, DiscreteAction, Status};
use std::collections::{HashMap, VecDeque};
use std::sync::atomic::AtomicBool;

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
    /// Soft target updates instead: after every update the target network moves this fraction
    /// of the way to the online one (`None`: a full copy every `target_update` updates).
    pub target_tau: Option<f64>,
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
    /// Steps summed before bootstrapping (n of n-step returns; 1: Algorithm 1's).
    pub n_step: usize,
    /// A dueling head (value and advantages; folds into a plain network when saved).
    pub dueling: bool,
    /// The loss on the TD error.
    pub loss: Loss,
    /// Largest norm of the gradient over all weights; larger ones are scaled down. `None`: no
    /// clipping.
    pub grad_clip: Option<f64>,
    /// The learning rate at the end, as a fraction of `learning_rate`: it falls linearly over
    /// training (1: constant).
    pub lr_end_fraction: f64,
    /// Prioritised replay, when set.
    pub prioritized: Option<Priorities>,
    /// Evaluation on held-out seeds during training, keeping the best network; `None`: the
    /// network at the end is the result.
    pub validation: Option<Validation>,
    /// Seed of the initial weights and the replay sampling.
    pub seed: u64,
    /// Episode seeds are `seed_start`, `seed_start + 1`, ...: keep them apart from evaluation seeds.
    pub seed_start: u64,
}

/// Evaluation during training (as Stable-Baselines3's `EvalCallback` keeps its best model):
/// every `every` environment steps the current network, with the decision rule it will be saved
/// with, runs `seeds` (apart from the training seeds and from the seeds it will be tested on);
/// the network with the highest success rate there (then SPL) is the one returned.
#[derive(Clone, Debug, PartialEq)]
pub struct Validation {
    /// Environment steps between evaluations.
    pub every: u64,
    /// The validation seeds.
    pub seeds: Seeds,
    /// How outputs become actions in the evaluation (the saved file's rule).
    pub decision: DecisionRule,
    /// The validation episodes' step limit (`None`: the training configuration's). Validating
    /// under the limit the policy will be evaluated with picks the network that does best there.
    pub max_steps: Option<u32>,
}

/// The loss on the TD error `d = Q(s, a) - y`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Loss {
    /// `d^2` (Algorithm 1's).
    Mse,
    /// `d^2 / 2` within 1 of 0, `|d| - 1/2` beyond: large errors do not swamp the update.
    Huber,
}

/// Proportional prioritised replay: transition `i` is drawn with probability `p_i^alpha / sum`,
/// `p_i = |d_i| + 1e-3` (new ones at the largest priority so far), and its loss weighted by
/// `(N P(i))^-beta` over the batch's largest, beta rising linearly to 1 over training.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Priorities {
    /// How strongly priorities skew sampling (0: uniform).
    pub alpha: f64,
    /// Importance-weight exponent at the start.
    pub beta_start: f64,
}

impl Default for Priorities {
    fn default() -> Self {
        Self {
            alpha: 0.6,
            beta_start: 0.4,
        }
    }
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
            target_tau: None,
            epsilon_start: 1.0,
            epsilon_end: 0.05,
            epsilon_decay_steps: 300_000,
            envs: 32,
            steps: 1_000_000,
            updates_per_round: 1,
            warmup: 5_000,
            double: true,
            n_step: 3,
            dueling: true,
            loss: Loss::Huber,
            grad_clip: Some(10.0),
            lr_end_fraction: 0.1,
            prioritized: None,
            validation: None,
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
    /// Current learning rate.
    pub learning_rate: f64,
    /// Success rate of the latest validation (NaN before the first, or without validation).
    pub validation_success: f64,
    /// The best validation success rate so far (NaN likewise).
    pub best_validation_success: f64,
}

/// The evaluator validation runs in when its step limit differs from training's (`None`: the
/// training evaluator serves).
fn validation_evaluator(
    evaluator: &Evaluator,
    validation: Option<&Validation>,
) -> Result<Option<Evaluator>, LearnError> {
    let Some(max_steps) = validation.and_then(|v| v.max_steps) else {
        return Ok(None);
    };
    let mut sim = evaluator.config().as_sim_config().clone();
    sim.episode.max_steps = max_steps;
    let config = sim
        .validate()
        .map_err(|e| LearnError::Data(format!("validation episodes: {e}")))?;
    Ok(Some(Evaluator::new(config, evaluator.scenes().clone())))
}

/// `seeds` in words: "seeds 500000..=500999" or "12 seeds".
fn describe_seeds(seeds: &Seeds) -> String {
    match seeds {
        Seeds::Range { start, count } if *count > 0 => {
            format!("seeds {start}..={}", start.saturating_add(count - 1))
        }
        Seeds::Range { .. } => "no seeds".to_string(),
        Seeds::List(list) => format!("{} seeds", list.len()),
    }
}

/// Runs `v.seeds` with `online`'s current network under `v.decision`: its success rate, mean
/// SPL and the network.
fn validate(
    evaluator: &Evaluator,
    online: &Net,
    v: &Validation,
    threads: usize,
) -> Result<(f64, f64, Mlp), LearnError> {
    let mlp = online.to_mlp(HashMap::from([("decision".to_string(), v.decision.name())]))?;
    let factory = MlpFactory::new(mlp.clone(), "validation");
    let options = EvalOptions {
        seeds: v.seeds.clone(),
        threads,
        recording: Recording::default(),
        steps_of: Vec::new(),
    };
    let run = evaluator
        .run(&factory, &options, &AtomicBool::new(false), &|_| {})
        .map_err(|e| LearnError::Network(format!("validation: {e}")))?;
    if let Some(e) = run.error {
        return Err(LearnError::Run(e));
    }
    let n = run.records.len().max(1) as f64;
    let success = run
        .records
        .iter()
        .filter(|r| r.outcome == Outcome::Success)
        .count() as f64
        / n;
    let spl = run.records.iter().map(|r| r.spl).sum::<f64>() / n;
    Ok((success, spl, mlp))
}

/// Scales the gradients in `grads` of `vars` down so that their joint norm is at most `max`.
fn clip_norm(grads: &mut GradStore, vars: &[Var], max: f64) -> Result<(), LearnError> {
    let mut squares = 0.0f64;
    for v in vars {
        if let Some(g) = grads.get(v) {
            squares += f64::from(g.sqr()?.sum_all()?.to_scalar::<f32>()?);
        }
    }
    let norm = squares.sqrt();
    if norm > max {
        let scale = max / norm;
        for v in vars {
            if let Some(g) = grads.remove(v) {
                grads.insert(v, (g * scale)?);
            }
        }
    }
    Ok(())
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
    let make = |rng: &mut ChaCha8Rng| {
        if options.dueling {
            Net::dueling_policy(width, &options.hidden, options.activation, rng)
        } else {
            Net::policy(width, &options.hidden, options.activation, rng)
        }
    };
    let online = make(&mut rng)?;
    let target = make(&mut rng)?;
    target.copy_from(&online)?;
    let mut optimiser = online.adam(options.learning_rate)?;
    let vars = online.vars();
    let mut acting = online.to_mlp(HashMap::new())?;
    let mut replay = Replay::new(
        width,
        options.replay_capacity.max(options.batch),
        options.prioritized.map(|p| p.alpha),
    );
    let mut pending: Vec<NStep> = (0..batch.len())
        .map(|_| NStep::new(options.n_step, options.gamma))
        .collect();
    let mut recent: VecDeque<(f64, bool)> = VecDeque::with_capacity(100);
    let (mut steps, mut episodes, mut updates) = (0u64, 0u64, 0usize);
    let (mut loss_sum, mut loss_count) = (0.0, 0usize);
    let mut next_report = report_every.max(1);
    let progress = |steps: u64| (steps as f64 / options.steps.max(1) as f64).min(1.0);
    let epsilon_at = |steps: u64| {
        let f = (steps as f64 / options.epsilon_decay_steps.max(1) as f64).min(1.0);
        options.epsilon_start + f * (options.epsilon_end - options.epsilon_start)
    };
    let lr_at = |steps: u64| {
        options.learning_rate * (1.0 + progress(steps) * (options.lr_end_fraction - 1.0))
    };
    let validation_evaluator = validation_evaluator(evaluator, options.validation.as_ref())?;
    let mut best: Option<(f64, f64, Mlp)> = None;
    let mut latest_validation = f64::NAN;
    let mut next_validation = options
        .validation
        .as_ref()
        .map_or(u64::MAX, |v| v.every.max(1));
    let report = |steps,
                  episodes,
                  recent: &VecDeque<(f64, bool)>,
                  loss: f64,
                  latest: f64,
                  best: &Option<(f64, f64, Mlp)>| {
        let n = recent.len().max(1) as f64;
        DqnReport {
            steps,
            episodes,
            mean_return: recent.iter().map(|r| r.0).sum::<f64>() / n,
            success_rate: recent.iter().filter(|r| r.1).count() as f64 / n,
            epsilon: epsilon_at(steps),
            loss,
            learning_rate: lr_at(steps),
            validation_success: latest,
            best_validation_success: best.as_ref().map_or(f64::NAN, |b| b.0),
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
            for t in pending[i].add(
                &before[row.clone()],
                s.action.and_then(Action::discrete).map_or(0, |a| a as u32),
                s.reward as f32,
                &next[row],
                s.status,
            ) {
                replay.push(&t);
            }
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
            optimiser.set_learning_rate(lr_at(steps));
            let beta = options.prioritized.map_or(1.0, |p| {
                p.beta_start + progress(steps) * (1.0 - p.beta_start)
            });
            for _ in 0..options.updates_per_round {
                let b = replay.sample(options.batch, beta, &mut rng)?;
                let next_q = target.forward(&b.next_observations, None)?.detach();
                let best_next = if options.double {
                    let choice = online
                        .forward(&b.next_observations, None)?
                        .detach()
                        .argmax_keepdim(D::Minus1)?;
                    next_q.gather(&choice, D::Minus1)?.squeeze(D::Minus1)?
                } else {
                    next_q.max(D::Minus1)?
                };
                let y = (b.rewards + (best_next * b.bootstrap)?)?.detach();
                let q = online
                    .forward(&b.observations, None)?
                    .gather(&b.actions, D::Minus1)?
                    .squeeze(D::Minus1)?;
                let error = (q - y)?;
                let per_sample = match options.loss {
                    Loss::Mse => error.sqr()?,
                    Loss::Huber => {
                        let size = error.abs()?;
                        let small = size.minimum(1f32)?;
                        ((small.sqr()? * 0.5)? + (size - small)?)?
                    }
                };
                let loss = (per_sample * &b.weights)?.mean_all()?;
                let mut grads = loss.backward()?;
                if let Some(max) = options.grad_clip {
                    clip_norm(&mut grads, &vars, max)?;
                }
                optimiser.step(&grads)?;
                let l = f64::from(loss.to_scalar::<f32>()?);
                if !l.is_finite() {
                    return Err(LearnError::Diverged(format!(
                        "the loss became {l} after {updates} updates; lower the learning rate"
                    )));
                }
                if options.prioritized.is_some() {
                    replay.update_priorities(&b.slots, &error.detach().to_vec1::<f32>()?);
                }
                loss_sum += l;
                loss_count += 1;
                updates += 1;
                match options.target_tau {
                    Some(tau) => target.blend_from(&online, tau)?,
                    None if updates % options.target_update.max(1) == 0 => {
                        target.copy_from(&online)?;
                    }
                    None => {}
                }
            }
            acting = online.to_mlp(HashMap::new())?;
        }
        if let Some(v) = options
            .validation
            .as_ref()
            .filter(|_| steps >= next_validation)
        {
            next_validation += v.every.max(1);
            let within = validation_evaluator.as_ref().unwrap_or(evaluator);
            let (success, spl, mut mlp) = validate(within, &online, v, threads)?;
            latest_validation = success;
            if best.as_ref().is_none_or(|b| (success, spl) > (b.0, b.1)) {
                mlp.metadata.insert(
                    "validation".to_string(),
                    format!(
                        "kept the network of step {steps}: {:.1}% success, SPL {spl:.3} on {}, \
                         step limit {}",
                        100.0 * success,
                        describe_seeds(&v.seeds),
                        within.config().episode.max_steps
                    ),
                );
                best = Some((success, spl, mlp));
            }
        }
        if steps >= next_report {
            next_report += report_every.max(1);
            let loss = mean_loss(loss_sum, loss_count);
            (loss_sum, loss_count) = (0.0, 0);
            let r = report(steps, episodes, &recent, loss, latest_validation, &best);
            if !on_report(&r) {
                break;
            }
        }
    }
    // The last stretch, unless a report just covered it.
    if next_report - report_every.max(1) < steps {
        let loss = mean_loss(loss_sum, loss_count);
        on_report(&report(
            steps,
            episodes,
            &recent,
            loss,
            latest_validation,
            &best,
        ));
    }
    if let Some((_, _, mlp)) = best {
        return Ok(Mlp {
            metadata: metadata.into_iter().chain(mlp.metadata.clone()).collect(),
            ..mlp
        });
    }
    online.to_mlp(metadata)
}

#[cfg(test)]
mod tests {
    use super::*;
    use ronap_core::config::{EpisodeConfig, MazeConfig};
    use ronap_core::sim::Scenes;
    use ronap_core::SimConfig;

    /// A small open room where the goal is always in reach: DQN must learn to head for it.
    fn open_room_config() -> SimConfig {
        SimConfig {
            maze: MazeConfig {
                cols: 2,
                rows: 2,
                loops: 1.0,
                ..Default::default()
            },
            episode: EpisodeConfig {
                min_goal_distance_px: 60.0,
                max_steps: 200,
                ..Default::default()
            },
            ..Default::default()
        }
    }

    fn open_room() -> Evaluator {
        Evaluator::new(open_room_config().validate().unwrap(), Scenes::MazePerSeed)
    }

    /// A small network's options: one hidden layer of `width`, `steps` environment steps over
    /// `width / 2` environments, batches of `2 * width` after a warm-up of `16 * width` steps.
    fn small(width: usize, steps: u64) -> DqnOptions {
        DqnOptions {
            hidden: vec![width],
            steps,
            warmup: 16 * width,
            batch: 2 * width,
            envs: width / 2,
            ..DqnOptions::default()
        }
    }

    /// Validation every `every` steps on the `count` seeds from 500, deciding by `decision`,
    /// under a step limit of `max_steps`.
    fn validation(every: u64, count: u64, decision: DecisionRule, max_steps: u32) -> Validation {
        Validation {
            every,
            seeds: Seeds::Range { start: 500, count },
            decision,
            max_steps: Some(max_steps),
        }
    }

    #[test]
    fn same_network_on_any_thread_count() {
        let options = small(16, 2_000);
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

    #[test]
    fn every_option_on_is_still_the_same_on_any_thread_count() {
        // Shaping, prioritised replay, Algorithm 1's one-step MSE without a dueling head, a
        // learning-rate decay, and validation keeping the best network.
        let mut c = open_room_config();
        c.reward.shaping = ronap_core::config::Shaping::Geodesic;
        let evaluator = Evaluator::new(c.validate().unwrap(), Scenes::MazePerSeed);
        let options = DqnOptions {
            n_step: 1,
            dueling: false,
            loss: Loss::Mse,
            grad_clip: Some(1.0),
            lr_end_fraction: 0.1,
            prioritized: Some(Priorities::default()),
            validation: Some(validation(
                1000,
                10,
                DecisionRule::Sample { temperature: 0.3 },
                300,
            )),
            ..small(16, 3_000)
        };
        let mut reports = Vec::new();
        let mut run = |threads| {
            let mut seen = Vec::new();
            let mlp = train(
                &evaluator,
                &options,
                threads,
                HashMap::new(),
                1000,
                &mut |r| {
                    seen.push(*r);
                    true
                },
            )
            .unwrap();
            reports.push(seen);
            mlp
        };
        let (one, two) = (run(1), run(2));
        assert_eq!(one.layers, two.layers);
        assert_eq!(one.metadata, two.metadata);
        assert_eq!(reports[0], reports[1]);
        // Validation ran at every report, and the best network's rule is the one saved.
        assert!(reports[0].iter().all(|r| r.validation_success.is_finite()));
        assert_eq!(
            one.metadata.get("decision").map(String::as_str),
            Some("sample:0.3")
        );
        let last = reports[0].last().unwrap();
        assert!((last.learning_rate - 0.1 * options.learning_rate).abs() < 1e-12);
    }

    #[test]
    fn validation_runs_under_its_own_step_limit() {
        // One step is too few to reach any goal: validation under a one-step limit must find
        // no success, whatever the network, while the training episodes keep their own limit.
        let evaluator = open_room();
        let options = DqnOptions {
            validation: Some(validation(500, 5, DecisionRule::Argmax, 1)),
            ..small(8, 1_000)
        };
        let mut best = Vec::new();
        let mlp = train(&evaluator, &options, 1, HashMap::new(), 500, &mut |r| {
            best.push(r.best_validation_success);
            true
        })
        .unwrap();
        // The weights say which network was kept, and where it was validated.
        let kept = &mlp.metadata["validation"];
        assert!(
            kept.starts_with("kept the network of step 500: 0.0% success"),
            "{kept}"
        );
        assert!(kept.ends_with("on seeds 500..=504, step limit 1"), "{kept}");
        assert!(!best.is_empty());
        assert!(best.iter().all(|&b| b == 0.0), "{best:?}");
    }
}
