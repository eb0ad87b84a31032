//! The data log (the paper's "Save Data" / "Collect Data"): one CSV row per recorded action, and
//! the data sets learned policies train on.
//!
//! ronap's own rows (docs/model.md "Data log" order, then extras) are
//! `laser_0..laser_{m-1},heading,bearing,distance,action,direction,seed,step,x,y,goal_x,goal_y,collided`
//! with distances in px and angles in degrees, recorded at the pose *before* the action.
//! [`read`] also takes the original platform's header-less rows,
//! `"[498, ..., 330]",343.72,10.902,AHEAD`: 17 laser readings in view px (10.01 view px = 1 px,
//! 498 = nothing in range), D, direction and the action, or `WARNING` for a collision row.
//! Either way a row becomes the 18-value observation of docs/model.md "Observation" and an action index.

use crate::geometry::{wrap_deg, Point};
use crate::sim::{DiscreteAction, Episode, Pose, SeedRanges};
use std::io::Write;
use std::path::{Path, PathBuf};

/// View px per scene px in the original platform's logs.
pub const ORIGINAL_VIEW_PX_PER_PX: f64 = 10.01;
/// The original's laser reading for "no obstacle in range", view px.
pub const ORIGINAL_NO_HIT_VIEW_PX: f64 = 498.0;

/// One recorded action and the state it was taken in.
#[derive(Clone, Debug, PartialEq)]
pub struct Sample {
    /// Episode seed (scene, goal and re-posing stream).
    pub seed: u64,
    /// Index of the sample within its episode.
    pub step: u64,
    /// The pose the action was taken from.
    pub pose: Pose,
    /// The goal.
    pub goal: Point,
    /// Laser readings at `pose`, px.
    pub readings: Vec<f64>,
    /// Bearing to the goal, degrees.
    pub bearing_deg: f64,
    /// Distance to the goal, px.
    pub distance_px: f64,
    /// The action taken.
    pub action: DiscreteAction,
    /// Whether the action collided (the robot stayed where it was).
    pub collided: bool,
}

impl Sample {
    /// The episode's current state with `action` about to be taken.
    pub fn before(episode: &Episode, step: u64, action: DiscreteAction) -> Self {
        Self {
            seed: episode.seed(),
            step,
            pose: episode.pose(),
            goal: episode.goal(),
            readings: episode.readings().to_vec(),
            bearing_deg: episode.bearing_deg(),
            distance_px: episode.distance_px(),
            action,
            collided: false,
        }
    }

    /// Relative direction to the goal, degrees in [0, 360): 0 ahead, 90 to the left.
    pub fn direction_deg(&self) -> f64 {
        wrap_deg(self.bearing_deg - self.pose.z_deg)
    }

    /// The observation (docs/model.md "Observation") for a laser of `range_px`.
    pub fn observation(&self, range_px: f64) -> Vec<f32> {
        observation(&self.readings, self.direction_deg(), range_px)
    }
}

/// The header of a data log for `beams` laser beams.
pub fn header(beams: usize) -> String {
    let mut h: Vec<String> = (0..beams).map(|i| format!("laser_{i}")).collect();
    h.extend(
        [
            "heading",
            "bearing",
            "distance",
            "action",
            "direction",
            "seed",
            "step",
            "x",
            "y",
            "goal_x",
            "goal_y",
            "collided",
        ]
        .map(String::from),
    );
    h.join(",")
}

/// Writes data-log rows as they come, each flushed, so a crash or a quit loses nothing written.
#[derive(Debug)]
pub struct DataLogWriter<W: Write> {
    out: W,
    beams: usize,
}

impl<W: Write> DataLogWriter<W> {
    /// A writer for `beams` laser beams; writes the header now.
    pub fn new(mut out: W, beams: usize) -> std::io::Result<Self> {
        writeln!(out, "{}", header(beams))?;
        out.flush()?;
        Ok(Self { out, beams })
    }

    /// Appends one row and flushes it.
    pub fn write(&mut self, s: &Sample) -> std::io::Result<()> {
        if s.readings.len() != self.beams {
            return Err(std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                format!(
                    "sample has {} laser readings, the log {}",
                    s.readings.len(),
                    self.beams
                ),
            ));
        }
        let mut line = String::with_capacity(256);
        for r in &s.readings {
            line.push_str(&format!("{r:.3},"));
        }
        line.push_str(&format!(
            "{:.3},{:.3},{:.3},{},{:.3},{},{},{:.3},{:.3},{:.3},{:.3},{}\n",
            s.pose.z_deg,
            s.bearing_deg,
            s.distance_px,
            s.action.name(),
            s.direction_deg(),
            s.seed,
            s.step,
            s.pose.x,
            s.pose.y,
            s.goal.x,
            s.goal.y,
            u8::from(s.collided),
        ));
        self.out.write_all(line.as_bytes())?;
        self.out.flush()
    }

    /// The underlying writer.
    pub fn into_inner(self) -> W {
        self.out
    }
}

/// Which platform wrote a log.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// ronap's own rows, with a header.
    Ronap,
    /// The original RoNAP platform's header-less rows.
    Original,
}

/// Observations and expert actions, ready to train on.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct DataSet {
    /// Values per observation: beams + 1.
    pub width: usize,
    /// Observations, row after row (`len() * width` values).
    pub observations: Vec<f32>,
    /// Action index per row: 0 LEFT, 1 AHEAD, 2 RIGHT.
    pub actions: Vec<u8>,
    /// Rows left out: the original's `WARNING` rows and ronap's collided rows.
    pub skipped: usize,
    /// The episode seeds the rows came from, where the log records them (ronap's format).
    pub seeds: std::collections::BTreeSet<u64>,
}

impl DataSet {
    /// An empty data set of observations `width` wide.
    pub fn new(width: usize) -> Self {
        Self {
            width,
            ..Self::default()
        }
    }

    /// Number of rows.
    pub fn len(&self) -> usize {
        self.actions.len()
    }

    /// Whether there are no rows.
    pub fn is_empty(&self) -> bool {
        self.actions.is_empty()
    }

    /// Observation of row `i`.
    pub fn observation(&self, i: usize) -> &[f32] {
        &self.observations[i * self.width..(i + 1) * self.width]
    }

    /// Adds a row.
    pub fn push(&mut self, observation: &[f32], action: DiscreteAction) {
        debug_assert_eq!(observation.len(), self.width);
        self.observations.extend_from_slice(observation);
        self.actions.push(action as u8);
    }

    /// The episode seeds of the rows, as ranges of consecutive seeds (empty when the log does not
    /// record them).
    pub fn seed_ranges(&self) -> SeedRanges {
        let mut ranges: Vec<std::ops::RangeInclusive<u64>> = Vec::new();
        for &s in &self.seeds {
            match ranges.last_mut() {
                Some(r) if r.end().checked_add(1) == Some(s) => *r = *r.start()..=s,
                _ => ranges.push(s..=s),
            }
        }
        SeedRanges(ranges)
    }

    /// Rows per action, LEFT, AHEAD, RIGHT.
    pub fn action_counts(&self) -> [usize; 3] {
        let mut c = [0; 3];
        for &a in &self.actions {
            c[usize::from(a).min(2)] += 1;
        }
        c
    }
}

/// A data log that cannot be read.
#[derive(Debug, thiserror::Error)]
pub enum DataLogError {
    /// The file could not be read.
    #[error("cannot read {}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The error.
        source: std::io::Error,
    },
    /// A row (or the header) is malformed.
    #[error("{}:{line}: {message}", path.display())]
    Row {
        /// The file.
        path: PathBuf,
        /// 1-based line number.
        line: u64,
        /// What is wrong.
        message: String,
    },
    /// The file has no usable row.
    #[error("{}: no data rows", path.display())]
    Empty {
        /// The file.
        path: PathBuf,
    },
}

/// Reads a data log of either [`Format`] into observations for a laser of `range_px`.
pub fn read(path: &Path, range_px: f64) -> Result<(DataSet, Format), DataLogError> {
    let io = |source| DataLogError::Io {
        path: path.to_path_buf(),
        source,
    };
    let mut text = String::new();
    std::io::Read::read_to_string(
        &mut crate::bounded::open_lines(path).map_err(io)?,
        &mut text,
    )
    .map_err(io)?;
    parse(&text, path, range_px)
}

/// Parses the text of a data log; `path` names it in errors.
pub fn parse(text: &str, path: &Path, range_px: f64) -> Result<(DataSet, Format), DataLogError> {
    let first = text.lines().find(|l| !l.trim().is_empty()).unwrap_or("");
    let format = if first.trim_start().starts_with("laser_") {
        Format::Ronap
    } else {
        Format::Original
    };
    let row_error = |line: u64, message: String| DataLogError::Row {
        path: path.to_path_buf(),
        line,
        message,
    };
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(format == Format::Ronap)
        .flexible(true)
        .trim(csv::Trim::All)
        .from_reader(text.as_bytes());
    let columns = match format {
        Format::Ronap => Some(
            RonapColumns::from_header(reader.headers().map_err(|e| row_error(1, e.to_string()))?)
                .map_err(|m| row_error(1, m))?,
        ),
        Format::Original => None,
    };
    let mut data = DataSet::default();
    for record in reader.records() {
        let record = record.map_err(|e| {
            let line = e.position().map_or(0, csv::Position::line);
            row_error(line, e.to_string())
        })?;
        let line = record.position().map_or(0, csv::Position::line);
        if record.iter().all(str::is_empty) {
            continue;
        }
        let row = match &columns {
            Some(c) => c.row(&record, range_px),
            None => original_row(&record, range_px),
        }
        .map_err(|m| row_error(line, m))?;
        let Some((observation, action)) = row else {
            data.skipped += 1;
            continue;
        };
        if data.width == 0 {
            data.width = observation.len();
        } else if observation.len() != data.width {
            return Err(row_error(
                line,
                format!(
                    "{} laser readings where earlier rows had {}",
                    observation.len() - 1,
                    data.width - 1
                ),
            ));
        }
        data.push(&observation, action);
        let seed = columns
            .as_ref()
            .and_then(|c| c.seed)
            .and_then(|i| record.get(i));
        if let Some(seed) = seed.and_then(|s| s.parse::<u64>().ok()) {
            data.seeds.insert(seed);
        }
    }
    if data.is_empty() {
        return Err(DataLogError::Empty {
            path: path.to_path_buf(),
        });
    }
    Ok((data, format))
}

/// An observation and action, or `None` for a row to skip.
type Row = Option<(Vec<f32>, DiscreteAction)>;

fn number(field: &str, name: &str) -> Result<f64, String> {
    field
        .parse::<f64>()
        .ok()
        .filter(|v| v.is_finite())
        .ok_or_else(|| format!("{name} = {field:?} is not a finite number"))
}

fn action(field: &str) -> Result<DiscreteAction, String> {
    field
        .parse()
        .map_err(|_| format!("action = {field:?} is not AHEAD, LEFT or RIGHT"))
}

fn observation(readings_px: &[f64], direction_deg: f64, range_px: f64) -> Vec<f32> {
    let mut o: Vec<f32> = readings_px
        .iter()
        .map(|r| (r.clamp(0.0, range_px) / range_px) as f32)
        .collect();
    o.push((wrap_deg(direction_deg) / 360.0) as f32);
    o
}

/// Where ronap's columns are in a log's header.
struct RonapColumns {
    lasers: Vec<usize>,
    heading: usize,
    bearing: usize,
    action: usize,
    collided: Option<usize>,
    seed: Option<usize>,
}

impl RonapColumns {
    fn from_header(header: &csv::StringRecord) -> Result<Self, String> {
        let find = |name: &str| header.iter().position(|h| h == name);
        let need = |name: &str| find(name).ok_or_else(|| format!("header has no {name} column"));
        let lasers: Vec<usize> = (0..).map_while(|i| find(&format!("laser_{i}"))).collect();
        Ok(Self {
            lasers,
            heading: need("heading")?,
            bearing: need("bearing")?,
            action: need("action")?,
            collided: find("collided"),
            seed: find("seed"),
        })
    }

    fn row(&self, record: &csv::StringRecord, range_px: f64) -> Result<Row, String> {
        let get = |i: usize, name: &str| {
            record
                .get(i)
                .ok_or_else(|| format!("row has {} fields, no {name}", record.len()))
        };
        if let Some(c) = self.collided {
            if get(c, "collided")? == "1" {
                return Ok(None);
            }
        }
        let readings = self
            .lasers
            .iter()
            .enumerate()
            .map(|(k, &i)| {
                let name = format!("laser_{k}");
                number(get(i, &name)?, &name)
            })
            .collect::<Result<Vec<f64>, String>>()?;
        let heading = number(get(self.heading, "heading")?, "heading")?;
        let bearing = number(get(self.bearing, "bearing")?, "bearing")?;
        let action = action(get(self.action, "action")?)?;
        Ok(Some((
            observation(&readings, bearing - heading, range_px),
            action,
        )))
    }
}

fn original_row(record: &csv::StringRecord, range_px: f64) -> Result<Row, String> {
    if record.len() != 4 {
        return Err(format!(
            "expected 4 fields (\"[lasers]\", D, direction, action), found {}",
            record.len()
        ));
    }
    let list = &record[0];
    let inner = list
        .strip_prefix('[')
        .and_then(|l| l.strip_suffix(']'))
        .ok_or_else(|| format!("lasers = {list:?} is not a [..] list"))?;
    let readings = inner
        .split(',')
        .enumerate()
        .map(|(i, v)| {
            let view = number(v.trim(), &format!("laser {i}"))?;
            Ok(if view >= ORIGINAL_NO_HIT_VIEW_PX {
                range_px
            } else {
                view / ORIGINAL_VIEW_PX_PER_PX
            })
        })
        .collect::<Result<Vec<f64>, String>>()?;
    number(&record[1], "D")?;
    let direction = number(&record[2], "direction")?;
    if &record[3] == "WARNING" {
        return Ok(None);
    }
    let action = action(&record[3])?;
    Ok(Some((observation(&readings, direction, range_px), action)))
}

#[cfg(test)]
mod tests {
    use super::*;

    const ORIGINAL: &str = "\"[498, 498, 498, 498, 498, 498, 498, 498, 498, 498, 498, 498, 498, 498, 401, 357, 330]\",343.72,10.902,AHEAD\n\
\"[498, 498, 498, 498, 498, 498, 498, 498, 498, 498, 498, 498, 498, 498, 401, 357, 330]\",343.72,10.902,WARNING\n\
\"[100, 498, 498, 498, 498, 498, 498, 498, 498, 498, 498, 498, 498, 498, 401, 357, 330]\",300.0,350,LEFT\n";

    #[test]
    fn reads_the_original_format() {
        let (data, format) = parse(ORIGINAL, Path::new("o.csv"), 50.0).unwrap();
        assert_eq!(format, Format::Original);
        assert_eq!((data.len(), data.width, data.skipped), (2, 18, 1));
        let o = data.observation(0);
        assert_eq!(o[0], 1.0);
        assert!((o[16] - (330.0 / 10.01 / 50.0) as f32).abs() < 1e-6);
        assert!((o[17] - (10.902 / 360.0) as f32).abs() < 1e-6);
        assert!((data.observation(1)[0] - (100.0 / 10.01 / 50.0) as f32).abs() < 1e-6);
        assert_eq!(data.actions, vec![1, 0]);
    }

    #[test]
    fn bad_rows_name_file_and_line() {
        let bad = ORIGINAL.replace("300.0,350,LEFT", "300.0,350,JUMP");
        let e = parse(&bad, Path::new("o.csv"), 50.0)
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("o.csv:3:"), "{e}");
        assert!(e.contains("JUMP"), "{e}");
        let e = parse("laser_0,heading\n", Path::new("x.csv"), 50.0)
            .unwrap_err()
            .to_string();
        assert!(e.contains("x.csv:1") && e.contains("bearing"), "{e}");
    }

    #[test]
    fn ronap_rows_round_trip() {
        let mut w = DataLogWriter::new(Vec::new(), 3).unwrap();
        let mut s = Sample {
            seed: 4,
            step: 0,
            pose: Pose::new(10.0, 20.0, 350.0),
            goal: Point::new(100.0, 20.0),
            readings: vec![5.0, 60.0, 25.0],
            bearing_deg: 0.0,
            distance_px: 90.0,
            action: DiscreteAction::Left,
            collided: false,
        };
        w.write(&s).unwrap();
        s.collided = true;
        w.write(&s).unwrap();
        let text = String::from_utf8(w.into_inner()).unwrap();
        assert!(text.starts_with("laser_0,laser_1,laser_2,heading,bearing,distance,action"));
        let (data, format) = parse(&text, Path::new("r.csv"), 50.0).unwrap();
        assert_eq!(format, Format::Ronap);
        assert_eq!((data.len(), data.skipped), (1, 1));
        assert_eq!(data.observation(0), &[0.1, 1.0, 0.5, 10.0 / 360.0]);
        assert_eq!(data.actions, vec![0]);
    }
}
