//! The simulation configuration: every default of docs/model.md as a field, with its unit.
//!
//! [`SimConfig`] is what a user writes (TOML, flags, keyword arguments); [`ValidConfig`] is the
//! same data after [`SimConfig::validate`] has checked every field. The rest of the core only takes
//! a `ValidConfig`, so it never re-checks a value.
//!
//! One file per section, each with its fields, their defaults and their checks: `scene.rs` (scene,
//! maze, warehouse, map, static obstacles), `robot.rs` (robot, laser), `episode.rs` (episode,
//! reward, observation), `moving.rs`, `team.rs` (robots, team), `apf.rs`, `orca.rs`, `social_force.rs`, `dwa.rs`, `metrics.rs`. This file assembles
//! them into [`SimConfig`] and [`ValidConfig`]; `docs.rs` writes the commented TOML and `file.rs`
//! reads files. The sections sit here, below the layers that use them, rather than beside their
//! code: a scene, a robot and a policy all read the one validated configuration, and a section
//! kept in `sim` or `policy` would make this layer import from above it.
//!
//! The files are private: what other crates use is re-exported here (`pub use`), and what the
//! layers above use beside it, `pub(crate) use`, so a file can move without breaking anyone.

mod apf;
mod crowd;
mod docs;
mod dwa;
mod episode;
mod file;
mod metrics;
mod moving;
mod orca;
mod robot;
mod scene;
mod social_force;
mod team;

pub use apf::ApfConfig;
pub use crowd::{CrowdConfig, RobotPattern};
pub use dwa::DwaConfig;
pub use episode::{
    EpisodeConfig, ObservationConfig, RewardConfig, Shaping, ACTION_MEMORY, MAX_HISTORY,
};
pub use file::{key_line, ConfigFile};
pub use metrics::MetricsConfig;
#[cfg(test)]
pub(crate) use moving::maze_pedestrians;
pub use moving::{
    AgentOrca, Arrival, MotionKind, MovingConfig, MovingShape, Patrol, Pattern, MAX_MOVING,
};
pub use orca::{OrcaConfig, PlannerActions};
pub use robot::{
    KinematicsKind, LaserConfig, OnCollision, RobotConfig, Shape, DEFAULT_STEER_MAX_DEG, MAX_BEAMS,
};
pub use scene::{
    is_convex_polygon, MapConfig, MazeConfig, ObstacleConfig, SceneConfig, SceneKind,
    WarehouseConfig,
};
pub use social_force::{Forces, SocialForceConfig};
pub use team::{
    OnArrival, Order, TeamConfig, TeamRobotConfig, MAX_GOALS, MAX_NEIGHBOURS, MAX_ROBOTS,
};

use serde::{Deserialize, Serialize};
use std::ops::Deref;

/// A configuration value that is out of its range or malformed.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum ConfigError {
    /// A field holds a value outside its allowed range.
    #[error("{field} = {value}: {expected}")]
    OutOfRange {
        /// Dotted field name, as in the TOML file (`maze.cols`, `moving[2].speed_px`).
        field: String,
        /// The offending value, as written.
        value: String,
        /// What the field accepts.
        expected: &'static str,
    },
    /// The TOML text could not be read into a configuration (syntax, type or unknown key).
    #[error("{0}")]
    Toml(String),
    /// A configuration or scenario file that cannot be used: the file, the line when known, and
    /// what was wrong.
    #[error("{}{}: {message}", path.display(), line.map_or(String::new(), |l| format!(":{l}")))]
    File {
        /// The file.
        path: std::path::PathBuf,
        /// The line of the offending key, from 1.
        line: Option<usize>,
        /// What was wrong, naming the key and value.
        message: String,
    },
}

/// The whole simulation configuration, as a user writes it.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SimConfig {
    /// Where episodes take place.
    pub scene: SceneConfig,
    /// Maze generation.
    pub maze: MazeConfig,
    /// Warehouse generation.
    pub warehouse: WarehouseConfig,
    /// Image scenes.
    pub map: MapConfig,
    /// The robot.
    pub robot: RobotConfig,
    /// The laser.
    pub laser: LaserConfig,
    /// Start, goal, episode end.
    pub episode: EpisodeConfig,
    /// What a policy observes beyond the current values.
    #[serde(skip_serializing_if = "ObservationConfig::is_default")]
    pub observation: ObservationConfig,
    /// Reward terms.
    pub reward: RewardConfig,
    /// The artificial potential field policy.
    pub apf: ApfConfig,
    /// Static obstacles added to the scene.
    pub obstacles: Vec<ObstacleConfig>,
    /// Moving obstacles.
    pub moving: Vec<MovingConfig>,
    /// Crowds of reactive pedestrians placed by a pattern (docs/model.md "Crowds that react"):
    /// each stands for a `[[moving]]` entry, after the file's own.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub crowd: Vec<CrowdConfig>,
    /// Several robots (docs/model.md "Several robots"); none: the one robot of `[robot]`.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub robots: Vec<TeamRobotConfig>,
    /// How the robots of a team talk (docs/model.md "Several robots", communication).
    #[serde(skip_serializing_if = "TeamConfig::is_default")]
    pub team: TeamConfig,
    /// The `orca` policy (docs/model.md "Local planners among moving things").
    #[serde(skip_serializing_if = "OrcaConfig::is_default")]
    pub orca: OrcaConfig,
    /// The `social-force` policy (docs/model.md "Local planners among moving things").
    #[serde(skip_serializing_if = "SocialForceConfig::is_default")]
    pub social_force: SocialForceConfig,
    /// The `dwa` policy (docs/model.md "Local planners among moving things").
    #[serde(skip_serializing_if = "DwaConfig::is_default")]
    pub dwa: DwaConfig,
    /// Metrics beyond the standard ones (docs/model.md "Crowd metrics").
    #[serde(skip_serializing_if = "MetricsConfig::is_default")]
    pub metrics: MetricsConfig,
}

/// A [`SimConfig`] whose every field has been checked. Dereferences to the configuration in
/// effect: the one written with its shorthands spelt out (each `[[crowd]]` as the `[[moving]]`
/// entry it stands for, after the file's own; `episode.collision_ends` as
/// `robot.on_collision = "terminate"`). The default is the (valid) default configuration.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ValidConfig {
    /// In effect.
    effective: SimConfig,
    /// As written, when it differs from `effective`.
    written: Option<Box<SimConfig>>,
    /// Where a crowd's pattern puts the robot.
    robot_pattern: Option<RobotPattern>,
}

impl Deref for ValidConfig {
    type Target = SimConfig;
    fn deref(&self) -> &SimConfig {
        &self.effective
    }
}

impl ValidConfig {
    /// A checked configuration, in effect as written.
    fn plain(config: SimConfig) -> Self {
        Self {
            effective: config,
            written: None,
            robot_pattern: None,
        }
    }

    /// The configuration as written, for saving next to results.
    pub fn as_sim_config(&self) -> &SimConfig {
        self.written.as_deref().unwrap_or(&self.effective)
    }

    /// Where a `[[crowd]]` entry with `robot_follows` puts the robot's start and goal.
    pub fn robot_pattern(&self) -> Option<&RobotPattern> {
        self.robot_pattern.as_ref()
    }

    /// The robot's fixed start `[x, y, heading deg]` and goal `[x, y]` in a scene of `width` x
    /// `height` px: from `[episode]`, or from a crowd's pattern the robot follows.
    pub fn fixed_start_goal(
        &self,
        width: f64,
        height: f64,
    ) -> (Option<[f64; 3]>, Option<[f64; 2]>) {
        match self
            .robot_pattern
            .as_ref()
            .and_then(|p| p.start_goal(width, height))
        {
            Some((start, goal)) => (Some(start), Some(goal)),
            None => (self.episode.start, self.episode.goal),
        }
    }

    /// Whether the robot's start and goal are both fixed (by `[episode]` or a crowd's pattern).
    pub fn start_and_goal_fixed(&self) -> bool {
        let pattern = self
            .robot_pattern
            .as_ref()
            .is_some_and(|p| p.pattern != Pattern::Random);
        pattern || (self.episode.start.is_some() && self.episode.goal.is_some())
    }

    /// Length of the observation a policy sees: one value per laser beam, then the goal
    /// direction (docs/model.md "Observation and reward").
    pub fn observation_size(&self) -> usize {
        let k = self.observation.history.max(1) as usize;
        self.frame_size() * k + ACTION_MEMORY * (k - 1)
    }

    /// Length of one frame of the observation: one value per laser beam, the goal direction and
    /// a team's neighbour slots. The observation is this alone unless `observation.history` > 1.
    pub fn frame_size(&self) -> usize {
        self.laser.beams as usize + 1 + self.team.neighbours as usize * self.team.slot_size()
    }

    /// Robots in a team (0: no `[[robots]]`, the one robot of `[robot]`).
    pub fn team_size(&self) -> usize {
        self.robots.iter().map(|r| r.count as usize).sum()
    }

    /// This configuration as a team's: itself when it has `[[robots]]`, else its one robot as a
    /// team of one (one `[[robots]]` entry that sets nothing; `[episode]`'s fixed start and goal,
    /// if any, place it as they place the lone robot), whose episodes are the lone robot's, step
    /// for step (docs/model.md "Several robots").
    pub fn as_team(&self) -> ValidConfig {
        let mut team = self.clone();
        if team.team_size() == 0 {
            for c in std::iter::once(&mut team.effective).chain(team.written.as_deref_mut()) {
                c.robots = vec![TeamRobotConfig::default()];
            }
        }
        team
    }

    /// The `[[robots]]` entry of team robot `k` (from 0, in entry order).
    pub fn team_entry(&self, k: usize) -> Option<&TeamRobotConfig> {
        let mut left = k;
        self.robots.iter().find(|r| {
            if left < r.count as usize {
                true
            } else {
                left -= r.count as usize;
                false
            }
        })
    }

    /// The configuration of team robot `k` as a one-robot configuration: `[robot]`, `[laser]`
    /// and `[episode]` with its entry's fields put in (validated with the whole team).
    pub fn team_robot(&self, k: usize) -> ValidConfig {
        let mut c = self.effective.clone();
        c.robots = Vec::new();
        if let Some(e) = self.team_entry(k) {
            if let Some(v) = e.radius_px {
                c.robot.radius_px = v;
            }
            if let Some(v) = e.move_speed_px {
                c.robot.move_speed_px = v;
            }
            if let Some(v) = e.turn_speed_deg {
                c.robot.turn_speed_deg = v;
            }
            if let Some(v) = e.laser_beams {
                c.laser.beams = v;
            }
            if let Some(v) = e.laser_range_px {
                c.laser.range_px = v;
            }
            if let Some(v) = e.laser_fov_deg {
                c.laser.fov_deg = v;
            }
            // `[episode]`'s are set only in a lone robot's team of one (`as_team`).
            c.episode.start = e.start.or(c.episode.start);
            c.episode.goal = e.goal.or(e.goals.first().copied()).or(c.episode.goal);
        }
        // Only a team of one follows a crowd's pattern (validated), as the lone robot does.
        ValidConfig {
            robot_pattern: self.robot_pattern.clone().filter(|_| k == 0),
            ..ValidConfig::plain(c)
        }
    }

    /// The query distance scenes are indexed for: the laser range or a step plus the robot
    /// radius, whichever is longer, px.
    pub fn reach_px(&self) -> f64 {
        let step = self.robot.move_speed_px.max(self.robot.max_linear_speed_px);
        self.laser.range_px.max(step + self.robot.radius_px)
    }
}

/// Whether a field that defaults to false is false (left out of written configurations).
fn is_false(v: &bool) -> bool {
    !*v
}

/// Whether a field that defaults to 0 is 0 (left out of written configurations).
fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

fn check(
    ok: bool,
    field: &str,
    value: impl ToString,
    expected: &'static str,
) -> Result<(), ConfigError> {
    if ok {
        Ok(())
    } else {
        Err(ConfigError::OutOfRange {
            field: field.to_string(),
            value: value.to_string(),
            expected,
        })
    }
}

fn non_negative(field: &str, v: f64) -> Result<(), ConfigError> {
    check(
        v.is_finite() && v >= 0.0,
        field,
        v,
        "must be zero or positive",
    )
}

fn finite(field: &str, v: f64) -> Result<(), ConfigError> {
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

fn length(field: &str, v: f64, zero_ok: bool) -> Result<(), ConfigError> {
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
/// Checks that `v` is a time in steps: positive, finite and at most as long as the longest
/// length (an ORCA horizon).
fn steps(field: &str, v: f64) -> Result<(), ConfigError> {
    check(
        v.is_finite() && v > 0.0 && v <= MAX_LENGTH_PX,
        field,
        format!("{v:?}"),
        "must be a positive number of steps, at most 100000",
    )
}

/// Checks that `v` is a fraction, 0 to 1.
fn fraction(field: &str, v: f64) -> Result<(), ConfigError> {
    check(
        (0.0..=1.0).contains(&v),
        field,
        format!("{v:?}"),
        "must be between 0 and 1",
    )
}

fn point(field: &str, p: [f64; 2]) -> Result<(), ConfigError> {
    check(
        p.iter().all(|v| v.is_finite() && v.abs() <= MAX_LENGTH_PX),
        field,
        format!("{p:?}"),
        "must be two finite numbers [x, y] within 100000 px",
    )
}

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
        self.maze.validate()?;
        self.map.validate()?;
        self.robot.validate()?;
        self.laser.validate()?;
        self.episode.validate()?;
        self.reward.validate_terms()?;
        self.observation.validate()?;
        self.reward.validate_shaping()?;
        self.apf.validate()?;
        self.episode.validate_team_fields()?;
        self.scene.validate()?;
        self.warehouse.validate()?;
        scene::validate_obstacles(&self.obstacles)?;
        moving::validate_moving(&self.moving)?;
        let fixed = self.episode.start.is_some() || self.episode.goal.is_some();
        let robot_pattern = crowd::validate_crowds(&self.crowd, fixed, &self.robots)?;
        team::validate_robots(&self.robots)?;
        // A team's robots are placed by their entries; `[episode]`'s would go unheeded.
        if !self.robots.is_empty() {
            let fixed = [
                (
                    "episode.start",
                    self.episode.start.map(|s| format!("{s:?}")),
                ),
                ("episode.goal", self.episode.goal.map(|g| format!("{g:?}"))),
            ];
            for (field, value) in fixed {
                if let Some(v) = value {
                    check(
                        false,
                        field,
                        v,
                        "a team's robots are placed by their [[robots]] entries: set robots[i].start and robots[i].goal instead",
                    )?;
                }
            }
        }
        self.team.validate()?;
        self.metrics.validate()?;
        self.orca.validate()?;
        self.social_force.validate()?;
        self.dwa.validate()?;
        let disc = self.robot.shape == robot::Shape::Disc;
        if self.crowd.is_empty() && !self.episode.collision_ends && disc {
            moving::validate_total(&self.moving)?;
            return Ok(ValidConfig::plain(self));
        }
        let mut effective = self.clone();
        effective
            .moving
            .extend(effective.crowd.drain(..).map(|c| c.to_moving()));
        moving::validate_total(&effective.moving)?;
        if effective.episode.collision_ends {
            effective.robot.on_collision = OnCollision::Terminate;
        }
        // A rectangle or polygon is a disc that holds it wherever a disc is asked for (the free-space
        // grid, placement, other robots, moving obstacles); the still scene's checks take it
        // for the discs of `RobotConfig::cover`.
        effective.robot.radius_px = effective.robot.circumscribed_px();
        Ok(ValidConfig {
            effective,
            written: Some(Box::new(self)),
            robot_pattern,
        })
    }
}

/// Scenes the tests ask for by their shape.
#[cfg(test)]
impl SimConfig {
    /// This configuration in an open hall `side_px` square (a maze of one cell).
    pub(crate) fn open_hall(mut self, side_px: f64) -> Self {
        (self.maze.cols, self.maze.rows, self.maze.cell_px) = (1, 1, side_px);
        self
    }

    /// This configuration in an open hall `cols` x `cell_px` square when `maze` is false, else in
    /// a maze of `cols` x `cols` cells.
    pub(crate) fn hall_or_maze(mut self, maze: bool, cols: u32, cell_px: f64) -> Self {
        if !maze {
            return self.open_hall(cell_px * f64::from(cols));
        }
        (self.maze.cols, self.maze.rows) = (cols, cols);
        self
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_team_is_placed_by_its_entries_and_a_lone_robot_is_its_team_of_one() {
        for (line, field) in [
            ("start = [150.0, 150.0, 0.0]", "episode.start"),
            ("goal = [450.0, 350.0]", "episode.goal"),
        ] {
            let text = format!("[episode]\n{line}\n[[robots]]\ncount = 1\n");
            let e = SimConfig::from_toml_str(&text)
                .and_then(SimConfig::validate)
                .unwrap_err()
                .to_string();
            assert!(e.contains(field) && e.contains("robots[i].start"), "{e}");
        }
        let mut lone = SimConfig::default();
        lone.episode.start = Some([150.0, 150.0, 0.0]);
        lone.episode.goal = Some([450.0, 350.0]);
        let lone = lone.validate().expect("valid");
        let one = lone.as_team();
        assert_eq!(one.team_size(), 1);
        assert_eq!(one.team_entry(0), Some(&TeamRobotConfig::default()));
        let robot = one.team_robot(0);
        assert_eq!(
            (robot.episode.start, robot.episode.goal),
            (lone.episode.start, lone.episode.goal)
        );
        assert_eq!(one.as_team(), one);
    }

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
    fn every_section_names_its_own_fields() {
        // One field a section, each checked in that section's file: the error names the field
        // as the TOML file spells it (so a scenario's error finds its line).
        type Set = fn(&mut SimConfig);
        let cases: [(Set, &str); 12] = [
            (|c| c.maze.wall_thickness_px = 0.0, "maze.wall_thickness_px"),
            (|c| c.map.resolution_px = -1.0, "map.resolution_px"),
            (|c| c.robot.radius_px = 0.0, "robot.radius_px"),
            (|c| c.laser.fov_deg = 400.0, "laser.fov_deg"),
            (|c| c.episode.max_steps = 0, "episode.max_steps"),
            (|c| c.reward.turn = f64::NAN, "reward.turn"),
            (|c| c.reward.shaping_gamma = 2.0, "reward.shaping_gamma"),
            (|c| c.apf.lattice_px = 0.0, "apf.lattice_px"),
            (|c| c.episode.deadlock_steps = 0, "episode.deadlock_steps"),
            (
                |c| c.episode.safety_radius_px = Some(-1.0),
                "episode.safety_radius_px",
            ),
            (|c| c.warehouse.aisle_px = 0.0, "warehouse.aisle_px"),
            (|c| c.team.message_size = 65, "team.message_size"),
        ];
        for (set, field) in cases {
            let mut c = SimConfig::default();
            set(&mut c);
            match c.validate() {
                Err(ConfigError::OutOfRange { field: named, .. }) => assert_eq!(named, field),
                other => panic!("{field}: {other:?}"),
            }
        }
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

    #[test]
    fn the_example_scenario_reads_back_and_validates() {
        let c = SimConfig::example_scenario();
        let text = c.to_documented_toml();
        let back = SimConfig::from_toml_str(&text).unwrap();
        assert_eq!(back, c);
        assert!(back.validate().is_ok());
        // With no obstacles, the examples are there but commented out.
        let plain = SimConfig::default().to_documented_toml();
        assert!(plain.contains("# [[moving]]"));
        assert_eq!(
            SimConfig::from_toml_str(&plain).unwrap(),
            SimConfig::default()
        );
    }

    #[test]
    fn scenario_errors_name_file_line_key_and_value() {
        let text =
            "[scene]\nkind = \"maze\"\n\n[[moving]]\ncount = 2\n\n[[moving]]\nspeed_px = -3.0\n";
        let file = ConfigFile::from_text(std::path::Path::new("s.toml"), text.to_string());
        let e = file.parse().unwrap().validate().unwrap_err();
        let e = file.locate(e).to_string();
        assert_eq!(
            e,
            "s.toml:8: moving[1].speed_px = -3.0: must be between 0 and 100000 px"
        );
        let file = ConfigFile::from_text(
            std::path::Path::new("s.toml"),
            "[[moving]]\nmotion = \"teleport\"\n".to_string(),
        );
        let e = file.parse().unwrap_err().to_string();
        assert!(
            e.starts_with("s.toml:2: `motion = \"teleport\"`: unknown variant"),
            "{e}"
        );
        let file = ConfigFile::from_text(
            std::path::Path::new("s.toml"),
            "[[obstacles]]\nshape = \"polygon\"\npoints = [[0.0, 0.0], [10.0, 0.0], [0.0, 10.0], [10.0, 10.0]]\n".to_string(),
        );
        let e = file
            .locate(file.parse().unwrap().validate().unwrap_err())
            .to_string();
        assert!(e.starts_with("s.toml:3: obstacles[0].points = "), "{e}");
        assert_eq!(key_line("laser.beams = 3\n", "laser.beams"), Some(1));
        assert_eq!(key_line("[laser]\nrange_px = 3\n", "laser.beams"), None);
    }

    #[test]
    fn a_map_scene_file_is_relative_to_the_scenario() {
        let file = ConfigFile::from_text(
            std::path::Path::new("dir/s.toml"),
            "[scene]\nkind = \"map\"\nfile = \"room.png\"\n".to_string(),
        );
        let c = file.parse().unwrap();
        assert_eq!(
            c.scene.file.as_deref(),
            Some(std::path::Path::new("dir/room.png"))
        );
        let mut c = SimConfig::default();
        c.scene.kind = SceneKind::Map;
        assert!(c
            .validate()
            .unwrap_err()
            .to_string()
            .starts_with("scene.file"));
    }
}
