//! A batch of team episodes stepped side by side, across cores, for learning with several
//! robots: N environments of R robots each, actions and messages given as flat arrays, and
//! observations, rewards and flags written into flat buffers (`N x R x D`, `N x R`), where `D` is
//! the longest robot observation (shorter ones padded with zeros). An environment whose robots
//! are all done starts its next episode on the following step (Gymnasium's next-step autoreset),
//! which ignores its actions and reports the new start with rewards 0.
//!
//! Environment `i`'s `k`-th episode has seed `base + i + k N`, so a batch steps the same bits on
//! any number of threads.

use crate::config::ValidConfig;
use crate::run::team::TeamRollout;
use crate::run::{RunError, TeamShaper};
use crate::sim::{Action, Status, Worlds};
use rayon::prelude::*;

/// Environments per parallel task.
const MIN_PER_TASK: usize = 4;

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

/// One environment with its observation rows and robot step records.
type Lane<'a> = ((&'a mut Env, &'a mut [f32]), &'a mut [RobotStep]);

/// One environment: its team episode and where its next seed comes from.
struct Env {
    rollout: Option<TeamRollout>,
    /// Its robots' reward shaping, under `reward.shaping`.
    shaping: TeamShaper,
    next_seed: u64,
    /// Whether the latest call was a reset of this environment.
    reset: bool,
}

/// N team environments stepped together.
pub struct TeamBatch {
    worlds: Worlds,
    config: ValidConfig,
    pool: rayon::ThreadPool,
    envs: Vec<Env>,
    robots: usize,
    observation_size: usize,
    message_size: usize,
    observations: Vec<f32>,
    steps: Vec<RobotStep>,
}

impl TeamBatch {
    /// `envs` team environments (at least 1) in `worlds`, whose configuration has `[[robots]]`,
    /// on `threads` worker threads (0: all cores); none started yet.
    pub fn new(worlds: Worlds, envs: usize, threads: usize) -> Result<Self, RunError> {
        let config = worlds.config().clone();
        let robots = config.team_size();
        let n = envs.max(1);
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .map_err(|e| RunError::Threads(e.to_string()))?;
        let observation_size = (0..robots)
            .map(|k| config.team_robot(k).observation_size())
            .max()
            .unwrap_or(0);
        Ok(Self {
            message_size: config.team.message_size as usize,
            worlds,
            config,
            pool,
            envs: (0..n)
                .map(|_| Env {
                    rollout: None,
                    shaping: TeamShaper::default(),
                    next_seed: 0,
                    reset: false,
                })
                .collect(),
            robots,
            observation_size,
            observations: vec![0.0; n * robots * observation_size],
            steps: vec![RobotStep::default(); n * robots],
        })
    }

    /// Starts every environment afresh: environment `i` gets seed `seed + i`, its next episode
    /// `seed + i + N`, and so on.
    pub fn reset(&mut self, seed: u64) -> Result<(), RunError> {
        for (i, env) in self.envs.iter_mut().enumerate() {
            env.next_seed = seed.wrapping_add(i as u64);
            env.rollout = None;
        }
        self.each(|ctx, env, obs, out| ctx.start(env, obs, out))
    }

    /// Steps every environment: `actions[i R + k]` is robot `k` of environment `i`'s action
    /// (ignored for robots that are done); `messages`, when given, `N x R x message_size`
    /// floats, their messages for the next broadcast. Environments whose robots were all done
    /// start their next episode instead; environments never reset start theirs.
    pub fn step(&mut self, actions: &[Action], messages: Option<&[f32]>) -> Result<(), RunError> {
        let per_env = self.robots;
        if actions.len() != self.envs.len() * per_env {
            return Err(RunError::ActionCount {
                given: actions.len(),
                envs: self.envs.len() * per_env,
            });
        }
        let m = self.message_size;
        if let Some(messages) = messages {
            if messages.len() != actions.len() * m {
                return Err(RunError::ActionCount {
                    given: messages.len() / m.max(1),
                    envs: actions.len(),
                });
            }
        }
        self.each(|ctx, env, obs, out| {
            let i = ctx.index;
            let Some(rollout) = env.rollout.as_mut() else {
                return ctx.start(env, obs, out);
            };
            if rollout.finished() {
                return ctx.start(env, obs, out);
            }
            env.reset = false;
            let mine = &actions[i * per_env..(i + 1) * per_env];
            let mut chosen = Vec::with_capacity(per_env);
            for (k, (&a, o)) in mine.iter().zip(out.iter_mut()).enumerate() {
                let running = rollout.team().running(k);
                o.acted = running;
                chosen.push(running.then_some(a));
                if let (Some(messages), true) = (messages, running && m > 0) {
                    let at = (i * per_env + k) * m;
                    rollout.set_message(k, &messages[at..at + m]);
                }
            }
            rollout.step(&chosen);
            ctx.write(rollout, obs, out);
            for (k, o) in out.iter_mut().enumerate().filter(|(_, o)| o.acted) {
                o.reward = env.shaping.shaped(k, rollout.team().robot(k), o.reward);
            }
            Ok(())
        })
    }

    /// Runs `f` on every environment with its rows of the buffers; on the pool for a big
    /// batch. The first error in environment order wins.
    fn each(
        &mut self,
        f: impl Fn(&Ctx<'_>, &mut Env, &mut [f32], &mut [RobotStep]) -> Result<(), RunError> + Sync,
    ) -> Result<(), RunError> {
        let (r, d) = (self.robots, self.observation_size);
        let (stride, worlds, config) = (self.envs.len() as u64, &self.worlds, &self.config);
        let ctx = |index| Ctx {
            index,
            stride,
            worlds,
            config,
            observation_size: d,
        };
        let envs = &mut self.envs;
        let obs = &mut self.observations;
        let steps = &mut self.steps;
        let one = |(i, ((env, obs), out)): (usize, Lane<'_>)| f(&ctx(i), env, obs, out);
        let results: Vec<Result<(), RunError>> = if envs.len() <= MIN_PER_TASK {
            envs.iter_mut()
                .zip(obs.chunks_mut((r * d).max(1)))
                .zip(steps.chunks_mut(r.max(1)))
                .enumerate()
                .map(one)
                .collect()
        } else {
            self.pool.install(|| {
                envs.par_iter_mut()
                    .zip(obs.par_chunks_mut((r * d).max(1)))
                    .zip(steps.par_chunks_mut(r.max(1)))
                    .enumerate()
                    .with_min_len(MIN_PER_TASK)
                    .map(one)
                    .collect()
            })
        };
        results.into_iter().collect()
    }

    /// Observations: robot `k` of environment `i` at row `i R + k`, [`TeamBatch::observation_size`]
    /// floats a row (zeros past its own length).
    pub fn observations(&self) -> &[f32] {
        &self.observations
    }

    /// Each robot's latest step, `i R + k`.
    pub fn steps(&self) -> &[RobotStep] {
        &self.steps
    }

    /// Environment `i`'s current episode, once started.
    pub fn rollout(&self, i: usize) -> Option<&TeamRollout> {
        self.envs.get(i).and_then(|e| e.rollout.as_ref())
    }

    /// Whether environment `i`'s latest call started a new episode.
    pub fn was_reset(&self, i: usize) -> bool {
        self.envs.get(i).is_some_and(|e| e.reset)
    }

    /// Number of environments.
    pub fn len(&self) -> usize {
        self.envs.len()
    }

    /// Whether the batch has no environments (never: it has at least one).
    pub fn is_empty(&self) -> bool {
        self.envs.is_empty()
    }

    /// Robots per environment.
    pub fn robots(&self) -> usize {
        self.robots
    }

    /// Length of an observation row.
    pub fn observation_size(&self) -> usize {
        self.observation_size
    }

    /// Floats in a robot's message.
    pub fn message_size(&self) -> usize {
        self.message_size
    }
}

/// What every environment's work shares.
struct Ctx<'a> {
    index: usize,
    stride: u64,
    worlds: &'a Worlds,
    config: &'a ValidConfig,
    observation_size: usize,
}

impl Ctx<'_> {
    /// Starts `env`'s next episode into its rows.
    fn start(&self, env: &mut Env, obs: &mut [f32], out: &mut [RobotStep]) -> Result<(), RunError> {
        let seed = env.next_seed;
        let rollout = TeamRollout::placed(self.config, self.worlds.team(seed), seed)?;
        env.next_seed = seed.wrapping_add(self.stride);
        env.reset = true;
        self.write(&rollout, obs, out);
        env.shaping = TeamShaper::start(&rollout);
        for o in out.iter_mut() {
            o.reward = 0.0;
            o.acted = false;
            o.collided = false;
        }
        env.rollout = Some(rollout);
        Ok(())
    }

    /// Writes the rollout's observations and flags into its rows.
    fn write(&self, rollout: &TeamRollout, obs: &mut [f32], out: &mut [RobotStep]) {
        let team = rollout.team();
        let d = self.observation_size;
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
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::{SimConfig, TeamRobotConfig};
    use crate::sim::{DiscreteAction, Scenes};

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
        let mut b = TeamBatch::new(worlds(3), 6, threads).unwrap();
        b.reset(10).unwrap();
        let mut all_obs = b.observations().to_vec();
        let mut all_steps = b.steps().to_vec();
        for t in 0..90 {
            let actions: Vec<Action> = (0..18)
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
        let mut b = TeamBatch::new(w.clone(), 2, 1).unwrap();
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
        let mut b = TeamBatch::new(worlds(2), 3, 1).unwrap();
        b.reset(0).unwrap();
        let ahead: Action = DiscreteAction::from_index(1).unwrap().into();
        assert!(matches!(
            b.step(&[ahead; 5], None),
            Err(RunError::ActionCount { given: 5, envs: 6 })
        ));
    }
}
