//! The one core of `Env` and `MultiEnv`: a team episode stepped from Python, a lone robot's
//! configuration being its team of one ([`ValidConfig::as_team`]), whose episodes are the lone
//! robot's step for step. `Env` shows its one robot, `MultiEnv` every robot.

use crate::conv;
use crate::errors;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use ronap_core::config::RobotConfig;
use ronap_core::run::{TeamRollout, TeamShaper};
use ronap_core::sim::{Action, Team, Worlds};
use ronap_core::{Point, ValidConfig};

/// What a step gives: the team after it, and each robot's reward and whether it collided.
pub(crate) struct Stepped<'a> {
    pub(crate) team: &'a Team,
    pub(crate) rewards: Vec<f64>,
    pub(crate) collided: Vec<bool>,
}

/// A team's episodes, one at a time: the rollout, each robot's reward shaping (under
/// `reward.shaping`) and its path so far (for pictures).
pub(crate) struct TeamEnv {
    worlds: Worlds,
    rollout: Option<TeamRollout>,
    /// Its robots' reward shaping, under `reward.shaping`.
    shaping: TeamShaper,
    /// Each robot's centre at every step it moved, from its start.
    paths: Vec<Vec<Point>>,
    /// Each robot's body, when actions are continuous commands (its kinematics say what they
    /// hold); empty for discrete actions.
    continuous: Vec<RobotConfig>,
}

impl TeamEnv {
    /// The team of `config` (its one robot as a team of one when it has no `[[robots]]`) for
    /// `function` (`Env` or `MultiEnv`, named in errors), with its keyword `options`:
    /// `maze_seed` fixes one maze for every episode, `map_path` uses an image or ROS map instead
    /// of mazes, `continuous` takes each robot's continuous command instead of 0/1/2.
    pub(crate) fn new(
        function: &'static str,
        config: &ValidConfig,
        options: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        let o = crate::kwargs::Options::new(function, options);
        let maze_seed: Option<u64> = o.take("maze_seed", None)?;
        let map_path: Option<String> = o.take("map_path", None)?;
        let continuous: bool = o.take("continuous", false)?;
        o.finish()?;
        let map_path = map_path.as_deref();
        let team = config.as_team();
        let (_, scenes, _) = conv::scenes(&team, maze_seed, map_path)?;
        let continuous = (0..team.team_size())
            .filter(|_| continuous)
            .map(|k| team.team_robot(k).robot.clone())
            .collect();
        Ok(Self {
            worlds: Worlds::new(team, scenes),
            rollout: None,
            shaping: TeamShaper::default(),
            paths: Vec::new(),
            continuous,
        })
    }

    /// The team's configuration.
    pub(crate) fn config(&self) -> &ValidConfig {
        self.worlds.config()
    }

    /// Robots in the team.
    pub(crate) fn robots(&self) -> usize {
        self.config().team_size()
    }

    /// Starts the team episode of `seed` (the same as `ronap run` seed `seed`).
    pub(crate) fn reset(&mut self, py: Python<'_>, seed: u64) -> PyResult<&Team> {
        let worlds = self.worlds.team(seed);
        let config = self.worlds.config();
        let rollout = py
            .allow_threads(|| TeamRollout::placed(config, worlds, seed))
            .map_err(|e| errors::run(&e))?;
        let team = rollout.team();
        self.shaping = TeamShaper::start(&rollout);
        self.paths = team
            .robots()
            .iter()
            .map(|r| vec![r.pose().position()])
            .collect();
        Ok(self.rollout.insert(rollout).team())
    }

    /// The episode under way: `what` (the call) raises before the first reset.
    pub(crate) fn team(&self, what: &str) -> PyResult<&Team> {
        self.rollout
            .as_ref()
            .map(TeamRollout::team)
            .ok_or_else(|| errors::RonapError::new_err(format!("{what}() before reset()")))
    }

    /// The episode under way, to step: `what` raises before the first reset.
    pub(crate) fn rollout_mut(&mut self, what: &str) -> PyResult<&mut TeamRollout> {
        self.rollout
            .as_mut()
            .ok_or_else(|| errors::RonapError::new_err(format!("{what}() before reset()")))
    }

    /// Reads robot `k`'s action from Python (a continuous one by its own kinematics); the error
    /// says what was expected.
    pub(crate) fn action(&self, k: usize, value: &Bound<'_, PyAny>) -> Result<Action, String> {
        conv::action(value, self.continuous.get(k))
    }

    /// One step of the team, `actions[k]` robot `k`'s (None: it stands still). Gives each
    /// robot's reward and whether it collided: for a robot that acted (it was running and had
    /// an action), the step's, its reward shaped when the configuration asks for it; 0 and no
    /// collision for any other.
    pub(crate) fn step(
        &mut self,
        py: Python<'_>,
        actions: &[Option<Action>],
    ) -> PyResult<Stepped<'_>> {
        let rollout = self
            .rollout
            .as_mut()
            .ok_or_else(|| errors::RonapError::new_err("step() before reset()"))?;
        let acted: Vec<bool> = actions
            .iter()
            .enumerate()
            .map(|(k, a)| a.is_some() && rollout.team().running(k))
            .collect();
        py.allow_threads(|| rollout.step(actions));
        let team = rollout.team();
        let mut rewards = vec![0.0; team.robots().len()];
        let mut collided = vec![false; team.robots().len()];
        for (k, &acted) in acted.iter().enumerate() {
            if acted {
                rewards[k] = self.shaping.shaped(k, team.robot(k), team.rewards()[k]);
                collided[k] = team.collided(k);
            }
        }
        for (path, r) in self.paths.iter_mut().zip(team.robots()) {
            let p = r.pose().position();
            if path.last() != Some(&p) {
                path.push(p);
            }
        }
        Ok(Stepped {
            team,
            rewards,
            collided,
        })
    }

    /// The whole scene of `team` (this environment's, as it stands): every robot with its goal,
    /// start and path so far (a team of one as a lone robot is drawn), `scale` pixels per px.
    pub(crate) fn top_view(&self, team: &Team, scale: f64) -> image::RgbImage {
        ronap_core::render::team_frame(team, &self.paths, scale)
    }
}
