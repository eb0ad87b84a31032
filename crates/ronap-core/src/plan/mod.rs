//! Planning: geodesic distance fields over the free-space grid and the shortest paths they give,
//! for the planners' policies and for SPL; and the order in which to visit several goals. Uses
//! `config`, `geometry`, `scene` and `sim`.
//!
//! The files are private: what other crates use is re-exported here (`pub use`), and what the
//! layers above use beside it, `pub(crate) use`, so a file can move without breaking anyone.

mod field;
mod path;
mod team;
mod tour;

pub use field::{grid_path, DistanceField, LazyField};
pub use path::{path_length, shortest_path, shortest_path_px, smooth};
pub use tour::{order, CostMatrix, CostMatrixError, Order, Tour};

// For the layers above only: the team planner's search, which the coordinated policy drives.
pub(crate) use team::{
    pair_feasible, pair_plan, plan_team, Limits, Pair, PlanFailure, PlanGrid, Schedule, Stop, Task,
};
