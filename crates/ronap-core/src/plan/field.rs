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
    /// Per cell, its cost to the goal in the search's units and the next cell towards the goal.
    cells: Vec<Node>,
}

/// Cells around a point searched to attach it to the grid (a 5 x 5 block).
const ATTACH_CELLS: isize = 2;

impl DistanceField {
    /// The field towards `goal` for a disc of `radius`. Steps into or out of a
    /// [close](FreeGrid::is_close) cell cost `close_cost` times their length (1 gives plain
    /// shortest paths; more keeps paths away from walls). The search runs in buffers kept per
    /// thread; the field keeps a copy of its cells.
    pub fn new(scene: &Scene, grid: &FreeGrid, goal: Point, radius: f64, close_cost: f64) -> Self {
        let (cols, rows) = grid.size();
        WORK.with_borrow_mut(|work| {
            work.run(scene, grid, goal, radius, close_cost, None);
            Self {
                cols,
                rows,
                cell_px: grid.cell_px(),
                goal,
                cells: work.cells.clone(),
            }
        })
    }

    /// The cost of cell `i`, px (infinite where unreachable).
    fn cost(&self, i: usize) -> f64 {
        match self.cells[i].cost {
            u32::MAX => f64::INFINITY,
            c => c as f64 * (self.cell_px / AXIS as f64),
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
        self.cost(r as usize * self.cols + c as usize)
    }

    /// The geodesic distance from `p` to the goal: the least, over the cell holding `p` and its
    /// eight neighbours, of the cell's cost plus the straight line from `p` to its centre, so it
    /// changes smoothly as `p` moves within a cell. `None` when none of them reaches the goal.
    pub fn distance_at(&self, p: Point) -> Option<f64> {
        let (c, r) = ((p.x / self.cell_px).floor(), (p.y / self.cell_px).floor());
        let mut best = f64::INFINITY;
        for dr in -1..=1 {
            for dc in -1..=1 {
                let (cc, rr) = (c + f64::from(dc), r + f64::from(dr));
                if cc < 0.0 || rr < 0.0 || cc >= self.cols as f64 || rr >= self.rows as f64 {
                    continue;
                }
                let i = rr as usize * self.cols + cc as usize;
                let cost = self.cost(i);
                if cost.is_finite() {
                    best = best.min(cost + (p - self.center(i)).norm());
                }
            }
        }
        best.is_finite().then_some(best)
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
        let first = best_entry(&attach(scene, grid, start, radius), |i| self.cost(i))?;
        Some(walk(
            start,
            first,
            self.goal,
            |i| self.cells[i].parent,
            |i| self.center(i),
        ))
    }
}

/// The grid path a [`DistanceField`] towards `goal` gives from `start` (the same points as
/// `DistanceField::new(..).path(..)`), searching only as far from the goal as `start` lies: the
/// search stops once no cell it has not settled could begin a shorter path, so it settles only
/// the cells about as near the goal as `start` is. Buffers are kept per thread between calls.
pub fn grid_path(
    scene: &Scene,
    grid: &FreeGrid,
    start: Point,
    goal: Point,
    radius: f64,
    close_cost: f64,
) -> Option<Vec<Point>> {
    let entries = attach(scene, grid, start, radius);
    if entries.is_empty() {
        return None;
    }
    WORK.with_borrow_mut(|work| {
        work.run(scene, grid, goal, radius, close_cost, Some(&entries));
        let px_per_unit = grid.cell_px() / AXIS as f64;
        let cost = |i: usize| match work.cells[i].cost {
            u32::MAX => f64::INFINITY,
            c => c as f64 * px_per_unit,
        };
        // Entries the search stopped short of are provably no better than the best settled one,
        // so leaving them out picks the same entry as the whole field does.
        let settled = |i: usize| work.cells[i].cost <= work.reached;
        let first = best_entry(
            &entries,
            |i| if settled(i) { cost(i) } else { f64::INFINITY },
        )?;
        let (cols, cell_px) = (grid.size().0, grid.cell_px());
        let center = |i: usize| {
            Point::new(
                ((i % cols) as f64 + 0.5) * cell_px,
                ((i / cols) as f64 + 0.5) * cell_px,
            )
        };
        Some(walk(start, first, goal, |i| work.cells[i].parent, center))
    })
}

/// Axis step cost, in the integer units of the search (see [`Work::run`]).
const AXIS: u32 = 12;
/// Diagonal step cost (within 0.2% of 12 sqrt 2).
const DIAGONAL: u32 = 17;
/// Step costs of the moves E, W, N, S, NE, SE, NW, SW.
const STEP: [u32; 8] = [
    AXIS, AXIS, AXIS, AXIS, DIAGONAL, DIAGONAL, DIAGONAL, DIAGONAL,
];

thread_local! {
    /// Each thread's search buffers for [`grid_path`] and [`DistanceField::new`].
    static WORK: std::cell::RefCell<Work> = std::cell::RefCell::default();
}

/// A cell of the search: its cost to the goal in units ([`AXIS`] per cell side; `u32::MAX` where
/// not reached) and the next cell towards the goal (or [`ROOT`]).
#[derive(Clone, Copy, Debug)]
struct Node {
    cost: u32,
    parent: u32,
}

/// The search's buffers, reusable between searches over grids of any size.
#[derive(Default)]
struct Work {
    /// Per cell, its cost and parent side by side: a settled cell reads its neighbours' costs
    /// and writes cost and parent of those it improves, over a front spread across the whole
    /// grid, so one cache line a cell rather than two (apart, they measured slower).
    cells: Vec<Node>,
    /// Dial's ring of buckets: cells by cost modulo the ring's length.
    buckets: Vec<Vec<u32>>,
    /// Cells of the current bucket being settled.
    bucket: Vec<u32>,
    /// Every cell of cost up to this is settled (final cost and parent).
    reached: u32,
}

impl Work {
    /// Dijkstra from the cells `goal` attaches to, by Dial's algorithm: integer step costs
    /// ([`AXIS`] along an axis, [`DIAGONAL`] on a diagonal) in a ring of buckets, so each cell is
    /// settled in O(1). The smoothed path, not this cost, is what gets measured, so the integer
    /// rounding does not reach any metric.
    ///
    /// With `targets` (cells and their straight-line distance in px from a start), it stops as
    /// soon as every target it has not settled would, even at the least cost still possible,
    /// give a longer path than the best settled one; without, it settles every reachable cell.
    fn run(
        &mut self,
        scene: &Scene,
        grid: &FreeGrid,
        goal: Point,
        radius: f64,
        close_cost: f64,
        targets: Option<&[(usize, f64)]>,
    ) {
        let (cols, rows) = grid.size();
        let n = cols * rows;
        let cell_px = grid.cell_px();
        let close = close_cost.max(1.0).round() as u32;
        let ring = (DIAGONAL * close + 1) as usize;
        self.cells.clear();
        self.cells.resize(
            n,
            Node {
                cost: u32::MAX,
                parent: ROOT,
            },
        );
        self.buckets.resize_with(ring, Vec::new);
        self.buckets.truncate(ring);
        self.buckets.iter_mut().for_each(Vec::clear);
        self.reached = 0;
        let (cells, buckets) = (&mut self.cells, &mut self.buckets);
        let mut pending = 0usize;
        let units_per_px = AXIS as f64 / cell_px;
        let px_per_unit = cell_px / AXIS as f64;
        for (i, d) in attach(scene, grid, goal, radius) {
            let c = (d * units_per_px).round() as u32;
            if c < cells[i].cost {
                cells[i].cost = c;
                buckets[c as usize % ring].push(i as u32);
                pending += 1;
            }
        }
        let (moves, slow) = (grid.moves(), grid.close_moves());
        let offsets = grid.move_offsets();
        // Targets lie in a small block: a range check spares looking them up for most cells.
        let (lowest, highest) = targets
            .into_iter()
            .flatten()
            .fold((usize::MAX, 0), |(lo, hi), t| (lo.min(t.0), hi.max(t.0)));
        // The best path through a settled target so far, px (a start's straight line plus its
        // cell's cost).
        let mut best = f64::INFINITY;
        let mut current = 0u32;
        // `current % ring`, kept by hand: a step lands less than a ring ahead, so its bucket is
        // an addition and at most one wrap away.
        let mut slot = 0usize;
        // Step costs by move, plain and from or into a close cell.
        let steps = [STEP, STEP.map(|s| s * close)];
        let mut bucket = std::mem::take(&mut self.bucket);
        while pending > 0 {
            std::mem::swap(&mut bucket, &mut buckets[slot]);
            for &i in &bucket {
                let i = i as usize;
                if cells[i].cost > current {
                    // A start cost a ring or more ahead (the goal's attachments spread wider than
                    // one step): keep it for a later turn of the ring.
                    buckets[slot].push(i as u32);
                    continue;
                }
                pending -= 1;
                if cells[i].cost < current {
                    continue;
                }
                // Open moves as bits in the order E, W, N, S, NE, SE, NW, SW: the order decides
                // which of two equal-cost parents a cell keeps.
                let open = moves[i] as u32;
                let slow = slow[i] as u32;
                // Which open moves improve their cell, found for all eight before any is
                // taken (they reach eight different cells), without a branch on each: whether
                // a neighbour improves is a coin toss to the branch predictor. A closed move
                // looks at the cell itself, which never improves (every step costs more than
                // nothing).
                let mut better = 0u32;
                for k in 0..8 {
                    let mask = ((open as usize >> k) & 1).wrapping_neg();
                    let j = i.wrapping_add(offsets[k] as usize & mask);
                    let nd = current + steps[(slow >> k & 1) as usize][k];
                    better |= u32::from(nd < cells[j].cost) << k;
                }
                while better != 0 {
                    let k = better.trailing_zeros() as usize;
                    better &= better - 1;
                    let j = i.wrapping_add(offsets[k] as usize);
                    let step = steps[(slow >> k & 1) as usize][k];
                    cells[j] = Node {
                        cost: current + step,
                        parent: i as u32,
                    };
                    let mut to = slot + step as usize;
                    if to >= ring {
                        to -= ring;
                    }
                    buckets[to].push(j as u32);
                    pending += 1;
                }
                if (lowest..=highest).contains(&i) {
                    for &(t, d) in targets.unwrap_or_default() {
                        if t == i {
                            best = best.min(d + current as f64 * px_per_unit);
                        }
                    }
                }
            }
            bucket.clear();
            self.reached = current;
            if let Some(targets) = targets {
                // A target not yet settled costs at least `current + 1` units.
                let floor = (current + 1) as f64 * px_per_unit;
                if best.is_finite()
                    && targets
                        .iter()
                        .all(|&(t, d)| cells[t].cost <= current || d + floor > best)
                {
                    break;
                }
            }
            current += 1;
            slot += 1;
            if slot == ring {
                slot = 0;
            }
        }
        self.bucket = bucket;
    }
}

/// Of the cells a start attaches to (with their distances), the one beginning the shortest path
/// under `cost` (the first of equals); `None` when none is reachable.
fn best_entry(entries: &[(usize, f64)], cost: impl Fn(usize) -> f64) -> Option<usize> {
    entries
        .iter()
        .filter(|&&(i, _)| cost(i).is_finite())
        .min_by(|a, b| (a.1 + cost(a.0)).total_cmp(&(b.1 + cost(b.0))))
        .map(|&(i, _)| i)
}

/// `start`, the centres of the cells from `first` down `parent` to the root, and `goal`.
fn walk(
    start: Point,
    first: usize,
    goal: Point,
    parent: impl Fn(usize) -> u32,
    center: impl Fn(usize) -> Point,
) -> Vec<Point> {
    let mut points = vec![start];
    let mut i = first;
    loop {
        points.push(center(i));
        if parent(i) == ROOT {
            break;
        }
        i = parent(i) as usize;
    }
    points.push(goal);
    points
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::ValidConfig;
    use crate::sim::world::World;

    /// The early-stopping search gives exactly the whole field's path: in mazes and warehouses,
    /// plain and wall-shy costs, near and far starts.
    #[test]
    fn grid_path_is_the_whole_fields_path() {
        let config = ValidConfig::default();
        let mut compared = 0;
        for seed in 0..12u64 {
            let world = if seed % 3 == 2 {
                World::warehouse(config.clone(), seed)
            } else {
                World::maze(config.clone(), seed)
            };
            let (scene, grid) = (world.scene(), world.grid());
            let Ok(episode) = world.episode(seed) else {
                continue;
            };
            let goal = episode.goal();
            for close_cost in [1.0, 4.0] {
                let field = DistanceField::new(scene, grid, goal, 5.0, close_cost);
                let cells = grid.region_cells(0);
                for k in 0..25 {
                    let cell = cells[(k * 7919 + seed as usize * 131) % cells.len()] as usize;
                    let (cols, _) = grid.size();
                    let start = grid.center(cell % cols, cell / cols)
                        + crate::geometry::Vector::new(1.3, -0.7);
                    let whole = field.path(scene, grid, start, 5.0);
                    let early = grid_path(scene, grid, start, goal, 5.0, close_cost);
                    assert_eq!(whole, early, "seed {seed} cost {close_cost} start {start}");
                    compared += 1;
                }
                // The goal's own cell and a point outside the scene.
                let here = grid_path(scene, grid, goal, goal, 5.0, close_cost);
                assert_eq!(field.path(scene, grid, goal, 5.0), here);
                let outside = Point::new(-10.0, -10.0);
                assert_eq!(grid_path(scene, grid, outside, goal, 5.0, close_cost), None);
            }
        }
        assert!(compared > 400, "{compared}");
    }
}
