//! The artificial potential field policy's gains (docs/model.md "Algorithms", Algorithm 3), with
//! their defaults and checks.

use crate::config::{length, non_negative, ConfigError};
use serde::{Deserialize, Serialize};

/// The artificial potential field policy (docs/model.md "Algorithms", Algorithm 3).
///
/// `U = 1/2 xi d^2(q, goal) + 1/2 eta (1/c - 1/d0)^2` where `c <= d0`, with `c` the clearance of
/// the robot disc at `q` (distance to the nearest obstacle minus the radius). The paper gives no
/// gains; these keep the descent a few px off walls while the goal still pulls from across the
/// scene.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ApfConfig {
    /// Attraction gain xi, per px^2. Default 1.
    pub gravity_gain: f64,
    /// Repulsion gain eta, px^2. Default 50000.
    pub repulsion_gain: f64,
    /// Distance d0 beyond which obstacles do not repel, px. Default 20.
    pub influence_px: f64,
    /// Spacing of the positions the descent steps between (the paper's image pixels), px.
    /// Default 1.
    pub lattice_px: f64,
    /// Add the moving obstacles the laser can reach to the repulsion, steering round them while
    /// following the descent. Default false (the paper's APF knows only the still scene).
    pub repel_moving: bool,
}

impl Default for ApfConfig {
    fn default() -> Self {
        Self {
            gravity_gain: 1.0,
            repulsion_gain: 50_000.0,
            influence_px: 20.0,
            lattice_px: 1.0,
            repel_moving: false,
        }
    }
}

impl ApfConfig {
    /// Checks the gains and lengths, naming the first one out of range.
    pub(super) fn validate(&self) -> Result<(), ConfigError> {
        let a = self;
        non_negative("apf.gravity_gain", a.gravity_gain)?;
        non_negative("apf.repulsion_gain", a.repulsion_gain)?;
        length("apf.influence_px", a.influence_px, false)?;
        length("apf.lattice_px", a.lattice_px, false)?;
        Ok(())
    }
}
