//! Which metrics a run measures beyond the standard ones (docs/model.md "Crowd metrics"), with
//! their defaults and checks. The metrics themselves live in `eval::metric`.

use crate::config::{length, ConfigError};
use serde::{Deserialize, Serialize};

/// Metrics beyond the standard columns (docs/model.md "Crowd metrics").
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct MetricsConfig {
    /// Measure the crowd metrics (time to goal, intrusion ratio, least separation during
    /// intrusions, least time to collision, path irregularity, jerk): columns in `episodes.csv`
    /// (a team's `robots.csv`) and means in `summary.json`. Default false.
    pub crowd: bool,
    /// A step intrudes when a moving obstacle or another robot is closer than this beyond the
    /// two bodies, px. Default 4 (CrowdNav's 0.2 m on its 0.3 m agents, in ronap's px).
    pub discomfort_px: f64,
}

/// The default [`MetricsConfig::discomfort_px`].
const DISCOMFORT_PX: f64 = 4.0;

impl Default for MetricsConfig {
    fn default() -> Self {
        Self {
            crowd: false,
            discomfort_px: DISCOMFORT_PX,
        }
    }
}

impl MetricsConfig {
    /// Whether these are the defaults (the section is then left out of written configurations).
    pub fn is_default(&self) -> bool {
        *self == Self::default()
    }

    /// Checks the lengths, naming the first one out of range.
    pub(super) fn validate(&self) -> Result<(), ConfigError> {
        length("metrics.discomfort_px", self.discomfort_px, true)
    }
}
