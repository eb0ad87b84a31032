//! A coarse uniform grid over a scene's boxes for casting rays whose cost does not grow with range.
//!
//! Each square cell holds a copy of every box that touches it. A ray walks the cells it crosses in
//! order (Amanatides and Woo, "A fast voxel traversal algorithm for ray tracing", 1987), tests the
//! boxes of each with [`Aabb::ray_hit`], and stops at the first cell whose boxes give a hit no
//! further than the cell's far side: no box in a later cell can be nearer. A ray so pays per cell
//! it crosses before its first hit, whatever its range. Lengths in px.
//!
//! The answer is the minimum of `ray_hit` over the boxes the ray meets, exactly as testing every
//! box gives (that minimum does not depend on the order boxes are tested in, nor on extra boxes
//! tested). Cells list the boxes within a small margin of them, so a hit point that rounding puts
//! a hair across a cell line is still found in the cell the walk reads first; and a box is passed
//! to `ray_hit` unless the ray's line misses it by more than rounding could explain.

use crate::geometry::{Aabb, Point, Vector};

/// Most cells a grid has; its cells grow to keep under it.
pub const MAX_CELLS: usize = 1 << 20;

/// A box as a cell lists it: the box itself, and the centre and half extents of its part in the
/// cell, for the quick test of whether a ray crossing the cell meets it there.
#[derive(Clone, Copy, Debug)]
struct Listed {
    aabb: Aabb,
    center: Point,
    half: Vector,
}

impl Listed {
    /// An empty slot: its negative half extents fail every quick test.
    const NONE: Listed = Listed {
        aabb: Aabb {
            min: Point::new(0.0, 0.0),
            max: Point::new(0.0, 0.0),
        },
        center: Point::new(0.0, 0.0),
        half: Vector::new(f64::NEG_INFINITY, f64::NEG_INFINITY),
    };
}

/// Boxes a cell holds in place: most cells list no more, so a walk reads a cell without a loop
/// whose length the processor would have to guess.
const SLOTS: usize = 2;

/// A cell: its first boxes in place (the rest padded with [`Listed::NONE`]), and where the others
/// are in [`RayGrid::more`].
#[derive(Clone, Copy, Debug)]
struct Cell {
    slots: [Listed; SLOTS],
    more: u32,
    more_len: u32,
}

/// Boxes listed per square cell, for ray casts.
#[derive(Clone, Debug)]
pub struct RayGrid {
    /// Lower-left corner of cell `(0, 0)`.
    origin: Point,
    /// Width and height of the grid, px.
    extent: Vector,
    cell_px: f64,
    inv_cell_px: f64,
    cols: usize,
    rows: usize,
    /// Cells row by row from the bottom.
    cells: Vec<Cell>,
    /// The boxes of cells that list more than [`SLOTS`].
    more: Vec<Listed>,
    /// More than rounding can move a box's distance from a ray's line, px.
    slack_px: f64,
}

/// Where rays from one point start in a [`RayGrid`] ([`RayGrid::start`]).
#[derive(Clone, Copy, Debug)]
pub struct GridStart {
    origin: Point,
    /// The origin's cell, when the origin is in the grid.
    cell: Option<(isize, isize)>,
}

impl RayGrid {
    /// A grid of cells of side `cell_px` whose lines pass through `anchor`, covering `bounds` and
    /// every box. Cells are doubled in side until there are at most [`MAX_CELLS`].
    pub fn new(boxes: &[Aabb], bounds: Aabb, anchor: Point, cell_px: f64) -> Self {
        let area = boxes.iter().fold(bounds, |a, b| Aabb {
            min: Point::new(a.min.x.min(b.min.x), a.min.y.min(b.min.y)),
            max: Point::new(a.max.x.max(b.max.x), a.max.y.max(b.max.y)),
        });
        let mut cell_px = cell_px;
        let (origin, cols, rows) = loop {
            let line_below = |v: f64, a: f64| a + ((v - a) / cell_px).floor() * cell_px;
            let origin = Point::new(
                line_below(area.min.x, anchor.x),
                line_below(area.min.y, anchor.y),
            );
            let cols = (((area.max.x - origin.x) / cell_px).floor() as usize + 1).max(1);
            let rows = (((area.max.y - origin.y) / cell_px).floor() as usize + 1).max(1);
            if cols.saturating_mul(rows) <= MAX_CELLS {
                break (origin, cols, rows);
            }
            cell_px *= 2.0;
        };
        // Rounding in the walk moves a cell line by far less than this.
        let margin = cell_px * 1e-6;
        let cell_of = |v: f64, lo: f64, n: usize| -> usize {
            (((v - lo) / cell_px).floor().max(0.0) as usize).min(n - 1)
        };
        let cells_of = |b: &Aabb| {
            let g = b.inflated(margin);
            (
                cell_of(g.min.x, origin.x, cols)..=cell_of(g.max.x, origin.x, cols),
                cell_of(g.min.y, origin.y, rows)..=cell_of(g.max.y, origin.y, rows),
            )
        };
        // Two passes (count, then fill) build the compressed rows without per-cell vectors.
        let mut starts = vec![0u32; cols * rows + 1];
        for b in boxes {
            let (cs, rs) = cells_of(b);
            for r in rs {
                for c in cs.clone() {
                    starts[r * cols + c + 1] += 1;
                }
            }
        }
        for i in 1..starts.len() {
            starts[i] += starts[i - 1];
        }
        let mut fill = starts.clone();
        let empty = Listed {
            aabb: Aabb::from_corners(Point::origin(), Point::origin()),
            center: Point::origin(),
            half: Vector::zeros(),
        };
        let mut listed = vec![empty; starts[cols * rows] as usize];
        for b in boxes {
            let (cs, rs) = cells_of(b);
            for r in rs {
                for c in cs.clone() {
                    // The part of the box in the cell (grown by the margin), which is what a ray
                    // crossing the cell can meet there.
                    let lo = origin + Vector::new(c as f64, r as f64) * cell_px;
                    let cell = Aabb {
                        min: lo,
                        max: lo + Vector::new(cell_px, cell_px),
                    }
                    .inflated(margin);
                    let part = Aabb {
                        min: Point::new(b.min.x.max(cell.min.x), b.min.y.max(cell.min.y)),
                        max: Point::new(b.max.x.min(cell.max.x), b.max.y.min(cell.max.y)),
                    };
                    let half = part.extents() / 2.0;
                    let slot = &mut fill[r * cols + c];
                    listed[*slot as usize] = Listed {
                        aabb: *b,
                        center: part.min + half,
                        half,
                    };
                    *slot += 1;
                }
            }
        }
        // The first boxes of each cell in place, the rest after one another.
        let mut more = Vec::new();
        let cells = starts
            .windows(2)
            .map(|w| {
                let all = &listed[w[0] as usize..w[1] as usize];
                let mut slots = [Listed::NONE; SLOTS];
                for (slot, b) in slots.iter_mut().zip(all) {
                    *slot = *b;
                }
                let extra = all.get(SLOTS..).unwrap_or(&[]);
                let cell = Cell {
                    slots,
                    more: more.len() as u32,
                    more_len: extra.len() as u32,
                };
                more.extend_from_slice(extra);
                cell
            })
            .collect();
        let largest = [area.min.x, area.min.y, area.max.x, area.max.y]
            .iter()
            .fold(1.0f64, |m, v| m.max(v.abs()));
        Self {
            origin,
            extent: Vector::new(cols as f64, rows as f64) * cell_px,
            cell_px,
            inv_cell_px: 1.0 / cell_px,
            cols,
            rows,
            cells,
            more,
            slack_px: largest * 1e-9,
        }
    }

    /// A grid over `boxes` in a scene spanning `bounds`, with cells sized to the boxes' density:
    /// about one cell per box over the scene (anchored at its corner), none smaller than 4 px.
    /// Larger cells mean fewer steps and more boxes tested in each; one per box measured fastest
    /// for 1000 px rays in every scene tried (an office plan of 12 boxes, mazes drawn as images,
    /// warehouses of 134 boxes, 1500 scattered small boxes), from 1.2x to 1.6x faster than four.
    pub fn fitted(boxes: &[Aabb], bounds: Aabb) -> Self {
        let size = bounds.extents();
        let per_box = size.x * size.y / boxes.len().max(1) as f64;
        let cell_px = per_box.sqrt().max(4.0);
        Self::new(boxes, bounds, bounds.min, cell_px)
    }

    /// The cell holding `p`, if `p` is in the grid. A float cast truncates, which is the floor
    /// here (and saturates, so a hair below the grid is its first cell).
    #[inline]
    fn cell_of(&self, p: Point) -> (isize, isize) {
        let rel = p - self.origin;
        (
            ((rel.x * self.inv_cell_px) as isize).min(self.cols as isize - 1),
            ((rel.y * self.inv_cell_px) as isize).min(self.rows as isize - 1),
        )
    }

    /// What every ray from `origin` shares: the cell it starts in.
    #[inline]
    pub fn start(&self, origin: Point) -> GridStart {
        let rel = origin - self.origin;
        let inside =
            rel.x >= 0.0 && rel.y >= 0.0 && rel.x <= self.extent.x && rel.y <= self.extent.y;
        GridStart {
            origin,
            cell: inside.then(|| self.cell_of(origin)),
        }
    }

    /// The nearest [`Aabb::ray_hit`] of the ray `start.origin + t * dir`, `t` in `[0, max_t]`,
    /// given `inv_dir = 1 / dir` per component, over every box of the grid: `Some(0.0)` when the
    /// origin is inside a box, `None` when no box lies within `max_t`.
    #[inline(always)]
    pub fn cast(&self, start: &GridStart, dir: Vector, inv_dir: Vector, max_t: f64) -> Option<f64> {
        let o = start.origin;
        let (mut col, mut row) = match start.cell {
            Some(cell) => cell,
            None => {
                // Where the ray enters the grid, if it does within `max_t`.
                let area = Aabb {
                    min: self.origin,
                    max: self.origin + self.extent,
                };
                let enter = area.ray_hit(o, inv_dir, max_t)?;
                self.cell_of(o + dir * enter)
            }
        };
        let c = self.cell_px;
        // Per axis: the step between cells, the `t` of the next cell line ahead and the `t`
        // between lines. An axis the ray runs parallel to never steps: its next line is further
        // than any other.
        let ahead_x = isize::from(inv_dir.x > 0.0);
        let ahead_y = isize::from(inv_dir.y > 0.0);
        let (step_x, step_y) = (2 * ahead_x - 1, 2 * ahead_y - 1);
        let axis = |line: f64, o: f64, inv: f64| -> (f64, f64) {
            if inv.is_finite() {
                ((line - o) * inv, c * inv.abs())
            } else {
                (f64::MAX, 0.0)
            }
        };
        let line_x = self.origin.x + (col + ahead_x) as f64 * c;
        let line_y = self.origin.y + (row + ahead_y) as f64 * c;
        let (mut next_x, delta_x) = axis(line_x, o.x, inv_dir.x);
        let (mut next_y, delta_y) = axis(line_y, o.y, inv_dir.y);
        let (cols, rows) = (self.cols as isize, self.rows as isize);
        let mut cell = row * cols + col;
        let abs = dir.abs();
        let mut best = f64::INFINITY;
        loop {
            let here = &self.cells[cell as usize];
            let meets = here.slots.map(|b| self.meets(&b, o, dir, abs));
            // Not `any`, which stops at the first and so branches on each.
            if meets.iter().fold(false, |any, &m| any | m) {
                for (b, m) in here.slots.iter().zip(meets) {
                    if m {
                        Self::test(b, o, inv_dir, max_t, &mut best);
                    }
                }
            }
            if here.more_len > 0 {
                let more = here.more as usize..(here.more + here.more_len) as usize;
                for b in &self.more[more] {
                    if self.meets(b, o, dir, abs) {
                        Self::test(b, o, inv_dir, max_t, &mut best);
                    }
                }
            }
            // A branch on the axis crossed next: the processor guesses it well enough that the
            // walk's steps overlap, where a blend of the two would chain each step to the last.
            // Each arm checks the ray's end against its own line (one check before the branch,
            // against the nearer of the two, measured 2-5% slower on image rays).
            if next_x < next_y {
                if best.min(max_t) <= next_x {
                    break;
                }
                col += step_x;
                cell += step_x;
                next_x += delta_x;
                if (col as usize) >= cols as usize {
                    break;
                }
            } else {
                if best.min(max_t) <= next_y {
                    break;
                }
                row += step_y;
                cell += step_y * cols;
                next_y += delta_y;
                if (row as usize) >= rows as usize {
                    break;
                }
            }
        }
        (best <= max_t).then_some(best)
    }

    /// Whether the ray's line comes within the half width across it (the perpendicular of `dir`)
    /// of the box's part in the cell, give or take rounding: the line within the cell is the
    /// ray's piece there, so a box it misses is met, if at all, in another cell that lists it.
    #[inline(always)]
    fn meets(&self, b: &Listed, o: Point, dir: Vector, abs: Vector) -> bool {
        let rel = b.center - o;
        let across = rel.x * dir.y - rel.y * dir.x;
        across.abs() <= b.half.x * abs.y + b.half.y * abs.x + self.slack_px
    }

    /// Lowers `best` to the ray's hit on `b`, if any.
    #[inline(always)]
    fn test(b: &Listed, o: Point, inv_dir: Vector, max_t: f64, best: &mut f64) {
        if let Some(t) = b.aabb.ray_hit(o, inv_dir, max_t) {
            *best = if t < *best { t } else { *best };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::unit;
    use rand::{Rng, SeedableRng};

    fn inv(d: Vector) -> Vector {
        Vector::new(1.0 / d.x, 1.0 / d.y)
    }

    /// Thin walls on the lines of a 50 px grid and small boxes anywhere, some across the edge.
    fn walls_and_clutter(rng: &mut impl Rng) -> Vec<Aabb> {
        let mut boxes = Vec::new();
        for _ in 0..40 {
            let (c, r) = (
                rng.random_range(0..20) as f64,
                rng.random_range(0..20) as f64,
            );
            let len = rng.random_range(1..5) as f64 * 50.0;
            boxes.push(if rng.random() {
                Aabb::from_corners(
                    Point::new(c * 50.0 - 1.0, r * 50.0 - 1.0),
                    Point::new(c * 50.0 + len + 1.0, r * 50.0 + 1.0),
                )
            } else {
                Aabb::from_corners(
                    Point::new(c * 50.0 - 1.0, r * 50.0 - 1.0),
                    Point::new(c * 50.0 + 1.0, r * 50.0 + len + 1.0),
                )
            });
        }
        for _ in 0..40 {
            let p = Point::new(
                rng.random_range(-50.0..1050.0),
                rng.random_range(-50.0..1050.0),
            );
            let size = Vector::new(rng.random_range(0.0..40.0), rng.random_range(0.0..40.0));
            boxes.push(Aabb::from_corners(p, p + size));
        }
        boxes
    }

    #[test]
    fn a_walk_gives_the_bits_every_box_gives() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(17);
        let bounds = Aabb::from_corners(Point::origin(), Point::new(1000.0, 1000.0));
        let mut walked = 0;
        for round in 0..6 {
            let boxes = walls_and_clutter(&mut rng);
            let grid = match round {
                0 => RayGrid::fitted(&boxes, bounds),
                1 => RayGrid::new(&boxes, bounds, Point::origin(), 50.0),
                2 => RayGrid::new(&boxes, bounds, Point::new(3.3, -7.1), 13.7),
                3 => RayGrid::new(&boxes, bounds, Point::origin(), 5000.0),
                _ => RayGrid::new(&boxes, bounds, Point::origin(), 1.0 + round as f64),
            };
            for k in 0..4000 {
                // Origins on cell lines and corners, inside and outside the grid.
                let origin = match k % 4 {
                    0 => Point::new(
                        rng.random_range(0..21) as f64 * 50.0,
                        rng.random_range(0..21) as f64 * 50.0,
                    ),
                    1 => Point::new(
                        rng.random_range(0..21) as f64 * 50.0,
                        rng.random_range(-200.0..1200.0),
                    ),
                    _ => Point::new(
                        rng.random_range(-200.0..1200.0),
                        rng.random_range(-200.0..1200.0),
                    ),
                };
                // Along the axes and diagonals, and anywhere.
                let deg = if k % 3 == 0 {
                    rng.random_range(0..8) as f64 * 45.0
                } else {
                    rng.random_range(0.0..360.0)
                };
                let inv = inv(unit(deg));
                let max_t = [0.0, 1.0, 50.0, 500.0, 2000.0][k % 5];
                let ours = grid.cast(&grid.start(origin), unit(deg), inv, max_t);
                let all = crate::geometry::nearest_box_hit(&boxes, origin, inv, max_t);
                assert_eq!(
                    ours.map(f64::to_bits),
                    all.map(f64::to_bits),
                    "round {round} from {origin:?} at {deg} deg up to {max_t}: {ours:?} vs {all:?}"
                );
                walked += usize::from(all.is_some());
            }
        }
        assert!(walked > 6000, "only {walked} rays hit something");
    }

    #[test]
    fn exact_axis_directions_walk_along_cell_lines() {
        // A wall across a grid line, and rays running exactly along that line (signed zeros).
        let wall = Aabb::from_corners(Point::new(99.0, 300.0), Point::new(101.0, 302.0));
        let bounds = Aabb::from_corners(Point::origin(), Point::new(1000.0, 1000.0));
        let grid = RayGrid::new(&[wall], bounds, Point::origin(), 100.0);
        let cast = |from: Point, dir: Vector, max_t: f64| {
            grid.cast(&grid.start(from), dir, inv(dir), max_t)
        };
        let up = Vector::new(0.0, 1.0);
        assert_eq!(cast(Point::new(100.0, 0.0), up, 1000.0), Some(300.0));
        let up_negative_zero = Vector::new(-0.0, 1.0);
        assert_eq!(
            cast(Point::new(101.0, 0.0), up_negative_zero, 1000.0),
            Some(300.0)
        );
        assert_eq!(cast(Point::new(100.0, 0.0), up, 299.0), None);
        let down = Vector::new(0.0, -1.0);
        assert_eq!(cast(Point::new(99.0, 900.0), down, 1000.0), Some(598.0));
        // Starting inside the wall reads 0.
        assert_eq!(cast(Point::new(100.0, 301.0), up, 1000.0), Some(0.0));
    }

    #[test]
    fn cells_stay_under_the_cap() {
        let boxes = [Aabb::from_corners(Point::origin(), Point::new(1.0, 1.0))];
        let bounds = Aabb::from_corners(Point::origin(), Point::new(100_000.0, 100_000.0));
        let grid = RayGrid::new(&boxes, bounds, Point::origin(), 1.0);
        let (cols, rows) = (grid.cols, grid.rows);
        assert!(cols * rows <= MAX_CELLS, "{cols} x {rows}");
        let (from, west) = (Point::new(50_000.0, 0.5), unit(180.0));
        assert_eq!(
            grid.cast(&grid.start(from), west, inv(west), 1e6),
            Some(49_999.0)
        );
    }
}
