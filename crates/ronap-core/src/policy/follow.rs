//! Following a planned path with the discrete actions: turn towards a point a little way along
//! the path, go ahead when facing it within half a turn step; or, for a car-like robot, which
//! cannot turn on the spot, by pure pursuit: steer onto the circle through that point.
//!
//! The follower also watches its own progress: when the remaining path length has not shrunk for
//! a while (pushing into a wall, turning back and forth) it reports itself stuck, so no episode
//! waits for its time-out to fail.

use crate::config::{KinematicsKind, RobotConfig};
use crate::geometry::{wrap_deg, Point};
use crate::sim::{Action, DiscreteAction, Episode};

/// Steps without the remaining length shrinking by [`PROGRESS_PX`] before the follower gives up:
/// two full turns and then some.
const PATIENCE_STEPS: u32 = 60;
/// Progress that counts, px.
const PROGRESS_PX: f64 = 1.0;
/// A car-like robot's patience: turning round in a narrow aisle takes several moves back and
/// forth that shorten nothing.
const CAR_PATIENCE_STEPS: u32 = 4 * PATIENCE_STEPS;
/// Steps a car-like robot backs up after running into something.
const BACK_UP_STEPS: u32 = 8;

/// What the follower does next.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FollowStep {
    /// Take this action.
    Act(DiscreteAction),
    /// Drive a car-like robot at this speed and steering angle (pure pursuit).
    Steer {
        /// Speed, px per step (negative: backing up).
        v: f64,
        /// Steering angle, degrees.
        steer_deg: f64,
    },
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
            FollowStep::Steer { v, steer_deg } => {
                super::Decision::Act(Action::Steer { v, steer_deg })
            }
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
    /// A car's steps still to back up, and the contacts its episode had counted at its last
    /// command (a new one starts the backing up).
    backing: u32,
    contacts: u32,
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
            backing: 0,
            contacts: 0,
        }
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

    /// The next command for `episode`'s robot: [`Follower::next`]'s discrete action, or for a
    /// car-like robot ([`KinematicsKind::Ackermann`]) pure pursuit's speed and steering angle.
    pub fn drive(&mut self, episode: &Episode) -> FollowStep {
        let robot = &episode.config().robot;
        if robot.kinematics != KinematicsKind::Ackermann {
            return self.next(episode);
        }
        let contacts = episode.collisions() + episode.robot_collisions();
        if contacts > self.contacts {
            self.backing = BACK_UP_STEPS;
        }
        self.contacts = contacts;
        match self.progress(episode) {
            Ok((_, error)) if self.backing > 0 => {
                // Ran into something: back up.
                self.backing -= 1;
                back_up(robot, error)
            }
            Ok((aim, error)) => {
                let p = episode.pose().position();
                pursue(robot, (aim - p).norm(), error)
            }
            Err(step) => step,
        }
    }

    /// The next discrete action for `episode`'s robot.
    pub fn next(&mut self, episode: &Episode) -> FollowStep {
        let (_, error) = match self.progress(episode) {
            Ok(aim) => aim,
            Err(step) => return step,
        };
        let half_turn = episode.config().robot.turn_speed_deg / 2.0;
        FollowStep::Act(if error > half_turn {
            DiscreteAction::Left
        } else if error < -half_turn {
            DiscreteAction::Right
        } else {
            DiscreteAction::Ahead
        })
    }

    /// Where `episode`'s robot is along the path: the point it aims at and the signed turn to
    /// it from its heading (degrees in [-180, 180)), or what ends the following (the end
    /// reached, or no progress for too long).
    fn progress(&mut self, episode: &Episode) -> Result<(Point, f64), FollowStep> {
        let Some(&last) = self.path.last() else {
            return Err(FollowStep::Arrived);
        };
        let pose = episode.pose();
        let p = pose.position();
        if self.path.len() == 1 {
            return Err(FollowStep::Arrived);
        }
        let along = self.along(p);
        let total = self.length_to[self.length_to.len() - 1];
        let remaining = total - along.0 + (p - self.point_at(along.0)).norm();
        if remaining < self.best_remaining - PROGRESS_PX {
            self.best_remaining = remaining;
            self.since_progress = 0;
        } else {
            self.since_progress += 1;
            let patience = match episode.config().robot.kinematics {
                KinematicsKind::Ackermann => CAR_PATIENCE_STEPS,
                _ => PATIENCE_STEPS,
            };
            if self.since_progress > patience {
                return Err(FollowStep::Stuck);
            }
        }
        if (last - p).norm() < self.lookahead_px / 4.0 {
            return Err(FollowStep::Arrived);
        }
        let aim = self.point_at(along.0 + self.lookahead_px);
        let bearing = (aim - p).y.atan2((aim - p).x).to_degrees();
        Ok((aim, wrap_deg(bearing - pose.z_deg + 180.0) - 180.0))
    }
}

/// Pure pursuit for a car-like `robot` whose aim lies `distance` px away, `error` degrees off
/// its heading: the steering angle of the circle through the aim tangent to the heading
/// (curvature `2 sin(error) / distance`), at full speed when the aim is ahead, slower the
/// further it is off; an aim behind the robot is backed towards at half speed with the
/// steering turned over, which turns the car round.
fn pursue(robot: &RobotConfig, distance: f64, error: f64) -> FollowStep {
    let e = error.to_radians();
    if e.cos() < 0.0 {
        return back_up(robot, error);
    }
    let curvature = 2.0 * e.sin() / distance.max(1e-9);
    let steer_deg = (curvature * robot.axle_base_px()).atan().to_degrees();
    let steer_max = robot.steer_limit_deg();
    FollowStep::Steer {
        v: robot.max_linear_speed_px * e.cos().max(0.3),
        steer_deg: steer_deg.clamp(-steer_max, steer_max),
    }
}

/// A car-like `robot` backing up at half speed, the steering turned over so that its front
/// swings towards an aim `error` degrees off its heading.
fn back_up(robot: &RobotConfig, error: f64) -> FollowStep {
    FollowStep::Steer {
        v: -robot.max_linear_speed_px / 2.0,
        steer_deg: -robot.steer_limit_deg() * error.signum(),
    }
}
