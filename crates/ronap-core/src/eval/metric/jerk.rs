//! `jerk`: the mean absolute change of the robot's acceleration from step to step, px/step^3
//! (smoothness: a robot that keeps an even pace has none).

use crate::config::ValidConfig;
use crate::eval::metric::{Column, End, Kind, Metric, View};
use crate::geometry::Vector;

pub(super) const KIND: Kind = Kind {
    column: Column {
        name: "jerk",
        unit: "px/step^3",
        decimals: 4,
        about: "mean absolute change of acceleration per step",
    },
    make,
};

fn make(_: &ValidConfig) -> Box<dyn Metric> {
    Box::new(Jerk::default())
}

#[derive(Default)]
struct Jerk {
    velocity: Option<Vector>,
    acceleration: Option<Vector>,
    sum: f64,
    count: u32,
}

impl Metric for Jerk {
    fn observe(&mut self, view: &View<'_>) {
        if view.step == 0 {
            return;
        }
        let v = view.velocity;
        let a = self.velocity.map(|last| v - last);
        if let (Some(a), Some(last)) = (a, self.acceleration) {
            self.sum += (a - last).norm();
            self.count += 1;
        }
        self.velocity = Some(v);
        self.acceleration = a;
    }

    fn value(&self, _: &End) -> Option<f64> {
        (self.count > 0).then(|| self.sum / f64::from(self.count))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::Outcome;
    use crate::geometry::Point;
    use crate::sim::Pose;

    fn run(velocities: &[[f64; 2]]) -> Option<f64> {
        let mut m = make(&ValidConfig::default());
        for (i, v) in velocities.iter().enumerate() {
            m.observe(&View {
                step: i as u32 + 1,
                pose: Pose::new(0.0, 0.0, 0.0),
                radius_px: 5.0,
                velocity: Vector::new(v[0], v[1]),
                goal: Point::new(0.0, 100.0),
                others: &[],
            });
        }
        m.value(&End {
            outcome: Outcome::Timeout,
            steps: velocities.len() as u32,
            arrived_at: None,
            path_length_px: 1.0,
        })
    }

    #[test]
    fn an_even_pace_has_no_jerk() {
        assert_eq!(run(&[[5.0, 0.0]; 6]), Some(0.0));
        // Constant acceleration: none either.
        assert_eq!(run(&[[1.0, 0.0], [2.0, 0.0], [3.0, 0.0]]), Some(0.0));
        // Stop and go: speeds 5, 0, 5, 0 give accelerations -5, 5, -5 and jerks 10, 10.
        assert_eq!(
            run(&[[5.0, 0.0], [0.0, 0.0], [5.0, 0.0], [0.0, 0.0]]),
            Some(10.0)
        );
        // Two steps give no jerk at all.
        assert_eq!(run(&[[5.0, 0.0], [0.0, 0.0]]), None);
    }
}
