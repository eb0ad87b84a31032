//! The simulation configuration: every default of docs/model.md as a field, with its unit.
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

/// Which scene episodes take place in (docs/model.md "Scenario files").
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SceneKind {
    /// A maze generated as `[maze]` says (the paper's scene).
    #[default]
    Maze,
    /// A warehouse generated as `[warehouse]` says.
    Warehouse,
    /// An image (PNG/PGM) or ROS `map_server` YAML file, read as `[map]` says.
    Map,
}

/// Where episodes take place: the scene section of a scenario file.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SceneConfig {
    /// `maze` (default), `warehouse` or `map`.
    pub kind: SceneKind,
    /// Generated scenes: the seed of the one scene every episode uses. Unset: each episode's
    /// seed draws its own scene.
    pub seed: Option<u64>,
    /// Map scenes: the image or YAML file (relative to the scenario file).
    pub file: Option<std::path::PathBuf>,
}

/// A static obstacle added to the scene (docs/model.md "Static obstacles beyond boxes").
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "shape", rename_all = "lowercase", deny_unknown_fields)]
pub enum ObstacleConfig {
    /// An axis-aligned box between two corners, px.
    Box {
        /// Lower-left corner `[x, y]`.
        min: [f64; 2],
        /// Upper-right corner `[x, y]`.
        max: [f64; 2],
    },
    /// A disc.
    Disc {
        /// Centre `[x, y]`, px.
        center: [f64; 2],
        /// Radius, px.
        radius_px: f64,
    },
    /// A convex polygon, its corners in order (either way round).
    Polygon {
        /// Corners `[[x, y], ...]`, px; at least three, convex.
        points: Vec<[f64; 2]>,
    },
}

/// The shape of a moving obstacle.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum MovingShape {
    /// A disc of `radius_px`.
    #[default]
    Disc,
    /// An axis-aligned box of `size_px`.
    Box,
}

/// How a moving obstacle moves (docs/model.md "Moving obstacles").
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MotionKind {
    /// Does not move.
    Still,
    /// Constant velocity, reflecting off static obstacles and the scene border.
    Linear,
    /// Patrols `points`.
    Waypoints,
    /// Heading changes drawn from N(0, `turn_sigma_deg`^2) each step, reflecting off static
    /// obstacles.
    #[default]
    RandomWalk,
    /// Absent until a step drawn in `[from_step, to_step]`, then present and moving as `then`.
    Appear,
}

/// How a `waypoints` obstacle goes round its points.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Patrol {
    /// From the last point back to the first, and round again.
    #[default]
    Loop,
    /// Back and forth along the points.
    PingPong,
}

/// One `[[moving]]` entry: `count` obstacles alike (docs/model.md "Moving obstacles").
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct MovingConfig {
    /// How many obstacles this entry makes. Default 1.
    pub count: u32,
    /// `disc` (default) or `box`.
    pub shape: MovingShape,
    /// Disc radius, px. Default 8.
    pub radius_px: f64,
    /// Box width and height, px. Default [24, 12].
    pub size_px: [f64; 2],
    /// Fixed start `[x, y]` (of the centre), px. Default: drawn from the seed in free space, at
    /// least `min_robot_distance_px` from the robot's start and goal (waypoints: the first point).
    /// A fixed start on the robot's start keeps the obstacle away until the robot has moved off.
    pub start: Option<[f64; 2]>,
    /// `still`, `linear`, `waypoints`, `random_walk` (default) or `appear`.
    pub motion: MotionKind,
    /// Distance moved per step, px. Default 2.
    pub speed_px: f64,
    /// `linear`: direction of travel, degrees. Default: drawn from the seed.
    pub direction_deg: Option<f64>,
    /// `random_walk`: standard deviation of the heading change per step, degrees. Default 15.
    pub turn_sigma_deg: f64,
    /// `waypoints`: the points patrolled `[[x, y], ...]`, px.
    pub points: Vec<[f64; 2]>,
    /// `waypoints`: `loop` (default) or `ping_pong`.
    pub mode: Patrol,
    /// `appear`: earliest step of appearance. Default 1.
    pub from_step: u32,
    /// `appear`: latest step of appearance. Default 200.
    pub to_step: u32,
    /// Least gap between the obstacle and the robot where it starts or appears, px. Default 30.
    pub min_robot_distance_px: f64,
    /// `appear`: how it moves once there: `still` (default), `linear` or `random_walk`.
    pub then: MotionKind,
}

impl Default for MovingConfig {
    fn default() -> Self {
        Self {
            count: 1,
            shape: MovingShape::Disc,
            radius_px: 8.0,
            size_px: [24.0, 12.0],
            start: None,
            motion: MotionKind::RandomWalk,
            speed_px: 2.0,
            direction_deg: None,
            turn_sigma_deg: 15.0,
            points: Vec::new(),
            mode: Patrol::Loop,
            from_step: 1,
            to_step: 200,
            min_robot_distance_px: 30.0,
            then: MotionKind::Still,
        }
    }
}

/// Maze generation (docs/model.md "Scene: maze").
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

/// How an image becomes a scene (docs/model.md "Maze loaded as a picture").
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

/// A generated logistics warehouse (docs/model.md "Warehouse scene"): rows of racks back to back in pairs,
/// aisles between them, cross aisles, a free loading area along the bottom, and pallets of clutter
/// in the aisles.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct WarehouseConfig {
    /// Pairs of rack rows (two racks back to back), bottom to top. Default 5.
    pub rack_pairs: u32,
    /// Racks along one row. Default 12.
    pub racks_per_row: u32,
    /// Length of one rack along its row, px. Default 50.
    pub rack_length_px: f64,
    /// Depth of one rack (a pair is twice as deep), px. Default 15.
    pub rack_depth_px: f64,
    /// Width of the aisles between rack pairs, of the cross aisles and of the border aisle, px.
    /// Default 40.
    pub aisle_px: f64,
    /// A cross aisle after every this many racks along a row. Default 4.
    pub cross_aisle_every: u32,
    /// Depth of the free loading area along the bottom, px. Default 150.
    pub loading_px: f64,
    /// Fraction of aisle spots (one rack length each) holding a pallet, 0 to 1. Default 0.15.
    pub clutter: f64,
    /// Side of a square pallet, px. Default 12.
    pub pallet_px: f64,
    /// Thickness of the outer walls, px. Default 2.
    pub wall_thickness_px: f64,
}

impl WarehouseConfig {
    /// Width and height of the warehouse, px: walls, side aisles, the racks along a row with a
    /// cross aisle after every `cross_aisle_every` of them (not after the last), and bottom to top
    /// the loading area, the border aisle and each rack pair with the aisle above it.
    pub fn size_px(&self) -> (f64, f64) {
        let n = self.racks_per_row as usize;
        let cross_aisles = n
            .saturating_sub(1)
            .checked_div(self.cross_aisle_every as usize)
            .unwrap_or(0);
        let width = 2.0 * self.wall_thickness_px
            + 2.0 * self.aisle_px
            + n as f64 * self.rack_length_px
            + cross_aisles as f64 * self.aisle_px;
        let height = 2.0 * self.wall_thickness_px
            + self.loading_px
            + self.aisle_px
            + f64::from(self.rack_pairs) * (2.0 * self.rack_depth_px + self.aisle_px);
        (width, height)
    }
}

impl Default for WarehouseConfig {
    fn default() -> Self {
        Self {
            rack_pairs: 5,
            racks_per_row: 12,
            rack_length_px: 50.0,
            rack_depth_px: 15.0,
            aisle_px: 40.0,
            cross_aisle_every: 4,
            loading_px: 150.0,
            clutter: 0.15,
            pallet_px: 12.0,
            wall_thickness_px: 2.0,
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
    /// Several robots: the episode ends as a deadlock when no robot has moved for this many
    /// steps. Default 100.
    pub deadlock_steps: u32,
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
    /// Several robots (docs/model.md "Several robots"); none: the one robot of `[robot]`.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub robots: Vec<TeamRobotConfig>,
    /// How the robots of a team talk (docs/model.md "Several robots", communication).
    #[serde(skip_serializing_if = "TeamConfig::is_default")]
    pub team: TeamConfig,
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

/// Communication between the robots of a team: each broadcasts its pose, goal and a message of
/// `message_size` floats its policy chooses; a robot receives what the robots within
/// `comm_range_px` sent at the previous step, and its observation carries the `neighbours`
/// nearest of them after the paper's values.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct TeamConfig {
    /// Range of a broadcast, px. Default 200.
    pub comm_range_px: f64,
    /// Floats in a policy's message. Default 0 (pose and goal only).
    pub message_size: u32,
    /// Nearest senders in the observation: each `[dx, dy]` in the robot's frame over
    /// `comm_range_px`, the heading difference over 360, 1 (present), then its message;
    /// zeros for missing ones. Default 0 (the paper's observation).
    pub neighbours: u32,
}

impl Default for TeamConfig {
    fn default() -> Self {
        Self {
            comm_range_px: 200.0,
            message_size: 0,
            neighbours: 0,
        }
    }
}

impl TeamConfig {
    /// Whether every field has its default (then written configurations leave it out).
    pub fn is_default(&self) -> bool {
        *self == Self::default()
    }

    /// Values per neighbour in the observation.
    pub fn slot_size(&self) -> usize {
        4 + self.message_size as usize
    }
}

/// Most neighbours, and most floats in a message.
pub const MAX_NEIGHBOURS: u32 = 64;

/// In which order a robot visits its goals (docs/model.md "Multi-destination tasks").
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Order {
    /// As listed.
    #[default]
    Given,
    /// Greedily: each time the unvisited goal nearest by geodesic distance, the first listed on a
    /// tie.
    Nearest,
    /// The order minimising the summed geodesic distance: exact for up to
    /// `plan::tour::HELD_KARP_MAX_GOALS` (12) goals, never longer than [`Order::Nearest`]'s beyond.
    Optimal,
}

/// What a robot of a team does on reaching its goal.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum OnArrival {
    /// It stops there and stays an obstacle (default).
    #[default]
    Stay,
    /// It leaves the scene.
    Vanish,
}

/// A `[[robots]]` entry: `count` robots alike, each field left unset taking `[robot]`'s,
/// `[laser]`'s or `[episode]`'s value.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct TeamRobotConfig {
    /// How many robots this entry makes. Default 1.
    pub count: u32,
    /// Fixed start pose `[x px, y px, z deg]` (count 1 only). Default: drawn from the seed, clear
    /// of the other robots.
    pub start: Option<[f64; 3]>,
    /// Fixed goal `[x px, y px]` (count 1 only). Default: drawn from the seed.
    pub goal: Option<[f64; 2]>,
    /// The policy that drives these robots (any `--policy` name). Default: the run's.
    pub policy: Option<String>,
    /// Disc radius, px. Default: `robot.radius_px`.
    pub radius_px: Option<f64>,
    /// Distance of one AHEAD step, px. Default: `robot.move_speed_px`.
    pub move_speed_px: Option<f64>,
    /// Heading change of one LEFT or RIGHT step, degrees. Default: `robot.turn_speed_deg`.
    pub turn_speed_deg: Option<f64>,
    /// Laser beams. Default: `laser.beams`.
    pub laser_beams: Option<u32>,
    /// Laser range, px. Default: `laser.range_px`.
    pub laser_range_px: Option<f64>,
    /// Laser field of view, degrees. Default: `laser.fov_deg`.
    pub laser_fov_deg: Option<f64>,
    /// On reaching its (last) goal: `stay` (default; it stays an obstacle there) or `vanish`.
    pub on_arrival: OnArrival,
    /// Fixed goals `[[x, y], ...]` visited one after the other (count 1 only; instead of `goal`).
    /// Default: `goal_count` goals drawn from the seed.
    pub goals: Vec<[f64; 2]>,
    /// Goals drawn from the seed when `goals` is unset. Default 1.
    pub goal_count: u32,
    /// The order the goals are visited in: `given` (default), `nearest` (greedily by geodesic
    /// distance) or `optimal` (the shortest tour).
    pub order: Order,
}

impl Default for TeamRobotConfig {
    fn default() -> Self {
        Self {
            count: 1,
            start: None,
            goal: None,
            policy: None,
            radius_px: None,
            move_speed_px: None,
            turn_speed_deg: None,
            laser_beams: None,
            laser_range_px: None,
            laser_fov_deg: None,
            on_arrival: OnArrival::Stay,
            goals: Vec::new(),
            goal_count: 1,
            order: Order::Given,
        }
    }
}

/// Most goals one robot visits.
pub const MAX_GOALS: u32 = 64;

/// Largest number of robots in a team.
pub const MAX_ROBOTS: u32 = 10_000;

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
        let mut c = self.0.clone();
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
            c.episode.start = e.start;
            c.episode.goal = e.goal.or(e.goals.first().copied());
        }
        ValidConfig(c)
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
/// Checks that `v` is a fraction, 0 to 1.
fn fraction(field: &str, v: f64) -> Result<(), ConfigError> {
    check(
        (0.0..=1.0).contains(&v),
        field,
        format!("{v:?}"),
        "must be between 0 and 1",
    )
}

/// Largest number of laser beams.
pub const MAX_BEAMS: u32 = 4096;

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
        fraction("maze.loops", m.loops)?;
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
        check(
            (1..=MAX_HISTORY).contains(&self.observation.history),
            "observation.history",
            self.observation.history,
            "must be a whole number from 1 to 64",
        )?;
        check(
            self.observation.history == 1 || self.robots.is_empty(),
            "observation.history",
            self.observation.history,
            "must be 1 with [[robots]] (a team's observations carry no history yet)",
        )?;
        check(
            w.shaping_gamma > 0.0 && w.shaping_gamma <= 1.0,
            "reward.shaping_gamma",
            w.shaping_gamma.to_string(),
            "must be in (0, 1]",
        )?;

        let a = &self.apf;
        non_negative("apf.gravity_gain", a.gravity_gain)?;
        non_negative("apf.repulsion_gain", a.repulsion_gain)?;
        length("apf.influence_px", a.influence_px, false)?;
        length("apf.lattice_px", a.lattice_px, false)?;
        check(
            e.deadlock_steps >= 1,
            "episode.deadlock_steps",
            e.deadlock_steps,
            "must be at least 1",
        )?;
        if let Some(v) = e.safety_radius_px {
            length("episode.safety_radius_px", v, true)?;
        }
        self.validate_scenario()?;
        Ok(ValidConfig(self))
    }
}

/// Most moving obstacles a configuration may ask for.
pub const MAX_MOVING: u32 = 10_000;

fn point(field: &str, p: [f64; 2]) -> Result<(), ConfigError> {
    check(
        p.iter().all(|v| v.is_finite() && v.abs() <= MAX_LENGTH_PX),
        field,
        format!("{p:?}"),
        "must be two finite numbers [x, y] within 100000 px",
    )
}

impl SimConfig {
    /// Checks the scene, warehouse, obstacle and moving-obstacle sections.
    fn validate_scenario(&self) -> Result<(), ConfigError> {
        let s = &self.scene;
        match (s.kind, &s.file) {
            (SceneKind::Map, None) => check(
                false,
                "scene.file",
                "(unset)",
                "a map scene needs the image or YAML file",
            )?,
            (SceneKind::Maze | SceneKind::Warehouse, Some(f)) => check(
                false,
                "scene.file",
                f.display(),
                "only a map scene reads a file (set scene.kind = \"map\")",
            )?,
            _ => {}
        }
        let w = &self.warehouse;
        let count = "must be between 1 and 1000";
        check(
            (1..=1000).contains(&w.rack_pairs),
            "warehouse.rack_pairs",
            w.rack_pairs,
            count,
        )?;
        check(
            (1..=1000).contains(&w.racks_per_row),
            "warehouse.racks_per_row",
            w.racks_per_row,
            count,
        )?;
        check(
            w.cross_aisle_every <= 1000,
            "warehouse.cross_aisle_every",
            w.cross_aisle_every,
            "must be between 0 (no cross aisles) and 1000",
        )?;
        length("warehouse.rack_length_px", w.rack_length_px, false)?;
        length("warehouse.rack_depth_px", w.rack_depth_px, false)?;
        length("warehouse.aisle_px", w.aisle_px, false)?;
        length("warehouse.loading_px", w.loading_px, true)?;
        length("warehouse.pallet_px", w.pallet_px, false)?;
        length("warehouse.wall_thickness_px", w.wall_thickness_px, false)?;
        fraction("warehouse.clutter", w.clutter)?;
        let (wide, tall) = w.size_px();
        check(
            wide.max(tall) <= MAX_LENGTH_PX,
            "warehouse.racks_per_row",
            w.racks_per_row,
            "the warehouse would be wider or taller than 100000 px",
        )?;

        for (i, o) in self.obstacles.iter().enumerate() {
            match o {
                ObstacleConfig::Box { min, max } => {
                    point(&format!("obstacles[{i}].min"), *min)?;
                    point(&format!("obstacles[{i}].max"), *max)?;
                    check(
                        min[0] < max[0] && min[1] < max[1],
                        &format!("obstacles[{i}].max"),
                        format!("{max:?}"),
                        "must be above and to the right of min",
                    )?;
                }
                ObstacleConfig::Disc { center, radius_px } => {
                    point(&format!("obstacles[{i}].center"), *center)?;
                    length(&format!("obstacles[{i}].radius_px"), *radius_px, false)?;
                }
                ObstacleConfig::Polygon { points } => {
                    let field = format!("obstacles[{i}].points");
                    for p in points {
                        point(&field, *p)?;
                    }
                    check(
                        is_convex_polygon(points),
                        &field,
                        format!("{points:?}"),
                        "must be at least three corners of a convex polygon with an area, in order",
                    )?;
                }
            }
        }

        let mut total = 0u64;
        for (i, m) in self.moving.iter().enumerate() {
            let f = |name: &str| format!("moving[{i}].{name}");
            check(
                (1..=MAX_MOVING).contains(&m.count),
                &f("count"),
                m.count,
                "must be between 1 and 10000",
            )?;
            total += u64::from(m.count);
            length(&f("radius_px"), m.radius_px, false)?;
            length(&f("size_px"), m.size_px[0], false)?;
            length(&f("size_px"), m.size_px[1], false)?;
            if let Some(p) = m.start {
                point(&f("start"), p)?;
            }
            length(&f("speed_px"), m.speed_px, true)?;
            if let Some(d) = m.direction_deg {
                finite(&f("direction_deg"), d)?;
            }
            check(
                m.turn_sigma_deg.is_finite() && (0.0..=360.0).contains(&m.turn_sigma_deg),
                &f("turn_sigma_deg"),
                format!("{:?}", m.turn_sigma_deg),
                "must be between 0 and 360",
            )?;
            length(&f("min_robot_distance_px"), m.min_robot_distance_px, true)?;
            for p in &m.points {
                point(&f("points"), *p)?;
            }
            let patrols = m.motion == MotionKind::Waypoints
                || (m.motion == MotionKind::Appear && m.then == MotionKind::Waypoints);
            check(
                !patrols || m.points.len() >= 2,
                &f("points"),
                format!("{:?}", m.points),
                "a waypoints obstacle needs at least two points",
            )?;
            check(
                !(m.motion == MotionKind::Appear && m.then == MotionKind::Waypoints),
                &f("then"),
                "\"waypoints\"",
                "an appearing obstacle moves as still, linear or random_walk",
            )?;
            check(
                m.then != MotionKind::Appear,
                &f("then"),
                "\"appear\"",
                "an appearing obstacle moves as still, linear or random_walk",
            )?;
            check(
                m.from_step <= m.to_step,
                &f("to_step"),
                m.to_step,
                "must be at least from_step",
            )?;
        }
        check(
            total <= u64::from(MAX_MOVING),
            "moving",
            total,
            "at most 10000 moving obstacles in all",
        )?;
        let mut robots = 0u64;
        for (i, r) in self.robots.iter().enumerate() {
            let f = |name: &str| format!("robots[{i}].{name}");
            check(
                (1..=MAX_ROBOTS).contains(&r.count),
                &f("count"),
                r.count,
                "must be between 1 and 10000",
            )?;
            robots += u64::from(r.count);
            for (name, v) in [("start", r.start.map(|s| [s[0], s[1]])), ("goal", r.goal)] {
                if let Some(p) = v {
                    point(&f(name), p)?;
                    check(
                        r.count == 1,
                        &f(name),
                        format!("{p:?}"),
                        "a fixed start or goal is for one robot (count = 1)",
                    )?;
                }
            }
            if let Some(s) = r.start {
                finite(&f("start"), s[2])?;
            }
            for (name, v) in [
                ("radius_px", r.radius_px),
                ("move_speed_px", r.move_speed_px),
                ("laser_range_px", r.laser_range_px),
            ] {
                if let Some(v) = v {
                    length(&f(name), v, false)?;
                }
            }
            if let Some(v) = r.turn_speed_deg {
                finite(&f("turn_speed_deg"), v)?;
            }
            if let Some(v) = r.laser_beams {
                check(
                    (1..=MAX_BEAMS).contains(&v),
                    &f("laser_beams"),
                    v,
                    "must be between 1 and 4096",
                )?;
            }
            if let Some(v) = r.laser_fov_deg {
                check(
                    v.is_finite() && (0.0..=360.0).contains(&v),
                    &f("laser_fov_deg"),
                    format!("{v:?}"),
                    "must be between 0 and 360",
                )?;
            }
            for p in &r.goals {
                point(&f("goals"), *p)?;
            }
            check(
                r.goals.is_empty() || (r.count == 1 && r.goal.is_none()),
                &f("goals"),
                format!("{:?}", r.goals),
                "a goal list is for one robot (count = 1) without `goal`",
            )?;
            check(
                (1..=MAX_GOALS).contains(&r.goal_count),
                &f("goal_count"),
                r.goal_count,
                "must be between 1 and 64",
            )?;
            if let Some(p) = &r.policy {
                check(
                    !p.trim().is_empty(),
                    &f("policy"),
                    "\"\"",
                    "must name a policy",
                )?;
            }
        }
        check(
            robots <= u64::from(MAX_ROBOTS),
            "robots",
            robots,
            "at most 10000 robots in all",
        )?;
        let t = &self.team;
        length("team.comm_range_px", t.comm_range_px, true)?;
        check(
            t.message_size <= MAX_NEIGHBOURS,
            "team.message_size",
            t.message_size,
            "must be between 0 and 64",
        )?;
        check(
            t.neighbours <= MAX_NEIGHBOURS,
            "team.neighbours",
            t.neighbours,
            "must be between 0 and 64",
        )
    }
}

/// Whether `points` are the corners, in order either way round, of a convex polygon with an area.
pub fn is_convex_polygon(points: &[[f64; 2]]) -> bool {
    let n = points.len();
    if n < 3 {
        return false;
    }
    let mut sign = 0.0f64;
    for i in 0..n {
        let [ax, ay] = points[i];
        let [bx, by] = points[(i + 1) % n];
        let [cx, cy] = points[(i + 2) % n];
        let cross = (bx - ax) * (cy - by) - (by - ay) * (cx - bx);
        if cross == 0.0 {
            continue;
        }
        if sign * cross < 0.0 {
            return false;
        }
        sign = cross.signum();
    }
    let area2: f64 = (0..n)
        .map(|i| {
            let [ax, ay] = points[i];
            let [bx, by] = points[(i + 1) % n];
            ax * by - bx * ay
        })
        .sum();
    sign != 0.0 && area2.abs() > 1e-9
}

/// Every configuration field: section, name, and what it means with its unit. Fields that are
/// unset by default carry an example value, written commented out.
const FIELD_DOCS: &[(&str, &str, &str, Option<&str>)] = &[
    ("scene", "kind", "Where episodes take place: \"maze\" (the paper's), \"warehouse\" or \"map\" (an image or ROS YAML file).", None),
    ("scene", "seed", "Generated scenes: one scene, of this seed, for every episode. Unset: each episode's seed draws its own.", Some("7")),
    ("scene", "file", "Map scenes: the PNG/PGM image or ROS map_server YAML file, relative to this file.", Some("\"map.png\"")),
    ("maze", "cols", "Number of cell columns.", None),
    ("maze", "rows", "Number of cell rows.", None),
    ("maze", "cell_px", "Side of a square cell, px.", None),
    ("maze", "loops", "Fraction of the perfect maze's interior walls removed afterwards, 0 to 1 (0: perfect maze).", None),
    ("maze", "wall_thickness_px", "Wall thickness, px.", None),
    ("warehouse", "rack_pairs", "Pairs of rack rows (two racks back to back), bottom to top.", None),
    ("warehouse", "racks_per_row", "Racks along one row.", None),
    ("warehouse", "rack_length_px", "Length of a rack along its row, px.", None),
    ("warehouse", "rack_depth_px", "Depth of one rack (a pair is twice as deep), px.", None),
    ("warehouse", "aisle_px", "Width of the aisles, cross aisles and border aisle, px.", None),
    ("warehouse", "cross_aisle_every", "A cross aisle after every this many racks (0: none).", None),
    ("warehouse", "loading_px", "Depth of the free loading area along the bottom, px.", None),
    ("warehouse", "clutter", "Fraction of aisle spots holding a pallet, 0 to 1 (kept passable for the robot).", None),
    ("warehouse", "pallet_px", "Side of a square pallet, px.", None),
    ("warehouse", "wall_thickness_px", "Thickness of the outer walls, px.", None),
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
    ("episode", "safety_radius_px", "A step is near a moving obstacle when the gap to one is below this, px. Unset: two robot radii.", Some("10.0")),
    ("episode", "deadlock_steps", "Several robots: the episode ends as a deadlock when no robot has moved for this many steps.", None),
    ("team", "comm_range_px", "Several robots: range of each robot's broadcast (pose, goal, message), px.", None),
    ("team", "message_size", "Several robots: floats in the message a policy broadcasts each step (0: pose and goal only).", None),
    ("team", "neighbours", "Several robots: nearest senders in the observation, after the paper's values (0: the paper's observation).", None),
    ("observation", "history", "Frames a policy observes, newest first, then the last history - 1 actions (three values each: LEFT, AHEAD, RIGHT); 1: the paper's 18 values.", None),
    ("reward", "collision", "r_a: added on a step that collided.", None),
    ("reward", "progress_per_px", "r_b: per px of progress towards the goal (negative when moving away).", None),
    ("reward", "turn", "r_c: added on LEFT and RIGHT (scaled by |w| / w_max for continuous actions).", None),
    ("reward", "success", "r_d: added on reaching the goal.", None),
    ("reward", "shaping", "How progress is paid to a learner: \"none\" (r_b, the paper's) or \"geodesic\" (r_b replaced by F = gamma Phi(s') - Phi(s), Phi = -progress_per_px x geodesic distance to the goal, 0 once an episode ends other than by a time-out: keeps the optimal policy, pays nothing for dead ends; episodes.csv keeps the paper's return).", None),
    ("reward", "shaping_gamma", "gamma of the geodesic shaping term; the learner's discount keeps its optimal policy exactly (ronap train dqn sets it to its --gamma unless --shaping-gamma is given).", None),
    ("apf", "gravity_gain", "APF policy: attraction gain xi, per px^2.", None),
    ("apf", "repulsion_gain", "APF policy: repulsion gain eta, px^2.", None),
    ("apf", "influence_px", "APF policy: distance d0 beyond which obstacles do not repel, px.", None),
    ("apf", "lattice_px", "APF policy: spacing of the positions the descent steps between, px.", None),
    ("apf", "repel_moving", "APF policy: also steer away from the moving obstacles within laser range.", None),
];

/// Every field of a `[[moving]]` entry and what it means.
const MOVING_DOCS: &[(&str, &str)] = &[
    ("count", "How many obstacles this entry makes."),
    (
        "shape",
        "\"disc\" (radius_px) or \"box\" (size_px, axis-aligned).",
    ),
    ("radius_px", "Disc radius, px."),
    ("size_px", "Box width and height, px."),
    (
        "start",
        "Fixed start of the centre [x, y], px. Unset: drawn in free space from the seed.",
    ),
    (
        "motion",
        "\"still\", \"linear\", \"waypoints\", \"random_walk\" or \"appear\".",
    ),
    ("speed_px", "Distance moved per step, px."),
    (
        "direction_deg",
        "linear: direction of travel, degrees. Unset: drawn from the seed.",
    ),
    (
        "turn_sigma_deg",
        "random_walk: standard deviation of the heading change per step, degrees.",
    ),
    (
        "points",
        "waypoints: the points patrolled [[x, y], ...], px.",
    ),
    ("mode", "waypoints: \"loop\" or \"ping_pong\"."),
    ("from_step", "appear: earliest step of appearance."),
    ("to_step", "appear: latest step of appearance."),
    (
        "min_robot_distance_px",
        "Least gap to the robot where the obstacle starts or appears, px.",
    ),
    (
        "then",
        "appear: how it moves once there: \"still\", \"linear\" or \"random_walk\".",
    ),
];

/// Every field of a `[[robots]]` entry and what it means.
const ROBOTS_DOCS: &[(&str, &str)] = &[
    ("count", "How many robots this entry makes."),
    (
        "start",
        "Fixed start pose [x px, y px, heading deg] (count 1). Unset: drawn from the seed.",
    ),
    (
        "goal",
        "Fixed goal [x, y], px (count 1). Unset: drawn from the seed.",
    ),
    (
        "policy",
        "The policy that drives them (any --policy name). Unset: the run's.",
    ),
    ("radius_px", "Disc radius, px. Unset: robot.radius_px."),
    (
        "move_speed_px",
        "Distance of one AHEAD step, px. Unset: robot.move_speed_px.",
    ),
    (
        "turn_speed_deg",
        "Heading change of LEFT / RIGHT, degrees. Unset: robot.turn_speed_deg.",
    ),
    ("laser_beams", "Laser beams. Unset: laser.beams."),
    ("laser_range_px", "Laser range, px. Unset: laser.range_px."),
    (
        "laser_fov_deg",
        "Laser field of view, degrees. Unset: laser.fov_deg.",
    ),
    (
        "on_arrival",
        "On reaching the (last) goal: \"stay\" (an obstacle there) or \"vanish\" (leave the scene).",
    ),
    (
        "goals",
        "Fixed goals [[x, y], ...] visited one after the other (count 1). Unset: goal_count drawn.",
    ),
    ("goal_count", "Goals drawn from the seed, visited one after the other."),
    (
        "order",
        "Visiting order: \"given\", \"nearest\" (greedy, geodesic) or \"optimal\" (shortest tour).",
    ),
];

fn commented(block: &str) -> String {
    block.lines().map(|l| format!("# {l}\n")).collect()
}

impl SimConfig {
    /// The configuration as TOML with a comment on every field (meaning and unit), ready to copy
    /// and edit. Unset optional fields appear commented out with an example value; with no static
    /// or moving obstacles, an example of each appears commented out.
    pub fn to_documented_toml(&self) -> String {
        let mut out = String::from(
            "# ronap scenario: everything about a task (scene, robot, laser, episode, reward, static\n\
             # and moving obstacles). Pass it with --scenario FILE.toml (flags override it), or to\n\
             # ronap.NavEnv(scenario=...). Units: px (scene pixels, x right, y up) and degrees\n\
             # (counter-clockwise from +x).\n",
        );
        let mut value =
            toml::Value::try_from(self).unwrap_or(toml::Value::Table(Default::default()));
        // [team] is left out of written configurations when it has its defaults: show them here.
        if let (Some(table), Ok(team)) = (value.as_table_mut(), toml::Value::try_from(&self.team)) {
            table.entry("team").or_insert(team);
        }
        // So are [observation] and reward shaping.
        if let (Some(table), Ok(observation)) = (
            value.as_table_mut(),
            toml::Value::try_from(&self.observation),
        ) {
            table.entry("observation").or_insert(observation);
        }
        if let Some(reward) = value.get_mut("reward").and_then(|r| r.as_table_mut()) {
            if let Ok(kind) = toml::Value::try_from(self.reward.shaping) {
                reward.entry("shaping").or_insert(kind);
            }
            reward
                .entry("shaping_gamma")
                .or_insert(toml::Value::Float(self.reward.shaping_gamma));
        }
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
        out.push_str(
            "\n# Static obstacles added to the scene, any number: shape = \"box\" (min, max corners),\n\
             # \"disc\" (center, radius_px) or \"polygon\" (points: the corners of a convex polygon).\n",
        );
        let obstacles = value.get("obstacles").and_then(|v| v.as_array());
        match obstacles.filter(|a| !a.is_empty()) {
            Some(list) => {
                for o in list {
                    out.push_str("[[obstacles]]\n");
                    out.push_str(&inline_fields(o));
                }
            }
            None => out.push_str(&commented(
                "[[obstacles]]\nshape = \"disc\"\ncenter = [500.0, 500.0]\nradius_px = 20.0\n",
            )),
        }
        out.push_str(
            "\n# Moving obstacles, any number of entries; each makes `count` obstacles alike. They\n\
             # move first in each step, then the robot; contact either way is a dynamic collision.\n",
        );
        let moving = value.get("moving").and_then(|v| v.as_array());
        match moving.filter(|a| !a.is_empty()) {
            Some(list) => {
                for m in list {
                    out.push_str("[[moving]]\n");
                    for &(field, doc) in MOVING_DOCS {
                        out.push_str(&format!("# {doc}\n"));
                        match m.get(field) {
                            Some(v) => out.push_str(&format!("{field} = {v}\n")),
                            None => out.push_str(&format!("# {field} = ...\n")),
                        }
                    }
                }
            }
            None => out.push_str(&commented(
                "[[moving]]\ncount = 5\nshape = \"disc\"\nradius_px = 8.0\nmotion = \"random_walk\"\nspeed_px = 2.0\n",
            )),
        }
        out.push_str(
            "\n# Several robots, any number of entries; each makes `count` robots alike, and a field\n\
             # left out takes [robot]'s, [laser]'s or [episode]'s value. All robots act at once;\n\
             # robots whose motions would touch stay where they were (a robot collision).\n",
        );
        let robots = value.get("robots").and_then(|v| v.as_array());
        match robots.filter(|a| !a.is_empty()) {
            Some(list) => {
                for r in list {
                    out.push_str("[[robots]]\n");
                    for &(field, doc) in ROBOTS_DOCS {
                        out.push_str(&format!("# {doc}\n"));
                        match r.get(field) {
                            Some(v) => out.push_str(&format!("{field} = {v}\n")),
                            None => out.push_str(&format!("# {field} = ...\n")),
                        }
                    }
                }
            }
            None => out.push_str(&commented(
                "[[robots]]\ncount = 4\npolicy = \"geodesic\"\non_arrival = \"stay\"\n",
            )),
        }
        out
    }

    /// A scenario that shows every kind of entry: the default maze with a pillar, a rotated
    /// shelf, crossing walkers, a patrol, a linear mover and obstacles that appear mid-episode.
    pub fn example_scenario() -> Self {
        let obstacles = vec![
            ObstacleConfig::Disc {
                center: [450.0, 450.0],
                radius_px: 12.0,
            },
            ObstacleConfig::Polygon {
                points: vec![
                    [620.0, 300.0],
                    [660.0, 320.0],
                    [650.0, 340.0],
                    [610.0, 320.0],
                ],
            },
        ];
        let moving = vec![
            MovingConfig {
                count: 4,
                ..MovingConfig::default()
            },
            MovingConfig {
                shape: MovingShape::Box,
                motion: MotionKind::Waypoints,
                points: vec![[150.0, 850.0], [850.0, 850.0]],
                mode: Patrol::PingPong,
                speed_px: 3.0,
                ..MovingConfig::default()
            },
            MovingConfig {
                motion: MotionKind::Linear,
                direction_deg: Some(45.0),
                ..MovingConfig::default()
            },
            MovingConfig {
                count: 2,
                motion: MotionKind::Appear,
                from_step: 20,
                to_step: 100,
                ..MovingConfig::default()
            },
        ];
        Self {
            obstacles,
            moving,
            ..Self::default()
        }
    }
}

/// The fields of one array-of-tables entry as `key = value` lines.
fn inline_fields(entry: &toml::Value) -> String {
    entry
        .as_table()
        .map(|t| t.iter().map(|(k, v)| format!("{k} = {v}\n")).collect())
        .unwrap_or_default()
}

/// A configuration or scenario file as read: its path and text, for naming lines in errors.
#[derive(Clone, Debug)]
pub struct ConfigFile {
    path: std::path::PathBuf,
    text: String,
}

impl ConfigFile {
    /// Reads `path` (not yet parsed).
    pub fn read(path: &std::path::Path) -> Result<Self, ConfigError> {
        let text =
            crate::bounded::read_to_string(path, crate::bounded::TEXT_LIMIT).map_err(|e| {
                ConfigError::File {
                    path: path.to_path_buf(),
                    line: None,
                    message: format!("cannot read: {e}"),
                }
            })?;
        Ok(Self {
            path: path.to_path_buf(),
            text,
        })
    }

    /// A file of `text` said to be at `path` (for text that did not come from disk).
    pub fn from_text(path: &std::path::Path, text: String) -> Self {
        Self {
            path: path.to_path_buf(),
            text,
        }
    }

    /// The file.
    pub fn path(&self) -> &std::path::Path {
        &self.path
    }

    /// The configuration the file sets (unset fields keep their defaults), with a map scene's
    /// file made relative to the directory of this file. An unknown key or a wrong type is an
    /// error naming the file, line, key and value.
    pub fn parse(&self) -> Result<SimConfig, ConfigError> {
        let mut config: SimConfig = toml::from_str(&self.text).map_err(|e| {
            let message = e.message().trim().replace('\n', " ");
            let line = e.span().map(|span| {
                self.text[..span.start.min(self.text.len())]
                    .matches('\n')
                    .count()
                    + 1
            });
            let quoted = line
                .and_then(|l| self.text.lines().nth(l - 1))
                .map(|t| format!("`{}`: ", t.trim()))
                .unwrap_or_default();
            ConfigError::File {
                path: self.path.clone(),
                line,
                message: format!("{quoted}{message}"),
            }
        })?;
        if let Some(file) = &mut config.scene.file {
            if file.is_relative() {
                if let Some(dir) = self.path.parent() {
                    *file = dir.join(&*file);
                }
            }
        }
        Ok(config)
    }

    /// `error` from validating a configuration read from this file, with the file and the line
    /// of the offending key when the file sets it (a value from a flag has no line here).
    pub fn locate(&self, error: ConfigError) -> ConfigError {
        let ConfigError::OutOfRange { field, .. } = &error else {
            return error;
        };
        match key_line(&self.text, field) {
            Some(line) => ConfigError::File {
                path: self.path.clone(),
                line: Some(line),
                message: error.to_string(),
            },
            None => error,
        }
    }
}

/// The line (from 1) where `field` (`laser.beams`, `moving[2].speed_px`, `scene.file`) is set in
/// TOML `text` written with `[section]` / `[[array]]` headers, if it is.
pub fn key_line(text: &str, field: &str) -> Option<usize> {
    let (table, key) = field.split_once('.').unwrap_or((field, ""));
    let (name, index) = match table.split_once('[') {
        Some((n, rest)) => (n, rest.trim_end_matches(']').parse::<usize>().ok()),
        None => (table, None),
    };
    let mut current = String::new();
    let mut counts: std::collections::HashMap<String, usize> = Default::default();
    let mut current_index = None;
    for (i, raw) in text.lines().enumerate() {
        let line = raw.split('#').next().unwrap_or("").trim();
        if let Some(h) = line.strip_prefix("[[").and_then(|l| l.strip_suffix("]]")) {
            let h = h.trim().to_string();
            let n = counts.entry(h.clone()).or_insert(0);
            current_index = Some(*n);
            *n += 1;
            if key.is_empty() && h == name && (index.is_none() || index == current_index) {
                return Some(i + 1);
            }
            current = h;
            continue;
        }
        if let Some(h) = line.strip_prefix('[').and_then(|l| l.strip_suffix(']')) {
            current = h.trim().to_string();
            current_index = None;
            continue;
        }
        let Some((k, _)) = line.split_once('=') else {
            continue;
        };
        let k = k.trim();
        let here = current == name && (index.is_none() || index == current_index);
        if here && k == key {
            return Some(i + 1);
        }
        // A dotted key at the top level: `laser.beams = 9`.
        if current.is_empty() && index.is_none() && k == field {
            return Some(i + 1);
        }
    }
    None
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
        c.episode.safety_radius_px = Some(3.0);
        c.scene.seed = Some(1);
        c.scene.file = Some("m.png".into());
        c.team.neighbours = 1;
        c.observation.history = 2;
        c.reward.shaping = Shaping::Geodesic;
        c.reward.shaping_gamma = 0.9;
        let full = toml::Value::try_from(&c).unwrap();
        let mut count = 0;
        for (sec, table) in full.as_table().unwrap() {
            let Some(table) = table.as_table() else {
                continue;
            };
            for field in table.keys() {
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
