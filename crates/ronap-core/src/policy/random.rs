//! The random policy: LEFT, AHEAD or RIGHT with equal probability, from the episode's policy stream.

use super::{Decision, Policy, PolicyError};
use crate::sim::{stream, DiscreteAction, Episode, Rng, Stream, World};
use rand::Rng as _;

/// Uniformly random discrete actions.
#[derive(Debug, Default)]
pub struct RandomPolicy {
    rng: Option<Rng>,
}

impl Policy for RandomPolicy {
    fn reset(&mut self, _world: &World, episode: &Episode) -> Result<(), PolicyError> {
        self.rng = Some(stream(episode.seed(), Stream::Policy));
        Ok(())
    }

    fn act(&mut self, episode: &Episode) -> Result<Decision, PolicyError> {
        let rng = self
            .rng
            .get_or_insert_with(|| stream(episode.seed(), Stream::Policy));
        let action = DiscreteAction::ALL[rng.random_range(0..3)];
        Ok(Decision::Act(action.into()))
    }
}
