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

/// Axis step cost, in the integer units of the search (see [`Work::search`]).
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
    /// The step costs of the search under way.
    steps: Steps,
    /// The length of [`Work::front`]'s ring.
    ring: usize,
    /// The sum (cost plus least distance) a steered search settles next: every cell whose sum
    /// is less is settled.
    current: u32,
    /// The bucket of `current`: `current % ring`.
    slot: usize,
    /// How many entries wait in the ring.
    pending: usize,
    /// The cell (column, row) a steered search heads for.
    from: (u32, u32),
    /// What [`Work::least`] takes off the octile distance to `from`: [`ENTRY_SLACK`] for
    /// [`Work::bound`], whose start enters the grid anywhere around its cell; nothing for a
    /// [`LazyField`].
    slack: u32,
    /// [`Work::bound`]'s ring of buckets: cells by cost plus least distance to the start
    /// modulo the ring's length.
    front: Vec<Vec<u32>>,
    /// The cells [`Work::bound`] settled; a [`LazyField`]'s, every cell it has settled.
    closed: Vec<u32>,
    /// The cells [`Work::narrow`] keeps.
    shortest: Vec<u32>,
    /// Whether every cell is unreached ([`UNREACHED`]): what [`Work::bound`] needs, left so by
    /// [`Work::tidy`] at the cost of the cells it touched rather than of all.
    clean: bool,
}

/// What a steered search ([`Work::settle_steered`]) tells as it goes, and asks.
trait Steer {
    /// Cell `i`, at column `c` and row `r`, has just been settled at `cost`.
    fn settled(&mut self, i: usize, c: u32, r: u32, cost: u32);
    /// Whether to stop, every cell whose cost plus least distance is at most `current` being
    /// settled.
    fn stop(&mut self, cells: &[Node], current: u32) -> bool;
}

/// [`Work::bound`]'s steer: on until no target left could begin a shorter path than the best
/// through one settled.
struct Entries<'a> {
    /// The start's entries to the grid: cells and their straight line from the start, px.
    targets: &'a [(usize, f64)],
    /// The start's cell.
    from: (u32, u32),
    px_per_unit: f64,
    /// The best path through a settled target so far, px (a start's straight line plus its
    /// cell's cost).
    best: f64,
}

impl Steer for Entries<'_> {
    #[inline(always)]
    fn settled(&mut self, i: usize, c: u32, r: u32, cost: u32) {
        let (fc, fr) = self.from;
        if c.abs_diff(fc) <= ATTACH_CELLS as u32 && r.abs_diff(fr) <= ATTACH_CELLS as u32 {
            for &(t, d) in self.targets {
                if t == i {
                    self.best = self.best.min(d + cost as f64 * self.px_per_unit);
                }
            }
        }
    }

    #[inline(always)]
    fn stop(&mut self, cells: &[Node], current: u32) -> bool {
        // A target's least distance is nothing, so one not yet settled costs at least
        // `current + 1` units.
        let floor = (current + 1) as f64 * self.px_per_unit;
        self.best.is_finite()
            && self
                .targets
                .iter()
                .all(|&(t, d)| cells[t].cost <= current || d + floor > self.best)
    }
}

/// [`LazyField`]'s steer: on until every cell whose cost plus least distance is below `until`
/// is settled, marking each in `settled`.
struct Until<'a> {
    until: u32,
    settled: &'a mut [bool],
}

impl Steer for Until<'_> {
    #[inline(always)]
    fn settled(&mut self, i: usize, _: u32, _: u32, _: u32) {
        self.settled[i] = true;
    }

    #[inline(always)]
    fn stop(&mut self, _: &[Node], current: u32) -> bool {
        current + 1 >= self.until
    }
}

/// [`Work::narrow`]'s mark on a cell it keeps (no cell is a parent of this index).
const MARKED: u32 = u32::MAX - 1;

/// The move back for each move E, W, N, S, NE, SE, NW, SW.
const REVERSE: [usize; 8] = [1, 0, 3, 2, 7, 6, 5, 4];

/// A cell not reached (yet).
const UNREACHED: Node = Node {
    cost: u32::MAX,
    parent: ROOT,
};

/// The most a lower bound on a cell's distance to a start allows for the start's entries lying
/// up to [`ATTACH_CELLS`] cells from its own cell, in units.
const ENTRY_SLACK: u32 = ATTACH_CELLS as u32 * DIAGONAL;

impl Work {
    /// Dijkstra from the cells the goal attaches to (`roots`, with their distances from the goal
    /// in px), by Dial's algorithm: integer step costs
    /// ([`AXIS`] along an axis, [`DIAGONAL`] on a diagonal) in a ring of buckets, so each cell is
    /// settled in O(1). The smoothed path, not this cost, is what gets measured, so the integer
    /// rounding does not reach any metric.
    ///
    /// It searches the cells whose cost starts at `u32::MAX`; a cell whose cost starts lower
    /// (nothing, say) keeps it, and so stays out of the search. A cell's parent is the first
    /// settled neighbour to offer its final cost, and cells of equal cost are settled in the
    /// order they were reached, so a cell's parent follows from the costs and the moves' order
    /// alone: it is the same whatever cells are left out, as long as every neighbour offering a
    /// searched cell its cost is searched too.
    fn search(&mut self, grid: &FreeGrid, roots: &[(usize, f64)], close_cost: f64) {
        self.set_steps(close_cost);
        let starts: Vec<(usize, u32)> = root_costs(grid, roots).collect();
        // Longer than any step and than the goal's attachments spread, so every cell in a bucket
        // costs the level being settled (or less, when improved since it was put there); a power
        // of two, so a cost's bucket is its low bits.
        let widest = starts.iter().map(|s| s.1).max().unwrap_or(0);
        let ring = (self.steps.longest().max(widest) as usize + 1).next_power_of_two();
        let mask = ring - 1;
        reset_ring(&mut self.buckets, ring);
        let (cells, buckets, steps) = (&mut self.cells, &mut self.buckets, &self.steps);
        for (i, c) in starts {
            if c < cells[i].cost {
                cells[i].cost = c;
                buckets[c as usize].push(i as u32);
            }
        }
        let n = cells.len();
        // As long as the cells, so a cell's index needs checking only once.
        let (moves, slow) = (&grid.moves()[..n], &grid.close_moves()[..n]);
        let offsets = grid.move_offsets();
        let mut current = 0u32;
        // Buckets found empty in a row: a whole ring of them, and no cell is left to settle.
        let mut idle = 0;
        let mut bucket = std::mem::take(&mut self.bucket);
        while idle < ring {
            let (cost, slot) = (current, current as usize & mask);
            current += 1;
            if buckets[slot].is_empty() {
                idle += 1;
                continue;
            }
            idle = 0;
            std::mem::swap(&mut bucket, &mut buckets[slot]);
            for &i in &bucket {
                let i = i as usize;
                if cells[i].cost != cost {
                    // Improved since it was put here, and settled then.
                    continue;
                }
                // Open moves as bits in the order E, W, N, S, NE, SE, NW, SW: the order decides
                // which of two equal-cost parents a cell keeps.
                let open = moves[i] as u32;
                let (slow, st) = steps.of(slow[i]);
                let mut better = improving(cells, i, cost, open, slow, st, &offsets);
                while better != 0 {
                    let k = better.trailing_zeros() as usize;
                    better &= better - 1;
                    let j = i.wrapping_add(offsets[k] as usize);
                    let to = cost + st[k];
                    cells[j] = Node {
                        cost: to,
                        parent: i as u32,
                    };
                    buckets[to as usize & mask].push(j as u32);
                }
            }
            bucket.clear();
        }
        self.bucket = bucket;
    }

    /// Settles the cells that a grid path from `start` (in cell `from`, entering the grid at
    /// `targets`: cells and their straight-line distance in px from `start`) could use, at their
    /// final costs, into [`Work::closed`]. Returns the costs, in units, of the targets it
    /// settled: those beyond could not begin the shortest path.
    ///
    /// This is A* from the goal's attachments, with [`Work::search`]'s step costs, steered by
    /// the octile distance to `from` less the most the targets allow ([`ENTRY_SLACK`]): never
    /// more than a cell's true distance to a target, and changing by at most a step's cost
    /// between neighbours, so a cell is settled at its final cost. It settles every cell whose
    /// cost plus that least distance is at most a bound, the cost of the best path through a
    /// target. A neighbour offering a cell on the path its cost has no larger a sum than that
    /// cell, so it is settled too, and so are those offering it theirs, down to the goal. The
    /// cells reached but not settled wait in [`Work::front`].
    fn bound(
        &mut self,
        grid: &FreeGrid,
        roots: &[(usize, f64)],
        close_cost: f64,
        from: (usize, usize),
        targets: &[(usize, f64)],
    ) -> Vec<Option<u32>> {
        let (cols, rows) = grid.size();
        if !self.clean || self.cells.len() != cols * rows {
            self.cells.clear();
            self.cells.resize(cols * rows, UNREACHED);
        }
        self.clean = false;
        self.closed.clear();
        self.slack = ENTRY_SLACK;
        self.begin_steered(grid, roots, close_cost, from);
        let mut entries = Entries {
            targets,
            from: (from.0 as u32, from.1 as u32),
            px_per_unit: grid.cell_px() / AXIS as f64,
            best: f64::INFINITY,
        };
        self.settle_steered(grid, &mut entries);
        // Every cell whose cost plus least distance is below `current` is settled; a target's
        // least distance is nothing.
        let current = self.current;
        targets
            .iter()
            .map(|&(t, _)| Some(self.cells[t].cost).filter(|&c| c < current))
            .collect()
    }

    /// The least a path from cell (`c`, `r`) to the cell a steered search heads for costs,
    /// less [`Work::slack`], in units: the octile distance, which changes by no more than a
    /// step's cost from a cell to its neighbour.
    fn least(&self, c: u32, r: u32) -> u32 {
        let (dc, dr) = (c.abs_diff(self.from.0), r.abs_diff(self.from.1));
        (AXIS * dc.max(dr) + (DIAGONAL - AXIS) * dc.min(dr)).saturating_sub(self.slack)
    }

    /// A steered search's start ([`Work::bound`]'s A*): the goal's attachments `roots` put in an
    /// empty ring by their cost plus least distance to cell `from`, nothing settled.
    fn begin_steered(
        &mut self,
        grid: &FreeGrid,
        roots: &[(usize, f64)],
        close_cost: f64,
        from: (usize, usize),
    ) {
        self.set_steps(close_cost);
        let mut starts = Vec::new();
        for (i, c) in root_costs(grid, roots) {
            if c < self.cells[i].cost {
                self.cells[i].cost = c;
                starts.push(i as u32);
            }
        }
        self.queue_steered(grid, &starts, from);
    }

    /// Puts `cells`, reached and not settled (each once), in an empty ring by their cost plus
    /// least distance to cell `from`: a steered search's start, or its front steered anew.
    fn queue_steered(&mut self, grid: &FreeGrid, cells: &[u32], from: (usize, usize)) {
        let cols = grid.size().0;
        self.from = (from.0 as u32, from.1 as u32);
        let starts: Vec<(u32, u32)> = cells
            .iter()
            .map(|&i| {
                let (col, row) = ((i as usize % cols) as u32, (i as usize / cols) as u32);
                (i, self.cells[i as usize].cost + self.least(col, row))
            })
            .collect();
        let current = starts.iter().map(|s| s.1).min().unwrap_or(0);
        // A step changes a cell's sum by 0 to twice its cost; the goal's attachments, or a front
        // steered anew, may spread wider than that.
        let widest = starts.iter().map(|s| s.1 - current).max().unwrap_or(0);
        self.ring = (2 * self.steps.longest()).max(widest) as usize + 1;
        reset_ring(&mut self.front, self.ring);
        for &(at, sum) in &starts {
            self.front[sum as usize % self.ring].push(at);
        }
        (self.current, self.slot, self.pending) =
            (current, current as usize % self.ring, starts.len());
    }

    /// Carries a steered search on, sum by sum, until `steer` says to stop or nothing is left:
    /// every cell whose cost plus least distance is below [`Work::current`] is then settled, at
    /// its final cost, and listed in [`Work::closed`]; the cells reached but not settled wait in
    /// [`Work::front`].
    fn settle_steered(&mut self, grid: &FreeGrid, steer: &mut impl Steer) {
        let cols = grid.size().0 as u32;
        let ring = self.ring;
        let (mut pending, mut current, mut slot) = (self.pending, self.current, self.slot);
        let ((fc, fr), slack) = (self.from, self.slack);
        // [`Work::least`], on copies the loop can keep in registers.
        let least = |c: u32, r: u32| {
            let (dc, dr) = (c.abs_diff(fc), r.abs_diff(fr));
            (AXIS * dc.max(dr) + (DIAGONAL - AXIS) * dc.min(dr)).saturating_sub(slack)
        };
        let (cells, closed, front) = (&mut self.cells, &mut self.closed, &mut self.front);
        let steps = &self.steps;
        let (moves, slow) = (grid.moves(), grid.close_moves());
        let offsets = grid.move_offsets();
        // Column and row changes of the moves E, W, N, S, NE, SE, NW, SW.
        const DC: [u32; 8] = [1, u32::MAX, 0, 0, 1, 1, u32::MAX, u32::MAX];
        const DR: [u32; 8] = [0, 0, 1, u32::MAX, 1, u32::MAX, 1, u32::MAX];
        while pending > 0 {
            // A push lands 0 to `ring - 1` sums ahead: one at the sum being settled (a step
            // towards the start often keeps it) joins the end of this bucket, which is read to
            // its end, without a branch on which (one the processor would often guess wrong).
            let mut n = 0;
            while let Some(i) = front[slot].get(n).copied() {
                n += 1;
                pending -= 1;
                let (r, c) = (i / cols, i % cols);
                let i = i as usize;
                let cost = cells[i].cost;
                // The ring is wider than any push is ahead, so a bucket holds one sum (or less,
                // for a cell improved since it was put there).
                debug_assert!(cost + least(c, r) <= current);
                if cost + least(c, r) < current {
                    continue;
                }
                closed.push(i as u32);
                let open = moves[i] as u32;
                let (slow, st) = steps.of(slow[i]);
                let mut better = improving(cells, i, cost, open, slow, st, &offsets);
                while better != 0 {
                    let k = better.trailing_zeros() as usize;
                    better &= better - 1;
                    let j = i.wrapping_add(offsets[k] as usize);
                    let nd = cost + st[k];
                    cells[j].cost = nd;
                    let (nc, nr) = (c.wrapping_add(DC[k]), r.wrapping_add(DR[k]));
                    let ahead = (nd + least(nc, nr) - current) as usize;
                    let mut to = slot + ahead;
                    if to >= ring {
                        to -= ring;
                    }
                    front[to].push(j as u32);
                    pending += 1;
                }
                steer.settled(i, c, r, cost);
            }
            front[slot].clear();
            let stop = steer.stop(cells, current);
            current += 1;
            slot += 1;
            if slot == ring {
                slot = 0;
            }
            if stop {
                break;
            }
        }
        (self.pending, self.current, self.slot) = (pending, current, slot);
    }

    /// Readies [`Work::cells`], after [`Work::bound`], for a [`Work::search`] over just the
    /// cells on the shortest paths from the goal to cell `to` (settled by the bound): `to` and,
    /// in turn, every neighbour that offers a cell in the set its cost. Their costs are left
    /// unknown; other settled cells keep their final costs, and cells still waiting in the ring
    /// cost nothing, so the search goes no further. The search gives each of them the parent
    /// the whole field does: a cell's parent is one of those neighbours, and which one follows
    /// from how they were reached, in turn, down to the goal.
    fn narrow(&mut self, grid: &FreeGrid, to: usize, close_cost: f64) {
        let steps = step_costs(close_cost);
        let (moves, slow) = (grid.moves(), grid.close_moves());
        let offsets = grid.move_offsets();
        let (cells, shortest) = (&mut self.cells, &mut self.shortest);
        shortest.clear();
        shortest.push(to as u32);
        cells[to].parent = MARKED;
        let mut n = 0;
        while let Some(&j) = shortest.get(n) {
            n += 1;
            let j = j as usize;
            let cost = cells[j].cost;
            let mut todo = moves[j] as u32;
            while todo != 0 {
                let k = todo.trailing_zeros() as usize;
                todo &= todo - 1;
                // The neighbour that way, and its move back here.
                let i = j.wrapping_add(offsets[k] as usize);
                let back = REVERSE[k];
                if moves[i] >> back & 1 == 1
                    && cells[i].parent != MARKED
                    && cells[i]
                        .cost
                        .checked_add(steps[(slow[i] >> back & 1) as usize][back])
                        == Some(cost)
                {
                    cells[i].parent = MARKED;
                    shortest.push(i as u32);
                }
            }
        }
        // Settled cells outside the set keep their costs, which no step betters; cells with an
        // entry still in the ring (those reached but not settled, and settled ones with a stale
        // entry, reset just after if in the set) cost nothing, so the search stops there.
        for &i in self.front.iter().flatten() {
            cells[i as usize].cost = 0;
        }
        for &i in shortest.iter() {
            cells[i as usize] = UNREACHED;
        }
    }

    /// Makes [`Work::steps`] those of `close_cost`, building their table only when they change.
    fn set_steps(&mut self, close_cost: f64) {
        if self.steps.pair != step_costs(close_cost) {
            self.steps = Steps::new(close_cost);
        }
    }

    /// Leaves every cell unreached again after a [`Work::bound`] and [`Work::search`], or a
    /// [`LazyField`]'s searches: only the cells they reached, which wait in the ring or are
    /// settled.
    fn tidy(&mut self) {
        for &i in self.front.iter().flatten() {
            self.cells[i as usize] = UNREACHED;
        }
        for &i in &self.closed {
            self.cells[i as usize] = UNREACHED;
        }
        self.clean = true;
    }
}

/// Step costs by move (E, W, N, S, NE, SE, NW, SW), plain and from or into a close cell: those
/// cost `close_cost` times as much, rounded, and at least as much as plain ones.
fn step_costs(close_cost: f64) -> [[u32; 8]; 2] {
    let close = close_cost.max(1.0).round() as u32;
    [STEP, STEP.map(|s| s * close)]
}

/// The cells the goal attaches to (`roots`, with their distances from the goal in px) and those
/// distances in the searches' units, rounded: where both searches start.
fn root_costs<'a>(
    grid: &FreeGrid,
    roots: &'a [(usize, f64)],
) -> impl Iterator<Item = (usize, u32)> + 'a {
    let units_per_px = AXIS as f64 / grid.cell_px();
    roots
        .iter()
        .map(move |&(i, d)| (i, (d * units_per_px).round() as u32))
}

/// Step costs by move (E, W, N, S, NE, SE, NW, SW) for a cell, whatever its close moves.
struct Steps {
    /// Plain, and from or into a close cell (see [`step_costs`]).
    pair: [[u32; 8]; 2],
    /// Row `slow`: the step costs from a cell whose close moves are the bits of `slow`, so a
    /// move's cost is one look-up rather than a pick between the two.
    by_close: Box<[[u32; 8]; 256]>,
    /// What of a cell's close moves matters: all of them, or none when close steps cost what
    /// plain ones do (every cell inside the grid then takes [`improving`]'s quickest way).
    close_mask: u8,
}

impl Steps {
    fn new(close_cost: f64) -> Self {
        let pair = step_costs(close_cost);
        let by_close = Box::new(std::array::from_fn(|slow| {
            std::array::from_fn(|k| pair[slow >> k & 1][k])
        }));
        let close_mask = if pair[0] == pair[1] { 0 } else { u8::MAX };
        Self {
            pair,
            by_close,
            close_mask,
        }
    }

    /// The longest step: a diagonal from or into a close cell.
    fn longest(&self) -> u32 {
        self.pair[1][7]
    }

    /// Of a cell whose close moves are the bits of `close`, those that matter, and its moves'
    /// step costs.
    #[inline(always)]
    fn of(&self, close: u8) -> (u8, &[u32; 8]) {
        let slow = close & self.close_mask;
        (slow, &self.by_close[usize::from(slow)])
    }
}

impl Default for Steps {
    fn default() -> Self {
        Self::new(1.0)
    }
}

/// Which open moves from cell `i` (at `cost`; `open` and `slow` its open and close moves as
/// bits, `st` its moves' step costs) improve the cell they reach, as bits. Found for all eight
/// before any is taken (they reach eight different cells), without a branch on each: whether a
/// neighbour improves is a coin toss to the branch predictor.
#[inline(always)]
fn improving(
    cells: &[Node],
    i: usize,
    cost: u32,
    open: u32,
    slow: u8,
    st: &[u32; 8],
    offsets: &[isize; 8],
) -> u32 {
    // Most cells lie inside the grid: their three rows of neighbours are read whole, and the
    // closed moves masked off at the end.
    let w = offsets[2] as usize;
    if i > w && i + w + 1 < cells.len() {
        let rows = (
            <&[Node; 3]>::try_from(&cells[i - w - 1..i - w + 2]),
            <&[Node; 3]>::try_from(&cells[i - 1..i + 2]),
            <&[Node; 3]>::try_from(&cells[i + w - 1..i + w + 2]),
        );
        if let (Ok(south), Ok(row), Ok(north)) = rows {
            if slow == 0 {
                // No close move: two offers, in registers.
                let (axis, diagonal) = (cost + st[0], cost + st[4]);
                let lt = |step: u32, node: &Node, k: u32| u32::from(step < node.cost) << k;
                return open
                    & (lt(axis, &row[2], 0)
                        | lt(axis, &row[0], 1)
                        | lt(axis, &north[1], 2)
                        | lt(axis, &south[1], 3)
                        | lt(diagonal, &north[2], 4)
                        | lt(diagonal, &south[2], 5)
                        | lt(diagonal, &north[0], 6)
                        | lt(diagonal, &south[0], 7));
            }
            let lt = |k: usize, node: &Node| u32::from(cost + st[k] < node.cost) << k;
            return open
                & (lt(0, &row[2])
                    | lt(1, &row[0])
                    | lt(2, &north[1])
                    | lt(3, &south[1])
                    | lt(4, &north[2])
                    | lt(5, &south[2])
                    | lt(6, &north[0])
                    | lt(7, &south[0]));
        }
    }
    improving_each(cells, i, cost, open, st, offsets)
}

/// [`improving`] one move at a time, for any cell: a closed move looks at the cell itself, which
/// never improves (every step costs more than nothing).
#[inline(always)]
fn improving_each(
    cells: &[Node],
    i: usize,
    cost: u32,
    open: u32,
    st: &[u32; 8],
    offsets: &[isize; 8],
) -> u32 {
    let mut better = 0u32;
    for k in 0..8 {
        let mask = ((open as usize >> k) & 1).wrapping_neg();
        let j = i.wrapping_add(offsets[k] as usize & mask);
        better |= u32::from(cost + st[k] < cells[j].cost) << k;
    }
    better
}

/// Empties `buckets` and makes them `ring` long.
fn reset_ring(buckets: &mut Vec<Vec<u32>>, ring: usize) {
    buckets.resize_with(ring, Vec::new);
    buckets.truncate(ring);
    buckets.iter_mut().for_each(Vec::clear);
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
    use crate::sim::world::World;
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
                        improving(&cells, i, cell.cost, open, slow, st, &offsets),
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
        use crate::sim::robot::{Action, DiscreteAction};
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
