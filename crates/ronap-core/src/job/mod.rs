//! Use-cases, above `io`: running an evaluation into a run directory, a lone robot's
//! ([`evaluate_into`]) or a team's ([`evaluate_team_into`]), and replaying a team episode from
//! its robots' step logs ([`replay_team`]), animating a run's chosen episodes from the steps it
//! recorded, and the HTML players of episodes ([`play_lone`], [`play_team`]): the sequences the
//! command line,
//! Python and `compare` share. A use-case takes one [`RunRequest`] (what to run, where its
//! results go, how to stop it) rather than a long list of arguments. Uses every layer up to `io`;
//! `io` reads and writes formats, `render` draws, and neither runs an episode for this layer.
//!
//! The files are private: what other crates use is re-exported here (`pub use`), and what the
//! layers above use beside it, `pub(crate) use`, so a file can move without breaking anyone.

mod animate;
mod evaluate;
mod into;
mod player;
mod replay;
mod team;

pub use evaluate::{evaluate_into, Evaluation};
pub(crate) use player::{lone_record, team_record};
pub use player::{play_lone, play_team, single_page};
pub use replay::{replay_team, ReplayError, RobotLog};
pub use team::{evaluate_team_into, TeamEvaluation};

use crate::eval::{EvalOptions, Evaluator};
use crate::io::{RunInfo, RunWriter};
use std::sync::atomic::AtomicBool;

/// An evaluation to run and where its results go.
pub struct RunRequest<'a> {
    /// The episodes' configuration and scenes.
    pub evaluator: &'a Evaluator,
    /// The seeds, threads and what to record.
    pub options: &'a EvalOptions,
    /// What the manifest records of the run: the policy's name, the scenes, the map.
    pub info: &'a RunInfo,
    /// The run directory, made or taken up again to resume (`None`: figures only, no files).
    pub writer: Option<RunWriter>,
    /// Set (Ctrl-C, a signal) to stop the run between episodes, keeping what finished.
    pub cancel: &'a AtomicBool,
}
