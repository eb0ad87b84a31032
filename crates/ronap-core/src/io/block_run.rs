//! Runs whose episodes are evaluated elsewhere (seed blocks on other machines, as Python's Ray
//! driver runs them) and come back as rows, written into the run files
//! [`crate::job::evaluate_into`] writes for the same run.

use crate::config::ValidConfig;
use crate::eval::{EpisodeRecord, EvalOptions, Figures, RunResult, Seeds, Tally};
use crate::io::atomic::OutputError;
use crate::io::figures::{self, FIGURES_FILE};
use crate::io::manifest::RunManifest;
use crate::io::run_dir::{
    episode_row, finish, lone_headers, manifest, restore, timing_row, Layout, RunInfo, RunWriter,
    Streams,
};

/// The rows one finished episode adds to a lone robot's run files: its `episodes.csv` and
/// `timing.csv` rows and its exact figures (what the summary is made of). What a seed block
/// evaluated elsewhere hands back to the [`BlockRun`] that writes the whole run.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct EpisodeRows {
    /// The episode seed.
    pub seed: u64,
    /// Its `episodes.csv` row.
    pub episode: Vec<String>,
    /// Its `timing.csv` row.
    pub timing: Vec<String>,
    /// Its exact figures, as the figures file holds them.
    pub figures: Vec<String>,
}

impl EpisodeRows {
    /// The rows of `record`, whose figures are `f`, laid out as `layout` says.
    pub fn with(record: &EpisodeRecord, f: &Figures, layout: Layout) -> Self {
        Self {
            seed: record.seed,
            episode: episode_row(record, layout),
            timing: timing_row(record.seed, record.wall_time_s).to_vec(),
            figures: figures::lone_row(record.seed, f),
        }
    }

    /// The rows of `record`, laid out as `layout` says.
    pub fn of(record: &EpisodeRecord, layout: Layout) -> Self {
        Self::with(record, &Figures::of(record), layout)
    }

    /// The rows for each run file, in the order of `RUN_FILES` (see [`crate::io::run_dir`]) (no `robots.csv`).
    pub(crate) fn files(&self) -> [Vec<Vec<String>>; 3] {
        [
            vec![self.episode.clone()],
            vec![self.timing.clone()],
            vec![self.figures.clone()],
        ]
    }
}

/// A lone robot's run whose episodes were evaluated elsewhere (seed blocks on other machines)
/// and come back as [`EpisodeRows`], written into the files [`crate::job::evaluate_into`] writes
/// for the same run: the same `episodes.csv` bytes, the same summary figures, the same plan (so a
/// killed run can be taken up again with [`RunWriter::resume`]).
pub struct BlockRun {
    writer: RunWriter,
    streams: Streams,
    tally: Tally,
    config: ValidConfig,
    options: EvalOptions,
    info: RunInfo,
    /// How many of the seeds have their rows.
    next: usize,
    steps_before: u64,
    /// The run files failed to take rows: the run ends without a summary, its files partial.
    broken: Option<String>,
}

impl BlockRun {
    /// Starts the run of `options.seeds` under `config` in `writer`'s directory (or, for a
    /// resumed writer, takes it up after the episodes it had).
    pub fn create(
        writer: RunWriter,
        config: &ValidConfig,
        options: &EvalOptions,
        info: &RunInfo,
    ) -> Result<Self, OutputError> {
        let plan = writer.plan(config, options, info);
        let layout = Layout::of(config);
        let streams = writer.open(&plan, lone_headers(layout));
        let mut tally = Tally::measuring(layout.metrics);
        let done = writer.done();
        if done > 0 {
            restore(&writer.dir, done, &mut |row| {
                let (_, f) = figures::parse_lone(row, layout.metrics.len())?;
                tally.add(&f);
                Ok(())
            })?;
        }
        let steps_before = tally.steps();
        Ok(Self {
            writer,
            streams,
            tally,
            config: config.clone(),
            options: options.clone(),
            info: info.clone(),
            next: done,
            broken: None,
            steps_before,
        })
    }

    /// The seeds whose rows have not come yet, in order.
    pub fn remaining(&self) -> Seeds {
        self.options.seeds.after(self.next)
    }

    /// Adds the rows of the next episodes, in seed order: each must be the run's next seed.
    pub fn add(&mut self, rows: &[EpisodeRows]) -> Result<(), OutputError> {
        for r in rows {
            let expected = self.options.seeds.get(self.next);
            if expected != Some(r.seed) {
                return Err(OutputError::Format {
                    path: self.writer.dir.join("episodes.csv"),
                    message: match expected {
                        Some(e) => format!("rows of seed {} came where seed {e} is next", r.seed),
                        None => format!("rows of seed {} came after the run's last seed", r.seed),
                    },
                });
            }
            let record = csv::StringRecord::from(r.figures.clone());
            let metrics = self.tally.metrics();
            let (_, f) =
                figures::parse_lone(&record, metrics).map_err(|message| OutputError::Format {
                    path: self.writer.dir.join(FIGURES_FILE),
                    message: format!("seed {}: {message}", r.seed),
                })?;
            if let Err(e) = self.streams.add(&self.writer, &r.files()) {
                self.broken = Some(e.to_string());
                return Err(e);
            }
            self.tally.add(&f);
            self.next += 1;
        }
        Ok(())
    }

    /// Ends the run after `wall_time_s` seconds: the files to their final names (kept partial,
    /// for a resume, when seeds are missing) and `summary.json`. Returns what it holds.
    pub fn finish(self, wall_time_s: f64) -> Result<RunManifest, OutputError> {
        if let Some(message) = &self.broken {
            // As `evaluate_into` after a write error: no file under a final name half-written.
            return Err(OutputError::Format {
                path: self.writer.dir.join("summary.json"),
                message: format!("not written: the run files could not be written ({message})"),
            });
        }
        let missing = self.next < self.options.seeds.len();
        let result = RunResult {
            records: Vec::new(),
            cancelled: missing,
            error: None,
            wall_time_s,
        };
        let summary = self
            .tally
            .summary(wall_time_s, self.tally.steps() - self.steps_before);
        let manifest = manifest(&self.config, &self.options, &self.info, &result, &summary);
        finish(&self.writer, Some(self.streams), &manifest, &result)?;
        Ok(manifest)
    }
}
