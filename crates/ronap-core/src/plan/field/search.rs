//! The search under every field and path: Dijkstra over the free-space grid in integer step
//! costs with a ring of buckets, optionally steered (A*) towards a point, with each thread's
//! buffers kept between searches.

use super::*;

/// Axis step cost, in the integer units of the search (see [`Work::search`]).
pub(super) const AXIS: u32 = 12;
/// Diagonal step cost (within 0.2% of 12 sqrt 2).
pub(super) const DIAGONAL: u32 = 17;
/// Step costs of the moves E, W, N, S, NE, SE, NW, SW.
pub(super) const STEP: [u32; 8] = [
    AXIS, AXIS, AXIS, AXIS, DIAGONAL, DIAGONAL, DIAGONAL, DIAGONAL,
];

thread_local! {
    /// Each thread's search buffers for [`grid_path`] and [`DistanceField::new`].
    pub(super) static WORK: std::cell::RefCell<Work> = std::cell::RefCell::default();
}

/// A cell of the search: its cost to the goal in units ([`AXIS`] per cell side; `u32::MAX` where
/// not reached) and the next cell towards the goal (or [`ROOT`]).
#[derive(Clone, Copy, Debug)]
pub(super) struct Node {
    pub(super) cost: u32,
    pub(super) parent: u32,
}

/// The search's buffers, reusable between searches over grids of any size.
#[derive(Default)]
pub(super) struct Work {
    /// Per cell, its cost and parent side by side: a settled cell reads its neighbours' costs
    /// and writes cost and parent of those it improves, over a front spread across the whole
    /// grid, so one cache line a cell rather than two (apart, they measured slower).
    pub(super) cells: Vec<Node>,
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
    pub(super) current: u32,
    /// The bucket of `current`: `current % ring`.
    slot: usize,
    /// How many entries wait in the ring.
    pub(super) pending: usize,
    /// The cell (column, row) a steered search heads for.
    pub(super) from: (u32, u32),
    /// What [`Work::least`] takes off the octile distance to `from`: [`ENTRY_SLACK`] for
    /// [`Work::bound`], whose start enters the grid anywhere around its cell; nothing for a
    /// [`LazyField`].
    pub(super) slack: u32,
    /// [`Work::bound`]'s ring of buckets: cells by cost plus least distance to the start
    /// modulo the ring's length.
    pub(super) front: Vec<Vec<u32>>,
    /// The cells [`Work::bound`] settled; a [`LazyField`]'s, every cell it has settled.
    pub(super) closed: Vec<u32>,
    /// The cells [`Work::narrow`] keeps.
    shortest: Vec<u32>,
    /// Whether every cell is unreached ([`UNREACHED`]): what [`Work::bound`] needs, left so by
    /// [`Work::tidy`] at the cost of the cells it touched rather than of all.
    clean: bool,
}

/// What a steered search ([`Work::settle_steered`]) tells as it goes, and asks.
pub(super) trait Steer {
    /// Cell `i`, at column `c` and row `r`, has just been settled at `cost`.
    fn settled(&mut self, i: usize, c: u32, r: u32, cost: u32);
    /// Whether to stop, every cell whose cost plus least distance is at most `current` being
    /// settled.
    fn stop(&mut self, cells: &[Node], current: u32) -> bool;
}

/// [`Work::bound`]'s steer: on until no target left could begin a shorter path than the best
/// through one settled.
pub(super) struct Entries<'a> {
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
pub(super) struct Until<'a> {
    pub(super) until: u32,
    pub(super) settled: &'a mut [bool],
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
pub(super) const MARKED: u32 = u32::MAX - 1;

/// The move back for each move E, W, N, S, NE, SE, NW, SW.
pub(super) const REVERSE: [usize; 8] = [1, 0, 3, 2, 7, 6, 5, 4];

/// A cell not reached (yet).
pub(super) const UNREACHED: Node = Node {
    cost: u32::MAX,
    parent: ROOT,
};

/// The most a lower bound on a cell's distance to a start allows for the start's entries lying
/// up to [`ATTACH_CELLS`] cells from its own cell, in units.
pub(super) const ENTRY_SLACK: u32 = ATTACH_CELLS as u32 * DIAGONAL;

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
    pub(super) fn search(&mut self, grid: &FreeGrid, roots: &[(usize, f64)], close_cost: f64) {
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
        let moves = Moves {
            open: &grid.moves()[..n],
            close: &grid.close_moves()[..n],
            offsets: grid.move_offsets(),
        };
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
                // The moves' order decides which of two equal-cost parents a cell keeps.
                for (_, j, step) in moves.improving(cells, i, steps) {
                    let to = cost + step;
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
    pub(super) fn bound(
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
    pub(super) fn least(&self, c: u32, r: u32) -> u32 {
        let (dc, dr) = (c.abs_diff(self.from.0), r.abs_diff(self.from.1));
        (AXIS * dc.max(dr) + (DIAGONAL - AXIS) * dc.min(dr)).saturating_sub(self.slack)
    }

    /// A steered search's start ([`Work::bound`]'s A*): the goal's attachments `roots` put in an
    /// empty ring by their cost plus least distance to cell `from`, nothing settled.
    pub(super) fn begin_steered(
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
    pub(super) fn queue_steered(&mut self, grid: &FreeGrid, cells: &[u32], from: (usize, usize)) {
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
    pub(super) fn settle_steered(&mut self, grid: &FreeGrid, steer: &mut impl Steer) {
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
        let moves = Moves {
            open: grid.moves(),
            close: grid.close_moves(),
            offsets: grid.move_offsets(),
        };
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
                for (k, j, step) in moves.improving(cells, i, steps) {
                    let nd = cost + step;
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
    pub(super) fn narrow(&mut self, grid: &FreeGrid, to: usize, close_cost: f64) {
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
    pub(super) fn set_steps(&mut self, close_cost: f64) {
        if self.steps.pair != step_costs(close_cost) {
            self.steps = Steps::new(close_cost);
        }
    }

    /// Leaves every cell unreached again after a [`Work::bound`] and [`Work::search`], or a
    /// [`LazyField`]'s searches: only the cells they reached, which wait in the ring or are
    /// settled.
    pub(super) fn tidy(&mut self) {
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
pub(super) fn step_costs(close_cost: f64) -> [[u32; 8]; 2] {
    let close = close_cost.max(1.0).round() as u32;
    [STEP, STEP.map(|s| s * close)]
}

/// The cells the goal attaches to (`roots`, with their distances from the goal in px) and those
/// distances in the searches' units, rounded: where both searches start.
pub(super) fn root_costs<'a>(
    grid: &FreeGrid,
    roots: &'a [(usize, f64)],
) -> impl Iterator<Item = (usize, u32)> + 'a {
    let units_per_px = AXIS as f64 / grid.cell_px();
    roots
        .iter()
        .map(move |&(i, d)| (i, (d * units_per_px).round() as u32))
}

/// Step costs by move (E, W, N, S, NE, SE, NW, SW) for a cell, whatever its close moves.
pub(super) struct Steps {
    /// Plain, and from or into a close cell (see [`step_costs`]).
    pub(super) pair: [[u32; 8]; 2],
    /// Row `slow`: the step costs from a cell whose close moves are the bits of `slow`, so a
    /// move's cost is one look-up rather than a pick between the two.
    pub(super) by_close: Box<[[u32; 8]; 256]>,
    /// What of a cell's close moves matters: all of them, or none when close steps cost what
    /// plain ones do (every cell inside the grid then takes [`improving`]'s quickest way).
    close_mask: u8,
}

impl Steps {
    pub(super) fn new(close_cost: f64) -> Self {
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
    pub(super) fn longest(&self) -> u32 {
        self.pair[1][7]
    }

    /// Of a cell whose close moves are the bits of `close`, those that matter, and its moves'
    /// step costs.
    #[inline(always)]
    pub(super) fn of(&self, close: u8) -> (u8, &[u32; 8]) {
        let slow = close & self.close_mask;
        (slow, &self.by_close[usize::from(slow)])
    }
}

impl Default for Steps {
    fn default() -> Self {
        Self::new(1.0)
    }
}

/// A grid's moves as the searches read them: each cell's open and close moves, as bits in the
/// order E, W, N, S, NE, SE, NW, SW, and each move's offset in the cells.
#[derive(Clone, Copy)]
struct Moves<'a> {
    open: &'a [u8],
    close: &'a [u8],
    offsets: [isize; 8],
}

impl Moves<'_> {
    /// The open moves from cell `i` that improve the cell they reach ([`improving`]), in the
    /// moves' order, with their step costs under `steps`.
    #[inline(always)]
    fn improving<'s>(&self, cells: &[Node], i: usize, steps: &'s Steps) -> Improving<'s> {
        let (slow, st) = steps.of(self.close[i]);
        let open = u32::from(self.open[i]);
        Improving {
            better: improving(cells, i, open, slow, st, &self.offsets),
            i,
            offsets: self.offsets,
            st,
        }
    }
}

/// [`Moves::improving`]'s moves: each as its index `k`, the cell it reaches and its step cost.
struct Improving<'s> {
    better: u32,
    i: usize,
    offsets: [isize; 8],
    st: &'s [u32; 8],
}

impl Iterator for Improving<'_> {
    type Item = (usize, usize, u32);

    #[inline(always)]
    fn next(&mut self) -> Option<Self::Item> {
        if self.better == 0 {
            return None;
        }
        let k = self.better.trailing_zeros() as usize;
        self.better &= self.better - 1;
        Some((k, self.i.wrapping_add(self.offsets[k] as usize), self.st[k]))
    }
}

/// Which open moves from cell `i` (at its cost; `open` and `slow` its open and close moves as
/// bits, `st` its moves' step costs) improve the cell they reach, as bits. Found for all eight
/// before any is taken (they reach eight different cells), without a branch on each: whether a
/// neighbour improves is a coin toss to the branch predictor.
#[inline(always)]
pub(super) fn improving(
    cells: &[Node],
    i: usize,
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
            let cost = row[1].cost;
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
    improving_each(cells, i, cells[i].cost, open, st, offsets)
}

/// [`improving`] one move at a time, for any cell: a closed move looks at the cell itself, which
/// never improves (every step costs more than nothing).
#[inline(always)]
pub(super) fn improving_each(
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
pub(super) fn reset_ring(buckets: &mut Vec<Vec<u32>>, ring: usize) {
    buckets.resize_with(ring, Vec::new);
    buckets.truncate(ring);
    buckets.iter_mut().for_each(Vec::clear);
}
