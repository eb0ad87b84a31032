//! How hard an episode's task is, from its scene alone (computed once per seed, whatever the
//! policies): how far the shortest path strays from the straight line, the narrowest passage it
//! goes through, and how often it turns; and results broken down into bins of each.

use crate::geometry::{Point, Vector};
use crate::plan::shortest_path;
use crate::sim::World;
use serde::Serialize;

/// A path corner counts as a turn when the heading changes by more than this, degrees.
pub const TURN_DEG: f64 = 20.0;

/// Spacing of the samples along the shortest path where the passage width is measured, px.
const SAMPLE_PX: f64 = 2.0;

/// The scene figures of one seed's task.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Difficulty {
    /// The seed.
    pub seed: u64,
    /// Straight-line distance from start to goal, px.
    pub straight_px: f64,
    /// Length of the shortest collision-free path, px (`None`: the goal cannot be reached).
    pub geodesic_px: Option<f64>,
    /// `geodesic_px / straight_px` (1: a straight run).
    pub ratio: Option<f64>,
    /// The narrowest free width across the shortest path (the sum of the free distances to
    /// either side, perpendicular to the path), px.
    pub narrowest_gap_px: Option<f64>,
    /// Corners of the shortest path where it turns by more than `TURN_DEG` (20 degrees).
    pub turns: Option<u32>,
}

impl Difficulty {
    /// The figures of the task of `seed` in `world` (its start and goal as the episode draws
    /// them); `None` when no episode can start there.
    pub fn of(world: &World, seed: u64) -> Option<Self> {
        let episode = world.episode(seed).ok()?;
        Some(Self::of_task(
            world,
            seed,
            episode.start().position(),
            episode.goal(),
        ))
    }

    /// The figures of team episode `seed` of `evaluator`: its hardest robot's in each (the
    /// largest ratio, the narrowest gap, the most turns), and the straight and shortest lengths
    /// summed over its robots, each robot's task from its start to its first goal. A team is as
    /// hard as its hardest task, since it succeeds only when every robot arrives; one robot
    /// without a path leaves the team's path figures empty. `None` when the team cannot be
    /// placed.
    pub fn of_team(evaluator: &crate::eval::Evaluator, seed: u64) -> Option<Self> {
        let worlds = evaluator.worlds().team(seed);
        let team = crate::sim::Team::new(evaluator.config(), &worlds, seed).ok()?;
        let tasks: Vec<Self> = team
            .robots()
            .iter()
            .zip(crate::run::robot_worlds(evaluator.config(), &worlds))
            .map(|(r, w)| Self::of_task(&w, seed, r.start().position(), r.goal()))
            .collect();
        let all = |f: fn(&Self) -> Option<f64>| tasks.iter().map(f).collect::<Option<Vec<f64>>>();
        let most = |v: Vec<f64>| v.into_iter().fold(f64::NEG_INFINITY, f64::max);
        Some(Self {
            seed,
            straight_px: tasks.iter().map(|t| t.straight_px).sum(),
            geodesic_px: all(|t| t.geodesic_px).map(|v| v.iter().sum()),
            ratio: all(|t| t.ratio).map(most),
            narrowest_gap_px: all(|t| t.narrowest_gap_px)
                .map(|v| v.into_iter().fold(f64::INFINITY, f64::min)),
            turns: all(|t| t.turns.map(f64::from)).map(|v| most(v) as u32),
        })
    }

    /// The figures of the task from `start` to `goal` in `world`.
    fn of_task(world: &World, seed: u64, start: Point, goal: Point) -> Self {
        let straight_px = (goal - start).norm();
        let radius = world.config().robot.radius_px;
        let path = shortest_path(world.scene(), world.grid(), start, goal, radius);
        let Some(path) = path else {
            return Self {
                seed,
                straight_px,
                geodesic_px: None,
                ratio: None,
                narrowest_gap_px: None,
                turns: None,
            };
        };
        let geodesic_px = crate::plan::path_length(&path);
        let reach = world.scene().width().max(world.scene().height());
        Self {
            seed,
            straight_px,
            geodesic_px: Some(geodesic_px),
            ratio: Some(if straight_px > 0.0 {
                geodesic_px / straight_px
            } else {
                1.0
            }),
            narrowest_gap_px: narrowest_gap(world, &path, reach),
            turns: Some(turns(&path)),
        }
    }

    /// The figure `by` names.
    pub fn figure(&self, by: Figure) -> Option<f64> {
        match by {
            Figure::Ratio => self.ratio,
            Figure::NarrowestGap => self.narrowest_gap_px,
            Figure::Turns => self.turns.map(f64::from),
        }
    }
}

/// The narrowest free width across `path`: at samples every [`SAMPLE_PX`], the free distance to
/// the left plus that to the right, perpendicular to the segment.
fn narrowest_gap(world: &World, path: &[Point], reach: f64) -> Option<f64> {
    let scene = world.scene();
    let mut least: Option<f64> = None;
    for w in path.windows(2) {
        let d = w[1] - w[0];
        let len = d.norm();
        if len <= 0.0 {
            continue;
        }
        let along = d / len;
        let side = Vector::new(-along.y, along.x);
        let samples = (len / SAMPLE_PX).ceil().max(1.0) as usize;
        for k in 0..=samples {
            let p = w[0] + d * (k as f64 / samples as f64);
            let left = scene.cast_ray(p, side, reach).unwrap_or(reach);
            let right = scene.cast_ray(p, -side, reach).unwrap_or(reach);
            let width = left + right;
            least = Some(least.map_or(width, |l| l.min(width)));
        }
    }
    least
}

/// Corners of `path` where the heading changes by more than [`TURN_DEG`].
fn turns(path: &[Point]) -> u32 {
    let headings: Vec<Vector> = path
        .windows(2)
        .map(|w| w[1] - w[0])
        .filter(|d| d.norm() > 1e-9)
        .collect();
    let limit = TURN_DEG.to_radians().cos();
    headings
        .windows(2)
        .filter(|h| h[0].dot(&h[1]) / (h[0].norm() * h[1].norm()) < limit)
        .count() as u32
}

/// A difficulty figure results can be broken down by.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Figure {
    /// Shortest path over straight line.
    Ratio,
    /// Narrowest passage on the shortest path, px (smaller is harder).
    NarrowestGap,
    /// Turns of the shortest path.
    Turns,
}

impl Figure {
    /// Every figure, in report order.
    pub const ALL: [Figure; 3] = [Figure::Ratio, Figure::NarrowestGap, Figure::Turns];

    /// The name in tables and files.
    pub fn name(self) -> &'static str {
        match self {
            Figure::Ratio => "path / straight ratio",
            Figure::NarrowestGap => "narrowest gap (px)",
            Figure::Turns => "turns",
        }
    }

    /// How a value of it is written, with `extra` more decimals than usual.
    pub fn format(self, v: f64, extra: usize) -> String {
        let digits = match self {
            Figure::Ratio => 2,
            Figure::NarrowestGap | Figure::Turns => 0,
        } + extra;
        format!("{v:.digits$}")
    }
}

/// A bin of seeds with a difficulty figure in `[low, high]`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Bin {
    /// Its label, e.g. `1.00-1.35`.
    pub label: String,
    /// Least value in the bin.
    pub low: f64,
    /// Greatest value in the bin.
    pub high: f64,
    /// Indices (into the seed list) of the seeds in the bin.
    #[serde(skip)]
    pub members: Vec<usize>,
}

/// `values` (one per seed, `None` for a seed without the figure) cut into at most `count` bins
/// of about equal size at their quantiles; equal values always share a bin.
pub fn bins(values: &[Option<f64>], count: usize, by: Figure) -> Vec<Bin> {
    let mut known: Vec<(f64, usize)> = values
        .iter()
        .enumerate()
        .filter_map(|(i, v)| v.filter(|v| v.is_finite()).map(|v| (v, i)))
        .collect();
    known.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    let n = known.len();
    let mut out: Vec<Bin> = Vec::new();
    let mut start = 0;
    for b in 1..=count.max(1) {
        if start >= n {
            break;
        }
        let mut end = (n * b / count.max(1)).max(start + 1).min(n);
        // Ties stay together.
        while end < n && known[end].0 == known[end - 1].0 {
            end += 1;
        }
        if b == count.max(1) {
            end = n;
        }
        let slice = &known[start..end];
        let (low, high) = (slice[0].0, slice[slice.len() - 1].0);
        out.push(Bin {
            label: String::new(),
            low,
            high,
            members: slice.iter().map(|&(_, i)| i).collect(),
        });
        start = end;
    }
    // Labels with as many decimals as it takes for neighbouring bins not to read the same.
    for extra in 0..=4 {
        let label = |b: &Bin| {
            let (lo, hi) = (by.format(b.low, extra), by.format(b.high, extra));
            if lo == hi {
                lo
            } else {
                format!("{lo}-{hi}")
            }
        };
        let edges: Vec<String> = out
            .iter()
            .flat_map(|b| [by.format(b.low, extra), by.format(b.high, extra)])
            .collect();
        let distinct = edges.windows(2).skip(1).step_by(2).all(|w| w[0] != w[1]);
        if distinct || extra == 4 {
            for b in &mut out {
                b.label = label(b);
            }
            break;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bins_split_at_quantiles_and_keep_ties_together() {
        let values: Vec<Option<f64>> = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0]
            .into_iter()
            .map(Some)
            .collect();
        let b = bins(&values, 3, Figure::Ratio);
        assert_eq!(b.len(), 3);
        assert_eq!(b[0].members, vec![0, 1, 2]);
        assert_eq!(b[2].label, "7.00-9.00");
        let ties = [Some(0.0), Some(0.0), Some(0.0), Some(0.0), Some(1.0), None];
        let b = bins(&ties, 3, Figure::Turns);
        assert_eq!(b.len(), 2, "{b:?}");
        assert_eq!(b[0].members, vec![0, 1, 2, 3]);
        assert_eq!(b[0].label, "0");
        assert_eq!(b[1].members, vec![4]);
        assert!(bins(&[None, None], 3, Figure::Ratio).is_empty());
    }

    #[test]
    fn an_l_shaped_path_turns_once() {
        let path = [
            Point::new(0.0, 0.0),
            Point::new(10.0, 0.0),
            Point::new(10.0, 10.0),
        ];
        assert_eq!(turns(&path), 1);
        let straight = [
            Point::new(0.0, 0.0),
            Point::new(5.0, 0.1),
            Point::new(10.0, 0.0),
        ];
        assert_eq!(turns(&straight), 0);
    }

    #[test]
    fn maze_tasks_have_sensible_figures() {
        let config = crate::ValidConfig::default();
        for seed in 0..5 {
            let world = World::maze(config.clone(), seed);
            let d = Difficulty::of(&world, seed).expect("an episode");
            let ratio = d.ratio.expect("connected");
            assert!(ratio >= 0.99, "{d:?}");
            let gap = d.narrowest_gap_px.expect("a path");
            // A robot of radius 5 passes, so the gap is at least its diameter.
            assert!(gap >= 10.0 && gap <= 1000.0 * 2f64.sqrt(), "{d:?}");
            assert!(d.turns.is_some());
        }
    }
}
