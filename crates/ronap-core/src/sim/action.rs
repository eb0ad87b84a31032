//! What a robot is told and where it is: its pose `[x px, y px, z deg]`, the paper's three
//! discrete actions and the continuous commands (`(v, w)`, an omnidirectional robot's
//! `(vx, vy, w)`, a car's `(v, steer)`), with the text logs write them as.

use crate::geometry::{wrap_deg, Point};
use serde::{Deserialize, Serialize};
use std::fmt;
use std::str::FromStr;

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
    /// An omnidirectional robot's command: speeds along its heading `vx` and to its left `vy`,
    /// px per step, and its turn rate `w_deg`, degrees per step, clipped to its limits.
    Omni {
        /// Speed along the heading, px per step.
        vx: f64,
        /// Speed to the left of the heading, px per step.
        vy: f64,
        /// Angular speed, degrees per step.
        w_deg: f64,
    },
    /// A car-like robot's command: speed `v`, px per step, and steering angle `steer_deg`,
    /// degrees (positive steers left), clipped to its limits.
    Steer {
        /// Linear speed, px per step.
        v: f64,
        /// Steering angle, degrees.
        steer_deg: f64,
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
            _ => None,
        }
    }

    /// Whether every number of the action is finite (a discrete action always is).
    pub fn is_finite(self) -> bool {
        match self {
            Action::Discrete(_) => true,
            Action::Continuous { v, w_deg } => v.is_finite() && w_deg.is_finite(),
            Action::Omni { vx, vy, w_deg } => vx.is_finite() && vy.is_finite() && w_deg.is_finite(),
            Action::Steer { v, steer_deg } => v.is_finite() && steer_deg.is_finite(),
        }
    }

    /// The action with each number times its dimension's `scale` (a normalised continuous
    /// action made full: `RobotConfig::action_scale`); a discrete action, or a number without
    /// a scale, as it is.
    pub fn scaled(self, scale: &[f64]) -> Self {
        let s = |i: usize| scale.get(i).copied().unwrap_or(1.0);
        match self {
            Action::Discrete(_) => self,
            Action::Continuous { v, w_deg } => Action::Continuous {
                v: v * s(0),
                w_deg: w_deg * s(1),
            },
            Action::Omni { vx, vy, w_deg } => Action::Omni {
                vx: vx * s(0),
                vy: vy * s(1),
                w_deg: w_deg * s(2),
            },
            Action::Steer { v, steer_deg } => Action::Steer {
                v: v * s(0),
                steer_deg: steer_deg * s(1),
            },
        }
    }
}

/// As logs write it: `LEFT`, `AHEAD`, `RIGHT`, `v=SPEED;w=TURN` for a continuous action,
/// `vx=SPEED;vy=SPEED;w=TURN` for an omnidirectional one, `v=SPEED;steer=ANGLE` for a car's.
impl fmt::Display for Action {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Action::Discrete(a) => f.write_str(a.name()),
            Action::Continuous { v, w_deg } => write!(f, "v={v};w={w_deg}"),
            Action::Omni { vx, vy, w_deg } => write!(f, "vx={vx};vy={vy};w={w_deg}"),
            Action::Steer { v, steer_deg } => write!(f, "v={v};steer={steer_deg}"),
        }
    }
}

/// Reads what [`Action`]'s `Display` writes.
impl FromStr for Action {
    type Err = String;
    fn from_str(text: &str) -> Result<Self, String> {
        let number = |s: &str| {
            s.parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| format!("{text:?}: {s:?} is not a finite number"))
        };
        if let Some(rest) = text.strip_prefix("vx=") {
            let (vx, rest) = rest
                .split_once(";vy=")
                .and_then(|(vx, rest)| Some((vx, rest.split_once(";w=")?)))
                .ok_or_else(|| format!("{text:?}: expected vx=SPEED;vy=SPEED;w=TURN"))?;
            return Ok(Action::Omni {
                vx: number(vx)?,
                vy: number(rest.0)?,
                w_deg: number(rest.1)?,
            });
        }
        if let Some(rest) = text.strip_prefix("v=") {
            if let Some((v, steer)) = rest.split_once(";steer=") {
                return Ok(Action::Steer {
                    v: number(v)?,
                    steer_deg: number(steer)?,
                });
            }
            let (v, w) = rest
                .split_once(";w=")
                .ok_or_else(|| format!("{text:?}: expected v=SPEED;w=TURN"))?;
            return Ok(Action::Continuous {
                v: number(v)?,
                w_deg: number(w)?,
            });
        }
        text.parse::<DiscreteAction>().map(Action::from)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_action_reads_back_what_it_writes() {
        for a in [
            Action::from(DiscreteAction::Left),
            Action::Continuous {
                v: 1.5,
                w_deg: -3.25,
            },
            Action::Omni {
                vx: 0.5,
                vy: -2.0,
                w_deg: 7.0,
            },
            Action::Steer {
                v: 3.0,
                steer_deg: -21.5,
            },
        ] {
            assert_eq!(a.to_string().parse::<Action>(), Ok(a), "{a}");
        }
        for bad in ["vx=1;vy=2", "v=1;steer=x", "vx=1;vy=inf;w=0", "v=3"] {
            assert!(bad.parse::<Action>().is_err(), "{bad}");
        }
    }
}
