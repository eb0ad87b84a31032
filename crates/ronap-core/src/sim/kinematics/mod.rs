//! Kinematics: how a robot's body answers a command. A [`Kinematics`] says where an action
//! takes the robot in one step and which straight sweeps of its body the step's collision check
//! must pass, so that no speed carries the robot through an obstacle. One file per kind of
//! robot: [`Unicycle`] (the paper's discrete actions and continuous `(v, w)` arcs) is the
//! built-in; a new kind is a new file implementing [`Kinematics`] and a line in
//! [`for_robot`] that makes it ([`Built::Other`]).

mod unicycle;

pub use unicycle::Unicycle;

use crate::config::RobotConfig;
use crate::geometry::{Point, Vector};
use crate::sim::action::{Action, Pose};
use std::fmt::Debug;
use std::sync::Arc;

/// The pose a step leads to, before the collision check, and how the body gets there.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Motion {
    /// The pose at the end of the step.
    pub end: Pose,
    /// How much of a full turn command the step is, in [0, 1] (for the turning penalty).
    pub turn_fraction: f64,
    /// Linear speed over the step, px (signed).
    pub(crate) v: f64,
    /// Heading change over the step, degrees (signed).
    pub(crate) w_deg: f64,
}

impl Motion {
    /// The motion to `end` of a step that moves `v` px along the way (signed) while turning
    /// `w_deg` degrees, `turn_fraction` of a full turn command (for the turning penalty): what a
    /// [`Kinematics`] of one's own returns.
    pub fn new(end: Pose, turn_fraction: f64, v: f64, w_deg: f64) -> Self {
        Self {
            end,
            turn_fraction,
            v,
            w_deg,
        }
    }

    /// Linear speed over the step, px (signed).
    pub fn v(&self) -> f64 {
        self.v
    }

    /// Heading change over the step, degrees (signed).
    pub fn w_deg(&self) -> f64 {
        self.w_deg
    }
}

/// A robot's body in motion: what an action does to its pose, and what the step sweeps.
pub trait Kinematics: Send + Sync + Debug {
    /// Where `action` takes the body from `pose` in free space (no collision check); `facing`
    /// is `pose`'s unit heading when the caller has it already (the same bits as working it
    /// out).
    fn motion(&self, pose: Pose, facing: Option<Vector>, action: Action) -> Motion;

    /// Whether the body, a disc of `radius_px`, can make `motion` from `pose` with every
    /// straight piece of its sweep passing `sweep_clear(from, to, radius)` (the radius grown
    /// where a straight piece stands for a curve, so the check errs on the side of a
    /// collision).
    fn sweep(
        &self,
        pose: Pose,
        motion: &Motion,
        radius_px: f64,
        sweep_clear: &mut dyn FnMut(Point, Point, f64) -> bool,
    ) -> bool;

    /// `action` as the three values an observation's action memory keeps of it, each in
    /// [0, 1] (`observation.history`).
    fn remembered(&self, action: Action) -> [f32; 3];
}

/// The kinematics of the robot `config` describes.
pub fn for_robot(config: &RobotConfig) -> Built {
    Built::Unicycle(Unicycle::new(config))
}

/// A robot's kinematics as [`for_robot`] makes them: the built-in unicycle as itself (so that
/// the robot calls it directly, its step inlined), any other kind behind the trait.
#[derive(Clone, Debug)]
pub enum Built {
    /// The paper's robot.
    Unicycle(Unicycle),
    /// Any other kind.
    Other(Arc<dyn Kinematics>),
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::robot::{DiscreteAction, Robot};

    /// The unicycle behind the trait, as a kind of robot of one's own would be.
    #[derive(Debug)]
    struct Wrapped(Unicycle);

    impl Kinematics for Wrapped {
        fn motion(&self, pose: Pose, facing: Option<Vector>, action: Action) -> Motion {
            self.0.motion(pose, facing, action)
        }

        fn sweep(
            &self,
            pose: Pose,
            motion: &Motion,
            radius_px: f64,
            sweep_clear: &mut dyn FnMut(Point, Point, f64) -> bool,
        ) -> bool {
            self.0.sweep(pose, motion, radius_px, sweep_clear)
        }

        fn remembered(&self, action: Action) -> [f32; 3] {
            self.0.remembered(action)
        }
    }

    #[test]
    fn kinematics_behind_the_trait_move_a_robot_as_the_built_in_does() {
        let config = RobotConfig::default();
        let built_in = Robot::new(&config);
        let own =
            Robot::with_kinematics(config.radius_px, Arc::new(Wrapped(Unicycle::new(&config))));
        let config_all = crate::SimConfig::default().validate().expect("valid");
        let scene = crate::sim::world::maze_scene(&config_all, 3);
        let actions = [
            Action::from(DiscreteAction::Left),
            DiscreteAction::Ahead.into(),
            DiscreteAction::Right.into(),
            Action::Continuous {
                v: 4.0,
                w_deg: -9.0,
            },
            Action::Continuous {
                v: 50.0,
                w_deg: 90.0,
            },
            Action::Continuous {
                v: -2.0,
                w_deg: 0.0,
            },
        ];
        let mut blocked = 0;
        for i in 0..400 {
            let pose = Pose::new(
                5.0 + f64::from(i * 37 % 990),
                5.0 + f64::from(i * 91 % 990),
                f64::from(i * 13),
            );
            for &a in &actions {
                let (m, n) = (built_in.motion(pose, a), own.motion(pose, a));
                assert_eq!(m, n);
                let clear = built_in.motion_clear(&scene, pose, &m);
                assert_eq!(clear, own.motion_clear(&scene, pose, &n));
                blocked += usize::from(!clear);
                assert_eq!(
                    built_in.kinematics().remembered(a),
                    own.kinematics().remembered(a)
                );
            }
        }
        // Some of those moves run into walls, so both answers of the check are compared.
        assert!(blocked > 0);
    }
}
