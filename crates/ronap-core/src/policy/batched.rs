//! Batched decisions: many episodes run side by side, each on its own worker as usual, and their
//! requests for an action are gathered into one call of a policy that decides for many
//! observations at once (a Python model, a network on an accelerator), where one call per
//! observation would cost most of the time.
//!
//! Each worker's [`Policy::act`] hands its observation in and waits. Whoever finds no call under
//! way and the requests gathered (one from every worker still running, or the batch full, or no
//! new request for [`GATHER`]) makes the call for all of them. Which requests share a call
//! depends on timing, but an episode's actions depend only on its own observations, so a run's
//! episodes are the same as unbatched, bit for bit, for any policy that decides each row by itself.

use crate::policy::{Decision, Policy, PolicyError, PolicyFactory};
use crate::sim::{Action, Episode, World};
use std::collections::HashMap;
use std::sync::{Arc, Condvar, Mutex, MutexGuard};
use std::time::{Duration, Instant};

/// How long a gathered batch waits for one more request before it is decided anyway (a worker
/// may be setting up its next episode, or have no seeds left).
pub const GATHER: Duration = Duration::from_millis(2);

/// A policy that decides for many observations in one call.
pub trait BatchPolicy: Send {
    /// Pushes onto `actions` one action for each of the observation `rows`, in row order.
    fn act_batch(&mut self, rows: Rows<'_>, actions: &mut Vec<Action>) -> Result<(), PolicyError>;
}

/// Observations a row each, row-major: what a [`BatchPolicy`] decides for.
#[derive(Clone, Copy, Debug)]
pub struct Rows<'a> {
    /// Every row's values, one row after the other.
    pub values: &'a [f32],
    /// Values a row.
    pub width: usize,
}

impl Rows<'_> {
    /// The number of rows (`values.len() / width`; none when `width` is 0).
    pub fn count(&self) -> usize {
        self.values.len().checked_div(self.width).unwrap_or(0)
    }
}

#[derive(Default)]
struct State {
    /// Requests not yet decided: ticket and observation.
    pending: Vec<(u64, Vec<f32>)>,
    /// Decisions not yet collected, by ticket.
    done: HashMap<u64, Result<Action, String>>,
    next_ticket: u64,
    /// Whether a call is under way.
    calling: bool,
    /// Workers holding a policy (each asks for at most one action at a time).
    live: usize,
    last_arrival: Option<Instant>,
}

struct Shared {
    state: Mutex<State>,
    changed: Condvar,
    policy: Mutex<Box<dyn BatchPolicy>>,
    max_rows: usize,
}

impl Shared {
    fn lock(&self) -> MutexGuard<'_, State> {
        self.state.lock().unwrap_or_else(|e| e.into_inner())
    }
}

/// Makes the per-worker policies of a batched evaluation: give it as the factory and run the
/// evaluation with `max_rows` worker threads, so that up to `max_rows` episodes are under way.
pub struct Batched {
    shared: Arc<Shared>,
    name: String,
}

impl Batched {
    /// Batches of at most `max_rows` (at least 1) observations for `policy`, reported as `name`.
    pub fn new(policy: Box<dyn BatchPolicy>, max_rows: usize, name: impl Into<String>) -> Self {
        Self {
            shared: Arc::new(Shared {
                state: Mutex::new(State::default()),
                changed: Condvar::new(),
                policy: Mutex::new(policy),
                max_rows: max_rows.max(1),
            }),
            name: name.into(),
        }
    }
}

impl PolicyFactory for Batched {
    fn make(&self) -> Result<Box<dyn Policy>, PolicyError> {
        self.shared.lock().live += 1;
        Ok(Box::new(Worker {
            shared: self.shared.clone(),
        }))
    }

    fn name(&self) -> String {
        self.name.clone()
    }
}

/// One worker's share of a [`Batched`] policy.
struct Worker {
    shared: Arc<Shared>,
}

impl Drop for Worker {
    fn drop(&mut self) {
        self.shared.lock().live -= 1;
        self.shared.changed.notify_all();
    }
}

impl Worker {
    /// Decides the pending requests of `state` (at most `max_rows`, oldest first) in one call,
    /// with the state unlocked during it.
    fn call<'a>(&'a self, mut state: MutexGuard<'a, State>) -> MutexGuard<'a, State> {
        let shared = &self.shared;
        state.calling = true;
        let take = state.pending.len().min(shared.max_rows);
        let batch: Vec<(u64, Vec<f32>)> = state.pending.drain(..take).collect();
        drop(state);
        let width = batch.first().map_or(0, |(_, o)| o.len());
        let mut flat = Vec::with_capacity(width * batch.len());
        let mut widths_agree = true;
        for (_, o) in &batch {
            widths_agree &= o.len() == width;
            flat.extend_from_slice(o);
        }
        let mut actions = Vec::with_capacity(batch.len());
        let outcome = if !widths_agree {
            Err("observations of different sizes in one batch".to_string())
        } else {
            let mut policy = shared.policy.lock().unwrap_or_else(|e| e.into_inner());
            match policy.act_batch(
                Rows {
                    values: &flat,
                    width,
                },
                &mut actions,
            ) {
                Ok(()) if actions.len() == batch.len() => Ok(()),
                Ok(()) => Err(format!(
                    "gave {} actions for {} observations",
                    actions.len(),
                    batch.len()
                )),
                Err(e) => Err(e.to_string()),
            }
        };
        let mut state = shared.lock();
        for (k, (ticket, _)) in batch.iter().enumerate() {
            let decided = match &outcome {
                Ok(()) => Ok(actions[k]),
                Err(why) => Err(why.clone()),
            };
            state.done.insert(*ticket, decided);
        }
        state.calling = false;
        shared.changed.notify_all();
        state
    }
}

impl Policy for Worker {
    fn reset(&mut self, _world: &World, _episode: &Episode) -> Result<(), PolicyError> {
        Ok(())
    }

    fn act(&mut self, episode: &Episode) -> Result<Decision, PolicyError> {
        let shared = self.shared.clone();
        let mut state = shared.lock();
        let ticket = state.next_ticket;
        state.next_ticket += 1;
        state.pending.push((ticket, episode.observation().to_vec()));
        state.last_arrival = Some(Instant::now());
        // No one is woken: the request that fills the batch finds it full below and makes the
        // call itself, and waiters look again every GATHER (waking every waiter on every request
        // cost a thundering herd a step).
        loop {
            if let Some(decided) = state.done.remove(&ticket) {
                return decided.map(Decision::Act).map_err(PolicyError::Failed);
            }
            let quiet = state.last_arrival.is_some_and(|t| t.elapsed() >= GATHER);
            let full = state.pending.len() >= shared.max_rows.min(state.live.max(1));
            if !state.calling && !state.pending.is_empty() && (full || quiet) {
                state = self.call(state);
                continue;
            }
            state = shared
                .changed
                .wait_timeout(state, GATHER)
                .unwrap_or_else(|e| e.into_inner())
                .0;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::{EvalOptions, Evaluator};
    use crate::sim::DiscreteAction;
    use crate::{Scenes, SimConfig};
    use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

    /// Turns towards the goal; counts its calls and the largest batch.
    struct Toward {
        calls: Arc<AtomicUsize>,
        most: Arc<AtomicUsize>,
    }

    impl BatchPolicy for Toward {
        fn act_batch(
            &mut self,
            rows: Rows<'_>,
            actions: &mut Vec<Action>,
        ) -> Result<(), PolicyError> {
            self.calls.fetch_add(1, Ordering::Relaxed);
            self.most.fetch_max(rows.count(), Ordering::Relaxed);
            for row in rows.values.chunks(rows.width) {
                actions.push(Action::from(toward(row)));
            }
            Ok(())
        }
    }

    fn toward(row: &[f32]) -> DiscreteAction {
        let d = f64::from(row[row.len() - 1]) * 360.0;
        if 15.0 < d && d < 180.0 {
            DiscreteAction::Left
        } else if (180.0..345.0).contains(&d) {
            DiscreteAction::Right
        } else {
            DiscreteAction::Ahead
        }
    }

    /// The same policy, one observation at a time.
    struct One;

    impl Policy for One {
        fn reset(&mut self, _: &World, _: &Episode) -> Result<(), PolicyError> {
            Ok(())
        }
        fn act(&mut self, episode: &Episode) -> Result<Decision, PolicyError> {
            Ok(Decision::Act(Action::from(toward(episode.observation()))))
        }
    }

    struct OneFactory;

    impl PolicyFactory for OneFactory {
        fn make(&self) -> Result<Box<dyn Policy>, PolicyError> {
            Ok(Box::new(One))
        }
        fn name(&self) -> String {
            "one".into()
        }
    }

    fn run(factory: &dyn PolicyFactory, threads: usize) -> Vec<String> {
        let mut config = SimConfig::default();
        config.episode.max_steps = 150;
        let evaluator = Evaluator::new(config.validate().expect("valid"), Scenes::MazePerSeed);
        let options = EvalOptions {
            seeds: (0..40u64).collect::<Vec<_>>().into(),
            threads,
            ..EvalOptions::default()
        };
        let result = evaluator
            .run(factory, &options, &AtomicBool::new(false), &|_| {})
            .expect("runs");
        assert!(result.error.is_none());
        result
            .records
            .iter()
            .map(|r| {
                format!(
                    "{} {:?} {} {} {}",
                    r.seed, r.outcome, r.steps, r.collisions, r.path_length_px
                )
            })
            .collect()
    }

    #[test]
    fn batched_episodes_equal_unbatched_and_share_calls() {
        let (calls, most) = (Arc::new(AtomicUsize::new(0)), Arc::new(AtomicUsize::new(0)));
        let batched = Batched::new(
            Box::new(Toward {
                calls: calls.clone(),
                most: most.clone(),
            }),
            8,
            "toward",
        );
        let want = run(&OneFactory, 1);
        assert_eq!(run(&batched, 8), want);
        let steps: u64 = want
            .iter()
            .map(|r| {
                r.split(' ')
                    .nth(2)
                    .and_then(|s| s.parse::<u64>().ok())
                    .unwrap_or(0)
            })
            .sum();
        let calls = calls.load(Ordering::Relaxed) as u64;
        assert!(most.load(Ordering::Relaxed) > 1, "never batched");
        assert!(calls < steps, "{calls} calls for {steps} steps");
        // Fewer workers than the batch: still every episode, and the same.
        assert_eq!(
            run(
                &Batched::new(
                    Box::new(Toward {
                        calls: Arc::default(),
                        most: Arc::default()
                    }),
                    8,
                    "t"
                ),
                3
            ),
            want
        );
    }

    struct Fails;

    impl BatchPolicy for Fails {
        fn act_batch(&mut self, _: Rows<'_>, _: &mut Vec<Action>) -> Result<(), PolicyError> {
            Err(PolicyError::Failed("no idea".into()))
        }
    }

    #[test]
    fn a_failing_batch_fails_the_run_naming_why() {
        let config = SimConfig::default().validate().expect("valid");
        let evaluator = Evaluator::new(config, Scenes::MazePerSeed);
        let options = EvalOptions {
            seeds: (0..6u64).collect::<Vec<_>>().into(),
            threads: 3,
            ..EvalOptions::default()
        };
        let result = evaluator
            .run(
                &Batched::new(Box::new(Fails), 3, "f"),
                &options,
                &AtomicBool::new(false),
                &|_| {},
            )
            .expect("runs");
        let error = result.error.expect("fails").to_string();
        assert!(error.contains("no idea"), "{error}");
    }
}
