//! A team rollout: one episode of several robots, each driven by its own policy, a step at a
//! time. Every policy decides from the same state (its robot's own episode view: pose, laser with
//! the other robots in it, goal), then the team moves at once. A policy that gives up takes its
//! robot out of the running; it stays where it is, an obstacle to the others. A lone robot's
//! episode is its team of one (a configuration without `[[robots]]`), stepped here too.

use crate::geometry::Point;
use crate::plan::{path_length, smooth, CostMatrix, DistanceField, Order};
use crate::policy::{Decision, TeamPolicy};
use crate::run::RunError;
use crate::sim::{Action, Team, World};
use std::sync::Arc;

/// One team episode in progress with its robots' policies' reasons for giving up.
#[derive(Clone, Debug)]
pub struct TeamRollout {
    team: Team,
    worlds: Vec<Arc<World>>,
    gave_up: Vec<Option<String>>,
    /// The tour lengths of each robot with a goal list.
    tours: Vec<Option<TourLengths>>,
    /// Floats in a policy's message.
    message_size: usize,
    /// The actions of the last step, robot by robot (`None`: the robot did not act).
    actions: Vec<Option<Action>>,
    /// Why no plan can do the task, when the team policy found so before the first step.
    infeasible: Option<String>,
    /// A step's buffers, kept between steps: the decisions, the actions being made, a message,
    /// and each robot's goals reached before the step.
    decisions: Vec<Option<Decision>>,
    next_actions: Vec<Option<Action>>,
    message: Vec<f32>,
    reached: Vec<u32>,
}

/// A goal list's tour lengths under each order (geodesic, px; infinite where a leg cannot be
/// driven), and the one the robot drives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TourLengths {
    /// In the order listed or drawn.
    pub given: f64,
    /// Greedily to the nearest goal.
    pub nearest: f64,
    /// The shortest tour (exact up to 12 goals).
    pub optimal: f64,
    /// The order the robot drives.
    pub chosen: Order,
}

impl TourLengths {
    /// The length of the tour the robot drives.
    pub fn chosen_px(&self) -> f64 {
        match self.chosen {
            Order::Given => self.given,
            Order::Nearest => self.nearest,
            Order::Optimal => self.optimal,
        }
    }
}

/// The tour lengths from `start` through `goals` in `world` under every order, and the visiting
/// order `order` gives (indices into `goals`). Costs are shortest-path lengths for the world's
/// robot (a distance field per goal, each leg's path smoothed).
fn plan_tour(
    world: &World,
    start: Point,
    goals: &[Point],
    order: Order,
) -> (TourLengths, Vec<usize>) {
    let radius = world.config().robot.radius_px;
    let nodes: Vec<Point> = std::iter::once(start)
        .chain(goals.iter().copied())
        .collect();
    let fields: Vec<DistanceField> = goals
        .iter()
        .map(|&g| DistanceField::new(world.scene(), world.grid(), g, radius, 1.0))
        .collect();
    let leg = |from: usize, to: usize| -> f64 {
        if to == 0 || from == to {
            return 0.0;
        }
        fields[to - 1]
            .path(world.scene(), world.grid(), nodes[from], radius)
            .map_or(f64::INFINITY, |p| {
                path_length(&smooth(world.scene(), &p, radius))
            })
    };
    let tours = CostMatrix::from_fn(nodes.len(), leg).map(|costs| {
        [Order::Given, Order::Nearest, Order::Optimal].map(|o| crate::plan::order(&costs, o))
    });
    match tours {
        Ok([given, nearest, optimal]) => {
            let visit = match order {
                Order::Given => given.goals.clone(),
                Order::Nearest => nearest.goals.clone(),
                Order::Optimal => optimal.goals.clone(),
            };
            (
                TourLengths {
                    given: given.length,
                    nearest: nearest.length,
                    optimal: optimal.length,
                    chosen: order,
                },
                visit,
            )
        }
        Err(_) => (
            TourLengths {
                given: f64::INFINITY,
                nearest: f64::INFINITY,
                optimal: f64::INFINITY,
                chosen: order,
            },
            (0..goals.len()).collect(),
        ),
    }
}

impl TeamRollout {
    /// The team episode of `seed` under `config` in `worlds` (one per `[[robots]]` entry, or the
    /// lone robot's one world: [`crate::sim::Worlds::team`]), with `policy` reset for it.
    pub fn start(
        config: &crate::ValidConfig,
        worlds: Vec<Arc<World>>,
        seed: u64,
        policy: &mut dyn TeamPolicy,
    ) -> Result<Self, RunError> {
        let mut rollout = Self::placed(config, worlds, seed)?;
        policy
            .reset(&rollout.team, &rollout.worlds)
            .map_err(|(_, e)| RunError::reset(seed, e))?;
        // An infeasible task ends before its first step: every robot out of the running.
        if let Some(why) = policy.infeasible() {
            rollout.infeasible = Some(why.to_string());
            for k in 0..rollout.team.robots().len() {
                rollout.team.retire(k);
            }
        }
        Ok(rollout)
    }

    /// The team episode of `seed` with every goal list put in its order, for actions chosen
    /// outside (an environment stepped from Python): [`TeamRollout::step`] moves it.
    pub fn placed(
        config: &crate::ValidConfig,
        worlds: Vec<Arc<World>>,
        seed: u64,
    ) -> Result<Self, RunError> {
        let team = Team::new(config, &worlds, seed)
            .map_err(|source| RunError::Episode { seed, source })?;
        let n = team.robots().len();
        let per_robot = robot_worlds(config, &worlds);
        let mut team = team;
        let mut tours = vec![None; n];
        for (k, tour) in tours.iter_mut().enumerate() {
            if team.goals(k).len() < 2 {
                continue;
            }
            let order = config.team_entry(k).map(|e| e.order).unwrap_or_default();
            let (lengths, visit) = plan_tour(
                &per_robot[k],
                team.robot(k).start().position(),
                team.goals(k),
                order,
            );
            team.order_goals(k, &visit);
            *tour = Some(lengths);
        }
        Ok(Self {
            gave_up: vec![None; n],
            actions: vec![None; n],
            team,
            worlds: per_robot,
            tours,
            message_size: config.team.message_size as usize,
            infeasible: None,
            decisions: Vec::new(),
            next_actions: Vec::new(),
            message: Vec::new(),
            reached: Vec::new(),
        })
    }

    /// The team.
    pub fn team(&self) -> &Team {
        &self.team
    }

    /// Robot `k`'s world.
    pub fn world(&self, k: usize) -> &Arc<World> {
        &self.worlds[k]
    }

    /// The episode of a lone robot's team of one, which holds all of it ([`Team::lone_mut`]);
    /// `None` for any other team.
    pub fn lone_mut(&mut self) -> Option<&mut crate::sim::Episode> {
        self.team.lone_mut()
    }

    /// Robot `k`'s tour lengths, when it has a goal list.
    pub fn tour(&self, k: usize) -> Option<TourLengths> {
        self.tours[k]
    }

    /// Why no plan can do the task, when the team policy found so before the first step.
    pub fn infeasible(&self) -> Option<&str> {
        self.infeasible.as_deref()
    }

    /// Why robot `k`'s policy gave up, if it did.
    pub fn gave_up(&self, k: usize) -> Option<&str> {
        self.gave_up[k].as_deref()
    }

    /// Sets robot `k`'s message for the next broadcast (`team.message_size` floats; shorter is
    /// padded with zeros, longer cut).
    pub fn set_message(&mut self, k: usize, message: &[f32]) {
        self.team.set_message(k, message);
    }

    /// One step of actions chosen outside: `actions[k]` for robot `k` (`None`: it stands).
    /// Robots whose episodes are over ignore theirs.
    pub fn step(&mut self, actions: &[Option<Action>]) {
        self.team.step(actions);
        self.actions.clear();
        self.actions.extend_from_slice(actions);
    }

    /// Takes robot `k` out of the running, as its policy giving up does (replaying a log that
    /// ends while the team goes on).
    pub fn retire(&mut self, k: usize) {
        self.team.retire(k);
    }

    /// What each robot did at the last step (`None`: it did not act).
    pub fn last_actions(&self) -> &[Option<Action>] {
        &self.actions
    }

    /// Robot `k`'s `decision` for the next step, checked: the action to take, or `None` when
    /// the policy gave up (the robot is then out of the running, [`TeamRollout::gave_up`] says
    /// why). An action that is not finite, or one the robot does not take, is an error.
    /// [`TeamRollout::advance`] checks every decision so; a caller asking the policy itself
    /// (episodes side by side) does, then [steps](TeamRollout::step).
    pub fn decided(&mut self, k: usize, decision: Decision) -> Result<Option<Action>, RunError> {
        match decision {
            Decision::Act(action) if self.accepts(k, action) => Ok(Some(action)),
            Decision::Act(action) => Err(self.invalid(action)),
            Decision::GiveUp(why) => {
                self.give_up(k, why);
                Ok(None)
            }
        }
    }

    /// Whether robot `k` takes `action`: finite, and of its kinematics.
    fn accepts(&self, k: usize, action: Action) -> bool {
        let kind = self.team.robot(k).config().robot.kinematics;
        action.is_finite() && crate::sim::accepts(kind, action)
    }

    /// The error of a policy deciding `action`, which its robot does not take.
    #[cold]
    fn invalid(&self, action: Action) -> RunError {
        RunError::InvalidAction {
            seed: self.seed(),
            step: self.team.steps() + 1,
            action,
        }
    }

    /// Takes robot `k` out of the running, its policy having given up for `why`.
    fn give_up(&mut self, k: usize, why: String) {
        self.gave_up[k] = Some(why);
        self.team.retire(k);
    }

    /// The error of the policy failing to decide the next step.
    #[cold]
    pub fn policy_error(&self, source: crate::policy::PolicyError) -> RunError {
        RunError::Policy {
            seed: self.seed(),
            step: self.team.steps() + 1,
            source,
        }
    }

    /// The episode's seed.
    pub fn seed(&self) -> u64 {
        self.team.robot(0).seed()
    }

    /// Whether every robot is done.
    pub fn finished(&self) -> bool {
        self.team.is_done()
    }

    /// One step: the team policy decides for every running robot, then the team moves. `false`
    /// once the episode is over (nothing was stepped).
    pub fn advance(&mut self, policy: &mut dyn TeamPolicy) -> Result<bool, RunError> {
        if self.finished() {
            return Ok(false);
        }
        let n = self.team.robots().len();
        if n == 1 && self.message_size == 0 {
            return self.advance_alone(policy);
        }
        let step = self.team.steps() + 1;
        let seed = self.seed();
        let mut decisions = std::mem::take(&mut self.decisions);
        decisions.clear();
        decisions.resize(n, None);
        let failed = policy.act(&self.team, &mut decisions).err();
        // Robot by robot, as the robots decided: a robot's invalid action before the robot
        // whose policy failed is the error.
        let mut actions = std::mem::take(&mut self.next_actions);
        actions.clear();
        actions.resize(n, None);
        let mut message = std::mem::take(&mut self.message);
        message.clear();
        message.resize(self.message_size, 0.0);
        for (k, decision) in decisions.drain(..).enumerate() {
            if failed.as_ref().is_some_and(|(j, _)| *j <= k) {
                break;
            }
            match decision {
                Some(decision) if self.team.running(k) => {
                    let Some(action) = self.decided(k, decision)? else {
                        continue;
                    };
                    actions[k] = Some(action);
                    if !message.is_empty() {
                        message.fill(0.0);
                        policy.message(k, &mut message);
                        self.team.set_message(k, &message);
                    }
                }
                // A running robot left without a decision would never step nor end.
                None if self.team.running(k) => return Err(self.undecided(k)),
                _ => {}
            }
        }
        self.decisions = decisions;
        self.message = message;
        if let Some((_, source)) = failed {
            return Err(RunError::Policy { seed, step, source });
        }
        if self.finished() {
            return Ok(false);
        }
        self.reached.clear();
        self.reached
            .extend(self.team.robots().iter().map(|r| r.goals_reached()));
        self.team.step(&actions);
        // The last step's actions are kept; their buffer takes the next step's.
        self.next_actions = std::mem::replace(&mut self.actions, actions);
        // A robot on to the next goal of its list starts a new leg: its policy plans afresh.
        for (k, &reached) in self.reached.iter().enumerate() {
            let r = self.team.robot(k);
            if self.team.running(k) && r.goals_reached() > reached {
                policy
                    .next_goal(k, &self.worlds[k], r)
                    .map_err(|source| RunError::Policy { seed, step, source })?;
            }
        }
        Ok(true)
    }

    /// [`TeamRollout::advance`] for a team of one that sends no messages (a lone robot's), without
    /// the buffers a team's step needs: the same step at a lone robot's speed.
    fn advance_alone(&mut self, policy: &mut dyn TeamPolicy) -> Result<bool, RunError> {
        let decision = match policy.act_alone(&self.team) {
            Ok(decision) => decision,
            Err(source) => return Err(self.policy_error(source)),
        };
        // `decided`'s checks, matched here: a lone robot's every step passes this way, and
        // handing its answer back through `decided`'s result cost 2% more instructions
        // (`--policy random`, callgrind).
        let action = match decision {
            Some(Decision::Act(action)) if self.accepts(0, action) => action,
            Some(Decision::Act(action)) => return Err(self.invalid(action)),
            Some(Decision::GiveUp(why)) => {
                self.give_up(0, why);
                return Ok(false);
            }
            None => return Err(self.undecided(0)),
        };
        let reached = self.team.robot(0).goals_reached();
        self.team.step(&[Some(action)]);
        self.actions.clear();
        self.actions.push(Some(action));
        let r = self.team.robot(0);
        if self.team.running(0) && r.goals_reached() > reached {
            policy
                .next_goal(0, &self.worlds[0], r)
                .map_err(|source| RunError::Policy {
                    seed: self.seed(),
                    step: self.team.steps(),
                    source,
                })?;
        }
        Ok(true)
    }

    /// The error of the team policy leaving running robot `k` without a decision, which would
    /// never step nor end.
    #[cold]
    fn undecided(&self, k: usize) -> RunError {
        self.policy_error(crate::policy::PolicyError::Failed(format!(
            "the team policy decided nothing for robot {k}, which is running"
        )))
    }

    /// The team, and each robot's reason for giving up.
    pub fn into_parts(self) -> (Team, Vec<Arc<World>>, Vec<Option<String>>) {
        (self.team, self.worlds, self.gave_up)
    }
}

/// Each robot's world: its entry's (a lone robot's team of one: its one world).
pub(crate) fn robot_worlds(config: &crate::ValidConfig, worlds: &[Arc<World>]) -> Vec<Arc<World>> {
    if config.robots.is_empty() {
        return worlds.to_vec();
    }
    config
        .robots
        .iter()
        .zip(worlds)
        .flat_map(|(e, w)| std::iter::repeat_n(w.clone(), e.count as usize))
        .collect()
}
