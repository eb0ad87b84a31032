//! [`RunWriter`]: a locked run directory being written, made for a new run or taken up again to
//! finish one stopped short, and the run files it streams row by row until the run ends.

use super::episode_files::{remove_stale_files, write_episode_files, write_team_files};
use super::{Pictures, ResumeError, RunFiles, RunInfo, RUN_FILES};
use crate::config::ValidConfig;
use crate::eval::{EpisodeRecord, EvalOptions, Outcome, Recording, RunResult, Seeds, TeamRecord};
use crate::io::atomic::{is_temporary, remove_temporaries, write_atomic, OutputError};
use crate::io::fault::{self, Op};
use crate::io::figures::FIGURES_FILE;
use crate::io::lock::{RunLock, LOCK_FILE};
use crate::io::manifest::{ManifestError, RunManifest, RunPlan, PLAN_FILE, PLAN_SCHEMA_VERSION};
use crate::io::partial::{partial_path, whole_rows, PartialCsv};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// A run directory being written, locked against other runs for as long as this lives: made
/// (with the sub-directories its files need) for a new run, or taken up again to finish a run
/// stopped short ([`RunWriter::resume`]). Nothing already in the directory is removed or changed
/// before the first episode finishes, so a run that fails to start leaves it as it was.
#[derive(Debug)]
pub struct RunWriter {
    pub(crate) dir: PathBuf,
    pub(crate) files: RunFiles,
    first_seed: u64,
    errors: Mutex<Vec<String>>,
    front_end: serde_json::Value,
    resumed: Option<Resumed>,
    /// The directory held something (an earlier run, other files) before this run.
    held: bool,
    /// Whether the directory has been made ready for this run's files: an earlier run's
    /// pictures, step logs and GIFs removed (with the first finished episode, whichever
    /// finishes first), and its run files, summary and plan (with the first episode's rows, in
    /// seed order: a run whose first seed fails leaves them).
    ready: Mutex<Ready>,
    /// The run ended cleanly: its lock file goes with the lock.
    clean: AtomicBool,
    /// The seeds whose episodes are animated into `gif/`.
    gif_seeds: Vec<u64>,
    /// The episodes whose HTML players go into `html/`.
    players: Option<Pictures>,
    lock: Option<RunLock>,
}

impl Drop for RunWriter {
    fn drop(&mut self) {
        if let Some(lock) = self.lock.take() {
            if self.clean.load(Ordering::SeqCst) {
                lock.release();
            }
        }
    }
}

/// How far a directory was made ready for a new run's files.
#[derive(Debug, Default)]
struct Ready {
    episode_files: bool,
    run_files: bool,
}

/// What a run stopped short had finished.
#[derive(Debug)]
struct Resumed {
    /// The plan it was started with.
    plan: RunPlan,
    /// Episodes finished: the first `done` seeds.
    done: usize,
}

/// What a directory holds, for starting a run in it.
#[derive(Debug)]
enum Holding {
    /// Nothing (or only a lock file).
    Nothing,
    /// A run that finished every episode.
    Finished,
    /// A run stopped short, and how it shows.
    StoppedShort(String),
    /// A run that failed before finishing any episode: nothing to keep, replaced without asking.
    Failed,
    /// Something that is no run: the first entry found.
    Other(String),
}

impl Holding {
    fn of(dir: &Path) -> Self {
        let killed = RUN_FILES
            .iter()
            .find(|name| partial_path(&dir.join(name)).exists());
        if let Some(name) = killed {
            return Self::StoppedShort(format!(
                "{} is still there",
                partial_path(Path::new(name)).display()
            ));
        }
        if let Ok(m) = RunManifest::read(&dir.join("summary.json")) {
            return if m.interrupted {
                Self::StoppedShort("its summary.json says it was interrupted".into())
            } else if m.error.is_some() && m.summary.episodes > 0 {
                Self::StoppedShort(format!(
                    "its summary.json says it failed after {} episodes",
                    m.summary.episodes
                ))
            } else if m.error.is_some() {
                Self::Failed
            } else {
                Self::Finished
            };
        }
        if dir.join(PLAN_FILE).exists() {
            return Self::StoppedShort(format!("its {PLAN_FILE} has no summary.json beside it"));
        }
        // The lock, what a run killed while writing a file left, and the empty folders a run
        // that failed at once made, are nothing.
        let empty_folder = |e: &std::fs::DirEntry| {
            ["png", "steps", "gif", "html"]
                .iter()
                .any(|n| e.file_name() == *n)
                && std::fs::read_dir(e.path()).is_ok_and(|mut d| d.next().is_none())
        };
        let mut entries = std::fs::read_dir(dir).into_iter().flatten().flatten();
        let nothing = |e: &std::fs::DirEntry| {
            e.file_name() == LOCK_FILE
                || is_temporary(&e.file_name().to_string_lossy())
                || empty_folder(e)
        };
        // A comparison is named by its report (whatever entry comes first).
        if dir.join("compare.json").exists() {
            return Self::Other("compare.json".into());
        }
        match entries.find(|e| !nothing(e)) {
            Some(e) => Self::Other(e.file_name().to_string_lossy().into_owned()),
            None => Self::Nothing,
        }
    }
}

impl RunWriter {
    /// Makes and locks `dir` for a run whose seeds start at `first_seed`. A directory already
    /// holding something is refused unless `replace`: a finished run
    /// ([`OutputError::Finished`]), a run stopped short, whose episodes are for resuming
    /// ([`OutputError::StoppedShort`]), or files of no run ([`OutputError::NotARun`]). Replacing
    /// waits for this run's first finished episode: then the earlier run's files go (and its
    /// pictures, step logs and GIFs); nothing else in the directory is touched.
    pub fn create(
        dir: &Path,
        files: RunFiles,
        first_seed: u64,
        replace: bool,
    ) -> Result<Self, OutputError> {
        make_dir(dir)?;
        let lock = RunLock::take(dir)?;
        let holding = Holding::of(dir);
        let held = !matches!(holding, Holding::Nothing);
        let refusal = match holding {
            Holding::Nothing | Holding::Failed => None,
            _ if replace => None,
            Holding::Finished => Some(OutputError::Finished {
                dir: dir.to_path_buf(),
                file: "summary.json",
            }),
            Holding::StoppedShort(why) => Some(OutputError::StoppedShort {
                dir: dir.to_path_buf(),
                why,
            }),
            Holding::Other(file) => Some(OutputError::NotARun {
                dir: dir.to_path_buf(),
                file,
            }),
        };
        if let Some(e) = refusal {
            return Err(e);
        }
        let subs = [
            (files.pictures.is_some_and(Pictures::any), "png"),
            (files.steps, "steps"),
            (files.gifs, "gif"),
        ];
        for (wanted, sub) in subs {
            if wanted {
                make_dir(&dir.join(sub))?;
            }
        }
        Ok(Self {
            dir: dir.to_path_buf(),
            files,
            first_seed,
            errors: Mutex::new(Vec::new()),
            front_end: serde_json::Value::Null,
            resumed: None,
            held,
            ready: Mutex::new(Ready::default()),
            clean: AtomicBool::new(false),
            gif_seeds: Vec::new(),
            players: None,
            lock: Some(lock),
        })
    }

    /// Makes the directory ready for this run's per-episode files, once: a new run removes an
    /// earlier run's pictures, step logs and GIFs there; a resumed run keeps everything.
    pub(crate) fn make_ready(&self) -> Result<(), OutputError> {
        let mut ready = self.ready.lock().unwrap_or_else(|e| e.into_inner());
        if !ready.episode_files && self.resumed.is_none() && self.held {
            remove_stale_files(&self.dir)?;
        }
        ready.episode_files = true;
        Ok(())
    }

    /// Makes the directory ready for this run's run files, once (and for its per-episode
    /// files): a new run removes an earlier run's summary first, then its run files, then its
    /// plan, so a directory stopped half-way through never shows a finished run without its
    /// episodes.
    fn make_ready_for_rows(&self) -> Result<(), OutputError> {
        self.make_ready()?;
        let mut ready = self.ready.lock().unwrap_or_else(|e| e.into_inner());
        if !ready.run_files && self.resumed.is_none() && self.held {
            remove_if_there(&self.dir.join("summary.json"))?;
            for name in RUN_FILES.iter().chain(&[PLAN_FILE]) {
                let path = self.dir.join(name);
                remove_if_there(&path)?;
                remove_if_there(&partial_path(&path))?;
            }
        }
        ready.run_files = true;
        Ok(())
    }

    /// Locks `dir`, a run stopped short (killed, interrupted or out of disk), to finish it: reads
    /// its plan (`run.json`) and counts the episodes it finished (the whole rows every one of its
    /// run files holds; a row torn by a crash is dropped). The caller rebuilds the run from the
    /// plan and hands this writer to [`crate::job::evaluate_into`] or
    /// [`crate::job::evaluate_team_into`], which run only the seeds left. Pictures and step logs
    /// already written are kept.
    pub fn resume(dir: &Path) -> Result<(Self, RunPlan), ResumeError> {
        let plan_path = dir.join(PLAN_FILE);
        // Nothing is changed before the first episode of the rest finishes: a resume that fails
        // to start leaves the directory as it was.
        if !dir.is_dir() {
            return Err(ResumeError::NoRun {
                dir: dir.to_path_buf(),
                why: "no such directory".into(),
            });
        }
        if !plan_path.exists() {
            return Err(ResumeError::NoRun {
                dir: dir.to_path_buf(),
                why: format!(
                    "it has no {PLAN_FILE} (runs of older ronap versions cannot be resumed)"
                ),
            });
        }
        let lock = RunLock::take(dir)?;
        let plan = RunPlan::read(&plan_path)?;
        let seeds = plan.seeds().len();
        let summary = dir.join("summary.json");
        let stopped_short = RUN_FILES
            .iter()
            .any(|name| partial_path(&dir.join(name)).exists())
            || !summary.exists()
            || RunManifest::read(&summary).map_or(true, |m| m.interrupted || m.error.is_some());
        if !stopped_short {
            // A run killed after its summary but before its last clean-up: finish that.
            remove_if_there(&dir.join(FIGURES_FILE))?;
            lock.release();
            return Err(ResumeError::Complete {
                dir: dir.to_path_buf(),
                episodes: seeds,
            });
        }
        let team = plan
            .config
            .robots
            .iter()
            .map(|r| r.count as usize)
            .sum::<usize>();
        let mut done = seeds;
        let mut files = Vec::new();
        for (name, per_episode) in [
            ("episodes.csv", 1),
            ("timing.csv", 1),
            ("robots.csv", team),
            (FIGURES_FILE, 1),
        ] {
            if per_episode == 0 {
                continue;
            }
            let path = dir.join(name);
            let partial = partial_path(&path);
            let at = if partial.exists() { partial } else { path };
            let rows = whole_rows(&at)?.saturating_sub(1);
            done = done.min(rows / per_episode);
            files.push((at, per_episode));
        }
        check_rows(&files, &plan.seeds(), done).map_err(|why| ResumeError::NoRun {
            dir: dir.to_path_buf(),
            why,
        })?;
        let files = RunFiles {
            pictures: plan
                .pictures
                .as_deref()
                .map(str::parse)
                .transpose()
                .map_err(|message: String| {
                    ResumeError::Plan(ManifestError::Format {
                        path: plan_path.clone(),
                        message: format!("`pictures`: {message}"),
                    })
                })?,
            steps: plan.steps,
            gifs: plan.gifs,
        };
        let writer = Self {
            dir: dir.to_path_buf(),
            files,
            first_seed: plan.seeds().first().unwrap_or(0),
            errors: Mutex::new(Vec::new()),
            front_end: plan.front_end.clone(),
            resumed: Some(Resumed {
                plan: plan.clone(),
                done,
            }),
            held: true,
            ready: Mutex::new(Ready::default()),
            clean: AtomicBool::new(false),
            gif_seeds: Vec::new(),
            players: None,
            lock: Some(lock),
        };
        Ok((writer, plan))
    }

    /// Animates the episodes of `seeds` into `gif/seed-SEED-OUTCOME.gif` as they finish
    /// ([`crate::job::evaluate_into`] and [`crate::job::evaluate_team_into`] record their steps).
    pub fn animating(mut self, seeds: Vec<u64>) -> Result<Self, OutputError> {
        if !seeds.is_empty() {
            make_dir(&self.dir.join("gif"))?;
            self.files.gifs = true;
        }
        self.gif_seeds = seeds;
        Ok(self)
    }

    /// The seeds whose episodes are animated.
    pub fn gif_seeds(&self) -> &[u64] {
        &self.gif_seeds
    }

    /// Writes the animation of episode `seed`, which ended as `outcome` (`bytes`, a GIF, or why
    /// it could not be drawn); a failure is kept for the end, as [`RunWriter::episode`] does.
    pub fn animation(&self, seed: u64, outcome: Outcome, bytes: Result<&[u8], String>) {
        self.episode_file(("gif", "gif"), seed, outcome, bytes);
    }

    /// Writes `folder/seed-SEED-OUTCOME.extension` (`bytes`, or why they could not be made),
    /// keeping a failure for the end.
    fn episode_file(
        &self,
        (folder, extension): (&str, &str),
        seed: u64,
        outcome: Outcome,
        bytes: Result<&[u8], String>,
    ) {
        let path = self
            .dir
            .join(folder)
            .join(format!("seed-{seed:06}-{}.{extension}", outcome.name()));
        let written = match bytes {
            Ok(b) => self
                .make_ready()
                .and_then(|()| write_atomic(&path, |w| w.write_all(b))),
            Err(message) => Err(OutputError::Format { path, message }),
        };
        if let Err(e) = written {
            self.note(e);
        }
    }

    /// Writes an HTML player of each episode `players` chooses into
    /// `html/seed-SEED-OUTCOME.html` as it finishes ([`crate::job::evaluate_into`] and
    /// [`crate::job::evaluate_team_into`] record their steps).
    pub fn playing(mut self, players: Option<Pictures>) -> Result<Self, OutputError> {
        if players.is_some_and(Pictures::any) {
            make_dir(&self.dir.join("html"))?;
        }
        self.players = players;
        Ok(self)
    }

    /// The episodes that get a player.
    pub fn players(&self) -> Option<Pictures> {
        self.players
    }

    /// Whether episode `seed`, which ended as `outcome`, gets a player.
    pub fn wants_player(&self, seed: u64, outcome: Outcome) -> bool {
        self.players
            .is_some_and(|p| p.wants_seed(seed, outcome, self.first_seed))
    }

    /// Writes the player of episode `seed`, which ended as `outcome` (`page`, its HTML, or why it
    /// could not be made); a failure is kept for the end, as [`RunWriter::episode`] does.
    pub fn player(&self, seed: u64, outcome: Outcome, page: Result<&[u8], String>) {
        self.episode_file(("html", "html"), seed, outcome, page);
    }

    /// Records the front end's own options in the run's plan, for a later `--resume`.
    pub fn with_front_end(mut self, options: serde_json::Value) -> Self {
        self.front_end = options;
        self
    }

    /// The directory.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// The episodes a resumed run had finished (0 for a new run).
    pub fn done(&self) -> usize {
        self.resumed.as_ref().map_or(0, |r| r.done)
    }

    /// What the evaluator must keep of each episode for this writer's files.
    pub fn recording(&self) -> Recording {
        Recording {
            trajectory: self.files.pictures.is_some(),
            steps: self.files.steps,
        }
    }

    /// Writes the per-episode files of `record`; a failure is kept for the end so the run goes
    /// on (and its other results are saved).
    pub fn episode(&self, record: &EpisodeRecord) {
        if let Err(e) = self.make_ready() {
            return self.note(e);
        }
        let picture = self
            .files
            .pictures
            .is_some_and(|p| p.wants(record, self.first_seed));
        if let Err(e) = write_episode_files(&self.dir, record, picture, self.files.steps) {
            self.note(e);
        }
    }

    /// Writes the per-episode files of team episode `record` (its picture; when the run writes
    /// step logs, one per robot, `steps/seed-SEED-robot-K.csv`); a failure is kept for the end,
    /// as [`RunWriter::episode`] does.
    pub fn team_episode(&self, record: &TeamRecord) {
        if let Err(e) = self.make_ready() {
            return self.note(e);
        }
        let picture = self
            .files
            .pictures
            .is_some_and(|p| p.wants_seed(record.seed, record.outcome, self.first_seed));
        if let Err(e) = write_team_files(&self.dir, record, picture, self.files.steps) {
            self.note(e);
        }
    }

    pub(crate) fn note(&self, e: OutputError) {
        if let Ok(mut all) = self.errors.lock() {
            all.push(e.to_string());
        }
    }

    /// The plan of this run: the resumed run's own, else one made of what it is.
    pub(crate) fn plan(
        &self,
        config: &ValidConfig,
        options: &EvalOptions,
        info: &RunInfo,
    ) -> RunPlan {
        if let Some(r) = &self.resumed {
            return r.plan.clone();
        }
        let first = options.seeds.first().unwrap_or(0);
        let count = options.seeds.len() as u64;
        let range = matches!(options.seeds, Seeds::Range { .. })
            || options
                .seeds
                .iter()
                .enumerate()
                .all(|(i, s)| Some(s) == first.checked_add(i as u64));
        RunPlan {
            schema_version: PLAN_SCHEMA_VERSION,
            ronap_version: env!("CARGO_PKG_VERSION").to_string(),
            model_version: crate::MODEL_VERSION,
            policy: info.policy.clone(),
            seed_start: first,
            seeds_requested: count,
            seeds: (!range).then(|| options.seeds.iter().collect()),
            threads: options.threads,
            scenes: info.scenes.clone(),
            map: info.map.clone(),
            pictures: self.files.pictures.map(|p| p.to_string()),
            steps: self.files.steps,
            gifs: self.files.gifs,
            front_end: self.front_end.clone(),
            config: config.as_sim_config().clone(),
        }
    }

    /// The run files, to be opened (`headers[k]` for `RUN_FILES[k]`; `None`: not written) when
    /// the first episode's rows come: the plan written first for a new run, or the files
    /// reopened after the finished episodes for a resumed one.
    pub(crate) fn open(&self, plan: &RunPlan, headers: [Option<Vec<String>>; 4]) -> Streams {
        Streams {
            files: Vec::new(),
            flushed: Instant::now(),
            pending: Some((plan.clone(), headers)),
        }
    }

    /// Opens the run files [`RunWriter::open`] set up.
    fn open_now(
        &self,
        plan: &RunPlan,
        headers: [Option<Vec<String>>; 4],
    ) -> Result<Vec<PartialCsv>, OutputError> {
        self.make_ready_for_rows()?;
        let done = self.done();
        if self.resumed.is_none() {
            plan.write(&self.dir.join(PLAN_FILE))?;
        }
        let team: usize = plan.config.robots.iter().map(|r| r.count as usize).sum();
        let mut files = Vec::new();
        for (name, header) in RUN_FILES.iter().zip(headers) {
            let Some(header) = header else { continue };
            let header: Vec<&str> = header.iter().map(String::as_str).collect();
            let path = self.dir.join(name);
            let rows = if *name == "robots.csv" {
                done * team
            } else {
                done
            };
            files.push(if self.resumed.is_some() {
                PartialCsv::reopen(&path, &header, rows)?
            } else {
                PartialCsv::create(&path, &header)?
            });
        }
        Ok(files)
    }

    /// The errors of per-episode files, as one.
    pub(crate) fn episode_errors(&self) -> Option<OutputError> {
        let errors = self
            .errors
            .lock()
            .map(|mut e| std::mem::take(&mut *e))
            .unwrap_or_default();
        errors.first().map(|first| OutputError::Episodes {
            count: errors.len(),
            first: first.clone(),
        })
    }
}

/// Makes `dir` and its parents.
fn make_dir(dir: &Path) -> Result<(), OutputError> {
    if dir.exists() && !dir.is_dir() {
        return Err(OutputError::Io {
            path: dir.to_path_buf(),
            source: std::io::Error::other("it is a file, not a directory"),
        });
    }
    let made = fault::check(Op::Create).and_then(|()| std::fs::create_dir_all(dir));
    made.map_err(|source| OutputError::Io {
        path: dir.to_path_buf(),
        source,
    })
}

/// Removes `path` if it is there.
fn remove_if_there(path: &Path) -> Result<(), OutputError> {
    match fault::check(Op::Remove).and_then(|()| std::fs::remove_file(path)) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => Err(OutputError::Io {
            path: path.to_path_buf(),
            source: e,
        }),
        _ => Ok(()),
    }
}

/// The run files under way, in the order of [`RUN_FILES`] (those the run writes), opened with
/// the first episode's rows.
#[derive(Debug)]
pub(crate) struct Streams {
    files: Vec<PartialCsv>,
    flushed: Instant,
    /// The plan and headers, until the files are opened.
    pending: Option<(RunPlan, [Option<Vec<String>>; 4])>,
}

impl Streams {
    /// How often what is buffered goes to the files, so a killed run loses at most this much.
    const FLUSH_EVERY: Duration = Duration::from_secs(1);

    /// Opens the files, if not yet.
    fn ensure_open(&mut self, writer: &RunWriter) -> Result<(), OutputError> {
        if let Some((plan, headers)) = &self.pending {
            self.files = writer.open_now(plan, headers.clone())?;
            self.pending = None;
        }
        Ok(())
    }

    /// Adds one episode's rows (`rows[k]` to file `k`).
    pub(crate) fn add(
        &mut self,
        writer: &RunWriter,
        rows: &[Vec<Vec<String>>],
    ) -> Result<(), OutputError> {
        self.ensure_open(writer)?;
        for (file, rows) in self.files.iter_mut().zip(rows) {
            for row in rows {
                file.row(row)?;
            }
        }
        if self.flushed.elapsed() >= Self::FLUSH_EVERY {
            for file in &mut self.files {
                file.flush()?;
            }
            self.flushed = Instant::now();
        }
        Ok(())
    }

    /// Renames the files to their final names.
    fn finish(self) -> Result<(), OutputError> {
        for file in self.files {
            file.finish()?;
        }
        Ok(())
    }
}

/// Ends a run's files: the run files to their final names, then `summary.json`, then whether
/// any per-episode file failed. A run that changed nothing (no episode finished) and did not
/// complete leaves a directory that held something as it was, writing nothing.
pub(crate) fn finish(
    writer: &RunWriter,
    streams: Option<Streams>,
    manifest: &RunManifest,
    result: &RunResult,
) -> Result<(), OutputError> {
    let complete = !result.cancelled && result.error.is_none();
    if let Some(mut s) = streams {
        if s.pending.is_some() && writer.held && !complete {
            // Nothing of this run reached the run files: the directory keeps what it held (its
            // lock file too, as it was).
            return Ok(());
        }
        s.ensure_open(writer)?;
        s.finish()?;
    }
    manifest.write(&writer.dir.join("summary.json"))?;
    // The exact figures stay for a later `--resume` of a run stopped short; a complete run's
    // summary holds what they made (a run stopped by this removal failing resumes to the end).
    if complete {
        remove_if_there(&writer.dir.join(FIGURES_FILE))?;
        // What a run killed while writing a file left (this run's own files are whole).
        for sub in ["", "png", "steps", "gif", "html"] {
            remove_temporaries(&writer.dir.join(sub))?;
        }
    }
    match writer.episode_errors() {
        Some(e) => Err(e),
        None => {
            writer.clean.store(true, Ordering::SeqCst);
            Ok(())
        }
    }
}

/// Checks the rows a resumed run keeps (`done` episodes' worth of each of `files`, with the rows
/// an episode has in each): each row's seed is the run's seed of its place, in order, and
/// `episodes.csv` and the exact figures (the summary is made from them) give each episode the
/// same outcome. A file edited by hand, or holding another run's rows, would otherwise be
/// finished into a run whose rows and summary disagree. Says what is wrong (file, line, value).
fn check_rows(files: &[(PathBuf, usize)], seeds: &Seeds, done: usize) -> Result<(), String> {
    let mut outcomes: Vec<(&PathBuf, Vec<String>)> = Vec::new();
    for (path, per_episode) in files {
        let rows = seeds_and_outcomes(path, done * per_episode)?;
        for (i, (seed, _)) in rows.iter().enumerate() {
            let expected = seeds.get(i / per_episode);
            if expected != Some(*seed) {
                return Err(format!(
                    "{}: line {}: seed {seed} where the run's seed {} belongs: the file was \
                     edited or holds another run's rows; start the run again (--force)",
                    path.display(),
                    i + 2,
                    expected.map_or("(none)".to_string(), |s| s.to_string()),
                ));
            }
        }
        // The two files that give each episode's outcome (a team's robots.csv gives each
        // robot's, even for a team of one).
        let name = path.file_name().unwrap_or_default().to_string_lossy();
        if name.starts_with("episodes.csv") || name.starts_with(FIGURES_FILE) {
            let mut kept = Vec::with_capacity(rows.len());
            for (i, (_, outcome)) in rows.into_iter().enumerate() {
                let Some(outcome) = outcome else {
                    return Err(format!("{}: line {}: no outcome", path.display(), i + 2));
                };
                kept.push(outcome);
            }
            outcomes.push((path, kept));
        }
    }
    if let [(a, first), (b, second)] = &outcomes[..] {
        if let Some(i) = (0..first.len().min(second.len())).find(|&i| first[i] != second[i]) {
            return Err(format!(
                "{}: line {}: outcome {} where {} says {}: the files disagree; start the run \
                 again (--force)",
                a.display(),
                i + 2,
                first[i],
                b.display(),
                second[i]
            ));
        }
    }
    Ok(())
}

/// The seed and outcome (`None` in a file without that column) of each of the first `rows`
/// rows of the CSV file `path` (none when `rows` is 0: the file may not have been begun).
fn seeds_and_outcomes(path: &Path, rows: usize) -> Result<Vec<(u64, Option<String>)>, String> {
    if rows == 0 {
        return Ok(Vec::new());
    }
    let what = |e: &dyn std::fmt::Display| format!("{}: {e}", path.display());
    let mut reader = csv::ReaderBuilder::new()
        .flexible(true)
        .from_path(path)
        .map_err(|e| what(&e))?;
    let headers = reader.headers().map_err(|e| what(&e))?.clone();
    let column = |name: &str| headers.iter().position(|h| h == name);
    let seed = column("seed").ok_or_else(|| what(&"no seed column"))?;
    let outcome = column("outcome");
    let mut out = Vec::with_capacity(rows);
    for (i, record) in reader.records().take(rows).enumerate() {
        let record = record.map_err(|e| what(&e))?;
        let cell = record.get(seed).unwrap_or("");
        let value = cell.parse().map_err(|_| {
            format!(
                "{}: line {}: seed = {cell:?} is not a seed",
                path.display(),
                i + 2
            )
        })?;
        out.push((
            value,
            outcome.and_then(|k| record.get(k)).map(str::to_string),
        ));
    }
    Ok(out)
}
