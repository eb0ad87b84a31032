//! `time_to_goal`: the step at which the robot reached its (last) goal, on success.

use crate::config::ValidConfig;
use crate::eval::metric::{Column, End, Kind, Metric, View};
use crate::eval::Outcome;

pub(super) const KIND: Kind = Kind {
    column: Column {
        name: "time_to_goal",
        unit: "steps",
        decimals: 0,
        about: "the step the robot reached its goal (successful episodes only)",
    },
    make,
};

fn make(_: &ValidConfig) -> Box<dyn Metric> {
    Box::new(TimeToGoal)
}

struct TimeToGoal;

impl Metric for TimeToGoal {
    fn observe(&mut self, _: &View<'_>) {}

    fn value(&self, end: &End) -> Option<f64> {
        (end.outcome == Outcome::Success)
            .then_some(end.arrived_at.unwrap_or(end.steps))
            .map(f64::from)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_a_success_has_a_time_to_goal() {
        let m = make(&ValidConfig::default());
        let end = |outcome, arrived_at| End {
            outcome,
            steps: 40,
            arrived_at,
            path_length_px: 100.0,
        };
        assert_eq!(m.value(&end(Outcome::Success, Some(31))), Some(31.0));
        assert_eq!(m.value(&end(Outcome::Success, None)), Some(40.0));
        assert_eq!(m.value(&end(Outcome::Timeout, None)), None);
    }
}
