//! Prioritised planning in space and time (cooperative A*): robots are planned one after the
//! other on the [`PlanGrid`], each around the cells the robots before it reserved at each tick.
//!
//! Two robots never hold one cell within a tick of each other: a cell a robot leaves at tick
//! `t` is free to another from tick `t + 2` (so the first has finished its move out before the
//! second starts its move in), and two diagonal moves never cross the same corner within a tick.
//! Followed in that order rather than to the tick (see [`super::Schedule`]), such a plan keeps
//! the robots apart whatever their delays.

use super::grid::PlanGrid;
use rand::seq::SliceRandom;
use std::collections::{BinaryHeap, HashMap};
use std::hash::{BuildHasherDefault, Hasher};

/// What one robot must do: from its start cell through its goal cells in order.
#[derive(Clone, Debug, PartialEq)]
pub struct Task {
    /// Its start cell.
    pub start: usize,
    /// Its goal cells, in visiting order.
    pub goals: Vec<usize>,
    /// Whether it leaves the scene at its last goal (else it stays there).
    pub vanish: bool,
}

/// One stop of a robot's plan: a cell it moves to, and the ticks it holds it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Stop {
    /// The cell.
    pub cell: usize,
    /// The tick it arrives there (0 for the start).
    pub arrive: u32,
    /// The last tick it is there (`u32::MAX` at a last goal it stays on).
    pub leave: u32,
    /// The index of the goal it reaches there, if one.
    pub goal: Option<usize>,
    /// The corner its move here crosses, for a diagonal move.
    pub corner: Option<usize>,
}

/// Why a team could not be planned.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PlanFailure {
    /// The robot that found no plan around the others in the last order tried.
    pub robot: usize,
    /// Orders tried.
    pub attempts: u32,
}

/// How hard the planner tries.
#[derive(Clone, Copy, Debug)]
pub struct Limits {
    /// Priority orders to try before giving up.
    pub attempts: u32,
    /// States one robot's search may expand.
    pub expansions: usize,
}

impl Default for Limits {
    fn default() -> Self {
        Self {
            attempts: 12,
            expansions: 400_000,
        }
    }
}

/// A hasher for keys that are already well spread: `(tick << 32) | cell`.
#[derive(Default)]
struct KeyHasher(u64);

impl Hasher for KeyHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0 ^ u64::from(b)).wrapping_mul(0x100_0000_01b3);
        }
    }
    fn write_u64(&mut self, k: u64) {
        // Fibonacci hashing, then the high bits folded down for the table's low-bit buckets.
        let h = k.wrapping_mul(0x9E37_79B9_7F4A_7C15);
        self.0 = h ^ (h >> 29);
    }
}

type KeyMap<V> = HashMap<u64, V, BuildHasherDefault<KeyHasher>>;

fn key(t: u32, i: usize) -> u64 {
    (u64::from(t) << 32) | i as u64
}

/// What the robots planned so far hold.
#[derive(Default)]
struct Reservations {
    /// The robot at each `(tick, cell)`.
    cells: KeyMap<u32>,
    /// The robot crossing each `(tick of departure, corner)`.
    corners: KeyMap<u32>,
    /// The tick from which a robot stays on each cell for good, and which robot.
    parked: Vec<(u32, u32)>,
    /// The last tick any robot holds each cell (before staying for good).
    last: Vec<u32>,
}

impl Reservations {
    fn new(cells: usize) -> Self {
        Self {
            parked: vec![(u32::MAX, u32::MAX); cells],
            last: vec![0; cells],
            ..Default::default()
        }
    }

    /// Whether robot `me` may be on cell `i` at tick `t`.
    fn cell_open(&self, i: usize, t: u32, me: u32) -> bool {
        let (from, by) = self.parked[i];
        if by != me && t.saturating_add(1) >= from {
            return false;
        }
        (t.saturating_sub(1)..=t + 1).all(|u| self.cells.get(&key(u, i)).is_none_or(|&r| r == me))
    }

    /// Whether robot `me` may cross corner `c` leaving at tick `t`.
    fn corner_open(&self, c: usize, t: u32, me: u32) -> bool {
        (t.saturating_sub(1)..=t + 1).all(|u| self.corners.get(&key(u, c)).is_none_or(|&r| r == me))
    }

    fn hold(&mut self, i: usize, t: u32, me: u32) {
        self.cells.insert(key(t, i), me);
        self.last[i] = self.last[i].max(t);
    }
}

#[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
struct Open {
    /// For the max-heap: least ticks to the goal, then least length to the goal (its octile
    /// estimate: straight ways first among the many of equal ticks on a grid), both negated;
    /// then the latest.
    f: std::cmp::Reverse<(u32, u32)>,
    t: u32,
    node: u32,
}

struct Node {
    cell: usize,
    t: u32,
    parent: u32,
    /// The move that led here (8: a wait or the start).
    how: u8,
}

/// Cost of a move in thousandths of a cell: straight, diagonal, wait.
fn move_length(how: usize) -> u32 {
    match how {
        0..=3 => 1000,
        4..=7 => 1414,
        _ => 0,
    }
}

/// One robot's search among the reservations of those planned before it.
struct Search<'a> {
    grid: &'a PlanGrid,
    res: &'a Reservations,
    me: u32,
    limits: &'a Limits,
}

impl Search<'_> {
    /// The leg from `from` at tick `t0` to `goal` (`h`: each cell's moves to it); `park`: the
    /// robot stays on the goal for good, so no one may come there later. The cells of each tick
    /// from `t0` on, with the move taken into each (8 for a wait).
    fn leg(
        &self,
        from: usize,
        t0: u32,
        goal: usize,
        park: bool,
        h: &[u32],
    ) -> Option<Vec<(usize, u8)>> {
        let res = self.res;
        if h[from] == u32::MAX {
            return None;
        }
        let earliest = if park {
            res.last[goal].saturating_add(2)
        } else {
            0
        };
        let horizon = t0 + 2 * h[from] + 64 + earliest.saturating_sub(t0);
        // The length of a straight and diagonal way to the goal, thousandths of a cell.
        let (cols, _) = self.grid.size();
        let octile = |i: usize| -> u32 {
            let dx = (i % cols).abs_diff(goal % cols) as u32;
            let dy = (i / cols).abs_diff(goal / cols) as u32;
            1000 * dx.max(dy) + 414 * dx.min(dy)
        };
        let mut nodes = vec![Node {
            cell: from,
            t: t0,
            parent: u32::MAX,
            how: 8,
        }];
        let mut lengths = vec![0u32];
        let mut seen: KeyMap<()> = KeyMap::default();
        let mut open = BinaryHeap::new();
        open.push(Open {
            f: std::cmp::Reverse((t0 + h[from], octile(from))),
            t: t0,
            node: 0,
        });
        let mut expanded = 0usize;
        while let Some(Open { node, .. }) = open.pop() {
            let (cell, t) = (nodes[node as usize].cell, nodes[node as usize].t);
            if seen.insert(key(t, cell), ()).is_some() {
                continue;
            }
            if cell == goal && t >= earliest && (!park || res.parked[goal].0 == u32::MAX) {
                let mut out = Vec::new();
                let mut n = node;
                while n != u32::MAX {
                    let x = &nodes[n as usize];
                    out.push((x.cell, x.how));
                    n = x.parent;
                }
                out.reverse();
                return Some(out);
            }
            expanded += 1;
            if expanded > self.limits.expansions {
                return None;
            }
            if t >= horizon {
                continue;
            }
            let len = lengths[node as usize];
            let mut push = |to: usize, how: usize| {
                if h[to] == u32::MAX || seen.contains_key(&key(t + 1, to)) {
                    return;
                }
                let l = len + move_length(how);
                nodes.push(Node {
                    cell: to,
                    t: t + 1,
                    parent: node,
                    how: how as u8,
                });
                lengths.push(l);
                open.push(Open {
                    f: std::cmp::Reverse((t + 1 + h[to], l + octile(to))),
                    t: t + 1,
                    node: (nodes.len() - 1) as u32,
                });
            };
            if res.cell_open(cell, t + 1, self.me) {
                push(cell, 8);
            }
            for (d, j) in self.grid.neighbours(cell) {
                if !res.cell_open(j, t + 1, self.me) {
                    continue;
                }
                if let Some(c) = self.grid.corner(cell, d) {
                    if !res.corner_open(c, t, self.me) {
                        continue;
                    }
                }
                push(j, d);
            }
        }
        None
    }

    /// Every leg of `task` (`h[g]`: each cell's moves to goal `g`), tick by tick from 0; `None`
    /// when a leg finds no way.
    fn robot(&self, task: &Task, h: &[&[u32]]) -> Option<Vec<(usize, u8)>> {
        let mut ticks: Vec<(usize, u8)> = vec![(task.start, 8)];
        let mut at = task.start;
        for (g, &goal) in task.goals.iter().enumerate() {
            let last = g + 1 == task.goals.len();
            let t0 = (ticks.len() - 1) as u32;
            let steps = self.leg(at, t0, goal, last && !task.vanish, h[g])?;
            ticks.extend_from_slice(&steps[1..]);
            at = goal;
        }
        Some(ticks)
    }
}

/// The stops of a robot's tick-by-tick plan (waits folded into the stop before), each goal
/// marked at the first stop on its cell after the goal before.
pub(super) fn stops(grid: &PlanGrid, task: &Task, ticks: &[(usize, u8)]) -> Vec<Stop> {
    let mut out: Vec<Stop> = Vec::new();
    for (t, &(cell, how)) in ticks.iter().enumerate() {
        let t = t as u32;
        match out.last_mut() {
            Some(s) if how == 8 => s.leave = t,
            last => {
                let corner = last.and_then(|prev| grid.corner(prev.cell, usize::from(how)));
                out.push(Stop {
                    cell,
                    arrive: t,
                    leave: t,
                    goal: None,
                    corner,
                });
            }
        }
    }
    let mut from = 0usize;
    for (g, &goal) in task.goals.iter().enumerate() {
        if let Some(k) = (from..out.len()).find(|&k| out[k].cell == goal) {
            out[k].goal = Some(g);
            from = k;
        }
    }
    if let Some(last) = out.last_mut() {
        if !task.vanish {
            last.leave = u32::MAX;
        }
    }
    out
}

/// Plans every robot of `tasks` on `grid`: robots in an order of priority (the longest way
/// first; then the robot that failed moved to the front; then orders drawn from `rng`), each
/// around those before it and clear of the `blocked` cells. The stops of each robot's plan, or the robot that found no way in
/// the last order tried.
pub fn plan_team(
    grid: &PlanGrid,
    tasks: &[Task],
    blocked: &[usize],
    limits: &Limits,
    rng: &mut impl rand::Rng,
) -> Result<Vec<Vec<Stop>>, PlanFailure> {
    // Each goal's table of moves to it, shared by the robots with that goal.
    let mut tables: HashMap<usize, Vec<u32>> = HashMap::new();
    for t in tasks {
        for &g in &t.goals {
            tables.entry(g).or_insert_with(|| grid.moves_to(g));
        }
    }
    let h_of = |k: usize| -> Vec<&[u32]> {
        tasks[k]
            .goals
            .iter()
            .map(|g| tables[g].as_slice())
            .collect()
    };
    let way = |k: usize| -> u64 {
        let mut at = tasks[k].start;
        let mut sum = 0u64;
        for &goal in &tasks[k].goals {
            sum += u64::from(tables[&goal][at]);
            at = goal;
        }
        sum
    };
    let mut order: Vec<usize> = (0..tasks.len()).collect();
    order.sort_by_key(|&k| std::cmp::Reverse(way(k)));
    let mut failed = 0usize;
    for attempt in 0..limits.attempts.max(1) {
        if attempt > 0 && attempt < 4 {
            if let Some(p) = order.iter().position(|&k| k == failed) {
                let k = order.remove(p);
                order.insert(0, k);
            }
        } else if attempt > 0 {
            order.shuffle(rng);
        }
        let mut res = Reservations::new(grid.len());
        for &c in blocked {
            res.parked[c] = (0, u32::MAX);
        }
        for (k, t) in tasks.iter().enumerate() {
            res.hold(t.start, 0, k as u32);
        }
        let mut plans: Vec<Vec<Stop>> = vec![Vec::new(); tasks.len()];
        let mut ok = true;
        for &k in &order {
            let search = Search {
                grid,
                res: &res,
                me: k as u32,
                limits,
            };
            let Some(ticks) = search.robot(&tasks[k], &h_of(k)) else {
                failed = k;
                ok = false;
                break;
            };
            for (t, &(cell, how)) in ticks.iter().enumerate() {
                res.hold(cell, t as u32, k as u32);
                if t > 0 && how < 8 {
                    if let Some(c) = grid.corner(ticks[t - 1].0, usize::from(how)) {
                        res.corners.insert(key(t as u32 - 1, c), k as u32);
                    }
                }
            }
            if !tasks[k].vanish {
                res.parked[ticks[ticks.len() - 1].0] = (ticks.len() as u32 - 1, k as u32);
            }
            plans[k] = stops(grid, &tasks[k], &ticks);
        }
        if ok {
            return Ok(plans);
        }
    }
    Err(PlanFailure {
        robot: failed,
        attempts: limits.attempts.max(1),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Point;
    use crate::sim::World;
    use proptest::prelude::*;
    use rand::SeedableRng;

    /// Robot `stops`' centre at half-tick `h` (tick `h / 2`, or half way through a move).
    fn at(grid: &PlanGrid, stops: &[Stop], h: u32) -> Point {
        let t = h / 2;
        let k = stops.iter().rposition(|s| s.arrive <= t).unwrap_or(0);
        let here = grid.center(stops[k].cell);
        match stops.get(k + 1) {
            // Leaving at tick t, it is half way at t + 1/2.
            Some(next) if h % 2 == 1 && stops[k].leave == t => {
                (here + grid.center(next.cell).coords) * 0.5
            }
            _ => here,
        }
    }

    /// A scene: an open hall, or a maze of `cols` x `cols` cells, with its grid for discs of
    /// radius 5.
    fn scene(maze: bool, cols: u32, seed: u64) -> PlanGrid {
        let c = crate::SimConfig::default().hall_or_maze(maze, cols, 60.0);
        let world = World::maze(c.validate().expect("valid"), seed);
        PlanGrid::best(world.scene(), 5.5, 18.4, &[])
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(24))]

        /// On random open and maze scenes with 2-30 robots (random starts and goals on free
        /// cells, staying or leaving), a plan found never puts two robots' discs (radius 5)
        /// in contact, at a tick or half way through a move, and never has two robots on one
        /// cell within a tick of each other.
        #[test]
        fn a_plan_keeps_every_two_robots_apart(
            maze in any::<bool>(),
            cols in 3u32..8,
            robots in 2usize..31,
            seed in 0u64..1000,
            vanish in any::<bool>(),
        ) {
            let grid = scene(maze, cols, seed);
            let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
            let free: Vec<usize> = (0..grid.len()).filter(|&i| grid.is_free(i)).collect();
            prop_assume!(free.len() >= 2 * robots + 2);
            let mut cells = free.clone();
            cells.shuffle(&mut rng);
            let tasks: Vec<Task> = (0..robots)
                .map(|k| Task {
                    start: cells[k],
                    goals: vec![cells[robots + k]],
                    vanish,
                })
                .collect();
            let Ok(plans) = plan_team(&grid, &tasks, &[], &Limits::default(), &mut rng) else {
                return Ok(());
            };
            let end = plans
                .iter()
                .flat_map(|p| p.iter().map(|s| s.arrive))
                .max()
                .unwrap_or(0);
            for h in 0..=2 * end + 2 {
                for i in 0..robots {
                    for j in i + 1..robots {
                        // A robot that left is gone after its last arrival.
                        let gone = |k: usize| vanish && h / 2 > plans[k].last().map_or(0, |s| s.arrive);
                        if gone(i) || gone(j) {
                            continue;
                        }
                        let d = (at(&grid, &plans[i], h) - at(&grid, &plans[j], h)).norm();
                        prop_assert!(d >= 10.0, "robots {i} and {j} {d} px apart at half-tick {h}");
                    }
                }
            }
            for (i, a) in plans.iter().enumerate() {
                for (j, b) in plans.iter().enumerate().skip(i + 1) {
                    for s in a {
                        for u in b.iter().filter(|u| u.cell == s.cell) {
                            let apart = s.leave.saturating_add(1) < u.arrive
                                || u.leave.saturating_add(1) < s.arrive;
                            prop_assert!(apart, "robots {i} and {j} on cell {} at {s:?} and {u:?}", s.cell);
                        }
                    }
                }
            }
            // Every robot ends on its goal.
            for (k, p) in plans.iter().enumerate() {
                prop_assert_eq!(p.last().map(|s| s.cell), Some(tasks[k].goals[0]));
            }
        }
    }
}
