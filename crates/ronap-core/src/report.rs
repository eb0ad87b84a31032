//! What an evaluation writes: `episodes.csv`, `timing.csv`, per-step logs in the data-log format,
//! and trajectory pictures like the paper's Figures 7-9.
//!
//! Everything here is deterministic given the records except `timing.csv`, which holds the wall
//! times, so `episodes.csv` is byte-identical whatever the thread count.

use crate::evaluate::{action_name, EpisodeRecord};
use crate::render::{Canvas, GOAL, PATH, START};
use crate::robot::{Action, DiscreteAction, Pose};
use std::io::Write;
use std::path::{Path, PathBuf};

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

/// One row of a step log, read back: what replaying it needs.
#[derive(Clone, Debug, PartialEq)]
pub struct LoggedStep {
    /// The episode seed.
    pub seed: u64,
    /// The step number, from 1.
    pub step: u32,
    /// The pose the action was taken in.
    pub pose: Pose,
    /// The action.
    pub action: Action,
}

/// A step log that cannot be read back.
#[derive(Debug, thiserror::Error)]
#[error("{}{}: {message}", path.display(), line.map_or(String::new(), |l| format!(", line {l}")))]
pub struct StepsError {
    /// The file.
    pub path: PathBuf,
    /// The line (1 is the header), when one line is at fault.
    pub line: Option<u64>,
    /// What is wrong.
    pub message: String,
}

/// Parses an action as the logs write it: `LEFT`, `AHEAD`, `RIGHT` or `v=..;w=..`.
pub fn parse_action(text: &str) -> Result<Action, String> {
    if let Some(rest) = text.strip_prefix("v=") {
        let (v, w) = rest
            .split_once(";w=")
            .ok_or_else(|| format!("{text:?}: expected v=SPEED;w=TURN"))?;
        let number = |s: &str| {
            s.parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| format!("{text:?}: {s:?} is not a finite number"))
        };
        return Ok(Action::Continuous {
            v: number(v)?,
            w_deg: number(w)?,
        });
    }
    text.parse::<DiscreteAction>().map(Action::from)
}

/// Reads a step log ([`write_steps`]; the heading may also be a `heading` column, as in data
/// logs): one episode's consecutive steps, numbered from 1. Extra columns are ignored.
pub fn read_steps(path: &Path) -> Result<Vec<LoggedStep>, StepsError> {
    let error = |line: Option<u64>, message: String| StepsError {
        path: path.to_path_buf(),
        line,
        message,
    };
    let mut reader = csv::Reader::from_path(path).map_err(|e| error(None, e.to_string()))?;
    let header = reader
        .headers()
        .map_err(|e| error(Some(1), e.to_string()))?
        .clone();
    let column = |names: &[&str]| {
        header
            .iter()
            .position(|h| names.contains(&h))
            .ok_or_else(|| {
                error(
                    Some(1),
                    format!(
                        "no `{}` column: not a step log (ronap run --log-steps writes them)",
                        names[0]
                    ),
                )
            })
    };
    let (seed_at, step_at, x_at, y_at, z_at, action_at) = (
        column(&["seed"])?,
        column(&["step"])?,
        column(&["x"])?,
        column(&["y"])?,
        column(&["z", "heading"])?,
        column(&["action"])?,
    );
    let mut steps: Vec<LoggedStep> = Vec::new();
    for record in reader.records() {
        let record = record.map_err(|e| {
            let line = e.position().map(|p| p.line());
            error(line, e.to_string())
        })?;
        let line = record.position().map_or(0, |p| p.line());
        let field = |at: usize, name: &str| {
            record
                .get(at)
                .ok_or_else(|| error(Some(line), format!("no `{name}` value")))
        };
        let number = |at: usize, name: &str| -> Result<f64, StepsError> {
            let text = field(at, name)?;
            text.parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| error(Some(line), format!("{name} {text:?} is not a number")))
        };
        let seed = field(seed_at, "seed")?
            .parse::<u64>()
            .map_err(|_| error(Some(line), "seed is not a whole number".into()))?;
        let step = field(step_at, "step")?
            .parse::<u32>()
            .map_err(|_| error(Some(line), "step is not a whole number".into()))?;
        let action = parse_action(field(action_at, "action")?).map_err(|m| error(Some(line), m))?;
        let pose = Pose::new(number(x_at, "x")?, number(y_at, "y")?, number(z_at, "z")?);
        if let Some(first) = steps.first() {
            if seed != first.seed {
                return Err(error(
                    Some(line),
                    format!("seed {seed} after seed {}: one episode per log", first.seed),
                ));
            }
        }
        let expected = steps.len() as u32 + 1;
        if step != expected {
            return Err(error(
                Some(line),
                format!("step {step} where step {expected} was due: the steps must be consecutive from 1"),
            ));
        }
        steps.push(LoggedStep {
            seed,
            step,
            pose,
            action,
        });
    }
    Ok(steps)
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::evaluate::{Evaluator, Recording, Scenes};
    use crate::policy::{Builtin, PolicyFactory};

    #[test]
    fn step_logs_read_back_as_written() {
        let evaluator = Evaluator::new(Default::default(), Scenes::MazePerSeed);
        let mut policy = Builtin::Random.make().unwrap();
        let recording = Recording {
            trajectory: false,
            steps: true,
        };
        let mut record = evaluator
            .run_episode(policy.as_mut(), 4, recording)
            .unwrap();
        record.step_log.truncate(30);
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("steps.csv");
        crate::output::write_atomic(&path, |out| write_steps(&record, out)).unwrap();
        let steps = read_steps(&path).unwrap();
        assert_eq!(steps.len(), 30);
        for (read, logged) in steps.iter().zip(&record.step_log) {
            assert_eq!(
                (read.seed, read.step, read.action),
                (4, logged.step, logged.action)
            );
            assert!((read.pose.x - logged.pose.x).abs() < 5e-4);
            assert!((read.pose.z_deg - logged.pose.z_deg).abs() < 5e-4);
        }
    }

    #[test]
    fn bad_step_logs_are_named_by_file_and_line() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("s.csv");
        let check = |text: &str, expected: &str| {
            std::fs::write(&path, text).unwrap();
            let e = read_steps(&path).unwrap_err().to_string();
            assert!(e.starts_with(&path.display().to_string()), "{e}");
            assert!(e.contains(expected), "{e:?} lacks {expected:?}");
        };
        check("seed,step,x,y,action\n", "line 1: no `z` column");
        check(
            "seed,step,x,y,z,action\n1,1,2,3,4,AHEAD\n1,3,2,3,4,LEFT\n",
            "line 3: step 3 where step 2 was due",
        );
        check(
            "seed,step,x,y,z,action\n1,1,2,3,4,JUMP\n",
            "line 2: unknown action \"JUMP\"",
        );
        check(
            "seed,step,x,y,z,action\n1,1,two,3,4,LEFT\n",
            "line 2: x \"two\" is not a number",
        );
        check(
            "seed,step,x,y,z,action\n1,1,2,3,4,LEFT\n2,2,2,3,4,LEFT\n",
            "line 3: seed 2 after seed 1",
        );
        let e = read_steps(&dir.path().join("none.csv")).unwrap_err();
        assert!(e.to_string().contains("none.csv"), "{e}");
        assert_eq!(
            parse_action("v=1.5;w=-3").unwrap(),
            Action::Continuous {
                v: 1.5,
                w_deg: -3.0
            }
        );
    }
}
