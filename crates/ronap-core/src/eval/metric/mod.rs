//! The seam for an episode metric (docs/model.md "Crowd metrics"): a [`Metric`] watches one robot
//! after every step and gives one value at the end of its episode. Each built-in is one file: its
//! [`Kind`] (column name, unit, decimals, meaning) and its per-step update. The writers add a
//! column per metric to `episodes.csv` (a team's `robots.csv`) and the figures file, and the
//! summary a mean per metric, from the [`Kind`] alone: a new metric is its file and its line in
//! [`CROWD`].
//!
//! Metrics are measured by the evaluator (its `Gauges`), never in the stepping loop of a bench or
//! a learner, so a run that asks for none pays nothing.

mod gauges;
mod irregularity;
mod jerk;
mod separation;
mod time_to_goal;
mod ttc;

pub(crate) use gauges::Gauges;

use crate::config::ValidConfig;
use crate::eval::Outcome;
use crate::geometry::{Point, Vector};
use crate::sim::{Body, Pose};

/// What the files call a metric and how they write it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Column {
    /// The column of `episodes.csv` and `robots.csv`, and the key of its mean in `summary.json`.
    pub name: &'static str,
    /// Its unit.
    pub unit: &'static str,
    /// Decimals written in `episodes.csv`.
    pub decimals: usize,
    /// What it measures, in a line.
    pub about: &'static str,
}

/// A kind of metric: its column, and a fresh gauge of it for an episode under a configuration.
#[derive(Clone, Copy)]
pub struct Kind {
    /// Its column.
    pub column: Column,
    /// A gauge for one robot's episode under a configuration.
    pub make: fn(&ValidConfig) -> Box<dyn Metric>,
}

impl std::fmt::Debug for Kind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_tuple("Kind").field(&self.column.name).finish()
    }
}

/// Another agent as a metric sees it after a step: a moving obstacle or another robot.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Other {
    /// Its centre, px.
    pub at: Point,
    /// Its body (a robot is a disc).
    pub body: Body,
    /// Its displacement over the step just taken, px per step (zero at the start or when it
    /// just appeared).
    pub velocity: Vector,
}

impl Other {
    /// The gap between it and a disc of `radius` at `p`, px (negative when they overlap).
    pub fn gap(&self, p: Point, radius: f64) -> f64 {
        self.body.gap(self.at, p, radius)
    }
}

/// One robot after a step (or at its start), as a metric sees it.
#[derive(Clone, Copy, Debug)]
pub struct View<'a> {
    /// The robot's steps so far (0: its start).
    pub step: u32,
    /// Its pose.
    pub pose: Pose,
    /// Its radius, px.
    pub radius_px: f64,
    /// Its displacement over the step just taken, px per step (zero at the start).
    pub velocity: Vector,
    /// Its current goal.
    pub goal: Point,
    /// Every other agent present: moving obstacles, then the other robots.
    pub others: &'a [Other],
}

/// How a robot's episode ended, for a metric's value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct End {
    /// Its outcome.
    pub outcome: Outcome,
    /// Steps it took.
    pub steps: u32,
    /// The step at which it reached its (last) goal.
    pub arrived_at: Option<u32>,
    /// Distance it drove, px.
    pub path_length_px: f64,
}

/// One metric of one robot's episode: it sees the robot after every step, then gives a value.
pub trait Metric: Send {
    /// Sees the robot after a step, or at its start (`view.step == 0`).
    fn observe(&mut self, view: &View<'_>);

    /// The value of the finished episode; `None` when it has none (an empty cell, left out of
    /// the mean).
    fn value(&self, end: &End) -> Option<f64>;
}

/// The crowd metrics (docs/model.md "Crowd metrics"), in column order.
pub static CROWD: [Kind; 6] = [
    time_to_goal::KIND,
    separation::INTRUSION,
    separation::MIN_SEPARATION,
    ttc::KIND,
    irregularity::KIND,
    jerk::KIND,
];

/// The metrics `config` asks for beyond the standard columns, in column order.
pub fn kinds(config: &ValidConfig) -> &'static [Kind] {
    if config.metrics.crowd {
        &CROWD
    } else {
        &[]
    }
}

/// The columns of `kinds`.
pub fn columns(kinds: &[Kind]) -> impl Iterator<Item = Column> + '_ {
    kinds.iter().map(|k| k.column)
}

/// `value` as `episodes.csv` writes a metric of `column` (empty for none).
pub fn cell(column: &Column, value: Option<f64>) -> String {
    match value {
        Some(v) if v.is_finite() => format!("{v:.prec$}", prec = column.decimals),
        _ => String::new(),
    }
}

/// The mean of one metric over a run's episodes.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct MetricMean {
    /// The metric's column name.
    pub name: String,
    /// Its unit.
    pub unit: String,
    /// Mean over the episodes that had a value.
    pub mean: f64,
    /// Episodes that had a value.
    pub episodes: usize,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_crowd_metric_has_its_own_column() {
        let names: std::collections::BTreeSet<_> = CROWD.iter().map(|k| k.column.name).collect();
        assert_eq!(names.len(), CROWD.len());
        assert!(kinds(&ValidConfig::default()).is_empty());
        let mut c = crate::SimConfig::default();
        c.metrics.crowd = true;
        let c = c.validate().expect("valid");
        assert_eq!(kinds(&c).len(), 6);
        assert_eq!(cell(&CROWD[1].column, Some(0.25)), "0.2500");
        assert_eq!(cell(&CROWD[1].column, None), "");
        assert_eq!(cell(&CROWD[3].column, Some(f64::INFINITY)), "");
    }
}
