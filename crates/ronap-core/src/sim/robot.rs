//! The robot: a disc with a pose `[x px, y px, z deg]` and its discrete and continuous actions.
//!
//! Discrete actions turn by `turn_speed_deg` or move `move_speed_px` along the heading. Continuous
//! actions `(v, w)` follow a unicycle arc over one step. Either way the whole motion of a step is
//! swept against the scene, so no speed carries the disc through a wall.

use crate::config::RobotConfig;
use crate::geometry::{wrap_deg, Point, Vector};
use crate::scene::Scene;
use serde::{Deserialize, Serialize};
use std::fmt;
use std::str::FromStr;

/// Largest sagitta, px, between a continuous step's arc and the chords it is checked along; the
/// chords are checked with the radius grown by it, so the check errs on the side of a collision.
const ARC_TOLERANCE_PX: f64 = 0.01;

/// Position and heading.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Pose {
    /// x, px.
    pub x: f64,
    /// y, px.
    pub y: f64,
    /// Heading, degrees counter-clockwise from +x, in [0, 360).
    pub z_deg: f64,
}

impl Pose {
    /// A pose with the heading wrapped into [0, 360).
    pub fn new(x: f64, y: f64, z_deg: f64) -> Self {
        Self {
            x,
            y,
            z_deg: wrap_deg(z_deg),
        }
    }

    /// The position.
    pub fn position(&self) -> Point {
        Point::new(self.x, self.y)
    }
}

/// The paper's three discrete actions.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "UPPERCASE")]
pub enum DiscreteAction {
    /// Turn counter-clockwise by `turn_speed_deg`.
    Left = 0,
    /// Move `move_speed_px` along the heading.
    Ahead = 1,
    /// Turn clockwise by `turn_speed_deg`.
    Right = 2,
}

impl DiscreteAction {
    /// All actions in index order (the index a learned policy outputs).
    pub const ALL: [Self; 3] = [Self::Left, Self::Ahead, Self::Right];

    /// The action with index `i` (0 LEFT, 1 AHEAD, 2 RIGHT).
    pub fn from_index(i: usize) -> Option<Self> {
        Self::ALL.get(i).copied()
    }

    /// The name used in data logs.
    pub fn name(self) -> &'static str {
        match self {
            Self::Left => "LEFT",
            Self::Ahead => "AHEAD",
            Self::Right => "RIGHT",
        }
    }
}

impl fmt::Display for DiscreteAction {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for DiscreteAction {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s.trim() {
            "LEFT" => Ok(Self::Left),
            "AHEAD" => Ok(Self::Ahead),
            "RIGHT" => Ok(Self::Right),
            other => Err(format!(
                "unknown action {other:?} (expected LEFT, AHEAD or RIGHT)"
            )),
        }
    }
}

/// One step's command.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Action {
    /// A discrete action.
    Discrete(DiscreteAction),
    /// Linear speed `v` px per step and angular speed `w_deg` degrees per step, clipped to the
    /// robot's limits.
    Continuous {
        /// Linear speed, px per step.
        v: f64,
        /// Angular speed, degrees per step.
        w_deg: f64,
    },
}

impl From<DiscreteAction> for Action {
    fn from(a: DiscreteAction) -> Self {
        Action::Discrete(a)
    }
}

impl Action {
    /// The discrete action, if this is one.
    pub fn discrete(self) -> Option<DiscreteAction> {
        match self {
            Action::Discrete(a) => Some(a),
            Action::Continuous { .. } => None,
        }
    }
}

/// As logs write it: `LEFT`, `AHEAD`, `RIGHT`, or `v=SPEED;w=TURN` for a continuous action.
impl fmt::Display for Action {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Action::Discrete(a) => f.write_str(a.name()),
            Action::Continuous { v, w_deg } => write!(f, "v={v};w={w_deg}"),
        }
    }
}

/// Reads what [`Action`]'s `Display` writes.
impl FromStr for Action {
    type Err = String;
    fn from_str(text: &str) -> Result<Self, String> {
        if let Some(rest) = text.strip_prefix("v=") {
            let (v, w) = rest
                .split_once(";w=")
                .ok_or_else(|| format!("{text:?}: expected v=SPEED;w=TURN"))?;
            let number = |s: &str| {
                s.parse::<f64>()
                    .ok()
                    .filter(|x| x.is_finite())
                    .ok_or_else(|| format!("{text:?}: {s:?} is not a finite number"))
            };
            return Ok(Action::Continuous {
                v: number(v)?,
                w_deg: number(w)?,
            });
        }
        text.parse::<DiscreteAction>().map(Action::from)
    }
}

/// The pose a step leads to, before the collision check.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Motion {
    /// The pose at the end of the step.
    pub end: Pose,
    /// How much of a full turn command the step is, in [0, 1] (for the turning penalty).
    pub turn_fraction: f64,
    /// Linear speed over the step, px (signed).
    v: f64,
    /// Heading change over the step, degrees (signed).
    w_deg: f64,
}

/// The robot's shape and action limits.
#[derive(Clone, Debug)]
pub struct Robot {
    config: RobotConfig,
}

impl Robot {
    /// The robot `config` describes.
    pub fn new(config: &RobotConfig) -> Self {
        Self {
            config: config.clone(),
        }
    }

    /// Disc radius, px.
    pub fn radius_px(&self) -> f64 {
        self.config.radius_px
    }

    /// Where `action` takes the robot from `pose` in free space.
    pub fn motion(&self, pose: Pose, action: Action) -> Motion {
        self.motion_facing(pose, None, action)
    }

    /// [`Robot::motion`], given `pose`'s unit heading (`unit(pose.z_deg)`) when the caller has it
    /// already: a move straight ahead goes along it (the same bits: `unit` is the heading's cosine
    /// and sine, as the move works them out without it).
    pub fn motion_facing(&self, pose: Pose, facing: Option<Vector>, action: Action) -> Motion {
        let c = &self.config;
        let (v, w_deg, turn_fraction) = match action {
            Action::Discrete(DiscreteAction::Left) => (0.0, c.turn_speed_deg, 1.0),
            Action::Discrete(DiscreteAction::Right) => (0.0, -c.turn_speed_deg, 1.0),
            Action::Discrete(DiscreteAction::Ahead) => (c.move_speed_px, 0.0, 0.0),
            Action::Continuous { v, w_deg } => {
                let v = if v.is_nan() { 0.0 } else { v };
                let w = if w_deg.is_nan() { 0.0 } else { w_deg };
                let v = v.clamp(-c.max_linear_speed_px, c.max_linear_speed_px);
                let w = w.clamp(-c.max_angular_speed_deg, c.max_angular_speed_deg);
                let frac = if c.max_angular_speed_deg > 0.0 {
                    w.abs() / c.max_angular_speed_deg
                } else {
                    0.0
                };
                (v, w, frac)
            }
        };
        Motion {
            end: arc_end(pose, v, w_deg, facing),
            turn_fraction,
            v,
            w_deg,
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
        let r = self.config.radius_px;
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
