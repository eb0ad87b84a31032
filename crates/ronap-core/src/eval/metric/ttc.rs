//! `ttc_min`: the least time to collision with another agent under constant velocity, steps
//! (bodies as their bounding discs; 0 while touching).

use crate::config::ValidConfig;
use crate::eval::metric::{Column, End, Kind, Metric, View};
use crate::geometry::Vector;

pub(super) const KIND: Kind = Kind {
    column: Column {
        name: "ttc_min",
        unit: "steps",
        decimals: 3,
        about: "least time to collision with another agent at constant velocities",
    },
    make,
};

fn make(_: &ValidConfig) -> Box<dyn Metric> {
    Box::new(LeastTtc(f64::INFINITY))
}

struct LeastTtc(f64);

/// When two discs `d` apart (the other's centre less this one's), closing at `w` (the other's
/// velocity less this one's), first touch with summed radius `r`: 0 when they touch, `None` when
/// they never will.
pub(super) fn time_to_collision(d: Vector, w: Vector, r: f64) -> Option<f64> {
    let c = d.norm_squared() - r * r;
    if c <= 0.0 {
        return Some(0.0);
    }
    let a = w.norm_squared();
    let b = d.dot(&w);
    if a == 0.0 || b >= 0.0 {
        return None;
    }
    // |d + w t|^2 = r^2: a t^2 + 2 b t + c = 0, the smaller root (positive, as b < 0 < c).
    let disc = b * b - a * c;
    (disc >= 0.0).then(|| c / (-b + disc.sqrt()))
}

impl Metric for LeastTtc {
    fn observe(&mut self, view: &View<'_>) {
        if view.step == 0 {
            return;
        }
        let p = view.pose.position();
        for o in view.others {
            let r = view.radius_px + o.body.bounding_radius();
            if let Some(t) = time_to_collision(o.at - p, o.velocity - view.velocity, r) {
                self.0 = self.0.min(t);
            }
        }
    }

    fn value(&self, _: &End) -> Option<f64> {
        self.0.is_finite().then_some(self.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn head_on_discs_meet_when_their_gap_closes() {
        // 20 px apart centre to centre, radii summing to 10, closing at 2 px a step: 5 steps.
        let t = time_to_collision(Vector::new(20.0, 0.0), Vector::new(-2.0, 0.0), 10.0);
        assert!((t.expect("meets") - 5.0).abs() < 1e-12);
        // Moving apart, or side by side at the same speed: never.
        assert_eq!(
            time_to_collision(Vector::new(20.0, 0.0), Vector::new(2.0, 0.0), 10.0),
            None
        );
        assert_eq!(
            time_to_collision(Vector::new(20.0, 0.0), Vector::zeros(), 10.0),
            None
        );
        // Passing 15 px off a 10 px contact distance: never; touching: now.
        assert_eq!(
            time_to_collision(Vector::new(20.0, 15.0), Vector::new(-1.0, 0.0), 10.0),
            None
        );
        assert_eq!(
            time_to_collision(Vector::new(5.0, 0.0), Vector::new(1.0, 0.0), 10.0),
            Some(0.0)
        );
        // An oblique course, against the quadratic's root found by bisection.
        let (d, w, r) = (Vector::new(30.0, 8.0), Vector::new(-3.0, -0.5), 9.0);
        let t = time_to_collision(d, w, r).expect("meets");
        let (mut lo, mut hi) = (0.0f64, t * 2.0);
        for _ in 0..200 {
            let mid = (lo + hi) / 2.0;
            if (d + w * mid).norm() > r {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        assert!((t - lo).abs() < 1e-9, "{t} vs {lo}");
    }
}
