//! The reward a learner is given under `reward.shaping = "geodesic"` (docs/model.md "Reward"): the
//! paper's straight-line progress term r_b replaced by potential-based shaping
//! `F = gamma Phi(s') - Phi(s)`, `Phi = -progress_per_px x` the geodesic distance to the goal
//! (Ng, Harada and Russell 1999), so that heading into a dead end no longer pays. The potential of
//! a state that ends the episode other than by a time-out is 0; a time-out cuts the episode
//! short without ending the task, so its last state keeps its potential.
//!
//! Summed with discount gamma over an episode, F telescopes to `gamma^T Phi(s_T) - Phi(s_0)`:
//! a constant for episodes from one start that end at the goal, so the order of their returns, and
//! the optimal policy, are those of the other three terms. The sim layer's episode knows nothing
//! of planners; the distance field comes from [`crate::plan`], one per goal, searched only as far
//! as the robot's poses need.

use crate::config::Shaping;
use crate::plan::LazyField;
use crate::run::TeamRollout;
use crate::sim::{Episode, World};
use std::sync::Arc;

/// The shaping of one episode: its field towards the current goal and the current potential.
#[derive(Debug)]
pub struct Shaper {
    world: Arc<World>,
    field: LazyField,
    /// Phi of the current state.
    potential: f64,
    /// Summed shaped reward so far.
    total: f64,
}

impl Shaper {
    /// The shaping of `episode`, just started in `world`, when its configuration asks for it.
    pub fn start(world: Arc<World>, episode: &Episode) -> Option<Self> {
        if world.config().reward.shaping == Shaping::None {
            return None;
        }
        let field = field(&world, episode);
        let mut shaper = Self {
            world,
            field,
            potential: 0.0,
            total: 0.0,
        };
        shaper.potential = shaper.potential_of(episode);
        Some(shaper)
    }

    /// The shaped reward of the step `episode` just took, whose reward was `reward`.
    pub fn step(&mut self, episode: &Episode, reward: f64) -> f64 {
        let next = if episode.status().is_terminated() {
            0.0
        } else {
            if self.field.goal() != episode.goal() {
                // On to the next goal of a list: the potential follows the new goal.
                self.field = field(&self.world, episode);
            }
            self.potential_of(episode)
        };
        let gamma = self.world.config().reward.shaping_gamma;
        let shaped = reward - episode.last_progress_reward() + gamma * next - self.potential;
        self.potential = next;
        self.total += shaped;
        shaped
    }

    /// The potential of the current state, Phi(s).
    pub fn potential(&self) -> f64 {
        self.potential
    }

    /// The shaped rewards of the episode so far, summed.
    pub fn total(&self) -> f64 {
        self.total
    }

    /// Phi at `episode`'s pose: the geodesic distance, or the straight line where the field does
    /// not reach (a pose outside the goal's free region, which a robot never enters).
    fn potential_of(&mut self, episode: &Episode) -> f64 {
        let p = episode.pose().position();
        let distance = self
            .field
            .distance_at(self.world.grid(), p)
            .unwrap_or_else(|| (episode.goal() - p).norm());
        -self.world.config().reward.progress_per_px * distance
    }
}

/// The shaping of a team episode's robots: each one's reward shaped towards its own current goal
/// ([`Shaper`]) at each step it acts; none when the configuration asks for no shaping.
#[derive(Debug, Default)]
pub struct TeamShaper {
    robots: Vec<Option<Shaper>>,
}

impl TeamShaper {
    /// The shaping of `rollout`'s robots, just placed.
    pub fn start(rollout: &TeamRollout) -> Self {
        let team = rollout.team();
        Self {
            robots: (0..team.robots().len())
                .map(|k| Shaper::start(rollout.world(k).clone(), team.robot(k)))
                .collect(),
        }
    }

    /// Robot `k`'s reward for the step it just took in `episode` (its own episode in the team),
    /// whose reward was `reward`: shaped, or as it was without shaping. Call it only for a robot
    /// that acted in the step (it was running and had an action).
    pub fn shaped(&mut self, k: usize, episode: &Episode, reward: f64) -> f64 {
        match self.robots.get_mut(k) {
            Some(Some(shaper)) => shaper.step(episode, reward),
            _ => reward,
        }
    }
}

/// The plain shortest-path field towards `episode`'s goal for its robot's disc, searched out from
/// the goal towards the robot.
fn field(world: &World, episode: &Episode) -> LazyField {
    LazyField::new(
        world.scene(),
        world.grid(),
        episode.goal(),
        episode.pose().position(),
        world.config().robot.radius_px,
        1.0,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::policy::{Builtin, Decision, PolicyFactory};
    use crate::sim::{Action, DiscreteAction};
    use crate::SimConfig;

    /// The default maze of seed 3 with geodesic shaping at `gamma`.
    fn world(gamma: f64) -> Arc<World> {
        let mut c = SimConfig::default();
        c.reward.shaping = Shaping::Geodesic;
        c.reward.shaping_gamma = gamma;
        Arc::new(World::maze(c.validate().unwrap(), 3))
    }

    /// One trajectory from seed 3's start: the geodesic policy's actions, with a turn left and
    /// back right every `detour` steps (0: none). Returns the discounted return of the shaped
    /// rewards, that of the paper's rewards without the progress term, Phi(s_0), Phi(s_T) and
    /// whether it ended at the goal.
    fn trajectory(world: &Arc<World>, detour: u32) -> (f64, f64, f64, f64, bool) {
        let gamma = world.config().reward.shaping_gamma;
        let mut episode = world.episode(3).unwrap();
        let mut shaper = Shaper::start(world.clone(), &episode).unwrap();
        let phi0 = shaper.potential();
        let mut policy = Builtin::Geodesic.make().unwrap();
        policy.reset(world, &episode).unwrap();
        let (mut shaped, mut sparse, mut discount) = (0.0, 0.0, 1.0);
        let mut t = 0;
        while !episode.status().is_done() {
            let action = if detour > 0 && t % detour == 0 {
                Action::from(DiscreteAction::Left)
            } else if detour > 0 && t % detour == 1 {
                Action::from(DiscreteAction::Right)
            } else {
                match policy.act(&episode).unwrap() {
                    Decision::Act(a) => a,
                    Decision::GiveUp(why) => panic!("{why}"),
                }
            };
            let reward = episode.step(action).reward;
            let r = shaper.step(&episode, reward);
            shaped += discount * r;
            sparse += discount * (reward - episode.last_progress_reward());
            discount *= gamma;
            t += 1;
        }
        let success = episode.status() == crate::Status::Success;
        (shaped, sparse, phi0, shaper.potential(), success)
    }

    #[test]
    fn the_shaping_terms_telescope() {
        for gamma in [1.0, 0.99, 0.9] {
            let w = world(gamma);
            for detour in [0, 7, 13] {
                let (shaped, sparse, phi0, phi_end, _) = trajectory(&w, detour);
                // Summed with discount, F is gamma^T Phi(s_T) - Phi(s_0); Phi(s_T) = 0 at the
                // goal, and these runs reach it.
                assert_eq!(phi_end, 0.0);
                let off = (shaped - sparse + phi0).abs();
                assert!(off < 1e-9, "gamma {gamma}, detour {detour}: {off}");
            }
        }
    }

    #[test]
    fn shaping_keeps_the_order_of_returns_of_episodes_that_reach_the_goal() {
        let w = world(0.99);
        let (direct, direct_sparse, phi0, _, ok1) = trajectory(&w, 0);
        let (wiggly, wiggly_sparse, phi0_b, _, ok2) = trajectory(&w, 5);
        assert!(ok1 && ok2);
        assert_eq!(phi0, phi0_b);
        // The same constant apart (-Phi(s_0)), so the same order, with or without shaping.
        assert!((direct - direct_sparse - (wiggly - wiggly_sparse)).abs() < 1e-9);
        assert!(direct > wiggly && direct_sparse > wiggly_sparse);
        // The start's potential is the geodesic distance, at least the straight line.
        let e = w.episode(3).unwrap();
        assert!(-phi0 / 0.1 >= e.distance_px() - 1e-9);
    }

    #[test]
    fn walking_into_a_dead_end_is_not_paid() {
        // Straight-line progress pays for moving towards the goal through a wall; the geodesic
        // potential pays only for what shortens the way round. Over a random walk, every step
        // that shortens the straight line but lengthens the geodesic gets a negative F.
        let w = world(1.0);
        let mut episode = w.episode(11).unwrap();
        let mut shaper = Shaper::start(w.clone(), &episode).unwrap();
        let mut rng = crate::sim::stream(5, crate::sim::Stream::Policy);
        let mut seen = 0;
        for _ in 0..2000 {
            if episode.status().is_done() {
                break;
            }
            use rand::Rng as _;
            let a = DiscreteAction::ALL[rng.random_range(0..3)];
            let before = shaper.potential();
            let reward = episode.step(Action::from(a)).reward;
            let straight = episode.last_progress_reward();
            let shaped = shaper.step(&episode, reward);
            let f = shaped - (reward - straight);
            if straight > 1e-9 && shaper.potential() < before - 1e-9 {
                seen += 1;
                assert!(f < 0.0, "{f}");
            }
        }
        assert!(
            seen > 0,
            "the walk never moved towards the goal the wrong way"
        );
    }
}
