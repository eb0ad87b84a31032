//! Planning: geodesic distance fields over the free-space grid and the shortest paths they give,
//! for the planners' policies and for SPL; and the order in which to visit several goals. Uses
//! `config`, `geometry`, `scene` and `sim`.

pub mod field;
pub mod path;
pub mod team;
pub mod tour;

pub use field::{grid_path, DistanceField, LazyField};
pub use path::{path_length, shortest_path, shortest_path_px, smooth};
pub use tour::{order, CostMatrix, CostMatrixError, Order, Tour};
