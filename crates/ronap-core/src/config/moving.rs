//! Moving and appearing obstacles (docs/model.md "Moving obstacles"): each `[[moving]]` entry's
//! shape, start and motion, with its defaults and checks.

use crate::config::{check, finite, length, point, steps, ConfigError, Forces};
use serde::{Deserialize, Serialize};

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
    /// A pedestrian with a goal that avoids the others by Optimal Reciprocal Collision
    /// Avoidance (docs/model.md "Crowds that react").
    Orca,
    /// A pedestrian with a goal pushed by the social force model (docs/model.md "Crowds that
    /// react").
    SocialForce,
}

impl MotionKind {
    /// Whether it is a reactive pedestrian's (`orca`, `social_force`): a goal, a preferred
    /// speed, seeing the others.
    pub fn is_reactive(self) -> bool {
        matches!(self, MotionKind::Orca | MotionKind::SocialForce)
    }

    /// The name a TOML file gives it.
    pub fn name(self) -> &'static str {
        match self {
            MotionKind::Still => "still",
            MotionKind::Linear => "linear",
            MotionKind::Waypoints => "waypoints",
            MotionKind::RandomWalk => "random_walk",
            MotionKind::Appear => "appear",
            MotionKind::Orca => "orca",
            MotionKind::SocialForce => "social_force",
        }
    }
}

/// What a reactive pedestrian does at its goal.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Arrival {
    /// Stops there (and still gives way).
    #[default]
    Stay,
    /// Walks on to a new goal drawn in free space.
    NewGoal,
    /// Leaves the scene.
    Vanish,
}

impl Arrival {
    fn is_stay(&self) -> bool {
        *self == Arrival::Stay
    }
}

/// Where a crowd's pedestrians start and head (CrowdNav's crossings).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Pattern {
    /// On a circle of `pattern_radius_px` round `pattern_center`, at angles drawn from the seed,
    /// heading for the opposite point.
    Circle,
    /// On one side of a square of half side `pattern_radius_px` round `pattern_center` (left or
    /// right, drawn), heading for a point drawn on the opposite side.
    Square,
    /// Start and goal drawn in free space (as with no pattern).
    Random,
}

/// How a reactive (`orca`) pedestrian avoids: RVO2's agent settings, in steps and px.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct AgentOrca {
    /// Steps over which its velocity keeps clear of other agents. Default 20 (CrowdNav's 5 s at
    /// 0.25 s a step).
    pub time_horizon_steps: f64,
    /// Steps over which its velocity keeps clear of still obstacles. Default 20.
    pub obstacle_time_horizon_steps: f64,
    /// How far it looks for other agents, px. Default 200 (CrowdNav's 10 m).
    pub neighbour_dist_px: f64,
    /// Most agents it avoids at once (the nearest). Default 10.
    pub max_neighbours: u32,
    /// Added to its radius (and to the other agents') in ORCA, px: in a dense crossing ORCA's
    /// linear program can have no solution and agents would overlap by a fraction of a px.
    /// Default 1.
    pub safety_margin_px: f64,
}

impl Default for AgentOrca {
    fn default() -> Self {
        Self {
            time_horizon_steps: 20.0,
            obstacle_time_horizon_steps: 20.0,
            neighbour_dist_px: 200.0,
            max_neighbours: 10,
            safety_margin_px: 1.0,
        }
    }
}

impl AgentOrca {
    pub(super) fn is_default(&self) -> bool {
        *self == Self::default()
    }
}

/// A pattern as a TOML file writes it.
fn pattern_name(p: Option<Pattern>) -> String {
    match p {
        Some(Pattern::Circle) => "\"circle\"".into(),
        Some(Pattern::Square) => "\"square\"".into(),
        Some(Pattern::Random) => "\"random\"".into(),
        None => String::new(),
    }
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
    /// `orca`, `social_force`: fixed goal `[x, y]`, px. Default: from `pattern`, else drawn in free space.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub goal: Option<[f64; 2]>,
    /// `orca`, `social_force`: largest speed, px per step (`speed_px` is the preferred one). Default `speed_px`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_speed_px: Option<f64>,
    /// `orca`, `social_force`: at its goal `stay` (default), `new_goal` or `vanish`.
    #[serde(skip_serializing_if = "Arrival::is_stay")]
    pub on_arrival: Arrival,
    /// `orca`, `social_force`: whether it avoids the robots too. Default false (CrowdNav's invisible robot: it
    /// walks into a robot that does not give way).
    #[serde(skip_serializing_if = "super::is_false")]
    pub sees_robots: bool,
    /// `orca`, `social_force`: place start and goal by a crowd pattern, `circle`, `square` or `random`. Default: drawn.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pattern: Option<Pattern>,
    /// The pattern's centre `[x, y]`, px. Default: the scene's centre.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pattern_center: Option<[f64; 2]>,
    /// The circle's radius, or the square's half side, px.
    #[serde(skip_serializing_if = "super::is_zero")]
    pub pattern_radius_px: f64,
    /// A pattern's start and goal move by up to this much in x and y, px (uniform). Default 0.
    #[serde(skip_serializing_if = "super::is_zero")]
    pub jitter_px: f64,
    /// `orca`: how it avoids.
    #[serde(skip_serializing_if = "AgentOrca::is_default")]
    pub orca: AgentOrca,
    /// `social_force`: its forces.
    #[serde(skip_serializing_if = "Forces::is_default")]
    pub social_force: Forces,
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
            goal: None,
            max_speed_px: None,
            on_arrival: Arrival::Stay,
            sees_robots: false,
            pattern: None,
            pattern_center: None,
            pattern_radius_px: 0.0,
            jitter_px: 0.0,
            orca: AgentOrca::default(),
            social_force: Forces::default(),
        }
    }
}

/// The paper's maze with the 20 wandering pedestrians of `scenarios/maze-pedestrians.toml`
/// (discs of 6 px at 1.5 px a step, turning by N(0, 20 deg^2)), for tests.
#[cfg(test)]
pub(crate) fn maze_pedestrians() -> super::SimConfig {
    super::SimConfig {
        moving: vec![MovingConfig {
            count: 20,
            radius_px: 6.0,
            motion: MotionKind::RandomWalk,
            speed_px: 1.5,
            turn_sigma_deg: 20.0,
            ..Default::default()
        }],
        ..Default::default()
    }
}

/// Most moving obstacles a configuration may ask for.
pub const MAX_MOVING: u32 = 10_000;

/// Checks every `[[moving]]` entry (`moving[i]`) and their total, naming the first field out of
/// range.
pub(super) fn validate_moving(moving: &[MovingConfig]) -> Result<(), ConfigError> {
    for (i, m) in moving.iter().enumerate() {
        validate_entry(m, &|name: &str| format!("moving[{i}].{name}"))?;
    }
    Ok(())
}

/// Checks that `moving` (every entry, crowds included) makes at most [`MAX_MOVING`] obstacles.
pub(super) fn validate_total(moving: &[MovingConfig]) -> Result<(), ConfigError> {
    let total: u64 = moving.iter().map(|m| u64::from(m.count)).sum();
    check(
        total <= u64::from(MAX_MOVING),
        "moving",
        total,
        "at most 10000 moving obstacles in all",
    )
}

/// Checks one entry, naming its fields by `f` (`moving[2].speed_px`, `crowd[0].speed_px`).
pub(super) fn validate_entry(
    m: &MovingConfig,
    f: &dyn Fn(&str) -> String,
) -> Result<(), ConfigError> {
    check(
        (1..=MAX_MOVING).contains(&m.count),
        &f("count"),
        m.count,
        "must be between 1 and 10000",
    )?;
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
    check(
        !m.then.is_reactive(),
        &f("then"),
        format!("{:?}", m.then.name()),
        "an appearing obstacle moves as still, linear or random_walk",
    )?;
    if let Some(g) = m.goal {
        point(&f("goal"), g)?;
    }
    if let Some(v) = m.max_speed_px {
        length(&f("max_speed_px"), v, true)?;
    }
    if let Some(c) = m.pattern_center {
        point(&f("pattern_center"), c)?;
    }
    length(&f("pattern_radius_px"), m.pattern_radius_px, true)?;
    check(
        matches!(m.pattern, None | Some(Pattern::Random)) || m.pattern_radius_px > 0.0,
        &f("pattern"),
        pattern_name(m.pattern),
        "a crowd pattern needs a positive pattern_radius_px",
    )?;
    check(
        m.pattern.is_none() || m.motion.is_reactive(),
        &f("pattern"),
        pattern_name(m.pattern),
        "crowd patterns place pedestrians (motion = \"orca\" or \"social_force\")",
    )?;
    length(&f("jitter_px"), m.jitter_px, true)?;
    let o = &m.orca;
    steps(&f("orca.time_horizon_steps"), o.time_horizon_steps)?;
    steps(
        &f("orca.obstacle_time_horizon_steps"),
        o.obstacle_time_horizon_steps,
    )?;
    length(&f("orca.neighbour_dist_px"), o.neighbour_dist_px, true)?;
    length(&f("orca.safety_margin_px"), o.safety_margin_px, true)?;
    check(
        o.max_neighbours <= 1000,
        &f("orca.max_neighbours"),
        o.max_neighbours,
        "must be between 0 and 1000",
    )?;
    m.social_force.validate(&f("social_force"))?;
    Ok(())
}
