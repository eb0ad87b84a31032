//! Several robots (docs/model.md "Several robots", "Multi-destination tasks"): the `[[robots]]`
//! entries with their goals and policies, and how the robots talk (`[team]`), with their defaults
//! and checks.

use crate::config::{check, finite, length, point, ConfigError, MAX_BEAMS};
use serde::{Deserialize, Serialize};

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
    /// Moves the fixed `start` and `goal` by up to this much in x and in y, px, uniformly, drawn
    /// from the episode seed's own jitter stream (so each seed poses the task a little apart and
    /// no other draw changes). Default 0.
    #[serde(skip_serializing_if = "super::is_zero")]
    pub jitter_px: f64,
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
            jitter_px: 0.0,
        }
    }
}

/// Most goals one robot visits.
pub const MAX_GOALS: u32 = 64;

/// Largest number of robots in a team.
pub const MAX_ROBOTS: u32 = 10_000;

impl TeamConfig {
    /// Checks the range and the sizes of messages and neighbour slots.
    pub(super) fn validate(&self) -> Result<(), ConfigError> {
        let t = self;
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
        )?;
        Ok(())
    }
}

/// Checks every `[[robots]]` entry (`robots[i]`) and their total, naming the first field out of
/// range.
pub(super) fn validate_robots(robots_config: &[TeamRobotConfig]) -> Result<(), ConfigError> {
    let mut robots = 0u64;
    for (i, r) in robots_config.iter().enumerate() {
        let f = |name: &str| format!("robots[{i}].{name}");
        check(
            (1..=MAX_ROBOTS).contains(&r.count),
            &f("count"),
            r.count,
            "must be between 1 and 10000",
        )?;
        robots += u64::from(r.count);
        length(&f("jitter_px"), r.jitter_px, true)?;
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
    Ok(())
}
