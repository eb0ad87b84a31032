//! The robot: a disc with a pose `[x px, y px, z deg]`, its discrete and continuous actions, and
//! its kinematics ([`crate::sim::kinematics`]), which say where an action takes it. The whole
//! motion of a step is swept against the scene, so no speed carries the disc through a wall.

pub use crate::sim::action::{Action, DiscreteAction, Pose};
pub use crate::sim::kinematics::Motion;

use crate::config::RobotConfig;
use crate::geometry::{Point, Vector};
use crate::scene::Scene;
use crate::sim::kinematics::{self, Built, Kinematics};
use std::sync::Arc;

/// The robot's shape and how it moves ([`Kinematics`]).
#[derive(Clone, Debug)]
pub struct Robot {
    radius_px: f64,
    /// The built-in unicycle held as itself, any other kind behind the trait: a step's motion and
    /// sweep then inline into the episode's step for the paper's robot, where three calls
    /// through the trait (motion, sweep, and the sweep's test) cost 4% of `ronap bench
    /// --threads 1`'s steps.
    kinematics: Built,
}

impl Robot {
    /// The robot `config` describes.
    pub fn new(config: &RobotConfig) -> Self {
        Self {
            radius_px: config.radius_px,
            kinematics: kinematics::for_robot(config),
        }
    }

    /// A disc of `radius_px` moving as `kinematics` says (a kind of robot of one's own).
    pub fn with_kinematics(radius_px: f64, kinematics: Arc<dyn Kinematics>) -> Self {
        Self {
            radius_px,
            kinematics: Built::Other(kinematics),
        }
    }

    /// Disc radius, px.
    pub fn radius_px(&self) -> f64 {
        self.radius_px
    }

    /// How the robot moves.
    pub fn kinematics(&self) -> &dyn Kinematics {
        match &self.kinematics {
            Built::Unicycle(u) => u,
            Built::Other(k) => k.as_ref(),
        }
    }

    /// Where `action` takes the robot from `pose` in free space.
    pub fn motion(&self, pose: Pose, action: Action) -> Motion {
        self.motion_facing(pose, None, action)
    }

    /// [`Robot::motion`], given `pose`'s unit heading (`unit(pose.z_deg)`) when the caller has it
    /// already: a move straight ahead goes along it (the same bits: `unit` is the heading's cosine
    /// and sine, as the move works them out without it).
    pub fn motion_facing(&self, pose: Pose, facing: Option<Vector>, action: Action) -> Motion {
        match &self.kinematics {
            Built::Unicycle(u) => u.motion(pose, facing, action),
            Built::Other(k) => k.motion(pose, facing, action),
        }
    }

    /// Whether the disc can make `motion` from `pose` without touching an obstacle.
    pub fn motion_clear(&self, scene: &Scene, pose: Pose, motion: &Motion) -> bool {
        self.motion_clear_by(pose, motion, |a, b, r| scene.sweep_clear(a, b, r))
    }

    /// Whether the disc can make `motion` from `pose` with every straight piece of its sweep
    /// passing `sweep_clear(from, to, radius)`: the same check against any obstacles.
    pub fn motion_clear_by(
        &self,
        pose: Pose,
        motion: &Motion,
        mut sweep_clear: impl FnMut(Point, Point, f64) -> bool,
    ) -> bool {
        match &self.kinematics {
            Built::Unicycle(u) => u.sweep_by(pose, motion, self.radius_px, &mut sweep_clear),
            Built::Other(k) => k.sweep(pose, motion, self.radius_px, &mut sweep_clear),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn discrete_actions_follow_the_spec() {
        let robot = Robot::new(&RobotConfig::default());
        let p = Pose::new(100.0, 100.0, 90.0);
        let ahead = robot.motion(p, DiscreteAction::Ahead.into()).end;
        assert!((ahead.x - 100.0).abs() < 1e-12 && (ahead.y - 105.0).abs() < 1e-12);
        assert_eq!(
            robot.motion(p, DiscreteAction::Left.into()).end.z_deg,
            105.0
        );
        assert_eq!(
            robot.motion(p, DiscreteAction::Right.into()).end.z_deg,
            75.0
        );
        let wrapped = robot.motion(Pose::new(0.0, 0.0, 350.0), DiscreteAction::Left.into());
        assert_eq!(wrapped.end.z_deg, 5.0);
    }

    #[test]
    fn continuous_actions_are_clipped_unicycle_arcs() {
        let robot = Robot::new(&RobotConfig::default());
        let p = Pose::new(0.0, 0.0, 0.0);
        let m = robot.motion(
            p,
            Action::Continuous {
                v: 100.0,
                w_deg: 0.0,
            },
        );
        assert!((m.end.x - 5.0).abs() < 1e-12);
        // A quarter turn at v = 5, w = 90 would be clipped to w = 15 deg.
        let m = robot.motion(
            p,
            Action::Continuous {
                v: 5.0,
                w_deg: 90.0,
            },
        );
        assert!((m.end.z_deg - 15.0).abs() < 1e-12);
        let r = 5.0 / 15f64.to_radians();
        assert!((m.end.x - r * 15f64.to_radians().sin()).abs() < 1e-9);
        assert!((m.end.y - r * (1.0 - 15f64.to_radians().cos())).abs() < 1e-9);
        assert_eq!(m.turn_fraction, 1.0);
    }
}
