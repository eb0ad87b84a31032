//! Where episodes take place (docs/model.md "Scenario files", "Scene: maze", "Warehouse scene",
//! "Maze loaded as a picture", "Static obstacles beyond boxes"): the scene's kind and file, the
//! maze's, the warehouse's and the image map's fields, and the static obstacles a scenario adds,
//! each with its default and its checks.

use crate::config::{
    check, fraction, length, point, ConfigError, MAX_LENGTH_PX, MAX_MAZE_CELLS_PER_SIDE,
};
use serde::{Deserialize, Serialize};

/// Which scene episodes take place in (docs/model.md "Scenario files").
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SceneKind {
    /// A maze generated as `[maze]` says (the paper's scene).
    #[default]
    Maze,
    /// A warehouse generated as `[warehouse]` says.
    Warehouse,
    /// An image (PNG/PGM) or ROS `map_server` YAML file, read as `[map]` says.
    Map,
}

/// Where episodes take place: the scene section of a scenario file.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SceneConfig {
    /// `maze` (default), `warehouse` or `map`.
    pub kind: SceneKind,
    /// Generated scenes: the seed of the one scene every episode uses. Unset: each episode's
    /// seed draws its own scene.
    pub seed: Option<u64>,
    /// Map scenes: the image or YAML file (relative to the scenario file).
    pub file: Option<std::path::PathBuf>,
}

/// A static obstacle added to the scene (docs/model.md "Static obstacles beyond boxes").
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "shape", rename_all = "lowercase", deny_unknown_fields)]
pub enum ObstacleConfig {
    /// An axis-aligned box between two corners, px.
    Box {
        /// Lower-left corner `[x, y]`.
        min: [f64; 2],
        /// Upper-right corner `[x, y]`.
        max: [f64; 2],
    },
    /// A disc.
    Disc {
        /// Centre `[x, y]`, px.
        center: [f64; 2],
        /// Radius, px.
        radius_px: f64,
    },
    /// A convex polygon, its corners in order (either way round).
    Polygon {
        /// Corners `[[x, y], ...]`, px; at least three, convex.
        points: Vec<[f64; 2]>,
    },
}

/// Maze generation (docs/model.md "Scene: maze").
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct MazeConfig {
    /// Number of cell columns. Default 10.
    pub cols: u32,
    /// Number of cell rows. Default 10.
    pub rows: u32,
    /// Side of a square cell, px. Default 100.
    pub cell_px: f64,
    /// Fraction of the interior walls left by the perfect maze that are then removed, in [0, 1].
    /// Default 0.4; 0 gives a perfect maze.
    pub loops: f64,
    /// Wall thickness, px. Default 2.
    pub wall_thickness_px: f64,
}

impl Default for MazeConfig {
    fn default() -> Self {
        Self {
            cols: 10,
            rows: 10,
            cell_px: 100.0,
            loops: 0.4,
            wall_thickness_px: 2.0,
        }
    }
}

/// How an image becomes a scene (docs/model.md "Maze loaded as a picture").
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct MapConfig {
    /// Grey value at or below which a pixel is an obstacle, 0-255. Default 127.
    pub threshold: u8,
    /// Scene px per image pixel. Default 1.
    pub resolution_px: f64,
}

impl Default for MapConfig {
    fn default() -> Self {
        Self {
            threshold: 127,
            resolution_px: 1.0,
        }
    }
}

/// A generated logistics warehouse (docs/model.md "Warehouse scene"): rows of racks back to back in pairs,
/// aisles between them, cross aisles, a free loading area along the bottom, and pallets of clutter
/// in the aisles.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct WarehouseConfig {
    /// Pairs of rack rows (two racks back to back), bottom to top. Default 5.
    pub rack_pairs: u32,
    /// Racks along one row. Default 12.
    pub racks_per_row: u32,
    /// Length of one rack along its row, px. Default 50.
    pub rack_length_px: f64,
    /// Depth of one rack (a pair is twice as deep), px. Default 15.
    pub rack_depth_px: f64,
    /// Width of the aisles between rack pairs, of the cross aisles and of the border aisle, px.
    /// Default 40.
    pub aisle_px: f64,
    /// A cross aisle after every this many racks along a row. Default 4.
    pub cross_aisle_every: u32,
    /// Depth of the free loading area along the bottom, px. Default 150.
    pub loading_px: f64,
    /// Fraction of aisle spots (one rack length each) holding a pallet, 0 to 1. Default 0.15.
    pub clutter: f64,
    /// Side of a square pallet, px. Default 12.
    pub pallet_px: f64,
    /// Thickness of the outer walls, px. Default 2.
    pub wall_thickness_px: f64,
}

impl WarehouseConfig {
    /// Width and height of the warehouse, px: walls, side aisles, the racks along a row with a
    /// cross aisle after every `cross_aisle_every` of them (not after the last), and bottom to top
    /// the loading area, the border aisle and each rack pair with the aisle above it.
    pub fn size_px(&self) -> (f64, f64) {
        let n = self.racks_per_row as usize;
        let cross_aisles = n
            .saturating_sub(1)
            .checked_div(self.cross_aisle_every as usize)
            .unwrap_or(0);
        let width = 2.0 * self.wall_thickness_px
            + 2.0 * self.aisle_px
            + n as f64 * self.rack_length_px
            + cross_aisles as f64 * self.aisle_px;
        let height = 2.0 * self.wall_thickness_px
            + self.loading_px
            + self.aisle_px
            + f64::from(self.rack_pairs) * (2.0 * self.rack_depth_px + self.aisle_px);
        (width, height)
    }
}

impl Default for WarehouseConfig {
    fn default() -> Self {
        Self {
            rack_pairs: 5,
            racks_per_row: 12,
            rack_length_px: 50.0,
            rack_depth_px: 15.0,
            aisle_px: 40.0,
            cross_aisle_every: 4,
            loading_px: 150.0,
            clutter: 0.15,
            pallet_px: 12.0,
            wall_thickness_px: 2.0,
        }
    }
}

impl SceneConfig {
    /// Checks that a file is given exactly when the scene is a map.
    pub(super) fn validate(&self) -> Result<(), ConfigError> {
        let s = self;
        match (s.kind, &s.file) {
            (SceneKind::Map, None) => check(
                false,
                "scene.file",
                "(unset)",
                "a map scene needs the image or YAML file",
            )?,
            (SceneKind::Maze | SceneKind::Warehouse, Some(f)) => check(
                false,
                "scene.file",
                f.display(),
                "only a map scene reads a file (set scene.kind = \"map\")",
            )?,
            _ => {}
        }
        Ok(())
    }
}

impl MazeConfig {
    /// Checks every maze field, naming the first one out of range.
    pub(super) fn validate(&self) -> Result<(), ConfigError> {
        let m = self;
        let side = "must be between 1 and 1000";
        check(
            (1..=MAX_MAZE_CELLS_PER_SIDE).contains(&m.cols),
            "maze.cols",
            m.cols,
            side,
        )?;
        check(
            (1..=MAX_MAZE_CELLS_PER_SIDE).contains(&m.rows),
            "maze.rows",
            m.rows,
            side,
        )?;
        length("maze.cell_px", m.cell_px, false)?;
        let side = "the scene side (cells x maze.cell_px) must be at most 100000 px";
        let widest = m.cols.max(m.rows) as f64 * m.cell_px;
        check(
            widest <= MAX_LENGTH_PX,
            "maze.cell_px",
            format!("{:?}", m.cell_px),
            side,
        )?;
        fraction("maze.loops", m.loops)?;
        length("maze.wall_thickness_px", m.wall_thickness_px, false)?;
        check(
            m.wall_thickness_px < m.cell_px,
            "maze.wall_thickness_px",
            format!("{:?}", m.wall_thickness_px),
            "must be smaller than maze.cell_px",
        )?;
        Ok(())
    }
}

impl MapConfig {
    /// Checks the map's resolution.
    pub(super) fn validate(&self) -> Result<(), ConfigError> {
        length("map.resolution_px", self.resolution_px, false)?;
        Ok(())
    }
}

impl WarehouseConfig {
    /// Checks every warehouse field, naming the first one out of range.
    pub(super) fn validate(&self) -> Result<(), ConfigError> {
        let w = self;
        let count = "must be between 1 and 1000";
        check(
            (1..=1000).contains(&w.rack_pairs),
            "warehouse.rack_pairs",
            w.rack_pairs,
            count,
        )?;
        check(
            (1..=1000).contains(&w.racks_per_row),
            "warehouse.racks_per_row",
            w.racks_per_row,
            count,
        )?;
        check(
            w.cross_aisle_every <= 1000,
            "warehouse.cross_aisle_every",
            w.cross_aisle_every,
            "must be between 0 (no cross aisles) and 1000",
        )?;
        length("warehouse.rack_length_px", w.rack_length_px, false)?;
        length("warehouse.rack_depth_px", w.rack_depth_px, false)?;
        length("warehouse.aisle_px", w.aisle_px, false)?;
        length("warehouse.loading_px", w.loading_px, true)?;
        length("warehouse.pallet_px", w.pallet_px, false)?;
        length("warehouse.wall_thickness_px", w.wall_thickness_px, false)?;
        fraction("warehouse.clutter", w.clutter)?;
        let (wide, tall) = w.size_px();
        check(
            wide.max(tall) <= MAX_LENGTH_PX,
            "warehouse.racks_per_row",
            w.racks_per_row,
            "the warehouse would be wider or taller than 100000 px",
        )?;
        Ok(())
    }
}

/// Checks every static obstacle (`obstacles[i]`), naming the first field out of range.
pub(super) fn validate_obstacles(obstacles: &[ObstacleConfig]) -> Result<(), ConfigError> {
    for (i, o) in obstacles.iter().enumerate() {
        match o {
            ObstacleConfig::Box { min, max } => {
                point(&format!("obstacles[{i}].min"), *min)?;
                point(&format!("obstacles[{i}].max"), *max)?;
                check(
                    min[0] < max[0] && min[1] < max[1],
                    &format!("obstacles[{i}].max"),
                    format!("{max:?}"),
                    "must be above and to the right of min",
                )?;
            }
            ObstacleConfig::Disc { center, radius_px } => {
                point(&format!("obstacles[{i}].center"), *center)?;
                length(&format!("obstacles[{i}].radius_px"), *radius_px, false)?;
            }
            ObstacleConfig::Polygon { points } => {
                let field = format!("obstacles[{i}].points");
                for p in points {
                    point(&field, *p)?;
                }
                check(
                    is_convex_polygon(points),
                    &field,
                    format!("{points:?}"),
                    "must be at least three corners of a convex polygon with an area, in order",
                )?;
            }
        }
    }
    Ok(())
}

/// Whether `p` lies inside or on the convex polygon `points` (corners in order round it).
pub(crate) fn is_inside_convex(points: &[[f64; 2]], p: [f64; 2]) -> bool {
    let n = points.len();
    let mut sign = 0.0f64;
    for i in 0..n {
        let [ax, ay] = points[i];
        let [bx, by] = points[(i + 1) % n];
        let cross = (bx - ax) * (p[1] - ay) - (by - ay) * (p[0] - ax);
        if cross == 0.0 {
            continue;
        }
        if sign * cross < 0.0 {
            return false;
        }
        sign = cross.signum();
    }
    true
}

/// Whether `points` are the corners, in order either way round, of a convex polygon with an area.
pub fn is_convex_polygon(points: &[[f64; 2]]) -> bool {
    let n = points.len();
    if n < 3 {
        return false;
    }
    let mut sign = 0.0f64;
    for i in 0..n {
        let [ax, ay] = points[i];
        let [bx, by] = points[(i + 1) % n];
        let [cx, cy] = points[(i + 2) % n];
        let cross = (bx - ax) * (cy - by) - (by - ay) * (cx - bx);
        if cross == 0.0 {
            continue;
        }
        if sign * cross < 0.0 {
            return false;
        }
        sign = cross.signum();
    }
    let area2: f64 = (0..n)
        .map(|i| {
            let [ax, ay] = points[i];
            let [bx, by] = points[(i + 1) % n];
            ax * by - bx * ay
        })
        .sum();
    sign != 0.0 && area2.abs() > 1e-9
}
