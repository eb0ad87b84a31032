//! `path_irregularity`: the robot's summed absolute heading change beyond the one turn a straight
//! line to its goal needs (from its start heading to the bearing of its first goal), per px
//! driven, degrees per px.

use crate::config::ValidConfig;
use crate::eval::metric::{Column, End, Kind, Metric, View};
use crate::geometry::wrap_deg;

pub(super) const KIND: Kind = Kind {
    column: Column {
        name: "path_irregularity",
        unit: "deg/px",
        decimals: 4,
        about: "summed absolute heading change beyond a straight line's, per px driven",
    },
    make,
};

fn make(_: &ValidConfig) -> Box<dyn Metric> {
    Box::new(Irregularity::default())
}

#[derive(Default)]
struct Irregularity {
    /// The last heading seen, degrees.
    heading: Option<f64>,
    /// Summed absolute heading change, degrees.
    turned_deg: f64,
    /// The straight line's turn: from the start heading to the first goal's bearing, degrees.
    needed_deg: f64,
}

/// The signed turn from `from` to `to`, degrees in [-180, 180).
fn turn_deg(from: f64, to: f64) -> f64 {
    wrap_deg(to - from + 180.0) - 180.0
}

impl Metric for Irregularity {
    fn observe(&mut self, view: &View<'_>) {
        let z = view.pose.z_deg;
        match self.heading {
            None => {
                let to_goal = view.goal - view.pose.position();
                if to_goal.norm_squared() > 0.0 {
                    let bearing = to_goal.y.atan2(to_goal.x).to_degrees();
                    self.needed_deg = turn_deg(z, bearing).abs();
                }
            }
            Some(last) => self.turned_deg += turn_deg(last, z).abs(),
        }
        self.heading = Some(z);
    }

    fn value(&self, end: &End) -> Option<f64> {
        (end.path_length_px > 0.0)
            .then(|| (self.turned_deg - self.needed_deg).max(0.0) / end.path_length_px)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::Outcome;
    use crate::geometry::{Point, Vector};
    use crate::sim::Pose;

    fn run(headings: &[f64], path_length_px: f64) -> Option<f64> {
        let mut m = make(&ValidConfig::default());
        for (i, &z) in headings.iter().enumerate() {
            m.observe(&View {
                step: i as u32,
                pose: Pose::new(0.0, 0.0, z),
                radius_px: 5.0,
                velocity: Vector::zeros(),
                // The goal lies straight up (bearing 90 degrees).
                goal: Point::new(0.0, 100.0),
                others: &[],
            });
        }
        m.value(&End {
            outcome: Outcome::Success,
            steps: headings.len() as u32,
            arrived_at: None,
            path_length_px,
        })
    }

    #[test]
    fn only_turning_beyond_the_straight_line_counts() {
        // Turning once to face the goal, then straight: regular.
        assert_eq!(run(&[0.0, 45.0, 90.0, 90.0], 100.0), Some(0.0));
        // Weaving 30 degrees each way over 100 px after facing it: 120 degrees too many.
        let w = run(&[90.0, 120.0, 90.0, 60.0, 90.0], 100.0).expect("drove");
        assert!((w - 1.2).abs() < 1e-12, "{w}");
        // Across 0/360 the turn is the short way round.
        let w = run(&[90.0, 350.0, 10.0], 10.0).expect("drove");
        assert!((w - (100.0 + 20.0) / 10.0).abs() < 1e-9, "{w}");
        // No distance driven: none.
        assert_eq!(run(&[90.0, 100.0], 0.0), None);
    }
}
