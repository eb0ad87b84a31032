//! The geodesic policy: plan the shortest path on the free grid (Dijkstra over the geodesic
//! distance to the goal, a navigation function with no local minima), pull it straight, follow it.
//!
//! Planning charges steps next to walls extra and smooths with a margin, so the path keeps a few
//! px off corners the discrete robot could clip.

use super::follow::{FollowStep, Follower};
use super::{Decision, Policy, PolicyError};
use crate::geometry::Point;
use crate::plan::{grid_path, smooth, DistanceField};
use crate::sim::{DiscreteAction, Episode, World};

/// Cost factor of grid steps within a radius of touching a wall.
const CLOSE_COST: f64 = 4.0;
/// Extra clearance, px, the smoothed path keeps where it can.
const MARGIN_PX: f64 = 6.0;

/// Shortest-path following.
#[derive(Debug, Default)]
pub struct Geodesic {
    follower: Option<Follower>,
}

/// `geodesic-wait`: how near ahead (px beyond the robot's radius) an unexpected obstacle makes
/// it wait, and over what angle either side of the heading.
const WAIT_WITHIN_PX: f64 = 15.0;
const WAIT_HALF_ANGLE_DEG: f64 = 40.0;
/// Most steps in a row it waits before going on regardless (a still obstacle that appeared in the
/// corridor would otherwise hold it for ever).
const MAX_WAIT_STEPS: u32 = 40;

/// Shortest-path following that gives way: where the laser sees an obstacle the still scene does
/// not have close ahead (a moving or appeared one), it waits, turning on the spot left then right,
/// until the way is clear (at most `MAX_WAIT_STEPS` in a row).
#[derive(Debug, Default)]
pub struct GeodesicWait {
    inner: Geodesic,
    waited: u32,
    last_wait: Option<DiscreteAction>,
}

impl Policy for GeodesicWait {
    fn reset(&mut self, world: &World, episode: &Episode) -> Result<(), PolicyError> {
        self.waited = 0;
        self.last_wait = None;
        self.inner.reset(world, episode)
    }

    fn act(&mut self, episode: &Episode) -> Result<Decision, PolicyError> {
        // Finish a wait's turn back to the heading first.
        if self.last_wait == Some(DiscreteAction::Left) {
            self.last_wait = Some(DiscreteAction::Right);
            return Ok(Decision::Act(DiscreteAction::Right.into()));
        }
        let decision = self.inner.act(episode)?;
        let ahead = matches!(decision, Decision::Act(a) if a == DiscreteAction::Ahead.into());
        let reach = episode.config().robot.radius_px + WAIT_WITHIN_PX;
        let blocked = ahead
            && super::dodge::unexpected(episode)
                .iter()
                .any(|&(angle, d)| angle.abs() <= WAIT_HALF_ANGLE_DEG && d <= reach);
        if blocked && self.waited < MAX_WAIT_STEPS {
            self.waited += 1;
            self.last_wait = Some(DiscreteAction::Left);
            return Ok(Decision::Act(DiscreteAction::Left.into()));
        }
        self.waited = 0;
        self.last_wait = None;
        Ok(decision)
    }
}

/// Grid points of the path an [`Expert`] smooths: about the next 400 px, plenty for its label
/// (smoothing the whole path for every sample costs 3x the time and changes 0.5% of labels).
const EXPERT_PATH_POINTS: usize = 80;

/// A follower of a grid `path`, smoothed; with `prefix`, of only its first `prefix` points.
fn follow(world: &World, mut path: Vec<Point>, prefix: Option<usize>) -> Follower {
    if let Some(n) = prefix {
        path.truncate(n.max(2));
    }
    let radius = world.config().robot.radius_px;
    let path = smooth(world.scene(), &path, radius + MARGIN_PX);
    Follower::new(path, world.config().robot.move_speed_px * 2.0)
}

/// A follower of the smoothed shortest path from `from` to `goal` in `world`; `None` when there
/// is none.
pub(crate) fn planned(world: &World, from: Point, goal: Point) -> Option<Follower> {
    let radius = world.config().robot.radius_px;
    grid_path(world.scene(), world.grid(), from, goal, radius, CLOSE_COST)
        .map(|path| follow(world, path, None))
}

impl Policy for Geodesic {
    fn reset(&mut self, world: &World, episode: &Episode) -> Result<(), PolicyError> {
        self.follower = planned(world, episode.pose().position(), episode.goal());
        Ok(())
    }

    fn act(&mut self, episode: &Episode) -> Result<Decision, PolicyError> {
        let Some(follower) = &mut self.follower else {
            return Ok(Decision::GiveUp("no path to the goal".into()));
        };
        Ok(follower
            .drive(episode)
            .decision("reached the end of the path short of the goal"))
    }
}

/// The geodesic policy as a teacher: the action it would take from any pose towards one goal,
/// planned afresh from that pose, for labelling data (re-posed samples, or states another policy
/// drove to).
#[derive(Debug)]
pub struct Expert {
    field: DistanceField,
}

impl Expert {
    fn field(world: &World, goal: Point) -> DistanceField {
        DistanceField::new(
            world.scene(),
            world.grid(),
            goal,
            world.config().robot.radius_px,
            CLOSE_COST,
        )
    }

    /// A teacher for `goal` in `world`.
    pub fn new(world: &World, goal: Point) -> Self {
        Self {
            field: Self::field(world, goal),
        }
    }

    /// The action from `episode`'s pose; `None` when the goal is unreachable from there or the
    /// robot is already at the end of the path.
    pub fn action(&self, world: &World, episode: &Episode) -> Option<DiscreteAction> {
        let from = episode.pose().position();
        let radius = world.config().robot.radius_px;
        let path = self.field.path(world.scene(), world.grid(), from, radius)?;
        match follow(world, path, Some(EXPERT_PATH_POINTS)).next(episode) {
            FollowStep::Act(a) => Some(a),
            FollowStep::Steer { .. } | FollowStep::Arrived | FollowStep::Stuck => None,
        }
    }
}
