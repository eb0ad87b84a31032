//! The `orca` policy (docs/model.md "Local planners among moving things"): Optimal Reciprocal
//! Collision Avoidance for the robot. Each step it wants to go at full speed towards the point a
//! lookahead ahead on its geodesic path; ORCA ([`crate::geometry::orca`]) gives the velocity
//! nearest that which keeps clear, for `orca.time_horizon_steps`, of the moving obstacles and
//! other robots it senses (their positions and last step's displacements, ground truth within
//! `orca.sense_range_px`) and, for `orca.obstacle_time_horizon_steps`, of the still scene. The
//! velocity becomes the unicycle command that tracks it, or the discrete action whose result lies
//! closest. Robots of a team that all run `orca` each take half the avoidance.

use super::follow::Follower;
use super::local::{self, Local, Planner, Senses};
use super::Decision;
use crate::geometry::Horizon;
use crate::sim::{Avoid, Avoider, Episode};

/// The `orca` policy: ORCA towards the geodesic path's lookahead point.
pub type Orca = Local<OrcaPlanner>;

/// ORCA's choice of velocity, with its scratch space.
#[derive(Debug, Default)]
pub struct OrcaPlanner {
    avoider: Avoider,
}

impl Planner for OrcaPlanner {
    fn range(me: &Episode) -> f64 {
        let config = me.config();
        config.orca.sense_range_px.unwrap_or(config.laser.range_px)
    }

    fn decide(&mut self, me: &Episode, path: &mut Follower, senses: &Senses) -> Decision {
        let config = me.config();
        let actions = config.orca.actions;
        let speed = local::planner_speed(me, config.orca.speed_px, actions);
        let (preferred, to_aim) = local::preferred(path, me, speed, senses.index);
        let horizon = Horizon {
            agents: config.orca.time_horizon_steps,
            obstacles: config.orca.obstacle_time_horizon_steps,
            max_speed: speed,
            time_step: 1.0,
        };
        let v = self.avoider.velocity(
            me.scene(),
            &Avoid {
                agents: &senses.agents,
                me: 0,
                preferred,
                horizon,
                neighbour_dist: Self::range(me),
                max_neighbours: config.orca.max_neighbours as usize,
                margin: config.orca.safety_margin_px,
                candidates: None,
            },
        );
        Decision::Act(local::action(me, v, to_aim, actions))
    }
}

#[cfg(test)]
mod tests {
    use crate::config::{PlannerActions, TeamRobotConfig};
    use crate::eval::{EvalOptions, Evaluator, Outcome, Summary};
    use crate::policy::local::lone_run;
    use crate::policy::{factory, PerRobotFactory};
    use crate::sim::Scenes;
    use std::sync::atomic::AtomicBool;

    #[test]
    fn among_pedestrians_orca_arrives_with_fewer_contacts_than_geodesic() {
        let orca = lone_run(crate::config::maze_pedestrians(), "orca", 30);
        let geodesic = lone_run(crate::config::maze_pedestrians(), "geodesic", 30);
        let contacts = |s: &Summary| {
            s.moving
                .as_ref()
                .expect("movers")
                .dynamic_collisions_per_episode
        };
        assert!(orca.success_rate >= 0.95, "{orca:?}");
        assert_eq!(orca.collisions_per_episode, 0.0, "{orca:?}");
        assert!(
            contacts(&orca) < contacts(&geodesic) / 4.0,
            "{orca:?} {geodesic:?}"
        );
    }

    #[test]
    fn with_discrete_actions_orca_reaches_maze_goals_without_touching_a_wall() {
        let mut c = crate::SimConfig::default();
        c.orca.actions = PlannerActions::Discrete;
        let s = lone_run(c, "orca", 20);
        assert!(s.success_rate >= 0.95, "{s:?}");
        assert_eq!(s.collisions_per_episode, 0.0, "{s:?}");
    }

    #[test]
    fn two_orca_robots_pass_each_other_head_on_without_touching() {
        let robot = |start: [f64; 3], goal: [f64; 2]| TeamRobotConfig {
            start: Some(start),
            goal: Some(goal),
            jitter_px: 2.0,
            ..Default::default()
        };
        let mut c = crate::SimConfig {
            robots: vec![
                robot([50.0, 200.0, 0.0], [350.0, 200.0]),
                robot([350.0, 200.0, 180.0], [50.0, 200.0]),
            ],
            ..Default::default()
        }
        .open_hall(400.0);
        c.episode.min_goal_distance_px = 0.0;
        c.orca.sense_range_px = Some(150.0);
        let ev = Evaluator::new(c.validate().expect("valid"), Scenes::MazePerSeed);
        let f = factory("orca", ev.config().observation_size()).expect("orca");
        let team = PerRobotFactory::new(vec![f.as_ref(); 2], vec!["orca".to_string(); 2]);
        let options = EvalOptions {
            seeds: (0..10).collect::<Vec<_>>().into(),
            ..Default::default()
        };
        let run = ev
            .run_team(&team, &options, &AtomicBool::new(false), &|_| {})
            .expect("runs");
        for r in &run.records {
            assert_eq!(r.outcome, Outcome::Success, "seed {}", r.seed);
            assert_eq!(r.robot_collisions, 0, "seed {}", r.seed);
        }
    }
}
