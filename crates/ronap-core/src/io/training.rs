//! A training log beside a weights file: `NAME-training.csv` (one row per report) and
//! `NAME-training.png` (its curves), for `W = NAME.safetensors`. Both are written atomically and
//! rewritten at every report, so a training run stopped at any point leaves its curves so far.

use crate::io::atomic::{save_image, write_atomic, OutputError};
use crate::render::chart::{line_chart, Line, Panel};
use std::path::{Path, PathBuf};

/// One panel of the picture: its y-axis label, the columns drawn in it, and a fixed y range.
#[derive(Clone, Debug, PartialEq)]
pub struct Curves {
    /// The y-axis label.
    pub label: &'static str,
    /// Columns drawn as lines: the column's name and the line's name in the legend.
    pub columns: &'static [(&'static str, &'static str)],
    /// A fixed y range (rates: 0 to 1); `None` fits the data.
    pub range: Option<(f64, f64)>,
}

/// The rows of a training run so far and where they go.
#[derive(Clone, Debug)]
pub struct TrainingLog {
    csv: PathBuf,
    png: PathBuf,
    title: String,
    columns: Vec<&'static str>,
    panels: Vec<Curves>,
    rows: Vec<Vec<f64>>,
}

/// The log files of weights file `weights`: `NAME-training.csv` and `NAME-training.png` beside
/// it.
pub fn log_paths(weights: &Path) -> (PathBuf, PathBuf) {
    let stem = weights
        .file_stem()
        .map_or_else(|| "policy".into(), |s| s.to_string_lossy().into_owned());
    let dir = weights.parent().unwrap_or(Path::new(""));
    (
        dir.join(format!("{stem}-training.csv")),
        dir.join(format!("{stem}-training.png")),
    )
}

impl TrainingLog {
    /// A log for weights file `weights` with these `columns` (the first is the x axis of every
    /// panel) and `panels`, under `title`.
    pub fn new(
        weights: &Path,
        title: impl Into<String>,
        columns: &[&'static str],
        panels: &[Curves],
    ) -> Self {
        let (csv, png) = log_paths(weights);
        Self {
            csv,
            png,
            title: title.into(),
            columns: columns.to_vec(),
            panels: panels.to_vec(),
            rows: Vec::new(),
        }
    }

    /// The CSV file's path.
    pub fn csv_path(&self) -> &Path {
        &self.csv
    }

    /// The picture's path.
    pub fn png_path(&self) -> &Path {
        &self.png
    }

    /// Adds a row (one value per column; NaN for a figure that does not exist yet, written
    /// empty) and rewrites both files.
    pub fn push(&mut self, row: Vec<f64>) -> Result<(), OutputError> {
        self.rows.push(row);
        self.save()
    }

    /// Writes both files from the rows so far.
    pub fn save(&self) -> Result<(), OutputError> {
        write_atomic(&self.csv, |w| {
            writeln!(w, "{}", self.columns.join(","))?;
            for row in &self.rows {
                let cells: Vec<String> = row
                    .iter()
                    .map(|v| {
                        if v.is_finite() {
                            v.to_string()
                        } else {
                            String::new()
                        }
                    })
                    .collect();
                writeln!(w, "{}", cells.join(","))?;
            }
            Ok(())
        })?;
        save_image(&self.png, &self.picture())
    }

    /// The curves: one panel per [`Curves`], x the first column.
    pub fn picture(&self) -> image::RgbImage {
        let column = |name: &str| self.columns.iter().position(|c| *c == name);
        let panels: Vec<Panel> = self
            .panels
            .iter()
            .map(|p| Panel {
                y_label: p.label.to_string(),
                y_range: p.range,
                lines: p
                    .columns
                    .iter()
                    .filter_map(|(name, legend)| {
                        let k = column(name)?;
                        Some(Line {
                            name: (*legend).to_string(),
                            points: self.rows.iter().map(|r| (r[0], r[k])).collect(),
                        })
                    })
                    .collect(),
            })
            .collect();
        line_chart(
            &self.title,
            &self
                .columns
                .first()
                .map_or(String::new(), |c| c.replace('_', " ")),
            &panels,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_log_sits_beside_the_weights_and_holds_every_row() {
        assert_eq!(
            log_paths(Path::new("policies/dqn.safetensors")),
            (
                PathBuf::from("policies/dqn-training.csv"),
                PathBuf::from("policies/dqn-training.png")
            )
        );
        let dir = tempfile::tempdir().unwrap();
        let weights = dir.path().join("w.safetensors");
        let mut log = TrainingLog::new(
            &weights,
            "DQN",
            &["steps", "mean_return", "success_rate"],
            &[
                Curves {
                    label: "mean return",
                    columns: &[("mean_return", "mean return")],
                    range: None,
                },
                Curves {
                    label: "success rate",
                    columns: &[("success_rate", "success rate")],
                    range: Some((0.0, 1.0)),
                },
            ],
        );
        log.push(vec![1000.0, f64::NAN, 0.0]).unwrap();
        log.push(vec![2000.0, 3.5, 0.25]).unwrap();
        let text = std::fs::read_to_string(dir.path().join("w-training.csv")).unwrap();
        assert_eq!(
            text,
            "steps,mean_return,success_rate\n1000,,0\n2000,3.5,0.25\n"
        );
        let png = image::open(dir.path().join("w-training.png")).unwrap();
        assert!(png.width() > 100 && png.height() > 100);
    }
}
