//! The `dwa` policy's settings (docs/model.md "Local planners among moving things"), with their
//! defaults and checks.

use crate::config::{check, length, ConfigError, PlannerActions};
use serde::{Deserialize, Serialize};

/// The `dwa` policy: the dynamic window approach (Fox, Burgard and Thrun 1997). Each step it
/// samples unicycle commands `(v, w)` within reach of the last one, rolls each out for
/// `horizon_steps` against the laser's points and the moving obstacles and other robots it
/// senses (moving on at their last velocities), and takes the best by heading to the next point
/// of its geodesic path, steps before a contact, and speed.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct DwaConfig {
    /// Steps each command is rolled out for. Default 8.
    pub horizon_steps: u32,
    /// Linear speeds sampled across the window. Default 7.
    pub speed_samples: u32,
    /// Turn rates sampled across the window. Default 11.
    pub turn_samples: u32,
    /// Largest change of the linear speed in a step, px per step². Default 1.
    pub linear_accel_px: f64,
    /// Largest change of the turn rate in a step, degrees per step². Default 15 (the whole
    /// range of the paper's robot).
    pub angular_accel_deg: f64,
    /// Weight of the heading term (1 facing the aim at the rollout's end, 0 facing away).
    /// Default 1.
    pub heading_weight: f64,
    /// Weight of the clearance term (the share of the rollout's steps before it first comes
    /// within `safety_margin_px` of anything sensed). Default 0.6.
    pub clearance_weight: f64,
    /// Weight of the speed term (the speed as a fraction of the largest). Default 0.4.
    pub speed_weight: f64,
    /// A rollout step nearer than this to anything sensed (beyond the bodies) is a contact,
    /// px. Default 1.
    pub safety_margin_px: f64,
    /// How far the robot senses moving agents, px. Default: the laser's range.
    pub sense_range_px: Option<f64>,
    /// `continuous` (default: the sampled `(v, w)`) or `discrete` (LEFT, AHEAD and RIGHT, each
    /// taken once and followed by AHEAD steps).
    pub actions: PlannerActions,
}

impl Default for DwaConfig {
    fn default() -> Self {
        Self {
            horizon_steps: 8,
            speed_samples: 7,
            turn_samples: 11,
            linear_accel_px: 1.0,
            angular_accel_deg: 15.0,
            heading_weight: 1.0,
            clearance_weight: 0.6,
            speed_weight: 0.4,
            safety_margin_px: 1.0,
            sense_range_px: None,
            actions: PlannerActions::Continuous,
        }
    }
}

impl DwaConfig {
    /// Whether these are the defaults (left out of written configurations).
    pub fn is_default(&self) -> bool {
        *self == Self::default()
    }

    /// Checks every field, naming the first one out of range.
    pub(super) fn validate(&self) -> Result<(), ConfigError> {
        check(
            (1..=200).contains(&self.horizon_steps),
            "dwa.horizon_steps",
            self.horizon_steps,
            "must be between 1 and 200",
        )?;
        check(
            (2..=101).contains(&self.speed_samples),
            "dwa.speed_samples",
            self.speed_samples,
            "must be between 2 and 101",
        )?;
        check(
            (2..=101).contains(&self.turn_samples),
            "dwa.turn_samples",
            self.turn_samples,
            "must be between 2 and 101",
        )?;
        length("dwa.linear_accel_px", self.linear_accel_px, false)?;
        check(
            self.angular_accel_deg.is_finite()
                && self.angular_accel_deg > 0.0
                && self.angular_accel_deg <= 360.0,
            "dwa.angular_accel_deg",
            format!("{:?}", self.angular_accel_deg),
            "must be above 0 and at most 360",
        )?;
        for (name, w) in [
            ("dwa.heading_weight", self.heading_weight),
            ("dwa.clearance_weight", self.clearance_weight),
            ("dwa.speed_weight", self.speed_weight),
        ] {
            check(
                w.is_finite() && (0.0..=1000.0).contains(&w),
                name,
                format!("{w:?}"),
                "must be between 0 and 1000",
            )?;
        }
        length("dwa.safety_margin_px", self.safety_margin_px, true)?;
        if let Some(r) = self.sense_range_px {
            length("dwa.sense_range_px", r, false)?;
        }
        Ok(())
    }
}
