//! The sequence every evaluation into a run directory follows, whatever kind of episode it runs
//! (a lone robot's, a team's): the recording the writer asks for, the figures of the episodes a
//! resumed run had finished, the seeds left run with each episode's own files written as it
//! ends and its rows as they come in seed order, and the stop at the first write error. The
//! kind says how its episodes run ([`Episodes`]) and what its rows and figures are
//! ([`Tallies`]).

use crate::eval::{EvalOptions, Outcome, RunEnd, RunResult};
use crate::io::{restore, OutputError, Pictures, RunWriter, Streams};
use crate::job::RunRequest;
use crate::policy::PolicyError;
use std::sync::atomic::AtomicBool;

/// One episode's rows of one run file.
pub(super) type FileRows = Vec<Vec<String>>;

/// How a kind of run's episodes run, and the files an episode has of its own.
pub(super) trait Episodes<R>: Sync {
    /// Runs `options`' seeds: each record to `on_finish` as it ends (any order), then to `sink`
    /// in seed order (`false`: stop).
    fn stream(
        &self,
        options: &EvalOptions,
        cancel: &AtomicBool,
        on_finish: &(dyn Fn(&R) + Sync),
        sink: &mut dyn FnMut(R) -> bool,
    ) -> Result<RunEnd, PolicyError>;

    /// Writes `record`'s own files (pictures, step logs, its animation) into `writer`'s run.
    fn files(&self, writer: &RunWriter, record: &R);
}

/// A kind of run's rows and figures.
pub(super) trait Tallies<R> {
    /// The headers of the run files: `episodes.csv`, `timing.csv`, `robots.csv` (a team's) and
    /// the exact figures.
    fn headers(&self) -> [Option<Vec<String>>; 4];

    /// Adds a row of the exact figures (an episode the run's earlier process finished).
    fn restore(&mut self, row: &csv::StringRecord) -> Result<(), String>;

    /// From now on, steps are this process's (for its steps per second).
    fn start(&mut self);

    /// Hands `record`'s rows of the run files to `write`, then, if it took them, adds the
    /// record to the figures; whether it did.
    fn add(&mut self, record: R, write: &mut dyn FnMut(&[FileRows]) -> bool) -> bool;
}

/// How the run went, with its files still under their partial names.
pub(super) struct Ran {
    /// How it stopped (no records: the tallies keep what they keep).
    pub result: RunResult,
    /// The options it ran with (the recording the writer asked for).
    pub options: EvalOptions,
    /// The run files, to finish.
    pub streams: Option<Streams>,
    /// The first write error.
    pub write_error: Option<OutputError>,
}

/// Runs `request` with `episodes`, adding up in `tallies`; `on_record` hears every finished
/// episode (progress).
pub(super) fn run_into<R>(
    request: &RunRequest<'_>,
    episodes: &dyn Episodes<R>,
    tallies: &mut dyn Tallies<R>,
    on_record: &(dyn Fn(&R) + Sync),
) -> Result<Ran, PolicyError> {
    let writer = request.writer.as_ref();
    let mut options = request.options.clone();
    if let Some(w) = writer {
        options.recording = w.recording();
        options.steps_of = w.gif_seeds().to_vec();
        // A player shows every step: its episodes' steps are recorded (all of them when the
        // run's outcome decides, as for `--html failures`).
        match w.players() {
            Some(Pictures::First(n)) => options.steps_of.extend(
                options
                    .seeds
                    .iter()
                    .filter(|s| w.wants_player(*s, Outcome::Success))
                    .take(n as usize),
            ),
            Some(_) => options.recording.steps = true,
            None => {}
        }
    }
    let mut write_error = None;
    let mut streams = None;
    let done = writer.map_or(0, RunWriter::done);
    if let Some(w) = writer {
        let plan = w.plan(request.evaluator.config(), &options, request.info);
        streams = Some(w.open(&plan, tallies.headers()));
        if done > 0 {
            if let Err(e) = restore(&w.dir, done, &mut |row| tallies.restore(row)) {
                write_error = Some(e);
            }
        }
    }
    tallies.start();
    let end = if write_error.is_some() {
        RunEnd {
            episodes: 0,
            cancelled: false,
            error: None,
            wall_time_s: 0.0,
        }
    } else {
        let rest = EvalOptions {
            seeds: options.seeds.after(done),
            ..options.clone()
        };
        let on_finish = |r: &R| {
            if let Some(w) = writer {
                episodes.files(w, r);
            }
            on_record(r);
        };
        episodes.stream(&rest, request.cancel, &on_finish, &mut |r| {
            tallies.add(r, &mut |rows| {
                if let (Some(s), Some(w)) = (&mut streams, writer) {
                    if let Err(e) = s.add(w, rows) {
                        write_error = Some(e);
                        return false;
                    }
                }
                true
            })
        })?
    };
    let result = RunResult {
        records: Vec::new(),
        cancelled: end.cancelled && write_error.is_none(),
        error: end.error,
        wall_time_s: end.wall_time_s,
    };
    Ok(Ran {
        result,
        options,
        streams,
        write_error,
    })
}
