//! Episodes side by side: a worker steps several episodes at once on its thread, asking the
//! policy for all their actions in one call ([`PolicyFactory::side_by_side`]), so a network
//! evaluates its rows together and loads each weight once for several of them. Records are the
//! same, bit for bit, as one episode after another.

use crate::eval::ordered::{run_in_order, Ordered, Window};
use crate::eval::{
    worker_pool, EpisodeRecord, EvalOptions, Evaluator, Failure, Recorder, Recording, RunEnd,
};
use crate::policy::{Policy, PolicyError, PolicyFactory};
use crate::run::{RunError, TeamRollout};
use crate::sim::Episode;
use std::sync::atomic::AtomicBool;
use std::time::Instant;

/// Lane-fuls of seeds in each job of a side-by-side evaluation: lanes whose episodes end take the
/// block's next seeds, so only the block's last episodes run with lanes idle.
pub const SIDE_BY_SIDE_BLOCK: usize = 8;

/// An episode under way in a lane.
struct Live {
    /// Its place in the seeds.
    index: usize,
    lane: usize,
    /// The episode, as its robot's team of one.
    rollout: TeamRollout,
    recorder: Recorder,
}

/// Keeps `index`'s error if it is the first failed episode in seed order so far.
fn fail(failed: &mut Option<(usize, RunError)>, index: usize, e: RunError) {
    if failed.as_ref().is_none_or(|(f, _)| index < *f) {
        *failed = Some((index, e));
    }
}

impl Evaluator {
    /// Runs the episodes of `seeds` side by side, `lanes` at a time on this thread, `policy`
    /// deciding for all of them at once at each step ([`PolicyFactory::side_by_side`]); a lane
    /// whose episode ends takes the next seed. Each record goes to `finished`, with its place in
    /// `seeds`, as its episode ends, in the order they end (so a caller keeps only what it needs
    /// of it). Gives the place and error of the first failed episode in seed order: every episode
    /// before it has finished; none after it is started once it failed, but some may have ended
    /// before it failed and gone to `finished`, so a caller keeping a prefix cuts at the failed
    /// place (as [`Evaluator::run_episode`] one seed after another would have stopped there).
    /// Every record is the one [`Evaluator::run_episode`] gives, bit for bit, but for its wall
    /// time, which counts the steps of the episodes beside it.
    pub fn run_side_by_side(
        &self,
        policy: &mut dyn Policy,
        seeds: &[u64],
        lanes: usize,
        recording: &dyn Fn(u64) -> Recording,
        finished: &mut dyn FnMut(usize, EpisodeRecord),
    ) -> Option<(usize, RunError)> {
        let lanes = lanes.max(1);
        // The first failed episode in seed order so far.
        let mut failed: Option<(usize, RunError)> = None;
        let mut live: Vec<Live> = Vec::with_capacity(lanes);
        let mut free: Vec<usize> = (0..lanes).rev().collect();
        let mut next = 0;
        let mut decisions = Vec::with_capacity(lanes);
        loop {
            // Episodes after a failed one are neither started nor kept going.
            let stop = failed.as_ref().map_or(seeds.len(), |(f, _)| *f);
            live.retain(|l| {
                if l.index >= stop {
                    free.push(l.lane);
                }
                l.index < stop
            });
            while next < failed.as_ref().map_or(seeds.len(), |(f, _)| *f) {
                let Some(lane) = free.pop() else {
                    break;
                };
                let (index, seed) = (next, seeds[next]);
                next += 1;
                let clock = Instant::now();
                let started = RunError::refuse_team(self.config(), seed)
                    .and_then(|()| {
                        TeamRollout::placed(self.config(), self.worlds().team(seed), seed)
                    })
                    .and_then(|rollout| {
                        policy
                            .reset_lane(lane, rollout.world(0), rollout.team().robot(0))
                            .map_err(|e| RunError::reset(seed, e))?;
                        Ok(rollout)
                    });
                match started {
                    Ok(rollout) => {
                        let recorder =
                            Recorder::start(self.config(), recording(seed), clock, &rollout, true);
                        live.push(Live {
                            index,
                            lane,
                            rollout,
                            recorder,
                        });
                    }
                    Err(e) => {
                        free.push(lane);
                        fail(&mut failed, index, e);
                    }
                }
            }
            // Episodes over (or given up) end here.
            let mut k = 0;
            while k < live.len() {
                if live[k].rollout.finished() {
                    let l = live.remove(k);
                    free.push(l.lane);
                    if failed.as_ref().is_none_or(|(f, _)| l.index < *f) {
                        finished(l.index, l.recorder.lone(l.rollout));
                    }
                } else {
                    k += 1;
                }
            }
            if live.is_empty() {
                if next >= failed.as_ref().map_or(seeds.len(), |(f, _)| *f) {
                    break;
                }
                continue;
            }
            decisions.clear();
            let asked: Vec<(usize, &Episode)> = live
                .iter()
                .map(|l| (l.lane, l.rollout.team().robot(0)))
                .collect();
            let mut refused = policy.act_lanes(&asked, &mut decisions).err();
            // One decision per episode asked, up to the one whose decision failed: anything
            // else would hand actions to the wrong episodes (or ask again for ever).
            let expected = refused.as_ref().map_or(asked.len(), |(k, _)| *k);
            if decisions.len() != expected || expected > asked.len() {
                let message = format!(
                    "the policy gave {} decisions for {} episodes side by side{}",
                    decisions.len(),
                    asked.len(),
                    refused
                        .as_ref()
                        .map_or(String::new(), |(k, _)| format!(", failing at episode {k}")),
                );
                decisions.clear();
                refused = Some((0, PolicyError::Failed(message)));
            }
            drop(asked);
            let mut decided = decisions.drain(..);
            for (k, l) in live.iter_mut().enumerate() {
                let decision = if let Some(d) = decided.next() {
                    Ok(d)
                } else if let Some((_, e)) = refused.take_if(|(at, _)| *at == k) {
                    Err(l.rollout.policy_error(e))
                } else {
                    // Not asked (the policy stopped at an earlier episode's error): asked again.
                    continue;
                };
                match decision.and_then(|d| l.rollout.decided(0, d)) {
                    Ok(Some(action)) => {
                        l.recorder.before(l.rollout.team());
                        l.rollout.step(&[Some(action)]);
                        l.recorder.after(&l.rollout);
                    }
                    Ok(None) => {}
                    Err(e) => fail(&mut failed, l.index, e),
                }
            }
        }
        failed
    }
}

/// [`Evaluator::stream`] for a policy deciding for `lanes` episodes at once: each job is a block
/// of [`SIDE_BY_SIDE_BLOCK`] lane-fuls of seeds, run side by side on one worker
/// ([`Evaluator::run_side_by_side`]), so the cancel flag stops the run between blocks.
pub(crate) struct SideBySide<'a> {
    pub(crate) evaluator: &'a Evaluator,
    pub(crate) factory: &'a dyn PolicyFactory,
    pub(crate) options: &'a EvalOptions,
    pub(crate) lanes: usize,
    /// Each record as its episode ends, in any order.
    pub(crate) on_finish: &'a (dyn Fn(&EpisodeRecord) + Sync),
}

impl SideBySide<'_> {
    /// Streams the records to `sink` in seed order, without their paths, until it refuses one or
    /// `cancel` is set; how the run ended.
    pub(crate) fn stream(
        self,
        cancel: &AtomicBool,
        sink: &mut dyn FnMut(EpisodeRecord) -> bool,
    ) -> Result<RunEnd, PolicyError> {
        let Self {
            evaluator,
            factory,
            options,
            lanes,
            on_finish,
        } = self;
        let clock = Instant::now();
        let pool = worker_pool(options.threads)?;
        let count = options.seeds.len();
        let block = lanes * SIDE_BY_SIDE_BLOCK;
        // A failed block gives the records before its failed episode with the failure.
        type Failed = (Vec<EpisodeRecord>, Failure);
        let work = |policy: &mut Option<Box<dyn Policy>>, b: usize| -> Result<_, Failed> {
            let policy = match policy {
                Some(p) => p,
                None => policy.insert(
                    factory
                        .make()
                        .map_err(|e| (Vec::new(), Failure::Policy(e)))?,
                ),
            };
            let seeds: Vec<u64> = (b * block..count.min((b + 1) * block))
                .filter_map(|i| options.seeds.get(i))
                .collect();
            let mut records: Vec<Option<EpisodeRecord>> = seeds.iter().map(|_| None).collect();
            let failed = evaluator.run_side_by_side(
                policy.as_mut(),
                &seeds,
                lanes,
                &|seed| options.recording_of(seed),
                &mut |i, mut record| {
                    on_finish(&record);
                    record.strip();
                    records[i] = Some(record);
                },
            );
            // Every episode before the first failed one has finished.
            let records = records.into_iter().map_while(|r| r).collect();
            match failed {
                Some((_, e)) => Err((records, Failure::Run(e))),
                None => Ok(records),
            }
        };
        let mut handed = 0;
        let mut hand = |records: Vec<EpisodeRecord>| {
            for record in records {
                if !sink(record) {
                    return false;
                }
                handed += 1;
            }
            true
        };
        let ended = run_in_order(
            &pool,
            count.div_ceil(block),
            // Blocks each worker may run ahead: enough to keep every worker busy.
            Window(4 * pool.current_num_threads()),
            cancel,
            &work,
            &mut hand,
        );
        let mut refused = ended.refused;
        let failed = match ended.failed {
            Some((b, (records, failure))) => {
                // The records before the failed episode come after every earlier block's; a
                // sink that stops among them stops the run before the failure is reached.
                if !refused {
                    refused = !hand(records);
                }
                (!refused).then_some((b, failure))
            }
            None => None,
        };
        RunEnd::of(
            Ordered {
                handed,
                failed,
                refused,
            },
            count,
            clock,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::SimConfig;
    use crate::policy::{Decision, MlpFactory};
    use crate::sim::{DiscreteAction, Scenes, World};
    use std::path::Path;
    use std::sync::atomic::Ordering;

    fn evaluator() -> Evaluator {
        let config = SimConfig::default().validate().expect("valid");
        Evaluator::new(config, Scenes::MazePerSeed)
    }

    fn shipped(name: &str) -> MlpFactory {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../policies")
            .join(name);
        MlpFactory::load(&path, 18).expect("shipped")
    }

    /// Another factory's policies, one episode at a time.
    struct Alone<'a>(&'a dyn PolicyFactory);

    impl PolicyFactory for Alone<'_> {
        fn make(&self) -> Result<Box<dyn Policy>, PolicyError> {
            self.0.make()
        }
        fn name(&self) -> String {
            self.0.name()
        }
    }

    /// A record as text, but for its wall time and its world.
    fn key(r: &EpisodeRecord) -> String {
        let mut r = r.clone();
        r.wall_time_s = 0.0;
        r.world = None;
        format!("{r:?}")
    }

    /// `count` seeds from `start` on `threads` threads.
    fn options(start: u64, count: u64, threads: usize) -> EvalOptions {
        EvalOptions {
            seeds: crate::eval::Seeds::Range { start, count },
            threads,
            ..EvalOptions::default()
        }
    }

    fn stream(
        factory: &dyn PolicyFactory,
        seeds: u64,
        threads: usize,
    ) -> (Vec<EpisodeRecord>, RunEnd) {
        let options = options(0, seeds, threads);
        let mut records = Vec::new();
        let end = evaluator()
            .stream(
                factory,
                &options,
                &AtomicBool::new(false),
                &|_| {},
                &mut |r| {
                    records.push(r);
                    true
                },
            )
            .expect("policies made");
        (records, end)
    }

    /// The shipped networks (bc samples from its stream, dqn takes the argmax) give the same
    /// records side by side as one at a time, on one and two threads.
    #[test]
    fn side_by_side_records_are_the_records_one_at_a_time() {
        for name in ["bc.safetensors", "dqn.safetensors"] {
            let factory = shipped(name);
            assert!(factory.side_by_side() > 1);
            let (alone, _) = stream(&Alone(&factory), 150, 1);
            assert_eq!(alone.len(), 150);
            for threads in [1, 2] {
                let (together, end) = stream(&factory, 150, threads);
                assert_eq!(end.episodes, 150);
                assert!(end.error.is_none() && !end.cancelled);
                let (a, b): (Vec<_>, Vec<_>) = alone
                    .iter()
                    .zip(&together)
                    .map(|(a, b)| (key(a), key(b)))
                    .unzip();
                assert_eq!(a, b, "{name} on {threads} threads");
            }
        }
    }

    /// Trajectories and step logs too, with lanes fewer than the seeds and more.
    #[test]
    fn side_by_side_records_trajectories_and_steps_as_one_at_a_time() {
        let evaluator = evaluator();
        let factory = shipped("bc.safetensors");
        let recording = Recording {
            trajectory: true,
            steps: true,
        };
        let seeds: Vec<u64> = (100..112).collect();
        let mut policy = factory.make().expect("made");
        let alone: Vec<String> = seeds
            .iter()
            .map(|&s| {
                key(&evaluator
                    .run_episode(policy.as_mut(), s, recording)
                    .expect("runs"))
            })
            .collect();
        for lanes in [1, 3, 16] {
            let mut records: Vec<Option<EpisodeRecord>> = vec![None; seeds.len()];
            let failed = evaluator.run_side_by_side(
                policy.as_mut(),
                &seeds,
                lanes,
                &|_| recording,
                &mut |i, r| {
                    assert!(records[i].is_none(), "seed {i} twice");
                    records[i] = Some(r);
                },
            );
            assert!(failed.is_none());
            let records: Vec<EpisodeRecord> = records.into_iter().flatten().collect();
            assert_eq!(records.len(), seeds.len());
            assert!(records
                .iter()
                .all(|r| !r.trajectory.is_empty() && !r.step_log.is_empty()));
            let together: Vec<String> = records.iter().map(key).collect();
            assert_eq!(alone, together, "{lanes} lanes");
        }
    }

    /// Drives ahead; fails at `seed` when resetting (`step` 0) or at step `step`; decides for
    /// four lanes at once.
    struct Failing {
        seed: u64,
        step: u32,
    }

    impl PolicyFactory for Failing {
        fn make(&self) -> Result<Box<dyn Policy>, PolicyError> {
            Ok(Box::new(FailingPolicy {
                seed: self.seed,
                step: self.step,
            }))
        }
        fn name(&self) -> String {
            "failing".into()
        }
        fn side_by_side(&self) -> usize {
            4
        }
    }

    struct FailingPolicy {
        seed: u64,
        step: u32,
    }

    impl Policy for FailingPolicy {
        fn reset(&mut self, _: &World, episode: &Episode) -> Result<(), PolicyError> {
            if self.step == 0 && episode.seed() == self.seed {
                return Err(PolicyError::Failed("no reset".into()));
            }
            Ok(())
        }
        fn act(&mut self, episode: &Episode) -> Result<Decision, PolicyError> {
            if episode.seed() == self.seed && episode.steps() + 1 == self.step {
                return Err(PolicyError::Failed("no act".into()));
            }
            Ok(Decision::Act(DiscreteAction::Ahead.into()))
        }
    }

    /// A failed episode ends the run at it, side by side as one at a time: every record before
    /// it is handed on, none from it on, and the error is its own.
    #[test]
    fn a_failed_episode_ends_the_run_at_it_with_every_record_before() {
        for (seed, step) in [(37, 0), (37, 5), (0, 1), (40, 2)] {
            let factory = Failing { seed, step };
            let (alone, alone_end) = stream(&Alone(&factory), 100, 1);
            for threads in [1, 2] {
                let (together, end) = stream(&factory, 100, threads);
                assert_eq!(together.len(), seed as usize, "seed {seed} step {step}");
                assert_eq!(end.episodes, seed as usize);
                assert_eq!(end.error, alone_end.error);
                let expected = format!("seed {seed}, step {step}: policy failed");
                assert!(
                    end.error
                        .as_ref()
                        .expect("failed")
                        .to_string()
                        .starts_with(&expected),
                    "{:?}",
                    end.error
                );
                assert_eq!(
                    alone.iter().map(key).collect::<Vec<_>>(),
                    together.iter().map(key).collect::<Vec<_>>()
                );
            }
        }
    }

    /// A sink that stops among the records before a failed episode stops the run there: no
    /// error, as one at a time (the failure is never reached).
    #[test]
    fn a_sink_that_stops_before_a_failure_ends_the_run_without_it() {
        let factory = Failing { seed: 37, step: 5 };
        for f in [&factory as &dyn PolicyFactory, &Alone(&factory)] {
            let options = options(0, 100, 1);
            let mut seen = 0;
            let end = evaluator()
                .stream(f, &options, &AtomicBool::new(false), &|_| {}, &mut |_| {
                    seen += 1;
                    seen < 10
                })
                .expect("made");
            assert_eq!(end.episodes, 9);
            assert!(end.error.is_none() && end.cancelled, "{end:?}");
        }
    }

    /// A policy giving too few decisions for the episodes side by side fails the run (naming
    /// what it gave) rather than asking again for ever.
    #[test]
    fn a_policy_short_of_decisions_fails_the_run() {
        struct Short;
        impl PolicyFactory for Short {
            fn make(&self) -> Result<Box<dyn Policy>, PolicyError> {
                Ok(Box::new(ShortPolicy))
            }
            fn name(&self) -> String {
                "short".into()
            }
            fn side_by_side(&self) -> usize {
                4
            }
        }
        struct ShortPolicy;
        impl Policy for ShortPolicy {
            fn reset(&mut self, _: &World, _: &Episode) -> Result<(), PolicyError> {
                Ok(())
            }
            fn act(&mut self, _: &Episode) -> Result<Decision, PolicyError> {
                Ok(Decision::Act(DiscreteAction::Ahead.into()))
            }
            fn act_lanes(
                &mut self,
                episodes: &[(usize, &Episode)],
                decisions: &mut Vec<Decision>,
            ) -> Result<(), (usize, PolicyError)> {
                for _ in 1..episodes.len() {
                    decisions.push(Decision::Act(DiscreteAction::Left.into()));
                }
                Ok(())
            }
        }
        let (records, end) = stream(&Short, 10, 1);
        assert!(records.is_empty());
        let error = end.error.expect("failed").to_string();
        assert!(
            error.starts_with("seed 0, step 1: policy failed: the policy gave 3 decisions for 4"),
            "{error}"
        );
    }

    /// A sink that stops after 10 records gets 10, in order; a run cancelled before it starts
    /// runs nothing.
    #[test]
    fn a_sink_stops_and_the_cancel_flag_stops_between_blocks() {
        let factory = shipped("dqn.safetensors");
        let options = options(5, 300, 2);
        let mut seen = Vec::new();
        let end = evaluator()
            .stream(
                &factory,
                &options,
                &AtomicBool::new(false),
                &|_| {},
                &mut |r| {
                    seen.push(r.seed);
                    seen.len() < 10
                },
            )
            .expect("made");
        assert_eq!(seen, (5..15).collect::<Vec<_>>());
        assert_eq!(end.episodes, 9);
        let cancel = AtomicBool::new(false);
        cancel.store(true, Ordering::Relaxed);
        let end = evaluator()
            .stream(&factory, &options, &cancel, &|_| {}, &mut |_| true)
            .expect("made");
        assert_eq!(end.episodes, 0);
        assert!(end.cancelled);
    }
}
