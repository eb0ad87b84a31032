//! The artificial potential field policy: the paper's Algorithm 3.
//!
//! From the start, the descent repeatedly moves to the lowest-potential of the 8 neighbouring
//! lattice positions (`apf.lattice_px` apart, the paper's pixels) until within epsilon of the goal,
//! with `U = 1/2 xi d^2(q, goal) + 1/2 eta (1/c - 1/d0)^2` for clearance `c <= d0` (the scene
//! binarised into obstacles; `c` is the disc's clearance, so the robot's radius is accounted for).
//! The robot then follows that path with discrete actions.
//!
//! Plain APF has local minima: in a maze the descent gets trapped against walls. Because it always
//! moves to the lowest neighbour, a trapped descent returns to a position it visited; that is
//! detected at once, the path is kept up to there, and the robot follows it into the trap and then
//! gives up, so the run ends as a failure promptly instead of timing out.

use super::follow::Follower;
use super::{Decision, Policy, PolicyError};
use crate::config::ApfConfig;
use crate::geometry::{Point, Vector};
use crate::scene::Scene;
use crate::sim::{DiscreteAction, Episode, World};
use std::collections::HashSet;

/// The result of the descent.
#[derive(Clone, Debug, PartialEq)]
pub struct ApfPlan {
    /// Positions visited, start first.
    pub path: Vec<Point>,
    /// Whether the descent reached the goal (else it was trapped).
    pub reached: bool,
}

/// The potential at `q`: attraction to `goal` plus repulsion from obstacles within `influence_px`
/// of the disc's edge; infinite where the disc would touch an obstacle.
pub fn potential(scene: &Scene, config: &ApfConfig, radius: f64, goal: Point, q: Point) -> f64 {
    let d_goal2 = (q - goal).norm_squared();
    let mut u = 0.5 * config.gravity_gain * d_goal2;
    match scene.clearance(q, radius + config.influence_px) {
        Some(d) if d <= radius => return f64::INFINITY,
        Some(d) => {
            let c = d - radius;
            u += 0.5 * config.repulsion_gain * (1.0 / c - 1.0 / config.influence_px).powi(2);
        }
        None => {}
    }
    // Inside an obstacle the clearance above is 0; what is left is leaving the scene.
    if !scene.bounds().contains(q) {
        return f64::INFINITY;
    }
    u
}

/// What [`plan`] descends: from where to where, for which disc, and for how long.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Descent {
    /// Where the descent begins.
    pub start: Point,
    /// Where it heads.
    pub goal: Point,
    /// The disc's radius, px.
    pub radius: f64,
    /// How near `goal` counts as reaching it, px.
    pub tolerance: f64,
    /// The most positions the descent runs.
    pub max_positions: usize,
}

/// Algorithm 3: descend the potential from `start` over the 8-neighbour lattice until within
/// `tolerance` of `goal`, or until the descent revisits a position (a local minimum or an
/// oscillation) or runs `max_positions` positions.
pub fn plan(scene: &Scene, config: &ApfConfig, descent: &Descent) -> ApfPlan {
    let Descent {
        start,
        goal,
        radius,
        tolerance,
        max_positions,
    } = *descent;
    let h = config.lattice_px;
    let offsets: [(i64, i64); 8] = [
        (1, 0),
        (1, 1),
        (0, 1),
        (-1, 1),
        (-1, 0),
        (-1, -1),
        (0, -1),
        (1, -1),
    ];
    let at = |i: i64, j: i64| start + Vector::new(i as f64 * h, j as f64 * h);
    let (mut i, mut j) = (0i64, 0i64);
    let mut visited = HashSet::new();
    let mut path = Vec::new();
    loop {
        let q = at(i, j);
        path.push(q);
        if (q - goal).norm() <= tolerance {
            return ApfPlan {
                path,
                reached: true,
            };
        }
        if !visited.insert((i, j)) || path.len() >= max_positions {
            path.pop();
            return ApfPlan {
                path,
                reached: false,
            };
        }
        // Two positions with clear discs less than a diameter apart cannot have a wall between
        // them; a coarser lattice must check each move, or it would hop thin walls.
        let hops = h * std::f64::consts::SQRT_2 >= 2.0 * radius;
        let best = offsets
            .iter()
            .map(|&(di, dj)| {
                let next = at(i + di, j + dj);
                (
                    (i + di, j + dj),
                    next,
                    potential(scene, config, radius, goal, next),
                )
            })
            .filter(|&(_, next, u)| u.is_finite() && (!hops || scene.sweep_clear(q, next, radius)))
            .map(|(ij, _, u)| (ij, u))
            .min_by(|a, b| a.1.total_cmp(&b.1));
        match best {
            Some(((ni, nj), _)) => (i, j) = (ni, nj),
            None => {
                return ApfPlan {
                    path,
                    reached: false,
                }
            }
        }
    }
}

/// The APF policy: plan with [`plan`], follow the path, give up at the end of a trapped path.
#[derive(Debug, Default)]
pub struct Apf {
    follower: Option<Follower>,
    reached: bool,
}

impl Policy for Apf {
    fn reset(&mut self, world: &World, episode: &Episode) -> Result<(), PolicyError> {
        let config = world.config();
        let scene = world.scene();
        let lattice = config.apf.lattice_px;
        // A bound far above any path that does not loop: four times the scene's perimeter.
        let max_positions = (8.0 * (scene.width() + scene.height()) / lattice).ceil() as usize + 16;
        let descent = Descent {
            start: episode.pose().position(),
            goal: episode.goal(),
            radius: config.robot.radius_px,
            tolerance: config.episode.goal_tolerance_px,
            max_positions,
        };
        let plan = plan(scene, &config.apf, &descent);
        self.reached = plan.reached;
        let mut path = plan.path;
        if plan.reached {
            path.push(episode.goal());
        }
        self.follower = Some(Follower::new(path, config.robot.move_speed_px * 2.0));
        Ok(())
    }

    fn act(&mut self, episode: &Episode) -> Result<Decision, PolicyError> {
        let Some(follower) = &mut self.follower else {
            return Err(PolicyError::Failed("apf: act() before reset()".into()));
        };
        let end_reason = if self.reached {
            "reached the end of the path short of the goal"
        } else {
            "trapped in a local minimum of the potential"
        };
        let decision = follower.next(episode).decision(end_reason);
        if !episode.config().apf.repel_moving {
            return Ok(decision);
        }
        Ok(match decision {
            Decision::Act(a) if a == DiscreteAction::Ahead.into() => {
                Decision::Act(repel(episode).unwrap_or(DiscreteAction::Ahead).into())
            }
            other => other,
        })
    }
}

/// With `apf.repel_moving`: the turn away from the strongest repulsion of the obstacles the laser
/// sees and the still scene does not have, within `influence_px` of the robot's disc and in front
/// of it, weighted as the potential's gradient `(1/c - 1/d0) / c^2`; `None` when none repels.
fn repel(episode: &Episode) -> Option<DiscreteAction> {
    let c = episode.config();
    let d0 = c.apf.influence_px;
    let radius = c.robot.radius_px;
    let mut push = 0.0;
    let mut any = false;
    for (angle, d) in super::dodge::unexpected(episode) {
        let clearance = (d - radius).max(0.5);
        if clearance > d0 || angle.abs() > 90.0 {
            continue;
        }
        any = true;
        // Obstacles to the left (positive angles) push right, and the other way round.
        push -=
            angle.to_radians().sin().signum() * (1.0 / clearance - 1.0 / d0) / clearance.powi(2);
    }
    any.then_some(if push >= 0.0 {
        DiscreteAction::Left
    } else {
        DiscreteAction::Right
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Aabb;

    fn room(extra: Vec<Aabb>) -> Scene {
        let mut boxes = Scene::from_occupancy(300, 200, &vec![false; 300 * 200], 1.0, 50.0)
            .boxes()
            .to_vec();
        boxes.extend(extra);
        Scene::from_boxes(300.0, 200.0, boxes, 50.0)
    }

    #[test]
    fn open_room_descent_reaches_the_goal() {
        let scene = room(vec![]);
        let descent = Descent {
            start: Point::new(30.0, 40.0),
            goal: Point::new(260.0, 170.0),
            radius: 5.0,
            tolerance: 10.0,
            max_positions: 10_000,
        };
        let p = plan(&scene, &ApfConfig::default(), &descent);
        assert!(p.reached);
        assert!((p.path.last().unwrap() - Point::new(260.0, 170.0)).norm() <= 10.0);
    }

    #[test]
    fn a_coarse_lattice_does_not_hop_a_thin_wall() {
        // A 2 px wall across the room between start and goal, and a 20 px lattice.
        let wall = vec![Aabb::from_corners(
            Point::new(149.0, 0.0),
            Point::new(151.0, 200.0),
        )];
        let scene = room(wall);
        let config = ApfConfig {
            lattice_px: 20.0,
            ..ApfConfig::default()
        };
        let descent = Descent {
            start: Point::new(100.0, 100.0),
            goal: Point::new(200.0, 100.0),
            radius: 5.0,
            tolerance: 10.0,
            max_positions: 10_000,
        };
        let p = plan(&scene, &config, &descent);
        assert!(!p.reached);
        assert!(p.path.iter().all(|q| q.x < 149.0), "{:?}", p.path);
    }

    #[test]
    fn a_cup_facing_the_goal_traps_the_descent_promptly() {
        // A U-shaped cup open to the left, the start inside it, the goal to its right.
        let cup = vec![
            Aabb::from_corners(Point::new(140.0, 60.0), Point::new(142.0, 140.0)),
            Aabb::from_corners(Point::new(80.0, 60.0), Point::new(142.0, 62.0)),
            Aabb::from_corners(Point::new(80.0, 138.0), Point::new(142.0, 140.0)),
        ];
        let scene = room(cup);
        let descent = Descent {
            start: Point::new(110.0, 100.0),
            goal: Point::new(260.0, 100.0),
            radius: 5.0,
            tolerance: 10.0,
            max_positions: 10_000,
        };
        let p = plan(&scene, &ApfConfig::default(), &descent);
        assert!(!p.reached);
        // Trapped against the cup's back wall, well before the position bound.
        let end = *p.path.last().unwrap();
        assert!(end.x > 110.0 && end.x < 140.0, "{end:?}");
        assert!(p.path.len() < 100, "{}", p.path.len());
    }
}
