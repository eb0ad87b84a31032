//! The unicycle: the paper's robot. A discrete action turns on the spot by `turn_speed_deg`
//! (LEFT, RIGHT) or moves `move_speed_px` along the heading (AHEAD); a continuous action
//! `(v, w)`, clipped to `max_linear_speed_px` and `max_angular_speed_deg`, follows an arc of
//! constant speed and turn rate over the step. The body is a disc; an arc is checked along
//! chords with the radius grown by the arc's distance from them.

use crate::config::{RobotConfig, ACTION_MEMORY};
use crate::geometry::{Point, Vector};
use crate::sim::action::{Action, DiscreteAction, Pose};
use crate::sim::kinematics::{Kinematics, Motion};

/// Largest sagitta, px, between a continuous step's arc and the chords it is checked along; the
/// chords are checked with the radius grown by it, so the check errs on the side of a collision.
const ARC_TOLERANCE_PX: f64 = 0.01;

/// A unicycle's speeds and limits (docs/model.md "Robot").
#[derive(Clone, Debug, PartialEq)]
pub struct Unicycle {
    /// AHEAD's distance, px.
    move_speed_px: f64,
    /// LEFT's and RIGHT's turn, degrees.
    turn_speed_deg: f64,
    /// Largest |v| of a continuous action, px per step.
    max_linear_speed_px: f64,
    /// Largest |w| of a continuous action, degrees per step.
    max_angular_speed_deg: f64,
}

impl Unicycle {
    /// The unicycle of the robot `config` describes.
    pub fn new(config: &RobotConfig) -> Self {
        Self {
            move_speed_px: config.move_speed_px,
            turn_speed_deg: config.turn_speed_deg,
            max_linear_speed_px: config.max_linear_speed_px,
            max_angular_speed_deg: config.max_angular_speed_deg,
        }
    }

    /// The speed, turn and turn fraction `action` commands.
    #[inline]
    fn command(&self, action: Action) -> (f64, f64, f64) {
        match action {
            Action::Discrete(DiscreteAction::Left) => (0.0, self.turn_speed_deg, 1.0),
            Action::Discrete(DiscreteAction::Right) => (0.0, -self.turn_speed_deg, 1.0),
            Action::Discrete(DiscreteAction::Ahead) => (self.move_speed_px, 0.0, 0.0),
            Action::Continuous { v, w_deg } => {
                let (v_max, w_max) = (self.max_linear_speed_px, self.max_angular_speed_deg);
                let v = if v.is_nan() { 0.0 } else { v };
                let w = if w_deg.is_nan() { 0.0 } else { w_deg };
                let v = v.clamp(-v_max, v_max);
                let w = w.clamp(-w_max, w_max);
                let frac = if w_max > 0.0 { w.abs() / w_max } else { 0.0 };
                (v, w, frac)
            }
        }
    }
}

impl Kinematics for Unicycle {
    #[inline]
    fn motion(&self, pose: Pose, facing: Option<Vector>, action: Action) -> Motion {
        let (v, w_deg, turn_fraction) = self.command(action);
        Motion {
            end: arc_end(pose, v, w_deg, facing),
            turn_fraction,
            v,
            w_deg,
        }
    }

    fn sweep(
        &self,
        pose: Pose,
        motion: &Motion,
        radius_px: f64,
        sweep_clear: &mut dyn FnMut(Point, Point, f64) -> bool,
    ) -> bool {
        self.sweep_by(pose, motion, radius_px, sweep_clear)
    }

    /// One-hot LEFT, AHEAD, RIGHT; a continuous action as `w+ / w_max, v / v_max, w- / w_max`.
    fn remembered(&self, action: Action) -> [f32; ACTION_MEMORY] {
        match action {
            Action::Discrete(d) => {
                let mut v = [0.0; ACTION_MEMORY];
                v[d as usize] = 1.0;
                v
            }
            Action::Continuous { v, w_deg } => {
                let (v_max, w_max) = (self.max_linear_speed_px, self.max_angular_speed_deg);
                let w = (w_deg / w_max).clamp(-1.0, 1.0);
                [
                    w.max(0.0) as f32,
                    (v / v_max).clamp(0.0, 1.0) as f32,
                    (-w).max(0.0) as f32,
                ]
            }
        }
    }
}

impl Unicycle {
    /// [`Kinematics::sweep`] with the test known to the compiler (inlined into a step).
    #[inline]
    pub(crate) fn sweep_by(
        &self,
        pose: Pose,
        motion: &Motion,
        radius_px: f64,
        mut sweep_clear: impl FnMut(Point, Point, f64) -> bool,
    ) -> bool {
        let r = radius_px;
        if motion.v == 0.0 {
            // Turning in place sweeps nothing new.
            return true;
        }
        let w = motion.w_deg.to_radians();
        if w.abs() < 1e-12 {
            return sweep_clear(pose.position(), motion.end.position(), r);
        }
        // Follow the arc by chords short enough that the arc stays within ARC_TOLERANCE_PX of
        // them (at most 1024 chords), and check each with the radius grown by the arc's actual
        // distance from its chords, so the check errs on the side of a collision.
        let arc_radius = (motion.v / w).abs();
        let max_angle = if arc_radius > ARC_TOLERANCE_PX {
            2.0 * (1.0 - ARC_TOLERANCE_PX / arc_radius).acos()
        } else {
            std::f64::consts::PI
        };
        let chords = ((w.abs() / max_angle).ceil() as usize).clamp(1, 1024);
        let sagitta = arc_radius * (1.0 - (w.abs() / chords as f64 / 2.0).cos());
        let mut from = pose;
        for k in 1..=chords {
            let part = k as f64 / chords as f64;
            let to = arc_end(pose, motion.v * part, motion.w_deg * part, None);
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
}

/// The pose after moving `v` px along a unicycle arc that turns `w_deg` degrees from `pose`
/// (whose unit heading `facing` is, when given).
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
