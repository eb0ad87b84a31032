//! Drawing scenes to images: white floor, black walls, y flipped so up is up.
//!
//! A [`Canvas`] maps scene px to image pixels at `scale` pixels per px. Markers and paths are drawn
//! in scene coordinates, so callers never deal with the flip.

use crate::geometry::{Aabb, Point};
use crate::lidar::{Laser, RayClass};
use crate::robot::Pose;
use crate::scene::Scene;
use image::{Rgb, RgbImage};

/// Floor colour.
pub const FLOOR: Rgb<u8> = Rgb([255, 255, 255]);
/// Wall colour.
pub const WALL: Rgb<u8> = Rgb([0, 0, 0]);
/// Start marker colour (the paper's red).
pub const START: Rgb<u8> = Rgb([220, 30, 30]);
/// Goal marker colour (the paper's green).
pub const GOAL: Rgb<u8> = Rgb([30, 170, 60]);
/// Path colour.
pub const PATH: Rgb<u8> = Rgb([40, 80, 230]);

/// Colour of a laser ray of class `class`.
pub fn ray_colour(class: RayClass) -> Rgb<u8> {
    match class {
        RayClass::Green => PALETTE[5],
        RayClass::Yellow => PALETTE[6],
        RayClass::Red => PALETTE[7],
    }
}

/// An image of a scene region, with drawing in scene coordinates.
pub struct Canvas {
    image: RgbImage,
    scale: f64,
}

impl Canvas {
    /// A canvas showing `scene` (floor and walls) at `scale` image pixels per scene px.
    pub fn new(scene: &Scene, scale: f64) -> Self {
        let w = ((scene.width() * scale).round() as u32).max(1);
        let h = ((scene.height() * scale).round() as u32).max(1);
        let mut canvas = Self {
            image: RgbImage::from_pixel(w, h, FLOOR),
            scale,
        };
        for b in scene.boxes() {
            canvas.fill_box(b, WALL);
        }
        canvas
    }

    /// Image pixels per scene px.
    pub fn scale(&self) -> f64 {
        self.scale
    }

    /// The pixel range `[lo, hi]` whose centres fall in `[a, b]` scene px on an axis of `n` pixels.
    fn pixel_span(&self, a: f64, b: f64, n: u32) -> Option<(u32, u32)> {
        let lo = (a * self.scale - 0.5).ceil().max(0.0);
        let hi = (b * self.scale - 0.5).floor().min(n as f64 - 1.0);
        (lo <= hi).then_some((lo as u32, hi as u32))
    }

    /// The pixel range of [`Canvas::pixel_span`], or, for a span thinner than a pixel, the pixel
    /// holding its middle: at small scales a thin wall still shows.
    fn thin_span(&self, a: f64, b: f64, n: u32) -> Option<(u32, u32)> {
        self.pixel_span(a, b, n).or_else(|| {
            // The middle of the part inside the image, so a wall on the border shows too.
            let (a, b) = (a.max(0.0), b.min(n as f64 / self.scale));
            let mid = ((a + b) / 2.0 * self.scale).floor().min(n as f64 - 1.0);
            (a <= b && mid >= 0.0).then_some((mid as u32, mid as u32))
        })
    }

    /// Fills the pixels whose centres lie in `b` (at least one pixel across, however thin `b`).
    pub fn fill_box(&mut self, b: &Aabb, colour: Rgb<u8>) {
        let (w, h) = self.image.dimensions();
        let (Some((c0, c1)), Some((r0, r1))) = (
            self.thin_span(b.min.x, b.max.x, w),
            self.thin_span(b.min.y, b.max.y, h),
        ) else {
            return;
        };
        for r in r0..=r1 {
            for c in c0..=c1 {
                self.image.put_pixel(c, h - 1 - r, colour);
            }
        }
    }

    /// Fills the disc of `radius` scene px around `p`.
    pub fn fill_disc(&mut self, p: Point, radius: f64, colour: Rgb<u8>) {
        let (w, h) = self.image.dimensions();
        let (Some((c0, c1)), Some((r0, r1))) = (
            self.pixel_span(p.x - radius, p.x + radius, w),
            self.pixel_span(p.y - radius, p.y + radius, h),
        ) else {
            // Too small to cover a pixel centre: colour the pixel holding the centre.
            self.put(p, colour);
            return;
        };
        let r2 = (radius * self.scale).powi(2);
        for r in r0..=r1 {
            for c in c0..=c1 {
                let dx = c as f64 + 0.5 - p.x * self.scale;
                let dy = r as f64 + 0.5 - p.y * self.scale;
                if dx * dx + dy * dy <= r2 {
                    self.image.put_pixel(c, h - 1 - r, colour);
                }
            }
        }
    }

    /// Colours the pixel holding `p`, if inside the image.
    pub fn put(&mut self, p: Point, colour: Rgb<u8>) {
        let (w, h) = self.image.dimensions();
        let (c, r) = ((p.x * self.scale).floor(), (p.y * self.scale).floor());
        if c >= 0.0 && r >= 0.0 && c < w as f64 && r < h as f64 {
            self.image.put_pixel(c as u32, h - 1 - r as u32, colour);
        }
    }

    /// Draws the segment `a`–`b`, `width_px` image pixels wide.
    pub fn line(&mut self, a: Point, b: Point, width_px: f64, colour: Rgb<u8>) {
        let length_px = (b - a).norm() * self.scale;
        let samples = (length_px * 2.0).ceil().max(1.0) as usize;
        let radius = width_px / 2.0 / self.scale;
        for k in 0..=samples {
            let p = a + (b - a) * (k as f64 / samples as f64);
            if width_px <= 1.0 {
                self.put(p, colour);
            } else {
                self.fill_disc(p, radius, colour);
            }
        }
    }

    /// Draws a polyline through `points`.
    pub fn path(&mut self, points: &[Point], width_px: f64, colour: Rgb<u8>) {
        for pair in points.windows(2) {
            self.line(pair[0], pair[1], width_px, colour);
        }
    }

    /// Draws the robot at `pose`: a disc of `radius` px in `colour` and a tick along its heading.
    pub fn robot(&mut self, pose: Pose, radius: f64, colour: Rgb<u8>) {
        let p = pose.position();
        self.fill_disc(p, radius, colour);
        let tip = p + crate::geometry::unit(pose.z_deg) * radius * 2.0;
        self.line(p, tip, 2.0, colour);
    }

    /// Draws a laser scan taken at `pose`: each ray to its reading, in its colour class.
    pub fn scan(&mut self, laser: &Laser, pose: Pose, readings: &[f64]) {
        for (i, &d) in readings.iter().enumerate() {
            let dir = crate::geometry::unit(laser.beam_angle_deg(i, pose.z_deg));
            self.line(
                pose.position(),
                pose.position() + dir * d,
                1.0,
                ray_colour(laser.class(d)),
            );
        }
    }

    /// The finished image.
    pub fn into_image(self) -> RgbImage {
        self.image
    }
}

/// The whole scene with an episode drawn on it: `path` in blue, start red, goal green, the robot
/// and its current laser scan.
pub fn top_down(episode: &crate::episode::Episode, path: &[Point], scale: f64) -> RgbImage {
    let config = episode.config();
    let mut canvas = Canvas::new(episode.scene(), scale);
    let least = 4.0 / scale;
    canvas.fill_disc(
        episode.goal(),
        config.episode.goal_tolerance_px.max(least),
        GOAL,
    );
    canvas.path(path, 2.0, PATH);
    canvas.scan(episode.laser(), episode.pose(), episode.readings());
    canvas.robot(episode.start(), config.robot.radius_px.max(least), START);
    canvas.robot(episode.pose(), config.robot.radius_px.max(least), PATH);
    canvas.into_image()
}

/// Colour of the circle of laser range in the first-person view.
pub const RANGE_CIRCLE: Rgb<u8> = Rgb([150, 150, 150]);

/// Every colour the pictures of this module use: floor, walls, markers, path, rays and the range
/// circle. An animation encodes with exactly these ([`crate::animation`]).
pub const PALETTE: [Rgb<u8>; 9] = [
    FLOOR,
    WALL,
    START,
    GOAL,
    PATH,
    Rgb([40, 190, 60]),
    Rgb([235, 190, 20]),
    Rgb([225, 40, 40]),
    RANGE_CIRCLE,
];

/// Half the side of the square the first-person view shows, as a multiple of the laser range:
/// the circle of range with a margin around it.
pub const FIRST_PERSON_HALF_SPAN: f64 = 1.2;

/// The first-person frame (SPEC.md, "Display only"): the scene turned by `theta_s = 90 - z` about
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
pub fn first_person(episode: &crate::episode::Episode, size: u32) -> RgbImage {
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn walls_are_black_and_up_is_up() {
        // A wall along the bottom edge of a 10 x 10 scene, 2 px high.
        let wall = Aabb::from_corners(Point::new(0.0, 0.0), Point::new(10.0, 2.0));
        let scene = Scene::from_boxes(10.0, 10.0, vec![wall], 5.0);
        let img = Canvas::new(&scene, 1.0).into_image();
        assert_eq!(img.dimensions(), (10, 10));
        assert_eq!(*img.get_pixel(3, 9), WALL);
        assert_eq!(*img.get_pixel(3, 8), WALL);
        assert_eq!(*img.get_pixel(3, 7), FLOOR);
        assert_eq!(*img.get_pixel(3, 0), FLOOR);
        // At a tenth of the scale the 2 px wall is a fifth of a pixel, and still one pixel high.
        let small = Canvas::new(&scene, 0.1).into_image();
        assert_eq!(small.dimensions(), (1, 1));
        assert_eq!(*small.get_pixel(0, 0), WALL);
        let inner = Aabb::from_corners(Point::new(49.0, 0.0), Point::new(51.0, 100.0));
        let border = Aabb::from_corners(Point::new(99.0, 0.0), Point::new(101.0, 100.0));
        let scene = Scene::from_boxes(100.0, 100.0, vec![inner, border], 5.0);
        let img = Canvas::new(&scene, 0.4).into_image();
        for col in [19, 20, 39] {
            let walls = (0..40).filter(|&r| *img.get_pixel(col, r) == WALL).count();
            assert_eq!(walls, if col == 19 { 0 } else { 40 }, "column {col}");
        }
    }

    #[test]
    fn heading_up_puts_the_heading_up_and_the_left_left() {
        for z in [0.0, 37.0, 90.0, 200.0, 359.0] {
            let pose = Pose::new(100.0, 50.0, z);
            let frame = HeadingUp::new(pose);
            let ahead = pose.position() + crate::geometry::unit(z) * 10.0;
            let left = pose.position() + crate::geometry::unit(z + 90.0) * 10.0;
            let (u, v) = frame.to_view(ahead);
            assert!(
                u.abs() < 1e-9 && (v - 10.0).abs() < 1e-9,
                "z {z}: ({u}, {v})"
            );
            let (u, v) = frame.to_view(left);
            assert!(
                (u + 10.0).abs() < 1e-9 && v.abs() < 1e-9,
                "z {z}: ({u}, {v})"
            );
            let back = frame.to_scene(3.0, -4.0);
            let (u, v) = frame.to_view(back);
            assert!((u - 3.0).abs() < 1e-9 && (v + 4.0).abs() < 1e-9);
            // The paper's arrow angle: theta_a = 90 + (theta - z).
            let theta = 10.0;
            let expected = crate::geometry::wrap_deg(90.0 + theta - z);
            let got = frame.angle_deg(theta);
            let diff = crate::geometry::wrap_deg(got - expected);
            assert!(diff.min(360.0 - diff) < 1e-9, "z {z}: {got} vs {expected}");
        }
    }
}
