//! A rollout: one episode driven by one policy, a step at a time. The evaluator, `ronap view` and
//! driven data collection all step episodes through it, so they agree on what a policy's answer
//! means: an action is taken (a non-finite continuous one is an error), giving up ends the episode
//! as a failure with the policy's reason.

use crate::policy::{Decision, Policy, PolicyError};
use crate::run::RunError;
use crate::sim::{Action, Episode, Pose, World};
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

/// One episode in its world, driven by a policy.
#[derive(Clone, Debug)]
pub struct Rollout {
    world: Arc<World>,
    episode: Episode,
    gave_up: Option<String>,
}

impl Rollout {
    /// The episode of `seed` in `world`, with `policy` reset for it.
    pub fn start(world: Arc<World>, seed: u64, policy: &mut dyn Policy) -> Result<Self, RunError> {
        Self::reset_by(world, seed, |world, episode| policy.reset(world, episode))
    }

    /// The episode of `seed` in `world`, with lane `lane` of `policy` reset for it (episodes run
    /// [side by side](crate::policy::PolicyFactory::side_by_side)).
    pub fn start_lane(
        world: Arc<World>,
        seed: u64,
        policy: &mut dyn Policy,
        lane: usize,
    ) -> Result<Self, RunError> {
        Self::reset_by(world, seed, |world, episode| {
            policy.reset_lane(lane, world, episode)
        })
    }

    /// The episode of `seed` in `world`, with `reset` (a policy's) called for it.
    fn reset_by(
        world: Arc<World>,
        seed: u64,
        reset: impl FnOnce(&World, &Episode) -> Result<(), PolicyError>,
    ) -> Result<Self, RunError> {
        let rollout = Self::new(world, seed)?;
        reset(&rollout.world, &rollout.episode).map_err(|e| RunError::reset(seed, e))?;
        Ok(rollout)
    }

    /// The episode of `seed` in `world`, for a caller that chooses every action itself.
    pub fn new(world: Arc<World>, seed: u64) -> Result<Self, RunError> {
        let episode = world
            .episode(seed)
            .map_err(|source| RunError::Episode { seed, source })?;
        Ok(Self {
            world,
            episode,
            gave_up: None,
        })
    }

    /// Whether the episode is over: its status says so, or the policy gave up.
    pub fn finished(&self) -> bool {
        self.episode.status().is_done() || self.gave_up.is_some()
    }

    /// The policy's next action, checked; `None` once the episode is over (the policy giving up
    /// ends it, and [`Rollout::gave_up`] then says why).
    pub fn decide(&mut self, policy: &mut dyn Policy) -> Result<Option<Action>, RunError> {
        if self.finished() {
            return Ok(None);
        }
        let decision = policy.act(&self.episode);
        self.decided(decision.map_err(|source| self.policy_error(source)))
    }

    /// The error of the policy failing to decide this step.
    pub fn policy_error(&self, source: PolicyError) -> RunError {
        RunError::Policy {
            seed: self.episode.seed(),
            step: self.episode.steps() + 1,
            source,
        }
    }

    /// [`Rollout::decide`] for a decision already made (with the others of episodes side by
    /// side) for this episode while not [finished](Rollout::finished): the action, checked;
    /// `None` when the policy gave up.
    pub fn decided(
        &mut self,
        decision: Result<Decision, RunError>,
    ) -> Result<Option<Action>, RunError> {
        let action = match decision? {
            Decision::Act(action) => action,
            Decision::GiveUp(why) => {
                self.gave_up = Some(why);
                return Ok(None);
            }
        };
        let kind = self.episode.config().robot.kinematics;
        if !action.is_finite() || !crate::sim::accepts(kind, action) {
            return Err(RunError::InvalidAction {
                seed: self.episode.seed(),
                step: self.episode.steps() + 1,
                action,
            });
        }
        Ok(Some(action))
    }

    /// Takes `action`.
    pub fn take(&mut self, action: Action) -> Stepped {
        let r = self.episode.step(action);
        Stepped {
            step: r.step,
            action,
            collided: r.collided,
            reward: r.reward,
            pose: r.pose,
        }
    }

    /// Asks `policy` for the next action and takes it; `None` once the episode is over.
    pub fn advance(&mut self, policy: &mut dyn Policy) -> Result<Option<Stepped>, RunError> {
        Ok(self.decide(policy)?.map(|action| self.take(action)))
    }

    /// The episode as it stands.
    pub fn episode(&self) -> &Episode {
        &self.episode
    }

    /// The episode, for callers that move the robot by other means (re-posing in data collection).
    pub fn episode_mut(&mut self) -> &mut Episode {
        &mut self.episode
    }

    /// The world the episode runs in.
    pub fn world(&self) -> &Arc<World> {
        &self.world
    }

    /// Why the policy gave up, when it did.
    pub fn gave_up(&self) -> Option<&str> {
        self.gave_up.as_deref()
    }

    /// The world, the episode and the reason the policy gave up.
    pub fn into_parts(self) -> (Arc<World>, Episode, Option<String>) {
        (self.world, self.episode, self.gave_up)
    }
}
