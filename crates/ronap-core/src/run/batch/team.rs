//! A team's environments in a batch ([`TeamBatch`]), for learning with several robots: R rows
//! an environment, one per robot, actions and messages given as flat arrays (`N x R`, `N x R x
//! message_size`) and observations and flags written into the batch's flat buffers (`N x R x D`,
//! `N x R`), where `D` is the longest robot observation (shorter ones padded with zeros). An
//! environment's episode is over when all its robots are done. Over a configuration without
//! `[[robots]]`, each environment is the lone robot's team of one, and steps the same bits as a
//! [`Batch`](crate::run::Batch) of lone robots (tested below).

use super::{BatchOf, Lane};
use crate::run::team::TeamRollout;
use crate::run::{RunError, TeamShaper};
use crate::sim::{Action, Status, Worlds};

/// One robot's latest reset or step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RobotStep {
    /// The step's reward (0 for a reset, and for a robot whose episode was already over).
    pub reward: f64,
    /// The robot's episode ended in a terminal state (Gymnasium's `terminated`).
    pub terminated: bool,
    /// The robot's episode was cut short: time-out or deadlock (`truncated`).
    pub truncated: bool,
    /// The robot was still going before this step: its action counted (false after a reset).
    pub acted: bool,
    /// The robot's episode is still going after this step.
    pub running: bool,
    /// Collided in this step.
    pub collided: bool,
    /// The robot's episode ended at its goal (so far, or at this step).
    pub success: bool,
}

/// N team environments stepped together.
pub type TeamBatch = BatchOf<Teams>;

/// A team's environment: its episode and its robots' reward shaping.
pub struct Teams {
    rollout: Option<TeamRollout>,
    /// Its robots' reward shaping, under `reward.shaping`.
    shaping: TeamShaper,
}

impl Lane for Teams {
    type Record = RobotStep;

    fn idle(_: &Worlds) -> Self {
        Self {
            rollout: None,
            shaping: TeamShaper::default(),
        }
    }

    fn shape(worlds: &Worlds) -> (usize, usize) {
        let config = worlds.config();
        // A configuration without `[[robots]]`: its lone robot's team of one.
        let robots = config.team_size().max(1);
        let longest = (0..robots)
            .map(|k| config.team_robot(k).observation_size())
            .max()
            .unwrap_or(0);
        (robots, longest)
    }

    fn start(
        &mut self,
        worlds: &Worlds,
        seed: u64,
        obs: &mut [f32],
        out: &mut [RobotStep],
    ) -> Result<(), RunError> {
        let rollout = TeamRollout::placed(worlds.config(), worlds.team(seed), seed)?;
        write(&rollout, obs, out);
        self.shaping = TeamShaper::start(&rollout);
        for o in out.iter_mut() {
            o.reward = 0.0;
            o.acted = false;
            o.collided = false;
        }
        self.rollout = Some(rollout);
        Ok(())
    }

    fn started(&self) -> bool {
        self.rollout.is_some()
    }

    fn done(&self) -> bool {
        self.rollout.as_ref().is_some_and(TeamRollout::finished)
    }
}

impl Teams {
    /// One step of the team: `actions[k]` for robot `k` (ignored when it is done) and, when
    /// given, `messages` (`message_size` floats a robot) for the next broadcast; its
    /// observations into `obs` and its robots' records into `out`.
    fn step(
        &mut self,
        actions: &[Action],
        messages: Option<&[f32]>,
        obs: &mut [f32],
        out: &mut [RobotStep],
    ) {
        let Some(rollout) = self.rollout.as_mut() else {
            return;
        };
        let m = messages.map_or(0, |all| all.len() / actions.len().max(1));
        let mut chosen = Vec::with_capacity(actions.len());
        for (k, (&a, o)) in actions.iter().zip(out.iter_mut()).enumerate() {
            let running = rollout.team().running(k);
            o.acted = running;
            chosen.push(running.then_some(a));
            if let (Some(messages), true) = (messages, running && m > 0) {
                rollout.set_message(k, &messages[k * m..(k + 1) * m]);
            }
        }
        rollout.step(&chosen);
        write(rollout, obs, out);
        for (k, o) in out.iter_mut().enumerate().filter(|(_, o)| o.acted) {
            o.reward = self.shaping.shaped(k, rollout.team().robot(k), o.reward);
        }
    }
}

/// Writes the rollout's observations and flags into its rows (as many values a row as `obs`
/// holds over `out`'s robots).
fn write(rollout: &TeamRollout, obs: &mut [f32], out: &mut [RobotStep]) {
    let team = rollout.team();
    let d = obs.len() / out.len().max(1);
    for (k, (row, o)) in obs.chunks_mut(d.max(1)).zip(out.iter_mut()).enumerate() {
        let r = team.robot(k);
        let seen = r.observation();
        row[..seen.len()].copy_from_slice(seen);
        row[seen.len()..].fill(0.0);
        let status = r.status();
        o.reward = if o.acted { team.rewards()[k] } else { 0.0 };
        o.terminated = status.is_terminated();
        o.truncated = status.is_truncated();
        o.running = team.running(k);
        o.collided = o.acted && team.collided(k);
        o.success = status == Status::Success;
    }
}

impl BatchOf<Teams> {
    /// Steps every environment: `actions[i R + k]` is robot `k` of environment `i`'s action
    /// (ignored for robots that are done); `messages`, when given, `N x R x message_size`
    /// floats, their messages for the next broadcast. Environments waiting for a next-step
    /// reset start their next episode instead; environments never reset start theirs first (as
    /// a reset with the seeds they hold), then step, as a [`Batch`](crate::run::Batch)'s do.
    pub fn step(&mut self, actions: &[Action], messages: Option<&[f32]>) -> Result<(), RunError> {
        let per_env = self.rows();
        if actions.len() != self.len() * per_env {
            return Err(RunError::ActionCount {
                given: actions.len(),
                envs: self.len() * per_env,
            });
        }
        let m = self.message_size();
        if let Some(messages) = messages {
            if messages.len() != actions.len() * m {
                return Err(RunError::ActionCount {
                    given: messages.len() / m.max(1),
                    envs: actions.len(),
                });
            }
        }
        self.call(|batch| {
            batch.step_each(|i, teams, obs, out| {
                let mine = i * per_env..(i + 1) * per_env;
                let said = messages
                    .filter(|_| m > 0)
                    .map(|all| &all[mine.start * m..mine.end * m]);
                teams.step(&actions[mine], said, obs, out);
            })
        })
    }

    /// Environment `i`'s current episode, once started.
    pub fn rollout(&self, i: usize) -> Option<&TeamRollout> {
        self.lane(i).and_then(|t| t.rollout.as_ref())
    }

    /// Robots per environment.
    pub fn robots(&self) -> usize {
        self.rows()
    }

    /// Floats in a robot's message.
    pub fn message_size(&self) -> usize {
        self.worlds().config().team.message_size as usize
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::{SimConfig, TeamRobotConfig};
    use crate::run::{Autoreset, BatchOptions, SeedOrder};
    use crate::sim::{DiscreteAction, Scenes};

    fn options(envs: usize, threads: usize) -> BatchOptions {
        BatchOptions {
            envs,
            threads,
            autoreset: Autoreset::NextStep,
            seed_order: SeedOrder::Strided,
        }
    }

    fn worlds(count: u32) -> Worlds {
        let mut c = SimConfig {
            robots: vec![TeamRobotConfig {
                count,
                ..TeamRobotConfig::default()
            }],
            ..SimConfig::default()
        };
        c.episode.max_steps = 40;
        let valid = c.validate().unwrap();
        Worlds::new(valid, Scenes::MazePerSeed)
    }

    fn run(threads: usize) -> (Vec<f32>, Vec<RobotStep>) {
        // 40 environments of 3 robots: runs of 6 environments (18 rows) on two threads.
        let mut b = TeamBatch::new(worlds(3), options(40, threads)).unwrap();
        b.reset(10).unwrap();
        let mut all_obs = b.observations().to_vec();
        let mut all_steps = b.steps().to_vec();
        for t in 0..90 {
            let actions: Vec<Action> = (0..120)
                .map(|j| DiscreteAction::from_index((j + t) % 3).unwrap().into())
                .collect();
            b.step(&actions, None).unwrap();
            all_obs.extend_from_slice(b.observations());
            all_steps.extend_from_slice(b.steps());
        }
        (all_obs, all_steps)
    }

    #[test]
    fn same_bits_on_one_and_two_threads() {
        assert_eq!(run(1), run(2));
    }

    #[test]
    fn matches_a_lone_rollout_and_restarts_with_the_next_seed() {
        let w = worlds(3);
        let mut b = TeamBatch::new(w.clone(), options(2, 1)).unwrap();
        b.reset(5).unwrap();
        // Environment 1 plays seed 6 as a rollout of its own would.
        let mut lone = TeamRollout::placed(w.config(), w.team(6), 6).unwrap();
        let ahead: Action = DiscreteAction::from_index(1).unwrap().into();
        let mut steps = 0;
        while !lone.finished() {
            lone.step(&[Some(ahead); 3]);
            b.step(&[ahead; 6], None).unwrap();
            steps += 1;
            let team = lone.team();
            for k in 0..3 {
                let row =
                    &b.observations()[(3 + k) * b.observation_size()..][..b.observation_size()];
                assert_eq!(row, team.robot(k).observation(), "step {steps}, robot {k}");
                assert_eq!(b.steps()[3 + k].reward, team.rewards()[k]);
            }
        }
        assert!(steps <= 40);
        // Its next episode (on the following step) is seed 6 + 2.
        while !b.was_reset(1) {
            b.step(&[ahead; 6], None).unwrap();
        }
        assert_eq!(b.rollout(1).unwrap().team().robot(0).seed(), 8);
        assert!(b.steps()[3..6]
            .iter()
            .all(|s| !s.acted && s.reward == 0.0 && s.running));
    }

    #[test]
    fn wrong_counts_are_refused() {
        let mut b = TeamBatch::new(worlds(2), options(3, 1)).unwrap();
        b.reset(0).unwrap();
        let ahead: Action = DiscreteAction::from_index(1).unwrap().into();
        assert!(matches!(
            b.step(&[ahead; 5], None),
            Err(RunError::ActionCount { given: 5, envs: 6 })
        ));
    }

    /// Each step's observations, rows' (reward bits, terminated, truncated) and seeds.
    type Trace = Vec<(Vec<f32>, Vec<(u64, bool, bool)>, Vec<u64>)>;

    /// A batch's trace over `steps` steps of a fixed action pattern: every row's observation,
    /// reward bits and flags, and each environment's seed, restarting ended environments by
    /// hand when automatic resets are disabled.
    fn trace<E: Lane>(
        b: &mut BatchOf<E>,
        steps: usize,
        step: impl Fn(&mut BatchOf<E>, &[Action]),
        row: impl Fn(&E::Record) -> (u64, bool, bool),
        seed: impl Fn(&BatchOf<E>, usize) -> u64,
    ) -> Trace {
        let rows = b.len() * b.rows();
        let mut out = Vec::new();
        for t in 0..steps {
            let actions: Vec<Action> = (0..rows)
                .map(|j| DiscreteAction::from_index((j + t) % 3).unwrap().into())
                .collect();
            step(b, &actions);
            let seeds = (0..b.len()).map(|i| seed(b, i)).collect();
            out.push((
                b.observations().to_vec(),
                b.steps().iter().map(&row).collect(),
                seeds,
            ));
            if b.options().autoreset == Autoreset::Disabled {
                let ended: Vec<bool> = (0..b.len()).map(|i| b.lane(i).unwrap().done()).collect();
                if ended.contains(&true) {
                    b.restart(&ended, &vec![None; b.len()]).unwrap();
                }
            }
        }
        out
    }

    fn lone_worlds() -> Worlds {
        let mut c = SimConfig::default();
        c.episode.max_steps = 30;
        Worlds::new(c.validate().unwrap(), Scenes::MazePerSeed)
    }

    #[test]
    fn a_team_of_one_batch_steps_a_lone_batchs_bits_in_every_mode() {
        for autoreset in [
            Autoreset::NextStep,
            Autoreset::SameStep,
            Autoreset::Disabled,
        ] {
            for seed_order in [SeedOrder::Strided, SeedOrder::InOrder] {
                // 40 environments: runs of 16 on the calling thread and the pool's.
                let options = BatchOptions {
                    envs: 40,
                    threads: 2,
                    autoreset,
                    seed_order,
                };
                let mut lone = crate::run::Batch::new(lone_worlds(), options).unwrap();
                let mut team = TeamBatch::new(lone_worlds(), options).unwrap();
                assert_eq!(team.rows(), 1);
                assert_eq!(team.observation_size(), lone.observation_size());
                lone.reset(7).unwrap();
                team.reset(7).unwrap();
                let a = trace(
                    &mut lone,
                    150,
                    |b, actions| b.step_actions(actions).unwrap(),
                    |s| {
                        (
                            s.reward.to_bits(),
                            s.status.is_terminated(),
                            s.status.is_truncated(),
                        )
                    },
                    |b, i| b.episode(i).unwrap().seed(),
                );
                let b = trace(
                    &mut team,
                    150,
                    |b, actions| b.step(actions, None).unwrap(),
                    |s| (s.reward.to_bits(), s.terminated, s.truncated),
                    |b, i| b.rollout(i).unwrap().seed(),
                );
                assert!(a.iter().any(|(_, r, _)| r.iter().any(|f| f.1 || f.2)));
                assert_eq!(a, b, "{autoreset:?}, {seed_order:?}");
                if autoreset == Autoreset::SameStep {
                    assert!(lone.final_observations().iter().any(|&v| v != 0.0));
                    assert_eq!(lone.final_observations(), team.final_observations());
                }
            }
        }
    }

    #[test]
    fn a_team_batch_restarts_by_hand_as_same_step_autoreset_does() {
        let run = |autoreset, seed_order| {
            let options = BatchOptions {
                envs: 4,
                threads: 1,
                autoreset,
                seed_order,
            };
            let mut b = TeamBatch::new(worlds(3), options).unwrap();
            b.reset(3).unwrap();
            let t = trace(
                &mut b,
                100,
                |b, actions| b.step(actions, None).unwrap(),
                |s| (s.reward.to_bits(), s.terminated, s.truncated),
                |b, i| b.rollout(i).unwrap().seed(),
            );
            (t, b.observations().to_vec())
        };
        for order in [SeedOrder::Strided, SeedOrder::InOrder] {
            let same = run(Autoreset::SameStep, order);
            assert!(same.0.iter().any(|(_, r, _)| r.iter().any(|f| f.1 || f.2)));
            let off = run(Autoreset::Disabled, order);
            // The records of every step (the same-step restart shows the new episode's
            // observations and seed at once, restarting by hand a call later), and where the
            // episodes stand at the end.
            let records =
                |(t, _): &(Trace, Vec<f32>)| -> Vec<_> { t.iter().map(|s| s.1.clone()).collect() };
            assert_eq!(records(&same), records(&off), "{order:?}");
            assert_eq!(same.1, off.1, "{order:?}");
        }
        // In order, the restarts take the seeds after the first four, one by one.
        let (t, _) = run(Autoreset::SameStep, SeedOrder::InOrder);
        let mut seeds: Vec<u64> = t.iter().flat_map(|(_, _, s)| s.clone()).collect();
        seeds.sort_unstable();
        seeds.dedup();
        assert_eq!(seeds, (3..3 + seeds.len() as u64).collect::<Vec<_>>());
    }

    #[test]
    fn an_ended_team_is_refused_without_autoreset() {
        let options = BatchOptions {
            envs: 2,
            threads: 1,
            autoreset: Autoreset::Disabled,
            seed_order: SeedOrder::Strided,
        };
        let mut b = TeamBatch::new(worlds(2), options).unwrap();
        b.reset(0).unwrap();
        let ahead: Action = DiscreteAction::from_index(1).unwrap().into();
        let ended = loop {
            b.step(&[ahead; 4], None).unwrap();
            if let Some(i) = (0..2).find(|&i| b.lane(i).unwrap().done()) {
                break i;
            }
        };
        assert_eq!(
            b.step(&[ahead; 4], None),
            Err(RunError::Ended { env: ended })
        );
    }
}
