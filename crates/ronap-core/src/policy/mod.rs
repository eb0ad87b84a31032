//! Policies, above `plan`: what decides each step's action, one file per policy. Every policy
//! implements [`Policy`], so the episode loop and the evaluator never know which one they run.
//! Uses `config`, `geometry`, `scene`, `sim` and `plan`.

pub mod apf;
pub mod batched;
pub mod dodge;
pub mod follow;
pub mod geodesic;
pub mod mlp;
pub mod name;
pub mod random;

pub use name::{factory, Builtin, PolicyNameError};

use crate::sim::episode::Episode;
use crate::sim::robot::Action;
use crate::sim::world::World;

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

    /// The message a robot of a team broadcasts with its last decision (`team.message_size`
    /// floats, zeros already in `out`); the built-in policies send none.
    fn message(&mut self, out: &mut [f32]) {
        let _ = out;
    }

    /// What a robot of a team received at the last step (the broadcasts of the robots within
    /// `team.comm_range_px`, nearest first), told before each [`Policy::act`]; the built-in
    /// policies do not listen.
    fn hear(&mut self, inbox: crate::sim::team::Inbox<'_>) {
        let _ = inbox;
    }
}

/// Makes policies: one per worker thread of an evaluation.
pub trait PolicyFactory: Sync {
    /// A fresh policy.
    fn make(&self) -> Result<Box<dyn Policy>, PolicyError>;

    /// The policy's name, for reports.
    fn name(&self) -> String;
}
