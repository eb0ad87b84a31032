//! The paper's Collect Data mode with a person at the keys (docs/model.md "Data log"): the person
//! chooses LEFT, AHEAD or RIGHT for the state shown; the action is recorded with that state
//! ([`Sample::before`]), taken, and the robot then jumps to a random free pose facing roughly
//! towards the goal ([`Episode::repose`], from the seed's re-posing stream, as `ronap collect
//! --expert` does). Anti-mispress: after an action the action keys do nothing until the person
//! re-arms them (the paper's down arrow), so a held or doubled key records one row.
//!
//! Nothing here knows about keys or terminals: the front end maps its keys to
//! [`HumanCollector::act`] and [`HumanCollector::rearm`].

use crate::eval::Evaluator;
use crate::io::Sample;
use crate::run::RunError;
use crate::sim::{stream, DiscreteAction, Episode, Pose, Rng, Status, Stream, World};
use std::sync::Arc;

/// What the latest recorded action did, for the person to see.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Outcome {
    /// The action.
    pub action: DiscreteAction,
    /// It collided (the paper's "CollisionWarning"; the robot stayed where it was).
    pub collided: bool,
    /// It reached the goal (the paper's "TaskComplete"; the episode starts afresh).
    pub reached_goal: bool,
    /// The pose it was taken from.
    pub from: Pose,
}

/// A person's data-collection session: one seed (scene and goal) after another, `per_episode`
/// rows each.
pub struct HumanCollector<'a> {
    evaluator: &'a Evaluator,
    per_episode: u64,
    world: Arc<World>,
    episode: Episode,
    repose_rng: Rng,
    armed: bool,
    step: u64,
    rows: u64,
    seeds: u64,
    last: Option<Outcome>,
}

impl<'a> HumanCollector<'a> {
    /// A session starting at the start of episode `seed`, moving on to the next seed every
    /// `per_episode` rows (at least 1).
    pub fn new(evaluator: &'a Evaluator, seed: u64, per_episode: u64) -> Result<Self, RunError> {
        let world = evaluator.world(seed);
        let episode = world
            .episode(seed)
            .map_err(|source| RunError::Episode { seed, source })?;
        Ok(Self {
            evaluator,
            per_episode: per_episode.max(1),
            world,
            episode,
            repose_rng: stream(seed, Stream::Repose),
            armed: true,
            step: 0,
            rows: 0,
            seeds: 1,
            last: None,
        })
    }

    /// The episode as the person sees it: the state the next action will be taken in.
    pub fn episode(&self) -> &Episode {
        &self.episode
    }

    /// Whether the action keys work (false from an action until [`HumanCollector::rearm`]).
    pub fn armed(&self) -> bool {
        self.armed
    }

    /// Re-arms the action keys (the paper's down arrow).
    pub fn rearm(&mut self) {
        self.armed = true;
    }

    /// Rows recorded so far.
    pub fn rows(&self) -> u64 {
        self.rows
    }

    /// Rows recorded in the current episode.
    pub fn episode_rows(&self) -> u64 {
        self.step
    }

    /// Rows each episode gets before the next seed.
    pub fn per_episode(&self) -> u64 {
        self.per_episode
    }

    /// Episodes (seeds) visited, the current one included.
    pub fn seeds(&self) -> u64 {
        self.seeds
    }

    /// What the latest action did.
    pub fn last(&self) -> Option<Outcome> {
        self.last
    }

    /// Takes `action` when the keys are armed: returns the row to record (the state before the
    /// action, the action, whether it collided), having stepped and re-posed the robot, and
    /// disarms the keys. `Ok(None)` when disarmed: nothing happens. Moving on to the next seed
    /// can fail (a scene with no room for a start and goal).
    pub fn act(&mut self, action: DiscreteAction) -> Result<Option<Sample>, RunError> {
        if !self.armed {
            return Ok(None);
        }
        let mut sample = Sample::before(&self.episode, self.step, action);
        let result = self.episode.step(action);
        sample.collided = result.collided;
        let reached_goal = result.status == Status::Success;
        self.armed = false;
        self.step += 1;
        self.rows += 1;
        self.last = Some(Outcome {
            action,
            collided: sample.collided,
            reached_goal,
            from: sample.pose,
        });
        let seed = self.episode.seed();
        if self.step >= self.per_episode {
            self.next_seed(seed.wrapping_add(1))?;
        } else {
            if self.episode.status().is_done() {
                // Reached the goal (or ran out of steps): the episode's bookkeeping starts afresh.
                self.episode = self
                    .world
                    .episode(seed)
                    .map_err(|source| RunError::Episode { seed, source })?;
            }
            // With no free pose found the robot stays put, which is still a state to label.
            let _ = self
                .episode
                .repose(Some(self.world.grid()), &mut self.repose_rng);
        }
        Ok(Some(sample))
    }

    /// Moves on to the start of episode `seed`.
    fn next_seed(&mut self, seed: u64) -> Result<(), RunError> {
        let world = self.evaluator.world(seed);
        self.episode = world
            .episode(seed)
            .map_err(|source| RunError::Episode { seed, source })?;
        self.world = world;
        self.repose_rng = stream(seed, Stream::Repose);
        self.step = 0;
        self.seeds += 1;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::ValidConfig;
    use crate::geometry::wrap_deg;
    use crate::sim::Scenes;

    fn evaluator() -> Evaluator {
        Evaluator::new(ValidConfig::default(), Scenes::MazePerSeed)
    }

    #[test]
    fn an_action_records_its_state_then_reposes_towards_the_goal() {
        let evaluator = evaluator();
        let mut c = HumanCollector::new(&evaluator, 11, 100).unwrap();
        let start = c.episode().pose();
        let readings = c.episode().readings().to_vec();
        let row = c.act(DiscreteAction::Ahead).unwrap().unwrap();
        assert_eq!(
            (row.seed, row.step, row.action),
            (11, 0, DiscreteAction::Ahead)
        );
        assert_eq!(row.pose, start);
        assert_eq!(row.readings, readings);
        // Re-posed: somewhere else, facing the goal within 4 sigma of 0.03 * 360 degrees.
        let now = c.episode().pose();
        assert!((now.x - start.x).hypot(now.y - start.y) > 1.0);
        let off = wrap_deg(c.episode().direction_deg() + 180.0) - 180.0;
        assert!(off.abs() < 4.0 * 0.03 * 360.0, "{off}");
        assert_eq!(c.rows(), 1);
    }

    #[test]
    fn after_an_action_the_keys_do_nothing_until_rearmed() {
        let evaluator = evaluator();
        let mut c = HumanCollector::new(&evaluator, 2, 100).unwrap();
        assert!(c.act(DiscreteAction::Left).unwrap().is_some());
        assert!(!c.armed());
        let pose = c.episode().pose();
        for a in DiscreteAction::ALL {
            assert_eq!(c.act(a).unwrap(), None);
        }
        assert_eq!(c.episode().pose(), pose);
        assert_eq!(c.rows(), 1);
        c.rearm();
        let row = c.act(DiscreteAction::Right).unwrap().unwrap();
        assert_eq!((row.step, row.pose), (1, pose));
    }

    #[test]
    fn the_same_seed_and_keys_give_the_same_rows_and_seeds_move_on() {
        let evaluator = evaluator();
        let keys = [
            DiscreteAction::Ahead,
            DiscreteAction::Left,
            DiscreteAction::Ahead,
            DiscreteAction::Right,
            DiscreteAction::Ahead,
        ];
        let session = || {
            let mut c = HumanCollector::new(&evaluator, 40, 2).unwrap();
            let rows: Vec<Sample> = keys
                .iter()
                .map(|&a| {
                    c.rearm();
                    c.act(a).unwrap().unwrap()
                })
                .collect();
            (rows, c.seeds())
        };
        let (a, seeds) = session();
        assert_eq!(a, session().0);
        assert_eq!(seeds, 3);
        let seeds: Vec<(u64, u64)> = a.iter().map(|s| (s.seed, s.step)).collect();
        assert_eq!(seeds, [(40, 0), (40, 1), (41, 0), (41, 1), (42, 0)]);
    }
}
