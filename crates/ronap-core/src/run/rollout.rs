//! A rollout: one robot's episode driven by one policy, a step at a time, for callers that follow
//! a single robot (`ronap view`, driven data collection). It is the robot's team of one
//! ([`TeamRollout`]) seen as one robot, so it steps and judges a policy's answer exactly as an
//! evaluation does: an action is taken (a non-finite one, or one the robot does not take, is an
//! error), and giving up ends the episode as a failure with the policy's reason.

use crate::policy::{Alone, Policy};
use crate::run::{RunError, TeamRollout};
use crate::scene::FreeGrid;
use crate::sim::{Action, Episode, Pose, Rng, World};
use std::sync::Arc;

/// What one step of a rollout did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stepped {
    /// The step number, from 1.
    pub step: u32,
    /// The action taken.
    pub action: Action,
    /// Whether its motion would have touched an obstacle (and so did not happen).
    pub collided: bool,
    /// Its reward.
    pub reward: f64,
    /// The pose after it.
    pub pose: Pose,
}

/// One robot's episode in its world, driven by a policy.
#[derive(Clone, Debug)]
pub struct Rollout {
    /// The robot's team of one.
    one: TeamRollout,
}

impl Rollout {
    /// The episode of `seed` in `world`, with `policy` reset for it.
    pub fn start(world: Arc<World>, seed: u64, policy: &mut dyn Policy) -> Result<Self, RunError> {
        let w = world.clone();
        RunError::refuse_team(w.config(), seed)?;
        let one = TeamRollout::start(w.config(), vec![world], seed, &mut Alone(policy))?;
        Ok(Self { one })
    }

    /// The episode of `seed` in `world`, for a caller that chooses every action itself.
    pub fn new(world: Arc<World>, seed: u64) -> Result<Self, RunError> {
        let w = world.clone();
        RunError::refuse_team(w.config(), seed)?;
        let one = TeamRollout::placed(w.config(), vec![world], seed)?;
        Ok(Self { one })
    }

    /// Whether the episode is over: its status says so, or the policy gave up.
    pub fn finished(&self) -> bool {
        self.one.finished()
    }

    /// The policy's next action, checked; `None` once the episode is over (the policy giving up
    /// ends it, and [`Rollout::gave_up`] then says why).
    pub fn decide(&mut self, policy: &mut dyn Policy) -> Result<Option<Action>, RunError> {
        if self.finished() {
            return Ok(None);
        }
        match policy.act_in_team(self.one.team(), 0) {
            Ok(decision) => self.one.decided(0, decision),
            Err(source) => Err(self.one.policy_error(source)),
        }
    }

    /// Takes `action`; on a finished episode (or one the policy gave up) nothing moves and the
    /// reward is 0.
    pub fn take(&mut self, action: Action) -> Stepped {
        let moves = !self.finished();
        self.one.step(&[Some(action)]);
        let team = self.one.team();
        Stepped {
            step: team.robot(0).steps(),
            action,
            collided: moves && team.collided(0),
            reward: if moves { team.rewards()[0] } else { 0.0 },
            pose: team.robot(0).pose(),
        }
    }

    /// Asks `policy` for the next action and takes it; `None` once the episode is over.
    pub fn advance(&mut self, policy: &mut dyn Policy) -> Result<Option<Stepped>, RunError> {
        Ok(self.decide(policy)?.map(|action| self.take(action)))
    }

    /// The episode as it stands.
    pub fn episode(&self) -> &Episode {
        self.one.team().robot(0)
    }

    /// Puts the robot down elsewhere ([`Episode::repose`]: the paper's re-posing in data
    /// collection); the pose, or `None` when no free pose turned up.
    pub fn repose(&mut self, grid: Option<&FreeGrid>, rng: &mut Rng) -> Option<Pose> {
        self.one.lone_mut()?.repose(grid, rng)
    }

    /// The world the episode runs in.
    pub fn world(&self) -> &Arc<World> {
        self.one.world(0)
    }

    /// Why the policy gave up, when it did.
    pub fn gave_up(&self) -> Option<&str> {
        self.one.gave_up(0)
    }
}
