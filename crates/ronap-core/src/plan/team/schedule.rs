//! A team plan followed in order rather than to the tick (an action dependency graph, as
//! Hönig et al. 2019 execute multi-agent plans): a robot moves on to its next cell only once the
//! robot that held that cell before it in the plan has moved on, and crosses a corner only once
//! the robot planned to cross it before has. Whatever the delays (turning, slowing, giving way),
//! the robots hold cells in the plan's order, so no two ever hold one cell at once, and since
//! the plan's order has no cycle, no robot waits for ever on another that waits on it.

use super::search::Stop;

/// What robot `robot` must have reached before another may go on: `robot` must be heading to
/// its stop `need` or beyond (or gone from the scene).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Wait {
    /// The robot waited for.
    pub robot: u32,
    /// The stop it must be heading to (or past).
    pub need: u32,
}

/// For every robot and every stop of its plan, what it waits for before moving to that stop.
#[derive(Clone, Debug, Default)]
pub struct Schedule {
    waits: Vec<Vec<Vec<Wait>>>,
}

impl Schedule {
    /// The schedule of `plans` (each robot's stops).
    pub fn new(plans: &[Vec<Stop>]) -> Self {
        use std::collections::HashMap;
        // Every hold of each cell and every crossing of each corner: (tick, robot, stop).
        let mut holds: HashMap<usize, Vec<(u32, usize, usize)>> = HashMap::new();
        let mut crossings: HashMap<usize, Vec<(u32, usize, usize)>> = HashMap::new();
        for (k, stops) in plans.iter().enumerate() {
            for (q, s) in stops.iter().enumerate() {
                holds.entry(s.cell).or_default().push((s.arrive, k, q));
                if let Some(c) = s.corner {
                    crossings.entry(c).or_default().push((s.arrive, k, q));
                }
            }
        }
        let mut waits: Vec<Vec<Vec<Wait>>> =
            plans.iter().map(|s| vec![Vec::new(); s.len()]).collect();
        let mut link = |events: &mut Vec<(u32, usize, usize)>, after: u32| {
            events.sort_unstable();
            for pair in events.windows(2) {
                let ((_, j, q), (_, k, p)) = (pair[0], pair[1]);
                if j != k && p > 0 {
                    waits[k][p].push(Wait {
                        robot: j as u32,
                        need: q as u32 + after,
                    });
                }
            }
        };
        // A cell is left once its holder heads past the stop after it (it arrived there).
        for events in holds.values_mut() {
            link(events, 2);
        }
        // A corner is crossed once its crosser heads past the stop it crossed into.
        for events in crossings.values_mut() {
            link(events, 1);
        }
        for w in waits.iter_mut().flatten() {
            w.sort_unstable_by_key(|w| (w.robot, w.need));
        }
        Self { waits }
    }

    /// What robot `k` waits for before moving to its stop `p`.
    pub fn waits(&self, k: usize, p: usize) -> &[Wait] {
        self.waits
            .get(k)
            .and_then(|w| w.get(p))
            .map_or(&[], Vec::as_slice)
    }

    /// Whether robot `k` may move to its stop `p`, `heading[j]` being the stop robot `j` heads
    /// to (`u32::MAX` for a robot gone from the scene).
    pub fn may_go(&self, k: usize, p: usize, heading: &[u32]) -> bool {
        self.waits(k, p)
            .iter()
            .all(|w| heading[w.robot as usize] >= w.need)
    }
}
