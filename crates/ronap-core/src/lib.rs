//! ronap-core: the RoNAP robot-navigation model (SPEC.md), as a library.
//!
//! A robot disc drives through a scene (a seeded maze or an image) with a 17-beam laser, discrete
//! or continuous actions and a goal; an [`Episode`] steps it and scores it. Units are scene px and
//! degrees, with x right and y up. Nothing here parses arguments, prints or exits: the `ronap`
//! binary and the Python module wrap it.

pub mod animation;
pub mod collect;
pub mod config;
pub mod datalog;
pub mod episode;
pub mod evaluate;
pub mod freespace;
pub mod geometry;
pub mod human;
pub mod index;
pub mod lidar;
pub mod map;
pub mod maze;
pub mod output;
pub mod planning;
pub mod policy;
pub mod reference;
pub mod render;
pub mod report;
pub mod rng;
pub mod robot;
pub mod scene;
pub mod summary;
pub mod world;

pub use config::{ConfigError, SimConfig, ValidConfig};
pub use episode::{Episode, EpisodeError, Placement, Status, StepResult};
pub use geometry::{Aabb, Point, Vector};
pub use lidar::Laser;
pub use maze::Maze;
pub use robot::{Action, DiscreteAction, Pose, Robot};
pub use scene::{Scene, SceneError};
pub use world::World;
