//! The `orca` policy's settings (docs/model.md "Local planners among moving things"), with their
//! defaults and checks.

use crate::config::{check, length, steps, ConfigError};
use serde::{Deserialize, Serialize};

/// Which actions a local planner turns its velocity into.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PlannerActions {
    /// `(v, w)`: the unicycle command that tracks the velocity.
    #[default]
    Continuous,
    /// LEFT, AHEAD or RIGHT: the one whose result lies closest to where the velocity leads.
    Discrete,
}

/// The `orca` policy: Optimal Reciprocal Collision Avoidance for the robot, towards the next
/// point of its geodesic path, among the moving obstacles and other robots it senses (ground
/// truth within `sense_range_px`, as CrowdNav gives its baselines) and the still scene.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct OrcaConfig {
    /// Steps over which velocities are kept clear of other agents. Default 10.
    pub time_horizon_steps: f64,
    /// Steps over which velocities are kept clear of still obstacles. Default 5.
    pub obstacle_time_horizon_steps: f64,
    /// Most agents avoided at once (the nearest). Default 10.
    pub max_neighbours: u32,
    /// The preferred speed, px per step (also the largest ORCA picks). Default: the robot's
    /// `max_linear_speed_px` (continuous actions) or `move_speed_px` (discrete).
    pub speed_px: Option<f64>,
    /// How far the robot senses other agents, px. Default: the laser's range.
    pub sense_range_px: Option<f64>,
    /// Added to the robot's radius in ORCA, px: at a radius a step, agents meeting in a crowd
    /// can otherwise overlap where the linear program has no solution. Default 2.
    pub safety_margin_px: f64,
    /// `continuous` (default) or `discrete` actions.
    pub actions: PlannerActions,
}

impl Default for OrcaConfig {
    fn default() -> Self {
        Self {
            time_horizon_steps: 10.0,
            obstacle_time_horizon_steps: 5.0,
            max_neighbours: 10,
            speed_px: None,
            sense_range_px: None,
            safety_margin_px: 2.0,
            actions: PlannerActions::Continuous,
        }
    }
}

impl OrcaConfig {
    /// Whether these are the defaults (the section is then left out of written configurations).
    pub fn is_default(&self) -> bool {
        *self == Self::default()
    }

    /// Checks the horizons and ranges, naming the first one out of range.
    pub(super) fn validate(&self) -> Result<(), ConfigError> {
        steps("orca.time_horizon_steps", self.time_horizon_steps)?;
        steps(
            "orca.obstacle_time_horizon_steps",
            self.obstacle_time_horizon_steps,
        )?;
        check(
            (1..=1000).contains(&self.max_neighbours),
            "orca.max_neighbours",
            self.max_neighbours,
            "must be between 1 and 1000",
        )?;
        length("orca.safety_margin_px", self.safety_margin_px, true)?;
        if let Some(v) = self.speed_px {
            length("orca.speed_px", v, false)?;
        }
        if let Some(r) = self.sense_range_px {
            length("orca.sense_range_px", r, false)?;
        }
        Ok(())
    }
}
