//! Geometry, the bottom layer: points, boxes and the exact queries on them, the bin index, the ray
//! grid, and parry2d as the reference geometry. Uses nothing of the crate.
//!
//! Plane geometry on axis-aligned boxes, in scene px (x right, y up).
//!
//! Every obstacle in a ronap scene is an axis-aligned box: a maze wall is a thin box along a cell
//! edge, an image scene is its occupied pixels merged into boxes. These are the exact queries the
//! sensors and the collision check need, written for boxes so they cost a few nanoseconds each.
//!
//! The files are private: what other crates use is re-exported here (`pub use`), and what the
//! layers above use beside it, `pub(crate) use`, so a file can move without breaking anyone.

mod index;
mod orca;
mod point_grid;
pub(crate) mod prefetch;
mod ray_grid;
mod reference;
mod shape;
pub(crate) mod social_force;

// The crowd-avoidance geometry (ORCA's half-planes, the crowd step) and the reference scene.
pub use orca::{
    agent_neighbours, crowd_step, new_velocity, Agent, CrowdAgent, CrowdChoice, CrowdSettings,
    Horizon, Line, Obstacles, Real, Surroundings, Vertex, V2,
};
pub use reference::ParryScene;
pub use shape::Shape;

// For the layers above only.
pub(crate) use index::BinIndex;
pub(crate) use orca::{agent_neighbours_among, obstacle_neighbours};
pub(crate) use point_grid::PointGrid;
pub(crate) use ray_grid::{GridStart, RayGrid};

use nalgebra::{Point2, Vector2};

/// The instruction sets of this processor, detected once: loops written to vectorise run under
/// `ARCH.dispatch`, compiled for the widest set the processor has up to AVX2 (AVX-512, measured
/// for the moving obstacles' pass, gained nothing there). Multiplies and adds stay separate
/// (Rust never fuses them), so every set gives the same bits.
pub(crate) static ARCH: std::sync::LazyLock<pulp::Arch> = std::sync::LazyLock::new(|| {
    #[cfg(target_arch = "x86_64")]
    if let Some(simd) = pulp::x86::V3::try_new() {
        return pulp::Arch::V3(simd);
    }
    pulp::Arch::new()
});

/// [`ARCH`], AVX-512 included where the processor has it: for the long rays' walks, scalar code
/// whose selects and comparisons AVX-512's mask registers take without branches (a ray through a
/// maze a sixth faster on an AMD EPYC, the same bits), and for the network's layers (3-4% faster
/// for sixteen rows on that EPYC; on an Intel Xeon, once, slower for one row).
pub(crate) static WIDEST: std::sync::LazyLock<pulp::Arch> =
    std::sync::LazyLock::new(pulp::Arch::new);

/// A point in the scene, px.
pub type Point = Point2<f64>;
/// A displacement or direction in the scene, px.
pub type Vector = Vector2<f64>;

/// An axis-aligned box `[min.x, max.x] x [min.y, max.y]`, px.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Lower-left corner.
    pub min: Point,
    /// Upper-right corner.
    pub max: Point,
}

/// Where the ray `o + t / inv` enters and leaves the slab `[lo, hi]` (`lo <= hi`) of one axis,
/// in `t`.
///
/// The slab's near side is `lo` when the ray runs up the axis (`inv > 0`) and `hi` when it runs
/// down: rounding keeps `lo - o <= hi - o`, so this is the least and greatest of the two crossings
/// without comparing them. A ray parallel to the axis (`inv` infinite) that starts exactly on a
/// face gives 0 * inf = NaN for that face; the ray then runs along the face, which counts as
/// touching: that slab spans the whole line, so NaN reads as -inf where the slab is entered and
/// +inf where it is left.
#[inline(always)]
fn slab(lo: f64, hi: f64, o: f64, inv: f64) -> (f64, f64) {
    let (t1, t2) = ((lo - o) * inv, (hi - o) * inv);
    let ordered = if inv > 0.0 { (t1, t2) } else { (t2, t1) };
    if !inv.is_finite() && (t1.is_nan() || t2.is_nan()) {
        (f64::NEG_INFINITY, f64::INFINITY)
    } else {
        ordered
    }
}

/// The larger of two numbers neither of which is NaN (one instruction; `f64::max` also checks
/// for NaN). Of two zeros it gives `b`.
#[inline(always)]
pub(crate) fn larger(a: f64, b: f64) -> f64 {
    if a > b {
        a
    } else {
        b
    }
}

/// The smaller of two numbers neither of which is NaN (one instruction). Of two zeros it gives
/// `b`.
#[inline(always)]
pub(crate) fn smaller(a: f64, b: f64) -> f64 {
    if a < b {
        a
    } else {
        b
    }
}

/// For each ray `k` from one origin (given by its inverse direction `(ix[k], iy[k])`, both
/// finite), the least [`Aabb::ray_hit`] within `max_t` over the boxes whose sides, less the
/// origin, are `sides` (`[min.x, max.x, min.y, max.y]` each), into `out[k]`: `max_t` where none
/// is hit. The same operations as `ray_hit` on the same differences, so the same bits; each box
/// goes against every ray as plain arithmetic, which vectorises (compiled here for the widest
/// instruction set the processor has).
pub(crate) fn least_box_hits(
    sides: &[[f64; 4]],
    ix: &[f64],
    iy: &[f64],
    max_t: f64,
    out: &mut [f64],
) {
    ARCH.dispatch(LeastBoxHits {
        sides,
        ix,
        iy,
        max_t,
        out,
    });
}

/// The nearest [`Aabb::ray_hit`] within `max_t` testing every box in turn, the way a scan without
/// a grid or an index does: what the tests hold the fast scans to.
#[cfg(test)]
pub(crate) fn nearest_box_hit(
    boxes: &[Aabb],
    origin: Point,
    inv: Vector,
    max_t: f64,
) -> Option<f64> {
    let mut best = max_t;
    let mut hit = false;
    for b in boxes {
        if let Some(t) = b.ray_hit(origin, inv, best) {
            best = t;
            hit = true;
        }
    }
    hit.then_some(best)
}

/// [`least_box_hits`] as pulp runs it, compiled once per instruction set.
struct LeastBoxHits<'a> {
    sides: &'a [[f64; 4]],
    ix: &'a [f64],
    iy: &'a [f64],
    max_t: f64,
    out: &'a mut [f64],
}

impl pulp::WithSimd for LeastBoxHits<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _: S) {
        let m = self.out.len();
        let (ix, iy, out) = (&self.ix[..m], &self.iy[..m], &mut *self.out);
        out.fill(self.max_t);
        for &[lx, hx, ly, hy] in self.sides {
            for k in 0..m {
                let (nx, fx) = if ix[k] > 0.0 { (lx, hx) } else { (hx, lx) };
                let (ny, fy) = if iy[k] > 0.0 { (ly, hy) } else { (hy, ly) };
                let enter = larger(larger(nx * ix[k], ny * iy[k]), 0.0);
                let exit = smaller(smaller(fx * ix[k], fy * iy[k]), self.max_t);
                let hit = if enter <= exit { enter } else { f64::INFINITY };
                out[k] = smaller(hit, out[k]);
            }
        }
    }
}

impl Aabb {
    /// The sides of the box less `origin`, as [`least_box_hits`] takes them.
    #[inline]
    pub(crate) fn sides_from(&self, origin: Point) -> [f64; 4] {
        [
            self.min.x - origin.x,
            self.max.x - origin.x,
            self.min.y - origin.y,
            self.max.y - origin.y,
        ]
    }

    /// The four corners, counter-clockwise from `min`.
    pub fn corners(&self) -> [Point; 4] {
        [
            self.min,
            Point::new(self.max.x, self.min.y),
            self.max,
            Point::new(self.min.x, self.max.y),
        ]
    }

    /// The box spanning two corners given in any order.
    pub fn from_corners(a: Point, b: Point) -> Self {
        Self {
            min: Point::new(a.x.min(b.x), a.y.min(b.y)),
            max: Point::new(a.x.max(b.x), a.y.max(b.y)),
        }
    }

    /// Width and height, px.
    pub fn extents(&self) -> Vector {
        self.max - self.min
    }

    /// The box grown by `margin` on every side.
    pub fn inflated(&self, margin: f64) -> Self {
        let m = Vector::new(margin, margin);
        Self {
            min: self.min - m,
            max: self.max + m,
        }
    }

    /// Whether `p` lies in the closed box.
    pub fn contains(&self, p: Point) -> bool {
        p.x >= self.min.x && p.x <= self.max.x && p.y >= self.min.y && p.y <= self.max.y
    }

    /// The point of the box nearest `p` (`p` itself inside).
    #[inline]
    pub fn nearest_point(&self, p: Point) -> Point {
        Point::new(
            p.x.clamp(self.min.x, self.max.x),
            p.y.clamp(self.min.y, self.max.y),
        )
    }

    /// Squared distance from `p` to the box, 0 inside.
    #[inline]
    pub fn distance_squared(&self, p: Point) -> f64 {
        let dx = (self.min.x - p.x).max(0.0).max(p.x - self.max.x);
        let dy = (self.min.y - p.y).max(0.0).max(p.y - self.max.y);
        dx * dx + dy * dy
    }

    /// Distance along the ray `origin + t * dir` to the box's boundary, for `t` in `[0, max_t]`,
    /// given `inv_dir = 1 / dir` per component. `Some(0.0)` when the origin is inside. For a box
    /// with `min <= max` and an origin with no NaN (as every box and scan of a scene).
    #[inline]
    pub fn ray_hit(&self, origin: Point, inv_dir: Vector, max_t: f64) -> Option<f64> {
        let (ex, xx) = slab(self.min.x, self.max.x, origin.x, inv_dir.x);
        let (ey, xy) = slab(self.min.y, self.max.y, origin.y, inv_dir.y);
        let enter = larger(larger(ex, ey), 0.0);
        let exit = smaller(smaller(xx, xy), max_t);
        (enter <= exit).then_some(enter)
    }

    /// Whether the segment `a`–`b` stays at least `radius` from the box: the same answer as
    /// `segment_distance_squared(a, b) >= radius * radius`, bit for bit, but settled without a
    /// division where the segment's bounding box keeps clear of the box grown by `radius` (with
    /// a hair to spare, so rounding cannot tell the two apart), and otherwise stopping at the
    /// first point found too close.
    #[inline]
    pub fn segment_clear(&self, a: Point, b: Point, radius: f64) -> bool {
        let grow = radius + SEGMENT_CLEAR_HAIR;
        if a.x.max(b.x) < self.min.x - grow
            || a.x.min(b.x) > self.max.x + grow
            || a.y.max(b.y) < self.min.y - grow
            || a.y.min(b.y) > self.max.y + grow
        {
            return true;
        }
        let r2 = radius * radius;
        let d = b - a;
        let len = d.norm();
        if len > 0.0 {
            let inv = Vector::new(1.0 / (d.x / len), 1.0 / (d.y / len));
            if self.ray_hit(a, inv, len).is_some() {
                return 0.0 >= r2;
            }
        } else if self.contains(a) {
            return 0.0 >= r2;
        }
        self.distance_squared(a) >= r2
            && self.distance_squared(b) >= r2
            && self
                .corners()
                .iter()
                .all(|&c| point_segment_distance_squared(c, a, b) >= r2)
    }

    /// Squared distance between the segment `a`–`b` and the box (0 when they meet).
    pub fn segment_distance_squared(&self, a: Point, b: Point) -> f64 {
        let d = b - a;
        let len = d.norm();
        if len > 0.0 {
            let inv = Vector::new(1.0 / (d.x / len), 1.0 / (d.y / len));
            if self.ray_hit(a, inv, len).is_some() {
                return 0.0;
            }
        } else if self.contains(a) {
            return 0.0;
        }
        // Disjoint convex sets in the plane are closest at a vertex of one of them.
        let corners = self.corners();
        corners
            .iter()
            .map(|&c| point_segment_distance_squared(c, a, b))
            .fold(
                self.distance_squared(a).min(self.distance_squared(b)),
                f64::min,
            )
    }

    /// Whether the segment `a`–`b` comes nearer the box than the distance whose square is
    /// `within2` (meeting it included), without a division or a square root. Rounding errs only
    /// for a segment within rounding of that distance: of its coordinates, and where the segment
    /// crosses the box's bounds, of the box's size.
    pub fn segment_nearer_than(&self, a: Point, b: Point, within2: f64) -> bool {
        if self.distance_squared(a) < within2 || self.distance_squared(b) < within2 {
            return true;
        }
        let d = b - a;
        let corners = self.corners();
        // Each corner's side of the segment's line, times the segment's length.
        let sides = corners.map(|c| {
            let v = c - a;
            v.x * d.y - v.y * d.x
        });
        // The segment meets the box when their bounds overlap and its line does not have every
        // corner strictly to one side (the separating axes of a segment and a box).
        let overlap = a.x.min(b.x) <= self.max.x
            && a.x.max(b.x) >= self.min.x
            && a.y.min(b.y) <= self.max.y
            && a.y.max(b.y) >= self.min.y;
        if overlap && sides.iter().any(|&s| s <= 0.0) && sides.iter().any(|&s| s >= 0.0) {
            return true;
        }
        // Apart, they are nearest at an end of the segment (tested first) or at a corner of the
        // box whose foot on the line falls between the ends.
        let dd = d.norm_squared();
        corners.iter().zip(sides).any(|(&c, side)| {
            let along = (c - a).dot(&d);
            along > 0.0 && along < dd && side * side < within2 * dd
        })
    }
}

/// How much further than asked [`Aabb::segment_clear`]'s division-free test wants a segment to
/// keep, px: far above the rounding of coordinates up to millions of px, far below anything
/// that matters.
const SEGMENT_CLEAR_HAIR: f64 = 1e-6;

/// Squared distance from `p` to the segment `a`–`b`.
pub fn point_segment_distance_squared(p: Point, a: Point, b: Point) -> f64 {
    let d = b - a;
    let len2 = d.norm_squared();
    let t = if len2 > 0.0 {
        ((p - a).dot(&d) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (a + d * t - p).norm_squared()
}

/// The unit vector at `deg` degrees counter-clockwise from +x.
pub fn unit(deg: f64) -> Vector {
    let (s, c) = deg.to_radians().sin_cos();
    Vector::new(c, s)
}

/// An angle in degrees brought into `[0, 360)`.
pub fn wrap_deg(deg: f64) -> f64 {
    // The common cases without `rem_euclid`'s `fmod` (a slow software remainder), giving its
    // bits: within one turn below or above [0, 360) the remainder is exact, so it is `deg`,
    // `deg + 360` as `rem_euclid` adds it, or `deg - 360` (exact by Sterbenz's lemma).
    let w = if (0.0..360.0).contains(&deg) {
        deg
    } else if -360.0 < deg && deg < 0.0 {
        deg + 360.0
    } else if (360.0..720.0).contains(&deg) {
        deg - 360.0
    } else {
        deg.rem_euclid(360.0)
    };
    // rem_euclid can round up to exactly 360.0 for tiny negative inputs.
    if w >= 360.0 {
        0.0
    } else {
        w
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The fast cases of `wrap_deg` give `rem_euclid`'s bits, edges, zeros' signs and NaN
    /// included.
    #[test]
    fn wrap_deg_is_rem_euclid_bit_for_bit() {
        let reference = |d: f64| {
            let w = d.rem_euclid(360.0);
            if w >= 360.0 {
                0.0
            } else {
                w
            }
        };
        let mut values = vec![
            0.0,
            -0.0,
            360.0,
            -360.0,
            720.0,
            -720.0,
            1e-300,
            -1e-300,
            359.99999999999994,
            -359.99999999999994,
            719.9999999999999,
            1e20,
            -1e20,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::MIN_POSITIVE,
            -f64::MIN_POSITIVE,
            5e-324,
            -5e-324,
        ];
        let mut x = 0x9e37_79b9_7f4a_7c15u64;
        for _ in 0..200_000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let u = (x >> 11) as f64 / (1u64 << 53) as f64;
            values.push(u * 2200.0 - 1100.0);
            values.push(f64::from_bits(x));
        }
        for d in values {
            assert_eq!(wrap_deg(d).to_bits(), reference(d).to_bits(), "{d:e}");
        }
    }

    fn inv(d: Vector) -> Vector {
        Vector::new(1.0 / d.x, 1.0 / d.y)
    }

    #[test]
    fn ray_hits_box_ahead_and_misses_behind() {
        let b = Aabb::from_corners(Point::new(10.0, -1.0), Point::new(12.0, 1.0));
        let o = Point::new(0.0, 0.0);
        assert_eq!(b.ray_hit(o, inv(Vector::new(1.0, 0.0)), 50.0), Some(10.0));
        assert_eq!(b.ray_hit(o, inv(Vector::new(-1.0, 0.0)), 50.0), None);
        assert_eq!(b.ray_hit(o, inv(Vector::new(1.0, 0.0)), 5.0), None);
        assert_eq!(
            b.ray_hit(Point::new(11.0, 0.0), inv(Vector::new(0.0, 1.0)), 5.0),
            Some(0.0)
        );
    }

    #[test]
    fn ray_along_a_face_touches_it() {
        let b = Aabb::from_corners(Point::new(10.0, 20.0), Point::new(12.0, 30.0));
        let up = inv(Vector::new(0.0, 1.0));
        assert_eq!(b.ray_hit(Point::new(10.0, 0.0), up, 50.0), Some(20.0));
        assert_eq!(b.ray_hit(Point::new(12.0, 0.0), up, 50.0), Some(20.0));
        assert_eq!(b.ray_hit(Point::new(12.5, 0.0), up, 50.0), None);
        let right = inv(Vector::new(1.0, 0.0));
        assert_eq!(b.ray_hit(Point::new(0.0, 30.0), right, 50.0), Some(10.0));
    }

    #[test]
    fn segment_distance_matches_hand_values() {
        let b = Aabb::from_corners(Point::new(0.0, 0.0), Point::new(2.0, 2.0));
        // Passing above the box at height 5.
        let d = b.segment_distance_squared(Point::new(-10.0, 5.0), Point::new(10.0, 5.0));
        assert!((d - 9.0).abs() < 1e-12);
        // Crossing it.
        let d = b.segment_distance_squared(Point::new(-10.0, 1.0), Point::new(10.0, 1.0));
        assert_eq!(d, 0.0);
        // Diagonal approach to a corner.
        let d = b.segment_distance_squared(Point::new(5.0, 5.0), Point::new(3.0, 3.0));
        assert!((d - 2.0).abs() < 1e-12);
        // A segment passing a corner diagonally: the corner is the closest point.
        let d = b.segment_distance_squared(Point::new(5.0, 0.0), Point::new(0.0, 5.0));
        assert!((d - 0.5).abs() < 1e-12, "{d}");
    }

    #[test]
    fn wrap_stays_in_range() {
        assert_eq!(wrap_deg(360.0), 0.0);
        assert_eq!(wrap_deg(-15.0), 345.0);
        assert!(wrap_deg(-1e-18) < 360.0);
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(4096))]

        /// The slab test that orders each axis's crossings by the ray's sign and compares with
        /// single instructions gives what the test with `f64::min`/`max` gave, to the bit (but
        /// for the sign of a zero), for rays along axes, from faces and corners, and anywhere.
        #[test]
        fn ray_hit_is_the_min_max_slab_test(
            min in (0.0f64..100.0, 0.0f64..100.0),
            size in (0.0f64..60.0, 0.0f64..60.0),
            o in (-40.0f64..200.0, -40.0f64..200.0),
            deg in 0.0f64..360.0,
            snap in 0u8..6,
            max_t in 0.0f64..300.0,
        ) {
            let b = Aabb::from_corners(
                Point::new(min.0, min.1),
                Point::new(min.0 + size.0, min.1 + size.1),
            );
            // Origins on a face's line or at a corner, rays along either axis.
            let o = match snap {
                0 => Point::new(b.min.x, o.1),
                1 => Point::new(o.0, b.max.y),
                2 => b.max,
                _ => Point::new(o.0, o.1),
            };
            let axes = [(1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0)];
            let dir = if snap % 2 == 0 {
                let (x, y) = axes[(deg / 90.0) as usize % 4];
                Vector::new(x, y)
            } else {
                unit(deg)
            };
            let inv_dir = inv(dir);
            let slab = |lo: f64, hi: f64, o: f64, inv: f64| {
                let (t1, t2) = ((lo - o) * inv, (hi - o) * inv);
                if t1.is_nan() || t2.is_nan() {
                    (f64::NEG_INFINITY, f64::INFINITY)
                } else {
                    (t1.min(t2), t1.max(t2))
                }
            };
            let (ex, xx) = slab(b.min.x, b.max.x, o.x, inv_dir.x);
            let (ey, xy) = slab(b.min.y, b.max.y, o.y, inv_dir.y);
            let enter = ex.max(ey).max(0.0);
            let reference = (enter <= xx.min(xy).min(max_t)).then_some(enter);
            let ours = b.ray_hit(o, inv_dir, max_t);
            let key = |t: Option<f64>| t.map(|t| if t == 0.0 { 0 } else { t.to_bits() });
            proptest::prop_assert_eq!(key(ours), key(reference), "{:?} {:?}", ours, reference);
        }

        /// Boxes against rays side by side give each ray's least `ray_hit`, to the bit.
        #[test]
        fn least_box_hits_is_the_least_ray_hit(
            boxes in proptest::collection::vec(
                ((0.0f64..200.0, 0.0f64..200.0), (0.0f64..40.0, 0.0f64..40.0)),
                0..12,
            ),
            o in (-20.0f64..220.0, -20.0f64..220.0),
            first in 0.0f64..360.0,
            rays in 1usize..40,
            max_t in 0.0f64..300.0,
        ) {
            let boxes: Vec<Aabb> = boxes
                .iter()
                .map(|&((x, y), (w, h))| {
                    Aabb::from_corners(Point::new(x, y), Point::new(x + w, y + h))
                })
                .collect();
            let origin = Point::new(o.0, o.1);
            let dirs: Vec<Vector> = (0..rays).map(|k| unit(first + k as f64 * 9.7)).collect();
            let ix: Vec<f64> = dirs.iter().map(|d| 1.0 / d.x).collect();
            let iy: Vec<f64> = dirs.iter().map(|d| 1.0 / d.y).collect();
            let sides: Vec<[f64; 4]> = boxes.iter().map(|b| b.sides_from(origin)).collect();
            let mut out = vec![f64::NAN; rays];
            least_box_hits(&sides, &ix, &iy, max_t, &mut out);
            for (k, d) in dirs.iter().enumerate() {
                let want = boxes
                    .iter()
                    .filter_map(|b| b.ray_hit(origin, inv(*d), max_t))
                    .fold(max_t, smaller);
                proptest::prop_assert_eq!(out[k].to_bits(), want.to_bits(), "ray {}", k);
            }
        }

        /// The division-free tests answer as the distance does, including segments that graze
        /// the grown box, lie along a face, or are a single point.
        #[test]
        fn segment_clear_is_segment_distance_at_least_radius(
            min in (0.0f64..100.0, 0.0f64..100.0),
            size in (0.0f64..60.0, 0.0f64..60.0),
            a in (-40.0f64..200.0, -40.0f64..200.0),
            d in (-80.0f64..80.0, -80.0f64..80.0),
            snap in 0u8..6,
            radius in 0.0f64..20.0,
            turn in 0.0f64..90.0,
            gap in -1e-2f64..1e-2,
        ) {
            let b = Aabb::from_corners(
                Point::new(min.0, min.1),
                Point::new(min.0 + size.0, min.1 + size.1),
            );
            let a = Point::new(a.0, a.1);
            // Segments ending on the grown box's edge, running along a face, or of no length.
            let end = match snap {
                0 => a + Vector::new(d.0, d.1),
                1 => Point::new(b.min.x - radius, a.y + d.1),
                2 => Point::new(a.x, b.max.y + radius),
                _ => a,
            };
            let a = if snap == 2 { Point::new(a.x + d.0, b.max.y + radius) } else { a };
            // Or slanted past the top right corner at `radius` from it, give or take rounding
            // (beside the box within the segment's bounding box), or a hair nearer or further.
            let (a, end) = if snap >= 4 {
                let out = unit(turn);
                let along = Vector::new(-out.y, out.x);
                let hair = if snap == 5 { gap } else { 0.0 };
                let touch = b.max + out * (radius + hair).max(0.0);
                (touch - along * d.0.abs(), touch + along * d.1.abs())
            } else {
                (a, end)
            };
            let (exact, r2) = (b.segment_distance_squared(a, end), radius * radius);
            proptest::prop_assert_eq!(b.segment_clear(a, end, radius), exact >= r2);
            // The nearness test without a division answers as the distance does, but for
            // rounding: never near when the distance is clearly more, always when clearly less.
            let (near, rounding) = (b.segment_nearer_than(a, end, r2), 1e-9 * (1.0 + r2));
            proptest::prop_assert!(!near || exact < r2 + rounding, "near at {}", exact);
            proptest::prop_assert!(near || exact >= r2 - rounding, "not near at {}", exact);
        }
    }
}
