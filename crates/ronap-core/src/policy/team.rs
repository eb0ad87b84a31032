//! Team policies: what decides every robot's action of a team at a step, together. A planner
//! that coordinates its robots (reserving cells in space and time, giving way) implements
//! [`TeamPolicy`] directly; the common case, each robot driven by a [`Policy`] of its own, is
//! [`PerRobot`]. The team rollout and the evaluator only ever see a [`TeamPolicy`].

use crate::policy::batched::BatchPolicy;
use crate::policy::{Decision, Policy, PolicyError, PolicyFactory};
use crate::sim::{Episode, Team, World};
use std::sync::Arc;

/// A policy's failure for one robot of a team: the robot, and what went wrong.
pub type RobotError = (usize, PolicyError);

/// Decides for every robot of a team at once.
pub trait TeamPolicy: Send {
    /// Prepares for a new team episode, before the first [`TeamPolicy::act`]: robot `k` acts in
    /// `worlds[k]` (its `[[robots]]` entry's configuration and the shared scene).
    fn reset(&mut self, team: &Team, worlds: &[Arc<World>]) -> Result<(), RobotError>;

    /// The decisions of this step: `decisions[k]` for robot `k`, `Some` for every robot that
    /// [runs](Team::running) and `None` for the others (`decisions` arrives with one `None` per
    /// robot). On an error, the failing robot; the decisions set before it stand.
    fn act(&mut self, team: &Team, decisions: &mut [Option<Decision>]) -> Result<(), RobotError>;

    /// The decision for the one robot of a team of one (a lone robot's episode), which runs:
    /// what [`TeamPolicy::act`] would decide for it, without a step's buffers. The default asks
    /// `act`.
    fn act_alone(&mut self, team: &Team) -> Result<Option<Decision>, PolicyError> {
        let mut decisions = [None];
        self.act(team, &mut decisions).map_err(|(_, e)| e)?;
        Ok(decisions[0].take())
    }

    /// Why the team's task cannot be done, when the policy found out at [`TeamPolicy::reset`]
    /// (no plan can bring every robot to its goals): the episode then ends before its first
    /// step, every robot's outcome `infeasible`. The default finds nothing.
    fn infeasible(&self) -> Option<&str> {
        None
    }

    /// The message robot `k` broadcasts with its last decision (`team.message_size` floats,
    /// zeros already in `out`); asked after [`TeamPolicy::act`] for each robot that acted. The
    /// default sends none.
    fn message(&mut self, robot: usize, out: &mut [f32]) {
        let _ = (robot, out);
    }

    /// Robot `k` reached a goal of its list and drives on to the next (its `episode` now heads
    /// there): a policy that planned the leg plans afresh.
    fn next_goal(&mut self, k: usize, world: &World, episode: &Episode) -> Result<(), PolicyError>;
}

/// Makes team policies: one per team episode.
pub trait TeamPolicyFactory: Sync {
    /// A fresh team policy.
    fn make(&self) -> Result<Box<dyn TeamPolicy>, PolicyError>;

    /// The name of the policy that drives each robot, in robot order (for records and tables).
    fn names(&self) -> Vec<String>;
}

/// Each robot driven by its own [`Policy`], deciding from its own view of the team: it hears
/// its inbox, then decides, then says its message, one robot after the other.
pub struct PerRobot {
    policies: Vec<Box<dyn Policy>>,
    /// What each robot said with its last decision.
    said: Vec<Vec<f32>>,
}

impl PerRobot {
    /// Robot `k` driven by `policies[k]`.
    pub fn new(policies: Vec<Box<dyn Policy>>) -> Self {
        Self {
            said: vec![Vec::new(); policies.len()],
            policies,
        }
    }
}

impl TeamPolicy for PerRobot {
    fn reset(&mut self, team: &Team, worlds: &[Arc<World>]) -> Result<(), RobotError> {
        if self.policies.len() != team.robots().len() {
            return Err((
                self.policies.len().min(team.robots().len()),
                PolicyError::Failed(format!(
                    "{} policies for {} robots",
                    self.policies.len(),
                    team.robots().len()
                )),
            ));
        }
        for (k, policy) in self.policies.iter_mut().enumerate() {
            policy
                .reset(&worlds[k], team.robot(k))
                .map_err(|e| (k, e))?;
        }
        Ok(())
    }

    fn act(&mut self, team: &Team, decisions: &mut [Option<Decision>]) -> Result<(), RobotError> {
        let size = team.message_size();
        for (k, policy) in self.policies.iter_mut().enumerate() {
            if !team.running(k) {
                continue;
            }
            policy.hear(team.inbox(k));
            let decision = policy.act_in_team(team, k).map_err(|e| (k, e))?;
            if size > 0 && matches!(decision, Decision::Act(_)) {
                let said = &mut self.said[k];
                said.clear();
                said.resize(size, 0.0);
                policy.message(said);
            }
            decisions[k] = Some(decision);
        }
        Ok(())
    }

    fn message(&mut self, robot: usize, out: &mut [f32]) {
        for (o, m) in out.iter_mut().zip(&self.said[robot]) {
            *o = *m;
        }
    }

    fn next_goal(&mut self, k: usize, world: &World, episode: &Episode) -> Result<(), PolicyError> {
        self.policies[k].reset(world, episode)
    }
}

/// A lone robot's policy as the team policy of its team of one (the evaluator runs a lone robot
/// so): it decides from its robot's view of the team, which shows the moving obstacles
/// ([`Policy::act_in_team`]), and hears and says nothing, as it would alone.
pub struct Alone<'a>(pub &'a mut dyn Policy);

impl TeamPolicy for Alone<'_> {
    fn reset(&mut self, team: &Team, worlds: &[Arc<World>]) -> Result<(), RobotError> {
        self.0.reset(&worlds[0], team.robot(0)).map_err(|e| (0, e))
    }

    fn act(&mut self, team: &Team, decisions: &mut [Option<Decision>]) -> Result<(), RobotError> {
        if team.running(0) {
            decisions[0] = Some(self.0.act_in_team(team, 0).map_err(|e| (0, e))?);
        }
        Ok(())
    }

    fn act_alone(&mut self, team: &Team) -> Result<Option<Decision>, PolicyError> {
        self.0.act_in_team(team, 0).map(Some)
    }

    fn next_goal(&mut self, _: usize, world: &World, episode: &Episode) -> Result<(), PolicyError> {
        self.0.reset(world, episode)
    }
}

/// Makes [`PerRobot`] team policies: robot `k`'s policy from `factories[k]`, named `names[k]`.
pub struct PerRobotFactory<'a> {
    factories: Vec<&'a dyn PolicyFactory>,
    names: Vec<String>,
}

impl<'a> PerRobotFactory<'a> {
    /// Robot `k` driven by a policy from `factories[k]`, reported as `names[k]`.
    pub fn new(factories: Vec<&'a dyn PolicyFactory>, names: Vec<String>) -> Self {
        Self { factories, names }
    }
}

impl TeamPolicyFactory for PerRobotFactory<'_> {
    fn make(&self) -> Result<Box<dyn TeamPolicy>, PolicyError> {
        let policies = self
            .factories
            .iter()
            .map(|f| f.make())
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Box::new(PerRobot::new(policies)))
    }

    fn names(&self) -> Vec<String> {
        self.names.clone()
    }
}

/// A team whose robots marked `joint` are decided together by one [`BatchPolicy`] call a step
/// (a `(robots, observation size)` array of those running, in robot order: `ronap run --batch`
/// on a team scenario, a joint Python function), the others each by a [`Policy`] of their own.
pub struct Joint {
    batch: Box<dyn BatchPolicy>,
    joint: Vec<bool>,
    others: Vec<Option<Box<dyn Policy>>>,
    rows: Vec<f32>,
    robots: Vec<usize>,
    actions: Vec<crate::sim::Action>,
}

impl Joint {
    /// Robots `k` with `joint[k]` decided by `batch`, the others by `others[k]`.
    pub fn new(
        batch: Box<dyn BatchPolicy>,
        joint: Vec<bool>,
        others: Vec<Option<Box<dyn Policy>>>,
    ) -> Self {
        Self {
            batch,
            joint,
            others,
            rows: Vec::new(),
            robots: Vec::new(),
            actions: Vec::new(),
        }
    }
}

impl TeamPolicy for Joint {
    fn reset(&mut self, team: &Team, worlds: &[Arc<World>]) -> Result<(), RobotError> {
        let n = team.robots().len();
        if self.joint.len() != n || self.others.len() != n {
            return Err((
                0,
                PolicyError::Failed(format!("policies for {} robots, not {n}", self.joint.len())),
            ));
        }
        let mut width = None;
        for (k, world) in worlds.iter().enumerate().take(n) {
            if let Some(policy) = &mut self.others[k] {
                policy.reset(world, team.robot(k)).map_err(|e| (k, e))?;
            } else if self.joint[k] {
                let w = team.robot(k).observation().len();
                if *width.get_or_insert(w) != w {
                    return Err((
                        k,
                        PolicyError::Failed(
                            "robots decided together need observations of one size (its laser \
                             has another beam count)"
                                .into(),
                        ),
                    ));
                }
            }
        }
        Ok(())
    }

    fn act(&mut self, team: &Team, decisions: &mut [Option<Decision>]) -> Result<(), RobotError> {
        self.rows.clear();
        self.robots.clear();
        for (k, decision) in decisions.iter_mut().enumerate() {
            if !team.running(k) {
                continue;
            }
            if let Some(policy) = &mut self.others[k] {
                policy.hear(team.inbox(k));
                *decision = Some(policy.act(team.robot(k)).map_err(|e| (k, e))?);
            } else if self.joint[k] {
                self.rows.extend_from_slice(team.robot(k).observation());
                self.robots.push(k);
            }
        }
        let Some(&first) = self.robots.first() else {
            return Ok(());
        };
        let width = self.rows.len() / self.robots.len();
        self.actions.clear();
        self.batch
            .act_batch(
                super::Rows {
                    values: &self.rows,
                    width,
                },
                &mut self.actions,
            )
            .map_err(|e| (first, e))?;
        if self.actions.len() != self.robots.len() {
            return Err((
                first,
                PolicyError::Failed(format!(
                    "returned {} actions for {} robots, expected one per row",
                    self.actions.len(),
                    self.robots.len()
                )),
            ));
        }
        for (&k, &a) in self.robots.iter().zip(&self.actions) {
            decisions[k] = Some(Decision::Act(a));
        }
        Ok(())
    }

    fn message(&mut self, robot: usize, out: &mut [f32]) {
        if let Some(policy) = &mut self.others[robot] {
            policy.message(out);
        }
    }

    fn next_goal(&mut self, k: usize, world: &World, episode: &Episode) -> Result<(), PolicyError> {
        match &mut self.others[k] {
            Some(policy) => policy.reset(world, episode),
            None => Ok(()),
        }
    }
}

/// Makes [`Joint`] team policies of every robot together: a fresh [`BatchPolicy`] from `make`
/// for each team episode, every robot named `name`.
pub struct JointFactory {
    make: Box<dyn Fn() -> Result<Box<dyn BatchPolicy>, PolicyError> + Sync>,
    robots: usize,
    name: String,
}

impl JointFactory {
    /// `robots` robots decided together by batch policies from `make`, named `name`.
    pub fn new(
        make: Box<dyn Fn() -> Result<Box<dyn BatchPolicy>, PolicyError> + Sync>,
        robots: usize,
        name: String,
    ) -> Self {
        Self { make, robots, name }
    }
}

impl TeamPolicyFactory for JointFactory {
    fn make(&self) -> Result<Box<dyn TeamPolicy>, PolicyError> {
        Ok(Box::new(Joint::new(
            (self.make)()?,
            vec![true; self.robots],
            (0..self.robots).map(|_| None).collect(),
        )))
    }

    fn names(&self) -> Vec<String> {
        vec![self.name.clone(); self.robots]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::TeamRobotConfig;
    use crate::run::{RunError, TeamRollout};
    use crate::sim::{DiscreteAction, Worlds};

    /// Robot 0 drives ahead and says its step; robot 1 gives up at once; robot 2's policy
    /// fails at the third step.
    struct Scripted {
        steps: u32,
    }

    impl TeamPolicy for Scripted {
        fn reset(&mut self, _: &Team, _: &[Arc<World>]) -> Result<(), RobotError> {
            self.steps = 0;
            Ok(())
        }

        fn act(
            &mut self,
            team: &Team,
            decisions: &mut [Option<Decision>],
        ) -> Result<(), RobotError> {
            self.steps += 1;
            for (k, d) in decisions.iter_mut().enumerate() {
                if !team.running(k) {
                    continue;
                }
                *d = Some(match k {
                    1 => Decision::GiveUp("waits for the others".into()),
                    2 if self.steps == 3 => {
                        return Err((k, PolicyError::Failed("no plan".into())));
                    }
                    _ => Decision::Act(DiscreteAction::Ahead.into()),
                });
            }
            Ok(())
        }

        fn message(&mut self, robot: usize, out: &mut [f32]) {
            out[0] = robot as f32 + 10.0 * self.steps as f32;
        }

        fn next_goal(&mut self, _: usize, _: &World, _: &Episode) -> Result<(), PolicyError> {
            Ok(())
        }
    }

    #[test]
    fn a_team_policy_decides_for_every_robot_at_once() {
        let mut config = crate::SimConfig {
            robots: vec![TeamRobotConfig {
                count: 3,
                ..Default::default()
            }],
            ..Default::default()
        };
        config.team.message_size = 1;
        config.team.comm_range_px = 1e5;
        let config = config.validate().expect("valid");
        let worlds = Worlds::new(config.clone(), crate::sim::Scenes::MazePerSeed);
        let mut policy = Scripted { steps: 0 };
        let mut rollout =
            TeamRollout::start(&config, worlds.team(4), 4, &mut policy).expect("starts");
        assert!(rollout.advance(&mut policy).expect("step 1"));
        assert_eq!(rollout.gave_up(1), Some("waits for the others"));
        assert!(rollout.team().retired(1));
        assert!(!rollout.team().retired(0) && !rollout.team().retired(2));
        assert_eq!(rollout.team().robot(0).steps(), 1);
        assert_eq!(rollout.team().robot(1).steps(), 0);
        // Robot 0's message of step 1 reached robot 2 (and robot 1, retired but present).
        let heard: Vec<(usize, f32)> = rollout
            .team()
            .inbox(2)
            .iter()
            .map(|b| (b.from, b.message[0]))
            .collect();
        assert!(heard.contains(&(0, 10.0)), "{heard:?}");
        assert!(rollout.advance(&mut policy).expect("step 2"));
        match rollout.advance(&mut policy) {
            Err(RunError::Policy { seed, step, source }) => {
                assert_eq!((seed, step), (4, 3));
                assert_eq!(source, PolicyError::Failed("no plan".into()));
            }
            other => panic!("expected robot 2's failure, got {other:?}"),
        }
    }
}
