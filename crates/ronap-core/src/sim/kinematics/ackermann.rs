//! A car-like robot (Ackermann steering, as a bicycle model): commanded a speed `v` and a
//! steering angle, `wheel_base_px` between its axles. The speed changes by at most
//! `accel_max_px` a step and the steering angle by at most `steer_rate_max_deg`, within
//! `steer_max_deg`; over the step the body turns at `w = v tan(steer) / wheel_base`, so it
//! cannot turn on the spot. A `(v, w)` command steers to its curvature `w / v`; the paper's
//! discrete actions drive at `move_speed_px` steering fully left (LEFT), straight (AHEAD) or
//! fully right (RIGHT).

use crate::config::{RobotConfig, ACTION_MEMORY};
use crate::sim::action::{Action, DiscreteAction};
use crate::sim::kinematics::{finite_or_zero, one_hot, remembered_as, Kinematics, Velocity};

/// A car-like robot's speeds and limits (docs/model.md "Kinematics").
#[derive(Clone, Debug, PartialEq)]
pub struct Ackermann {
    move_speed_px: f64,
    v_max: f64,
    wheel_base_px: f64,
    steer_max_deg: f64,
    steer_rate_max_deg: Option<f64>,
    accel_max_px: Option<f64>,
}

impl Ackermann {
    /// The robot `config` describes (a validated one gives its wheel base).
    pub fn new(config: &RobotConfig) -> Self {
        Self {
            move_speed_px: config.move_speed_px,
            v_max: config.max_linear_speed_px,
            wheel_base_px: config.axle_base_px(),
            steer_max_deg: config.steer_limit_deg(),
            steer_rate_max_deg: config.steer_rate_max_deg,
            accel_max_px: config.accel_max_px,
        }
    }

    /// The turn rate, degrees per step, of speed `v` at steering angle `steer_deg`.
    fn turn_deg(&self, v: f64, steer_deg: f64) -> f64 {
        (v * steer_deg.to_radians().tan() / self.wheel_base_px).to_degrees()
    }

    /// The steering angle that turns at `w_deg` a step at speed `v` (the curvature `w / v`);
    /// standing, full lock towards the turn (a car cannot turn on the spot), or `current`
    /// without one.
    fn steer_for(&self, v: f64, w_deg: f64, current: f64) -> f64 {
        if v.abs() > 1e-9 {
            (w_deg.to_radians() * self.wheel_base_px / v)
                .atan()
                .to_degrees()
        } else if w_deg != 0.0 {
            self.steer_max_deg * w_deg.signum()
        } else {
            current
        }
    }
}

/// `x` moved towards `target` by at most `limit` (no limit: all the way).
fn towards(x: f64, target: f64, limit: Option<f64>) -> f64 {
    match limit {
        Some(l) => x + (target - x).clamp(-l, l),
        None => target,
    }
}

impl Kinematics for Ackermann {
    fn command(&self, velocity: Velocity, action: Action) -> (Velocity, f64) {
        let m = self.steer_max_deg;
        let (v, steer) = match action {
            Action::Discrete(DiscreteAction::Left) => (self.move_speed_px, m),
            Action::Discrete(DiscreteAction::Ahead) => (self.move_speed_px, 0.0),
            Action::Discrete(DiscreteAction::Right) => (self.move_speed_px, -m),
            Action::Steer { v, steer_deg } => (v, steer_deg),
            Action::Continuous { v, w_deg } => {
                let (v, w) = (finite_or_zero(v), finite_or_zero(w_deg));
                (v, self.steer_for(v, w, velocity.steer_deg))
            }
            Action::Omni { vx, w_deg, .. } => {
                let (v, w) = (finite_or_zero(vx), finite_or_zero(w_deg));
                (v, self.steer_for(v, w, velocity.steer_deg))
            }
        };
        let v = finite_or_zero(v).clamp(-self.v_max, self.v_max);
        let steer = finite_or_zero(steer).clamp(-m, m);
        let v = towards(velocity.v, v, self.accel_max_px).clamp(-self.v_max, self.v_max);
        let steer = towards(velocity.steer_deg, steer, self.steer_rate_max_deg).clamp(-m, m);
        (
            Velocity {
                v,
                vy: 0.0,
                w_deg: self.turn_deg(v, steer),
                steer_deg: steer,
            },
            (steer.abs() / m).min(1.0),
        )
    }

    fn clamp(&self, velocity: Velocity) -> Velocity {
        let v = velocity.v.clamp(-self.v_max, self.v_max);
        Velocity {
            v,
            vy: 0.0,
            // Noise on the turn rate stands for slip: kept within what full lock turns.
            w_deg: velocity.w_deg.clamp(
                -self.turn_deg(v.abs(), self.steer_max_deg),
                self.turn_deg(v.abs(), self.steer_max_deg),
            ),
            steer_deg: velocity.steer_deg,
        }
    }

    /// The steering angle as the turn: `steer+ / steer_max, v / v_max, steer- / steer_max`.
    fn remembered(&self, action: Action) -> [f32; ACTION_MEMORY] {
        let m = self.steer_max_deg;
        match action {
            Action::Discrete(d) => one_hot(d),
            Action::Steer { v, steer_deg } => remembered_as(v, self.v_max, steer_deg, m),
            Action::Continuous { v, w_deg } => {
                remembered_as(v, self.v_max, self.steer_for(v, w_deg, 0.0), m)
            }
            Action::Omni { vx, w_deg, .. } => {
                remembered_as(vx, self.v_max, self.steer_for(vx, w_deg, 0.0), m)
            }
        }
    }
}
