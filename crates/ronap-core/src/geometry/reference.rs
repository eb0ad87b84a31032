//! The scene as a parry2d compound shape: a slow, general reference for the box queries.
//!
//! `crate::scene::Scene` answers ray casts and sweeps with its own box index because parry2d's
//! general queries cost several times more per ray. This module builds the same obstacles as parry2d
//! cuboids so tests (and benchmarks) can hold the fast path to parry2d's answers.

use crate::geometry::{Aabb, Point, Vector};
use parry2d_f64::math::{Isometry, Point as PPoint, Vector as PVector};
use parry2d_f64::query::{Ray, RayCast};
use parry2d_f64::shape::{Ball, Capsule, Compound, Cuboid, SharedShape};

/// A scene's obstacles as one parry2d compound of cuboids.
pub struct ParryScene {
    compound: Compound,
}

impl ParryScene {
    /// The compound of a scene's obstacle `boxes` (`Scene::boxes`); `None` when there are none.
    pub fn new(boxes: &[Aabb]) -> Option<Self> {
        let shapes: Vec<(Isometry<f64>, SharedShape)> = boxes
            .iter()
            .map(|b| {
                let half = b.extents() / 2.0;
                let centre = b.min + half;
                (
                    Isometry::translation(centre.x, centre.y),
                    SharedShape::new(Cuboid::new(PVector::new(half.x, half.y))),
                )
            })
            .collect();
        (!shapes.is_empty()).then(|| Self {
            compound: Compound::new(shapes),
        })
    }

    /// Distance along the unit direction `dir` from `origin` to the first obstacle within `max_px`.
    pub fn cast_ray(&self, origin: Point, dir: Vector, max_px: f64) -> Option<f64> {
        let ray = Ray::new(PPoint::new(origin.x, origin.y), PVector::new(dir.x, dir.y));
        self.compound
            .cast_ray(&Isometry::identity(), &ray, max_px, true)
    }

    /// Whether a disc of `radius` moving from `a` to `b` stays clear of every obstacle.
    pub fn sweep_clear(&self, a: Point, b: Point, radius: f64) -> bool {
        let identity = Isometry::identity();
        let hit = if a == b {
            let ball = Ball::new(radius);
            parry2d_f64::query::intersection_test(
                &Isometry::translation(a.x, a.y),
                &ball,
                &identity,
                &self.compound,
            )
        } else {
            let capsule = Capsule::new(PPoint::new(a.x, a.y), PPoint::new(b.x, b.y), radius);
            parry2d_f64::query::intersection_test(&identity, &capsule, &identity, &self.compound)
        };
        !hit.unwrap_or(true)
    }
}
