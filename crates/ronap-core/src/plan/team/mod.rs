//! Planning a team together (docs/model.md "Teams that finish"): a coarse grid whose cells keep
//! two robots apart ([`PlanGrid`]), prioritised planning in space and time on it ([`plan_team`]),
//! the order in which to follow the plan whatever the delays ([`Schedule`]), and a complete
//! search of two robots alone that proves a task infeasible ([`pair_feasible`]).

mod grid;
mod pair;
mod schedule;
mod search;

pub use grid::PlanGrid;
pub use pair::{pair_feasible, pair_plan, Pair};
pub use schedule::Schedule;
pub use search::{plan_team, Limits, PlanFailure, Stop, Task};
