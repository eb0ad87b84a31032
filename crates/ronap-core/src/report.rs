//! What an evaluation writes: `episodes.csv`, `timing.csv`, per-step logs in the data-log format,
//! and trajectory pictures like the paper's Figures 7-9.
//!
//! Everything here is deterministic given the records except `timing.csv`, which holds the wall
//! times, so `episodes.csv` is byte-identical whatever the thread count.

use crate::evaluate::{action_name, EpisodeRecord};
use crate::render::{Canvas, GOAL, PATH, START};
use std::io::Write;

/// Which episodes get a trajectory picture.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pictures {
    /// The first N seeds of the range.
    First(u64),
    /// Every episode that did not succeed.
    Failures,
    /// Every episode.
    All,
}

impl std::str::FromStr for Pictures {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "failures" => Ok(Self::Failures),
            "all" => Ok(Self::All),
            n => n
                .parse()
                .map(Self::First)
                .map_err(|_| format!("{n:?}: expected a number, `failures` or `all`")),
        }
    }
}

impl Pictures {
    /// Whether `record` gets a picture, in a run whose seeds start at `first_seed`.
    pub fn wants(self, record: &EpisodeRecord, first_seed: u64) -> bool {
        match self {
            Pictures::All => true,
            Pictures::Failures => record.outcome != crate::evaluate::Outcome::Success,
            Pictures::First(n) => record.seed.wrapping_sub(first_seed) < n,
        }
    }
}

/// Columns of `episodes.csv`.
pub const EPISODE_COLUMNS: [&str; 14] = [
    "seed",
    "outcome",
    "steps",
    "collisions",
    "path_length_px",
    "shortest_px",
    "spl",
    "return",
    "start_x",
    "start_y",
    "start_heading_deg",
    "goal_x",
    "goal_y",
    "reason",
];

/// Writes `episodes.csv`: one row per record.
pub fn write_episodes(records: &[EpisodeRecord], out: &mut dyn Write) -> std::io::Result<()> {
    let mut w = csv::Writer::from_writer(out);
    w.write_record(EPISODE_COLUMNS)?;
    for r in records {
        w.write_record([
            r.seed.to_string(),
            r.outcome.name().to_string(),
            r.steps.to_string(),
            r.collisions.to_string(),
            format!("{:.3}", r.path_length_px),
            r.shortest_px.map_or(String::new(), |l| format!("{l:.3}")),
            format!("{:.4}", r.spl),
            format!("{:.4}", r.total_reward),
            format!("{:.3}", r.start.x),
            format!("{:.3}", r.start.y),
            format!("{:.3}", r.start.z_deg),
            format!("{:.3}", r.goal.x),
            format!("{:.3}", r.goal.y),
            r.reason.clone().unwrap_or_default(),
        ])?;
    }
    w.flush()
}

/// Writes `timing.csv`: each episode's wall time (setup, planning, stepping), milliseconds.
pub fn write_timing(records: &[EpisodeRecord], out: &mut dyn Write) -> std::io::Result<()> {
    let mut w = csv::Writer::from_writer(out);
    w.write_record(["seed", "wall_time_ms"])?;
    for r in records {
        w.write_record([r.seed.to_string(), format!("{:.3}", r.wall_time_s * 1000.0)])?;
    }
    w.flush()
}

/// Writes one episode's steps in the data-log format: `seed, step, x, y, z, d_1..d_m, theta, D,
/// direction, action, collided, reward`, the state being the one the action was taken in.
pub fn write_steps(record: &EpisodeRecord, out: &mut dyn Write) -> std::io::Result<()> {
    let mut w = csv::Writer::from_writer(out);
    let beams = record.last_readings.len();
    let mut header: Vec<String> = ["seed", "step", "x", "y", "z"].map(String::from).to_vec();
    header.extend((1..=beams).map(|i| format!("d_{i}")));
    header.extend(["theta", "D", "direction", "action", "collided", "reward"].map(String::from));
    w.write_record(&header)?;
    for s in &record.step_log {
        let mut row = vec![
            record.seed.to_string(),
            s.step.to_string(),
            format!("{:.3}", s.pose.x),
            format!("{:.3}", s.pose.y),
            format!("{:.3}", s.pose.z_deg),
        ];
        row.extend(s.readings.iter().map(|d| format!("{d:.3}")));
        row.extend([
            format!("{:.3}", s.bearing_deg),
            format!("{:.3}", s.distance_px),
            format!("{:.3}", s.direction_deg),
            action_name(&s.action),
            u8::from(s.collided).to_string(),
            format!("{:.4}", s.reward),
        ]);
        w.write_record(&row)?;
    }
    w.flush()
}

/// The picture of an episode: the whole scene, the path in blue, the start in red, the goal in
/// green, and the last laser scan in its colour classes. Needs the record's trajectory and world
/// (`None` once the record is stripped).
pub fn trajectory_image(record: &EpisodeRecord, scale: f64) -> Option<image::RgbImage> {
    let world = record.world.as_ref()?;
    let config = world.config();
    let mut canvas = Canvas::new(world.scene(), scale);
    let least = 4.0 / scale;
    canvas.fill_disc(
        record.goal,
        config.episode.goal_tolerance_px.max(least),
        GOAL,
    );
    let points: Vec<_> = record.trajectory.iter().map(|p| p.position()).collect();
    canvas.path(&points, 2.0, PATH);
    let laser = crate::lidar::Laser::new(&config.laser);
    canvas.scan(&laser, record.end, &record.last_readings);
    canvas.robot(record.start, config.robot.radius_px.max(least), START);
    canvas.robot(record.end, config.robot.radius_px.max(least), PATH);
    Some(canvas.into_image())
}

/// Writes a run's files into `dir`: `episodes.csv`, `timing.csv` and `summary.json`, the last
/// being `meta` (what was run: policy, seeds, scenes...) with the summary figures and the full
/// configuration added.
pub fn write_run(
    dir: &std::path::Path,
    mut meta: serde_json::Map<String, serde_json::Value>,
    config: &crate::config::ValidConfig,
    result: &crate::evaluate::RunResult,
    summary: &crate::summary::Summary,
) -> Result<(), crate::output::OutputError> {
    use crate::output::write_atomic;
    write_atomic(&dir.join("episodes.csv"), |out| {
        write_episodes(&result.records, out)
    })?;
    write_atomic(&dir.join("timing.csv"), |out| {
        write_timing(&result.records, out)
    })?;
    meta.insert("ronap_version".into(), env!("CARGO_PKG_VERSION").into());
    meta.insert("interrupted".into(), result.cancelled.into());
    meta.insert(
        "error".into(),
        result.error.as_ref().map(|e| e.to_string()).into(),
    );
    meta.insert(
        "summary".into(),
        serde_json::to_value(summary).unwrap_or_default(),
    );
    meta.insert(
        "config".into(),
        serde_json::to_value(config.as_sim_config()).unwrap_or_default(),
    );
    write_atomic(&dir.join("summary.json"), |out| {
        serde_json::to_writer_pretty(&mut *out, &meta)?;
        out.write_all(b"\n")
    })
}

/// Writes the per-episode files a record asks for: its trajectory picture (`png/`) and its step
/// log (`steps/`), each when `picture` / `steps` say so and the record holds what they need.
pub fn write_episode_files(
    dir: &std::path::Path,
    record: &EpisodeRecord,
    picture: bool,
    steps: bool,
) -> Result<(), crate::output::OutputError> {
    if picture {
        if let Some(img) = trajectory_image(record, 1.0) {
            let path = dir.join("png").join(format!(
                "seed-{:06}-{}.png",
                record.seed,
                record.outcome.name()
            ));
            crate::output::save_image(&path, &img)?;
        }
    }
    if steps {
        let path = dir
            .join("steps")
            .join(format!("seed-{:06}.csv", record.seed));
        crate::output::write_atomic(&path, |out| write_steps(record, out))?;
    }
    Ok(())
}
