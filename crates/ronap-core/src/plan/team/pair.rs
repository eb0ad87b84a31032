//! Whether two robots can trade places at all: a complete search over both robots' cells on the
//! [`PlanGrid`], one robot moving at a time, ignoring everyone else. When two robots alone cannot
//! reach their goals, no plan of the whole team can: the task is infeasible.

use super::grid::PlanGrid;
use super::search::Task;

/// Largest number of joint states the search visits before it stops, undecided.
pub const MAX_STATES: usize = 4_000_000;

/// What the search found.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pair {
    /// Both reach their goals.
    Feasible,
    /// No sequence of moves brings both to their goals.
    Infeasible,
    /// Too many joint states to search.
    Undecided,
}

/// Whether robots with one goal each, `a` and `b`, can both reach their goals on `grid` (a
/// robot that vanishes on arrival leaves the grid there).
pub fn pair_feasible(grid: &PlanGrid, a: &Task, b: &Task) -> Pair {
    let (Some(&ga), Some(&gb)) = (a.goals.last(), b.goals.last()) else {
        return Pair::Feasible;
    };
    let n = grid.len() + 1;
    // Cell `n - 1` stands for "gone".
    let gone = n - 1;
    if n.saturating_mul(n) > MAX_STATES {
        return Pair::Undecided;
    }
    let index = |x: usize, y: usize| x * n + y;
    let mut seen = vec![false; n * n];
    let mut queue = std::collections::VecDeque::new();
    seen[index(a.start, b.start)] = true;
    queue.push_back((a.start, b.start));
    let done = |x: usize, y: usize| {
        (x == ga || (a.vanish && x == gone)) && (y == gb || (b.vanish && y == gone))
    };
    while let Some((x, y)) = queue.pop_front() {
        if done(x, y) {
            return Pair::Feasible;
        }
        let mut visit = |x2: usize, y2: usize, queue: &mut std::collections::VecDeque<_>| {
            let i = index(x2, y2);
            if !seen[i] {
                seen[i] = true;
                queue.push_back((x2, y2));
            }
        };
        if x != gone {
            if a.vanish && x == ga {
                visit(gone, y, &mut queue);
            }
            for (_, x2) in grid.neighbours(x) {
                if x2 != y {
                    visit(x2, y, &mut queue);
                }
            }
        }
        if y != gone {
            if b.vanish && y == gb {
                visit(x, gone, &mut queue);
            }
            for (_, y2) in grid.neighbours(y) {
                if y2 != x {
                    visit(x, y2, &mut queue);
                }
            }
        }
    }
    Pair::Infeasible
}
