//! The simulation configuration: every default of SPEC.md as a field, with its unit.
//!
//! [`SimConfig`] is what a user writes (TOML, flags, keyword arguments); [`ValidConfig`] is the
//! same data after [`SimConfig::validate`] has checked every field. The rest of the core only takes
//! a `ValidConfig`, so it never re-checks a value.

use serde::{Deserialize, Serialize};
use std::ops::Deref;

/// A configuration value that is out of its range or malformed.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum ConfigError {
    /// A field holds a value outside its allowed range.
    #[error("{field} = {value}: {expected}")]
    OutOfRange {
        /// Dotted field name, as in the TOML file (`maze.cols`).
        field: &'static str,
        /// The offending value, as written.
        value: String,
        /// What the field accepts.
        expected: &'static str,
    },
    /// The TOML text could not be read into a configuration (syntax, type or unknown key).
    #[error("{0}")]
    Toml(String),
}

/// Maze generation (SPEC "Scene: maze").
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct MazeConfig {
    /// Number of cell columns. Default 10.
    pub cols: u32,
    /// Number of cell rows. Default 10.
    pub rows: u32,
    /// Side of a square cell, px. Default 100.
    pub cell_px: f64,
    /// Fraction of the interior walls left by the perfect maze that are then removed, in [0, 1].
    /// Default 0.4; 0 gives a perfect maze.
    pub loops: f64,
    /// Wall thickness, px. Default 2.
    pub wall_thickness_px: f64,
}

impl Default for MazeConfig {
    fn default() -> Self {
        Self {
            cols: 10,
            rows: 10,
            cell_px: 100.0,
            loops: 0.4,
            wall_thickness_px: 2.0,
        }
    }
}

/// How an image becomes a scene (SPEC "maze loaded as a picture").
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct MapConfig {
    /// Grey value at or below which a pixel is an obstacle, 0-255. Default 127.
    pub threshold: u8,
    /// Scene px per image pixel. Default 1.
    pub resolution_px: f64,
}

impl Default for MapConfig {
    fn default() -> Self {
        Self {
            threshold: 127,
            resolution_px: 1.0,
        }
    }
}

/// What a step that would touch an obstacle does.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum OnCollision {
    /// The pose stays where it was and the episode goes on (the paper's behaviour).
    Revert,
    /// The pose stays where it was and the episode ends as a collision.
    Terminate,
}

/// The robot disc and its actions (SPEC "Robot").
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

/// The laser range finder (SPEC "Sensors").
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

/// Start, goal and the end of an episode (SPEC "Episode").
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
        }
    }
}

/// The four reward terms `r = r_a + r_b + r_c + r_d` (SPEC "Observation and reward").
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
}

impl Default for RewardConfig {
    fn default() -> Self {
        Self {
            collision: -1.0,
            progress_per_px: 0.1,
            turn: -0.05,
            success: 10.0,
        }
    }
}

/// The artificial potential field policy (SPEC "Algorithms", Algorithm 3).
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
}

impl Default for ApfConfig {
    fn default() -> Self {
        Self {
            gravity_gain: 1.0,
            repulsion_gain: 50_000.0,
            influence_px: 20.0,
            lattice_px: 1.0,
        }
    }
}

/// The whole simulation configuration, as a user writes it.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SimConfig {
    /// Maze generation.
    pub maze: MazeConfig,
    /// Image scenes.
    pub map: MapConfig,
    /// The robot.
    pub robot: RobotConfig,
    /// The laser.
    pub laser: LaserConfig,
    /// Start, goal, episode end.
    pub episode: EpisodeConfig,
    /// Reward terms.
    pub reward: RewardConfig,
    /// The artificial potential field policy.
    pub apf: ApfConfig,
}

/// A [`SimConfig`] whose every field has been checked. Dereferences to the `SimConfig`.
/// The default is the (valid) default configuration.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ValidConfig(SimConfig);

impl Deref for ValidConfig {
    type Target = SimConfig;
    fn deref(&self) -> &SimConfig {
        &self.0
    }
}

impl ValidConfig {
    /// The configuration as written, for saving next to results.
    pub fn as_sim_config(&self) -> &SimConfig {
        &self.0
    }

    /// Length of the observation a policy sees: one value per laser beam, then the goal
    /// direction (SPEC "Observation and reward").
    pub fn observation_size(&self) -> usize {
        self.laser.beams as usize + 1
    }

    /// The query distance scenes are indexed for: the laser range or a step plus the robot
    /// radius, whichever is longer, px.
    pub fn reach_px(&self) -> f64 {
        let step = self.robot.move_speed_px.max(self.robot.max_linear_speed_px);
        self.laser.range_px.max(step + self.robot.radius_px)
    }
}

fn check(
    ok: bool,
    field: &'static str,
    value: impl ToString,
    expected: &'static str,
) -> Result<(), ConfigError> {
    if ok {
        Ok(())
    } else {
        Err(ConfigError::OutOfRange {
            field,
            value: value.to_string(),
            expected,
        })
    }
}

fn non_negative(field: &'static str, v: f64) -> Result<(), ConfigError> {
    check(
        v.is_finite() && v >= 0.0,
        field,
        v,
        "must be zero or positive",
    )
}

fn finite(field: &'static str, v: f64) -> Result<(), ConfigError> {
    check(
        v.is_finite(),
        field,
        format!("{v:?}"),
        "must be a finite number",
    )
}

/// Largest maze side in cells: keeps a generated scene (and its pictures) within memory.
pub const MAX_MAZE_CELLS_PER_SIDE: u32 = 1000;
/// Largest length any field may give, px: scene sides, ranges, radii and speeds.
pub const MAX_LENGTH_PX: f64 = 100_000.0;

fn length(field: &'static str, v: f64, zero_ok: bool) -> Result<(), ConfigError> {
    let low_ok = if zero_ok { v >= 0.0 } else { v > 0.0 };
    check(
        v.is_finite() && low_ok && v <= MAX_LENGTH_PX,
        field,
        format!("{v:?}"),
        if zero_ok {
            "must be between 0 and 100000 px"
        } else {
            "must be a positive length of at most 100000 px"
        },
    )
}
/// Largest number of laser beams.
pub const MAX_BEAMS: u32 = 360;

impl SimConfig {
    /// Reads a configuration from TOML text; missing fields keep their defaults and an unknown
    /// key is an error that names it.
    pub fn from_toml_str(text: &str) -> Result<Self, ConfigError> {
        toml::from_str(text).map_err(|e| {
            let message = e.message().trim().replace('\n', " ");
            match e.span() {
                Some(span) => {
                    let before = &text[..span.start.min(text.len())];
                    let line = before.matches('\n').count() + 1;
                    let column = before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1;
                    ConfigError::Toml(format!("line {line}, column {column}: {message}"))
                }
                None => ConfigError::Toml(message),
            }
        })
    }

    /// Checks every field, naming the first one that is out of range.
    pub fn validate(self) -> Result<ValidConfig, ConfigError> {
        let m = &self.maze;
        let side = "must be between 1 and 1000";
        check(
            (1..=MAX_MAZE_CELLS_PER_SIDE).contains(&m.cols),
            "maze.cols",
            m.cols,
            side,
        )?;
        check(
            (1..=MAX_MAZE_CELLS_PER_SIDE).contains(&m.rows),
            "maze.rows",
            m.rows,
            side,
        )?;
        length("maze.cell_px", m.cell_px, false)?;
        let side = "the scene side (cells x maze.cell_px) must be at most 100000 px";
        let widest = m.cols.max(m.rows) as f64 * m.cell_px;
        check(
            widest <= MAX_LENGTH_PX,
            "maze.cell_px",
            format!("{:?}", m.cell_px),
            side,
        )?;
        check(
            (0.0..=1.0).contains(&m.loops),
            "maze.loops",
            format!("{:?}", m.loops),
            "must be between 0 and 1",
        )?;
        length("maze.wall_thickness_px", m.wall_thickness_px, false)?;
        check(
            m.wall_thickness_px < m.cell_px,
            "maze.wall_thickness_px",
            format!("{:?}", m.wall_thickness_px),
            "must be smaller than maze.cell_px",
        )?;
        length("map.resolution_px", self.map.resolution_px, false)?;

        let r = &self.robot;
        length("robot.radius_px", r.radius_px, false)?;
        length("robot.move_speed_px", r.move_speed_px, true)?;
        finite("robot.turn_speed_deg", r.turn_speed_deg)?;
        length("robot.max_linear_speed_px", r.max_linear_speed_px, true)?;
        non_negative("robot.max_angular_speed_deg", r.max_angular_speed_deg)?;

        let l = &self.laser;
        check(
            (1..=MAX_BEAMS).contains(&l.beams),
            "laser.beams",
            l.beams,
            "must be between 1 and 360",
        )?;
        check(
            l.fov_deg.is_finite() && (0.0..=360.0).contains(&l.fov_deg),
            "laser.fov_deg",
            format!("{:?}", l.fov_deg),
            "must be between 0 and 360",
        )?;
        length("laser.range_px", l.range_px, false)?;
        length("laser.noise_sigma_px", l.noise_sigma_px, true)?;

        let e = &self.episode;
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

        let w = &self.reward;
        finite("reward.collision", w.collision)?;
        finite("reward.progress_per_px", w.progress_per_px)?;
        finite("reward.turn", w.turn)?;
        finite("reward.success", w.success)?;

        let a = &self.apf;
        non_negative("apf.gravity_gain", a.gravity_gain)?;
        non_negative("apf.repulsion_gain", a.repulsion_gain)?;
        length("apf.influence_px", a.influence_px, false)?;
        length("apf.lattice_px", a.lattice_px, false)?;
        Ok(ValidConfig(self))
    }
}

/// Every configuration field: section, name, and what it means with its unit. Fields that are
/// unset by default carry an example value, written commented out.
const FIELD_DOCS: &[(&str, &str, &str, Option<&str>)] = &[
    ("maze", "cols", "Number of cell columns.", None),
    ("maze", "rows", "Number of cell rows.", None),
    ("maze", "cell_px", "Side of a square cell, px.", None),
    ("maze", "loops", "Fraction of the perfect maze's interior walls removed afterwards, 0 to 1 (0: perfect maze).", None),
    ("maze", "wall_thickness_px", "Wall thickness, px.", None),
    ("map", "threshold", "Image maps: grey value (0-255) at or below which a pixel is an obstacle.", None),
    ("map", "resolution_px", "Image maps: scene px per image pixel.", None),
    ("robot", "radius_px", "Robot disc radius, px.", None),
    ("robot", "move_speed_px", "Distance of one AHEAD step, px (v_m).", None),
    ("robot", "turn_speed_deg", "Heading change of one LEFT or RIGHT step, degrees (v_r).", None),
    ("robot", "max_linear_speed_px", "Continuous actions: largest |v|, px per step.", None),
    ("robot", "max_angular_speed_deg", "Continuous actions: largest |w|, degrees per step.", None),
    ("robot", "on_collision", "A step that would touch an obstacle: \"revert\" (stay, go on; the paper) or \"terminate\" (end the episode).", None),
    ("laser", "beams", "Number of laser beams m.", None),
    ("laser", "fov_deg", "Angle the beams cover, centred on the heading, degrees.", None),
    ("laser", "range_px", "Largest reading d_max, px.", None),
    ("laser", "noise_sigma_px", "Standard deviation of Gaussian reading noise, px (0: none).", None),
    ("episode", "goal_tolerance_px", "Success when the goal distance falls below this, px (epsilon).", None),
    ("episode", "max_steps", "Steps before a time-out.", None),
    ("episode", "reward_min", "End the episode when the summed reward falls to this (R_min). Unset: never.", Some("-50.0")),
    ("episode", "min_goal_distance_px", "Least straight-line distance between a drawn start and goal, px.", None),
    ("episode", "start", "Fixed start pose [x px, y px, heading deg]. Unset: drawn from the seed.", Some("[150.0, 150.0, 0.0]")),
    ("episode", "goal", "Fixed goal [x px, y px]. Unset: drawn from the seed.", Some("[850.0, 850.0]")),
    ("episode", "grid_px", "Cell side of the free-space grid for connected regions and planners, px.", None),
    ("reward", "collision", "r_a: added on a step that collided.", None),
    ("reward", "progress_per_px", "r_b: per px of progress towards the goal (negative when moving away).", None),
    ("reward", "turn", "r_c: added on LEFT and RIGHT (scaled by |w| / w_max for continuous actions).", None),
    ("reward", "success", "r_d: added on reaching the goal.", None),
    ("apf", "gravity_gain", "APF policy: attraction gain xi, per px^2.", None),
    ("apf", "repulsion_gain", "APF policy: repulsion gain eta, px^2.", None),
    ("apf", "influence_px", "APF policy: distance d0 beyond which obstacles do not repel, px.", None),
    ("apf", "lattice_px", "APF policy: spacing of the positions the descent steps between, px.", None),
];

impl SimConfig {
    /// The configuration as TOML with a comment on every field (meaning and unit), ready to copy
    /// and edit. Unset optional fields appear commented out with an example value.
    pub fn to_documented_toml(&self) -> String {
        let mut out = String::from(
            "# ronap configuration. Every field of the model with its value; pass the file with\n\
             # --config FILE.toml (flags override it). Units: px (scene pixels, x right, y up) and\n\
             # degrees (counter-clockwise from +x).\n",
        );
        let value = toml::Value::try_from(self).unwrap_or(toml::Value::Table(Default::default()));
        let mut section = "";
        for &(sec, field, doc, example) in FIELD_DOCS {
            if sec != section {
                out.push_str(&format!("\n[{sec}]\n"));
                section = sec;
            }
            out.push_str(&format!("# {doc}\n"));
            match value.get(sec).and_then(|s| s.get(field)) {
                Some(v) => out.push_str(&format!("{field} = {v}\n")),
                None => out.push_str(&format!("# {field} = {}\n", example.unwrap_or("..."))),
            }
        }
        out
    }
}

#[cfg(test)]
mod documented_tests {
    use super::*;

    #[test]
    fn every_field_is_documented_and_the_text_reads_back() {
        let mut c = SimConfig::default();
        c.episode.goal = Some([1.0, 2.0]);
        let text = c.to_documented_toml();
        assert_eq!(SimConfig::from_toml_str(&text).unwrap(), c);
        assert!(text.contains("# start = [150.0, 150.0, 0.0]"));
        assert!(text.contains("goal = [1.0, 2.0]"));
        // Every serialised field (and every optional one) has a line of its own.
        c.episode.reward_min = Some(-1.0);
        c.episode.start = Some([0.0; 3]);
        let full = toml::Value::try_from(&c).unwrap();
        let mut count = 0;
        for (sec, table) in full.as_table().unwrap() {
            for field in table.as_table().unwrap().keys() {
                assert!(
                    FIELD_DOCS.iter().any(|(s, f, _, _)| s == sec && f == field),
                    "{sec}.{field} has no documentation"
                );
                count += 1;
            }
        }
        assert_eq!(count, FIELD_DOCS.len());
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_the_spec_values_and_valid() {
        let c = SimConfig::default();
        assert_eq!((c.maze.cols, c.maze.rows, c.maze.cell_px), (10, 10, 100.0));
        assert_eq!(c.maze.loops, 0.4);
        assert_eq!(
            (c.laser.beams, c.laser.fov_deg, c.laser.range_px),
            (17, 180.0, 50.0)
        );
        assert_eq!((c.robot.move_speed_px, c.robot.turn_speed_deg), (5.0, 15.0));
        assert_eq!(c.episode.goal_tolerance_px, 10.0);
        assert!(c.validate().is_ok());
    }

    #[test]
    fn out_of_range_names_the_field_and_value() {
        let mut c = SimConfig::default();
        c.maze.loops = 1.5;
        let e = c.validate().unwrap_err();
        assert_eq!(e.to_string(), "maze.loops = 1.5: must be between 0 and 1");
        let mut c = SimConfig::default();
        c.maze.cols = 0;
        assert!(c
            .validate()
            .unwrap_err()
            .to_string()
            .starts_with("maze.cols = 0"));
    }

    #[test]
    fn toml_unknown_key_is_named() {
        let e = SimConfig::from_toml_str("[maze]\ncolz = 3\n").unwrap_err();
        assert!(
            e.to_string()
                .starts_with("line 2, column 1: unknown field `colz`"),
            "{e}"
        );
        let e = SimConfig::from_toml_str("[laser]\nbeams = \"many\"\n").unwrap_err();
        assert!(e.to_string().starts_with("line 2, column 9:"), "{e}");
        let c = SimConfig::from_toml_str("[maze]\ncols = 3\n").unwrap();
        assert_eq!(c.maze.cols, 3);
        assert_eq!(c.maze.rows, 10);
    }
}
