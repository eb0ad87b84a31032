//! Static obstacles that are not axis-aligned boxes: discs and convex polygons, queried through
//! parry2d's shapes (ray casts, point and segment distances).

use crate::geometry::{Aabb, Point, Vector};
use parry2d_f64::math::{Isometry, Point as PPoint, Vector as PVector};
use parry2d_f64::query::{PointQuery, Ray, RayCast};
use parry2d_f64::shape::{Ball, ConvexPolygon, Segment};

/// The geometry of a [`Shape`].
#[derive(Clone, Debug)]
enum Kind {
    Disc { center: Point, ball: Ball },
    Polygon(ConvexPolygon),
}

/// A disc or convex polygon in scene px, with its bounding box.
#[derive(Clone, Debug)]
pub struct Shape {
    kind: Kind,
    aabb: Aabb,
}

fn pp(p: Point) -> PPoint<f64> {
    PPoint::new(p.x, p.y)
}

impl Shape {
    /// A disc of `radius` at `center`.
    pub fn disc(center: Point, radius: f64) -> Self {
        let r = Vector::new(radius, radius);
        Self {
            kind: Kind::Disc {
                center,
                ball: Ball::new(radius),
            },
            aabb: Aabb::from_corners(center - r, center + r),
        }
    }

    /// The convex polygon with corners `points` (in order either way round); `None` when they
    /// do not make one with an area.
    pub fn polygon(points: &[Point]) -> Option<Self> {
        let corners: Vec<PPoint<f64>> = points.iter().map(|&p| pp(p)).collect();
        let polygon = ConvexPolygon::from_convex_hull(&corners)?;
        let (lo, hi) = polygon.points().iter().fold(
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
        Some(Self {
            kind: Kind::Polygon(polygon),
            aabb: Aabb::from_corners(lo, hi),
        })
    }

    /// The bounding box.
    pub fn aabb(&self) -> Aabb {
        self.aabb
    }

    /// For a disc, its centre and radius.
    pub fn as_disc(&self) -> Option<(Point, f64)> {
        match &self.kind {
            Kind::Disc { center, ball } => Some((*center, ball.radius)),
            Kind::Polygon(_) => None,
        }
    }

    /// For a polygon, its corners (counter-clockwise).
    pub fn corners(&self) -> Vec<Point> {
        match &self.kind {
            Kind::Disc { .. } => Vec::new(),
            Kind::Polygon(p) => p.points().iter().map(|p| Point::new(p.x, p.y)).collect(),
        }
    }

    /// Distance along the unit direction `dir` from `origin` to the shape, within `max_px`
    /// (`Some(0.0)` from inside).
    pub fn cast_ray(&self, origin: Point, dir: Vector, max_px: f64) -> Option<f64> {
        let ray = Ray::new(pp(origin), PVector::new(dir.x, dir.y));
        match &self.kind {
            Kind::Disc { center, ball } => ball.cast_ray(
                &Isometry::translation(center.x, center.y),
                &ray,
                max_px,
                true,
            ),
            Kind::Polygon(p) => p.cast_ray(&Isometry::identity(), &ray, max_px, true),
        }
    }

    /// Distance from `p` to the shape, 0 inside.
    pub fn distance(&self, p: Point) -> f64 {
        match &self.kind {
            Kind::Disc { center, ball } => ((p - center).norm() - ball.radius).max(0.0),
            Kind::Polygon(poly) => poly.distance_to_point(&Isometry::identity(), &pp(p), true),
        }
    }

    /// The point of the shape nearest `p` (`p` itself inside).
    pub fn nearest_point(&self, p: Point) -> Point {
        match &self.kind {
            Kind::Disc { center, ball } => {
                let away = p - center;
                let d = away.norm();
                if d <= ball.radius {
                    p
                } else {
                    center + away * (ball.radius / d)
                }
            }
            Kind::Polygon(poly) => {
                let q = poly.project_point(&Isometry::identity(), &pp(p), true);
                Point::new(q.point.x, q.point.y)
            }
        }
    }

    /// Distance between the segment `a`–`b` and the shape, 0 when they meet.
    pub fn segment_distance(&self, a: Point, b: Point) -> f64 {
        match &self.kind {
            Kind::Disc { center, ball } => {
                (crate::geometry::point_segment_distance_squared(*center, a, b).sqrt()
                    - ball.radius)
                    .max(0.0)
            }
            Kind::Polygon(poly) => {
                if a == b {
                    return self.distance(a);
                }
                let segment = Segment::new(pp(a), pp(b));
                parry2d_f64::query::distance(
                    &Isometry::identity(),
                    &segment,
                    &Isometry::identity(),
                    poly,
                )
                .unwrap_or(0.0)
            }
        }
    }
}

impl Shape {
    /// Distance between the shape and the convex hull of `corners` (0 when they meet).
    pub fn hull_distance(&self, corners: &[Point]) -> f64 {
        let points: Vec<PPoint<f64>> = corners.iter().map(|&p| pp(p)).collect();
        let Some(hull) = ConvexPolygon::from_convex_hull(&points) else {
            return 0.0;
        };
        let id = Isometry::identity();
        let d = match &self.kind {
            Kind::Disc { center, ball } => parry2d_f64::query::distance(
                &Isometry::translation(center.x, center.y),
                ball,
                &id,
                &hull,
            ),
            Kind::Polygon(poly) => parry2d_f64::query::distance(&id, poly, &id, &hull),
        };
        d.unwrap_or(0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::unit;

    #[test]
    fn disc_and_polygon_answer_like_hand_values() {
        let d = Shape::disc(Point::new(50.0, 0.0), 10.0);
        assert_eq!(d.cast_ray(Point::origin(), unit(0.0), 100.0), Some(40.0));
        assert_eq!(d.cast_ray(Point::origin(), unit(180.0), 100.0), None);
        assert!((d.distance(Point::new(50.0, 30.0)) - 20.0).abs() < 1e-12);
        assert!(
            (d.segment_distance(Point::new(0.0, 15.0), Point::new(100.0, 15.0)) - 5.0).abs()
                < 1e-12
        );
        let square = Shape::polygon(&[
            Point::new(10.0, -5.0),
            Point::new(20.0, -5.0),
            Point::new(20.0, 5.0),
            Point::new(10.0, 5.0),
        ])
        .unwrap();
        let t = square.cast_ray(Point::origin(), unit(0.0), 100.0).unwrap();
        assert!((t - 10.0).abs() < 1e-9);
        assert!((square.distance(Point::new(0.0, 0.0)) - 10.0).abs() < 1e-9);
        assert_eq!(square.distance(Point::new(15.0, 0.0)), 0.0);
        let through = square.segment_distance(Point::new(0.0, 0.0), Point::new(30.0, 0.0));
        assert!(through.abs() < 1e-9);
        assert!(Shape::polygon(&[Point::origin(), Point::new(1.0, 1.0)]).is_none());
    }
}
