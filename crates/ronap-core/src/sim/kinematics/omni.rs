//! An omnidirectional base: commanded `(vx, vy, w)` in its own frame (ahead, to the left, turn
//! rate), each within its limit (`max_linear_speed_px`, `max_lateral_speed_px`,
//! `max_angular_speed_deg`); the velocity it holds changes by at most `accel_max_px` (the
//! length of the change of `(vx, vy)`) and `alpha_max_deg` a step. A `(v, w)` command has no
//! sideways part; the paper's discrete actions are the unicycle's.

use crate::config::{RobotConfig, ACTION_MEMORY};
use crate::sim::action::{Action, DiscreteAction};
use crate::sim::kinematics::{
    approach, finite_or_zero, remembered_twist, turn_fraction, Kinematics, Velocity,
};

/// An omnidirectional base's speeds and limits (docs/model.md "Kinematics").
#[derive(Clone, Debug, PartialEq)]
pub struct Omni {
    move_speed_px: f64,
    turn_speed_deg: f64,
    v_max: f64,
    vy_max: f64,
    w_max: f64,
    accel_max_px: Option<f64>,
    alpha_max_deg: Option<f64>,
}

impl Omni {
    /// The base the robot `config` describes.
    pub fn new(config: &RobotConfig) -> Self {
        Self {
            move_speed_px: config.move_speed_px,
            turn_speed_deg: config.turn_speed_deg,
            v_max: config.max_linear_speed_px,
            vy_max: config.lateral_speed_px(),
            w_max: config.max_angular_speed_deg,
            accel_max_px: config.accel_max_px,
            alpha_max_deg: config.alpha_max_deg,
        }
    }

    fn within(&self, [vx, vy, w]: [f64; 3]) -> [f64; 3] {
        [
            finite_or_zero(vx).clamp(-self.v_max, self.v_max),
            finite_or_zero(vy).clamp(-self.vy_max, self.vy_max),
            finite_or_zero(w).clamp(-self.w_max, self.w_max),
        ]
    }
}

impl Kinematics for Omni {
    fn command(&self, velocity: Velocity, action: Action) -> (Velocity, f64) {
        let target = match action {
            Action::Discrete(DiscreteAction::Left) => [0.0, 0.0, self.turn_speed_deg],
            Action::Discrete(DiscreteAction::Right) => [0.0, 0.0, -self.turn_speed_deg],
            Action::Discrete(DiscreteAction::Ahead) => [self.move_speed_px, 0.0, 0.0],
            Action::Continuous { v, w_deg } => [v, 0.0, w_deg],
            Action::Omni { vx, vy, w_deg } => [vx, vy, w_deg],
            Action::Steer { v, .. } => [v, 0.0, 0.0],
        };
        let [v, vy, w_deg] = approach(
            [velocity.v, velocity.vy, velocity.w_deg],
            self.within(target),
            self.accel_max_px,
            self.alpha_max_deg,
        );
        (
            Velocity {
                v,
                vy,
                w_deg,
                steer_deg: 0.0,
            },
            turn_fraction(w_deg, self.w_max),
        )
    }

    fn clamp(&self, velocity: Velocity) -> Velocity {
        let [v, vy, w_deg] = self.within([velocity.v, velocity.vy, velocity.w_deg]);
        Velocity {
            v,
            vy,
            w_deg,
            steer_deg: 0.0,
        }
    }

    /// As the unicycle's: the sideways speed is not remembered.
    fn remembered(&self, action: Action) -> [f32; ACTION_MEMORY] {
        remembered_twist(action, self.v_max, self.w_max)
    }
}
