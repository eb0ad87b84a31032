//! The unicycle: the paper's robot. A discrete action turns on the spot by `turn_speed_deg`
//! (LEFT, RIGHT) or moves `move_speed_px` along the heading (AHEAD); a continuous action
//! `(v, w)`, clipped to `max_linear_speed_px` and `max_angular_speed_deg`, is reached at once
//! and held over the step (an arc of constant speed and turn rate).

use crate::config::{RobotConfig, ACTION_MEMORY};
use crate::sim::action::{Action, DiscreteAction};
use crate::sim::kinematics::{
    finite_or_zero, remembered_twist, turn_fraction, Kinematics, Velocity,
};

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

    /// The speed, turn and turn fraction `action` commands: a discrete action as the paper's,
    /// a continuous one clipped to the limits (a NaN is 0).
    #[inline(always)]
    pub(crate) fn target(&self, action: Action) -> (f64, f64, f64) {
        let continuous = |v: f64, w_deg: f64| {
            let (v_max, w_max) = (self.max_linear_speed_px, self.max_angular_speed_deg);
            let v = finite_or_zero(v).clamp(-v_max, v_max);
            let w = finite_or_zero(w_deg).clamp(-w_max, w_max);
            (v, w, turn_fraction(w, w_max))
        };
        match action {
            Action::Discrete(DiscreteAction::Left) => (0.0, self.turn_speed_deg, 1.0),
            Action::Discrete(DiscreteAction::Right) => (0.0, -self.turn_speed_deg, 1.0),
            Action::Discrete(DiscreteAction::Ahead) => (self.move_speed_px, 0.0, 0.0),
            Action::Continuous { v, w_deg } => continuous(v, w_deg),
            // Not a unicycle's commands: the part a unicycle can follow (no sideways speed; a
            // steering command drives straight).
            Action::Omni { vx, w_deg, .. } => continuous(vx, w_deg),
            Action::Steer { v, .. } => continuous(v, 0.0),
        }
    }
}

impl Kinematics for Unicycle {
    #[inline]
    fn command(&self, _velocity: Velocity, action: Action) -> (Velocity, f64) {
        let (v, w_deg, turn_fraction) = self.target(action);
        (
            Velocity {
                v,
                w_deg,
                ..Velocity::default()
            },
            turn_fraction,
        )
    }

    fn clamp(&self, velocity: Velocity) -> Velocity {
        let (v_max, w_max) = (self.max_linear_speed_px, self.max_angular_speed_deg);
        Velocity {
            v: velocity.v.clamp(-v_max, v_max),
            w_deg: velocity.w_deg.clamp(-w_max, w_max),
            ..Velocity::default()
        }
    }

    /// One-hot LEFT, AHEAD, RIGHT; a continuous action as `w+ / w_max, v / v_max, w- / w_max`.
    fn remembered(&self, action: Action) -> [f32; ACTION_MEMORY] {
        remembered_twist(action, self.max_linear_speed_px, self.max_angular_speed_deg)
    }
}
