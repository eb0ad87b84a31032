//! The social force model's settings (docs/model.md "Crowds that react"), for `social_force`
//! pedestrians and the `social-force` policy, with their defaults and
//! checks.
//!
//! The defaults are Helbing and Molnár's (1995: relaxation time 0.5 s, a repulsive potential of
//! 2.1 m²/s² decaying over 0.3 m, walls 10 m²/s² over 0.2 m, a weight of 0.5 behind) at the
//! scale of ronap's crowd scenarios, CrowdNav's: 20 px a metre, 4 steps a second.

use crate::config::{check, length, ConfigError, PlannerActions};
use serde::{Deserialize, Serialize};

/// The forces of the social force model: a driving term and exponential repulsions.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Forces {
    /// Steps over which the velocity relaxes to the preferred one (tau). Default 2 (0.5 s).
    pub relaxation_steps: f64,
    /// Another agent's push at contact, px per step² (A). Default 8.75 (2.1 m²/s² over 0.3 m).
    pub agent_strength_px: f64,
    /// Over how far the push of an agent decays by e, px (B). Default 6 (0.3 m).
    pub agent_range_px: f64,
    /// A still obstacle's push at contact, px per step². Default 62.5 (10 m²/s² over 0.2 m).
    pub obstacle_strength_px: f64,
    /// Over how far the push of a still obstacle decays by e, px. Default 4 (0.2 m).
    pub obstacle_range_px: f64,
    /// Weight of an agent right behind, against 1 for one right ahead (lambda). Default 0.5.
    pub lambda: f64,
    /// Agents further than this (centre to centre) do not push, px. Default 60 (3 m).
    pub neighbour_dist_px: f64,
}

impl Default for Forces {
    fn default() -> Self {
        Self {
            relaxation_steps: 2.0,
            agent_strength_px: 8.75,
            agent_range_px: 6.0,
            obstacle_strength_px: 62.5,
            obstacle_range_px: 4.0,
            lambda: 0.5,
            neighbour_dist_px: 60.0,
        }
    }
}

impl Forces {
    /// Whether these are the defaults (left out of written configurations).
    pub fn is_default(&self) -> bool {
        *self == Self::default()
    }

    /// Checks every field, each named `{prefix}.{field}`.
    pub(super) fn validate(&self, prefix: &str) -> Result<(), ConfigError> {
        let f = |name: &str| format!("{prefix}.{name}");
        check(
            self.relaxation_steps.is_finite() && self.relaxation_steps >= 1.0,
            &f("relaxation_steps"),
            format!("{:?}", self.relaxation_steps),
            "must be at least 1 step",
        )?;
        length(&f("agent_strength_px"), self.agent_strength_px, true)?;
        length(&f("agent_range_px"), self.agent_range_px, false)?;
        length(&f("obstacle_strength_px"), self.obstacle_strength_px, true)?;
        length(&f("obstacle_range_px"), self.obstacle_range_px, false)?;
        check(
            self.lambda.is_finite() && (0.0..=1.0).contains(&self.lambda),
            &f("lambda"),
            format!("{:?}", self.lambda),
            "must be between 0 and 1",
        )?;
        length(&f("neighbour_dist_px"), self.neighbour_dist_px, true)
    }
}

/// The `social-force` policy: the social force model's driving and repulsive terms applied to
/// the robot, towards the next point of its geodesic path, among the agents it senses (ground
/// truth within `sense_range_px`) and the still scene.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SocialForceConfig {
    /// The preferred (and largest) speed, px per step. Default: the robot's
    /// `max_linear_speed_px` (continuous actions) or `move_speed_px` (discrete).
    pub speed_px: Option<f64>,
    /// How far the robot senses other agents, px. Default: the laser's range.
    pub sense_range_px: Option<f64>,
    /// `continuous` (default) or `discrete` actions.
    pub actions: PlannerActions,
    /// The forces.
    pub forces: Forces,
}

impl SocialForceConfig {
    /// Whether these are the defaults (left out of written configurations).
    pub fn is_default(&self) -> bool {
        *self == Self::default()
    }

    /// Checks every field, naming the first one out of range.
    pub(super) fn validate(&self) -> Result<(), ConfigError> {
        if let Some(v) = self.speed_px {
            length("social_force.speed_px", v, false)?;
        }
        if let Some(r) = self.sense_range_px {
            length("social_force.sense_range_px", r, false)?;
        }
        self.forces.validate("social_force.forces")
    }
}
