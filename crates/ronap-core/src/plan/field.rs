//! Geodesic distance fields: for every free cell of a [`FreeGrid`], the length of the shortest
//! 8-neighbour path to the goal (Dijkstra; diagonal moves only where both side cells are free, so
//! paths never cut a corner). The field has no local minima: it is the navigation function the
//! `geodesic` policy descends and the yardstick for SPL.

use crate::geometry::Point;
use crate::scene::freespace::FreeGrid;
use crate::scene::Scene;

/// No parent: the cell connects straight to the goal.
const ROOT: u32 = u32::MAX;

/// Geodesic distances to a goal over a [`FreeGrid`].
#[derive(Clone, Debug)]
pub struct DistanceField {
    cols: usize,
    rows: usize,
    cell_px: f64,
    goal: Point,
    /// Cost to the goal per cell; infinite where unreachable.
    cost: Vec<f64>,
    /// Next cell towards the goal, or [`ROOT`].
    parent: Vec<u32>,
}

/// The 8 neighbour offsets with their step lengths in cells.
const NEIGHBOURS: [(isize, isize, f64); 8] = [
    (1, 0, 1.0),
    (-1, 0, 1.0),
    (0, 1, 1.0),
    (0, -1, 1.0),
    (1, 1, std::f64::consts::SQRT_2),
    (1, -1, std::f64::consts::SQRT_2),
    (-1, 1, std::f64::consts::SQRT_2),
    (-1, -1, std::f64::consts::SQRT_2),
];

/// Cells around a point searched to attach it to the grid (a 5 x 5 block).
const ATTACH_CELLS: isize = 2;

impl DistanceField {
    /// The field towards `goal` for a disc of `radius`. Steps into or out of a
    /// [close](FreeGrid::is_close) cell cost `close_cost` times their length (1 gives plain
    /// shortest paths; more keeps paths away from walls).
    pub fn new(scene: &Scene, grid: &FreeGrid, goal: Point, radius: f64, close_cost: f64) -> Self {
        let (cols, rows) = grid.size();
        let cell_px = grid.cell_px();
        // Dial's algorithm: integer step costs (12 along an axis, 17 on a diagonal, within 0.2% of
        // 12 sqrt 2) in a ring of buckets, so each cell is settled in O(1). The smoothed path, not
        // this cost, is what gets measured, so the integer rounding does not reach any metric.
        const AXIS: u32 = 12;
        const DIAGONAL: u32 = 17;
        let close = close_cost.max(1.0).round() as u32;
        let ring = (DIAGONAL * close + 1) as usize;
        let mut cost = vec![u32::MAX; cols * rows];
        let mut parent = vec![ROOT; cols * rows];
        let mut buckets: Vec<Vec<u32>> = vec![Vec::new(); ring];
        let mut pending = 0usize;
        let units_per_px = AXIS as f64 / cell_px;
        for (i, d) in attach(scene, grid, goal, radius) {
            let c = (d * units_per_px).round() as u32;
            if c < cost[i] {
                cost[i] = c;
                buckets[c as usize % ring].push(i as u32);
                pending += 1;
            }
        }
        let mut current = 0u32;
        let mut bucket = Vec::new();
        while pending > 0 {
            std::mem::swap(&mut bucket, &mut buckets[current as usize % ring]);
            for &i in &bucket {
                let i = i as usize;
                if cost[i] > current {
                    // A start cost a ring or more ahead (the goal's attachments spread wider than
                    // one step): keep it for a later turn of the ring.
                    buckets[current as usize % ring].push(i as u32);
                    continue;
                }
                pending -= 1;
                if cost[i] < current {
                    continue;
                }
                let (c, r) = ((i % cols) as isize, (i / cols) as isize);
                for &(dc, dr, _) in &NEIGHBOURS {
                    let (nc, nr) = (c + dc, r + dr);
                    if nc < 0 || nr < 0 || nc >= cols as isize || nr >= rows as isize {
                        continue;
                    }
                    let j = nr as usize * cols + nc as usize;
                    if !grid.is_free_index(j) || !grid.linked(i, j) {
                        continue;
                    }
                    let diagonal = dc != 0 && dr != 0;
                    if diagonal
                        && !(grid.is_free(nc as usize, r as usize)
                            && grid.is_free(c as usize, nr as usize))
                    {
                        continue;
                    }
                    let base = if diagonal { DIAGONAL } else { AXIS };
                    let weight = if grid.is_close(i) || grid.is_close(j) {
                        close
                    } else {
                        1
                    };
                    let nd = current + base * weight;
                    if nd < cost[j] {
                        cost[j] = nd;
                        parent[j] = i as u32;
                        buckets[nd as usize % ring].push(j as u32);
                        pending += 1;
                    }
                }
            }
            bucket.clear();
            current += 1;
        }
        let px_per_unit = cell_px / AXIS as f64;
        Self {
            cols,
            rows,
            cell_px,
            goal,
            cost: cost
                .into_iter()
                .map(|c| {
                    if c == u32::MAX {
                        f64::INFINITY
                    } else {
                        c as f64 * px_per_unit
                    }
                })
                .collect(),
            parent,
        }
    }

    /// The goal the field leads to.
    pub fn goal(&self) -> Point {
        self.goal
    }

    /// The field's cost at the cell holding `p` (infinite if blocked, unreachable or outside).
    pub fn cost_at(&self, p: Point) -> f64 {
        let (c, r) = ((p.x / self.cell_px).floor(), (p.y / self.cell_px).floor());
        if c < 0.0 || r < 0.0 || c >= self.cols as f64 || r >= self.rows as f64 {
            return f64::INFINITY;
        }
        self.cost[r as usize * self.cols + c as usize]
    }

    fn center(&self, i: usize) -> Point {
        Point::new(
            ((i % self.cols) as f64 + 0.5) * self.cell_px,
            ((i / self.cols) as f64 + 0.5) * self.cell_px,
        )
    }

    /// The grid path from `start` to the goal: `start`, cell centres down the field, the goal.
    /// `None` when the goal cannot be reached from `start`.
    pub fn path(
        &self,
        scene: &Scene,
        grid: &FreeGrid,
        start: Point,
        radius: f64,
    ) -> Option<Vec<Point>> {
        let (first, _) = attach(scene, grid, start, radius)
            .into_iter()
            .filter(|&(i, _)| self.cost[i].is_finite())
            .min_by(|a, b| (a.1 + self.cost[a.0]).total_cmp(&(b.1 + self.cost[b.0])))?;
        let mut points = vec![start];
        let mut i = first;
        loop {
            points.push(self.center(i));
            if self.parent[i] == ROOT {
                break;
            }
            i = self.parent[i] as usize;
        }
        points.push(self.goal);
        Some(points)
    }
}

/// Free cells near `p` that a disc of `radius` at `p` can reach in a straight line, with the
/// length of that line.
fn attach(scene: &Scene, grid: &FreeGrid, p: Point, radius: f64) -> Vec<(usize, f64)> {
    let Some((c, r)) = grid.cell_of(p) else {
        return Vec::new();
    };
    let (cols, rows) = grid.size();
    let mut out = Vec::new();
    for dr in -ATTACH_CELLS..=ATTACH_CELLS {
        for dc in -ATTACH_CELLS..=ATTACH_CELLS {
            let (nc, nr) = (c as isize + dc, r as isize + dr);
            if nc < 0 || nr < 0 || nc >= cols as isize || nr >= rows as isize {
                continue;
            }
            let (nc, nr) = (nc as usize, nr as usize);
            let centre = grid.center(nc, nr);
            if grid.is_free(nc, nr) && scene.sweep_clear(p, centre, radius) {
                out.push((nr * cols + nc, (centre - p).norm()));
            }
        }
    }
    out
}
