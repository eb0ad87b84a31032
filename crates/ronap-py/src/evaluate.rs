//! `evaluate()`: the core's run-into-a-directory use-case with a built-in policy or a Python
//! callable.

use crate::conv::{self, Config};
use crate::errors;
use crate::kwargs::Options;
use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use ronap_core::eval::{EvalOptions, Evaluator, TeamRecord};
use ronap_core::io::{
    robot_columns, robot_rows, team_episode_row, BlockRun, EpisodeRows, Layout, Pictures, RunFiles,
    RunInfo, RunWriter, TEAM_COLUMNS,
};
use ronap_core::job::{evaluate_into, evaluate_team_into, RunRequest};
use ronap_core::policy::{
    coordinated_drives, BatchPolicy, Batched, CoordinatedFactory, Decision, JointFactory, Policy,
    PolicyError, PolicyFactory, Rows, TeamPolicyFactory,
};
use ronap_core::sim::{continuous_action, Scenes};
use ronap_core::{Action, Episode, ValidConfig, World};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Condvar, Mutex};

/// One call at a time into a policy that is not known to be thread-safe.
///
/// A Python policy can release the GIL inside a call (torch does, in every forward pass), so the
/// GIL alone does not keep two workers out of it; a policy with state (SB3's `predict`) then gives
/// wrong actions. Waiting for the turn happens with the GIL released, so the holder can finish.
#[derive(Default)]
struct Turn {
    busy: Mutex<bool>,
    free: Condvar,
}

impl Turn {
    fn take(&self, py: Python<'_>) {
        py.allow_threads(|| {
            let mut busy = self.busy.lock().unwrap_or_else(|e| e.into_inner());
            while *busy {
                busy = self.free.wait(busy).unwrap_or_else(|e| e.into_inner());
            }
            *busy = true;
        });
    }

    fn give_back(&self) {
        *self.busy.lock().unwrap_or_else(|e| e.into_inner()) = false;
        self.free.notify_one();
    }
}

/// A Python callable as a policy: observation (a float32 array) in, action out.
struct PyPolicy {
    callable: Py<PyAny>,
    continuous: bool,
    /// Shared by every worker's copy of the policy; `None` for a thread-safe policy.
    turn: Option<Arc<Turn>>,
}

impl PyPolicy {
    /// Calls the policy on `episode`'s observation, in its turn.
    fn call(&self, py: Python<'_>, episode: &Episode) -> PyResult<PyObject> {
        let obs = PyArray1::from_slice(py, episode.observation());
        let Some(turn) = &self.turn else {
            return self.callable.call1(py, (obs,));
        };
        turn.take(py);
        let value = self.callable.call1(py, (obs,));
        turn.give_back();
        value
    }
}

impl Policy for PyPolicy {
    fn reset(&mut self, _world: &World, _episode: &Episode) -> Result<(), PolicyError> {
        Ok(())
    }

    fn act(&mut self, episode: &Episode) -> Result<Decision, PolicyError> {
        Python::with_gil(|py| {
            let value = self.call(py, episode).map_err(|e| {
                PolicyError::Failed(format!(
                    "raised {}",
                    e.value(py)
                        .repr()
                        .map_or_else(|_| e.to_string(), |r| r.to_string())
                ))
            })?;
            let robot = &episode.config().robot;
            conv::policy_action(value.bind(py), self.continuous.then_some(robot))
                // Continuous policies answer in [-1, 1], as NavEnv's action space.
                .map(|a| a.scaled(&robot.action_scale()))
                .map(Decision::Act)
                .map_err(PolicyError::Failed)
        })
    }
}

struct PyPolicyFactory {
    callable: Py<PyAny>,
    continuous: bool,
    name: String,
    turn: Option<Arc<Turn>>,
}

impl PolicyFactory for PyPolicyFactory {
    fn make(&self) -> Result<Box<dyn Policy>, PolicyError> {
        let callable = Python::with_gil(|py| self.callable.clone_ref(py));
        Ok(Box::new(PyPolicy {
            callable,
            continuous: self.continuous,
            turn: self.turn.clone(),
        }))
    }

    fn name(&self) -> String {
        self.name.clone()
    }
}

/// A Python callable that decides for many observations at once: an `(n, width)` float32 array
/// in, `n` actions out (or `(n, k)` normalised speeds when continuous, `k` the robot's
/// continuous action size).
struct PyBatchPolicy {
    callable: Py<PyAny>,
    continuous: bool,
    /// `ronap.env.discrete_actions` or `continuous_actions`: the returned actions as a checked
    /// array, or an `ActionError` naming what is wrong.
    check: Py<PyAny>,
    /// The robot, whose full speeds the normalised continuous actions scale to.
    robot: ronap_core::config::RobotConfig,
}

impl PyBatchPolicy {
    /// `callable` deciding for rows of observations, its actions checked as `continuous` or
    /// discrete ones, normalised continuous ones scaled to `robot`'s full speeds.
    fn new(
        callable: &Bound<'_, PyAny>,
        continuous: bool,
        robot: &ronap_core::config::RobotConfig,
    ) -> PyResult<Self> {
        let check = callable
            .py()
            .import("ronap.env")?
            .getattr(if continuous {
                "continuous_actions"
            } else {
                "discrete_actions"
            })?
            .unbind();
        Ok(Self {
            callable: callable.clone().unbind(),
            continuous,
            check,
            robot: robot.clone(),
        })
    }

    fn decide(&self, py: Python<'_>, batch: Rows<'_>, out: &mut Vec<Action>) -> Result<(), String> {
        let rows = batch.count();
        let obs = PyArray1::from_slice(py, batch.values)
            .reshape([rows, batch.width])
            .map_err(|e| e.to_string())?;
        let raised = |e: PyErr| {
            format!(
                "raised {}",
                e.value(py)
                    .repr()
                    .map_or_else(|_| e.to_string(), |r| r.to_string())
            )
        };
        let value = self.callable.call1(py, (obs,)).map_err(raised)?;
        let shown = || {
            let text = value.bind(py).to_string();
            if text.chars().count() > 80 {
                format!("{}...", text.chars().take(80).collect::<String>())
            } else {
                text
            }
        };
        // The returned actions as an array of `shape`, checked.
        let checked = |shape: &[usize]| {
            let shape = pyo3::types::PyTuple::new(py, shape).map_err(|e| e.to_string())?;
            self.check
                .bind(py)
                .call1((value.bind(py), shape))
                .map_err(|e| format!("returned {}: {}", shown(), e.value(py)))
        };
        if self.continuous {
            let scale = self.robot.action_scale();
            let array = checked(&[rows, scale.len()])?;
            let values: Vec<f64> = array
                .call_method0("ravel")
                .and_then(|a| a.extract())
                .map_err(|e| e.to_string())?;
            for (row, v) in values.chunks(scale.len()).enumerate() {
                let action = continuous_action(&self.robot, v).ok_or_else(|| {
                    format!("returned action {v:?} for row {row}: expected finite numbers")
                })?;
                out.push(action.scaled(&scale));
            }
        } else {
            let array = checked(&[rows])?;
            let indices: Vec<i64> = array.extract().map_err(|e| e.to_string())?;
            for (row, &i) in indices.iter().enumerate() {
                out.push(conv::discrete(i).ok_or_else(|| {
                    format!(
                        "returned action {i} for row {row}: expected 0 (LEFT), 1 (AHEAD) or \
                         2 (RIGHT)"
                    )
                })?);
            }
        }
        Ok(())
    }
}

impl BatchPolicy for PyBatchPolicy {
    fn act_batch(&mut self, rows: Rows<'_>, actions: &mut Vec<Action>) -> Result<(), PolicyError> {
        Python::with_gil(|py| self.decide(py, rows, actions)).map_err(PolicyError::Failed)
    }
}

/// The policy `policy` names or is: a built-in or network name, or a callable (observation ->
/// action), with the name reports give it.
fn policy_factory(
    policy: &Bound<'_, PyAny>,
    config: &ronap_core::ValidConfig,
    continuous: bool,
    thread_safe: bool,
) -> PyResult<(Box<dyn PolicyFactory>, String)> {
    Ok(if let Ok(name) = policy.extract::<String>() {
        let factory = ronap_core::policy::factory(&name, config.observation_size())
            .map_err(|e| errors::ConfigError::new_err(e.to_string()))?;
        (factory, name)
    } else if policy.is_callable() {
        let name = policy_name(policy);
        let factory = PyPolicyFactory {
            callable: policy.clone().unbind(),
            continuous,
            name: name.clone(),
            turn: (!thread_safe).then(|| Arc::new(Turn::default())),
        };
        (Box::new(factory), name)
    } else {
        return Err(errors::ConfigError::new_err(format!(
            "policy {policy}: expected a built-in policy name or a callable (observation -> \
                 action)"
        )));
    })
}

/// Runs `policy` (a built-in name or a callable) over `seeds`; returns {"summary": ...,
/// "episodes": [...]} with the figures and rows `ronap run` reports, and writes its files (the
/// same files, `summary.json` in the same schema) into `out` when given.
#[pyfunction]
#[pyo3(signature = (policy, seeds, config, **options))]
pub fn evaluate<'py>(
    py: Python<'py>,
    policy: &Bound<'py, PyAny>,
    seeds: Vec<u64>,
    config: &Config,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyDict>> {
    // maze_seed, map_path, threads, continuous, out, png, log_steps, thread_safe, batch, rows and
    // force, as ronap.evaluate names them.
    let o = Options::new("evaluate", options);
    let (maze_seed, map_path, threads) = o.scene_and_threads()?;
    let continuous: bool = o.take("continuous", false)?;
    let out: Option<std::path::PathBuf> = o.take("out", None)?;
    let png: Option<String> = o.take("png", None)?;
    let log_steps: bool = o.take("log_steps", false)?;
    let thread_safe: bool = o.take("thread_safe", false)?;
    let batch: usize = o.take("batch", 0)?;
    let rows: bool = o.take("rows", false)?;
    let force: bool = o.take("force", false)?;
    o.finish()?;
    let config = config.valid();
    let run = Run {
        first: first_seed(&seeds)?,
        maze_seed,
        map_path: map_path.as_deref(),
        // A batch of N is N episodes under way, a worker each.
        threads: if batch > 0 { batch } else { threads },
        out: out.as_deref(),
        png,
        log_steps,
        force,
    };
    if config.team_size() > 0 {
        if batch > 0 {
            return Err(errors::ConfigError::new_err(format!(
                "batch = {batch}: a team's callable already decides for every robot at once"
            )));
        }
        return evaluate_team(py, policy, seeds, config, continuous, &run);
    }
    let (factory, name) = if batch > 0 {
        if !policy.is_callable() || policy.extract::<String>().is_ok() {
            return Err(errors::ConfigError::new_err(format!(
                "batch = {batch}: batches are for Python callables; {policy} runs in Rust already"
            )));
        }
        let name = policy_name(policy);
        let decide = PyBatchPolicy::new(policy, continuous, &config.robot)?;
        let factory: Box<dyn PolicyFactory> =
            Box::new(Batched::new(Box::new(decide), batch, name.clone()));
        (factory, name)
    } else {
        policy_factory(policy, config, continuous, thread_safe)?
    };
    warn_if_not_held_out(py, &name, factory.as_ref(), &seeds)?;
    let mut prepared = run.prepare(name, config, seeds)?;
    let cancel = AtomicBool::new(false);
    let interrupt = Interrupt::here();
    let evaluation = py
        .allow_threads(|| {
            let keep = |_: &_| {
                interrupt.watch(&cancel);
                true
            };
            evaluate_into(prepared.request(&cancel), factory.as_ref(), &|_| {}, &keep)
        })
        .map_err(|e| errors::PolicyError::new_err(e.to_string()))?;
    let d = interrupt.finish(py, &evaluation)?;
    let episodes = PyList::empty(py);
    let metrics = ronap_core::eval::metric_kinds(config);
    for r in &evaluation.result.records {
        episodes.append(conv::record(py, r, metrics)?)?;
    }
    d.set_item("episodes", episodes)?;
    if rows {
        let layout = Layout::of(config);
        let all = PyList::empty(py);
        for r in &evaluation.result.records {
            let e = EpisodeRows::of(r, layout);
            all.append((e.seed, e.episode, e.timing, e.figures))?;
        }
        d.set_item("rows", all)?;
    }
    Ok(d)
}

/// How a run of [`evaluate`] runs and what it writes (as its options name them).
struct Run<'a> {
    /// The first seed (where a resumed run's files start).
    first: u64,
    maze_seed: Option<u64>,
    map_path: Option<&'a str>,
    threads: usize,
    out: Option<&'a std::path::Path>,
    png: Option<String>,
    log_steps: bool,
    force: bool,
}

/// A run ready to go: what its files record, its writer (given `out`), evaluator and options.
struct Prepared {
    info: RunInfo,
    writer: Option<RunWriter>,
    evaluator: Evaluator,
    options: EvalOptions,
}

impl Run<'_> {
    /// The run of the policy reports call `name` over `seeds` under `config`.
    fn prepare(&self, name: String, config: &ValidConfig, seeds: Vec<u64>) -> PyResult<Prepared> {
        let pictures: Option<Pictures> = self
            .png
            .as_deref()
            .map(str::parse)
            .transpose()
            .map_err(|e| errors::ConfigError::new_err(format!("png = {e}")))?;
        let (info, scenes) = run_info(name, config, self.maze_seed, self.map_path)?;
        let writer = self
            .out
            .map(|dir| {
                let files = RunFiles {
                    pictures,
                    steps: self.log_steps,
                    gifs: false,
                };
                RunWriter::create(dir, files, self.first, self.force).map_err(errors::out_dir)
            })
            .transpose()?;
        Ok(Prepared {
            info,
            writer,
            evaluator: Evaluator::new(config.clone(), scenes),
            options: EvalOptions {
                seeds: seeds.into(),
                threads: self.threads,
                ..EvalOptions::default()
            },
        })
    }
}

impl Prepared {
    /// The request that runs it (its writer handed over), stopped by `cancel`.
    fn request<'a>(&'a mut self, cancel: &'a AtomicBool) -> RunRequest<'a> {
        RunRequest {
            evaluator: &self.evaluator,
            options: &self.options,
            info: &self.info,
            writer: self.writer.take(),
            cancel,
        }
    }
}

/// A Ctrl-C (Python's KeyboardInterrupt) stops a run as `ronap run`'s does: the episodes under
/// way finish, the files are written, then the interrupt is raised. Python hears signals on its
/// main thread, which takes the records in seed order ([`Interrupt::watch`] from `keep`).
struct Interrupt {
    main: std::thread::ThreadId,
    caught: Mutex<Option<PyErr>>,
}

impl Interrupt {
    /// Watching for signals on this thread.
    fn here() -> Self {
        Self {
            main: std::thread::current().id(),
            caught: Mutex::new(None),
        }
    }

    /// On the main thread: a pending signal's error, kept, cancels the run.
    fn watch(&self, cancel: &AtomicBool) {
        if std::thread::current().id() == self.main && !cancel.load(Ordering::SeqCst) {
            if let Err(e) = Python::with_gil(|py| py.check_signals()) {
                cancel.store(true, Ordering::SeqCst);
                if let Ok(mut i) = self.caught.lock() {
                    *i = Some(e);
                }
            }
        }
    }

    /// The error of the signal that stopped the run, if one did.
    fn raise(self) -> PyResult<()> {
        match self.caught.into_inner().ok().flatten() {
            Some(e) => Err(e),
            None => Ok(()),
        }
    }

    /// How a finished run ends for Python, in order: its files could not be written, a signal
    /// stopped it (once its files were written), an episode failed; else the dict [`evaluate`]
    /// returns, its "summary" in.
    fn finish<'py>(self, py: Python<'py>, ended: &impl Ended) -> PyResult<Bound<'py, PyDict>> {
        let (write_error, run_error, summary) = ended.ended();
        if let Some(e) = write_error {
            return Err(errors::output(e));
        }
        self.raise()?;
        if let Some(e) = run_error {
            return Err(errors::run(e));
        }
        let d = PyDict::new(py);
        let summary = serde_json::to_value(summary).unwrap_or_default();
        d.set_item("summary", conv::json(py, &summary)?)?;
        Ok(d)
    }
}

/// A finished evaluation's files' write error, its failed episode's error and the robots'
/// summary.
type Ends<'a> = (
    Option<&'a ronap_core::io::OutputError>,
    Option<&'a ronap_core::run::RunError>,
    &'a ronap_core::eval::Summary,
);

/// A finished evaluation, one robot's or a team's, as [`Interrupt::finish`] reads it.
trait Ended {
    /// How it ended.
    fn ended(&self) -> Ends<'_>;
}

impl Ended for ronap_core::job::Evaluation {
    fn ended(&self) -> Ends<'_> {
        (
            self.write_error.as_ref(),
            self.result.error.as_ref(),
            &self.summary,
        )
    }
}

impl Ended for ronap_core::job::TeamEvaluation {
    fn ended(&self) -> Ends<'_> {
        (
            self.write_error.as_ref(),
            self.result.error.as_ref(),
            &self.summary,
        )
    }
}

/// The team policy `policy` names or is, with the name reports give it: `coordinated`, another
/// built-in or network name for the robots whose entries name none (entries that name one keep
/// it), or a callable deciding for every robot at once (a `(robots, observation size)` array of
/// the running robots' observations in, one action per row out).
fn team_factory(
    policy: &Bound<'_, PyAny>,
    config: &ValidConfig,
    continuous: bool,
) -> PyResult<(Box<dyn TeamPolicyFactory>, String)> {
    let n = config.team_size();
    if let Ok(name) = policy.extract::<String>() {
        if coordinated_drives(config, &name).map_err(errors::ConfigError::new_err)? {
            return Ok((Box::new(CoordinatedFactory::new(n)), name));
        }
        let mut factories: Vec<Box<dyn PolicyFactory>> = Vec::new();
        let mut names = Vec::new();
        let mut of_robot = Vec::new();
        for (i, entry) in config.robots.iter().enumerate() {
            let own = entry.policy.clone().unwrap_or_else(|| name.clone());
            let factory = ronap_core::policy::factory(
                &own,
                config.team_robot(names.len()).observation_size(),
            )
            .map_err(|e| errors::ConfigError::new_err(format!("robots[{i}]: {e}")))?;
            factories.push(factory);
            for _ in 0..entry.count {
                names.push(own.clone());
                of_robot.push(factories.len() - 1);
            }
        }
        return Ok((
            Box::new(Owned {
                factories,
                of_robot,
                names,
            }),
            name,
        ));
    }
    if !policy.is_callable() {
        return Err(errors::ConfigError::new_err(format!(
            "policy {policy}: expected a built-in policy name or a callable (the robots' \
             observations -> their actions)"
        )));
    }
    let name = policy_name(policy);
    let decide = PyBatchPolicy::new(policy, continuous, &config.team_robot(0).robot)?;
    let make = move || -> Result<Box<dyn BatchPolicy>, PolicyError> {
        Ok(Python::with_gil(|py| {
            Box::new(PyBatchPolicy {
                callable: decide.callable.clone_ref(py),
                check: decide.check.clone_ref(py),
                continuous: decide.continuous,
                robot: decide.robot.clone(),
            }) as Box<dyn BatchPolicy>
        }))
    };
    Ok((
        Box::new(JointFactory::new(Box::new(make), n, name.clone())),
        name,
    ))
}

/// Each robot driven by a policy of its own, from factories this owns.
struct Owned {
    factories: Vec<Box<dyn PolicyFactory>>,
    /// Robot `k`'s factory, as an index into `factories`.
    of_robot: Vec<usize>,
    names: Vec<String>,
}

impl TeamPolicyFactory for Owned {
    fn make(&self) -> Result<Box<dyn ronap_core::policy::TeamPolicy>, PolicyError> {
        let policies = self
            .of_robot
            .iter()
            .map(|&i| self.factories[i].make())
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Box::new(ronap_core::policy::PerRobot::new(policies)))
    }

    fn names(&self) -> Vec<String> {
        self.names.clone()
    }
}

/// [`evaluate`] of a team scenario: {"summary": the robots' figures, "team": the team's,
/// "episodes": a dict per team episode (its `episodes.csv` row, and "robots": a dict per robot,
/// its `robots.csv` row)}; the run files of `ronap run` in `run.out` when given.
fn evaluate_team<'py>(
    py: Python<'py>,
    policy: &Bound<'py, PyAny>,
    seeds: Vec<u64>,
    config: &ValidConfig,
    continuous: bool,
    run: &Run<'_>,
) -> PyResult<Bound<'py, PyDict>> {
    let (factory, name) = team_factory(policy, config, continuous)?;
    let mut prepared = run.prepare(name, config, seeds)?;
    let cancel = AtomicBool::new(false);
    let interrupt = Interrupt::here();
    let (evaluation, rows) = py
        .allow_threads(|| {
            // Each episode's rows, in seed order (the records themselves are not kept).
            let rows = std::cell::RefCell::new(Vec::new());
            let keep = |r: &TeamRecord| {
                interrupt.watch(&cancel);
                rows.borrow_mut()
                    .push((team_episode_row(r), robot_rows(r, &[])));
                false
            };
            let request = prepared.request(&cancel);
            evaluate_team_into(request, factory.as_ref(), &|_| {}, &keep)
                .map(|e| (e, rows.into_inner()))
        })
        .map_err(|e| errors::PolicyError::new_err(e.to_string()))?;
    let d = interrupt.finish(py, &evaluation)?;
    let team = serde_json::to_value(&evaluation.team).unwrap_or_default();
    d.set_item("team", conv::json(py, &team)?)?;
    let robot_columns = robot_columns(&[]);
    let episodes = PyList::empty(py);
    for (row, robots) in rows {
        let e = cells(py, &TEAM_COLUMNS, &row)?;
        let list = PyList::empty(py);
        for r in robots {
            list.append(cells(py, &robot_columns, &r)?)?;
        }
        e.set_item("robots", list)?;
        episodes.append(e)?;
    }
    d.set_item("episodes", episodes)?;
    Ok(d)
}

/// A dict of `columns` to a CSV row's cells: integers and numbers as such, an empty cell as
/// None, `true`/`false` as booleans, other text as it is.
fn cells<'py, S: AsRef<str>>(
    py: Python<'py>,
    columns: &[S],
    row: &[String],
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for (c, v) in columns.iter().zip(row) {
        let key = c.as_ref();
        if v.is_empty() {
            d.set_item(key, py.None())?;
        } else if let Ok(i) = v.parse::<i64>() {
            d.set_item(key, i)?;
        } else if let Ok(x) = v.parse::<f64>() {
            d.set_item(key, x)?;
        } else if v == "true" || v == "false" {
            d.set_item(key, v == "true")?;
        } else {
            d.set_item(key, v)?;
        }
    }
    Ok(d)
}

/// The name a run reports for `policy`: a built-in's or weights file's name as given, a Python
/// callable's `__name__` (or "python").
pub fn policy_name(policy: &Bound<'_, PyAny>) -> String {
    policy.extract::<String>().unwrap_or_else(|_| {
        policy
            .getattr("__name__")
            .and_then(|n| n.extract::<String>())
            .unwrap_or_else(|_| "python".into())
    })
}

/// Compares `policies` (built-in names or callables) on the same `seeds` as `ronap compare` does;
/// returns the figures of `compare.json` as a dict, and writes every file of `ronap compare` into
/// `out` when given. `runs`: finished run directories to reuse.
#[pyfunction]
#[pyo3(signature = (policies, seeds, config, **options))]
pub fn compare<'py>(
    py: Python<'py>,
    policies: Vec<Bound<'py, PyAny>>,
    seeds: Vec<u64>,
    config: &Config,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<PyObject> {
    // As ronap.compare names them.
    let o = Options::new("compare", options);
    let (maze_seed, map_path, threads) = o.scene_and_threads()?;
    let continuous: bool = o.take("continuous", false)?;
    let out: Option<std::path::PathBuf> = o.take("out", None)?;
    let runs: Vec<std::path::PathBuf> = o.take("runs", Vec::new())?;
    let by_difficulty: bool = o.take("by_difficulty", false)?;
    let bins: usize = o.take("bins", 3)?;
    let resamples: usize = o.take("resamples", 10_000)?;
    let sheet: usize = o.take("sheet", 6)?;
    let players: Option<usize> = o.take("players", None)?;
    let thread_safe: bool = o.take("thread_safe", false)?;
    let command: Option<String> = o.take("command", None)?;
    let force: bool = o.take("force", false)?;
    o.finish()?;
    let map_path = map_path.as_deref();
    use ronap_core::compare::{self as cmp, CompareInfo, CompareOptions, Contender};
    let config = config.valid();
    if bins == 0 {
        return Err(errors::ConfigError::new_err("bins = 0: must be at least 1"));
    }
    let mut contenders = Vec::new();
    for policy in &policies {
        let (factory, name) = policy_factory(policy, config, continuous, thread_safe)?;
        warn_if_not_held_out(py, &name, factory.as_ref(), &seeds)?;
        contenders.push(Contender {
            name,
            factory,
            team: None,
            reuse: None,
        });
    }
    // Runs of the named policies are reused; a run of another policy joins the comparison.
    let names: Vec<String> = contenders.iter().map(|c| c.name.clone()).collect();
    let chosen =
        cmp::with_runs(&names, &runs).map_err(|e| errors::ConfigError::new_err(e.to_string()))?;
    for (i, (name, reuse)) in chosen.into_iter().enumerate() {
        match contenders.get_mut(i) {
            Some(c) => c.reuse = reuse,
            None => {
                let factory = ronap_core::policy::factory(&name, config.observation_size())
                    .map_err(|e| errors::ConfigError::new_err(format!("runs: {e}")))?;
                contenders.push(Contender {
                    name,
                    factory,
                    team: None,
                    reuse,
                });
            }
        }
    }
    let (spec, scenes, map) = conv::scenes(config, maze_seed, map_path)?;
    let evaluator = Evaluator::new(config.clone(), scenes);
    let options = CompareOptions {
        seeds,
        threads,
        by_difficulty,
        difficulty_bins: bins,
        resamples,
        sheet_rows: sheet,
        players,
        replace: force,
    };
    let info = CompareInfo {
        scenes: spec,
        map,
        command: command.unwrap_or_else(|| "ronap.compare(...) from Python".to_string()),
    };
    let cancel = AtomicBool::new(false);
    let comparison = py
        .allow_threads(|| {
            let request = cmp::CompareRequest {
                evaluator: &evaluator,
                contenders: &contenders,
                options: &options,
                info: &info,
                out: out.as_deref(),
                cancel: &cancel,
            };
            cmp::compare(request, &|_| {})
        })
        .map_err(|e| match e {
            cmp::CompareError::Output(e) => errors::out_dir(e),
            cmp::CompareError::Policy { .. } | cmp::CompareError::Run { .. } => {
                errors::PolicyError::new_err(e.to_string())
            }
            e => errors::ConfigError::new_err(e.to_string()),
        })?;
    let value = serde_json::to_value(&comparison)
        .map_err(|e| errors::OutputError::new_err(e.to_string()))?;
    conv::json(py, &value)
}

/// A `UserWarning` when some of `seeds` are among those the policy was trained or chosen on.
fn warn_if_not_held_out(
    py: Python<'_>,
    name: &str,
    factory: &dyn PolicyFactory,
    seeds: &[u64],
) -> PyResult<()> {
    let seen = factory.seeds_seen();
    if seen.is_empty() {
        return Ok(());
    }
    let run = ronap_core::eval::Seeds::List(seeds.to_vec());
    match ronap_core::eval::held_out_warning(name, &seen, &run) {
        Some(w) => {
            let category = py.get_type::<pyo3::exceptions::PyUserWarning>();
            PyErr::warn(
                py,
                &category,
                &std::ffi::CString::new(w).unwrap_or_default(),
                2,
            )
        }
        None => Ok(()),
    }
}

/// The first of `seeds`; an empty list is refused.
fn first_seed(seeds: &[u64]) -> PyResult<u64> {
    seeds
        .first()
        .copied()
        .ok_or_else(|| errors::ConfigError::new_err("seeds is empty: give at least one seed"))
}

/// What a run's files record of `policy` and the scene under `config`, and the scenes it runs in.
fn run_info(
    policy: String,
    config: &ValidConfig,
    maze_seed: Option<u64>,
    map_path: Option<&str>,
) -> PyResult<(RunInfo, Scenes)> {
    let (spec, scenes, map) = conv::scenes(config, maze_seed, map_path)?;
    Ok((
        RunInfo {
            policy,
            scenes: spec,
            map,
        },
        scenes,
    ))
}

/// One episode's rows as Python holds them: (seed, episode row, timing row, figures row).
type RowsTuple = (u64, Vec<String>, Vec<String>, Vec<String>);

/// A run whose seed blocks are evaluated elsewhere (Ray tasks) and handed in as rows, written into
/// `out` as `ronap run` writes one run of all the seeds (the core's `BlockRun`).
#[pyclass(module = "ronap._ronap", name = "BlockRun")]
pub struct PyBlockRun {
    run: Option<BlockRun>,
}

#[pymethods]
impl PyBlockRun {
    /// Starts the run of `policy` (a name or a callable, for its name) over `seeds` under
    /// `config` in directory `out` (made, locked, cleared of an earlier run's files).
    #[new]
    #[pyo3(signature = (out, policy, seeds, config, **options))]
    fn new(
        out: std::path::PathBuf,
        policy: &Bound<'_, PyAny>,
        seeds: Vec<u64>,
        config: &Config,
        options: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        // maze_seed, map_path, threads and force.
        let o = Options::new("BlockRun", options);
        let (maze_seed, map_path, threads) = o.scene_and_threads()?;
        let force: bool = o.take("force", false)?;
        o.finish()?;
        let map_path = map_path.as_deref();
        let first = first_seed(&seeds)?;
        let (info, _) = run_info(policy_name(policy), config.valid(), maze_seed, map_path)?;
        let writer =
            RunWriter::create(&out, RunFiles::default(), first, force).map_err(errors::out_dir)?;
        let options = EvalOptions {
            seeds: seeds.into(),
            threads,
            ..EvalOptions::default()
        };
        let run =
            BlockRun::create(writer, config.valid(), &options, &info).map_err(errors::output)?;
        Ok(Self { run: Some(run) })
    }

    /// Adds the rows of the next episodes (each `(seed, episode row, timing row, figures row)`,
    /// as `evaluate(..., rows=True)` returns them), in seed order.
    fn add(&mut self, rows: Vec<RowsTuple>) -> PyResult<()> {
        let run = self
            .run
            .as_mut()
            .ok_or_else(|| errors::RonapError::new_err("the run is finished"))?;
        let rows: Vec<EpisodeRows> = rows
            .into_iter()
            .map(|(seed, episode, timing, figures)| EpisodeRows {
                seed,
                episode,
                timing,
                figures,
            })
            .collect();
        run.add(&rows).map_err(errors::output)
    }

    /// Ends the run after `wall_time_s` seconds (complete when every seed's rows came, else
    /// marked interrupted, its files left for a resume); returns the summary (`summary.json`'s)
    /// and the table `ronap run` prints of it.
    fn finish(&mut self, py: Python<'_>, wall_time_s: f64) -> PyResult<(PyObject, String)> {
        let run = self
            .run
            .take()
            .ok_or_else(|| errors::RonapError::new_err("the run is finished"))?;
        let manifest = run.finish(wall_time_s).map_err(errors::output)?;
        let value = serde_json::to_value(&manifest.summary).unwrap_or_default();
        Ok((conv::json(py, &value)?, manifest.summary.table()))
    }
}

/// Checks that `policy` can run under `config` (a known name, a weights file that fits the
/// observation, or a callable) without running it; raises `ConfigError` naming what is wrong.
/// Given the run's `seeds`, warns (`UserWarning`) when some are among those a trained network
/// was trained or chosen on.
#[pyfunction]
#[pyo3(signature = (policy, config, seeds = None))]
pub fn check_policy(
    policy: &Bound<'_, PyAny>,
    config: &Config,
    seeds: Option<Vec<u64>>,
) -> PyResult<()> {
    let (factory, name) = policy_factory(policy, config.valid(), false, false)?;
    match seeds {
        Some(seeds) => warn_if_not_held_out(policy.py(), &name, factory.as_ref(), &seeds),
        None => Ok(()),
    }
}
