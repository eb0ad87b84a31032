//! Whether two robots can trade places at all: a complete search over both robots' cells on the
//! [`PlanGrid`], one robot moving at a time, ignoring everyone else. When two robots alone cannot
//! reach their goals, no plan of the whole team can: the task is infeasible.

use super::grid::PlanGrid;
use super::search::{stops, Stop, Task};

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

/// A plan of robots `a` and `b` alone, one moving at a time (the shortest in joint moves), when
/// both reach their goals and stay there: what prioritised planning may miss when the robot
/// planned first must wait for the other (one giving way in a bay while the other passes).
/// Each robot's stops, tick by tick as the joint moves go; `None` when there is none, a robot
/// leaves the scene at its goal, or the joint states are too many to search.
pub fn pair_plan(grid: &PlanGrid, a: &Task, b: &Task) -> Option<[Vec<Stop>; 2]> {
    let (&ga, &gb) = (a.goals.last()?, b.goals.last()?);
    if a.vanish || b.vanish || a.goals.len() != 1 || b.goals.len() != 1 {
        return None;
    }
    let n = grid.len();
    if n.saturating_mul(n) > MAX_STATES {
        return None;
    }
    let index = |x: usize, y: usize| x * n + y;
    // Each joint state's state before it and the move into it (robot `a` moved when below 8,
    // robot `b` in direction `how - 8` otherwise).
    let mut from: Vec<Option<(usize, u8)>> = vec![None; n * n];
    let start = index(a.start, b.start);
    from[start] = Some((start, u8::MAX));
    let mut queue = std::collections::VecDeque::from([(a.start, b.start)]);
    let mut found = false;
    while let Some((x, y)) = queue.pop_front() {
        if x == ga && y == gb {
            found = true;
            break;
        }
        let here = index(x, y);
        for (d, x2) in grid.neighbours(x) {
            let i = index(x2, y);
            if x2 != y && from[i].is_none() {
                from[i] = Some((here, d as u8));
                queue.push_back((x2, y));
            }
        }
        for (d, y2) in grid.neighbours(y) {
            let i = index(x, y2);
            if y2 != x && from[i].is_none() {
                from[i] = Some((here, 8 + d as u8));
                queue.push_back((x, y2));
            }
        }
    }
    if !found {
        return None;
    }
    let mut moves = Vec::new();
    let mut at = index(ga, gb);
    while at != start {
        let (before, how) = from[at]?;
        moves.push((at, how));
        at = before;
    }
    moves.reverse();
    let mut ticks_a = vec![(a.start, 8u8)];
    let mut ticks_b = vec![(b.start, 8u8)];
    for (state, how) in moves {
        let (x, y) = (state / n, state % n);
        let (how_a, how_b) = if how < 8 { (how, 8) } else { (8, how - 8) };
        ticks_a.push((x, how_a));
        ticks_b.push((y, how_b));
    }
    Some([stops(grid, a, &ticks_a), stops(grid, b, &ticks_b)])
}
