//! The free-space grid: where the robot's centre may stand, on square cells of `grid_px`.
//!
//! A cell is free when a disc of the robot's radius centred on the cell centre touches no obstacle
//! (the configuration space, sampled). Connected regions use 4-neighbour moves between free cells,
//! so two cells in one region are joined by a path the robot can drive. Start and goal are drawn
//! from one region; planners search this grid.

use crate::geometry::Point;
use crate::scene::Scene;

/// Free cells of a scene for a disc of a given radius.
#[derive(Clone, Debug)]
pub struct FreeGrid {
    cell_px: f64,
    cols: usize,
    rows: usize,
    /// `free[row * cols + col]`, row 0 at the bottom.
    free: Vec<bool>,
    /// Region label of each free cell (`u32::MAX` for blocked cells).
    region: Vec<u32>,
    /// Cells of each region, largest region first.
    regions: Vec<Vec<u32>>,
}

impl FreeGrid {
    /// The grid of `scene` for a disc of `radius` px, with cells of `cell_px`.
    pub fn new(scene: &Scene, radius: f64, cell_px: f64) -> Self {
        let cols = ((scene.width() / cell_px).floor() as usize).max(1);
        let rows = ((scene.height() / cell_px).floor() as usize).max(1);
        let mut free = vec![true; cols * rows];
        let r2 = radius * radius;
        // Block the cells whose centres are within `radius` of each box: a pass per box over the
        // cells of its grown bounding box, exact at the rounded corners.
        for b in scene.boxes() {
            let g = b.inflated(radius);
            let lo = |v: f64| ((v / cell_px - 0.5).ceil().max(0.0)) as usize;
            let hi = |v: f64, n: usize| -> Option<usize> {
                let k = (v / cell_px - 0.5).floor();
                (k >= 0.0).then(|| (k as usize).min(n - 1))
            };
            let (Some(c1), Some(r1)) = (hi(g.max.x, cols), hi(g.max.y, rows)) else {
                continue;
            };
            let (c0, r0) = (lo(g.min.x), lo(g.min.y));
            for r in r0..=r1 {
                for c in c0..=c1 {
                    let p = Point::new((c as f64 + 0.5) * cell_px, (r as f64 + 0.5) * cell_px);
                    if b.distance_squared(p) < r2 {
                        free[r * cols + c] = false;
                    }
                }
            }
        }
        // Label regions by flood fill, numbering them in the order their first cell is met.
        let mut region = vec![u32::MAX; cols * rows];
        let mut sizes: Vec<usize> = Vec::new();
        let mut stack = Vec::new();
        for seed in 0..cols * rows {
            if !free[seed] || region[seed] != u32::MAX {
                continue;
            }
            let label = sizes.len() as u32;
            let mut size = 0;
            region[seed] = label;
            stack.push(seed);
            while let Some(i) = stack.pop() {
                size += 1;
                let (c, r) = (i % cols, i / cols);
                let mut visit = |j: usize| {
                    if free[j] && region[j] == u32::MAX {
                        region[j] = label;
                        stack.push(j);
                    }
                };
                if c > 0 {
                    visit(i - 1);
                }
                if c + 1 < cols {
                    visit(i + 1);
                }
                if r > 0 {
                    visit(i - cols);
                }
                if r + 1 < rows {
                    visit(i + cols);
                }
            }
            sizes.push(size);
        }
        // Renumber largest first (ties keep discovery order, so the result is deterministic) and
        // list each region's cells in increasing index order with one pass over the grid.
        let mut order: Vec<usize> = (0..sizes.len()).collect();
        order.sort_by_key(|&k| std::cmp::Reverse(sizes[k]));
        let mut relabel = vec![0u32; sizes.len()];
        for (new, &old) in order.iter().enumerate() {
            relabel[old] = new as u32;
        }
        let mut regions: Vec<Vec<u32>> = order
            .iter()
            .map(|&k| Vec::with_capacity(sizes[k]))
            .collect();
        for (i, l) in region.iter_mut().enumerate() {
            if *l != u32::MAX {
                *l = relabel[*l as usize];
                regions[*l as usize].push(i as u32);
            }
        }
        Self {
            cell_px,
            cols,
            rows,
            free,
            region,
            regions,
        }
    }

    /// Cell side, px.
    pub fn cell_px(&self) -> f64 {
        self.cell_px
    }

    /// Columns and rows.
    pub fn size(&self) -> (usize, usize) {
        (self.cols, self.rows)
    }

    /// Whether cell `(col, row)` is free.
    pub fn is_free(&self, col: usize, row: usize) -> bool {
        self.free[row * self.cols + col]
    }

    /// The cell holding `p`, if inside the grid.
    pub fn cell_of(&self, p: Point) -> Option<(usize, usize)> {
        let c = (p.x / self.cell_px).floor();
        let r = (p.y / self.cell_px).floor();
        (c >= 0.0 && r >= 0.0 && (c as usize) < self.cols && (r as usize) < self.rows)
            .then_some((c as usize, r as usize))
    }

    /// Centre of cell `(col, row)`.
    pub fn center(&self, col: usize, row: usize) -> Point {
        Point::new(
            (col as f64 + 0.5) * self.cell_px,
            (row as f64 + 0.5) * self.cell_px,
        )
    }

    /// Region label of the cell holding `p` (0 is the largest region), if it is free.
    pub fn region_at(&self, p: Point) -> Option<u32> {
        let (c, r) = self.cell_of(p)?;
        let l = self.region[r * self.cols + c];
        (l != u32::MAX).then_some(l)
    }

    /// Number of connected regions.
    pub fn region_count(&self) -> usize {
        self.regions.len()
    }

    /// Cells `row * cols + col` of region `label`, in increasing order.
    pub fn region_cells(&self, label: u32) -> &[u32] {
        self.regions.get(label as usize).map_or(&[], Vec::as_slice)
    }

    /// Number of free cells.
    pub fn free_count(&self) -> usize {
        self.free.iter().filter(|&&f| f).count()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Aabb;

    #[test]
    fn a_wall_splits_a_room_into_two_regions() {
        let wall = Aabb::from_corners(Point::new(49.0, 0.0), Point::new(51.0, 100.0));
        let frame =
            crate::scene::Scene::from_occupancy(100, 100, &vec![false; 100 * 100], 1.0, 50.0);
        let mut boxes = frame.boxes().to_vec();
        boxes.push(wall);
        let scene = Scene::from_boxes(100.0, 100.0, boxes, 50.0);
        let grid = FreeGrid::new(&scene, 5.0, 5.0);
        assert_eq!(grid.region_count(), 2);
        assert_ne!(
            grid.region_at(Point::new(20.0, 50.0)),
            grid.region_at(Point::new(80.0, 50.0))
        );
        // The centre cell column next to the wall is blocked; cells 5 px from the frame are free
        // only if their centre is at least 5 px away (centre 7.5 px: free; 2.5 px: blocked).
        assert_eq!(grid.region_at(Point::new(50.0, 50.0)), None);
        assert!(grid.is_free(1, 1));
        assert!(!grid.is_free(0, 1));
    }
}
