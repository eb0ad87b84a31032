//! A moving obstacle's body, a disc or an axis-aligned box, and the geometry of its contacts:
//! gaps, sweeps against a robot or the still scene, and laser rays.

use crate::geometry::{point_segment_distance_squared, Aabb, Point, Vector};
use crate::scene::Scene;

/// A moving obstacle's body.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Body {
    /// A disc of this radius, px.
    Disc(f64),
    /// An axis-aligned box of these half extents, px.
    Box(Vector),
}

impl Body {
    /// Radius of the smallest disc round the body, px.
    pub fn bounding_radius(&self) -> f64 {
        match *self {
            Body::Disc(r) => r,
            Body::Box(h) => h.norm(),
        }
    }

    /// Half extents of the box the body covers (a disc's bounding box), px.
    pub fn half_extents(&self) -> Vector {
        match *self {
            Body::Disc(r) => Vector::new(r, r),
            Body::Box(h) => h,
        }
    }

    /// The box the body covers at `center` (a disc's bounding box).
    pub fn aabb(&self, center: Point) -> Aabb {
        let h = self.half_extents();
        Aabb::from_corners(center - h, center + h)
    }

    /// The gap between the body at `center` and a disc of `radius` at `p` (negative when they
    /// overlap, for discs).
    pub fn gap(&self, center: Point, p: Point, radius: f64) -> f64 {
        match *self {
            Body::Disc(r) => (p - center).norm() - r - radius,
            Body::Box(_) => self.aabb(center).distance_squared(p).sqrt() - radius,
        }
    }

    /// Whether the body moving from `a` to `b` comes closer than `radius` to the point `p`
    /// (a robot disc of `radius` at `p` would be touched).
    pub(super) fn sweep_touches(&self, a: Point, b: Point, p: Point, radius: f64) -> bool {
        match *self {
            Body::Disc(r) => point_segment_distance_squared(p, a, b) < (r + radius).powi(2),
            Body::Box(h) => {
                // The point against the box at rest, moving the other way.
                let rest = Aabb::from_corners(Point::from(-h), Point::from(h));
                let d = b - a;
                rest.segment_distance_squared(Point::from(p - a), Point::from(p - a - d))
                    < radius * radius
            }
        }
    }

    /// Whether the body fits at `center` in `scene` without touching a static obstacle.
    pub(super) fn clear_at(&self, scene: &Scene, center: Point) -> bool {
        let inside = scene.bounds();
        match *self {
            Body::Disc(r) => {
                let b = self.aabb(center);
                inside.contains(b.min) && inside.contains(b.max) && scene.disc_clear(center, r)
            }
            Body::Box(_) => scene.box_clear(self.aabb(center)),
        }
    }

    /// Whether the body can move in a straight line from `a` to `b` in `scene`.
    pub(super) fn sweep_clear(&self, scene: &Scene, a: Point, b: Point) -> bool {
        match *self {
            Body::Disc(r) => scene.bounds().inflated(-r).contains(b) && scene.sweep_clear(a, b, r),
            Body::Box(h) => scene.box_sweep_clear(a, b, h),
        }
    }

    /// Distance along the unit direction `dir` from `origin` to the body at `center`.
    #[inline]
    pub(crate) fn ray(&self, center: Point, origin: Point, dir: Vector, max: f64) -> Option<f64> {
        match *self {
            Body::Disc(r) => {
                let oc = center - origin;
                let along = oc.dot(&dir);
                let d2 = oc.norm_squared() - along * along;
                let r2 = r * r;
                if d2 > r2 {
                    return None;
                }
                let t = along - (r2 - d2).sqrt();
                let t = if oc.norm_squared() <= r2 { 0.0 } else { t };
                (t >= 0.0 && t <= max).then_some(t)
            }
            Body::Box(_) => {
                let inv = Vector::new(1.0 / dir.x, 1.0 / dir.y);
                self.aabb(center).ray_hit(origin, inv, max)
            }
        }
    }
}
