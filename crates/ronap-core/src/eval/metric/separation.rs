//! `intrusion_ratio` and `min_separation_px`: how often, and how deep, another agent (a moving
//! obstacle or another robot) came within `metrics.discomfort_px` of the robot's body (CrowdNav's
//! discomfort distance).

use crate::config::ValidConfig;
use crate::eval::metric::{Column, End, Kind, Metric, View};

pub(super) const INTRUSION: Kind = Kind {
    column: Column {
        name: "intrusion_ratio",
        unit: "fraction of steps",
        decimals: 4,
        about: "share of steps ending with another agent within metrics.discomfort_px",
    },
    make: make_ratio,
};

pub(super) const MIN_SEPARATION: Kind = Kind {
    column: Column {
        name: "min_separation_px",
        unit: "px",
        decimals: 3,
        about: "least gap to another agent during the intruded steps",
    },
    make: make_separation,
};

fn make_ratio(config: &ValidConfig) -> Box<dyn Metric> {
    Box::new(Intrusions::new(config, false))
}

fn make_separation(config: &ValidConfig) -> Box<dyn Metric> {
    Box::new(Intrusions::new(config, true))
}

/// The intruded steps and the least gap during them; gives one or the other.
struct Intrusions {
    discomfort_px: f64,
    separation: bool,
    intruded: u32,
    least_px: f64,
}

impl Intrusions {
    fn new(config: &ValidConfig, separation: bool) -> Self {
        Self {
            discomfort_px: config.metrics.discomfort_px,
            separation,
            intruded: 0,
            least_px: f64::INFINITY,
        }
    }
}

impl Metric for Intrusions {
    fn observe(&mut self, view: &View<'_>) {
        if view.step == 0 {
            return;
        }
        let p = view.pose.position();
        let gap = view
            .others
            .iter()
            .map(|o| o.gap(p, view.radius_px))
            .fold(f64::INFINITY, f64::min);
        if gap < self.discomfort_px {
            self.intruded += 1;
            self.least_px = self.least_px.min(gap);
        }
    }

    fn value(&self, end: &End) -> Option<f64> {
        if self.separation {
            (self.intruded > 0).then_some(self.least_px)
        } else {
            Some(f64::from(self.intruded) / f64::from(end.steps.max(1)))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::metric::Other;
    use crate::eval::Outcome;
    use crate::geometry::{Point, Vector};
    use crate::sim::{Body, Pose};

    #[test]
    fn steps_within_the_discomfort_distance_are_counted() {
        let config = ValidConfig::default();
        let mut ratio = make_ratio(&config);
        let mut least = make_separation(&config);
        // A pedestrian of radius 5 at gaps 10, 3 and 1.5 from a robot of radius 5 (default
        // discomfort 4 px), then gone.
        let gaps: [Option<f64>; 4] = [Some(10.0), Some(3.0), Some(1.5), None];
        for (i, g) in gaps.iter().enumerate() {
            let others: Vec<Other> = g
                .iter()
                .map(|g| Other {
                    at: Point::new(10.0 + g, 0.0),
                    body: Body::Disc(5.0),
                    velocity: Vector::zeros(),
                })
                .collect();
            let view = View {
                step: i as u32 + 1,
                pose: Pose::new(0.0, 0.0, 0.0),
                radius_px: 5.0,
                velocity: Vector::zeros(),
                goal: Point::new(100.0, 0.0),
                others: &others,
            };
            ratio.observe(&view);
            least.observe(&view);
        }
        let end = End {
            outcome: Outcome::Timeout,
            steps: 4,
            arrived_at: None,
            path_length_px: 0.0,
        };
        assert_eq!(ratio.value(&end), Some(0.5));
        let l = least.value(&end).expect("intruded");
        assert!((l - 1.5).abs() < 1e-12, "{l}");
        let never = make_separation(&config);
        assert_eq!(never.value(&end), None);
    }
}
