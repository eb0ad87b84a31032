//! The paper's first-person view (docs/model.md "Sensors", display only): the scene turned so the heading
//! points up, the circle of laser range, the rays in their colour classes and the goal arrow.

use crate::geometry::Point;
use crate::render::{ray_colour, FLOOR, GOAL, PATH, RANGE_CIRCLE, WALL};
use crate::sim::Pose;
use image::{Rgb, RgbImage};

/// Half the side of the square the first-person view shows, as a multiple of the laser range:
/// the circle of range with a margin around it.
pub const FIRST_PERSON_HALF_SPAN: f64 = 1.2;

/// The first-person frame (docs/model.md "Sensors", display only): the scene turned by `theta_s = 90 - z` about
/// the robot, so the heading points up. View coordinates are px from the robot, `u` to the right
/// and `v` up (straight ahead); they keep scene lengths.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HeadingUp {
    origin: Point,
    /// The scene direction of the view's `+u` axis: the heading turned 90 degrees clockwise.
    right: crate::geometry::Vector,
    heading_deg: f64,
}

impl HeadingUp {
    /// The frame of a robot at `pose`.
    pub fn new(pose: Pose) -> Self {
        Self {
            origin: pose.position(),
            right: crate::geometry::unit(pose.z_deg - 90.0),
            heading_deg: pose.z_deg,
        }
    }

    /// The view coordinates `(u, v)` of scene point `p`.
    pub fn to_view(&self, p: Point) -> (f64, f64) {
        let d = p - self.origin;
        let r = self.right;
        (d.x * r.x + d.y * r.y, -d.x * r.y + d.y * r.x)
    }

    /// The scene point at view coordinates `(u, v)`.
    pub fn to_scene(&self, u: f64, v: f64) -> Point {
        let r = self.right;
        Point::new(
            self.origin.x + u * r.x - v * r.y,
            self.origin.y + u * r.y + v * r.x,
        )
    }

    /// The view direction of the scene direction `deg`, degrees counter-clockwise from `+u`.
    /// For the goal bearing theta this is the paper's arrow angle `theta_a = 90 + (theta - z)`.
    pub fn angle_deg(&self, deg: f64) -> f64 {
        crate::geometry::wrap_deg(90.0 + deg - self.heading_deg)
    }
}

/// The paper's first-person view: the scene around the robot rotated so the heading points up,
/// the circle of laser range, the rays in their colour classes and an arrow towards the goal.
/// `size` is the picture's side in pixels; it shows a square of `2 * FIRST_PERSON_HALF_SPAN *
/// range` px.
pub fn first_person(episode: &crate::sim::Episode, size: u32) -> RgbImage {
    let size = size.max(16);
    let laser = episode.laser();
    let range = laser.range_px();
    let pose = episode.pose();
    let scene = episode.scene();
    let px_per = size as f64 / (2.0 * FIRST_PERSON_HALF_SPAN * range);
    let centre = size as f64 / 2.0;
    let frame = HeadingUp::new(pose);
    let to_screen = |p: Point| {
        let (u, v) = frame.to_view(p);
        (centre + u * px_per, centre - v * px_per)
    };
    let mut img = RgbImage::from_pixel(size, size, FLOOR);
    for row in 0..size {
        for col in 0..size {
            let (u, v) = (col as f64 + 0.5 - centre, centre - (row as f64 + 0.5));
            if scene.occupied(frame.to_scene(u / px_per, v / px_per)) {
                img.put_pixel(col, row, WALL);
            }
        }
    }
    let mut put = |x: f64, y: f64, c: Rgb<u8>| {
        if x >= 0.0 && y >= 0.0 && x < size as f64 && y < size as f64 {
            img.put_pixel(x as u32, y as u32, c);
        }
    };
    let circle_steps = (2.0 * std::f64::consts::PI * range * px_per * 2.0) as usize;
    for k in 0..circle_steps.max(64) {
        let a = k as f64 / circle_steps.max(64) as f64 * std::f64::consts::TAU;
        put(
            centre + a.cos() * range * px_per,
            centre + a.sin() * range * px_per,
            RANGE_CIRCLE,
        );
    }
    let line =
        |put: &mut dyn FnMut(f64, f64, Rgb<u8>), a: (f64, f64), b: (f64, f64), c: Rgb<u8>| {
            let n = ((b.0 - a.0).hypot(b.1 - a.1) * 2.0).ceil().max(1.0) as usize;
            for k in 0..=n {
                let t = k as f64 / n as f64;
                put(a.0 + (b.0 - a.0) * t, a.1 + (b.1 - a.1) * t, c);
            }
        };
    for (i, &d) in episode.readings().iter().enumerate() {
        let dir = crate::geometry::unit(laser.beam_angle_deg(i, pose.z_deg));
        let end = to_screen(pose.position() + dir * d);
        line(&mut put, (centre, centre), end, ray_colour(laser.class(d)));
    }
    // The goal arrow: from the centre towards the goal, half the range long, with a head.
    let to_goal = (episode.goal() - pose.position()).try_normalize(1e-12);
    if let Some(g) = to_goal {
        let tip = to_screen(pose.position() + g * range * 0.5);
        line(&mut put, (centre, centre), tip, GOAL);
        let back = (centre - tip.0, centre - tip.1);
        let len = back.0.hypot(back.1).max(1e-9);
        let (bx, by) = (back.0 / len * 6.0, back.1 / len * 6.0);
        for s in [-0.5f64, 0.5] {
            let (c, sn) = (s.cos(), s.sin());
            let wing = (tip.0 + bx * c - by * sn, tip.1 + bx * sn + by * c);
            line(&mut put, tip, wing, GOAL);
        }
    }
    let robot_px = (episode.config().robot.radius_px * px_per).max(2.0);
    for row in 0..size {
        for col in 0..size {
            let (dx, dy) = (col as f64 + 0.5 - centre, row as f64 + 0.5 - centre);
            if dx * dx + dy * dy <= robot_px * robot_px {
                img.put_pixel(col, row, PATH);
            }
        }
    }
    img
}
