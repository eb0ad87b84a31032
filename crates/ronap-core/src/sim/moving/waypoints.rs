//! `waypoints`: an obstacle patrolling a list of points at its speed, in straight lines through
//! anything static (lay it along aisles), from the last back to the first (`loop`) or back and
//! forth (`ping_pong`).

use crate::config::Patrol;
use crate::geometry::Point;
use crate::scene::Scene;
use crate::sim::moving::{Agent, Behaviour, Neighbours};
use crate::sim::rng::Rng;
use std::sync::Arc;

/// A patrol of points.
#[derive(Clone, Debug)]
pub struct Waypoints {
    points: Arc<[Point]>,
    /// The point it heads for.
    target: usize,
    /// `ping_pong`: whether it goes up the list.
    forward: bool,
    mode: Patrol,
}

impl Waypoints {
    /// A patrol of `points` (two or more) heading first for `points[first]`.
    pub fn new(points: Arc<[Point]>, first: usize, mode: Patrol) -> Self {
        Self {
            points,
            target: first,
            forward: true,
            mode,
        }
    }
}

impl Behaviour for Waypoints {
    #[inline]
    fn next(&mut self, me: &Agent, _: &Neighbours<'_>, _: &Scene, _: &mut Rng) -> Option<Point> {
        let points = &self.points;
        let mut at = me.position;
        let mut left = me.speed_px;
        // Each leg at least as long as a step is entered once per call.
        for _ in 0..points.len() * 2 {
            let goal = points[self.target];
            let d = (goal - at).norm();
            if d > left {
                at += (goal - at) * (left / d);
                break;
            }
            at = goal;
            left -= d;
            advance_target(&mut self.target, &mut self.forward, self.mode, points.len());
            if left <= 0.0 {
                break;
            }
        }
        Some(at)
    }

    fn boxed_clone(&self) -> Box<dyn Behaviour> {
        Box::new(self.clone())
    }
}

/// The next waypoint after reaching `target`.
fn advance_target(target: &mut usize, forward: &mut bool, mode: Patrol, n: usize) {
    match mode {
        Patrol::Loop => *target = (*target + 1) % n,
        Patrol::PingPong => {
            if *forward && *target + 1 == n {
                *forward = false;
            } else if !*forward && *target == 0 {
                *forward = true;
            }
            *target = if *forward { *target + 1 } else { *target - 1 };
        }
    }
}
