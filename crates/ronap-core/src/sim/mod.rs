//! The simulation: the robot and its actions, the laser, the random streams, placement of start
//! and goal, the episode that steps and scores them, a team of several robots, and the worlds
//! episodes run in. Uses `config`, `geometry` and `scene`.

pub mod action;
pub mod episode;
pub mod kinematics;
pub mod lidar;
pub mod moving;
pub mod placement;
pub mod rng;
pub mod robot;
pub mod team;
pub mod world;
