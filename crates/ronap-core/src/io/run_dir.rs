//! A run directory: what an evaluation writes, and the one sequence that runs an evaluation into
//! it (used by `ronap run` and Python's `ronap.evaluate`). `episodes.csv`, `timing.csv` and the
//! manifest `summary.json` at the end; trajectory pictures (`png/`) and step logs (`steps/`) as
//! each episode finishes.
//!
//! Everything here is deterministic given the records except `timing.csv`, which holds the wall
//! times, so `episodes.csv` is byte-identical whatever the thread count.

use crate::config::ValidConfig;
use crate::eval::{
    EpisodeRecord, EvalOptions, Evaluator, Outcome, Recording, RunResult, Summary, TeamRecord,
    TeamRunResult, TeamSummary,
};
use crate::io::atomic::{save_image, write_atomic, OutputError};
use crate::io::manifest::{RunManifest, SCHEMA_VERSION};
use crate::io::steplog::write_steps;
use crate::policy::{PolicyError, PolicyFactory};
use crate::render::trajectory::trajectory_image;
use crate::scene::map::MapSource;
use crate::sim::world::SceneSpec;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;
use std::sync::Mutex;

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
        self.wants_seed(record.seed, record.outcome, first_seed)
    }

    /// Whether the episode of `seed`, which ended as `outcome`, gets a picture.
    pub fn wants_seed(self, seed: u64, outcome: Outcome, first_seed: u64) -> bool {
        match self {
            Pictures::All => true,
            Pictures::Failures => outcome != Outcome::Success,
            Pictures::First(n) => seed.wrapping_sub(first_seed) < n,
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

/// Columns `episodes.csv` gains when the episodes have moving obstacles.
pub const DYNAMIC_COLUMNS: [&str; 3] = [
    "dynamic_collisions",
    "min_clearance_px",
    "near_moving_fraction",
];

/// Writes `episodes.csv`: one row per record, with [`DYNAMIC_COLUMNS`] after the others when the
/// episodes had moving obstacles.
pub fn write_episodes(records: &[EpisodeRecord], out: &mut dyn Write) -> std::io::Result<()> {
    let mut w = csv::Writer::from_writer(out);
    let dynamic = records.iter().any(|r| r.dynamic.is_some());
    if dynamic {
        w.write_record(EPISODE_COLUMNS.iter().chain(&DYNAMIC_COLUMNS))?;
    } else {
        w.write_record(EPISODE_COLUMNS)?;
    }
    for r in records {
        let extra = r.dynamic.map(|d| {
            [
                d.collisions.to_string(),
                if d.min_clearance_px.is_finite() {
                    format!("{:.3}", d.min_clearance_px)
                } else {
                    String::new()
                },
                format!("{:.4}", d.near_steps as f64 / r.steps.max(1) as f64),
            ]
        });
        let base = [
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
        ];
        if dynamic {
            let extra = extra.unwrap_or_default();
            w.write_record(base.iter().chain(&extra))?;
        } else {
            w.write_record(base)?;
        }
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

/// What a run writes beside its run files.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RunFiles {
    /// Trajectory pictures in `png/`, for the episodes this chooses.
    pub pictures: Option<Pictures>,
    /// Step logs in `steps/`.
    pub steps: bool,
    /// Animations in `gif/` (written by the caller; the directory is made and cleared here).
    pub gifs: bool,
}

/// A run directory being written: made (with the sub-directories its files need) and cleared of
/// an earlier run's per-episode files before the first episode, filled as episodes finish.
#[derive(Debug)]
pub struct RunWriter {
    dir: PathBuf,
    files: RunFiles,
    first_seed: u64,
    errors: Mutex<Vec<String>>,
}

impl RunWriter {
    /// Makes `dir` for a run whose seeds start at `first_seed`.
    pub fn create(dir: &Path, files: RunFiles, first_seed: u64) -> Result<Self, OutputError> {
        let subs = [
            (true, ""),
            (files.pictures.is_some(), "png"),
            (files.steps, "steps"),
            (files.gifs, "gif"),
        ];
        for (wanted, sub) in subs {
            if wanted {
                let d = dir.join(sub);
                std::fs::create_dir_all(&d).map_err(|source| OutputError::Io {
                    path: d.clone(),
                    source,
                })?;
            }
        }
        remove_stale_files(dir)?;
        Ok(Self {
            dir: dir.to_path_buf(),
            files,
            first_seed,
            errors: Mutex::new(Vec::new()),
        })
    }

    /// The directory.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// What the evaluator must keep of each episode for this writer's files.
    pub fn recording(&self) -> Recording {
        Recording {
            trajectory: self.files.pictures.is_some(),
            steps: self.files.steps,
        }
    }

    /// Writes the per-episode files of `record`; a failure is kept for [`RunWriter::finish`] so
    /// the run goes on (and its other results are saved).
    pub fn episode(&self, record: &EpisodeRecord) {
        let picture = self
            .files
            .pictures
            .is_some_and(|p| p.wants(record, self.first_seed));
        if let Err(e) = write_episode_files(&self.dir, record, picture, self.files.steps) {
            if let Ok(mut all) = self.errors.lock() {
                all.push(e.to_string());
            }
        }
    }

    /// Writes `episodes.csv`, `timing.csv` and `summary.json`. Then, if an episode's files
    /// could not be written, says so (how many, and the first).
    pub fn finish(self, result: &RunResult, manifest: &RunManifest) -> Result<(), OutputError> {
        write_atomic(&self.dir.join("episodes.csv"), |out| {
            write_episodes(&result.records, out)
        })?;
        write_atomic(&self.dir.join("timing.csv"), |out| {
            write_timing(&result.records, out)
        })?;
        manifest.write(&self.dir.join("summary.json"))?;
        let errors = self.errors.into_inner().unwrap_or_default();
        match errors.first() {
            Some(first) => Err(OutputError::Episodes {
                count: errors.len(),
                first: first.clone(),
            }),
            None => Ok(()),
        }
    }
}

/// Writes the per-episode files a record asks for: its trajectory picture (`png/`) and its step
/// log (`steps/`), each when `picture` / `steps` say so and the record holds what they need.
fn write_episode_files(
    dir: &Path,
    record: &EpisodeRecord,
    picture: bool,
    steps: bool,
) -> Result<(), OutputError> {
    if picture {
        if let Some(img) = trajectory_image(record, 1.0) {
            let path = dir.join("png").join(format!(
                "seed-{:06}-{}.png",
                record.seed,
                record.outcome.name()
            ));
            save_image(&path, &img)?;
        }
    }
    if steps {
        let path = dir
            .join("steps")
            .join(format!("seed-{:06}.csv", record.seed));
        write_atomic(&path, |out| write_steps(record, out))?;
    }
    Ok(())
}

/// Removes the per-episode files an earlier run left in `dir` (`png/seed-*.png`,
/// `steps/seed-*.csv`, `gif/seed-*.gif`), so a reused output directory shows only this run.
/// Nothing else is touched.
fn remove_stale_files(dir: &Path) -> Result<(), OutputError> {
    for (sub, ext) in [("png", ".png"), ("steps", ".csv"), ("gif", ".gif")] {
        let Ok(entries) = std::fs::read_dir(dir.join(sub)) else {
            continue;
        };
        for entry in entries.flatten() {
            let name = entry.file_name();
            let name = name.to_string_lossy();
            if name.starts_with("seed-") && name.ends_with(ext) {
                std::fs::remove_file(entry.path()).map_err(|source| OutputError::Io {
                    path: entry.path(),
                    source,
                })?;
            }
        }
    }
    Ok(())
}

/// What a run is, for its manifest: the policy's name and where its episodes took place.
#[derive(Clone, Debug)]
pub struct RunInfo {
    /// The policy as named to the front end.
    pub policy: String,
    /// Where episodes take place.
    pub scenes: SceneSpec,
    /// What the map file was read as, for runs on a map.
    pub map: Option<MapSource>,
}

/// A finished evaluation: the records, their summary and the manifest that went to
/// `summary.json` (or would have, for a run without a directory).
#[derive(Debug)]
pub struct Evaluation {
    /// The records and how the run stopped.
    pub result: RunResult,
    /// The figures.
    pub summary: Summary,
    /// The manifest.
    pub manifest: RunManifest,
    /// The run directory's files could not all be written.
    pub write_error: Option<OutputError>,
}

/// Runs an evaluation and, given a `writer`, writes it into its directory: per-episode files as
/// episodes finish, the run files at the end (also after an interruption or a failing episode,
/// so finished episodes are never lost). `on_record` hears every finished episode (progress).
pub fn evaluate_into(
    evaluator: &Evaluator,
    factory: &dyn PolicyFactory,
    options: &EvalOptions,
    info: &RunInfo,
    writer: Option<RunWriter>,
    cancel: &AtomicBool,
    on_record: &(dyn Fn(&EpisodeRecord) + Sync),
) -> Result<Evaluation, PolicyError> {
    let mut options = options.clone();
    if let Some(w) = &writer {
        options.recording = w.recording();
    }
    let result = evaluator.run(factory, &options, cancel, &|r: &EpisodeRecord| {
        if let Some(w) = &writer {
            w.episode(r);
        }
        on_record(r);
    })?;
    let summary = Summary::new(&result.records, result.wall_time_s);
    let manifest = manifest(evaluator.config(), &options, info, &result, &summary);
    let write_error = writer.and_then(|w| w.finish(&result, &manifest).err());
    Ok(Evaluation {
        result,
        summary,
        manifest,
        write_error,
    })
}

fn manifest(
    config: &ValidConfig,
    options: &EvalOptions,
    info: &RunInfo,
    result: &RunResult,
    summary: &Summary,
) -> RunManifest {
    RunManifest {
        schema_version: SCHEMA_VERSION,
        ronap_version: env!("CARGO_PKG_VERSION").to_string(),
        policy: info.policy.clone(),
        seed_start: options.seeds.first().copied().unwrap_or(0),
        seeds_requested: options.seeds.len() as u64,
        threads: options.threads,
        scenes: info.scenes.clone(),
        map: info.map.clone(),
        interrupted: result.cancelled,
        error: result.error.as_ref().map(|e| e.to_string()),
        summary: summary.clone(),
        team: None,
        config: config.as_sim_config().clone(),
    }
}

/// Columns of a team run's `episodes.csv` (one row per team episode).
pub const TEAM_COLUMNS: [&str; 10] = [
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
];

/// Writes a team run's `episodes.csv`: one row per team episode.
pub fn write_team_episodes(records: &[TeamRecord], out: &mut dyn Write) -> std::io::Result<()> {
    let mut w = csv::Writer::from_writer(out);
    w.write_record(TEAM_COLUMNS)?;
    for r in records {
        w.write_record([
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
        ])?;
    }
    w.flush()
}

/// Columns of a team run's `robots.csv` (one row per robot per episode).
pub const ROBOT_COLUMNS: [&str; 24] = [
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
    "start_x",
    "start_y",
    "start_heading_deg",
    "goal_x",
    "goal_y",
    "reason",
];

/// Writes a team run's `robots.csv`: one row per robot of every episode.
pub fn write_robots(records: &[TeamRecord], out: &mut dyn Write) -> std::io::Result<()> {
    let mut w = csv::Writer::from_writer(out);
    w.write_record(ROBOT_COLUMNS)?;
    for r in records {
        for x in &r.robots {
            w.write_record([
                r.seed.to_string(),
                x.robot.to_string(),
                x.policy.clone(),
                x.outcome.name().to_string(),
                x.steps.to_string(),
                x.arrived_at.map_or(String::new(), |a| a.to_string()),
                x.collisions.to_string(),
                x.robot_collisions.to_string(),
                x.dynamic_collisions
                    .map_or(String::new(), |d| d.to_string()),
                x.goals.to_string(),
                x.goals_reached.to_string(),
                x.tour
                    .map_or(String::new(), |t| format!("{:.3}", t.chosen_px())),
                x.tour.map_or(String::new(), |t| format!("{:.3}", t.given)),
                x.tour
                    .map_or(String::new(), |t| format!("{:.3}", t.nearest)),
                x.tour
                    .map_or(String::new(), |t| format!("{:.3}", t.optimal)),
                format!("{:.3}", x.path_length_px),
                x.shortest_px.map_or(String::new(), |l| format!("{l:.3}")),
                format!("{:.4}", x.spl),
                format!("{:.3}", x.start.x),
                format!("{:.3}", x.start.y),
                format!("{:.3}", x.start.z_deg),
                format!("{:.3}", x.goal.x),
                format!("{:.3}", x.goal.y),
                x.reason.clone().unwrap_or_default(),
            ])?;
        }
    }
    w.flush()
}

/// A finished team evaluation.
#[derive(Debug)]
pub struct TeamEvaluation {
    /// The records and how the run stopped.
    pub result: TeamRunResult,
    /// The team figures.
    pub team: TeamSummary,
    /// The figures of every robot.
    pub summary: Summary,
    /// The run directory's files could not all be written.
    pub write_error: Option<OutputError>,
}

/// Runs a team evaluation (robot `k` driven by `factories[k]`, named `names[k]`) and, given
/// `dir`, writes `episodes.csv` (team rows), `robots.csv`, `timing.csv` and `summary.json` into
/// it at the end, also after an interruption or a failing episode.
#[allow(clippy::too_many_arguments)]
pub fn evaluate_team_into(
    evaluator: &Evaluator,
    factories: &[&dyn PolicyFactory],
    names: &[String],
    options: &EvalOptions,
    info: &RunInfo,
    dir: Option<&Path>,
    pictures: Option<Pictures>,
    cancel: &AtomicBool,
    on_record: &(dyn Fn(&TeamRecord) + Sync),
) -> Result<TeamEvaluation, PolicyError> {
    let mut options = options.clone();
    options.recording.trajectory = pictures.is_some() && dir.is_some();
    let first = options.seeds.first().copied().unwrap_or(0);
    let picture_errors: Mutex<Vec<String>> = Mutex::new(Vec::new());
    if let (Some(dir), Some(_)) = (dir, pictures) {
        let png = dir.join("png");
        if let Err(e) = std::fs::create_dir_all(&png) {
            return Err(PolicyError::Failed(format!(
                "cannot make {}: {e}",
                png.display()
            )));
        }
        if let Err(e) = remove_stale_files(dir) {
            return Err(PolicyError::Failed(e.to_string()));
        }
    }
    let result = evaluator.run_team(factories, names, &options, cancel, &|r: &TeamRecord| {
        if let (Some(dir), Some(p)) = (dir, pictures) {
            if p.wants_seed(r.seed, r.outcome, first) {
                if let Some(img) = crate::render::team::team_image(r, 1.0) {
                    let path = dir.join("png").join(format!(
                        "seed-{:06}-{}.png",
                        r.seed,
                        r.outcome.name()
                    ));
                    if let Err(e) = save_image(&path, &img) {
                        if let Ok(mut all) = picture_errors.lock() {
                            all.push(e.to_string());
                        }
                    }
                }
            }
        }
        on_record(r);
    })?;
    let options = &options;
    let team = TeamSummary::new(&result.records, result.wall_time_s);
    let robots: Vec<EpisodeRecord> = result
        .records
        .iter()
        .flat_map(|r| r.robots.iter().map(|x| x.as_episode(r.seed)))
        .collect();
    let summary = Summary::new(&robots, result.wall_time_s);
    let write_error = dir.and_then(|dir| {
        let write = || -> Result<(), OutputError> {
            std::fs::create_dir_all(dir).map_err(|source| OutputError::Io {
                path: dir.to_path_buf(),
                source,
            })?;
            write_atomic(&dir.join("episodes.csv"), |out| {
                write_team_episodes(&result.records, out)
            })?;
            write_atomic(&dir.join("robots.csv"), |out| {
                write_robots(&result.records, out)
            })?;
            write_atomic(&dir.join("timing.csv"), |out| {
                let mut w = csv::Writer::from_writer(out);
                w.write_record(["seed", "wall_time_ms"])?;
                for r in &result.records {
                    w.write_record([r.seed.to_string(), format!("{:.3}", r.wall_time_s * 1e3)])?;
                }
                w.flush()
            })?;
            let run = RunResult {
                records: Vec::new(),
                cancelled: result.cancelled,
                error: result.error.clone(),
                wall_time_s: result.wall_time_s,
            };
            let mut m = manifest(evaluator.config(), options, info, &run, &summary);
            m.team = Some(team.clone());
            m.write(&dir.join("summary.json"))?;
            let errors = picture_errors.into_inner().unwrap_or_default();
            match errors.first() {
                Some(first) => Err(OutputError::Episodes {
                    count: errors.len(),
                    first: first.clone(),
                }),
                None => Ok(()),
            }
        };
        write().err()
    });
    Ok(TeamEvaluation {
        result,
        team,
        summary,
        write_error,
    })
}
