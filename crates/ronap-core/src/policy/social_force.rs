//! The `social-force` policy (docs/model.md "Local planners among moving things"): the social
//! force model ([`crate::geometry::social_force`]) applied to the robot. Each step the robot's
//! velocity relaxes towards full speed along its geodesic path, pushed away from the moving
//! obstacles and other robots it senses (ground truth within `social_force.sense_range_px`; those
//! beyond `forces.neighbour_dist_px` do not push) and from the still scene; the velocity becomes the unicycle command that tracks it, or the
//! discrete action whose result lies closest.

use super::follow::Follower;
use super::local::{self, Local, Planner, Senses};
use super::Decision;
use crate::geometry::Point;
use crate::sim::{social_force_velocity, Episode};

/// The `social-force` policy: the social force model towards the geodesic path's lookahead point.
pub type SocialForce = Local<SocialForcePlanner>;

/// The social force model's velocity for the robot.
#[derive(Debug, Default)]
pub struct SocialForcePlanner;

impl Planner for SocialForcePlanner {
    fn range(me: &Episode) -> f64 {
        let config = me.config();
        config
            .social_force
            .sense_range_px
            .unwrap_or(config.laser.range_px)
    }

    fn decide(&mut self, me: &Episode, path: &mut Follower, senses: &Senses) -> Decision {
        let config = &me.config().social_force;
        let forces = &config.forces;
        let speed = local::planner_speed(me, config.speed_px, config.actions);
        let (preferred, to_aim) = local::preferred(path, me, speed, senses.index);
        let (mine, others) = senses.agents.split_at(1);
        let others = others
            .iter()
            .map(|o| (Point::new(o.position.x, o.position.y), o.radius));
        let v = social_force_velocity(forces, &mine[0], preferred, speed, others, me.scene());
        Decision::Act(local::action(me, v, to_aim, config.actions))
    }
}

#[cfg(test)]
mod tests {
    use crate::policy::local::lone_run;

    #[test]
    fn social_force_reaches_maze_goals_among_pedestrians() {
        let s = lone_run(crate::config::maze_pedestrians(), "social-force", 20);
        assert!(s.success_rate >= 0.9, "{s:?}");
    }
}
