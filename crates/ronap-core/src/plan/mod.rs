//! Planning: geodesic distance fields over the free-space grid and the shortest paths they give,
//! for the planners' policies and for SPL. Uses `config`, `geometry`, `scene` and `sim`.

pub mod field;
pub mod path;

pub use field::DistanceField;
pub use path::{path_length, shortest_path, shortest_path_px, smooth};
