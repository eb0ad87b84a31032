//! The `social-force` policy (docs/model.md "Local planners among moving things"): the social
//! force model ([`crate::geometry::social_force`]) applied to the robot. Each step the robot's
//! velocity relaxes towards full speed along its geodesic path, pushed away from the moving
//! obstacles and other robots it senses (ground truth within `social_force.sense_range_px`; those
//! beyond `forces.neighbour_dist_px` do not push) and from the still scene; the velocity becomes the unicycle command that tracks it, or the
//! discrete action whose result lies closest.

use super::follow::Follower;
use super::geodesic::planned;
use super::local::{self, Senses};
use super::{Decision, Policy, PolicyError};
use crate::geometry::Point;
use crate::sim::avoid::social_force_velocity;
use crate::sim::episode::Episode;
use crate::sim::team::Team;
use crate::sim::world::World;

/// The social force model towards the geodesic path's lookahead point.
#[derive(Debug, Default)]
pub struct SocialForce {
    path: Option<Follower>,
    senses: Senses,
}

impl SocialForce {
    /// How far the robot senses.
    fn range(me: &Episode) -> f64 {
        let config = me.config();
        config
            .social_force
            .sense_range_px
            .unwrap_or(config.laser.range_px)
    }

    /// The decision for `me` (whose agents are sensed) in its still scene.
    fn decide(&mut self, me: &Episode) -> Decision {
        let Some(path) = &mut self.path else {
            return Decision::GiveUp("no path to the goal".into());
        };
        let config = &me.config().social_force;
        let forces = &config.forces;
        let speed = local::planner_speed(me, config.speed_px, config.actions);
        let (preferred, to_aim) = local::preferred(path, me, speed, self.senses.index);
        let (mine, others) = self.senses.agents.split_at(1);
        let others = others
            .iter()
            .map(|o| (Point::new(o.position.x, o.position.y), o.radius));
        let v = social_force_velocity(forces, &mine[0], preferred, speed, others, me.scene());
        Decision::Act(local::action(me, v, to_aim, config.actions))
    }
}

impl Policy for SocialForce {
    fn reset(&mut self, world: &World, episode: &Episode) -> Result<(), PolicyError> {
        self.path = planned(world, episode.pose().position(), episode.goal());
        self.senses.reset(episode);
        Ok(())
    }

    fn act(&mut self, episode: &Episode) -> Result<Decision, PolicyError> {
        self.senses.lone(episode, Self::range(episode));
        Ok(self.decide(episode))
    }

    fn act_in_team(&mut self, team: &Team, k: usize) -> Result<Decision, PolicyError> {
        let me = team.robot(k);
        self.senses.in_team(team, k, Self::range(me));
        Ok(self.decide(me))
    }
}

#[cfg(test)]
mod tests {
    use crate::eval::{EvalOptions, Evaluator, Summary};
    use crate::policy::factory;
    use crate::sim::world::Scenes;
    use std::sync::atomic::AtomicBool;

    fn lone_run(config: crate::SimConfig, policy: &str, seeds: u64) -> Summary {
        let ev = Evaluator::new(config.validate().expect("valid"), Scenes::MazePerSeed);
        let f = factory(policy, ev.config().observation_size()).expect("policy");
        let options = EvalOptions {
            seeds: (0..seeds).collect::<Vec<_>>().into(),
            ..Default::default()
        };
        let run = ev
            .run(f.as_ref(), &options, &AtomicBool::new(false), &|_| {})
            .expect("runs");
        Summary::new(&run.records, crate::eval::metric::kinds(ev.config()), 1.0)
    }

    #[test]
    fn social_force_reaches_maze_goals_among_pedestrians() {
        let s = lone_run(crate::config::maze_pedestrians(), "social-force", 20);
        assert!(s.success_rate >= 0.9, "{s:?}");
    }
}
