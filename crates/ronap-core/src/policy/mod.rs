//! Policies, above `plan`: what decides each step's action, one file per policy. Every policy
//! implements [`Policy`], so the episode loop and the evaluator never know which one they run.
//! Uses `config`, `geometry`, `scene`, `sim` and `plan`.
//!
//! The files are private: what other crates use is re-exported here (`pub use`), and what the
//! layers above use beside it, `pub(crate) use`, so a file can move without breaking anyone.

mod apf;
mod batched;
mod coordinated;
mod dodge;
mod dwa;
mod follow;
mod geodesic;
mod local;
mod mlp;
mod name;
mod orca;
mod random;
mod social_force;
mod team;

// The built-in policies by name, and policies deciding for many robots or environments at once.
pub use batched::{BatchPolicy, Batched, Rows};
pub use name::{factory, Builtin, PolicyNameError};
pub use team::{
    Alone, Joint, JointFactory, PerRobot, PerRobotFactory, RobotError, TeamPolicy,
    TeamPolicyFactory,
};
// The team planner; its name and `drives` are aliased here, as the policy layer holds many names.
pub use coordinated::{
    drives as coordinated_drives, Coordinated, CoordinatedFactory, NAME as COORDINATED_NAME,
};
// Trained networks.
pub use mlp::{
    observation_layout, Activation, DecisionRule, Layer, Mlp, MlpError, MlpFactory, MlpPolicy,
    Scratch, RRELU_SLOPE, SIDE_BY_SIDE,
};

// For the layers above only.
pub(crate) use geodesic::Expert;

use crate::sim::{Action, Episode, World};

/// A policy that could not decide.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum PolicyError {
    /// The policy failed (a user policy raised, returned an invalid action or NaN, ...).
    #[error("{0}")]
    Failed(String),
}

/// What a policy does at a step.
#[derive(Clone, Debug, PartialEq)]
pub enum Decision {
    /// Take this action.
    Act(Action),
    /// Stop: the policy knows it cannot reach the goal (trapped in a local minimum, oscillating,
    /// no path). The episode ends as a failure with this reason.
    GiveUp(String),
}

/// Decides actions, one episode at a time.
pub trait Policy: Send {
    /// Prepares for a new episode (plans, clears state). Called before the first [`Policy::act`].
    fn reset(&mut self, world: &World, episode: &Episode) -> Result<(), PolicyError>;

    /// The decision for the episode's current state.
    fn act(&mut self, episode: &Episode) -> Result<Decision, PolicyError>;

    /// The decision for robot `k` of `team` when it is driven by this policy alone among the
    /// team's ([`team::PerRobot`]): by default [`Policy::act`] on the robot's own episode; a
    /// policy that avoids the other robots and the team's moving obstacles sees them here.
    fn act_in_team(&mut self, team: &crate::sim::Team, k: usize) -> Result<Decision, PolicyError> {
        self.act(team.robot(k))
    }

    /// The message a robot of a team broadcasts with its last decision (`team.message_size`
    /// floats, zeros already in `out`); the built-in policies send none.
    fn message(&mut self, out: &mut [f32]) {
        let _ = out;
    }

    /// What a robot of a team received at the last step (the broadcasts of the robots within
    /// `team.comm_range_px`, nearest first), told before each [`Policy::act`]; the built-in
    /// policies do not listen.
    fn hear(&mut self, inbox: crate::sim::Inbox<'_>) {
        let _ = inbox;
    }

    /// Prepares lane `lane` for a new episode, for a policy whose factory runs episodes
    /// [side by side](PolicyFactory::side_by_side): each lane keeps its own episode's state, as
    /// [`Policy::reset`] prepares the one episode of a policy run alone (the default).
    fn reset_lane(
        &mut self,
        lane: usize,
        world: &World,
        episode: &Episode,
    ) -> Result<(), PolicyError> {
        let _ = lane;
        self.reset(world, episode)
    }

    /// The decisions for several episodes at once, each given with its lane, pushed onto
    /// `decisions` in the same order: what [`Policy::act`] decides for each, but sharing the
    /// work between them (a network evaluating its rows together). Exactly one decision per
    /// episode; on an error, the index in `episodes` of the episode it belongs to, with one
    /// decision pushed for each episode before it (the evaluator fails the run otherwise). The
    /// default asks [`Policy::act`] in turn.
    fn act_lanes(
        &mut self,
        episodes: &[(usize, &Episode)],
        decisions: &mut Vec<Decision>,
    ) -> Result<(), (usize, PolicyError)> {
        for (k, (_, episode)) in episodes.iter().enumerate() {
            decisions.push(self.act(episode).map_err(|e| (k, e))?);
        }
        Ok(())
    }
}

/// Makes policies: one per worker thread of an evaluation.
pub trait PolicyFactory: Sync {
    /// A fresh policy.
    fn make(&self) -> Result<Box<dyn Policy>, PolicyError>;

    /// The policy's name, for reports.
    fn name(&self) -> String;

    /// How many episodes each policy it makes decides for together, through
    /// [`Policy::reset_lane`] and [`Policy::act_lanes`]: more than 1 only when deciding together
    /// is cheaper and every lane keeps its own state. The evaluator then steps that many episodes
    /// of a worker side by side; their records are the same as one at a time, bit for bit, but
    /// for the episodes' wall times.
    fn side_by_side(&self) -> usize {
        1
    }

    /// The episode seeds the policy was trained or chosen on, where it records them (a trained
    /// network's `training_seeds` and `validation_seeds`): a run over any of them is warned
    /// about ([`crate::eval::held_out_warning`]).
    fn seeds_seen(&self) -> crate::sim::SeedRanges {
        crate::sim::SeedRanges::default()
    }
}
