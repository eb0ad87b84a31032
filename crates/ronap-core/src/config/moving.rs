//! Moving and appearing obstacles (docs/model.md "Moving obstacles"): each `[[moving]]` entry's
//! shape, start and motion, with its defaults and checks.

use crate::config::{check, finite, length, point, ConfigError};
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

/// Most moving obstacles a configuration may ask for.
pub const MAX_MOVING: u32 = 10_000;

/// Checks every `[[moving]]` entry (`moving[i]`) and their total, naming the first field out of
/// range.
pub(super) fn validate_moving(moving: &[MovingConfig]) -> Result<(), ConfigError> {
    let mut total = 0u64;
    for (i, m) in moving.iter().enumerate() {
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
    Ok(())
}
