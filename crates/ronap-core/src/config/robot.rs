//! The robot and its laser (docs/model.md "Robot", "Sensors"): the disc, its speeds and what a
//! collision does, and the range finder, with their defaults and checks.

use crate::config::{check, finite, length, non_negative, ConfigError};
use serde::{Deserialize, Serialize};

/// What a step that would touch an obstacle does.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum OnCollision {
    /// The pose stays where it was and the episode goes on (the paper's behaviour).
    Revert,
    /// The pose stays where it was and the episode ends as a collision.
    Terminate,
}

/// The robot disc and its actions (docs/model.md "Robot").
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RobotConfig {
    /// Disc radius, px. Default 5.
    pub radius_px: f64,
    /// Distance of one AHEAD step, px (v_m). Default 5.
    pub move_speed_px: f64,
    /// Heading change of one LEFT or RIGHT step, degrees (v_r). Default 15.
    pub turn_speed_deg: f64,
    /// Continuous actions: largest |v|, px per step. Default 5.
    pub max_linear_speed_px: f64,
    /// Continuous actions: largest |w|, degrees per step. Default 15.
    pub max_angular_speed_deg: f64,
    /// `revert` (default, the paper) or `terminate`.
    pub on_collision: OnCollision,
}

impl Default for RobotConfig {
    fn default() -> Self {
        Self {
            radius_px: 5.0,
            move_speed_px: 5.0,
            turn_speed_deg: 15.0,
            max_linear_speed_px: 5.0,
            max_angular_speed_deg: 15.0,
            on_collision: OnCollision::Revert,
        }
    }
}

/// The laser range finder (docs/model.md "Sensors").
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct LaserConfig {
    /// Number of beams m. Default 17.
    pub beams: u32,
    /// Angle covered by the beams, centred on the heading, degrees. Default 180.
    pub fov_deg: f64,
    /// Largest reading d_max, px. Default 50.
    pub range_px: f64,
    /// Standard deviation of Gaussian reading noise, px. Default 0 (no noise).
    pub noise_sigma_px: f64,
}

impl Default for LaserConfig {
    fn default() -> Self {
        Self {
            beams: 17,
            fov_deg: 180.0,
            range_px: 50.0,
            noise_sigma_px: 0.0,
        }
    }
}

/// Largest number of laser beams.
pub const MAX_BEAMS: u32 = 4096;

impl RobotConfig {
    /// Checks every robot field, naming the first one out of range.
    pub(super) fn validate(&self) -> Result<(), ConfigError> {
        let r = self;
        length("robot.radius_px", r.radius_px, false)?;
        length("robot.move_speed_px", r.move_speed_px, true)?;
        finite("robot.turn_speed_deg", r.turn_speed_deg)?;
        length("robot.max_linear_speed_px", r.max_linear_speed_px, true)?;
        non_negative("robot.max_angular_speed_deg", r.max_angular_speed_deg)?;
        Ok(())
    }
}

impl LaserConfig {
    /// Checks every laser field, naming the first one out of range.
    pub(super) fn validate(&self) -> Result<(), ConfigError> {
        let l = self;
        check(
            (1..=MAX_BEAMS).contains(&l.beams),
            "laser.beams",
            l.beams,
            "must be between 1 and 4096",
        )?;
        check(
            l.fov_deg.is_finite() && (0.0..=360.0).contains(&l.fov_deg),
            "laser.fov_deg",
            format!("{:?}", l.fov_deg),
            "must be between 0 and 360",
        )?;
        length("laser.range_px", l.range_px, false)?;
        length("laser.noise_sigma_px", l.noise_sigma_px, true)?;
        Ok(())
    }
}
