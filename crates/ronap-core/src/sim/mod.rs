//! The simulation: poses and actions, the robot and its kinematics (a trait, one file per kind),
//! the laser, the random streams, placement of start and goal, the episode that steps and scores
//! a robot, moving obstacles (their behaviours a trait, one file each), a team of several robots
//! (a team of one steps as a lone robot), and the worlds episodes run in. Uses `config`,
//! `geometry` and `scene`.

pub mod action;
pub mod avoid;
pub mod episode;
pub mod kinematics;
pub mod lidar;
pub mod moving;
pub mod noise;
pub mod placement;
pub mod rng;
pub mod robot;
pub mod split;
pub mod team;
pub mod world;
