//! The laser range finder: `beams` rays spread evenly over `fov` degrees centred on the heading.
//!
//! Beam `i` points at `z - fov/2 + i * fov/(m-1)` degrees (beam 0 on the right). A reading is the
//! distance in px from the robot centre to the first obstacle, `range_px` when none is in range.
//!
//! A reading is the least [`Aabb::ray_hit`] over the scene's boxes. When few boxes lie within
//! range, every beam tests each of them; otherwise each beam walks the scene's ray index
//! ([`Scene::rays_from`]), which costs per cell crossed rather than per box in range. Both give
//! the same reading to the bit.

use crate::config::LaserConfig;
use crate::geometry::{least_box_hits, smaller, unit, Aabb, Point, Vector};
use crate::scene::Scene;
use rand_distr::{Distribution, Normal};

/// A scan looks for the boxes within range among those the index's bin lists when it lists at
/// most this many (a bin listing more is a long range, and looking would cost more than it saves).
const MAX_LISTED_BOXES: usize = 32;

/// Up to this many boxes within range, every beam tests each of them (the tests run side by side,
/// a few ns each); beyond, each beam walks the scene's ray grid, which costs about as much as
/// this many tests whatever the range (measured on the default maze and its image at 50-300 px).
const MAX_LOCAL_BOXES: usize = 10;

/// `offset` (a beam's unit vector in the robot frame) turned to the scene frame of `heading`.
#[inline]
fn turn(heading: Vector, offset: Vector) -> Vector {
    Vector::new(
        heading.x * offset.x - heading.y * offset.y,
        heading.x * offset.y + heading.y * offset.x,
    )
}

/// The few boxes within a scan's range: `picked` indexes `boxes`, `sides[k]` is box
/// `picked[k]`'s [`Aabb::sides_from`] the scan's origin.
struct Local<'a> {
    boxes: &'a [Aabb],
    picked: &'a [u32],
    sides: &'a [[f64; 4]],
}

/// Beams go through the vectorised loops in blocks of this many.
const BLOCK: usize = 32;

/// The inverse directions `1 / dir` of the beams at `offsets` for the unit heading `heading`,
/// into `ix` and `iy` (as many as there are offsets); whether one runs along an axis (an
/// infinite component).
#[inline]
fn inverse_directions(heading: Vector, offsets: &[Vector], ix: &mut [f64], iy: &mut [f64]) -> bool {
    let mut along_axis = false;
    for (k, offset) in offsets.iter().enumerate() {
        let dir = turn(heading, *offset);
        (ix[k], iy[k]) = (1.0 / dir.x, 1.0 / dir.y);
        along_axis |= !(ix[k].is_finite() && iy[k].is_finite());
    }
    along_axis
}

/// [`Laser::refine_discs_with`] compiled for the processor's widest instruction set.
struct RefineDiscs<'a> {
    laser: &'a Laser,
    heading: Vector,
    out: &'a mut [f64],
    discs: &'a [(Vector, f64, f64)],
}

impl pulp::WithSimd for RefineDiscs<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _: S) {
        self.laser
            .refine_discs_with(self.heading, self.out, self.discs)
    }
}

/// How much wider than the target a beam window of [`Laser::refine_round`] is on each side,
/// degrees: a hundred times the most [`atan2_deg_near`] can be off, and far above any rounding.
const WINDOW_MARGIN_DEG: f64 = 1e-2;

/// `y.atan2(x)` in degrees to within 1e-4 degrees (a polynomial, no library call): where to look
/// for a target, which an exact test then settles.
#[inline]
fn atan2_deg_near(y: f64, x: f64) -> f64 {
    let (ax, ay) = (x.abs(), y.abs());
    let (small, big) = if ax < ay { (ax, ay) } else { (ay, ax) };
    if big == 0.0 {
        return 0.0;
    }
    let a = small / big;
    let s = a * a;
    // atan on [0, 1] to within 2e-6 rad (an odd polynomial of degree 11).
    let mut r = a
        * (0.999_977_26
            + s * (-0.332_623_47
                + s * (0.193_543_46 + s * (-0.116_432_87 + s * (0.052_653_32 - s * 0.011_721_2)))));
    if ay > ax {
        r = std::f64::consts::FRAC_PI_2 - r;
    }
    if x < 0.0 {
        r = std::f64::consts::PI - r;
    }
    if y < 0.0 {
        r = -r;
    }
    r.to_degrees()
}

/// Colour class of a reading, for drawing rays (docs/model.md "Sensors").
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RayClass {
    /// d > 0.6 d_max.
    Green,
    /// 0.3 d_max < d <= 0.6 d_max.
    Yellow,
    /// d <= 0.3 d_max.
    Red,
}

/// A configured laser: beam directions relative to the heading, precomputed.
#[derive(Clone, Debug)]
pub struct Laser {
    range_px: f64,
    /// Unit vector of each beam in the robot frame (heading along +x).
    offsets: Vec<Vector>,
    first_offset_deg: f64,
    step_deg: f64,
    noise: Option<Normal<f64>>,
    /// How far at most a beam is turned from its place by the last jitter, degrees (0 without
    /// jitter): the beam windows of [`Laser::refine_round`] widen by it.
    spread_deg: f64,
}

impl Laser {
    /// The laser `config` describes (a validated config: at least one beam, positive range).
    pub fn new(config: &LaserConfig) -> Self {
        let m = config.beams as usize;
        let step_deg = if m > 1 {
            config.fov_deg / (m - 1) as f64
        } else {
            0.0
        };
        let first_offset_deg = if m > 1 { -config.fov_deg / 2.0 } else { 0.0 };
        let offsets = (0..m)
            .map(|i| unit(first_offset_deg + i as f64 * step_deg))
            .collect();
        // A validated sigma is finite and >= 0, so `Normal::new` cannot fail.
        let noise = (config.noise_sigma_px > 0.0)
            .then(|| Normal::new(0.0, config.noise_sigma_px).ok())
            .flatten();
        Self {
            range_px: config.range_px,
            offsets,
            first_offset_deg,
            step_deg,
            noise,
            spread_deg: 0.0,
        }
    }

    /// Turns beam `i` by `jitter_deg[i]` from its place, for the scans that follow
    /// (beam-angle jitter).
    pub(crate) fn jitter(&mut self, jitter_deg: &[f64]) {
        self.spread_deg = 0.0;
        for (i, (o, j)) in self.offsets.iter_mut().zip(jitter_deg).enumerate() {
            *o = unit(self.first_offset_deg + i as f64 * self.step_deg + j);
            self.spread_deg = self.spread_deg.max(j.abs());
        }
    }

    /// Number of beams.
    pub fn beams(&self) -> usize {
        self.offsets.len()
    }

    /// Asks for the beams' directions (see [`crate::geometry::prefetch`]).
    pub(crate) fn prefetch(&self) {
        crate::geometry::prefetch::lines(&self.offsets);
    }

    /// Largest reading, px.
    pub fn range_px(&self) -> f64 {
        self.range_px
    }

    /// Direction of beam `i` in the scene for heading `heading_deg`, degrees.
    pub fn beam_angle_deg(&self, i: usize, heading_deg: f64) -> f64 {
        heading_deg + self.first_offset_deg + i as f64 * self.step_deg
    }

    /// Colour class of reading `d`.
    pub fn class(&self, d: f64) -> RayClass {
        if d > 0.6 * self.range_px {
            RayClass::Green
        } else if d > 0.3 * self.range_px {
            RayClass::Yellow
        } else {
            RayClass::Red
        }
    }

    /// Noise-free readings from `position` at `heading_deg` into `out` (one per beam), px.
    pub fn scan(&self, scene: &Scene, position: Point, heading_deg: f64, out: &mut [f64]) {
        self.scan_toward(scene, position, unit(heading_deg), out);
    }

    /// [`Laser::scan`] for the unit heading `heading` (`unit(heading_deg)`), which a caller that
    /// also refines the readings works out once.
    pub fn scan_toward(&self, scene: &Scene, position: Point, heading: Vector, out: &mut [f64]) {
        debug_assert_eq!(out.len(), self.offsets.len());
        let range = self.range_px;
        let r2 = range * range;
        let near = scene.boxes_near(position, range);
        // The boxes within range (their indices, and their sides seen from `position`), when
        // the bin lists few enough to look through and there are few enough of them. (Two
        // small arrays: a scan zeroes them every step.)
        let mut picked = [0u32; MAX_LOCAL_BOXES];
        let mut sides = [[0.0; 4]; MAX_LOCAL_BOXES];
        let mut count = usize::MAX;
        let boxes = scene.boxes();
        if near.len() <= MAX_LISTED_BOXES {
            count = 0;
            for &i in near {
                let b = &boxes[i as usize];
                if b.distance_squared(position) <= r2 {
                    if count == MAX_LOCAL_BOXES {
                        count = usize::MAX;
                        break;
                    }
                    picked[count] = i;
                    sides[count] = b.sides_from(position);
                    count += 1;
                }
            }
        }
        if count <= MAX_LOCAL_BOXES {
            let local = Local {
                boxes,
                picked: &picked[..count],
                sides: &sides[..count],
            };
            self.local_hits(position, heading, &local, out);
        } else {
            let beams = self.offsets.iter().map(|offset| turn(heading, *offset));
            scene
                .rays_from(position)
                .first_box_hits(range, beams.zip(out.iter_mut()));
        }
        if !scene.shapes().is_empty() {
            let near: Vec<_> = scene
                .shapes()
                .iter()
                .filter(|s| s.aabb().distance_squared(position) <= r2)
                .collect();
            if !near.is_empty() {
                self.refine_toward(position, heading, out, |origin, dir, best| {
                    near.iter()
                        .filter_map(|s| s.cast_ray(origin, dir, best))
                        .fold(None, |m: Option<f64>, t| Some(m.map_or(t, |m| m.min(t))))
                });
            }
        }
    }

    /// Every beam's least [`Aabb::ray_hit`] over `boxes` (a few boxes within range) into `out`,
    /// `range_px` where none is hit: the beams in blocks, each box against a block's beams side
    /// by side ([`least_box_hits`], the same bits as `ray_hit`). A beam along an axis (an
    /// infinite inverse component, where `ray_hit` must look for NaN) is asked of `ray_hit`.
    fn local_hits(&self, position: Point, heading: Vector, local: &Local<'_>, out: &mut [f64]) {
        let range = self.range_px;
        let sides = local.sides;
        let (mut ix, mut iy) = ([0.0; BLOCK], [0.0; BLOCK]);
        for (offsets, out) in self.offsets.chunks(BLOCK).zip(out.chunks_mut(BLOCK)) {
            let along_axis = inverse_directions(heading, offsets, &mut ix, &mut iy);
            least_box_hits(sides, &ix, &iy, range, out);
            if along_axis {
                for k in 0..offsets.len() {
                    if !(ix[k].is_finite() && iy[k].is_finite()) {
                        let inv = Vector::new(ix[k], iy[k]);
                        out[k] = local
                            .picked
                            .iter()
                            .filter_map(|&i| local.boxes[i as usize].ray_hit(position, inv, range))
                            .fold(range, smaller);
                    }
                }
            }
        }
    }

    /// Shortens each reading in `out` (taken from `position` at `heading_deg`) to the nearer hit
    /// `hit(origin, unit direction, reading)` reports, if any: how obstacles beyond the scene's
    /// boxes join a scan.
    #[inline]
    pub fn refine(
        &self,
        position: Point,
        heading_deg: f64,
        out: &mut [f64],
        hit: impl FnMut(Point, Vector, f64) -> Option<f64>,
    ) {
        self.refine_toward(position, unit(heading_deg), out, hit);
    }

    /// [`Laser::refine`] for the unit heading `heading` (`unit(heading_deg)`).
    #[inline]
    pub fn refine_toward(
        &self,
        position: Point,
        heading: Vector,
        out: &mut [f64],
        mut hit: impl FnMut(Point, Vector, f64) -> Option<f64>,
    ) {
        for (reading, offset) in out.iter_mut().zip(&self.offsets) {
            let dir = turn(heading, *offset);
            if let Some(t) = hit(position, dir, *reading) {
                if t < *reading {
                    *reading = t;
                }
            }
        }
    }

    /// Like [`Laser::refine`] for a few round targets (`(centre, radius)`): `hit(j, origin,
    /// unit direction, reading)` is asked only for the beams whose direction passes within
    /// target `j`'s angular reach (plus a margin far above rounding), so a scan among many
    /// small targets costs per beam that can touch one, not per beam and target. The readings
    /// are those [`Laser::refine`] gives with a `hit` that reports the nearest target: the same
    /// directions, the same least hit.
    pub fn refine_round(
        &self,
        position: Point,
        heading_deg: f64,
        out: &mut [f64],
        targets: &[(Point, f64)],
        hit: impl FnMut(usize, Point, Vector, f64) -> Option<f64>,
    ) {
        self.refine_round_toward(position, unit(heading_deg), out, targets, hit);
    }

    /// [`Laser::refine_round`] for the unit heading `heading` (`unit(heading_deg)`), which the
    /// caller has already worked out.
    pub(crate) fn refine_round_toward(
        &self,
        position: Point,
        heading: Vector,
        out: &mut [f64],
        targets: &[(Point, f64)],
        mut hit: impl FnMut(usize, Point, Vector, f64) -> Option<f64>,
    ) {
        let m = self.offsets.len();
        let per_step = 1.0 / self.step_deg;
        let mut beam = |i: usize, j: usize, out: &mut [f64]| {
            let dir = turn(heading, self.offsets[i]);
            if let Some(t) = hit(j, position, dir, out[i]) {
                if t < out[i] {
                    out[i] = t;
                }
            }
        };
        // The windows of a few targets first, then their beams: each window is a long chain of
        // dependent operations (a square root, a division, the arctangent), and a loop of
        // windows alone lets the processor work on several chains at once.
        const CHUNK: usize = 16;
        for (c, chunk) in targets.chunks(CHUNK).enumerate() {
            // Per target: where it lies from the first beam, half the angle its window covers,
            // and whether every beam has to be asked.
            let mut windows = [(0.0, 0.0, false); CHUNK];
            for (w, &(centre, radius)) in windows.iter_mut().zip(chunk) {
                let oc = centre - position;
                let d2 = oc.norm_squared();
                // Where the target lies from the first beam: its angle from the heading as the
                // beams are turned (the heading's own unit vector, so any heading in degrees
                // reads the same), brought into [0, 360); a rounding is covered by the window's
                // margin.
                let mut from_first = atan2_deg_near(
                    heading.x * oc.y - heading.y * oc.x,
                    heading.x * oc.x + heading.y * oc.y,
                ) - self.first_offset_deg;
                if from_first < 0.0 {
                    from_first += 360.0;
                }
                if from_first >= 360.0 {
                    from_first -= 360.0;
                }
                // Overlapping the laser, one beam, or no direction to go by: every beam may
                // touch it.
                let r2 = radius * radius;
                let all = d2 <= r2 * (1.0 + 2e-9)
                    || self.step_deg == 0.0
                    || !d2.is_finite()
                    || !from_first.is_finite();
                // Half the angle the target covers (at most tan of it: asin(r / d) <=
                // r / sqrt(d^2 - r^2)), and its direction to within WINDOW_MARGIN_DEG / 100: a
                // window at least as wide as the target's, so every beam that can touch it is
                // asked (the others miss it). Not used when every beam is asked.
                let half = (radius / (d2 - r2).sqrt()).to_degrees() + WINDOW_MARGIN_DEG;
                // Jittered beams may stand off their places by up to the spread.
                let half = if self.spread_deg > 0.0 {
                    half + self.spread_deg
                } else {
                    half
                };
                *w = (from_first, half, all);
            }
            for (k, &(from_first, half, all)) in windows[..chunk.len()].iter().enumerate() {
                let j = c * CHUNK + k;
                if all {
                    for i in 0..m {
                        beam(i, j, out);
                    }
                    continue;
                }
                let last = m - 1;
                for shift in [-360.0, 0.0, 360.0] {
                    let at = from_first + shift;
                    let (lo, hi) = ((at - half) * per_step, (at + half) * per_step);
                    // Beams lo..=hi, each end rounded inwards (a float cast truncates, which is
                    // the floor of a number >= 0).
                    if hi >= 0.0 && lo <= last as f64 {
                        let first = if lo > 0.0 {
                            let t = lo as usize;
                            t + usize::from((t as f64) < lo)
                        } else {
                            0
                        };
                        for i in first..=(hi as usize).min(last) {
                            beam(i, j, out);
                        }
                    }
                }
            }
        }
    }

    /// Shortens each reading in `out` (taken at the unit heading `heading`) to the nearest of
    /// a few discs it meets, each given as `(centre - position, |centre - position|^2, radius^2)`:
    /// the readings [`Laser::refine_toward`] gives with a `hit` that reports the nearest disc by
    /// [`Body::ray`](crate::sim::moving::Body::ray)'s arithmetic (the same operations, so the same
    /// bits). The beams go through in blocks, their distances from each centre side by side.
    pub(crate) fn refine_discs(
        &self,
        heading: Vector,
        out: &mut [f64],
        discs: &[(Vector, f64, f64)],
    ) {
        crate::geometry::ARCH.dispatch(RefineDiscs {
            laser: self,
            heading,
            out,
            discs,
        });
    }

    /// [`Laser::refine_discs`]' loops, compiled for the instruction set [`RefineDiscs`] picks.
    #[inline(always)]
    fn refine_discs_with(&self, heading: Vector, out: &mut [f64], discs: &[(Vector, f64, f64)]) {
        let (mut dx, mut dy) = ([0.0; BLOCK], [0.0; BLOCK]);
        for (offsets, out) in self.offsets.chunks(BLOCK).zip(out.chunks_mut(BLOCK)) {
            let m = offsets.len();
            for (k, offset) in offsets.iter().enumerate() {
                let dir = turn(heading, *offset);
                (dx[k], dy[k]) = (dir.x, dir.y);
            }
            let (mut alongs, mut d2s) = ([0.0; BLOCK], [0.0; BLOCK]);
            for &(oc, oc2, r2) in discs {
                let inside = oc2 <= r2;
                // Where each beam passes the centre, side by side; then the square root only
                // for the few beams that pass within the radius (no other can hit).
                for k in 0..m {
                    // `oc.dot(&dir)` as nalgebra works it out for two components.
                    alongs[k] = oc.x * dx[k] + oc.y * dy[k];
                    d2s[k] = oc2 - alongs[k] * alongs[k];
                }
                for k in 0..m {
                    let (along, d2) = (alongs[k], d2s[k]);
                    if d2 <= r2 {
                        let t = along - (r2 - d2).sqrt();
                        let t = if inside { 0.0 } else { t };
                        if t >= 0.0 && t < out[k] {
                            out[k] = t;
                        }
                    }
                }
            }
        }
    }

    /// Adds Gaussian noise (if configured) to readings, keeping each in `[0, range]`.
    pub fn add_noise(&self, readings: &mut [f64], rng: &mut impl rand::Rng) {
        if let Some(noise) = &self.noise {
            for r in readings {
                *r = (*r + noise.sample(rng)).clamp(0.0, self.range_px);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::LaserConfig;
    use rand::{Rng, SeedableRng};

    fn laser() -> Laser {
        Laser::new(&LaserConfig::default())
    }

    fn scene(boxes: Vec<Aabb>) -> Scene {
        Scene::from_boxes(1000.0, 1000.0, boxes, 50.0)
    }

    fn read(scene: &Scene, p: Point, z: f64) -> Vec<f64> {
        let l = laser();
        let mut out = vec![0.0; l.beams()];
        l.scan(scene, p, z, &mut out);
        out
    }

    #[test]
    fn wall_straight_ahead_at_thirty() {
        // Heading +x; a wall whose near face is 30 px ahead.
        let s = scene(vec![Aabb::from_corners(
            Point::new(130.0, 0.0),
            Point::new(132.0, 1000.0),
        )]);
        let r = read(&s, Point::new(100.0, 500.0), 0.0);
        assert!((r[8] - 30.0).abs() < 1e-9, "{}", r[8]);
        // Beam 7 is 11.25 deg to the right of the heading: 30 / cos(11.25 deg).
        let expected = 30.0 / 11.25f64.to_radians().cos();
        assert!((r[7] - expected).abs() < 1e-9);
        // Beams at +-45 deg: 30 * sqrt 2 = 42.4 < 50, in range; beyond 53.13 deg it is out of range.
        assert!((r[4] - 30.0 * 2f64.sqrt()).abs() < 1e-9);
        assert_eq!(r[0], 50.0);
        assert_eq!(r[16], 50.0);
    }

    #[test]
    fn wall_at_an_angle() {
        // Heading 90 (up); a wall 20 px to the right: the beam at 60 deg right of the heading
        // meets it at 20 / cos(30 deg).
        let s = scene(vec![Aabb::from_corners(
            Point::new(120.0, 0.0),
            Point::new(122.0, 1000.0),
        )]);
        let l = Laser::new(&LaserConfig {
            beams: 7,
            ..LaserConfig::default()
        });
        let mut out = vec![0.0; 7];
        l.scan(&s, Point::new(100.0, 500.0), 90.0, &mut out);
        // Beams every 30 deg from -90: beam 1 points at 90 - 60 = 30 deg from +x.
        assert!(
            (out[1] - 20.0 / 30f64.to_radians().cos()).abs() < 1e-9,
            "{out:?}"
        );
        assert!((out[0] - 20.0).abs() < 1e-9);
    }

    #[test]
    fn into_a_corner() {
        // Walls at x = 120 and y = 120 meeting in a corner; robot at (100, 100) facing 45 deg.
        let s = scene(vec![
            Aabb::from_corners(Point::new(120.0, 0.0), Point::new(122.0, 122.0)),
            Aabb::from_corners(Point::new(0.0, 120.0), Point::new(122.0, 122.0)),
        ]);
        let r = read(&s, Point::new(100.0, 100.0), 45.0);
        assert!((r[8] - 20.0 * 2f64.sqrt()).abs() < 1e-9, "{}", r[8]);
        // Beams along +x and +y meet the walls square on, 20 px away.
        assert!((r[4] - 20.0).abs() < 1e-9);
        assert!((r[12] - 20.0).abs() < 1e-9);
        // The side beams (-45 and 135 deg) meet each wall at 45 degrees, 20 sqrt 2 away.
        assert!((r[0] - 20.0 * 2f64.sqrt()).abs() < 1e-9);
        assert!((r[16] - 20.0 * 2f64.sqrt()).abs() < 1e-9);
    }

    #[test]
    fn beam_along_a_wall_face_reads_it() {
        // Heading exactly 0: beam 8 runs along y = 50, the bottom face of the box.
        let s = scene(vec![Aabb::from_corners(
            Point::new(40.0, 50.0),
            Point::new(42.0, 90.0),
        )]);
        let r = read(&s, Point::new(20.0, 50.0), 0.0);
        assert_eq!(r[8], 20.0);
    }

    #[test]
    fn nothing_in_range_reads_exactly_range() {
        let s = scene(vec![Aabb::from_corners(
            Point::new(900.0, 900.0),
            Point::new(910.0, 910.0),
        )]);
        assert!(read(&s, Point::new(100.0, 100.0), 33.0)
            .iter()
            .all(|&d| d == 50.0));
    }

    #[test]
    fn noise_keeps_readings_in_range() {
        let l = Laser::new(&LaserConfig {
            noise_sigma_px: 30.0,
            ..LaserConfig::default()
        });
        let mut rng = crate::sim::rng::stream(1, crate::sim::rng::Stream::Noise);
        let mut r = vec![25.0; 17];
        for _ in 0..100 {
            l.add_noise(&mut r, &mut rng);
            assert!(r.iter().all(|&d| (0.0..=50.0).contains(&d)));
        }
    }

    #[test]
    fn the_near_atan2_is_within_a_hundredth_of_the_window_margin() {
        let mut worst: f64 = 0.0;
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        for k in 0..200_000 {
            let (x, y) = if k < 3600 {
                let v = unit(k as f64 / 10.0);
                (v.x, v.y)
            } else {
                let scale = 10f64.powi(rng.random_range(-6..6));
                (
                    rng.random_range(-1.0..1.0) * scale,
                    rng.random_range(-1.0..1.0) * scale,
                )
            };
            let exact = y.atan2(x).to_degrees();
            let mut off = (atan2_deg_near(y, x) - exact).abs();
            off = off.min((off - 360.0).abs());
            worst = worst.max(off);
        }
        for (x, y) in [
            (0.0, 0.0),
            (1.0, 0.0),
            (0.0, 1.0),
            (-1.0, 0.0),
            (0.0, -1.0),
            (-1.0, -1.0),
        ] {
            let off = (atan2_deg_near(y, x) - f64::atan2(y, x).to_degrees()).abs();
            worst = worst.max(off.min((off - 360.0).abs()));
        }
        assert!(worst <= 1e-4, "{worst} degrees off");
    }

    #[test]
    fn classes_follow_the_spec_thresholds() {
        let l = laser();
        assert_eq!(l.class(31.0), RayClass::Green);
        assert_eq!(l.class(30.0), RayClass::Yellow);
        assert_eq!(l.class(15.0), RayClass::Red);
    }

    /// The exact distance along `dir` from `origin` to a disc, as the moving model computes it.
    fn disc_ray(c: Point, r: f64, origin: Point, dir: Vector, max: f64) -> Option<f64> {
        let oc = c - origin;
        let along = oc.dot(&dir);
        let d2 = oc.norm_squared() - along * along;
        if d2 > r * r {
            return None;
        }
        let t = if oc.norm_squared() <= r * r {
            0.0
        } else {
            along - (r * r - d2).sqrt()
        };
        (t >= 0.0 && t <= max).then_some(t)
    }

    #[test]
    fn refine_round_reads_what_refine_reads_to_the_bit() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(9);
        for case in 0..2000 {
            let beams = [1, 2, 17, 64, 360, 1081][case % 6];
            let fov = [180.0, 360.0, 90.0, 270.0][case % 4];
            let mut l = Laser::new(&LaserConfig {
                beams,
                fov_deg: fov,
                range_px: 200.0,
                ..LaserConfig::default()
            });
            // Every third case with its beams jittered, some by many beam steps.
            if case % 3 == 1 {
                let sigma = [0.5, 3.0, 20.0][case % 9 / 3];
                let jitter: Vec<f64> = (0..beams)
                    .map(|_| sigma * rng.random_range(-2.0..2.0))
                    .collect();
                l.jitter(&jitter);
            }
            let p = Point::new(rng.random_range(0.0..500.0), rng.random_range(0.0..500.0));
            // Headings as a robot turns them, and far beyond a turn or two.
            let heading = match case % 10 {
                7 => rng.random_range(-1e7..1e7),
                8 => rng.random_range(-1e18..1e18),
                _ => rng.random_range(-720.0..720.0),
            };
            // Up to 40 discs: more than the 16 whose windows are worked out at a time.
            let discs: Vec<(Point, f64)> = (0..rng.random_range(0..40))
                .map(|_| {
                    let at = p + Vector::new(
                        rng.random_range(-220.0..220.0),
                        rng.random_range(-220.0..220.0),
                    );
                    (at, rng.random_range(0.5..12.0))
                })
                .collect();
            let walls: Vec<f64> = (0..beams).map(|_| rng.random_range(0.0..200.0)).collect();
            let mut want = walls.clone();
            l.refine(p, heading, &mut want, |o, dir, best| {
                discs
                    .iter()
                    .filter_map(|&(c, r)| disc_ray(c, r, o, dir, best))
                    .fold(None, |m: Option<f64>, t| Some(m.map_or(t, |m| m.min(t))))
            });
            let mut got = walls.clone();
            l.refine_round(p, heading, &mut got, &discs, |j, o, dir, best| {
                disc_ray(discs[j].0, discs[j].1, o, dir, best)
            });
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(
                bits(&got),
                bits(&want),
                "case {case}: {beams} beams over {fov} deg"
            );
        }
    }
}
