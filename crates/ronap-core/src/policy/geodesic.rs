//! The geodesic policy: plan the shortest path on the free grid (Dijkstra over the geodesic
//! distance to the goal, a navigation function with no local minima), pull it straight, follow it.
//!
//! Planning charges steps next to walls extra and smooths with a margin, so the path keeps a few
//! px off corners the discrete robot could clip.

use super::follow::Follower;
use super::{Decision, Policy, PolicyError};
use crate::episode::Episode;
use crate::planning::{smooth, DistanceField};
use crate::world::World;

/// Cost factor of grid steps within a radius of touching a wall.
const CLOSE_COST: f64 = 4.0;
/// Extra clearance, px, the smoothed path keeps where it can.
const MARGIN_PX: f64 = 6.0;

/// Shortest-path following.
#[derive(Debug, Default)]
pub struct Geodesic {
    follower: Option<Follower>,
}

impl Geodesic {
    /// The path being followed, once planned.
    pub fn path(&self) -> Option<&[crate::geometry::Point]> {
        self.follower.as_ref().map(Follower::path)
    }
}

impl Policy for Geodesic {
    fn reset(&mut self, world: &World, episode: &Episode) -> Result<(), PolicyError> {
        let radius = world.config().robot.radius_px;
        let scene = world.scene();
        let grid = world.grid();
        let field = DistanceField::new(scene, grid, episode.goal(), radius, CLOSE_COST);
        self.follower = field
            .path(scene, grid, episode.pose().position(), radius)
            .map(|path| {
                let path = smooth(scene, &path, radius + MARGIN_PX);
                Follower::new(path, world.config().robot.move_speed_px * 2.0)
            });
        Ok(())
    }

    fn act(&mut self, episode: &Episode) -> Result<Decision, PolicyError> {
        let Some(follower) = &mut self.follower else {
            return Ok(Decision::GiveUp("no path to the goal".into()));
        };
        Ok(follower
            .next(episode)
            .decision("reached the end of the path short of the goal"))
    }
}
