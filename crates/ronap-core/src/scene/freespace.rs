//! The free-space grid: where the robot's centre may stand, on square cells of `grid_px`.
//!
//! A cell is free when a disc of the robot's radius centred on the cell centre touches no obstacle
//! (the configuration space, sampled). Two neighbouring free cells are linked when the disc can
//! drive straight from one centre to the other; connected regions follow 4-neighbour links, so two
//! cells in one region are joined by a path the robot can drive. Start and goal are drawn from one
//! region; planners search this grid.
//!
//! Checking a link costs a swept-disc query, so it is done only where it can fail: between two
//! cells that are both within the margin of an obstacle (elsewhere the straight line between the
//! centres keeps the clearance), and not at all in a maze whose walls are too thick for two free
//! centres to lie on either side of one.

use crate::geometry::Point;
use crate::scene::Scene;

/// Most cells a grid has (about 150 MB with its labels).
pub const MAX_CELLS: usize = 25_000_000;

/// Free cells of a scene for a disc of a given radius.
#[derive(Clone, Debug)]
pub struct FreeGrid {
    cell_px: f64,
    cols: usize,
    rows: usize,
    /// `free[row * cols + col]`, row 0 at the bottom.
    free: Vec<bool>,
    /// Free cells whose centre is within `margin_px` of touching an obstacle.
    close: Vec<bool>,
    /// Links that are blocked, per cell: bit 0 to the east, 1 north, 2 north-east, 3 north-west.
    unlinked: Vec<u8>,
    /// Region label of each free cell (`u32::MAX` for blocked cells).
    region: Vec<u32>,
    /// Cells of each region, largest region first.
    regions: Vec<Vec<u32>>,
}

impl FreeGrid {
    /// The grid of `scene` for a disc of `radius` px, with cells of `cell_px`; free cells within
    /// `margin_px` of touching an obstacle are also marked [close](FreeGrid::is_close).
    ///
    /// Cells grow as needed to keep their number under [`MAX_CELLS`].
    pub fn new(scene: &Scene, radius: f64, cell_px: f64, margin_px: f64) -> Self {
        let cell_px = cell_px.max((scene.width() * scene.height() / MAX_CELLS as f64).sqrt());
        let cols = ((scene.width() / cell_px).floor() as usize).max(1);
        let rows = ((scene.height() / cell_px).floor() as usize).max(1);
        let mut free = vec![true; cols * rows];
        let mut close = vec![false; cols * rows];
        let r2 = radius * radius;
        let close2 = (radius + margin_px).powi(2);
        // Block the cells whose centres are within `radius` of each box: a pass per box over the
        // cells of its grown bounding box, exact at the rounded corners.
        for b in scene.boxes() {
            let g = b.inflated(radius + margin_px);
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
                    let d2 = b.distance_squared(p);
                    if d2 < r2 {
                        free[r * cols + c] = false;
                    } else if d2 < close2 {
                        close[r * cols + c] = true;
                    }
                }
            }
        }
        // The same for discs and polygons, measured through their shapes.
        for shape in scene.shapes() {
            let g = shape.aabb().inflated(radius + margin_px);
            let c0 = ((g.min.x / cell_px - 0.5).ceil().max(0.0)) as usize;
            let r0 = ((g.min.y / cell_px - 0.5).ceil().max(0.0)) as usize;
            let c1 = ((g.max.x / cell_px - 0.5).floor()).min(cols as f64 - 1.0);
            let r1 = ((g.max.y / cell_px - 0.5).floor()).min(rows as f64 - 1.0);
            if c1 < 0.0 || r1 < 0.0 {
                continue;
            }
            for r in r0..=r1 as usize {
                for c in c0..=c1 as usize {
                    let p = Point::new((c as f64 + 0.5) * cell_px, (r as f64 + 0.5) * cell_px);
                    let d = shape.distance(p);
                    if d < radius {
                        free[r * cols + c] = false;
                    } else if d < radius + margin_px {
                        close[r * cols + c] = true;
                    }
                }
            }
        }
        // Label regions by flood fill, numbering them in the order their first cell is met.
        let mut unlinked = vec![0u8; cols * rows];
        let maze_is_safe = !scene.has_added_obstacles()
            && match scene.source() {
                crate::scene::SceneSource::Maze {
                    wall_thickness_px, ..
                } => 2.0 * radius + wall_thickness_px > cell_px * std::f64::consts::SQRT_2,
                _ => false,
            };
        // A link between centres both at least radius + cell/sqrt 2 clear cannot fail: every point
        // of it is within cell/sqrt 2 of one of them. The margin must cover that to skip a check.
        let exact = !maze_is_safe && margin_px * 2.0 >= cell_px * std::f64::consts::SQRT_2;
        for r in 0..rows {
            for c in 0..cols {
                let i = r * cols + c;
                if !free[i] {
                    continue;
                }
                let links = [
                    (0u8, c + 1 < cols, i + 1),
                    (1, r + 1 < rows, i + cols),
                    (2, c + 1 < cols && r + 1 < rows, i + cols + 1),
                    (3, c > 0 && r + 1 < rows, (i + cols).wrapping_sub(1)),
                ];
                for (bit, inside, j) in links {
                    if !inside || !free[j] {
                        continue;
                    }
                    let must_check = if exact {
                        close[i] && close[j]
                    } else {
                        !maze_is_safe
                    };
                    if must_check {
                        let a = Point::new((c as f64 + 0.5) * cell_px, (r as f64 + 0.5) * cell_px);
                        let b = Point::new(
                            ((j % cols) as f64 + 0.5) * cell_px,
                            ((j / cols) as f64 + 0.5) * cell_px,
                        );
                        if !scene.sweep_clear(a, b, radius) {
                            unlinked[i] |= 1 << bit;
                        }
                    }
                }
            }
        }
        let linked = |i: usize, j: usize| link_open(&unlinked, cols, i, j);
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
                    if free[j] && region[j] == u32::MAX && linked(i, j) {
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
            close,
            unlinked,
            region,
            regions,
        }
    }

    /// Whether the disc can drive straight between the centres of neighbouring cells `i` and `j`
    /// (both free; `true` for cells that are not neighbours).
    pub fn linked(&self, i: usize, j: usize) -> bool {
        link_open(&self.unlinked, self.cols, i, j)
    }

    /// Whether free cell `index` (`row * cols + col`) is within the margin of an obstacle.
    pub fn is_close(&self, index: usize) -> bool {
        self.close[index] && self.free[index]
    }

    /// Whether cell `index` (`row * cols + col`) is free.
    pub fn is_free_index(&self, index: usize) -> bool {
        self.free[index]
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

/// Whether the link between neighbouring cells `i` and `j` is open in `unlinked`.
fn link_open(unlinked: &[u8], cols: usize, i: usize, j: usize) -> bool {
    let (lo, hi) = (i.min(j), i.max(j));
    let bit = match hi - lo {
        1 => 0,
        d if d == cols => 1,
        d if d == cols + 1 => 2,
        d if d + 1 == cols => 3,
        _ => return true,
    };
    unlinked[lo] & (1 << bit) == 0
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
        let grid = FreeGrid::new(&scene, 5.0, 5.0, 5.0);
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
        // Centre 7.5 px from the frame: clearance 2.5 px, within the 5 px margin. 12.5 px: not.
        assert!(grid.is_close(5 * 20 + 1));
        assert!(!grid.is_close(5 * 20 + 2));
    }

    #[test]
    fn a_gap_narrower_than_the_robot_does_not_join_regions() {
        // A 0.2 px wall across a room with a 9 px gap: a disc of radius 5 cannot pass, although
        // cell centres on both sides of the gap are clear.
        let frame = Scene::from_occupancy(100, 100, &vec![false; 100 * 100], 1.0, 50.0);
        let mut boxes = frame.boxes().to_vec();
        boxes.push(Aabb::from_corners(
            Point::new(0.0, 49.9),
            Point::new(48.0, 50.1),
        ));
        boxes.push(Aabb::from_corners(
            Point::new(57.0, 49.9),
            Point::new(100.0, 50.1),
        ));
        let scene = Scene::from_boxes(100.0, 100.0, boxes, 50.0);
        let grid = FreeGrid::new(&scene, 5.0, 5.0, 5.0);
        assert_eq!(grid.region_count(), 2);
        assert_ne!(
            grid.region_at(Point::new(50.0, 20.0)),
            grid.region_at(Point::new(50.0, 80.0))
        );
        // Widen the gap to 15 px and the robot fits through. (The grid is conservative: a gap the
        // disc just fits through may stay closed when no column of cell centres lines up with it.)
        let mut boxes = frame.boxes().to_vec();
        boxes.push(Aabb::from_corners(
            Point::new(0.0, 49.9),
            Point::new(43.0, 50.1),
        ));
        boxes.push(Aabb::from_corners(
            Point::new(58.0, 49.9),
            Point::new(100.0, 50.1),
        ));
        let scene = Scene::from_boxes(100.0, 100.0, boxes, 50.0);
        assert_eq!(FreeGrid::new(&scene, 5.0, 5.0, 5.0).region_count(), 1);
    }
}
