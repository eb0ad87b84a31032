//! An episode and what a learner is given (docs/model.md "Episode", "Observation and reward"):
//! start, goal and how an episode ends; the reward's terms and shaping; the observation's
//! memory, with their defaults and checks.

use crate::config::{check, finite, length, ConfigError};
use serde::{Deserialize, Serialize};

/// Start, goal and the end of an episode (docs/model.md "Episode").
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct EpisodeConfig {
    /// Success when the goal distance D falls below this, px (epsilon). Default 10.
    pub goal_tolerance_px: f64,
    /// Steps before a time-out. Default 2000.
    pub max_steps: u32,
    /// End the episode when the summed reward falls to this value (R_min). Default: none.
    pub reward_min: Option<f64>,
    /// Least straight-line distance between a sampled start and goal, px. Default 200.
    pub min_goal_distance_px: f64,
    /// Fixed start pose `[x px, y px, z deg]`. Default: drawn from the seed.
    pub start: Option<[f64; 3]>,
    /// Fixed goal `[x px, y px]`. Default: drawn from the seed.
    pub goal: Option<[f64; 2]>,
    /// Cell side of the free-space grid used to find connected regions (and by planners), px.
    /// Default 5.
    pub grid_px: f64,
    /// A step counts as near a moving obstacle when the gap to one is below this, px.
    /// Default: two robot radii.
    pub safety_radius_px: Option<f64>,
    /// Several robots: the episode ends as a deadlock when no robot of a team of two or more has
    /// moved for this many steps. Default 100.
    pub deadlock_steps: u32,
    /// Any contact (a wall, a moving obstacle, another robot) ends the episode as a collision,
    /// the rule crowd-navigation papers use: `robot.on_collision = "terminate"` for every
    /// robot. Default false.
    #[serde(skip_serializing_if = "super::is_false")]
    pub collision_ends: bool,
}

impl Default for EpisodeConfig {
    fn default() -> Self {
        Self {
            goal_tolerance_px: 10.0,
            max_steps: 2000,
            reward_min: None,
            min_goal_distance_px: 200.0,
            start: None,
            goal: None,
            grid_px: 5.0,
            safety_radius_px: None,
            deadlock_steps: 100,
            collision_ends: false,
        }
    }
}

/// The four reward terms `r = r_a + r_b + r_c + r_d` (docs/model.md "Observation and reward").
///
/// The paper gives no numbers. The defaults make one AHEAD step straight at the goal worth +0.5,
/// a collision cost as much as two such steps, a turn cost a tenth of one, and arriving worth
/// twenty: large enough that a learned policy prefers arriving to wandering.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RewardConfig {
    /// r_a, added on a step that collided. Default -1.
    pub collision: f64,
    /// r_b per px of progress `D_prev - D` (negative when moving away). Default 0.1.
    pub progress_per_px: f64,
    /// r_c, added on LEFT and RIGHT (scaled by |w| / w_max for continuous actions). Default -0.05.
    pub turn: f64,
    /// r_d, added on success. Default 10.
    pub success: f64,
    /// How progress is paid to a learner. Default `none`: the paper's straight-line term r_b.
    #[serde(skip_serializing_if = "Shaping::is_none")]
    pub shaping: Shaping,
    /// The discount gamma of the shaping term `F = gamma Phi(s') - Phi(s)`; the learner's keeps
    /// its optimal policy exactly (`ronap train dqn` sets it to its `--gamma` unless
    /// `--shaping-gamma` says otherwise). Default 0.99.
    #[serde(skip_serializing_if = "is_default_shaping_gamma")]
    pub shaping_gamma: f64,
}

/// Values per remembered action in an observation with history.
pub const ACTION_MEMORY: usize = 3;

/// Most frames an observation may hold.
pub const MAX_HISTORY: u32 = 64;

/// The default [`RewardConfig::shaping_gamma`].
const SHAPING_GAMMA: f64 = 0.99;

fn is_default_shaping_gamma(gamma: &f64) -> bool {
    *gamma == SHAPING_GAMMA
}

/// How progress towards the goal is paid (docs/model.md "Reward"; Ng, Harada and Russell 1999).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Shaping {
    /// The paper's r_b: `progress_per_px` per px of straight-line progress.
    #[default]
    None,
    /// Potential-based shaping along the geodesic: r_b is replaced by
    /// `F = gamma Phi(s') - Phi(s)` with `Phi = -progress_per_px x` (geodesic distance to the
    /// goal for the robot's disc), and `Phi = 0` once an episode ends by success, collision or
    /// `reward_min`. It keeps the optimal policy of the other three terms and no longer pays for
    /// heading into a dead end. Uses the map only for the reward a learner is given: the
    /// observation is unchanged, and `episodes.csv`'s `return` stays the paper's return.
    Geodesic,
}

impl Shaping {
    /// Whether this is the paper's reward.
    pub fn is_none(&self) -> bool {
        *self == Self::None
    }
}

impl Default for RewardConfig {
    fn default() -> Self {
        Self {
            collision: -1.0,
            progress_per_px: 0.1,
            turn: -0.05,
            success: 10.0,
            shaping: Shaping::None,
            shaping_gamma: SHAPING_GAMMA,
        }
    }
}

/// Observation memory (docs/model.md "Observation and reward"): with `history = k`, the observation is
/// the last `k` frames of the paper's values, newest first, then the last `k - 1` actions, newest
/// first, each as three values in [0, 1] (one-hot LEFT, AHEAD, RIGHT; a continuous action as
/// `w+ / w_max, v / v_max, w- / w_max`). At an episode's start the past frames repeat the first
/// and the past actions are zeros.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ObservationConfig {
    /// Frames observed, the current one included (1: the paper's observation). Default 1.
    pub history: u32,
}

impl Default for ObservationConfig {
    fn default() -> Self {
        Self { history: 1 }
    }
}

impl ObservationConfig {
    /// Whether this is the paper's observation.
    pub fn is_default(&self) -> bool {
        *self == Self::default()
    }
}

impl EpisodeConfig {
    /// Checks the start, goal and end fields, naming the first one out of range.
    pub(super) fn validate(&self) -> Result<(), ConfigError> {
        let e = self;
        length("episode.goal_tolerance_px", e.goal_tolerance_px, false)?;
        check(
            e.max_steps >= 1,
            "episode.max_steps",
            e.max_steps,
            "must be at least 1",
        )?;
        if let Some(v) = e.reward_min {
            finite("episode.reward_min", v)?;
        }
        length("episode.min_goal_distance_px", e.min_goal_distance_px, true)?;
        if let Some(s) = e.start {
            check(
                s.iter().all(|v| v.is_finite()),
                "episode.start",
                format!("{s:?}"),
                "must be three finite numbers [x, y, z]",
            )?;
        }
        if let Some(g) = e.goal {
            check(
                g.iter().all(|v| v.is_finite()),
                "episode.goal",
                format!("{g:?}"),
                "must be two finite numbers [x, y]",
            )?;
        }
        length("episode.grid_px", e.grid_px, false)?;
        Ok(())
    }

    /// Checks the fields of teams and moving obstacles (`deadlock_steps`, `safety_radius_px`).
    pub(super) fn validate_team_fields(&self) -> Result<(), ConfigError> {
        check(
            self.deadlock_steps >= 1,
            "episode.deadlock_steps",
            self.deadlock_steps,
            "must be at least 1",
        )?;
        if let Some(v) = self.safety_radius_px {
            length("episode.safety_radius_px", v, true)?;
        }
        Ok(())
    }
}

impl RewardConfig {
    /// Checks the four terms.
    pub(super) fn validate_terms(&self) -> Result<(), ConfigError> {
        let w = self;
        finite("reward.collision", w.collision)?;
        finite("reward.progress_per_px", w.progress_per_px)?;
        finite("reward.turn", w.turn)?;
        finite("reward.success", w.success)?;
        Ok(())
    }

    /// Checks the shaping's discount.
    pub(super) fn validate_shaping(&self) -> Result<(), ConfigError> {
        check(
            self.shaping_gamma > 0.0 && self.shaping_gamma <= 1.0,
            "reward.shaping_gamma",
            self.shaping_gamma.to_string(),
            "must be in (0, 1]",
        )?;
        Ok(())
    }
}

impl ObservationConfig {
    /// Checks the memory's length.
    pub(super) fn validate(&self) -> Result<(), ConfigError> {
        check(
            (1..=MAX_HISTORY).contains(&self.history),
            "observation.history",
            self.history,
            "must be a whole number from 1 to 64",
        )
    }
}
