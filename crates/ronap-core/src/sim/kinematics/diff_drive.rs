//! A differential-drive base: two wheels `wheel_base_px` apart, commanded `(v, w)` as a
//! unicycle is, but the velocity it holds changes by at most `accel_max_px` (linear) and
//! `alpha_max_deg` (turn) a step, and, given a wheel base, neither wheel turns faster than
//! `max_linear_speed_px`. The paper's discrete actions command `(0, +-turn_speed_deg)` and
//! `(move_speed_px, 0)` under the same limits.

use crate::config::{RobotConfig, ACTION_MEMORY};
use crate::sim::action::{Action, DiscreteAction};
use crate::sim::kinematics::{
    approach, finite_or_zero, remembered_twist, turn_fraction, Kinematics, Velocity,
};

/// A differential-drive base's speeds and limits (docs/model.md "Kinematics").
#[derive(Clone, Debug, PartialEq)]
pub struct DiffDrive {
    move_speed_px: f64,
    turn_speed_deg: f64,
    v_max: f64,
    w_max: f64,
    accel_max_px: Option<f64>,
    alpha_max_deg: Option<f64>,
    wheel_base_px: Option<f64>,
}

impl DiffDrive {
    /// The base the robot `config` describes.
    pub fn new(config: &RobotConfig) -> Self {
        Self {
            move_speed_px: config.move_speed_px,
            turn_speed_deg: config.turn_speed_deg,
            v_max: config.max_linear_speed_px,
            w_max: config.max_angular_speed_deg,
            accel_max_px: config.accel_max_px,
            alpha_max_deg: config.alpha_max_deg,
            wheel_base_px: config.wheel_base_px,
        }
    }

    /// `(v, w_deg)` within the speed limits and, given a wheel base, the wheel-speed limit:
    /// scaled down as a whole, so that its curvature stays.
    fn within(&self, v: f64, w_deg: f64) -> (f64, f64) {
        let v = finite_or_zero(v).clamp(-self.v_max, self.v_max);
        let w = finite_or_zero(w_deg).clamp(-self.w_max, self.w_max);
        if let Some(b) = self.wheel_base_px {
            // The faster wheel goes |v| + |w| b / 2.
            let wheel = v.abs() + w.to_radians().abs() * b / 2.0;
            if wheel > self.v_max {
                let s = self.v_max / wheel;
                return (v * s, w * s);
            }
        }
        (v, w)
    }
}

impl Kinematics for DiffDrive {
    fn command(&self, velocity: Velocity, action: Action) -> (Velocity, f64) {
        let (v, w) = match action {
            Action::Discrete(DiscreteAction::Left) => (0.0, self.turn_speed_deg),
            Action::Discrete(DiscreteAction::Right) => (0.0, -self.turn_speed_deg),
            Action::Discrete(DiscreteAction::Ahead) => (self.move_speed_px, 0.0),
            Action::Continuous { v, w_deg } => (v, w_deg),
            Action::Omni { vx, w_deg, .. } => (vx, w_deg),
            Action::Steer { v, .. } => (v, 0.0),
        };
        let (v, w) = self.within(v, w);
        // The start and the target both lie within the (convex) limits; a point between them
        // does too.
        let [v, _, w] = approach(
            [velocity.v, 0.0, velocity.w_deg],
            [v, 0.0, w],
            self.accel_max_px,
            self.alpha_max_deg,
        );
        (
            Velocity {
                v,
                w_deg: w,
                ..Velocity::default()
            },
            turn_fraction(w, self.w_max),
        )
    }

    fn clamp(&self, velocity: Velocity) -> Velocity {
        let (v, w_deg) = self.within(velocity.v, velocity.w_deg);
        Velocity {
            v,
            w_deg,
            ..Velocity::default()
        }
    }

    fn remembered(&self, action: Action) -> [f32; ACTION_MEMORY] {
        remembered_twist(action, self.v_max, self.w_max)
    }
}
