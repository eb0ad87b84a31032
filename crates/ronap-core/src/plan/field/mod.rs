//! Geodesic distance fields: for every free cell of a [`FreeGrid`], the length of the shortest
//! 8-neighbour path to the goal (Dijkstra; diagonal moves only where both side cells are free, so
//! paths never cut a corner). The field has no local minima: it is the navigation function the
//! `geodesic` policy descends and the yardstick for SPL.

use crate::geometry::Point;
use crate::scene::{FreeGrid, Scene};
use search::*;

mod search;

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
    /// shortest paths; more keeps paths away from walls). The search runs in the field's own
    /// cells (so they need no copying after) and the other buffers kept per thread.
    pub fn new(scene: &Scene, grid: &FreeGrid, goal: Point, radius: f64, close_cost: f64) -> Self {
        let (cols, rows) = grid.size();
        let mut cells = vec![UNREACHED; cols * rows];
        WORK.with_borrow_mut(|work| {
            // The thread's own cells, and whether they are clean, stay as they were.
            std::mem::swap(&mut work.cells, &mut cells);
            work.search(grid, &attach(scene, grid, goal, radius), close_cost);
            std::mem::swap(&mut work.cells, &mut cells);
        });
        Self {
            cols,
            rows,
            cell_px: grid.cell_px(),
            goal,
            cells,
        }
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
        let best = nearest(p, self.cols, self.rows, self.cell_px, |i| self.cost(i));
        best.is_finite().then_some(best)
    }

    fn center(&self, i: usize) -> Point {
        center(i, self.cols, self.cell_px)
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
        let entries = attach(scene, grid, start, radius);
        let first = best_entry(entries.iter().map(|&(i, d)| (i, d + self.cost(i))))?;
        Some(walk(
            start,
            first,
            self.goal,
            |i| self.cells[i].parent,
            |i| self.center(i),
        ))
    }
}

/// The cells around `p`: the cell holding it and its eight neighbours, those in the grid.
fn around(p: Point, cols: usize, rows: usize, cell_px: f64) -> impl Iterator<Item = Around> {
    let (c, r) = ((p.x / cell_px).floor(), (p.y / cell_px).floor());
    (-1..=1).flat_map(move |dr| {
        (-1..=1).filter_map(move |dc| {
            let (cc, rr) = (c + f64::from(dc), r + f64::from(dr));
            (cc >= 0.0 && rr >= 0.0 && cc < cols as f64 && rr < rows as f64).then(|| Around {
                index: rr as usize * cols + cc as usize,
                col: cc as u32,
                row: rr as u32,
                line: (p - Point::new((cc + 0.5) * cell_px, (rr + 0.5) * cell_px)).norm(),
            })
        })
    })
}

/// A cell [`around`] a point.
#[derive(Clone, Copy, Default)]
struct Around {
    /// The cell's index, `row * cols + col`.
    index: usize,
    col: u32,
    row: u32,
    /// The straight line from the point to the cell's centre, px.
    line: f64,
}

/// The least, over the cells [`around`] `p`, of a cell's `cost` (px; infinite where it does not
/// reach the goal) plus the straight line from `p` to its centre: infinite when none reaches.
fn nearest(p: Point, cols: usize, rows: usize, cell_px: f64, cost: impl Fn(usize) -> f64) -> f64 {
    around(p, cols, rows, cell_px)
        .map(|a| (cost(a.index), a.line))
        .filter(|(c, _)| c.is_finite())
        .fold(f64::INFINITY, |best, (c, line)| best.min(c + line))
}

/// The centre of cell `i` of a grid `cols` wide.
fn center(i: usize, cols: usize, cell_px: f64) -> Point {
    Point::new(
        ((i % cols) as f64 + 0.5) * cell_px,
        ((i / cols) as f64 + 0.5) * cell_px,
    )
}

/// A [`DistanceField`] searched only as far as the points asked about need: what reward shaping
/// asks at each step of an episode. Its search from the goal is [`grid_path`]'s A*, steered
/// towards the first point to be asked about (the robot's start), and it stops once every cell
/// that could give a point's distance is settled; a point further out carries it on from there,
/// steered anew towards that point when it lies far from where the search heads. So an episode
/// pays at its start for the cells between goal and start, and then for those its robot strays
/// to, rather than for all. The distances are the whole field's, bit for bit: a cell's cost is
/// its shortest path's, whichever order the cells are settled in.
pub struct LazyField {
    cols: usize,
    rows: usize,
    cell_px: f64,
    goal: Point,
    /// The search, stopped part way: its own buffers, since it goes on between calls.
    work: Box<Work>,
    /// Per cell, whether the search has settled it.
    settled: Vec<bool>,
}

/// How far, in units, a [`LazyField`] searches on at a time while none of a point's cells has
/// been reached: about ten cells' side.
const LAZY_CHUNK: u32 = 128;

/// How many cells (along a row or column) a point a [`LazyField`] must search on for may lie from
/// the cell its search heads for before it is steered towards the point.
const STEER_CELLS: u32 = 12;

impl LazyField {
    /// The field towards `goal` for a disc of `radius`, with steps into or out of a close cell
    /// costing `close_cost` times their length (as [`DistanceField::new`]), its search steered
    /// towards `toward` and nothing settled yet.
    pub fn new(
        scene: &Scene,
        grid: &FreeGrid,
        goal: Point,
        toward: Point,
        radius: f64,
        close_cost: f64,
    ) -> Self {
        let (cols, rows) = grid.size();
        let (mut work, mut settled) = LAZY_WORK
            .with_borrow_mut(Vec::pop)
            .unwrap_or_else(|| (Box::default(), Vec::new()));
        if work.cells.len() != cols * rows {
            work.cells.clear();
            work.cells.resize(cols * rows, UNREACHED);
            settled.clear();
            settled.resize(cols * rows, false);
        }
        let from = grid
            .cell_of(toward)
            .or(grid.cell_of(goal))
            .unwrap_or((0, 0));
        // Heading for one cell, the search needs no slack for the start's entries.
        work.slack = 0;
        work.begin_steered(grid, &attach(scene, grid, goal, radius), close_cost, from);
        Self {
            cols,
            rows,
            cell_px: grid.cell_px(),
            goal,
            work,
            settled,
        }
    }

    /// Steers the search on towards cell `to`: the cells waiting in its front put in a new ring
    /// by their cost plus least distance to `to`. A* stays exact when its estimate changes, as
    /// long as the new one changes by no more than a step's cost from a cell to its neighbour: a
    /// cell not yet settled still costs at least the least sum waiting, less its least distance.
    fn steer(&mut self, grid: &FreeGrid, to: (usize, usize)) {
        let work = &mut *self.work;
        // Each waiting cell once: its latest entry is the one at its cost, the others are stale.
        let mut waiting = Vec::new();
        for bucket in &work.front {
            for &i in bucket {
                let node = &mut work.cells[i as usize];
                if !self.settled[i as usize] && node.parent != MARKED {
                    node.parent = MARKED;
                    waiting.push(i);
                }
            }
        }
        for &i in &waiting {
            work.cells[i as usize].parent = ROOT;
        }
        work.queue_steered(grid, &waiting, to);
    }

    /// The goal the field leads to.
    pub fn goal(&self) -> Point {
        self.goal
    }

    /// [`DistanceField::distance_at`], searching on as far as `p` needs. `grid` must be the
    /// grid the field was made over.
    pub fn distance_at(&mut self, grid: &FreeGrid, p: Point) -> Option<f64> {
        debug_assert_eq!(grid.size(), (self.cols, self.rows));
        let px_per_unit = self.cell_px / AXIS as f64;
        let (cols, rows, cell_px) = (self.cols, self.rows, self.cell_px);
        let (mut near, mut n) = ([Around::default(); 9], 0);
        for a in around(p, cols, rows, cell_px) {
            near[n] = a;
            n += 1;
        }
        let near = &near[..n];
        let mut steered = false;
        loop {
            let work = &mut *self.work;
            // A cell not settled costs at least `next` less its least distance.
            let (next, done) = (work.current, work.pending == 0);
            let settled = |a: &Around| self.settled[a.index];
            let best = near
                .iter()
                .filter(|a| settled(a))
                .fold(f64::INFINITY, |best, a| {
                    best.min(work.cells[a.index].cost as f64 * px_per_unit + a.line)
                });
            if done {
                return best.is_finite().then_some(best);
            }
            // A free cell not yet settled costs at least `next` less its least distance; it
            // is left out once that, plus its line from `p`, is no better than the best.
            let mut until = u32::MIN;
            let mut open = false;
            for a in near {
                if settled(a) || !grid.is_free_index(a.index) {
                    continue;
                }
                let (least, line) = (work.least(a.col, a.row), a.line);
                if next.saturating_sub(least) as f64 * px_per_unit + line >= best {
                    continue;
                }
                open = true;
                // On until that bound passes the best, or, sooner, until the cell settles.
                let mut needed = if best.is_finite() {
                    least.saturating_add(((best - line) / px_per_unit).ceil() as u32 + 1)
                } else {
                    next.saturating_add(LAZY_CHUNK)
                };
                let cost = work.cells[a.index].cost;
                if cost != u32::MAX {
                    needed = needed.min(cost + least + 1);
                }
                until = until.max(needed);
            }
            if !open {
                return best.is_finite().then_some(best);
            }
            // Towards `p`, once, if the search heads somewhere else: a robot that strays from
            // its start would otherwise settle every cell as near the start as it is.
            if let Some((c, r)) = grid.cell_of(p).filter(|_| !steered) {
                let (fc, fr) = work.from;
                if (c as u32).abs_diff(fc).max((r as u32).abs_diff(fr)) > STEER_CELLS {
                    steered = true;
                    self.steer(grid, (c, r));
                    continue;
                }
            }
            let settled = &mut self.settled;
            work.settle_steered(
                grid,
                &mut Until {
                    until: until.max(next + 1),
                    settled,
                },
            );
        }
    }
}

/// Most searches of dropped lazy fields a thread keeps: an environment's shaping drops its old
/// field about when it makes a new one.
const LAZY_KEPT: usize = 4;

thread_local! {
    /// Searches (with their settled marks) of lazy fields dropped on this thread, every cell
    /// unreached and unmarked again, for the next lazy field to take up instead of clearing a
    /// whole grid's worth of new buffers.
    static LAZY_WORK: std::cell::RefCell<Vec<(Box<Work>, Vec<bool>)>> =
        const { std::cell::RefCell::new(Vec::new()) };
}

impl Drop for LazyField {
    /// Hands the search to the thread's `LAZY_WORK`, its cells put back as they were at the
    /// cost of the cells it reached rather than of all.
    fn drop(&mut self) {
        let mut work = std::mem::take(&mut self.work);
        let mut settled = std::mem::take(&mut self.settled);
        for &i in &work.closed {
            settled[i as usize] = false;
        }
        work.tidy();
        work.closed.clear();
        // Not kept when the thread is ending and its list is gone.
        let _ = LAZY_WORK.try_with(|kept| {
            let mut kept = kept.borrow_mut();
            if kept.len() < LAZY_KEPT {
                kept.push((work, settled));
            }
        });
    }
}

impl std::fmt::Debug for LazyField {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LazyField")
            .field("size", &(self.cols, self.rows))
            .field("goal", &self.goal)
            .field("settled", &self.settled.iter().filter(|&&s| s).count())
            .finish_non_exhaustive()
    }
}

/// The grid path a [`DistanceField`] towards `goal` gives from `start` (the same points as
/// `DistanceField::new(..).path(..)`), searching only the cells such a path could use.
///
/// A search from the goal that a lower bound on each cell's remaining distance to `start` steers
/// (A*) finds the cells that could lie on the path or decide between equal ones: a few thousand
/// of the default scene's 40 000 instead of every cell nearer the goal than `start`. The field's
/// own search then runs over just those cells, so that ties between equal paths fall exactly as
/// in the whole field. Buffers are kept per thread between calls.
pub fn grid_path(
    scene: &Scene,
    grid: &FreeGrid,
    start: Point,
    goal: Point,
    radius: f64,
    close_cost: f64,
) -> Option<Vec<Point>> {
    let entries = attach(scene, grid, start, radius);
    let from = grid.cell_of(start).filter(|_| !entries.is_empty())?;
    WORK.with_borrow_mut(|work| {
        let roots = attach(scene, grid, goal, radius);
        let costs = work.bound(grid, &roots, close_cost, from, &entries);
        // Entries beyond the bound are provably no better than the best one within it, so
        // leaving them out picks the same entry as the whole field does.
        let px_per_unit = grid.cell_px() / AXIS as f64;
        let totals = entries.iter().zip(&costs).map(|(&(i, d), cost)| {
            (
                i,
                cost.map_or(f64::INFINITY, |c| d + c as f64 * px_per_unit),
            )
        });
        let path = best_entry(totals).map(|first| {
            work.narrow(grid, first, close_cost);
            work.search(grid, &roots, close_cost);
            let (cols, cell_px) = (grid.size().0, grid.cell_px());
            walk(
                start,
                first,
                goal,
                |i| work.cells[i].parent,
                |i| center(i, cols, cell_px),
            )
        });
        work.tidy();
        path
    })
}

/// Of the cells a start attaches to, with the length of the path through each (px; infinite
/// where none), the one beginning the shortest (the first of equals); `None` when none does.
fn best_entry(totals: impl IntoIterator<Item = (usize, f64)>) -> Option<usize> {
    totals
        .into_iter()
        .filter(|e| e.1.is_finite())
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|e| e.0)
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
pub(crate) mod tests {
    use super::*;
    use crate::config::ValidConfig;
    use crate::geometry::Vector;
    use crate::sim::World;
    use rand::{Rng, SeedableRng};

    /// Worlds of seeds `0..n` with the default configuration, by turns a maze, a warehouse and
    /// `scenarios/office.png`.
    pub(crate) fn mixed_worlds(n: u64) -> impl Iterator<Item = (u64, World)> {
        let config = ValidConfig::default();
        let office =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios/office.png");
        let (office, _) =
            crate::scene::map::load(&office, &config.map, config.reach_px()).expect("a map");
        let office = std::sync::Arc::new(office);
        (0..n).map(move |seed| {
            let world = match seed % 3 {
                0 => World::maze(config.clone(), seed),
                1 => World::warehouse(config.clone(), seed),
                _ => World::new(config.clone(), office.clone()),
            };
            (seed, world)
        })
    }

    /// [`improving`], reading rows for cells inside the grid and its step costs from a table,
    /// finds the moves that each open move on its own finds with its step picked by its bit: at
    /// every cell of mazes, warehouses and an image map, border cells included, among neighbours
    /// at costs drawn at random (some not reached), with and without close moves.
    #[test]
    fn improving_reads_rows_as_each_move_would() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        let (mut quick, mut found) = (0, 0);
        for (_, world) in mixed_worlds(6) {
            let grid = world.grid();
            let (cols, rows) = grid.size();
            let cells: Vec<Node> = (0..cols * rows)
                .map(|_| Node {
                    cost: if rng.random_bool(0.3) {
                        u32::MAX
                    } else {
                        rng.random_range(0..400)
                    },
                    parent: ROOT,
                })
                .collect();
            let (moves, close) = (grid.moves(), grid.close_moves());
            let (offsets, steps) = (grid.move_offsets(), Steps::new(4.0));
            for (i, cell) in cells.iter().enumerate().filter(|(_, c)| c.cost != u32::MAX) {
                let open = u32::from(moves[i]);
                for slow in [close[i], 0] {
                    // Each open move on its own, its step picked by its bit.
                    let each = (0..8).filter(|&k| open >> k & 1 == 1).fold(0, |bits, k| {
                        let j = i.wrapping_add(offsets[k] as usize);
                        let step = steps.pair[usize::from(slow >> k & 1)][k];
                        bits | u32::from(cell.cost + step < cells[j].cost) << k
                    });
                    let st = &steps.by_close[usize::from(slow)];
                    assert_eq!(
                        improving(&cells, i, open, slow, st, &offsets),
                        each,
                        "cell {i} cost {} open {open:#b} slow {slow:#b}",
                        cell.cost
                    );
                    quick += usize::from(i > cols && i + cols + 1 < cells.len());
                    found += usize::from(each != 0);
                }
            }
        }
        assert!(quick > 100_000 && found > 50_000, "{quick} {found}");
    }

    /// Dijkstra as its definition reads, level by level of cost in a sorted map, each level's
    /// cells in the order they were reached, each move on its own: the costs and parents
    /// [`Work::search`] must give.
    fn by_levels(grid: &FreeGrid, roots: &[(usize, f64)], close_cost: f64) -> Vec<Node> {
        let (cols, rows) = grid.size();
        let mut cells = vec![UNREACHED; cols * rows];
        let steps = step_costs(close_cost);
        let mut levels = std::collections::BTreeMap::<u32, Vec<usize>>::new();
        for &(i, d) in roots {
            let c = (d * AXIS as f64 / grid.cell_px()).round() as u32;
            if c < cells[i].cost {
                cells[i].cost = c;
                levels.entry(c).or_default().push(i);
            }
        }
        let (moves, close, offsets) = (grid.moves(), grid.close_moves(), grid.move_offsets());
        while let Some((cost, level)) = levels.pop_first() {
            for i in level {
                if cells[i].cost != cost {
                    continue;
                }
                for k in (0..8).filter(|&k| moves[i] >> k & 1 == 1) {
                    let j = i.wrapping_add(offsets[k] as usize);
                    let to = cost + steps[usize::from(close[i] >> k & 1)][k];
                    if to < cells[j].cost {
                        cells[j] = Node {
                            cost: to,
                            parent: i as u32,
                        };
                        levels.entry(to).or_default().push(j);
                    }
                }
            }
        }
        cells
    }

    /// A whole field has, at every cell, the cost and parent of Dijkstra as its definition
    /// reads ([`by_levels`]): mazes, warehouses and an image map, plain and wall-shy costs,
    /// goals where episodes put them and at random free cells.
    #[test]
    fn a_whole_field_is_dijkstras_by_levels() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(9);
        let mut cells = 0;
        for (seed, world) in mixed_worlds(9) {
            let (scene, grid) = (world.scene(), world.grid());
            let (cols, rows) = grid.size();
            let free: Vec<(usize, usize)> = (0..rows)
                .flat_map(|r| (0..cols).map(move |c| (c, r)))
                .filter(|&(c, r)| grid.is_free(c, r))
                .collect();
            let random = free[rng.random_range(0..free.len())];
            let mut goals = vec![grid.center(random.0, random.1)];
            goals.extend(world.episode(seed).ok().map(|e| e.goal()));
            for goal in goals {
                for close_cost in [1.0, 4.0] {
                    let field = DistanceField::new(scene, grid, goal, 5.0, close_cost);
                    let roots = attach(scene, grid, goal, 5.0);
                    let expected = by_levels(grid, &roots, close_cost);
                    for (i, (got, want)) in field.cells.iter().zip(&expected).enumerate() {
                        assert_eq!(
                            (got.cost, got.parent),
                            (want.cost, want.parent),
                            "seed {seed}, goal {goal:?}, close cost {close_cost}, cell {i}"
                        );
                    }
                    cells += expected.iter().filter(|n| n.cost != u32::MAX).count();
                }
            }
        }
        assert!(cells > 500_000, "{cells}");
    }

    /// The search over just the cells a path could use gives exactly the whole field's path:
    /// in mazes, warehouses and an image map, plain and wall-shy costs, near and far starts,
    /// starts cut off from the goal, in walls and outside the scene.
    #[test]
    fn grid_path_is_the_whole_fields_path() {
        let mut compared = 0;
        for (seed, world) in mixed_worlds(15) {
            let (scene, grid) = (world.scene(), world.grid());
            let Ok(episode) = world.episode(seed) else {
                continue;
            };
            let goal = episode.goal();
            let (cols, rows) = grid.size();
            let mut starts = vec![goal, Point::new(-10.0, -10.0)];
            // Free cells of the goal's region and of any, and points anywhere.
            let reachable = grid.region_cells(grid.region_at(goal).expect("a region"));
            let free: Vec<usize> = (0..cols * rows)
                .filter(|&i| grid.is_free_index(i))
                .collect();
            for k in 0..25 {
                let cell = reachable[(k * 7919 + seed as usize * 131) % reachable.len()] as usize;
                starts.push(grid.center(cell % cols, cell / cols) + Vector::new(1.3, -0.7));
            }
            for k in 0..8 {
                let cell = free[(k * 104_729 + seed as usize * 17) % free.len()];
                starts.push(grid.center(cell % cols, cell / cols) + Vector::new(-2.1, 0.4));
                let (x, y) = ((k * 379 + 61) % 1000, (k * 617 + 233) % 1000);
                starts.push(Point::new(
                    scene.width() * x as f64 / 1000.0,
                    scene.height() * y as f64 / 1000.0,
                ));
            }
            for close_cost in [1.0, 4.0] {
                let field = DistanceField::new(scene, grid, goal, 5.0, close_cost);
                for &start in &starts {
                    let whole = field.path(scene, grid, start, 5.0);
                    let searched = grid_path(scene, grid, start, goal, 5.0, close_cost);
                    assert_eq!(
                        whole, searched,
                        "seed {seed} cost {close_cost} start {start}"
                    );
                    compared += 1;
                }
            }
        }
        assert!(compared > 1000, "{compared}");
    }

    /// A lazy field gives the whole field's distances, bit for bit, whatever order points are
    /// asked in: near the goal and far, in walls and outside the scene, mazes, warehouses and an
    /// image map, plain and wall-shy costs; and it searches a fraction of the grid for the
    /// start it heads for.
    #[test]
    fn a_lazy_field_gives_the_whole_fields_distances() {
        let (mut compared, mut searched, mut free) = (0, 0, 0);
        for (seed, world) in mixed_worlds(12) {
            let (scene, grid) = (world.scene(), world.grid());
            let Ok(episode) = world.episode(seed) else {
                continue;
            };
            let goal = episode.goal();
            let mut points = vec![goal, goal + Vector::new(3.0, 1.0), Point::new(-10.0, -10.0)];
            // A walk away from the goal a few px at a time, as a robot's poses come.
            for k in 0..300 {
                let t = f64::from(k) * 0.02;
                points.push(
                    goal + Vector::new(3.0 * f64::from(k) * t.cos(), 2.5 * f64::from(k) * t.sin()),
                );
            }
            for k in 0..200u64 {
                let (x, y) = ((k * 379 + seed * 61) % 1013, (k * 617 + seed * 233) % 1009);
                points.push(Point::new(
                    scene.width() * x as f64 / 1000.0 - 2.0,
                    scene.height() * y as f64 / 1000.0 - 2.0,
                ));
            }
            for close_cost in [1.0, 4.0] {
                let whole = DistanceField::new(scene, grid, goal, 5.0, close_cost);
                let start = episode.start().position();
                let mut lazy = LazyField::new(scene, grid, goal, start, 5.0, close_cost);
                for q in [start, goal] {
                    assert_eq!(lazy.distance_at(grid, q), whole.distance_at(q));
                }
                searched += lazy.settled.iter().filter(|&&s| s).count();
                free += grid.free_count();
                for &p in &points {
                    assert_eq!(
                        lazy.distance_at(grid, p).map(f64::to_bits),
                        whole.distance_at(p).map(f64::to_bits),
                        "seed {seed} cost {close_cost} point {p}"
                    );
                    compared += 1;
                }
            }
        }
        assert!(compared > 5000, "{compared}");
        assert!(
            searched < free / 3,
            "the starts' distances searched {searched} of {free} cells"
        );
    }

    /// A lazy field steered after a robot that wanders off at random gives the whole field's
    /// distances at every pose, and settles fewer cells than one that kept heading for the start
    /// (under 30% of them over these 8 mazes, against 35% when never steered anew).
    #[test]
    fn a_lazy_field_follows_a_wandering_robot() {
        use crate::sim::{Action, DiscreteAction};
        let (mut steered, mut free) = (0, 0);
        for seed in 0..8u64 {
            let world = World::maze(ValidConfig::default(), seed);
            let mut episode = world.episode(seed).expect("placement");
            let grid = world.grid();
            let (start, goal) = (episode.pose().position(), episode.goal());
            let whole = DistanceField::new(world.scene(), grid, goal, 5.0, 1.0);
            let mut lazy = LazyField::new(world.scene(), grid, goal, start, 5.0, 1.0);
            let mut x = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
            for _ in 0..300 {
                let p = episode.pose().position();
                assert_eq!(
                    lazy.distance_at(grid, p),
                    whole.distance_at(p),
                    "seed {seed} at {p}"
                );
                if episode.status().is_done() {
                    break;
                }
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                let turn = [
                    DiscreteAction::Left,
                    DiscreteAction::Ahead,
                    DiscreteAction::Right,
                ];
                episode.step(Action::from(turn[(x % 3) as usize]));
            }
            steered += lazy.settled.iter().filter(|&&s| s).count();
            free += grid.free_count();
        }
        assert!(steered * 10 < free * 3, "settled {steered} of {free} cells");
    }

    /// A dropped lazy field's search goes back to its thread with every cell unreached and
    /// unmarked, however far it went and however often it was steered anew, and the next lazy
    /// field takes it up (in the test above, each maze's field takes up the last one's search).
    #[test]
    fn a_dropped_lazy_fields_search_is_left_clean() {
        LAZY_WORK.with_borrow_mut(Vec::clear);
        for (seed, world) in mixed_worlds(6) {
            let grid = world.grid();
            let Ok(episode) = world.episode(seed) else {
                continue;
            };
            let (start, goal) = (episode.start().position(), episode.goal());
            let mut lazy = LazyField::new(world.scene(), grid, goal, start, 5.0, 4.0);
            let (w, h) = (world.scene().width(), world.scene().height());
            for k in 0..12 {
                let p = Point::new(w * (k as f64 * 0.37 % 1.0), h * (k as f64 * 0.61 % 1.0));
                lazy.distance_at(grid, p);
            }
            assert!(lazy.settled.iter().any(|&s| s), "seed {seed}");
            drop(lazy);
            LAZY_WORK.with_borrow(|kept| {
                assert_eq!(kept.len(), 1, "seed {seed}");
                let (work, settled) = &kept[0];
                assert!(work.closed.is_empty());
                assert!(!settled.iter().any(|&s| s), "seed {seed}");
                assert!(
                    work.cells
                        .iter()
                        .all(|c| c.cost == u32::MAX && c.parent == ROOT),
                    "seed {seed}"
                );
            });
        }
    }
}
