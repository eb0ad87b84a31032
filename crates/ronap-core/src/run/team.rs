//! A team rollout: one episode of several robots, each driven by its own policy, a step at a
//! time. Every policy decides from the same state (its robot's own episode view: pose, laser with
//! the other robots in it, goal), then the team moves at once. A policy that gives up takes its
//! robot out of the running; it stays where it is, an obstacle to the others.

use crate::policy::{Decision, Policy};
use crate::run::RunError;
use crate::sim::robot::Action;
use crate::sim::team::Team;
use crate::sim::world::World;
use std::sync::Arc;

/// One team episode in progress with its robots' policies' reasons for giving up.
#[derive(Clone, Debug)]
pub struct TeamRollout {
    team: Team,
    worlds: Vec<Arc<World>>,
    gave_up: Vec<Option<String>>,
}

impl TeamRollout {
    /// The team episode of `seed` under `config` (with its `[[robots]]`) in `worlds` (one per
    /// entry, [`crate::sim::world::Worlds::team`]), with `policies[k]` (one per robot) reset
    /// for it.
    pub fn start(
        config: &crate::ValidConfig,
        worlds: Vec<Arc<World>>,
        seed: u64,
        policies: &mut [Box<dyn Policy>],
    ) -> Result<Self, RunError> {
        let team = Team::new(config, &worlds, seed)
            .map_err(|source| RunError::Episode { seed, source })?;
        let n = team.robots().len();
        if policies.len() != n {
            return Err(RunError::ActionCount {
                given: policies.len(),
                envs: n,
            });
        }
        let per_robot = robot_worlds(config, &worlds);
        for (k, policy) in policies.iter_mut().enumerate() {
            policy
                .reset(&per_robot[k], team.robot(k))
                .map_err(|source| RunError::Policy {
                    seed,
                    step: 0,
                    source,
                })?;
        }
        Ok(Self {
            gave_up: vec![None; n],
            team,
            worlds: per_robot,
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

    /// Why robot `k`'s policy gave up, if it did.
    pub fn gave_up(&self, k: usize) -> Option<&str> {
        self.gave_up[k].as_deref()
    }

    /// Whether every robot is done.
    pub fn finished(&self) -> bool {
        self.team.is_done()
    }

    /// One step: every running robot's policy decides, then the team moves. `false` once the
    /// episode is over (nothing was stepped).
    pub fn advance(&mut self, policies: &mut [Box<dyn Policy>]) -> Result<bool, RunError> {
        if self.finished() {
            return Ok(false);
        }
        let n = self.team.robots().len();
        let step = self.team.steps() + 1;
        let mut actions: Vec<Option<Action>> = vec![None; n];
        for k in 0..n {
            if !self.team.running(k) {
                continue;
            }
            let episode = self.team.robot(k);
            let seed = episode.seed();
            match policies[k]
                .act(episode)
                .map_err(|source| RunError::Policy { seed, step, source })?
            {
                Decision::Act(action) => {
                    if let Action::Continuous { v, w_deg } = action {
                        if !v.is_finite() || !w_deg.is_finite() {
                            return Err(RunError::InvalidAction { seed, step, action });
                        }
                    }
                    actions[k] = Some(action);
                }
                Decision::GiveUp(why) => {
                    self.gave_up[k] = Some(why);
                    self.team.retire(k);
                }
            }
        }
        if self.finished() {
            return Ok(false);
        }
        self.team.step(&actions);
        Ok(true)
    }

    /// The team, and each robot's reason for giving up.
    pub fn into_parts(self) -> (Team, Vec<Arc<World>>, Vec<Option<String>>) {
        (self.team, self.worlds, self.gave_up)
    }
}

/// Each robot's world: its entry's.
fn robot_worlds(config: &crate::ValidConfig, worlds: &[Arc<World>]) -> Vec<Arc<World>> {
    config
        .robots
        .iter()
        .zip(worlds)
        .flat_map(|(e, w)| std::iter::repeat_n(w.clone(), e.count as usize))
        .collect()
}
