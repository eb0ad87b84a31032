//! A team run's rows: `episodes.csv` (a row per team episode) and `robots.csv` (a row per robot
//! of each), their columns, and the writers of whole files.

use crate::eval::metric::{self, Kind};
use crate::eval::{EpisodeRecord, InTeam, Outcome, TeamRecord};
use crate::io::run_dir::{joined, metric_cells, start_goal_cells, START_GOAL_COLUMNS};

/// Columns of a team run's `episodes.csv` (one row per team episode).
pub const TEAM_COLUMNS: [&str; 11] = [
    "seed",
    "outcome",
    "robots",
    "arrived",
    "steps",
    "makespan",
    "path_length_px",
    "collisions",
    "robot_collisions",
    "deadlock",
    "reason",
];

/// The team `episodes.csv` row of `r` (its `reason` empty when [`TeamRecord::reason`] has none).
pub fn team_episode_row(r: &TeamRecord) -> Vec<String> {
    vec![
        r.seed.to_string(),
        r.outcome.name().to_string(),
        r.robots.len().to_string(),
        r.robots
            .iter()
            .filter(|x| x.outcome == Outcome::Success)
            .count()
            .to_string(),
        r.steps.to_string(),
        r.makespan.map_or(String::new(), |m| m.to_string()),
        format!("{:.3}", r.path_length_px),
        r.collisions.to_string(),
        r.robot_collisions.to_string(),
        r.deadlock.to_string(),
        r.reason().unwrap_or_default().to_string(),
    ]
}

/// Columns of a team run's `robots.csv` (one row per robot per episode).
pub const ROBOT_COLUMNS: [&str; 26] = joined::<24, 2, 26>(
    joined::<18, 6, 24>(
        [
            "seed",
            "robot",
            "policy",
            "outcome",
            "steps",
            "arrived_at",
            "collisions",
            "robot_collisions",
            "dynamic_collisions",
            "goals",
            "goals_reached",
            "tour_px",
            "given_tour_px",
            "nearest_tour_px",
            "optimal_tour_px",
            "path_length_px",
            "shortest_px",
            "spl",
        ],
        START_GOAL_COLUMNS,
    ),
    ["lower_bound_steps", "waiting_steps"],
);

/// The columns of `robots.csv` measuring the metrics of `kinds`: `ROBOT_COLUMNS`, then one
/// per metric.
pub fn robot_columns(kinds: &[Kind]) -> Vec<String> {
    ROBOT_COLUMNS
        .iter()
        .map(|c| c.to_string())
        .chain(metric::columns(kinds).map(|c| c.name.to_string()))
        .collect()
}

/// The `robots.csv` rows of `r`: one per robot, with the metrics of `kinds`.
pub fn robot_rows(r: &TeamRecord, kinds: &[Kind]) -> Vec<Vec<String>> {
    r.robots.iter().map(|x| robot_row(x, kinds)).collect()
}

/// The `robots.csv` row of robot record `x`, with the metrics of `kinds` (every robot of a
/// [`TeamRecord`] has its [`InTeam`]; a record without one would get the default's cells).
fn robot_row(x: &EpisodeRecord, kinds: &[Kind]) -> Vec<String> {
    let lone = InTeam::default();
    let t = x.team.as_ref().unwrap_or(&lone);
    let mut row = vec![
        x.seed.to_string(),
        t.robot.to_string(),
        t.policy.clone(),
        x.outcome.name().to_string(),
        x.steps.to_string(),
        t.arrived_at.map_or(String::new(), |a| a.to_string()),
        x.collisions.to_string(),
        t.robot_collisions.to_string(),
        x.dynamic
            .map_or(String::new(), |d| d.collisions.to_string()),
        t.goals.to_string(),
        t.goals_reached.to_string(),
        t.tour
            .map_or(String::new(), |t| format!("{:.3}", t.chosen_px())),
        t.tour.map_or(String::new(), |t| format!("{:.3}", t.given)),
        t.tour
            .map_or(String::new(), |t| format!("{:.3}", t.nearest)),
        t.tour
            .map_or(String::new(), |t| format!("{:.3}", t.optimal)),
        format!("{:.3}", x.path_length_px),
        x.shortest_px.map_or(String::new(), |l| format!("{l:.3}")),
        format!("{:.4}", x.spl),
    ];
    row.extend(start_goal_cells(x.start, x.goal, x.reason.as_deref()));
    row.push(t.lower_bound_steps.map_or(String::new(), |b| b.to_string()));
    row.push(t.waiting_steps.to_string());
    row.extend(metric_cells(kinds, &x.metrics));
    row
}
