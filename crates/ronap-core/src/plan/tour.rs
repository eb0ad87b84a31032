//! Visiting orders for multi-destination tasks (docs/model.md "Multi-destination tasks"): in which order a
//! robot visits its goals, and how long that tour is. Tours are open paths from the start through
//! every goal once, not returning. The module sees only a [`CostMatrix`] of geodesic distances, px
//! (infinite where unreachable, possibly asymmetric), so it knows nothing of geometry.
//!
//! Three orders: [`Order::Given`] keeps the list; [`Order::Nearest`] goes greedily to the nearest
//! unvisited goal; [`Order::Optimal`] minimises the tour length, exactly by Held-Karp for up to
//! [`HELD_KARP_MAX_GOALS`] goals and by 2-opt and or-opt from the nearest-neighbour tour beyond.

/// Most goals [`Order::Optimal`] orders exactly (Held-Karp, O(2^n n^2) time, O(2^n n) memory);
/// beyond, it improves the nearest-neighbour tour by local search.
pub const HELD_KARP_MAX_GOALS: usize = 12;

/// Segment lengths, in goals, that or-opt moves.
const OR_OPT_MAX_SEGMENT: usize = 3;

/// A move improves a tour only when it shortens the changed legs by more than this fraction, far
/// above the rounding error of summing them, so rounding can never make local search cycle.
const MIN_IMPROVEMENT: f64 = 1e-9;

pub use crate::config::Order;

/// Why a [`CostMatrix`] could not be built.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum CostMatrixError {
    /// There is no row, not even the start's.
    #[error("a cost matrix needs at least the start node")]
    Empty,
    /// A row's length differs from the number of rows.
    #[error("cost matrix row {row} has {len} entries, expected {expected}")]
    NotSquare {
        /// The row, 0 for the start.
        row: usize,
        /// Its number of entries.
        len: usize,
        /// The number of rows.
        expected: usize,
    },
    /// An entry is NaN, negative, or finite but so large (above `f64::MAX` over the number of
    /// nodes) that a tour's length could overflow to infinity.
    #[error(
        "cost from node {from} to node {to} is {value}: must be infinite (unreachable) or a \
         non-negative number no larger than f64::MAX over the number of nodes"
    )]
    InvalidCost {
        /// The node the cost leaves, 0 for the start.
        from: usize,
        /// The node the cost reaches, 0 for the start.
        to: usize,
        /// The entry.
        value: f64,
    },
}

/// Travel costs, px, between the start (node 0) and the goals (nodes 1 to n): non-negative,
/// infinite where unreachable, `cost(i, j)` not necessarily `cost(j, i)`. Finite costs are small
/// enough that no sum of them along a tour overflows, so a tour is infinitely long exactly when
/// one of its legs is unreachable.
#[derive(Clone, Debug, PartialEq)]
pub struct CostMatrix {
    nodes: usize,
    /// Row-major: `costs[from * nodes + to]`.
    costs: Vec<f64>,
}

impl CostMatrix {
    /// The matrix with `rows[from][to]` the cost from node `from` to node `to`, row 0 the start's.
    /// The diagonal is never used but must be valid too.
    pub fn new(rows: &[Vec<f64>]) -> Result<Self, CostMatrixError> {
        let nodes = rows.len();
        if let Some((row, r)) = rows.iter().enumerate().find(|(_, r)| r.len() != nodes) {
            return Err(CostMatrixError::NotSquare {
                row,
                len: r.len(),
                expected: nodes,
            });
        }
        Self::from_fn(nodes, |from, to| rows[from][to])
    }

    /// The matrix of `nodes` nodes (the start and `nodes - 1` goals) with `cost(from, to)`.
    pub fn from_fn(
        nodes: usize,
        mut cost: impl FnMut(usize, usize) -> f64,
    ) -> Result<Self, CostMatrixError> {
        if nodes == 0 {
            return Err(CostMatrixError::Empty);
        }
        let max = f64::MAX / nodes as f64;
        let mut costs = Vec::with_capacity(nodes * nodes);
        for from in 0..nodes {
            for to in 0..nodes {
                let value = cost(from, to);
                // Written so that NaN fails too.
                if !(value >= 0.0 && (value <= max || value == f64::INFINITY)) {
                    return Err(CostMatrixError::InvalidCost { from, to, value });
                }
                costs.push(value);
            }
        }
        Ok(Self { nodes, costs })
    }

    /// Number of goals, n: the nodes after the start.
    pub fn goal_count(&self) -> usize {
        self.nodes - 1
    }

    /// Cost, px, from node `from` to node `to` (0 the start, `g + 1` goal `g`); infinite when
    /// either is not a node.
    pub fn cost(&self, from: usize, to: usize) -> f64 {
        if from < self.nodes && to < self.nodes {
            self.costs[from * self.nodes + to]
        } else {
            f64::INFINITY
        }
    }

    /// Cost from node `from` to goal `goal`, 0-based in the goal list.
    fn to_goal(&self, from: usize, goal: usize) -> f64 {
        self.cost(from, goal + 1)
    }
}

/// A visiting order and its length.
#[derive(Clone, Debug, PartialEq)]
pub struct Tour {
    /// Goals, 0-based in the goal list, in visiting order; each exactly once.
    pub goals: Vec<usize>,
    /// Summed cost, px, from the start through the goals in order; infinite when a leg is
    /// unreachable, 0 without goals.
    pub length: f64,
}

impl Tour {
    fn new(costs: &CostMatrix, goals: Vec<usize>) -> Self {
        let length = length(costs, &goals);
        Self { goals, length }
    }
}

/// The tour visiting every goal of `costs` in `order`. The length is infinite when no tour with
/// finite length exists (for [`Order::Optimal`]) or when the chosen one has an unreachable leg.
pub fn order(costs: &CostMatrix, order: Order) -> Tour {
    match order {
        Order::Given => Tour::new(costs, (0..costs.goal_count()).collect()),
        Order::Nearest => nearest(costs),
        Order::Optimal => optimal(costs),
    }
}

/// Summed cost, px, from the start through `goals` (0-based in the goal list) in order; 0 when
/// `goals` is empty. An index that is not a goal counts as unreachable: the length is infinite.
pub fn length(costs: &CostMatrix, goals: &[usize]) -> f64 {
    let mut from = 0;
    let mut total = 0.0;
    for &goal in goals {
        total += costs.to_goal(from, goal);
        from = goal + 1;
    }
    total
}

/// The greedy tour: from each node the unvisited goal it reaches most cheaply, the lowest index
/// among equals (and when every remaining goal is unreachable).
fn nearest(costs: &CostMatrix) -> Tour {
    let n = costs.goal_count();
    let mut visited = vec![false; n];
    let mut goals = Vec::with_capacity(n);
    let mut from = 0;
    for _ in 0..n {
        let mut best: Option<(usize, f64)> = None;
        for goal in (0..n).filter(|&g| !visited[g]) {
            let cost = costs.to_goal(from, goal);
            if best.is_none_or(|(_, c)| cost < c) {
                best = Some((goal, cost));
            }
        }
        let Some((goal, _)) = best else { break };
        visited[goal] = true;
        goals.push(goal);
        from = goal + 1;
    }
    Tour::new(costs, goals)
}

/// The shortest tour for few goals, the locally optimal tour from the nearest-neighbour one
/// beyond; never longer than [`nearest`]'s.
fn optimal(costs: &CostMatrix) -> Tour {
    let greedy = nearest(costs);
    let candidate = if costs.goal_count() <= HELD_KARP_MAX_GOALS {
        held_karp(costs).map(|goals| Tour::new(costs, goals))
    } else {
        Some(local_search(costs, greedy.goals.clone()))
    };
    match candidate {
        Some(tour) if tour.length <= greedy.length => tour,
        _ => greedy,
    }
}

/// The shortest open tour by Held-Karp's dynamic programme over subsets of goals; `None` when
/// every tour is infinitely long. Memory grows as 2^n: callers keep n small.
fn held_karp(costs: &CostMatrix) -> Option<Vec<usize>> {
    let n = costs.goal_count();
    if n == 0 {
        return Some(Vec::new());
    }
    let subsets = 1usize << n;
    // best[subset * n + last]: the shortest path from the start through `subset`, ending at
    // `last`; previous[..] the goal before `last` on it (NONE when `last` is the first).
    const NONE: usize = usize::MAX;
    let mut best = vec![f64::INFINITY; subsets * n];
    let mut previous = vec![NONE; subsets * n];
    for goal in 0..n {
        best[(1 << goal) * n + goal] = costs.to_goal(0, goal);
    }
    for subset in 1..subsets {
        for last in (0..n).filter(|&g| subset & (1 << g) != 0) {
            let here = best[subset * n + last];
            if !here.is_finite() {
                continue;
            }
            for next in (0..n).filter(|&g| subset & (1 << g) == 0) {
                let there = (subset | (1 << next)) * n + next;
                let through = here + costs.to_goal(last + 1, next);
                if through < best[there] {
                    best[there] = through;
                    previous[there] = last;
                }
            }
        }
    }
    let full = subsets - 1;
    let mut last = (0..n)
        .filter(|&g| best[full * n + g].is_finite())
        .min_by(|&a, &b| best[full * n + a].total_cmp(&best[full * n + b]))?;
    let mut subset = full;
    let mut goals = Vec::with_capacity(n);
    loop {
        goals.push(last);
        let before = previous[subset * n + last];
        subset &= !(1 << last);
        if subset == 0 {
            break;
        }
        // A finite state's predecessor is set, and is in the remaining subset; anything else is
        // a broken table, answered by falling back rather than by indexing out of bounds.
        if before >= n || subset & (1 << before) == 0 {
            return None;
        }
        last = before;
    }
    goals.reverse();
    Some(goals)
}

/// Whether replacing edges costing `old` by edges costing `new` shortens a tour. Costs are
/// non-negative, so neither is NaN; an infinite `old` is improved by any finite `new`.
fn improves(new: f64, old: f64) -> bool {
    new < old * (1.0 - MIN_IMPROVEMENT)
}

/// Improves `goals` by 2-opt (reversing a stretch) and or-opt (moving a stretch of up to
/// [`OR_OPT_MAX_SEGMENT`] goals elsewhere) until neither finds a shorter tour, taking the first
/// improving move in a fixed scan order, so the result is deterministic.
///
/// Each move strictly lowers the number of unreachable legs, or keeps it and lowers the summed
/// finite legs by a fraction [`MIN_IMPROVEMENT`], so the search ends.
fn local_search(costs: &CostMatrix, goals: Vec<usize>) -> Tour {
    // path[0] is the start; path[k] the node (goal + 1) visited k-th.
    let mut path: Vec<usize> = std::iter::once(0)
        .chain(goals.iter().map(|g| g + 1))
        .collect();
    while two_opt_pass(costs, &mut path) || or_opt_pass(costs, &mut path) {}
    Tour::new(costs, path[1..].iter().map(|node| node - 1).collect())
}

/// One sweep of 2-opt: reverses `path[i..=j]` wherever that shortens the tour. Costs may be
/// asymmetric, so the stretch's own edges are priced both ways. Returns whether it changed.
fn two_opt_pass(costs: &CostMatrix, path: &mut [usize]) -> bool {
    let last = path.len() - 1;
    let mut changed = false;
    for i in 1..last {
        // The stretch path[i..=j] walked forward and backward, grown one node at a time so that
        // no sum is formed by subtracting (infinity minus infinity).
        let mut forward = 0.0;
        let mut backward = 0.0;
        let mut j = i + 1;
        while j <= last {
            forward += costs.cost(path[j - 1], path[j]);
            backward += costs.cost(path[j], path[j - 1]);
            let (before, first, end) = (path[i - 1], path[i], path[j]);
            let (mut old, mut new) = (
                costs.cost(before, first) + forward,
                costs.cost(before, end) + backward,
            );
            if j < last {
                old += costs.cost(end, path[j + 1]);
                new += costs.cost(first, path[j + 1]);
            }
            if improves(new, old) {
                path[i..=j].reverse();
                changed = true;
                // The stretch's sums are stale: start again from this `i`.
                forward = 0.0;
                backward = 0.0;
                j = i + 1;
                continue;
            }
            j += 1;
        }
    }
    changed
}

/// One sweep of or-opt: moves a stretch `path[s..=e]`, keeping its direction, to between two
/// other nodes (or to the end) wherever that shortens the tour. Returns whether it changed.
fn or_opt_pass(costs: &CostMatrix, path: &mut Vec<usize>) -> bool {
    let last = path.len() - 1;
    for span in 1..=OR_OPT_MAX_SEGMENT.min(last) {
        for s in 1..=last + 1 - span {
            let e = s + span - 1;
            // Taking the stretch out joins path[s - 1] to path[e + 1].
            let mut removed = costs.cost(path[s - 1], path[s]);
            let mut joined = 0.0;
            if e < last {
                removed += costs.cost(path[e], path[e + 1]);
                joined += costs.cost(path[s - 1], path[e + 1]);
            }
            // Put it back after path[a], before path[a + 1] if any; a = s - 1 is where it is.
            for a in (0..s - 1).chain(e + 1..=last) {
                let mut old = removed;
                let mut new = joined + costs.cost(path[a], path[s]);
                if a < last {
                    old += costs.cost(path[a], path[a + 1]);
                    new += costs.cost(path[e], path[a + 1]);
                }
                if improves(new, old) {
                    let stretch: Vec<usize> = path.drain(s..=e).collect();
                    let at = if a < s { a + 1 } else { a + 1 - span };
                    path.splice(at..at, stretch);
                    return true;
                }
            }
        }
    }
    false
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// Start and goals at random points of a 1000 px square, costs their distances.
    fn euclidean(rng: &mut ChaCha8Rng, goals: usize) -> CostMatrix {
        let points: Vec<(f64, f64)> = (0..=goals)
            .map(|_| (rng.random_range(0.0..1000.0), rng.random_range(0.0..1000.0)))
            .collect();
        CostMatrix::from_fn(goals + 1, |a, b| {
            let (pa, pb) = (points[a], points[b]);
            (pa.0 - pb.0).hypot(pa.1 - pb.1)
        })
        .expect("distances are valid costs")
    }

    /// Independent random costs each way, a fraction `unreachable` of them infinite.
    fn asymmetric(rng: &mut ChaCha8Rng, goals: usize, unreachable: f64) -> CostMatrix {
        CostMatrix::from_fn(goals + 1, |_, _| {
            if rng.random_bool(unreachable) {
                f64::INFINITY
            } else {
                rng.random_range(0.0..100.0)
            }
        })
        .expect("random costs are valid")
    }

    /// The shortest tour length by trying every order.
    fn brute_force(costs: &CostMatrix) -> f64 {
        fn extend(costs: &CostMatrix, from: usize, left: &mut Vec<usize>, so_far: f64) -> f64 {
            if left.is_empty() {
                return so_far;
            }
            let mut best = f64::INFINITY;
            for k in 0..left.len() {
                let goal = left.swap_remove(k);
                let leg = costs.cost(from, goal + 1);
                best = best.min(extend(costs, goal + 1, left, so_far + leg));
                left.push(goal);
                let end = left.len() - 1;
                left.swap(k, end);
            }
            best
        }
        extend(costs, 0, &mut (0..costs.goal_count()).collect(), 0.0)
    }

    /// Asserts `tour` visits each goal once and its length is what [`length`] says.
    fn assert_valid(costs: &CostMatrix, tour: &Tour) {
        let mut sorted = tour.goals.clone();
        sorted.sort_unstable();
        assert_eq!(sorted, (0..costs.goal_count()).collect::<Vec<_>>());
        assert!(!tour.length.is_nan());
        assert_eq!(tour.length.to_bits(), length(costs, &tour.goals).to_bits());
    }

    fn assert_close(actual: f64, expected: f64) {
        if expected.is_finite() {
            assert!(
                (actual - expected).abs() <= 1e-9 * expected.max(1.0),
                "{actual} != {expected}"
            );
        } else {
            assert_eq!(actual, expected);
        }
    }

    #[test]
    fn held_karp_matches_brute_force() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let mut infinite = 0;
        for goals in 0..=8 {
            for instance in 0..40 {
                let costs = match instance % 4 {
                    0 | 1 => euclidean(&mut rng, goals),
                    2 => asymmetric(&mut rng, goals, 0.0),
                    _ => asymmetric(&mut rng, goals, 0.3),
                };
                let tour = order(&costs, Order::Optimal);
                assert_valid(&costs, &tour);
                let shortest = brute_force(&costs);
                assert_close(tour.length, shortest);
                infinite += usize::from(shortest.is_infinite());
            }
        }
        // The sparse instances must include some without any finite tour.
        assert!(infinite > 0);
    }

    #[test]
    fn optimal_runs_held_karp_at_twelve_goals() {
        let mut rng = ChaCha8Rng::seed_from_u64(12);
        for costs in [
            euclidean(&mut rng, HELD_KARP_MAX_GOALS),
            asymmetric(&mut rng, HELD_KARP_MAX_GOALS, 0.0),
        ] {
            let tour = order(&costs, Order::Optimal);
            assert_valid(&costs, &tour);
            assert!(tour.length <= order(&costs, Order::Nearest).length);
            // No 2-opt or or-opt move can shorten an optimal tour.
            let improved = local_search(&costs, tour.goals.clone());
            assert_eq!(improved.goals, tour.goals);
        }
    }

    #[test]
    fn local_search_beats_nearest_neighbour_beyond_held_karp() {
        let mut rng = ChaCha8Rng::seed_from_u64(40);
        let mut shorter = 0;
        let mut instances = 0;
        for goals in HELD_KARP_MAX_GOALS + 1..=40 {
            for costs in [euclidean(&mut rng, goals), asymmetric(&mut rng, goals, 0.0)] {
                let greedy = order(&costs, Order::Nearest);
                let tour = order(&costs, Order::Optimal);
                assert_valid(&costs, &tour);
                assert!(tour.length <= greedy.length);
                shorter += usize::from(tour.length < greedy.length);
                instances += 1;
                // 2-opt local optimum: reversing any stretch gives no shorter tour.
                for i in 0..goals {
                    for j in i + 1..goals {
                        let mut reversed = tour.goals.clone();
                        reversed[i..=j].reverse();
                        assert!(length(&costs, &reversed) >= tour.length * (1.0 - 1e-6));
                    }
                }
            }
        }
        assert!(shorter * 10 >= instances * 9, "{shorter} of {instances}");
    }

    #[test]
    fn local_search_is_deterministic() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let costs = asymmetric(&mut rng, 30, 0.1);
        let first = order(&costs, Order::Optimal);
        let second = order(&costs, Order::Optimal);
        assert_eq!(first.goals, second.goals);
        assert_eq!(first.length.to_bits(), second.length.to_bits());
    }

    #[test]
    fn nearest_goes_to_the_closest_unvisited_goal() {
        // On a line: start at 0, goals at 5, 1, 3, -2 and 7.
        let x = [0.0, 5.0, 1.0, 3.0, -2.0, 7.0];
        let costs = CostMatrix::from_fn(x.len(), |a, b| f64::abs(x[a] - x[b])).expect("valid");
        let tour = order(&costs, Order::Nearest);
        assert_eq!(tour.goals, vec![1, 2, 0, 4, 3]);
        assert_eq!(tour.length, 1.0 + 2.0 + 2.0 + 2.0 + 9.0);
        // Greedy leaves the goal behind the start for last; going there first is shorter.
        let best = order(&costs, Order::Optimal);
        assert_eq!(best.goals, vec![3, 1, 2, 0, 4]);
        assert_eq!(best.length, 2.0 + 3.0 + 2.0 + 2.0 + 2.0);
    }

    #[test]
    fn nearest_breaks_ties_by_index_and_reads_costs_forward() {
        // Goals 0 and 1 are equally near the start. From goal 0, goal 2 is nearer going forward
        // (5 against 6), goal 1 coming back (1 against 9).
        let costs = CostMatrix::new(&[
            vec![0.0, 4.0, 4.0, 9.0],
            vec![4.0, 0.0, 6.0, 5.0],
            vec![4.0, 1.0, 0.0, 1.0],
            vec![9.0, 9.0, 8.0, 0.0],
        ])
        .expect("valid");
        let tour = order(&costs, Order::Nearest);
        assert_eq!(tour.goals, vec![0, 2, 1]);
        assert_eq!(tour.length, 4.0 + 5.0 + 8.0);
        // Start -> goal 1 -> goal 0 -> goal 2 is shorter still.
        let best = order(&costs, Order::Optimal);
        assert_eq!(best.goals, vec![1, 0, 2]);
        assert_eq!(best.length, 4.0 + 1.0 + 5.0);
    }

    #[test]
    fn given_keeps_the_list() {
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let costs = asymmetric(&mut rng, 9, 0.0);
        let tour = order(&costs, Order::Given);
        assert_eq!(tour.goals, (0..9).collect::<Vec<_>>());
        let by_hand: f64 = (0..9).map(|g| costs.cost(g, g + 1)).sum();
        assert_eq!(tour.length, by_hand);
    }

    #[test]
    fn no_goals_is_an_empty_tour() {
        let costs = CostMatrix::new(&[vec![0.0]]).expect("valid");
        for by in [Order::Given, Order::Nearest, Order::Optimal] {
            assert_eq!(
                order(&costs, by),
                Tour {
                    goals: Vec::new(),
                    length: 0.0
                }
            );
        }
    }

    #[test]
    fn unreachable_goals_give_infinite_tours() {
        let inf = f64::INFINITY;
        // Goal 1 cannot be reached from anywhere.
        let costs = CostMatrix::new(&[
            vec![0.0, 1.0, inf, 2.0],
            vec![1.0, 0.0, inf, 1.0],
            vec![1.0, 1.0, 0.0, 1.0],
            vec![2.0, 1.0, inf, 0.0],
        ])
        .expect("valid");
        for by in [Order::Given, Order::Nearest, Order::Optimal] {
            let tour = order(&costs, by);
            assert_valid(&costs, &tour);
            assert_eq!(tour.length, inf);
        }
        // Sixteen goals all unreachable: local search must not produce NaN or loop.
        let costs = CostMatrix::from_fn(17, |a, b| if a == b { 0.0 } else { inf }).expect("valid");
        let tour = order(&costs, Order::Optimal);
        assert_valid(&costs, &tour);
        assert_eq!(tour.length, inf);
        assert_eq!(length(&costs, &[0, 99]), inf);
    }

    #[test]
    fn optimal_finds_the_only_finite_tour_where_nearest_gets_stuck() {
        let inf = f64::INFINITY;
        // Goal 0 is nearest but goal 0 -> goal 1 is one-way the wrong way.
        let costs = CostMatrix::new(&[
            vec![0.0, 1.0, 2.0],
            vec![1.0, 0.0, inf],
            vec![2.0, 1.0, 0.0],
        ])
        .expect("valid");
        assert_eq!(order(&costs, Order::Nearest).length, inf);
        let tour = order(&costs, Order::Optimal);
        assert_eq!(tour.goals, vec![1, 0]);
        assert_eq!(tour.length, 3.0);

        // Fifteen goals on a line, goal 4 a dead end: it must come last.
        let x = |node: usize| node as f64;
        let costs = CostMatrix::from_fn(16, |a, b| {
            if a == 5 && b != 5 {
                inf
            } else {
                (x(a) - x(b)).abs()
            }
        })
        .expect("valid");
        assert_eq!(order(&costs, Order::Nearest).length, inf);
        let tour = order(&costs, Order::Optimal);
        assert_valid(&costs, &tour);
        assert_eq!(tour.goals.last(), Some(&4));
        assert!(tour.length.is_finite());
    }

    #[test]
    fn cost_matrix_rejects_bad_input() {
        assert_eq!(CostMatrix::new(&[]), Err(CostMatrixError::Empty));
        assert_eq!(
            CostMatrix::new(&[vec![0.0, 1.0], vec![1.0]]),
            Err(CostMatrixError::NotSquare {
                row: 1,
                len: 1,
                expected: 2
            })
        );
        assert_eq!(
            CostMatrix::new(&[vec![0.0, -1.0], vec![1.0, 0.0]]),
            Err(CostMatrixError::InvalidCost {
                from: 0,
                to: 1,
                value: -1.0
            })
        );
        assert!(matches!(
            CostMatrix::new(&[vec![0.0, 1.0], vec![f64::NAN, 0.0]]),
            Err(CostMatrixError::InvalidCost { from: 1, to: 0, .. })
        ));
        // Two legs of f64::MAX / 2 would sum to infinity although both are reachable.
        assert!(CostMatrix::from_fn(3, |_, _| f64::MAX / 3.0).is_ok());
        assert!(matches!(
            CostMatrix::from_fn(3, |_, _| f64::MAX / 2.0),
            Err(CostMatrixError::InvalidCost { from: 0, to: 0, .. })
        ));
        let costs = CostMatrix::new(&[vec![0.0, f64::INFINITY], vec![1.0, 0.0]]).expect("valid");
        assert_eq!(costs.goal_count(), 1);
        assert_eq!(costs.cost(0, 1), f64::INFINITY);
        assert_eq!(costs.cost(1, 0), 1.0);
        assert_eq!(costs.cost(0, 2), f64::INFINITY);
    }

    #[test]
    fn order_reads_lower_case_names() {
        #[derive(serde::Deserialize, serde::Serialize)]
        struct Task {
            order: Order,
        }
        for (name, by) in [
            ("given", Order::Given),
            ("nearest", Order::Nearest),
            ("optimal", Order::Optimal),
        ] {
            let text = format!("order = \"{name}\"\n");
            let task: Task = toml::from_str(&text).expect("a known order");
            assert_eq!(task.order, by);
            assert_eq!(
                toml::to_string(&Task { order: by }).expect("serialises"),
                text
            );
        }
        assert!(toml::from_str::<Task>("order = \"Optimal\"").is_err());
        assert_eq!(Order::default(), Order::Given);
    }
}
