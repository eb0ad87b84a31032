//! Following a planned path with the discrete actions: turn towards a point a little way along
//! the path, go ahead when facing it within half a turn step.
//!
//! The follower also watches its own progress: when the remaining path length has not shrunk for
//! a while (pushing into a wall, turning back and forth) it reports itself stuck, so no episode
//! waits for its time-out to fail.

use crate::geometry::{wrap_deg, Point};
use crate::sim::episode::Episode;
use crate::sim::robot::DiscreteAction;

/// Steps without the remaining length shrinking by [`PROGRESS_PX`] before the follower gives up:
/// two full turns and then some.
const PATIENCE_STEPS: u32 = 60;
/// Progress that counts, px.
const PROGRESS_PX: f64 = 1.0;

/// What the follower does next.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FollowStep {
    /// Take this action.
    Act(DiscreteAction),
    /// The end of the path is reached.
    Arrived,
    /// No progress for too long.
    Stuck,
}

impl FollowStep {
    /// The policy's decision: act, or give up, with `end_reason` saying why reaching the end of
    /// the path (short of the goal, or the episode would have ended) is a failure.
    pub fn decision(self, end_reason: &str) -> super::Decision {
        match self {
            FollowStep::Act(a) => super::Decision::Act(a.into()),
            FollowStep::Arrived => super::Decision::GiveUp(end_reason.into()),
            FollowStep::Stuck => super::Decision::GiveUp("stuck following the path".into()),
        }
    }
}

/// A path and where along it the robot is.
#[derive(Clone, Debug)]
pub struct Follower {
    path: Vec<Point>,
    /// Path length from the start to each point.
    length_to: Vec<f64>,
    /// The segment the robot is along.
    segment: usize,
    lookahead_px: f64,
    best_remaining: f64,
    since_progress: u32,
}

impl Follower {
    /// A follower of `path` that aims at the point `lookahead_px` further along the path than the
    /// robot (pure pursuit), which keeps it within a few px of the path.
    pub fn new(path: Vec<Point>, lookahead_px: f64) -> Self {
        let mut length_to = vec![0.0; path.len()];
        for i in 1..path.len() {
            length_to[i] = length_to[i - 1] + (path[i] - path[i - 1]).norm();
        }
        Self {
            path,
            length_to,
            segment: 0,
            lookahead_px,
            best_remaining: f64::INFINITY,
            since_progress: 0,
        }
    }

    /// The path being followed.
    pub fn path(&self) -> &[Point] {
        &self.path
    }

    /// Where `p` projects onto segment `i`, as a path length.
    fn project(&self, i: usize, p: Point) -> (f64, f64) {
        let (a, b) = (self.path[i], self.path[i + 1]);
        let ab = b - a;
        let len2 = ab.norm_squared();
        let t = if len2 > 0.0 {
            ((p - a).dot(&ab) / len2).clamp(0.0, 1.0)
        } else {
            1.0
        };
        (self.length_to[i] + t * len2.sqrt(), t)
    }

    /// The point at path length `s` (clamped to the path).
    fn point_at(&self, s: f64) -> Point {
        let total = self.length_to[self.length_to.len() - 1];
        let s = s.clamp(0.0, total);
        let i = self
            .length_to
            .partition_point(|&l| l <= s)
            .clamp(1, self.path.len() - 1);
        let (a, b) = (self.path[i - 1], self.path[i]);
        let seg = self.length_to[i] - self.length_to[i - 1];
        if seg > 0.0 {
            a + (b - a) * ((s - self.length_to[i - 1]) / seg)
        } else {
            b
        }
    }

    /// Where `p` projects onto the path, moving on to the next segment once past the end of this
    /// one (and never back): the path length and the fraction of the segment.
    fn along(&mut self, p: Point) -> (f64, f64) {
        let mut along = self.project(self.segment, p);
        while along.1 >= 1.0 && self.segment + 2 < self.path.len() {
            self.segment += 1;
            along = self.project(self.segment, p);
        }
        along
    }

    /// The point the lookahead further along the path than `p` (the end once within the
    /// lookahead of it), for a policy that steers by velocity; `None` for an empty path.
    pub fn aim(&mut self, p: Point) -> Option<Point> {
        if self.path.len() < 2 {
            return self.path.last().copied();
        }
        let along = self.along(p);
        Some(self.point_at(along.0 + self.lookahead_px))
    }

    /// The next action for `episode`'s robot.
    pub fn next(&mut self, episode: &Episode) -> FollowStep {
        let Some(&last) = self.path.last() else {
            return FollowStep::Arrived;
        };
        let pose = episode.pose();
        let p = pose.position();
        if self.path.len() == 1 {
            return FollowStep::Arrived;
        }
        let along = self.along(p);
        let total = self.length_to[self.length_to.len() - 1];
        let remaining = total - along.0 + (p - self.point_at(along.0)).norm();
        if remaining < self.best_remaining - PROGRESS_PX {
            self.best_remaining = remaining;
            self.since_progress = 0;
        } else {
            self.since_progress += 1;
            if self.since_progress > PATIENCE_STEPS {
                return FollowStep::Stuck;
            }
        }
        if (last - p).norm() < self.lookahead_px / 4.0 {
            return FollowStep::Arrived;
        }
        let aim = self.point_at(along.0 + self.lookahead_px);
        let bearing = (aim - p).y.atan2((aim - p).x).to_degrees();
        let error = wrap_deg(bearing - pose.z_deg + 180.0) - 180.0;
        let half_turn = episode.config().robot.turn_speed_deg / 2.0;
        FollowStep::Act(if error > half_turn {
            DiscreteAction::Left
        } else if error < -half_turn {
            DiscreteAction::Right
        } else {
            DiscreteAction::Ahead
        })
    }
}
