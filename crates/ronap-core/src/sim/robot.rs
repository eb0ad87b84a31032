//! The robot: a disc with a pose `[x px, y px, z deg]`, its discrete and continuous actions, and
//! its kinematics ([`crate::sim::kinematics`]), which say where an action takes it. The whole
//! motion of a step is swept against the scene, so no speed carries the disc through a wall.

pub use crate::sim::action::{Action, DiscreteAction, Pose};
pub use crate::sim::kinematics::Motion;

use crate::config::RobotConfig;
use crate::geometry::{Point, Vector};
use crate::scene::Scene;
use crate::sim::kinematics::{self, Built, Kinematics, Velocity};
use std::sync::Arc;

/// The robot's shape and how it moves (`Kinematics`).
#[derive(Clone, Debug)]
pub struct Robot {
    radius_px: f64,
    /// The built-in unicycle held as itself, any other kind behind the trait: a step's command
    /// then inlines into the episode's step for the paper's robot, where calls through the
    /// trait cost 4% of `ronap bench --threads 1`'s steps.
    kinematics: Built,
    /// A footprint other than a disc as the discs that hold it (offset in the robot's frame,
    /// radius); empty for a disc.
    cover: Vec<(Vector, f64)>,
    /// The footprint's corners in the robot's frame ([`RobotConfig::outline`]); empty for a
    /// disc.
    outline: Vec<[f64; 2]>,
}

impl Robot {
    /// The robot `config` describes.
    pub fn new(config: &RobotConfig) -> Self {
        Self {
            radius_px: config.radius_px,
            kinematics: kinematics::for_robot(config),
            cover: (config.cover().into_iter())
                .map(|([x, y], r)| (Vector::new(x, y), r))
                .collect(),
            outline: config.outline(),
        }
    }

    /// A disc of `radius_px` moving as `kinematics` says (a kind of robot of one's own).
    pub fn with_kinematics(radius_px: f64, kinematics: Arc<dyn Kinematics>) -> Self {
        Self {
            radius_px,
            kinematics: Built::Other(kinematics),
            cover: Vec::new(),
            outline: Vec::new(),
        }
    }

    /// Disc radius, px.
    pub fn radius_px(&self) -> f64 {
        self.radius_px
    }

    /// The footprint's corners in the robot's frame, `[ahead px, left px]`; empty for a disc.
    pub fn outline(&self) -> &[[f64; 2]] {
        &self.outline
    }

    /// How the robot moves.
    pub fn kinematics(&self) -> &dyn Kinematics {
        match &self.kinematics {
            Built::Unicycle(u) => u,
            Built::Other(k) => k.as_ref(),
        }
    }

    /// Where `action` takes the robot from `pose`, standing, in free space.
    pub fn motion(&self, pose: Pose, action: Action) -> Motion {
        self.motion_from(pose, Velocity::default(), None, action)
    }

    /// The velocity `action` commands from `velocity` (the last step's), within the robot's
    /// limits, and how much of a full turn command it is.
    #[inline]
    pub fn command(&self, velocity: Velocity, action: Action) -> (Velocity, f64) {
        match &self.kinematics {
            Built::Unicycle(u) => u.command(velocity, action),
            Built::Other(k) => k.command(velocity, action),
        }
    }

    /// Where `action` takes the robot from `pose` with `velocity` held over the last step, in
    /// free space; `facing` is `pose`'s unit heading (`unit(pose.z_deg)`) when the caller has it
    /// already: a move straight ahead goes along it (the same bits: `unit` is the heading's
    /// cosine and sine, as the move works them out without it).
    #[inline]
    pub fn motion_from(
        &self,
        pose: Pose,
        velocity: Velocity,
        facing: Option<Vector>,
        action: Action,
    ) -> Motion {
        self.motion_executed(pose, velocity, facing, action, |_, v| v)
    }

    /// [`Robot::motion_from`] with the commanded velocity turned into the one the body
    /// executes by `executed` (given the kinematics; motion noise).
    #[inline]
    pub fn motion_executed(
        &self,
        pose: Pose,
        velocity: Velocity,
        facing: Option<Vector>,
        action: Action,
        executed: impl FnOnce(&dyn Kinematics, Velocity) -> Velocity,
    ) -> Motion {
        let (commanded, turn_fraction) = self.command(velocity, action);
        let velocity = executed(self.kinematics(), commanded);
        Motion {
            end: kinematics::travel(pose, velocity, facing),
            turn_fraction,
            velocity,
        }
    }

    /// Whether the disc can make `motion` from `pose` without touching an obstacle.
    #[inline]
    pub fn motion_clear(&self, scene: &Scene, pose: Pose, motion: &Motion) -> bool {
        self.motion_clear_by(pose, motion, |a, b, r| scene.sweep_clear(a, b, r))
    }

    /// Whether the body can make `motion` from `pose` with every straight piece of its sweep
    /// passing `sweep_clear(from, to, radius)`: the same check against any obstacles. A disc
    /// sweeps its arc; a rectangle, each disc that holds a piece of it along that piece's own
    /// arc (every point of a body turning at a constant rate moves on a circle).
    #[inline]
    pub fn motion_clear_by(
        &self,
        pose: Pose,
        motion: &Motion,
        mut sweep_clear: impl FnMut(Point, Point, f64) -> bool,
    ) -> bool {
        if self.cover.is_empty() {
            return kinematics::sweep_arc(
                pose,
                motion.velocity,
                motion.end,
                self.radius_px,
                sweep_clear,
            );
        }
        self.cover_clear(pose, motion, &mut sweep_clear)
    }

    /// [`Robot::motion_clear_by`] for a footprint other than a disc (out of the disc's way).
    #[inline(never)]
    fn cover_clear(
        &self,
        pose: Pose,
        motion: &Motion,
        sweep_clear: &mut dyn FnMut(Point, Point, f64) -> bool,
    ) -> bool {
        let v = motion.velocity;
        let w = v.w_deg.to_radians();
        let heading = crate::geometry::unit(pose.z_deg);
        let end_heading = crate::geometry::unit(motion.end.z_deg);
        self.cover.iter().all(|&(o, r)| {
            let at = |p: Pose, h: Vector| {
                let q = p.position() + h * o.x + Vector::new(-h.y, h.x) * o.y;
                Pose::new(q.x, q.y, p.z_deg)
            };
            // The piece's velocity in the robot's frame: the body's plus the turn's about the
            // robot's position.
            let piece = Velocity {
                v: v.v - w * o.y,
                vy: v.vy + w * o.x,
                ..v
            };
            kinematics::sweep_arc(
                at(pose, heading),
                piece,
                at(motion.end, end_heading),
                r,
                &mut *sweep_clear,
            )
        })
    }

    /// The footprint's corners at `pose` (a rectangle's four, counter-clockwise, or a
    /// polygon's), or `None` for a disc.
    pub fn corners(config: &RobotConfig, pose: Pose) -> Option<Vec<Point>> {
        let outline = config.outline();
        if outline.is_empty() {
            return None;
        }
        let mut out = Vec::with_capacity(outline.len());
        Self::place(&outline, pose, &mut out);
        Some(out)
    }

    /// The corners of `outline` (in the robot's frame, `[ahead px, left px]`) at `pose`, into
    /// `out`.
    pub(crate) fn place(outline: &[[f64; 2]], pose: Pose, out: &mut Vec<Point>) {
        let h = crate::geometry::unit(pose.z_deg);
        let left = Vector::new(-h.y, h.x);
        let p = pose.position();
        out.clear();
        out.extend(outline.iter().map(|&[x, y]| p + h * x + left * y));
    }
}

/// How far along the unit `dir` from `origin` the convex polygon `corners` (in order round it,
/// either way) lies, if within `max`: 0 from inside it.
pub(crate) fn ray_convex(corners: &[Point], origin: Point, dir: Vector, max: f64) -> Option<f64> {
    let n = corners.len();
    let twice_area: f64 = (0..n)
        .map(|i| {
            let (a, b) = (corners[i], corners[(i + 1) % n]);
            a.x * b.y - b.x * a.y
        })
        .sum();
    let turn = twice_area.signum();
    // Clip the ray to each edge's inner half-plane (its outward normal `outward`).
    let (mut enter, mut leave) = (0.0f64, max);
    for i in 0..n {
        let (a, b) = (corners[i], corners[(i + 1) % n]);
        let e = b - a;
        let outward = Vector::new(e.y, -e.x) * turn;
        let room = outward.dot(&(a - origin));
        let along = outward.dot(&dir);
        if along == 0.0 {
            if room < 0.0 {
                return None;
            }
            continue;
        }
        let t = room / along;
        if along < 0.0 {
            enter = enter.max(t);
        } else {
            leave = leave.min(t);
        }
        if enter > leave {
            return None;
        }
    }
    Some(enter)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn discrete_actions_follow_the_spec() {
        let robot = Robot::new(&RobotConfig::default());
        let p = Pose::new(100.0, 100.0, 90.0);
        let ahead = robot.motion(p, DiscreteAction::Ahead.into()).end;
        assert!((ahead.x - 100.0).abs() < 1e-12 && (ahead.y - 105.0).abs() < 1e-12);
        assert_eq!(
            robot.motion(p, DiscreteAction::Left.into()).end.z_deg,
            105.0
        );
        assert_eq!(
            robot.motion(p, DiscreteAction::Right.into()).end.z_deg,
            75.0
        );
        let wrapped = robot.motion(Pose::new(0.0, 0.0, 350.0), DiscreteAction::Left.into());
        assert_eq!(wrapped.end.z_deg, 5.0);
    }

    #[test]
    fn continuous_actions_are_clipped_unicycle_arcs() {
        let robot = Robot::new(&RobotConfig::default());
        let p = Pose::new(0.0, 0.0, 0.0);
        let m = robot.motion(
            p,
            Action::Continuous {
                v: 100.0,
                w_deg: 0.0,
            },
        );
        assert!((m.end.x - 5.0).abs() < 1e-12);
        // A quarter turn at v = 5, w = 90 would be clipped to w = 15 deg.
        let m = robot.motion(
            p,
            Action::Continuous {
                v: 5.0,
                w_deg: 90.0,
            },
        );
        assert!((m.end.z_deg - 15.0).abs() < 1e-12);
        let r = 5.0 / 15f64.to_radians();
        assert!((m.end.x - r * 15f64.to_radians().sin()).abs() < 1e-9);
        assert!((m.end.y - r * (1.0 - 15f64.to_radians().cos())).abs() < 1e-9);
        assert_eq!(m.turn_fraction, 1.0);
    }
}

#[cfg(test)]
mod ray_tests {
    use super::*;

    #[test]
    fn a_ray_meets_a_convex_polygon_where_its_edges_say() {
        // The square [0, 10] x [0, 10], counter-clockwise and clockwise.
        let square = [
            Point::new(0.0, 0.0),
            Point::new(10.0, 0.0),
            Point::new(10.0, 10.0),
            Point::new(0.0, 10.0),
        ];
        let reversed: Vec<Point> = square.iter().rev().copied().collect();
        for c in [&square[..], &reversed[..]] {
            let east = Vector::new(1.0, 0.0);
            assert_eq!(ray_convex(c, Point::new(-5.0, 5.0), east, 50.0), Some(5.0));
            assert_eq!(ray_convex(c, Point::new(5.0, 5.0), east, 50.0), Some(0.0));
            assert_eq!(ray_convex(c, Point::new(-5.0, 15.0), east, 50.0), None);
            assert_eq!(ray_convex(c, Point::new(-5.0, 5.0), east, 4.0), None);
            assert_eq!(ray_convex(c, Point::new(15.0, 5.0), east, 50.0), None);
            let d = Vector::new(1.0, 1.0).normalize();
            let t = ray_convex(c, Point::new(-3.0, -3.0), d, 50.0).expect("a hit");
            assert!((t - 3.0 * 2f64.sqrt()).abs() < 1e-12);
        }
    }
}
