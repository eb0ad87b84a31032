//! A lone robot's environments in a batch ([`Batch`]): one row each, its episode stepped by the
//! action a caller's closure chooses from its state (DQN's actors) or given in an array (the
//! vectorised Python environment). A lone robot is its team of one, and a
//! [`TeamBatch`](super::TeamBatch) over a configuration without `[[robots]]` steps the same bits
//! (tested in `team.rs`). This kind steps the episode directly, without the team's bookkeeping,
//! which the vectorised environment's speed does not leave room for.

use super::{BatchOf, Lane};
use crate::geometry::Point;
use crate::run::shaping::Shaper;
use crate::run::RunError;
use crate::sim::{stream, Action, Episode, Pose, Rng, Status, Stream, Worlds};

/// One environment's latest reset or step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct EnvStep {
    /// The seed of the episode the step belongs to (the one that ended, for a step that ended it).
    pub seed: u64,
    /// The action taken (`None` for a reset).
    pub action: Option<Action>,
    /// The step's reward (0 for a reset).
    pub reward: f64,
    /// The episode's status after the step.
    pub status: Status,
    /// Whether the step's motion would have touched an obstacle.
    pub collided: bool,
    /// Distance to the goal after the step, px.
    pub distance_px: f64,
    /// Pose after the step.
    pub pose: Pose,
    /// The episode's (current) goal.
    pub goal: Point,
    /// Steps taken in the episode so far.
    pub steps: u32,
    /// Steps of the episode so far that collided with a wall or a static obstacle.
    pub collisions: u32,
    /// Steps of the episode so far with contact between the robot and a moving obstacle (`None`
    /// when the scene has none).
    pub dynamic_collisions: Option<u32>,
    /// Summed reward of the episode so far, as given (with `reward.shaping`, the shaped one).
    pub total_reward: f64,
    /// Whether this was a reset: the environment started a new episode and did not step.
    pub reset: bool,
}

impl EnvStep {
    fn of(episode: &Episode, action: Option<Action>, reward: f64, collided: bool) -> Self {
        Self {
            seed: episode.seed(),
            action,
            reward,
            status: episode.status(),
            collided,
            distance_px: episode.distance_px(),
            pose: episode.pose(),
            goal: episode.goal(),
            steps: episode.steps(),
            collisions: episode.collisions(),
            dynamic_collisions: episode.dynamic_metrics().map(|m| m.collisions),
            total_reward: episode.total_reward(),
            reset: false,
        }
    }

    /// The record of `episode` just started: what a reset reports.
    pub fn start(episode: &Episode) -> Self {
        Self {
            reset: true,
            ..Self::of(episode, None, 0.0, false)
        }
    }
}

/// N lone robots' environments stepped together.
pub type Batch = BatchOf<Lone>;

/// A lone robot's environment: its episode, the random stream a policy may draw from, and the
/// shaping of its reward when the configuration asks for it.
pub struct Lone {
    episode: Option<Episode>,
    rng: Rng,
    shaper: Option<Shaper>,
}

impl Lane for Lone {
    type Record = EnvStep;

    fn idle(_: &Worlds) -> Self {
        Self {
            episode: None,
            rng: stream(0, Stream::Policy),
            shaper: None,
        }
    }

    fn shape(worlds: &Worlds) -> (usize, usize) {
        (1, worlds.config().observation_size())
    }

    fn start(
        &mut self,
        worlds: &Worlds,
        seed: u64,
        obs: &mut [f32],
        out: &mut [EnvStep],
    ) -> Result<(), RunError> {
        let world = worlds.world(seed);
        let episode = world
            .episode(seed)
            .map_err(|source| RunError::Episode { seed, source })?;
        obs.copy_from_slice(episode.observation());
        out[0] = EnvStep::start(&episode);
        self.shaper = Shaper::start(world, &episode);
        self.rng = stream(seed, Stream::Policy);
        self.episode = Some(episode);
        Ok(())
    }

    #[inline]
    fn started(&self) -> bool {
        self.episode.is_some()
    }

    #[inline]
    fn done(&self) -> bool {
        self.episode.as_ref().is_some_and(|e| e.status().is_done())
    }

    #[inline]
    fn prefetch(&self, stage: usize) {
        if let Some(episode) = &self.episode {
            episode.prefetch(stage);
        }
    }
}

impl Lone {
    /// One step of environment `i`: the action `choose` gives for its episode's state, its
    /// observation into `obs` and its record into `out`. Inlined into the batch's loop, as it
    /// was before the batch took teams too: called on its own it cost 1.5% more instructions a
    /// step (callgrind, 1024 environments).
    #[inline(always)]
    fn step(
        &mut self,
        i: usize,
        choose: &(dyn Fn(usize, &Episode, &mut Rng) -> Action + Sync),
        obs: &mut [f32],
        out: &mut EnvStep,
    ) {
        let Some(episode) = self.episode.as_mut() else {
            return;
        };
        let action = choose(i, episode, &mut self.rng);
        let r = episode.step(action);
        let (reward, collided) = (r.reward, r.collided);
        obs.copy_from_slice(r.observation);
        *out = match self.shaper.as_mut() {
            Some(shaper) => {
                let shaped = shaper.step(episode, reward);
                EnvStep {
                    total_reward: shaper.total(),
                    ..EnvStep::of(episode, Some(action), shaped, collided)
                }
            }
            None => EnvStep::of(episode, Some(action), reward, collided),
        };
    }
}

impl BatchOf<Lone> {
    /// Steps every environment: `choose(i, episode, rng)` gives environment `i`'s action for its
    /// episode's current state, drawing any randomness from `rng` (the episode seed's policy
    /// stream). Environments waiting for a next-step reset start their next episode instead.
    pub fn step(
        &mut self,
        choose: &(dyn Fn(usize, &Episode, &mut Rng) -> Action + Sync),
    ) -> Result<(), RunError> {
        self.call(|batch| {
            batch.step_each(|i, lone, obs, out| lone.step(i, choose, obs, &mut out[0]))
        })
    }

    /// Steps every environment with its action from `actions` (one per environment).
    pub fn step_actions(&mut self, actions: &[Action]) -> Result<(), RunError> {
        if actions.len() != self.len() {
            return Err(RunError::ActionCount {
                given: actions.len(),
                envs: self.len(),
            });
        }
        self.step(&|i, _, _| actions[i])
    }

    /// Environment `i`'s current episode, once started.
    pub fn episode(&self, i: usize) -> Option<&Episode> {
        self.lane(i).and_then(|l| l.episode.as_ref())
    }
}
