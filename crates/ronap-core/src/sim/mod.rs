//! The simulation: poses and actions, the robot and its kinematics (a trait, one file per kind),
//! the laser, the random streams, placement of start and goal, the episode that steps and scores
//! a robot, moving obstacles (their behaviours a trait, one file each), a team of several robots
//! (a team of one steps as a lone robot), and the worlds episodes run in. Uses `config`,
//! `geometry` and `scene`.
//!
//! The files are private: what other crates use is re-exported here (`pub use`), and what the
//! layers above use beside it, `pub(crate) use`, so a file can move without breaking anyone.

mod action;
mod avoid;
mod episode;
mod kinematics;
mod lidar;
mod moving;
mod noise;
mod placement;
mod rng;
mod robot;
mod split;
mod team;
mod world;

// A robot, its actions and its laser.
pub use kinematics::{continuous_action, Kinematics, Motion, Velocity};
pub use lidar::{Laser, RayClass};
pub use robot::{Action, DiscreteAction, Pose, Robot};
// An episode, where it starts, and the scenes and worlds it runs in.
pub use episode::{DynamicMetrics, Episode, Status, StepResult};
pub use placement::{free_grid, needs_region_grid, sample_placement, EpisodeError, Placement};
pub use split::{SeedRanges, Split};
pub use world::{maze_scene, warehouse_scene, SceneSpec, Scenes, World, Worlds};
// Moving obstacles and teams.
pub use moving::{
    Advance, Agent, Behaviour, Body, Disc, Mover, Movers, MovingError, Neighbours, Track,
};
pub use team::{Broadcast, Inbox, InboxIter, Team};

// For the layers above only.
pub(crate) use avoid::{social_force_velocity, Avoid, Avoider};
pub(crate) use episode::PREFETCH_STAGES;
pub(crate) use kinematics::accepts;
pub(crate) use rng::{stream, Rng, Stream};
