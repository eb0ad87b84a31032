//! Kinematics: how a robot's body answers a command (docs/model.md "Kinematics"). A
//! [`Kinematics`] turns an action into the velocity the body holds over the next step, within
//! its limits and from the velocity it had; every model's step is then the same exact motion:
//! a velocity held for a step follows a circular arc (a straight line without turning), and
//! the whole arc is swept against the obstacles, so no speed carries the robot through one.
//! One file per kind of robot: [`Unicycle`] (the paper's discrete actions and ideal `(v, w)`
//! arcs), [`DiffDrive`], [`Omni`] and [`Ackermann`]; a new kind is a new file implementing
//! [`Kinematics`] and a line in [`for_robot`] that makes it ([`Built::Other`]).

mod ackermann;
mod diff_drive;
mod omni;
mod unicycle;

pub use ackermann::Ackermann;
pub use diff_drive::DiffDrive;
pub use omni::Omni;
pub use unicycle::Unicycle;

use crate::config::{KinematicsKind, RobotConfig, ACTION_MEMORY};
use crate::geometry::{Point, Vector};
use crate::sim::action::{Action, DiscreteAction, Pose};
use std::fmt::Debug;
use std::sync::Arc;

/// Largest sagitta, px, between a step's arc and the chords it is checked along; the chords
/// are checked with the radius grown by it, so the check errs on the side of a collision.
const ARC_TOLERANCE_PX: f64 = 0.01;

/// The velocity a body holds over one step, in its own frame.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Velocity {
    /// Speed along the heading, px per step (signed).
    pub v: f64,
    /// Speed to the left of the heading, px per step (an omnidirectional robot's; 0 for the
    /// others).
    pub vy: f64,
    /// Turn rate, degrees per step (signed, counter-clockwise positive).
    pub w_deg: f64,
    /// Steering angle, degrees (a car-like robot's; 0 for the others).
    pub steer_deg: f64,
}

/// The pose a step leads to, before the collision check, and the velocity that takes the body
/// there.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Motion {
    /// The pose at the end of the step.
    pub end: Pose,
    /// How much of a full turn command the step is, in [0, 1] (for the turning penalty).
    pub turn_fraction: f64,
    /// The velocity held over the step.
    pub(crate) velocity: Velocity,
}

impl Motion {
    /// The velocity held over the step.
    pub fn velocity(&self) -> Velocity {
        self.velocity
    }

    /// Linear speed over the step, px (signed).
    pub fn v(&self) -> f64 {
        self.velocity.v
    }

    /// Heading change over the step, degrees (signed).
    pub fn w_deg(&self) -> f64 {
        self.velocity.w_deg
    }
}

/// A robot's body: what an action commands, within its limits.
pub trait Kinematics: Send + Sync + Debug {
    /// The velocity `action` commands over the next step, from `velocity` (the one held over
    /// the last step; zero at the start and after a blocked step), within the model's limits;
    /// and how much of a full turn command it is, in [0, 1] (for the turning penalty).
    fn command(&self, velocity: Velocity, action: Action) -> (Velocity, f64);

    /// `velocity` brought back within the model's speed limits (after motion noise).
    fn clamp(&self, velocity: Velocity) -> Velocity;

    /// `action` as the three values an observation's action memory keeps of it, each in
    /// [0, 1] (`observation.history`).
    fn remembered(&self, action: Action) -> [f32; ACTION_MEMORY];
}

/// The kinematics of the robot `config` describes.
pub fn for_robot(config: &RobotConfig) -> Built {
    match config.kinematics {
        KinematicsKind::Discrete | KinematicsKind::Unicycle => {
            Built::Unicycle(Unicycle::new(config))
        }
        KinematicsKind::DiffDrive => Built::Other(Arc::new(DiffDrive::new(config))),
        KinematicsKind::Omni => Built::Other(Arc::new(Omni::new(config))),
        KinematicsKind::Ackermann => Built::Other(Arc::new(Ackermann::new(config))),
    }
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

/// Whether a robot of kind `kind` takes `action`: every robot takes the paper's discrete
/// actions and `(v, w)` (a car steers to the curvature `w / v`); only an omnidirectional one
/// takes `(vx, vy, w)` and only a car `(v, steer)`.
pub fn accepts(kind: KinematicsKind, action: Action) -> bool {
    match action {
        Action::Discrete(_) | Action::Continuous { .. } => true,
        Action::Omni { .. } => kind == KinematicsKind::Omni,
        Action::Steer { .. } => kind == KinematicsKind::Ackermann,
    }
}

/// The continuous action of `values`, in full units (px, degrees) and as many as
/// [`RobotConfig::action_scale`] has: `(v, w)`, `(vx, vy, w)` for `omni`, `(v, steer)` for
/// `ackermann`. `None` for another count or a value that is not finite.
pub fn continuous_action(robot: &RobotConfig, values: &[f64]) -> Option<Action> {
    if values.iter().any(|v| !v.is_finite()) {
        return None;
    }
    match (robot.kinematics, values) {
        (KinematicsKind::Omni, &[vx, vy, w_deg]) => Some(Action::Omni { vx, vy, w_deg }),
        (KinematicsKind::Ackermann, &[v, steer_deg]) => Some(Action::Steer { v, steer_deg }),
        (KinematicsKind::Omni | KinematicsKind::Ackermann, _) => None,
        (_, &[v, w_deg]) => Some(Action::Continuous { v, w_deg }),
        _ => None,
    }
}

/// The pose after holding `velocity` for one step from `pose` (whose unit heading `facing` is,
/// when given): the exact arc of a constant velocity in the body's frame.
#[inline]
pub(crate) fn travel(pose: Pose, velocity: Velocity, facing: Option<Vector>) -> Pose {
    if velocity.vy == 0.0 {
        return arc_end(pose, velocity.v, velocity.w_deg, facing);
    }
    // Sideways speed: the body's point moves along the heading turned by the course angle,
    // on the same arc as a unicycle going that way.
    let (course, speed) = course(velocity);
    let along = arc_end(
        Pose::new(pose.x, pose.y, pose.z_deg + course),
        speed,
        velocity.w_deg,
        None,
    );
    Pose::new(along.x, along.y, pose.z_deg + velocity.w_deg)
}

/// The angle between the heading and the way a velocity moves the body, degrees, and its speed.
fn course(velocity: Velocity) -> (f64, f64) {
    (
        velocity.vy.atan2(velocity.v).to_degrees(),
        velocity.v.hypot(velocity.vy),
    )
}

/// Whether a disc of `radius_px` can hold `velocity` for a step from `pose` with every chord of
/// its arc passing `sweep_clear(from, to, radius)`, the radius grown by the arc's distance from
/// its chords, so the check errs on the side of a collision.
#[inline]
pub(crate) fn sweep_arc(
    pose: Pose,
    velocity: Velocity,
    end: Pose,
    radius_px: f64,
    mut sweep_clear: impl FnMut(Point, Point, f64) -> bool,
) -> bool {
    let r = radius_px;
    if velocity.v == 0.0 && velocity.vy == 0.0 {
        // Turning in place sweeps nothing new.
        return true;
    }
    let w = velocity.w_deg.to_radians();
    if w.abs() < 1e-12 {
        return sweep_clear(pose.position(), end.position(), r);
    }
    let (start, speed) = if velocity.vy == 0.0 {
        (pose, velocity.v)
    } else {
        let (course, speed) = course(velocity);
        (Pose::new(pose.x, pose.y, pose.z_deg + course), speed)
    };
    // Follow the arc by chords short enough that the arc stays within ARC_TOLERANCE_PX of
    // them (at most 1024 chords), and check each with the radius grown by the arc's actual
    // distance from its chords, so the check errs on the side of a collision.
    let arc_radius = (speed / w).abs();
    let max_angle = if arc_radius > ARC_TOLERANCE_PX {
        2.0 * (1.0 - ARC_TOLERANCE_PX / arc_radius).acos()
    } else {
        std::f64::consts::PI
    };
    let chords = ((w.abs() / max_angle).ceil() as usize).clamp(1, 1024);
    let sagitta = arc_radius * (1.0 - (w.abs() / chords as f64 / 2.0).cos());
    let mut from = start;
    for k in 1..=chords {
        let part = k as f64 / chords as f64;
        let to = arc_end(start, speed * part, velocity.w_deg * part, None);
        if !sweep_clear(
            from.position(),
            to.position(),
            r + sagitta.max(ARC_TOLERANCE_PX),
        ) {
            return false;
        }
        from = to;
    }
    true
}

/// The pose after moving `v` px along a unicycle arc that turns `w_deg` degrees from `pose`
/// (whose unit heading `facing` is, when given).
#[inline]
fn arc_end(pose: Pose, v: f64, w_deg: f64, facing: Option<Vector>) -> Pose {
    let z0 = pose.z_deg.to_radians();
    let w = w_deg.to_radians();
    let (dx, dy) = if v == 0.0 {
        // Turning on the spot (LEFT and RIGHT): the arc's formula gives a zero times its sines
        // and cosines, which a position plus zero leaves as it is. Four fewer calls to them.
        (0.0, 0.0)
    } else if w.abs() < 1e-12 {
        let (c, s) = facing.map_or_else(|| (z0.cos(), z0.sin()), |f| (f.x, f.y));
        (v * c, v * s)
    } else {
        let r = v / w;
        (
            r * ((z0 + w).sin() - z0.sin()),
            -r * ((z0 + w).cos() - z0.cos()),
        )
    };
    Pose::new(pose.x + dx, pose.y + dy, pose.z_deg + w_deg)
}

/// `target` reached from `from` as far as the limits allow: the change scaled down (the same
/// factor for every part, so a target and a start within a convex set of speeds give a result
/// within it) until the linear part changes by at most `accel` and the turn by at most
/// `alpha`.
fn approach(from: [f64; 3], target: [f64; 3], accel: Option<f64>, alpha: Option<f64>) -> [f64; 3] {
    let d = [
        target[0] - from[0],
        target[1] - from[1],
        target[2] - from[2],
    ];
    let linear = d[0].hypot(d[1]);
    let mut s: f64 = 1.0;
    if let Some(a) = accel {
        if linear > a {
            s = s.min(a / linear);
        }
    }
    if let Some(a) = alpha {
        if d[2].abs() > a {
            s = s.min(a / d[2].abs());
        }
    }
    if s >= 1.0 {
        return target;
    }
    [from[0] + s * d[0], from[1] + s * d[1], from[2] + s * d[2]]
}

/// A number made finite (a NaN command is no command).
fn finite_or_zero(x: f64) -> f64 {
    if x.is_nan() {
        0.0
    } else {
        x
    }
}

/// The action memory of one of the paper's actions: one-hot LEFT, AHEAD, RIGHT.
fn one_hot(action: DiscreteAction) -> [f32; ACTION_MEMORY] {
    let mut v = [0.0; ACTION_MEMORY];
    v[action as usize] = 1.0;
    v
}

/// The action memory of a body commanded in `(v, w)` with limits `v_max`, `w_max`: one-hot for
/// the paper's actions, else [`remembered_as`] (a sideways speed is not remembered; a steering
/// command, which such a body does not take, as going straight).
fn remembered_twist(action: Action, v_max: f64, w_max: f64) -> [f32; ACTION_MEMORY] {
    match action {
        Action::Discrete(d) => one_hot(d),
        Action::Continuous { v, w_deg } | Action::Omni { vx: v, w_deg, .. } => {
            remembered_as(v, v_max, w_deg, w_max)
        }
        Action::Steer { v, .. } => remembered_as(v, v_max, 0.0, w_max),
    }
}

/// How much of a full turn `w` is of the largest `w_max`, in [0, 1].
fn turn_fraction(w: f64, w_max: f64) -> f64 {
    if w_max > 0.0 {
        (w.abs() / w_max).min(1.0)
    } else {
        0.0
    }
}

/// The action memory of a command that goes `v` of `v_max` forward and turns `turn` of
/// `turn_max` (positive left): `left, ahead, right`, each in [0, 1].
fn remembered_as(v: f64, v_max: f64, turn: f64, turn_max: f64) -> [f32; ACTION_MEMORY] {
    let t = if turn_max > 0.0 {
        (turn / turn_max).clamp(-1.0, 1.0)
    } else {
        0.0
    };
    let a = if v_max > 0.0 {
        (v / v_max).clamp(0.0, 1.0)
    } else {
        0.0
    };
    [t.max(0.0) as f32, a as f32, (-t).max(0.0) as f32]
}

#[cfg(test)]
mod tests;
