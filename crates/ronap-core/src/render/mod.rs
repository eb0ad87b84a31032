//! Pictures, above `eval`: the canvas, the top view, the first-person view, trajectory pictures of
//! finished episodes, animated GIFs and the charts that compare policies ([`compare_chart`] and
//! the others of `chart`). Uses every layer below it.
//!
//! Drawing scenes to images: white floor, black walls, y flipped so up is up.
//!
//! A [`Canvas`] maps scene px to image pixels at `scale` pixels per px. Markers and paths are drawn
//! in scene coordinates, so callers never deal with the flip.
//!
//! The files are private: what other crates use is re-exported here (`pub use`), and what the
//! layers above use beside it, `pub(crate) use`, so a file can move without breaking anyone.

pub(crate) mod chart;
mod first_person;
mod gif;
mod player;
mod team;
mod trajectory;

// The charts that compare policies.
pub use chart::{
    compare_chart, contact_sheet, grouped_bars, outcome_strip, PolicyBars, Series, SheetRow,
};
pub use first_person::{first_person, HeadingUp, FIRST_PERSON_HALF_SPAN};
pub use gif::{animate, Animation, AnimationError, GifOptions, View};
pub use team::{team_frame, team_setup};

// For the layers above only.
pub(crate) use gif::{check_logged_step, same_pose, GifWriter};
pub use player::Trace;
pub(crate) use player::{player_page, Acted, PlayerPage, Recorder};
pub(crate) use team::team_gif_writer;
pub(crate) use trajectory::{team_image, trajectory_image};

use crate::geometry::{Aabb, Point};
use crate::scene::Scene;
use crate::sim::{Laser, Pose, RayClass};
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
/// Moving obstacle colour.
pub const MOVER: Rgb<u8> = Rgb([235, 120, 20]);
/// Moving obstacles' tracks: the mover colour faded.
pub const MOVER_TRACK: Rgb<u8> = Rgb([250, 210, 170]);

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
        for shape in scene.shapes() {
            match shape.as_disc() {
                Some((c, r)) => canvas.fill_disc(c, r, WALL),
                None => canvas.fill_polygon(&shape.corners(), WALL),
            }
        }
        canvas
    }

    /// Fills the pixels whose centres lie in the convex polygon of `corners` (counter-clockwise).
    pub fn fill_polygon(&mut self, corners: &[Point], colour: Rgb<u8>) {
        let (w, h) = self.image.dimensions();
        let (lo, hi) = corners.iter().fold(
            (
                Point::new(f64::MAX, f64::MAX),
                Point::new(f64::MIN, f64::MIN),
            ),
            |(lo, hi), p| {
                (
                    Point::new(lo.x.min(p.x), lo.y.min(p.y)),
                    Point::new(hi.x.max(p.x), hi.y.max(p.y)),
                )
            },
        );
        let (Some((c0, c1)), Some((r0, r1))) = (
            self.pixel_span(lo.x, hi.x, w),
            self.pixel_span(lo.y, hi.y, h),
        ) else {
            return;
        };
        let n = corners.len();
        for r in r0..=r1 {
            for c in c0..=c1 {
                let p = Point::new((c as f64 + 0.5) / self.scale, (r as f64 + 0.5) / self.scale);
                let inside = (0..n).all(|i| {
                    let (a, b) = (corners[i], corners[(i + 1) % n]);
                    (b - a).perp(&(p - a)) >= 0.0
                });
                if inside {
                    self.image.put_pixel(c, h - 1 - r, colour);
                }
            }
        }
    }

    /// Draws the present moving obstacles where they are.
    pub fn movers(&mut self, movers: &crate::sim::Movers) {
        for m in movers.items().filter(|m| m.present()) {
            self.mover(m.body(), m.position(), MOVER);
        }
    }

    /// Draws a moving obstacle's `body` at `center`.
    pub fn mover(&mut self, body: crate::sim::Body, center: Point, colour: Rgb<u8>) {
        match body {
            crate::sim::Body::Disc(r) => self.fill_disc(center, r, colour),
            crate::sim::Body::Box(_) => self.fill_box(&body.aabb(center), colour),
        }
    }

    /// Draws moving obstacles' tracks faded: each a polyline of its positions while present.
    pub fn tracks(&mut self, tracks: &[crate::sim::Track]) {
        for track in tracks {
            for pair in track.points.windows(2) {
                if let [Some(a), Some(b)] = pair {
                    self.line(*a, *b, 1.5, MOVER_TRACK);
                }
            }
        }
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

    /// Draws the robot `config` describes at `pose`, in `colour`: its footprint (a disc at
    /// least `least` px across, or its rectangle) and a heading line.
    pub fn body(
        &mut self,
        pose: Pose,
        config: &crate::config::RobotConfig,
        least: f64,
        colour: Rgb<u8>,
    ) {
        match crate::sim::Robot::corners(config, pose) {
            Some(corners) => {
                self.fill_polygon(&corners, colour);
                let p = pose.position();
                let reach = config.circumscribed_px().max(least);
                self.line(
                    p,
                    p + crate::geometry::unit(pose.z_deg) * reach * 1.5,
                    2.0,
                    colour,
                );
            }
            None => self.robot(pose, config.radius_px.max(least), colour),
        }
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
/// and its current laser scan (a team of one's [`team_frame`]).
pub fn top_down(episode: &crate::sim::Episode, path: &[Point], scale: f64) -> RgbImage {
    let robot = trajectory::Drawn::running(episode, path, 0, 1);
    let movers = trajectory::Obstacles::Live(episode.movers());
    trajectory::episode_image(episode.scene(), &[robot], movers, scale)
}

/// Colour of the circle of laser range in the first-person view.
pub const RANGE_CIRCLE: Rgb<u8> = Rgb([150, 150, 150]);

/// Every colour the pictures of this module use: floor, walls, markers, path, rays and the range
/// circle. An animation encodes with exactly these ([`animate`]).
pub const PALETTE: [Rgb<u8>; 11] = [
    FLOOR,
    WALL,
    START,
    GOAL,
    PATH,
    Rgb([40, 190, 60]),
    Rgb([235, 190, 20]),
    Rgb([225, 40, 40]),
    RANGE_CIRCLE,
    MOVER,
    MOVER_TRACK,
];

/// `image` encoded as a PNG file's bytes (for pages and reports that inline their pictures).
pub fn png_bytes(image: &image::RgbImage) -> Result<Vec<u8>, image::ImageError> {
    let mut bytes = Vec::new();
    image.write_to(
        &mut std::io::Cursor::new(&mut bytes),
        image::ImageFormat::Png,
    )?;
    Ok(bytes)
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
