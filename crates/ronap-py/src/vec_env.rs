//! A batch of environments stepped together in Rust, across cores, with the GIL released: the
//! core's [`Batch`] with any of Gymnasium's three autoreset modes, its flat buffers handed over as
//! numpy arrays with no Python object per environment. An environment's episode seeds follow
//! from the seed it starts with: `s, s + n, s + 2n, ...` for `n` environments.

use crate::conv::{self, Config};
use crate::errors;
use numpy::{PyArray1, PyArrayMethods, PyFixedUnicode, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::intern;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use ronap_core::run::{Batch, EnvStep, RunError};
use ronap_core::sim::continuous_action;
use ronap_core::{Action, Point, Status};

/// What `VecEnv.step` returns: observations, rewards, terminations, truncations, infos and the
/// finals of the episodes same-step autoreset restarted.
type Stepped<'py> = (
    Bound<'py, PyAny>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<bool>>,
    Bound<'py, PyArray1<bool>>,
    Bound<'py, PyDict>,
    Option<Finals<'py>>,
);

/// Many RoNAP environments stepped together.
#[pyclass(module = "ronap._ronap")]
pub struct VecEnv {
    batch: Batch,
    /// A mask of every environment, the infos' `_key` entries after a step (one array, not one
    /// a step).
    all: Py<PyArray1<bool>>,
    continuous: bool,
    /// Each environment's path in its episode so far, kept when it may be drawn.
    paths: Option<Vec<Vec<Point>>>,
    /// The actions of the last step, kept so a step allocates none.
    actions: Vec<Action>,
}

/// What a reset or a step hands back besides rewards and flags: observations, infos, and for the
/// episodes same-step autoreset restarted (`None` when there are none) a mask of them, their last
/// observations and their final infos.
type Arrays<'py> = (Bound<'py, PyAny>, Bound<'py, PyDict>, Option<Finals<'py>>);

/// The episodes same-step autoreset restarted: a mask of them, their last observations and their
/// final infos.
type Finals<'py> = (
    Bound<'py, PyArray1<bool>>,
    Bound<'py, PyAny>,
    Bound<'py, PyDict>,
);

/// The info arrays of `records`, one entry per environment, each filled in its own pass over
/// the records (a tight loop apiece; one pass pushing to all of them at once was slower) and
/// handed to numpy uncopied; beside each key `k`, Gymnasium's `_k`: `mask`, the environments it
/// holds a value for (set here, where the keys are known, rather than by a loop in Python).
fn infos<'py>(
    py: Python<'py>,
    records: &[EnvStep],
    mask: &Bound<'py, PyArray1<bool>>,
) -> PyResult<Bound<'py, PyDict>> {
    let n = records.len();
    fn each<T>(records: &[EnvStep], f: impl Fn(&EnvStep) -> T) -> Vec<T> {
        records.iter().map(f).collect()
    }
    let names = Status::ALL.map(status_name);
    let distance = each(records, |s| s.distance_px);
    let collided = each(records, |s| s.collided);
    let success = each(records, |s| s.status == Status::Success);
    let pose: Vec<f64> = records
        .iter()
        .flat_map(|s| [s.pose.x, s.pose.y, s.pose.z_deg])
        .collect();
    let goal: Vec<f64> = records.iter().flat_map(|s| [s.goal.x, s.goal.y]).collect();
    let status = each(records, |s| names[s.status as usize]);
    let steps = each(records, |s| u64::from(s.steps));
    let collisions = each(records, |s| u64::from(s.collisions));
    let seed = each(records, |s| s.seed);
    let total_reward = each(records, |s| s.total_reward);
    let any_dynamic = records.iter().any(|s| s.dynamic_collisions.is_some());
    let d = PyDict::new(py);
    macro_rules! put {
        ($key:literal, $value:expr) => {
            d.set_item(intern!(py, $key), $value)?;
            d.set_item(intern!(py, concat!("_", $key)), mask)?;
        };
    }
    put!("distance", PyArray1::from_vec(py, distance));
    put!("collided", PyArray1::from_vec(py, collided));
    put!("success", PyArray1::from_vec(py, success));
    put!("pose", PyArray1::from_vec(py, pose).reshape([n, 3])?);
    put!("goal", PyArray1::from_vec(py, goal).reshape([n, 2])?);
    put!("status", PyArray1::from_vec(py, status));
    put!("steps", PyArray1::from_vec(py, steps));
    put!("collisions", PyArray1::from_vec(py, collisions));
    put!("seed", PyArray1::from_vec(py, seed));
    // "return", as every info and result names the summed reward; "total_reward" is its
    // earlier name, kept for code written against it.
    let summed = PyArray1::from_vec(py, total_reward);
    put!("return", &summed);
    put!("total_reward", summed);
    if any_dynamic {
        let dynamic = each(records, |s| u64::from(s.dynamic_collisions.unwrap_or(0)));
        put!("dynamic_collisions", PyArray1::from_vec(py, dynamic));
    }
    Ok(d)
}

/// Longest [`Status::name`] ("reward_min").
const STATUS_CHARS: usize = 10;

/// `status`'s name as a numpy fixed-width string (dtype `<U10`): an array of them costs no Python
/// object per environment (a list of 1024 `str` per step once took a quarter of a step's time,
/// with the garbage collection it set off). [`infos`] looks the names up in a table it builds
/// once a call: a name built for each environment was read back whole straight after being written a
/// character at a time, a stall on every one (half of `infos`'s time in `perf`).
fn status_name(status: Status) -> PyFixedUnicode<STATUS_CHARS> {
    let mut chars = [0; STATUS_CHARS];
    for (c, b) in chars.iter_mut().zip(status.name().bytes()) {
        *c = u32::from(b);
    }
    PyFixedUnicode(chars)
}

/// A batch's error: stepping an ended environment is the caller's mistake (`RonapError`), the
/// rest as [`errors::run`] says.
pub(crate) fn run_error(e: &RunError) -> PyErr {
    match e {
        RunError::Ended { env } => errors::RonapError::new_err(format!(
            "environment {env}: its episode ended and autoreset is disabled: reset it first \
             (reset(options={{\"reset_mask\": mask}}))"
        )),
        _ => errors::run(e),
    }
}

impl VecEnv {
    /// Each environment's current state: the step it took, or the start of the episode that
    /// replaced the one it ended (the step records themselves, uncopied, when none was).
    fn current(&self) -> std::borrow::Cow<'_, [EnvStep]> {
        let steps = self.batch.steps();
        if !(0..steps.len()).any(|i| self.batch.restarted(i)) {
            return std::borrow::Cow::Borrowed(steps);
        }
        steps
            .iter()
            .enumerate()
            .map(|(i, s)| match self.batch.episode(i) {
                Some(e) if self.batch.restarted(i) => EnvStep::start(e),
                _ => *s,
            })
            .collect()
    }

    /// Adds each selected environment's new position to its path (a new path for a new episode).
    fn track(&mut self, which: Option<&[bool]>) {
        if self.paths.is_none() {
            return;
        }
        let current = self.current().into_owned();
        let Some(paths) = self.paths.as_mut() else {
            return;
        };
        for (i, (path, now)) in paths.iter_mut().zip(&current).enumerate() {
            if which.is_some_and(|w| !w[i]) {
                continue;
            }
            if now.reset {
                path.clear();
            }
            path.push(now.pose.position());
        }
    }

    /// The arrays of a reset or step; the infos' `_key` masks are `mask` (every environment when
    /// None).
    fn arrays<'py>(&self, py: Python<'py>, mask: Option<&[bool]>) -> PyResult<Arrays<'py>> {
        let (n, d) = (self.batch.len(), self.batch.observation_size());
        let current = self.current();
        let obs = PyArray1::from_slice(py, self.batch.observations()).reshape([n, d])?;
        let mask = match mask {
            Some(m) => PyArray1::from_slice(py, m),
            None => self.all.bind(py).clone(),
        };
        let info = infos(py, &current, &mask)?;
        let ended: Vec<bool> = (0..n).map(|i| self.batch.restarted(i)).collect();
        let finals = if ended.contains(&true) {
            let last = PyArray1::from_slice(py, self.batch.final_observations()).reshape([n, d])?;
            let ended = PyArray1::from_vec(py, ended);
            let final_infos = infos(py, self.batch.steps(), &ended)?;
            Some((ended, last.into_any(), final_infos))
        } else {
            None
        };
        Ok((obs.into_any(), info, finals))
    }
}

#[pymethods]
impl VecEnv {
    /// `num_envs` environments under `config`, stepped on `threads` threads (0: all cores), with
    /// `autoreset` "next_step", "same_step" or "disabled"; `continuous` takes (v, w) actions;
    /// `render` keeps each environment's path so it can be drawn.
    #[new]
    #[pyo3(signature = (num_envs, config, **options))]
    fn new(
        py: Python<'_>,
        num_envs: usize,
        config: &Config,
        options: Option<&Bound<'_, pyo3::types::PyDict>>,
    ) -> PyResult<Self> {
        // continuous and render, then maze_seed, map_path, threads and autoreset.
        let o = crate::kwargs::Options::new("VecEnv", options);
        let continuous: bool = o.take("continuous", false)?;
        let render: bool = o.take("render", false)?;
        let batch: Batch = o.batch(num_envs, config.valid())?;
        Ok(Self {
            batch,
            all: PyArray1::from_vec(py, vec![true; num_envs]).unbind(),
            continuous,
            paths: render.then(|| vec![Vec::new(); num_envs]),
            actions: Vec::with_capacity(num_envs),
        })
    }

    /// Starts the environments `mask` selects (all when None), each with its seed from `seeds`
    /// (one per environment) or, for None, the next seed of its sequence. Returns
    /// (observations, infos, None); beside each info `k`, `_k` is the mask of the environments
    /// started.
    fn reset<'py>(
        &mut self,
        py: Python<'py>,
        seeds: Vec<Option<u64>>,
        mask: Option<Vec<bool>>,
    ) -> PyResult<Arrays<'py>> {
        let which = mask.unwrap_or_else(|| vec![true; self.batch.len()]);
        py.allow_threads(|| self.batch.restart(&which, &seeds))
            .map_err(|e| run_error(&e))?;
        self.track(Some(&which));
        let partial = which.contains(&false);
        self.arrays(py, partial.then_some(&which[..]))
    }

    /// The full value of each dimension of a normalised continuous action (see
    /// `Env.action_scale`).
    #[getter]
    fn action_scale(&self) -> Vec<f64> {
        self.batch.worlds().config().robot.action_scale()
    }

    /// Steps every environment with `actions`: one index per environment (0 LEFT, 1 AHEAD,
    /// 2 RIGHT) as an int64 array, or for a continuous batch an (n, k) float64 array of the
    /// robot's continuous command (k = 2: (v px/step, w deg/step); see `action_scale`). Returns
    /// (observations, rewards, terminations, truncations, infos, finals), each info `k` beside
    /// Gymnasium's mask `_k`: `finals` is None, or for the episodes same-step autoreset restarted
    /// (ended mask, their last observations, their final infos, masked by it).
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        actions: &Bound<'py, PyAny>,
    ) -> PyResult<Stepped<'py>> {
        let n = self.batch.len();
        self.actions.clear();
        if self.continuous {
            let a: PyReadonlyArray2<'py, f64> = actions.extract()?;
            let a = a.as_array();
            let robot = &self.batch.worlds().config().robot;
            let k = robot.action_size();
            if a.dim() != (n, k) {
                return Err(errors::ActionError::new_err(format!(
                    "actions of shape {:?} for {n} environments: expected ({n}, {k})",
                    a.shape()
                )));
            }
            for (i, r) in a.rows().into_iter().enumerate() {
                let mut row = [0.0; 3];
                for (to, x) in row.iter_mut().zip(r.iter()) {
                    *to = *x;
                }
                let values = &row[..k];
                match continuous_action(robot, values) {
                    Some(action) => self.actions.push(action),
                    None => {
                        let shown: Vec<String> = values.iter().map(f64::to_string).collect();
                        return Err(errors::ActionError::new_err(format!(
                            "action ({}) for environment {i}: expected finite numbers",
                            shown.join(", ")
                        )));
                    }
                }
            }
        } else {
            let a: PyReadonlyArray1<'py, i64> = actions.extract()?;
            let a = a.as_slice()?;
            if a.len() != n {
                return Err(errors::ActionError::new_err(format!(
                    "{} actions for {n} environments",
                    a.len()
                )));
            }
            // Checked in one pass, then converted in another: a loop that may stop at any
            // action to report it stored each action and the vector's length one at a time.
            if let Some(i) = a.iter().position(|&a| conv::discrete(a).is_none()) {
                return Err(errors::ActionError::new_err(format!(
                    "action {} for environment {i}: expected 0 (LEFT), 1 (AHEAD) or 2 (RIGHT)",
                    a[i]
                )));
            }
            self.actions
                .extend(a.iter().filter_map(|&a| conv::discrete(a)));
        }
        let (batch, chosen) = (&mut self.batch, &self.actions);
        let stepped = py.allow_threads(|| batch.step_actions(chosen));
        stepped.map_err(|e| run_error(&e))?;
        self.track(None);
        let steps = self.batch.steps();
        let rewards = PyArray1::from_iter(py, steps.iter().map(|s| s.reward));
        let terminated = PyArray1::from_iter(py, steps.iter().map(|s| s.status.is_terminated()));
        let truncated = PyArray1::from_iter(py, steps.iter().map(|s| s.status.is_truncated()));
        let (obs, infos, finals) = self.arrays(py, None)?;
        Ok((obs, rewards, terminated, truncated, infos, finals))
    }

    /// The picture of environment `i`'s current state, as `Env.render` draws it ("top" with the
    /// path so far, or "first_person").
    fn render<'py>(
        &self,
        py: Python<'py>,
        i: usize,
        view: &str,
        scale: f64,
    ) -> PyResult<Bound<'py, numpy::PyArray3<u8>>> {
        let episode = self
            .batch
            .episode(i)
            .ok_or_else(|| errors::RonapError::new_err("render() before reset()"))?;
        let path = self.paths.as_ref().map_or(&[][..], |p| &p[i][..]);
        let top = |scale| ronap_core::render::top_down(episode, path, scale);
        conv::render(py, episode, &top, view, scale)
    }

    /// Number of environments.
    #[getter]
    fn num_envs(&self) -> usize {
        self.batch.len()
    }

    /// Length of one observation.
    #[getter]
    fn observation_size(&self) -> usize {
        self.batch.observation_size()
    }
}
