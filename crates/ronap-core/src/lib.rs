//! ronap-core: the RoNAP robot-navigation model (docs/model.md), as a library.
//!
//! A robot disc drives through a scene (a seeded maze or an image) with a 17-beam laser, discrete
//! or continuous actions and a goal; an [`Episode`] steps it and scores it. Units are scene px and
//! degrees, with x right and y up. Nothing here parses arguments, prints or exits: the `ronap`
//! binary and the Python module wrap it.
//!
//! The crate is in layers, each a folder whose `mod.rs` says what it is for. A layer uses only
//! the layers listed before it (`tests/layers.rs` holds the code to that):
//!
//! | layer | holds |
//! | --- | --- |
//! | [`bounded`] | reading a user's file within a size bound (uses nothing) |
//! | [`config`] | every model field with its default, and their validation |
//! | [`geometry`] | points, boxes, the bin index, the ray grid, parry2d as the reference geometry |
//! | [`scene`] | the scene's obstacles, mazes, image and ROS maps, the free-space grid |
//! | [`sim`] | robot and actions, laser, random streams, placement, the episode, worlds and scenes |
//! | [`plan`] | geodesic distance fields and shortest paths |
//! | [`policy`] | the `Policy` trait and one file per policy |
//! | [`run`] | one episode driven by one policy (a rollout), N episodes stepped side by side (a batch) |
//! | [`eval`] | the batch evaluator, its records and summary |
//! | [`render`] | pictures: canvas, first-person view, trajectories, GIFs |
//! | [`io`] | files: atomic writes, run directories and their manifest, data logs, step logs |
//! | [`job`] | use-cases: an evaluation (lone or team) into a run directory, a team replayed from its logs |
//! | [`collect`] | labelled data: expert and human collection |
//! | [`compare`] | several policies on the same seeds: paired statistics, pictures, a report |

// Every type the API hands out can be named by its callers (a `pub use` in its layer).
#![warn(unnameable_types)]

pub mod bounded;
pub mod collect;
pub mod compare;
pub mod config;
pub mod eval;
pub mod geometry;
pub mod io;
pub mod job;
pub mod plan;
pub mod policy;
pub mod render;
pub mod run;
pub mod scene;
pub mod sim;

/// The version of the simulation model: the scenes, sensors, kinematics, random streams and
/// metrics that make an episode out of a seed. Runs recorded under another model version do not
/// replay the same (`ronap --version` prints it, `summary.json` records it and `ronap replay`
/// refuses a run of another).
///
/// - 1: the first.
/// - 2: a `random_walk` obstacle turns by a near-normal draw (the sum of eight random bytes) of
///   its own SplitMix64 stream, not by a normal draw of the shared moving-obstacle stream.
pub const MODEL_VERSION: u32 = 2;

pub use config::{ConfigError, SimConfig, ValidConfig};
pub use geometry::{Aabb, Point, Vector};
pub use scene::{Maze, Scene, SceneError};
pub use sim::{
    Action, DiscreteAction, Episode, EpisodeError, Laser, Placement, Pose, Robot, Scenes, Status,
    StepResult, World,
};
