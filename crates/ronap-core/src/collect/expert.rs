//! Data collection without a human: an expert (the geodesic planner) labels states with the action
//! it would take, for behaviour cloning.
//!
//! Two ways to visit states. [`Posing::Repose`] is the paper's Collect Data mode (docs/model.md "Data log"): after
//! each recorded action the robot jumps to a random free pose facing roughly towards the goal.
//! [`Posing::Drive`] keeps the robot moving: a driver policy (the expert itself, or a learned policy
//! being improved, as in DAgger) chooses where it goes while the expert labels every state.

use crate::eval::Evaluator;
use crate::io::Sample;
use crate::policy::{Expert, Policy, PolicyError, PolicyFactory};
use crate::run::{Rollout, RunError};
use crate::sim::{stream, Stream};
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};

/// How the robot moves from one recorded state to the next.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Posing {
    /// Jump to a random free pose after each action (the paper's mode).
    Repose,
    /// Take the driver's action and record the state it leads to.
    Drive,
}

/// What went wrong in a collection.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum CollectError {
    /// An episode could not start.
    #[error(transparent)]
    Run(#[from] RunError),
    /// The driver policy failed.
    #[error("driver policy: {0}")]
    Policy(#[from] PolicyError),
}

/// The samples of episode `seed`: up to `per_episode` labelled states. With [`Posing::Drive`] and
/// no `driver`, the expert drives; the episode's samples end with the episode.
pub fn collect_episode(
    evaluator: &Evaluator,
    seed: u64,
    per_episode: usize,
    posing: Posing,
    mut driver: Option<&mut dyn Policy>,
) -> Result<Vec<Sample>, CollectError> {
    let world = evaluator.world(seed);
    let mut rollout = match driver.as_deref_mut() {
        Some(d) => Rollout::start(world.clone(), seed, d)?,
        None => Rollout::new(world.clone(), seed)?,
    };
    let expert = Expert::new(&world, rollout.episode().goal());
    let mut repose_rng = stream(seed, Stream::Repose);
    let mut samples = Vec::with_capacity(per_episode);
    let mut step = 0u64;
    while samples.len() < per_episode && !rollout.finished() {
        let Some(label) = expert.action(&world, rollout.episode()) else {
            if posing == Posing::Drive {
                break;
            }
            // Re-posed onto the goal, or somewhere the planner cannot leave: draw again.
            if rollout
                .repose(Some(world.grid()), &mut repose_rng)
                .is_none()
            {
                break;
            }
            continue;
        };
        let mut sample = Sample::before(rollout.episode(), step, label);
        let taken = match (posing, driver.as_deref_mut()) {
            (Posing::Drive, Some(d)) => match rollout.decide(d)? {
                Some(a) => a,
                None => break,
            },
            _ => label.into(),
        };
        if taken.discrete().is_none() {
            return Err(PolicyError::Failed("the driver must take discrete actions".into()).into());
        }
        sample.collided = rollout.take(taken).collided;
        samples.push(sample);
        step += 1;
        if posing == Posing::Repose {
            if rollout.episode().status().is_done() {
                // Reached the goal: re-posing starts the episode's bookkeeping afresh.
                rollout = Rollout::new(world.clone(), seed)?;
            }
            if rollout
                .repose(Some(world.grid()), &mut repose_rng)
                .is_none()
            {
                break;
            }
        }
    }
    Ok(samples)
}

/// A collection of labelled samples to make: where the episodes take place, how much to take,
/// how states are visited, and on how many threads.
#[derive(Clone, Copy)]
pub struct Collection<'a> {
    /// The episodes' configuration and scenes.
    pub evaluator: &'a Evaluator,
    /// Samples taken from each episode at most.
    pub per_episode: usize,
    /// Samples in all at most.
    pub max_samples: usize,
    /// How states are visited (re-posing, or driving).
    pub posing: Posing,
    /// Who drives (with [`Posing::Drive`]; `None`: the expert).
    pub driver: Option<&'a dyn PolicyFactory>,
    /// Worker threads (0: all cores).
    pub threads: usize,
    /// Set to stop between episodes, keeping every sample taken.
    pub cancel: &'a AtomicBool,
}

/// Collects from `seeds` in order on `threads` threads (0: all cores), handing each episode's
/// samples to `on_samples` in seed order, so the output is the same on any thread count. Stops
/// after `max_samples` samples in all, when `on_samples` returns `false`, or when `cancel` is set.
pub fn collect(
    request: &Collection<'_>,
    seeds: impl Iterator<Item = u64>,
    on_samples: &mut dyn FnMut(u64, &[Sample]) -> bool,
) -> Result<usize, CollectError> {
    let Collection {
        evaluator,
        per_episode,
        max_samples,
        posing,
        driver,
        threads,
        cancel,
    } = *request;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| PolicyError::Failed(format!("cannot start worker threads: {e}")))?;
    let chunk = pool.current_num_threads() * 4;
    let mut seeds = seeds.peekable();
    let mut total = 0;
    while total < max_samples && seeds.peek().is_some() && !cancel.load(Ordering::Relaxed) {
        let batch: Vec<u64> = seeds.by_ref().take(chunk).collect();
        let results: Vec<Result<Vec<Sample>, CollectError>> = pool.install(|| {
            batch
                .par_iter()
                .map(|&seed| {
                    let mut policy = driver.map(|f| f.make()).transpose()?;
                    let driver: Option<&mut dyn Policy> = match &mut policy {
                        Some(p) => Some(p.as_mut()),
                        None => None,
                    };
                    collect_episode(evaluator, seed, per_episode, posing, driver)
                })
                .collect()
        });
        for (seed, result) in batch.into_iter().zip(results) {
            let mut samples = result?;
            samples.truncate(max_samples - total);
            total += samples.len();
            if !on_samples(seed, &samples) || total >= max_samples {
                return Ok(total);
            }
        }
    }
    Ok(total)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::SimConfig;
    use crate::geometry::wrap_deg;
    use crate::sim::Scenes;

    fn evaluator() -> Evaluator {
        Evaluator::new(
            SimConfig::default().validate().unwrap(),
            Scenes::MazePerSeed,
        )
    }

    #[test]
    fn reposed_samples_face_the_goal_and_differ() {
        let samples = collect_episode(&evaluator(), 3, 200, Posing::Repose, None).unwrap();
        assert_eq!(samples.len(), 200);
        let mut far = 0;
        for s in &samples {
            let off = wrap_deg(s.direction_deg() + 180.0) - 180.0;
            if off.abs() > 3.0 * 360.0 * 0.03 {
                far += 1;
            }
        }
        // Headings are theta + N(0, 10.8 deg): beyond 3 sigma is rare.
        assert!(far <= 3, "{far} of 200 headings far from the goal bearing");
        let distinct: std::collections::HashSet<_> =
            samples.iter().map(|s| s.pose.x.to_bits()).collect();
        assert!(distinct.len() > 190);
    }

    #[test]
    fn driving_expert_reaches_the_goal_and_same_on_any_thread_count() {
        let samples = collect_episode(&evaluator(), 5, 5000, Posing::Drive, None).unwrap();
        let last = samples.last().unwrap();
        assert!(
            last.distance_px < 20.0,
            "ended {} px from the goal",
            last.distance_px
        );
        let gather = |threads| {
            let mut all = Vec::new();
            let (evaluator, cancel) = (evaluator(), AtomicBool::new(false));
            let request = Collection {
                evaluator: &evaluator,
                per_episode: 50,
                max_samples: usize::MAX,
                posing: Posing::Repose,
                driver: None,
                threads,
                cancel: &cancel,
            };
            collect(&request, 0..6, &mut |_, s| {
                all.extend_from_slice(s);
                true
            })
            .unwrap();
            all
        };
        assert_eq!(gather(1), gather(2));
    }
}
