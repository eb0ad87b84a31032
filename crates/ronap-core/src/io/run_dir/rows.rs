//! The rows of `episodes.csv` and `timing.csv`: their columns, a lone robot's row layout, and
//! writers of whole files from records.

use crate::config::ValidConfig;
use crate::eval::metric;
use crate::eval::EpisodeRecord;
use crate::geometry::Point;
use crate::sim::Pose;

/// Columns of `episodes.csv`.
pub const EPISODE_COLUMNS: [&str; 14] = joined(
    [
        "seed",
        "outcome",
        "steps",
        "collisions",
        "path_length_px",
        "shortest_px",
        "spl",
        "return",
    ],
    START_GOAL_COLUMNS,
);

/// The columns of [`start_goal_cells`], in `episodes.csv` and `robots.csv`.
pub(crate) const START_GOAL_COLUMNS: [&str; 6] = [
    "start_x",
    "start_y",
    "start_heading_deg",
    "goal_x",
    "goal_y",
    "reason",
];

/// The columns `a` then `b` (`N` is their count together).
pub(crate) const fn joined<const A: usize, const B: usize, const N: usize>(
    a: [&'static str; A],
    b: [&'static str; B],
) -> [&'static str; N] {
    assert!(A + B == N, "N must be A + B");
    let mut out = [""; N];
    let mut i = 0;
    while i < A {
        out[i] = a[i];
        i += 1;
    }
    while i < N {
        out[i] = b[i - A];
        i += 1;
    }
    out
}

/// Columns `episodes.csv` gains when the episodes have moving obstacles.
pub const DYNAMIC_COLUMNS: [&str; 3] = [
    "dynamic_collisions",
    "min_clearance_px",
    "near_moving_fraction",
];

/// What a lone robot's rows hold beyond `EPISODE_COLUMNS`: the moving-obstacle columns when
/// the episodes have moving obstacles, then a column per metric the configuration asks for.
#[derive(Clone, Copy, Debug, Default)]
pub struct Layout {
    /// The episodes have moving obstacles (`DYNAMIC_COLUMNS`).
    pub dynamic: bool,
    /// The metrics asked for, in column order.
    pub metrics: &'static [metric::Kind],
}

impl Layout {
    /// The rows of runs under `config`.
    pub fn of(config: &ValidConfig) -> Self {
        Self {
            dynamic: !config.moving.is_empty(),
            metrics: metric::kinds(config),
        }
    }
}

/// A row's start pose, goal and reason cells (`start_x` .. `reason`), as `episodes.csv` and
/// `robots.csv` write them.
pub(crate) fn start_goal_cells(start: Pose, goal: Point, reason: Option<&str>) -> [String; 6] {
    [
        format!("{:.3}", start.x),
        format!("{:.3}", start.y),
        format!("{:.3}", start.z_deg),
        format!("{:.3}", goal.x),
        format!("{:.3}", goal.y),
        reason.unwrap_or_default().to_string(),
    ]
}

/// The `episodes.csv` row of `r`, laid out as `layout` says.
pub fn episode_row(r: &EpisodeRecord, layout: Layout) -> Vec<String> {
    let mut row = vec![
        r.seed.to_string(),
        r.outcome.name().to_string(),
        r.steps.to_string(),
        r.collisions.to_string(),
        format!("{:.3}", r.path_length_px),
        r.shortest_px.map_or(String::new(), |l| format!("{l:.3}")),
        format!("{:.4}", r.spl),
        format!("{:.4}", r.total_reward),
    ];
    row.extend(start_goal_cells(r.start, r.goal, r.reason.as_deref()));
    if layout.dynamic {
        match r.dynamic {
            Some(d) => row.extend([
                d.collisions.to_string(),
                if d.min_clearance_px.is_finite() {
                    format!("{:.3}", d.min_clearance_px)
                } else {
                    String::new()
                },
                format!("{:.4}", d.near_steps as f64 / r.steps.max(1) as f64),
            ]),
            None => row.extend([String::new(), String::new(), String::new()]),
        }
    }
    row.extend(metric_cells(layout.metrics, &r.metrics));
    row
}

/// The cells of metric `values` (in the order of `kinds`), as `episodes.csv` and `robots.csv`
/// write them.
pub fn metric_cells<'a>(
    kinds: &'a [metric::Kind],
    values: &'a [Option<f64>],
) -> impl Iterator<Item = String> + 'a {
    kinds
        .iter()
        .enumerate()
        .map(|(i, k)| metric::cell(&k.column, values.get(i).copied().flatten()))
}

/// The `episodes.csv` header, laid out as `layout` says.
pub fn episode_header(layout: Layout) -> Vec<&'static str> {
    let mut header = EPISODE_COLUMNS.to_vec();
    if layout.dynamic {
        header.extend(DYNAMIC_COLUMNS);
    }
    header.extend(metric::columns(layout.metrics).map(|c| c.name));
    header
}

/// Columns of `timing.csv`.
pub const TIMING_COLUMNS: [&str; 2] = ["seed", "wall_time_ms"];

/// The `timing.csv` row of an episode of `seed` that took `wall_time_s`.
pub fn timing_row(seed: u64, wall_time_s: f64) -> [String; 2] {
    [seed.to_string(), format!("{:.3}", wall_time_s * 1000.0)]
}
