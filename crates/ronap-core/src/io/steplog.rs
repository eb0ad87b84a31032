//! Step logs (`ronap run --log-steps`): one episode's steps in the data-log format, written as
//! the episode ends and read back by `ronap replay`.

use crate::eval::{EpisodeRecord, StepLog};
use crate::sim::{Action, Pose};
use std::io::Write;
use std::path::{Path, PathBuf};

/// Writes one episode's steps in the data-log format: `seed, step, x, y, z, d_1..d_m, theta, D,
/// direction, action, collided, reward`, the state being the one the action was taken in.
pub fn write_steps(record: &EpisodeRecord, out: &mut dyn Write) -> std::io::Result<()> {
    write_step_log(
        record.seed,
        record.last_readings.len(),
        &record.step_log,
        out,
    )
}

/// Writes `steps` of the episode of `seed`, taken by a robot whose laser has `beams` beams, in
/// the data-log format of [`write_steps`].
fn write_step_log(
    seed: u64,
    beams: usize,
    steps: &[StepLog],
    out: &mut dyn Write,
) -> std::io::Result<()> {
    let mut w = csv::Writer::from_writer(out);
    let mut header: Vec<String> = ["seed", "step", "x", "y", "z"].map(String::from).to_vec();
    header.extend((1..=beams).map(|i| format!("d_{i}")));
    header.extend(["theta", "D", "direction", "action", "collided", "reward"].map(String::from));
    w.write_record(&header)?;
    for s in steps {
        let mut row = vec![
            seed.to_string(),
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
            s.action.to_string(),
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

/// Reads a step log (`write_steps`; the heading may also be a `heading` column, as in data
/// logs): one episode's consecutive steps, numbered from 1. Extra columns are ignored.
pub fn read_steps(path: &Path) -> Result<Vec<LoggedStep>, StepsError> {
    let file = crate::bounded::open_lines(path).map_err(|e| StepsError {
        path: path.to_path_buf(),
        line: None,
        message: e.to_string(),
    })?;
    parse_steps(file, path)
}

/// Parses a step log read from `input` ([`read_steps`]); `path` names it in errors.
pub fn parse_steps(input: impl std::io::Read, path: &Path) -> Result<Vec<LoggedStep>, StepsError> {
    let error = |line: Option<u64>, message: String| StepsError {
        path: path.to_path_buf(),
        line,
        message,
    };
    let mut reader = csv::Reader::from_reader(input);
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
        let action = field(action_at, "action")?
            .parse::<Action>()
            .map_err(|m| error(Some(line), m))?;
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::{Evaluator, Recording};
    use crate::policy::{Builtin, PolicyFactory};
    use crate::sim::Scenes;

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
        crate::io::atomic::write_atomic(&path, |out| write_steps(&record, out)).unwrap();
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
            "v=1.5;w=-3".parse::<Action>().unwrap(),
            Action::Continuous {
                v: 1.5,
                w_deg: -3.0
            }
        );
    }
}
