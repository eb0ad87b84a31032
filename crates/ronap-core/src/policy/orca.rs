//! The `orca` policy (docs/model.md "Local planners among moving things"): Optimal Reciprocal
//! Collision Avoidance for the robot. Each step it wants to go at full speed towards the point a
//! lookahead ahead on its geodesic path; ORCA ([`crate::geometry::orca`]) gives the velocity
//! nearest that which keeps clear, for `orca.time_horizon_steps`, of the moving obstacles and
//! other robots it senses (their positions and last step's displacements, ground truth within
//! `orca.sense_range_px`) and, for `orca.obstacle_time_horizon_steps`, of the still scene. The
//! velocity becomes the unicycle command that tracks it, or the discrete action whose result lies
//! closest. Robots of a team that all run `orca` each take half the avoidance.

use super::follow::Follower;
use super::geodesic::planned;
use super::{Decision, Policy, PolicyError};
use crate::config::PlannerActions;
use crate::geometry::orca::{Agent, Horizon, V2};
use crate::geometry::{wrap_deg, Point, Vector};
use crate::sim::avoid::{Avoid, Avoider};
use crate::sim::episode::Episode;
use crate::sim::moving::Movers;
use crate::sim::robot::{Action, DiscreteAction};
use crate::sim::team::Team;
use crate::sim::world::World;
use std::f64::consts::TAU;

/// How sharply a unicycle's speed falls with the angle between its chord and the velocity it
/// tracks: `cos^ALIGN_POWER`.
const ALIGN_POWER: i32 = 8;

/// ORCA towards the geodesic path's lookahead point.
#[derive(Debug, Default)]
pub struct Orca {
    path: Option<Follower>,
    /// Where each sensed agent was at the last decision (moving obstacles by index, then the
    /// team's robots by index): its velocity is its displacement since.
    last: Vec<Option<Point>>,
    /// Where this robot was at the last decision.
    last_me: Option<Point>,
    /// Its index in its team (0 alone).
    index: usize,
    // Scratch space kept between steps.
    agents: Vec<Agent<f64>>,
    avoider: Avoider,
}

impl Orca {
    /// The agents round `me` (the moving obstacles `movers`, then `robots`: a team's present
    /// robots by index, `me` among them as `index`; none for a lone robot) within the sensing
    /// range, with their velocities, into `self.agents` (`me` first); remembers where each is for
    /// the next step. `team_size`: robots in the team (0 alone).
    fn sense(
        &mut self,
        me: &Episode,
        movers: Option<&Movers>,
        robots: &[(usize, &Episode)],
        index: Option<usize>,
        team_size: usize,
    ) {
        let config = me.config();
        let range = config.orca.sense_range_px.unwrap_or(config.laser.range_px);
        let p = me.pose().position();
        let velocity = self.last_me.map_or(Vector::zeros(), |l| p - l);
        self.last_me = Some(p);
        self.agents.clear();
        self.agents.push(Agent {
            position: V2::from(p),
            velocity: V2::from(velocity),
            radius: config.robot.radius_px,
        });
        let mover_count = movers.map_or(0, |m| m.items().len());
        self.last.resize(mover_count + team_size, None);
        let mut seen = |slot: usize, at: Option<Point>, radius: f64, agents: &mut Vec<_>| {
            let last = std::mem::replace(&mut self.last[slot], at);
            if let Some(at) = at.filter(|a| (a - p).norm() <= range + radius) {
                agents.push(Agent {
                    position: V2::from(at),
                    velocity: V2::from(last.map_or(Vector::zeros(), |l| at - l)),
                    radius,
                });
            }
        };
        if let Some(m) = movers {
            for (i, o) in m.items().enumerate() {
                let at = o.present().then(|| o.position());
                seen(i, at, o.body().bounding_radius(), &mut self.agents);
            }
        }
        for &(k, r) in robots {
            if Some(k) != index {
                let radius = r.config().robot.radius_px;
                seen(
                    mover_count + k,
                    Some(r.pose().position()),
                    radius,
                    &mut self.agents,
                );
            }
        }
    }

    /// The decision for `me` (whose agents [`Orca::sense`] has gathered) in its still scene.
    fn decide(&mut self, me: &Episode) -> Decision {
        let Some(path) = &mut self.path else {
            return Decision::GiveUp("no path to the goal".into());
        };
        let config = me.config();
        let pose = me.pose();
        let p = pose.position();
        let actions = config.orca.actions;
        let speed = config.orca.speed_px.unwrap_or(match actions {
            PlannerActions::Continuous => config.robot.max_linear_speed_px,
            PlannerActions::Discrete => config.robot.move_speed_px,
        });
        // Full speed towards the lookahead point, slowing to land on the goal.
        let aim = path.aim(p).unwrap_or(me.goal());
        let to_aim = aim - p;
        let to_goal = (me.goal() - p).norm();
        let preferred = match to_aim.try_normalize(1e-12) {
            Some(u) => u * speed.min(to_goal),
            None => Vector::zeros(),
        };
        // A thousandth of a px off, in a direction turning with the step and the robot, as
        // RVO2's examples do: perfect symmetry (robots swapping across a circle) can otherwise
        // hold ORCA agents still for ever.
        let turn = f64::from(me.steps()) * 2.399_963 + self.index as f64 * 0.618_034 * TAU;
        let preferred = preferred + crate::geometry::unit(turn.to_degrees()) * 1e-3;
        let horizon = Horizon {
            agents: config.orca.time_horizon_steps,
            obstacles: config.orca.obstacle_time_horizon_steps,
            max_speed: speed,
            time_step: 1.0,
        };
        let v = self.avoider.velocity(
            me.scene(),
            &Avoid {
                agents: &self.agents,
                me: 0,
                preferred,
                horizon,
                neighbour_dist: config.orca.sense_range_px.unwrap_or(config.laser.range_px),
                max_neighbours: config.orca.max_neighbours as usize,
                margin: config.orca.safety_margin_px,
            },
        );
        Decision::Act(match actions {
            PlannerActions::Continuous => continuous(me, v, to_aim),
            PlannerActions::Discrete => discrete(me, v, to_aim).into(),
        })
    }
}

/// The signed turn from the robot's heading to `direction`, degrees in [-180, 180).
fn turn_to(me: &Episode, direction: Vector) -> f64 {
    let bearing = direction.y.atan2(direction.x).to_degrees();
    wrap_deg(bearing - me.pose().z_deg + 180.0) - 180.0
}

/// The unicycle command whose step moves the robot by `v`: an arc of constant speed and turn
/// rate ends along its chord, at half the turn from the heading (from the reversed heading when
/// driving backwards), so a turn of twice the velocity's bearing `e` from the heading (or from
/// the reversed heading, for a velocity behind the robot) and a speed of `|v| e / sin e` land
/// exactly on `v` when the turn is within `max_angular_speed_deg`. Beyond it the robot turns as
/// far as it may, at the speed that keeps its chord's advance along `v`. Standing (`v` zero), it
/// turns towards `aim`.
fn continuous(me: &Episode, v: Vector, aim: Vector) -> Action {
    let speed = v.norm();
    if speed <= 1e-9 {
        if aim.norm_squared() == 0.0 {
            return Action::Continuous { v: 0.0, w_deg: 0.0 };
        }
        let w_max = me.config().robot.max_angular_speed_deg;
        return Action::Continuous {
            v: 0.0,
            w_deg: turn_to(me, aim).clamp(-w_max, w_max),
        };
    }
    let error = turn_to(me, v);
    // A velocity behind the robot is driven backwards.
    let (error, sign) = if error.abs() > 90.0 {
        (wrap_deg(error) - 180.0, -1.0)
    } else {
        (error, 1.0)
    };
    let w_max = me.config().robot.max_angular_speed_deg;
    let w_deg = (2.0 * error).clamp(-w_max, w_max);
    let half = (w_deg / 2.0).to_radians();
    // The chord of an arc of length `v` turning by `w` is `v sin(w/2) / (w/2)` long.
    let chord_per_speed = if half.abs() < 1e-9 {
        1.0
    } else {
        half.sin() / half
    };
    // Off the velocity's line by `error - w/2`: slower the further off, so a robot that cannot
    // turn in time does not sweep across what ORCA kept it clear of.
    let along = (error.to_radians() - half).cos().max(0.0).powi(ALIGN_POWER);
    Action::Continuous {
        v: sign * speed * along / chord_per_speed,
        w_deg,
    }
}

/// The discrete action that follows velocity `v`: AHEAD when the heading lies within half a
/// turn of it and it is at least half a step long (the AHEAD step then lies closer to where `v`
/// leads than standing), else a turn towards it (towards `aim` when it is shorter).
fn discrete(me: &Episode, v: Vector, aim: Vector) -> DiscreteAction {
    let robot = &me.config().robot;
    let toward = if v.norm() >= robot.move_speed_px / 2.0 {
        v
    } else {
        aim
    };
    let error = turn_to(me, toward);
    if error.abs() <= robot.turn_speed_deg / 2.0 && toward == v {
        DiscreteAction::Ahead
    } else if error >= 0.0 {
        DiscreteAction::Left
    } else {
        DiscreteAction::Right
    }
}

impl Policy for Orca {
    fn reset(&mut self, world: &World, episode: &Episode) -> Result<(), PolicyError> {
        self.path = planned(world, episode.pose().position(), episode.goal());
        // On to the next goal of a list (mid-episode), the others' last positions still hold.
        if episode.steps() == 0 {
            self.last.clear();
            self.last_me = None;
        }
        Ok(())
    }

    fn act(&mut self, episode: &Episode) -> Result<Decision, PolicyError> {
        self.sense(episode, episode.movers(), &[], None, 0);
        Ok(self.decide(episode))
    }

    fn act_in_team(&mut self, team: &Team, k: usize) -> Result<Decision, PolicyError> {
        let me = team.robot(k);
        let robots: Vec<(usize, &Episode)> = team
            .robots()
            .iter()
            .enumerate()
            .filter(|&(j, _)| team.present(j))
            .collect();
        self.index = k;
        self.sense(me, team.movers(), &robots, Some(k), team.robots().len());
        Ok(self.decide(me))
    }
}

#[cfg(test)]
mod tests {
    use crate::config::{PlannerActions, TeamRobotConfig};
    use crate::eval::{EvalOptions, Evaluator, Outcome, Summary};
    use crate::policy::{factory, PerRobotFactory};
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
        };
        c.maze.cols = 1;
        c.maze.rows = 1;
        c.maze.cell_px = 400.0;
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
