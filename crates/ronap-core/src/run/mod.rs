//! Running policies, above `policy`: one episode of a team driven by a team policy
//! ([`TeamRollout`]), a lone robot's episode being its team of one; that team of one seen as
//! one robot driven by one policy ([`Rollout`]); and many episodes stepped side by side with
//! automatic resets, lone robots' or teams' ([`Batch`], the one engine of the vectorised Python
//! environments and of DQN; [`TeamBatch`] is its team kind). Uses every layer up to `policy`.
//!
//! The files are private: what other crates use is re-exported here (`pub use`), and what the
//! layers above use beside it, `pub(crate) use`, so a file can move without breaking anyone.

mod batch;
mod rollout;
mod shaping;
mod team;

pub use batch::{
    Autoreset, Batch, BatchOf, BatchOptions, EnvStep, Lane, Lone, RobotStep, SeedOrder, TeamBatch,
    Teams,
};
pub use rollout::{Rollout, Stepped};
pub use shaping::{Shaper, TeamShaper};
pub(crate) use team::robot_worlds;
pub use team::{TeamRollout, TourLengths};

// For the layers above only.

use crate::policy::PolicyError;
use crate::sim::{Action, EpisodeError};

/// An episode that could not start, or a policy that failed while driving one.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum RunError {
    /// An episode could not start.
    #[error("seed {seed}: {source}")]
    Episode {
        /// The episode seed.
        seed: u64,
        /// What went wrong.
        source: EpisodeError,
    },
    /// The policy failed.
    #[error("seed {seed}, step {step}: policy failed: {source}")]
    Policy {
        /// The episode seed.
        seed: u64,
        /// The step at which it failed (0: while resetting).
        step: u32,
        /// What went wrong.
        source: PolicyError,
    },
    /// The policy returned an action that is not finite, or one the robot does not take (a
    /// `(vx, vy, w)` command for a robot that is not omnidirectional, a `(v, steer)` one for a
    /// robot that does not steer).
    #[error("seed {seed}, step {step}: policy returned an invalid action {action:?}")]
    InvalidAction {
        /// The episode seed.
        seed: u64,
        /// The step.
        step: u32,
        /// The action.
        action: Action,
    },
    /// A batch was given another number of actions than it has environments.
    #[error("{given} actions for {envs} environments")]
    ActionCount {
        /// Actions given.
        given: usize,
        /// Environments.
        envs: usize,
    },
    /// A batch was given another number of per-environment values than it has environments.
    #[error("{given} {what} for {envs} environments")]
    Count {
        /// What was given.
        what: &'static str,
        /// How many.
        given: usize,
        /// Environments.
        envs: usize,
    },
    /// A batch without automatic resets was asked to step an environment whose episode ended.
    #[error("environment {env}: its episode ended; restart it before stepping it again")]
    Ended {
        /// The environment.
        env: usize,
    },
    /// The worker threads could not start.
    #[error("cannot start worker threads: {0}")]
    Threads(String),
}

impl RunError {
    /// Refuses `config` for a lone robot's episode of `seed` when it is a team's (it has
    /// `[[robots]]`): such an episode runs as a team ([`TeamRollout`]).
    pub fn refuse_team(config: &crate::ValidConfig, seed: u64) -> Result<(), Self> {
        match config.team_size() {
            0 => Ok(()),
            robots => Err(Self::Episode {
                seed,
                source: EpisodeError::Team { robots },
            }),
        }
    }

    /// The policy failing to prepare for the episode of `seed` (step 0).
    pub(crate) fn reset(seed: u64, source: PolicyError) -> Self {
        Self::Policy {
            seed,
            step: 0,
            source,
        }
    }
}
