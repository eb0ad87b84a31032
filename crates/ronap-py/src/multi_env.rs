//! Several robots in one episode, stepped from Python: the core's team rollout with actions
//! (and messages) chosen outside, on the core `Env` shares ([`TeamEnv`]). The PettingZoo class `ronap.MultiNavEnv` is built on it.

use crate::conv::{self, Config};
use crate::errors::{self, ActionError};
use crate::team_env::TeamEnv;
use numpy::{PyArray1, PyArray3, PyArrayMethods, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use ronap_core::run::{RobotStep, TeamBatch};
use ronap_core::sim::{Action, Team};

/// Several robots in one scene, an episode at a time, on the core `Env` shares ([`TeamEnv`]).
#[pyclass(module = "ronap._ronap")]
pub struct MultiEnv {
    core: TeamEnv,
}

/// Robot `k`'s info dictionary: its episode's figures, plus what it received at the last step.
fn robot_info<'py>(py: Python<'py>, team: &Team, k: usize) -> PyResult<Bound<'py, PyDict>> {
    let r = team.robot(k);
    let d = conv::info(py, r, team.collided(k))?;
    d.set_item("robot", k)?;
    d.set_item("present", team.present(k))?;
    d.set_item("goals_reached", r.goals_reached())?;
    d.set_item("goals", team.goals(k).len())?;
    let inbox = PyList::empty(py);
    for b in team.inbox(k) {
        let m = PyDict::new(py);
        m.set_item("from", b.from)?;
        m.set_item("pose", (b.pose.x, b.pose.y, b.pose.z_deg))?;
        m.set_item("goal", (b.goal.x, b.goal.y))?;
        m.set_item("message", PyArray1::from_slice(py, &b.message))?;
        inbox.append(m)?;
    }
    d.set_item("inbox", inbox)?;
    Ok(d)
}

/// Each robot's observation and info.
type Observed<'py> = (Vec<Bound<'py, PyArray1<f32>>>, Vec<Bound<'py, PyDict>>);

/// Each robot's message (or none) for a step.
type Messages<'py> = Vec<Option<PyReadonlyArray1<'py, f32>>>;

/// What `MultiEnv.step` returns: each robot's observation, reward, termination, truncation and
/// info.
type TeamStepped<'py> = (
    Vec<Bound<'py, PyArray1<f32>>>,
    Vec<f64>,
    Vec<bool>,
    Vec<bool>,
    Vec<Bound<'py, PyDict>>,
);

/// What `VecMultiEnv.step` returns: observations, rewards, terminations and truncations (arrays
/// of every robot of every team) and infos.
type BatchStepped<'py> = (
    Bound<'py, PyAny>,
    Bound<'py, PyAny>,
    Bound<'py, PyAny>,
    Bound<'py, PyAny>,
    Bound<'py, PyDict>,
);

/// Every robot's observation and info.
fn observe<'py>(py: Python<'py>, team: &Team) -> PyResult<Observed<'py>> {
    let n = team.robots().len();
    let obs = (0..n)
        .map(|k| PyArray1::from_slice(py, team.robot(k).observation()))
        .collect();
    let infos = (0..n)
        .map(|k| robot_info(py, team, k))
        .collect::<PyResult<_>>()?;
    Ok((obs, infos))
}

#[pymethods]
impl MultiEnv {
    /// The team of `config`'s `[[robots]]`, with the keyword options of [`TeamEnv::new`]
    /// (`maze_seed`, `map_path`, `continuous`).
    #[new]
    #[pyo3(signature = (config, **options))]
    fn new(config: &Config, options: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
        if config.valid().team_size() == 0 {
            return Err(errors::ConfigError::new_err(
                "MultiNavEnv needs a team: a scenario with [[robots]] entries \
                 (or robots=[{\"count\": N}])",
            ));
        }
        Ok(Self {
            core: TeamEnv::new("MultiEnv", config.valid(), options)?,
        })
    }

    /// Starts the team episode of `seed` (the same as `ronap run` seed `seed`); returns
    /// (observations, infos), one per robot.
    fn reset<'py>(&mut self, py: Python<'py>, seed: u64) -> PyResult<Observed<'py>> {
        let team = self.core.reset(py, seed)?;
        observe(py, team)
    }

    /// One step of the team: `actions[k]` for robot `k` (None: it stands still, as robots
    /// whose episodes are over do anyway), `messages[k]` its message for the next broadcast
    /// (None or a shorter array: zeros). Returns (observations, rewards, terminated, truncated,
    /// infos), one each per robot.
    #[pyo3(signature = (actions, messages = None))]
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        actions: Vec<Option<Bound<'py, PyAny>>>,
        messages: Option<Messages<'py>>,
    ) -> PyResult<TeamStepped<'py>> {
        let n = self.core.team("step")?.robots().len();
        if actions.len() != n {
            return Err(ActionError::new_err(format!(
                "{} actions for {n} robots",
                actions.len()
            )));
        }
        let mut chosen: Vec<Option<Action>> = Vec::with_capacity(n);
        for (k, a) in actions.iter().enumerate() {
            chosen.push(match a {
                None => None,
                Some(a) => Some(self.core.action(k, a).map_err(|why| {
                    ActionError::new_err(format!("robot_{k}'s action {a}: {why}"))
                })?),
            });
        }
        if let Some(messages) = &messages {
            if messages.len() != n {
                return Err(ActionError::new_err(format!(
                    "{} messages for {n} robots",
                    messages.len()
                )));
            }
            let rollout = self.core.rollout_mut("step")?;
            for (k, m) in messages.iter().enumerate() {
                if let Some(m) = m {
                    let m = m.as_slice().map_err(|_| {
                        ActionError::new_err(format!("robot_{k}'s message: not contiguous"))
                    })?;
                    if m.iter().any(|x| !x.is_finite()) {
                        return Err(ActionError::new_err(format!(
                            "robot_{k}'s message: NaN or infinite values"
                        )));
                    }
                    rollout.set_message(k, m);
                }
            }
        }
        let stepped = self.core.step(py, &chosen)?;
        let (team, rewards) = (stepped.team, stepped.rewards);
        let terminated = team
            .robots()
            .iter()
            .map(|r| conv::ends(r.status()).0)
            .collect();
        let truncated = team
            .robots()
            .iter()
            .map(|r| conv::ends(r.status()).1)
            .collect();
        let (obs, infos) = observe(py, team)?;
        Ok((obs, rewards, terminated, truncated, infos))
    }

    /// The whole scene as it stands, every robot in its own colour with its goal, start and path
    /// so far (a team of one as `NavEnv` draws its robot), `scale` pixels per px.
    fn render<'py>(&self, py: Python<'py>, scale: f64) -> PyResult<Bound<'py, PyArray3<u8>>> {
        if !(scale.is_finite() && scale > 0.0 && scale <= 16.0) {
            return Err(errors::ConfigError::new_err(format!(
                "render scale = {scale}: must be between 0 and 16"
            )));
        }
        let team = self.core.team("render")?;
        conv::image(py, self.core.top_view(team, scale))
    }

    /// Robots in the team.
    #[getter]
    fn robots(&self) -> usize {
        self.core.robots()
    }

    /// Each robot's observation length (its beams + 1 + the neighbour slots).
    #[getter]
    fn observation_sizes(&self) -> Vec<usize> {
        let config = self.core.config();
        (0..config.team_size())
            .map(|k| config.team_robot(k).observation_size())
            .collect()
    }

    /// Each robot's full value of each dimension of a normalised continuous action (see
    /// `Env.action_scale`).
    #[getter]
    fn action_scales(&self) -> Vec<Vec<f64>> {
        let config = self.core.config();
        (0..config.team_size())
            .map(|k| config.team_robot(k).robot.action_scale())
            .collect()
    }

    /// The floats of the neighbour slots at the end of each observation.
    #[getter]
    fn slots_size(&self) -> usize {
        let team = &self.core.config().team;
        team.neighbours as usize * team.slot_size()
    }

    /// Floats in a robot's message.
    #[getter]
    fn message_size(&self) -> usize {
        self.core.config().team.message_size as usize
    }

    /// Steps so far in this episode.
    #[getter]
    fn steps(&self) -> u32 {
        self.core.team("steps").map_or(0, |t| t.steps())
    }
}

/// Several team environments stepped together in Rust, across cores, with the GIL released.
#[pyclass(module = "ronap._ronap")]
pub struct VecMultiEnv {
    batch: TeamBatch,
}

impl VecMultiEnv {
    /// (observations `N x R x D`, infos of `N x R` or `N` arrays).
    fn arrays<'py>(&self, py: Python<'py>) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyDict>)> {
        let b = &self.batch;
        let (n, r, d) = (b.len(), b.robots(), b.observation_size());
        let obs = PyArray1::from_slice(py, b.observations()).reshape([n, r, d])?;
        let steps = b.steps();
        let grid = |f: &dyn Fn(&RobotStep) -> bool| {
            PyArray1::from_iter(py, steps.iter().map(f)).reshape([n, r])
        };
        let infos = PyDict::new(py);
        infos.set_item("active", grid(&|s| s.running)?)?;
        infos.set_item("acted", grid(&|s| s.acted)?)?;
        infos.set_item("collided", grid(&|s| s.collided)?)?;
        infos.set_item("success", grid(&|s| s.success)?)?;
        let rollouts = (0..n).map(|i| b.rollout(i));
        let seeds: Vec<u64> = rollouts
            .clone()
            .map(|t| t.map_or(0, |t| t.team().robot(0).seed()))
            .collect();
        infos.set_item("seed", PyArray1::from_vec(py, seeds))?;
        let team_steps: Vec<u32> = rollouts
            .map(|t| t.map_or(0, |t| t.team().steps()))
            .collect();
        infos.set_item("steps", PyArray1::from_vec(py, team_steps))?;
        let reset: Vec<bool> = (0..n).map(|i| b.was_reset(i)).collect();
        infos.set_item("reset", PyArray1::from_vec(py, reset))?;
        Ok((obs.into_any(), infos))
    }
}

#[pymethods]
impl VecMultiEnv {
    /// `num_envs` team environments under `config`, stepped on `threads` threads (0: all cores),
    /// with `autoreset` "next_step", "same_step" or "disabled".
    #[new]
    #[pyo3(signature = (num_envs, config, **options))]
    fn new(
        num_envs: usize,
        config: &Config,
        options: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        let valid = config.valid();
        if valid.team_size() == 0 {
            return Err(errors::ConfigError::new_err(
                "VecMultiNavEnv needs a team: a scenario with [[robots]] entries",
            ));
        }
        let o = crate::kwargs::Options::new("VecMultiEnv", options);
        let batch: TeamBatch = o.batch(num_envs, valid)?;
        Ok(Self { batch })
    }

    /// Starts every environment: environment `i` gets seed `seed + i`. Returns (observations,
    /// infos).
    fn reset<'py>(
        &mut self,
        py: Python<'py>,
        seed: u64,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyDict>)> {
        py.allow_threads(|| self.batch.reset(seed))
            .map_err(|e| errors::run(&e))?;
        self.arrays(py)
    }

    /// Starts afresh the environments `mask` selects, each with its seed from `seeds` (one per
    /// environment) or, for None, the next seed of its sequence. Returns (observations, infos).
    fn restart<'py>(
        &mut self,
        py: Python<'py>,
        seeds: Vec<Option<u64>>,
        mask: Vec<bool>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyDict>)> {
        py.allow_threads(|| self.batch.restart(&mask, &seeds))
            .map_err(|e| crate::vec_env::run_error(&e))?;
        self.arrays(py)
    }

    /// Steps every environment with `actions` (`N x R` indices: 0 LEFT, 1 AHEAD, 2 RIGHT) and
    /// optionally `messages` (`N x R x message_size` floats). Returns (observations, rewards,
    /// terminations, truncations, infos), the middle three `N x R`.
    #[pyo3(signature = (actions, messages = None))]
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        actions: PyReadonlyArray1<'py, i64>,
        messages: Option<PyReadonlyArray1<'py, f32>>,
    ) -> PyResult<BatchStepped<'py>> {
        let (n, r, m) = (
            self.batch.len(),
            self.batch.robots(),
            self.batch.message_size(),
        );
        let actions = actions.as_slice()?;
        if actions.len() != n * r {
            return Err(ActionError::new_err(format!(
                "{} actions for {n} environments of {r} robots",
                actions.len()
            )));
        }
        let actions = actions
            .iter()
            .enumerate()
            .map(|(j, &a)| {
                conv::discrete(a).ok_or_else(|| {
                    ActionError::new_err(format!(
                        "action {a} for environment {}, robot_{}: expected 0 (LEFT), \
                             1 (AHEAD) or 2 (RIGHT)",
                        j / r,
                        j % r
                    ))
                })
            })
            .collect::<PyResult<Vec<Action>>>()?;
        let messages = match &messages {
            Some(a) => {
                let s = a.as_slice()?;
                if s.len() != n * r * m {
                    return Err(ActionError::new_err(format!(
                        "{} message floats for {n} environments of {r} robots with \
                         message_size {m}",
                        s.len()
                    )));
                }
                if s.iter().any(|x| !x.is_finite()) {
                    return Err(ActionError::new_err("messages: NaN or infinite values"));
                }
                Some(s)
            }
            None => None,
        };
        py.allow_threads(|| self.batch.step(&actions, messages))
            .map_err(|e| crate::vec_env::run_error(&e))?;
        let steps = self.batch.steps();
        let rewards = PyArray1::from_iter(py, steps.iter().map(|s| s.reward)).reshape([n, r])?;
        let terminated =
            PyArray1::from_iter(py, steps.iter().map(|s| s.terminated)).reshape([n, r])?;
        let truncated =
            PyArray1::from_iter(py, steps.iter().map(|s| s.truncated)).reshape([n, r])?;
        let (obs, infos) = self.arrays(py)?;
        // Same-step autoreset: the episodes this step ended have restarted; their last
        // observations go in the infos.
        let restarted: Vec<bool> = (0..n).map(|i| self.batch.restarted(i)).collect();
        if restarted.contains(&true) {
            let d = self.batch.observation_size();
            let last =
                PyArray1::from_slice(py, self.batch.final_observations()).reshape([n, r, d])?;
            infos.set_item("final_obs", last)?;
            infos.set_item("_final_obs", PyArray1::from_vec(py, restarted))?;
        }
        Ok((
            obs,
            rewards.into_any(),
            terminated.into_any(),
            truncated.into_any(),
            infos,
        ))
    }

    /// Number of environments.
    #[getter]
    fn num_envs(&self) -> usize {
        self.batch.len()
    }

    /// Robots per environment.
    #[getter]
    fn robots(&self) -> usize {
        self.batch.robots()
    }

    /// Length of an observation row (the longest robot's; shorter ones padded with zeros).
    #[getter]
    fn observation_size(&self) -> usize {
        self.batch.observation_size()
    }

    /// Floats in a robot's message.
    #[getter]
    fn message_size(&self) -> usize {
        self.batch.message_size()
    }
}
