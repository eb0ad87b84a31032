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
    /// Region label of each free cell (`u32::MAX` for blocked cells) and the number of regions,
    /// labelled on first use: planners need only the moves, and placement in a maze no regions.
    labels: std::sync::OnceLock<(Vec<u32>, usize)>,
    /// Cells of each region, largest region first.
    regions: std::sync::OnceLock<Vec<Vec<u32>>>,
    /// The 8-neighbour moves open from each cell, as bits (see [`FreeGrid::moves`]).
    moves: Vec<u8>,
    /// Of those, the moves from or into a close cell, worked out on first use (a planner's).
    close_moves: std::sync::OnceLock<Vec<u8>>,
}

impl FreeGrid {
    /// The grid of `scene` for a disc of `radius` px, with cells of `cell_px`; free cells within
    /// `margin_px` of touching an obstacle are also marked [close](FreeGrid::is_close).
    ///
    /// Cells grow as needed to keep their number under `MAX_CELLS`.
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
        // A maze whose walls are too thick to slip between needs no link checked.
        if !maze_is_safe {
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
                        if !inside || !free[j] || (exact && !(close[i] && close[j])) {
                            continue;
                        }
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
        let moves = open_moves(cols, rows, &free, &unlinked);
        Self {
            cell_px,
            cols,
            rows,
            free,
            close,
            labels: std::sync::OnceLock::new(),
            regions: std::sync::OnceLock::new(),
            moves,
            close_moves: std::sync::OnceLock::new(),
        }
    }

    /// Whether free cell `index` (`row * cols + col`) is within the margin of an obstacle.
    pub fn is_close(&self, index: usize) -> bool {
        self.close[index] && self.free[index]
    }

    /// Whether cell `index` (`row * cols + col`) is free.
    pub fn is_free_index(&self, index: usize) -> bool {
        self.free[index]
    }

    /// The moves a disc can make from each cell to a neighbouring cell, as bits in the order
    /// E, W, N, S, NE, SE, NW, SW (row + 1 is north): a move is open when the target cell is free
    /// and linked and, for a diagonal, both cells beside it are free (paths never cut a corner).
    pub(crate) fn moves(&self) -> &[u8] {
        &self.moves
    }

    /// What each [move](FreeGrid::moves) adds to a cell's index, in the moves' bit order.
    pub(crate) fn move_offsets(&self) -> [isize; 8] {
        let w = self.cols as isize;
        [1, -1, w, -w, w + 1, 1 - w, w - 1, -w - 1]
    }

    /// Of the [moves](FreeGrid::moves) from each cell, those that start or end in a
    /// [close](FreeGrid::is_close) cell, as bits in the same order: what a planner charging for
    /// closeness needs, read from the cell it stands on rather than from each neighbour.
    pub(crate) fn close_moves(&self) -> &[u8] {
        self.close_moves.get_or_init(|| {
            let n = self.moves.len();
            // The close marks as bytes with a row and a cell of nothing either side, so every
            // cell reads its eight neighbours' in one pass: a move off the grid (or across its
            // edge) reads a mark that is not its target's, but it is never open.
            let pad = self.cols + 1;
            let mut close = vec![0u8; n + 2 * pad];
            for (c, &x) in close[pad..pad + n].iter_mut().zip(&self.close) {
                *c = u8::from(x);
            }
            let there = self
                .move_offsets()
                .map(|off| &close[(pad as isize + off) as usize..][..n]);
            let here = &close[pad..pad + n];
            let mut out = vec![0u8; n];
            for (i, (o, &m)) in out.iter_mut().zip(&self.moves).enumerate() {
                let mut near = 0u8.wrapping_sub(here[i]);
                for (k, there) in there.iter().enumerate() {
                    near |= there[i] << k;
                }
                *o = m & near;
            }
            out
        })
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
        let l = self.labels().0[r * self.cols + c];
        (l != u32::MAX).then_some(l)
    }

    /// Number of connected regions.
    pub fn region_count(&self) -> usize {
        self.labels().1
    }

    /// Region labels and their number, labelled on first use.
    fn labels(&self) -> &(Vec<u32>, usize) {
        self.labels
            .get_or_init(|| label_regions(self.cols, self.rows, &self.free, &self.moves))
    }

    /// Cells `row * cols + col` of region `label`, in increasing order (listed on first use).
    pub fn region_cells(&self, label: u32) -> &[u32] {
        let regions = self.regions.get_or_init(|| {
            let (labels, count) = self.labels();
            let mut regions = vec![Vec::new(); *count];
            for (i, &l) in labels.iter().enumerate() {
                if l != u32::MAX {
                    regions[l as usize].push(i as u32);
                }
            }
            regions
        });
        regions.get(label as usize).map_or(&[], Vec::as_slice)
    }

    /// Number of free cells.
    pub fn free_count(&self) -> usize {
        self.free.iter().filter(|&&f| f).count()
    }
}

/// Connected regions of free cells over 4-neighbour links: each free cell's label (`u32::MAX` for
/// blocked cells; 0 is the largest region, ties in the order of their lowest cell) and the number
/// of regions.
///
/// Union-find over runs: each row splits into runs of free cells linked east-west; a run joins
/// the runs below it that it is linked to; every set's root is its lowest cell. Links are read
/// from the cells' open [moves](open_moves): between two free cells, the east (bit 0) and north
/// (bit 2) moves are open exactly where the link is.
fn label_regions(cols: usize, rows: usize, free: &[bool], moves: &[u8]) -> (Vec<u32>, usize) {
    fn root(parent: &mut [u32], mut i: u32) -> u32 {
        while parent[i as usize] != i {
            let up = parent[parent[i as usize] as usize];
            parent[i as usize] = up;
            i = up;
        }
        i
    }
    // `run[i]`: the first cell of free cell i's run. `parent`: over run starts only.
    let mut run = vec![u32::MAX; cols * rows];
    let mut parent = vec![u32::MAX; cols * rows];
    for r in 0..rows {
        let here = r * cols;
        let mut start = u32::MAX;
        let mut below_last = u32::MAX;
        for c in 0..cols {
            let i = here + c;
            if !free[i] {
                start = u32::MAX;
                continue;
            }
            if start == u32::MAX || moves[i - 1] & 1 == 0 {
                start = i as u32;
                parent[i] = start;
                below_last = u32::MAX;
            }
            run[i] = start;
            if r > 0 && moves[i - cols] & 4 != 0 {
                let below = run[i - cols];
                if below != below_last {
                    below_last = below;
                    let (a, b) = (root(&mut parent, start), root(&mut parent, below));
                    if a != b {
                        let (lo, hi) = (a.min(b), a.max(b));
                        parent[hi as usize] = lo;
                    }
                }
            }
        }
    }
    // Label sets in the order of their lowest cell (met before the set's other cells), a run at a
    // time, counting cells.
    let mut region = run;
    let mut sizes: Vec<usize> = Vec::new();
    let mut i = 0;
    while i < cols * rows {
        if region[i] == u32::MAX {
            i += 1;
            continue;
        }
        let start = i;
        let top = root(&mut parent, start as u32) as usize;
        let label = if top == start {
            sizes.push(0);
            (sizes.len() - 1) as u32
        } else {
            region[top]
        };
        while i < cols * rows && region[i] == start as u32 {
            region[i] = label;
            i += 1;
        }
        sizes[label as usize] += i - start;
    }
    // Renumber largest first (ties keep discovery order, so the result is deterministic).
    let mut order: Vec<usize> = (0..sizes.len()).collect();
    order.sort_by_key(|&k| std::cmp::Reverse(sizes[k]));
    let mut relabel = vec![0u32; sizes.len()];
    for (new, &old) in order.iter().enumerate() {
        relabel[old] = new as u32;
    }
    for l in region.iter_mut().filter(|l| **l != u32::MAX) {
        *l = relabel[*l as usize];
    }
    (region, sizes.len())
}

/// [`FreeGrid::moves`] of every cell.
fn open_moves(cols: usize, rows: usize, free: &[bool], unlinked: &[u8]) -> Vec<u8> {
    let mut moves = vec![0u8; cols * rows];
    // A move's bit: its target free, its link open, and for a diagonal both side cells free.
    // Interior cells, row by row, in arithmetic rather than branches over slices cut to the
    // row's interior (`x_w`, `x_h`, `x_e`: the cells west of, at and east of each), so no bound
    // is left to check and the loop vectorises.
    let row = |r: usize| r * cols..(r + 1) * cols;
    let m = cols.saturating_sub(2);
    fn shifted<T>(s: &[T], m: usize) -> (&[T], &[T], &[T]) {
        (&s[..m], &s[1..=m], &s[2..m + 2])
    }
    let interior_rows = if cols >= 3 {
        1..rows.saturating_sub(1)
    } else {
        0..0
    };
    for r in interior_rows {
        let (s_w, s_h, s_e) = shifted(&free[row(r - 1)], m);
        let (h_w, h_h, h_e) = shifted(&free[row(r)], m);
        let (n_w, n_h, n_e) = shifted(&free[row(r + 1)], m);
        let (us_w, us_h, us_e) = shifted(&unlinked[row(r - 1)], m);
        let (uh_w, uh_h, _) = shifted(&unlinked[row(r)], m);
        let out = &mut moves[row(r)][1..=m];
        for c in 0..m {
            let (fe, fw, fno, fs) = (h_e[c] as u8, h_w[c] as u8, n_h[c] as u8, s_h[c] as u8);
            let (uh, uw, us) = (!uh_h[c], !uh_w[c], !us_h[c]);
            let bits = (fe & uh & 1)
                | (fw & uw & 1) << 1
                | (fno & uh >> 1 & 1) << 2
                | (fs & us >> 1 & 1) << 3
                | (fe & fno & n_e[c] as u8 & uh >> 2 & 1) << 4
                | (fe & fs & s_e[c] as u8 & !us_e[c] >> 3 & 1) << 5
                | (fw & fno & n_w[c] as u8 & uh >> 3 & 1) << 6
                | (fw & fs & s_w[c] as u8 & !us_w[c] >> 2 & 1) << 7;
            out[c] = bits * h_h[c] as u8;
        }
    }
    // The border, checking bounds: the first and last rows, the first and last columns.
    let last = rows - 1;
    let rims = (0..rows).flat_map(|r| {
        let every = r == 0 || r == last;
        let cs: Vec<usize> = if every {
            (0..cols).collect()
        } else {
            vec![0, cols - 1]
        };
        cs.into_iter().map(move |c| (c, r))
    });
    for (c, r) in rims {
        let i = r * cols + c;
        if !free[i] {
            continue;
        }
        let fe = c + 1 < cols && free[i + 1];
        let fw = c > 0 && free[i - 1];
        let fno = r + 1 < rows && free[i + cols];
        let fs = r > 0 && free[i - cols];
        let mut bits = (fe && unlinked[i] & 1 == 0) as u8
            | ((fw && unlinked[i - 1] & 1 == 0) as u8) << 1
            | ((fno && unlinked[i] & 2 == 0) as u8) << 2
            | ((fs && unlinked[i - cols] & 2 == 0) as u8) << 3;
        if fe && fno {
            bits |= ((free[i + cols + 1] && unlinked[i] & 4 == 0) as u8) << 4;
        }
        if fe && fs {
            bits |= ((free[i + 1 - cols] && unlinked[i + 1 - cols] & 8 == 0) as u8) << 5;
        }
        if fw && fno {
            bits |= ((free[i + cols - 1] && unlinked[i] & 8 == 0) as u8) << 6;
        }
        if fw && fs {
            bits |= ((free[i - cols - 1] && unlinked[i - cols - 1] & 4 == 0) as u8) << 7;
        }
        moves[i] = bits;
    }
    moves
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Aabb;

    /// Whether the link from cell `(c, r)` to its neighbour `(c + dc, r + dr)` is open: the bit
    /// is kept by the lower cell of the two (east, north, north-east, north-west).
    fn link(unlinked: &[u8], cols: usize, c: usize, r: usize, dc: isize, dr: isize) -> bool {
        let up = dr > 0 || (dr == 0 && dc > 0);
        let (lc, lr, dir) = if up {
            (c as isize, r as isize, (dc, dr))
        } else {
            (c as isize + dc, r as isize + dr, (-dc, -dr))
        };
        let bit = match dir {
            (1, 0) => 0,
            (0, 1) => 1,
            (1, 1) => 2,
            (-1, 1) => 3,
            _ => unreachable!("not a neighbour"),
        };
        unlinked[lr as usize * cols + lc as usize] & (1 << bit) == 0
    }

    /// The flood fill regions were first labelled with: seeds in index order, 4-neighbour links.
    fn flood_labels(cols: usize, rows: usize, free: &[bool], unlinked: &[u8]) -> Vec<u32> {
        let mut region = vec![u32::MAX; cols * rows];
        let mut sizes = Vec::new();
        for seed in 0..cols * rows {
            if !free[seed] || region[seed] != u32::MAX {
                continue;
            }
            let label = sizes.len() as u32;
            let (mut size, mut stack) = (0, vec![seed]);
            region[seed] = label;
            while let Some(i) = stack.pop() {
                size += 1;
                let (c, r) = (i % cols, i / cols);
                let near = [
                    (c > 0).then(|| (i - 1, -1, 0)),
                    (c + 1 < cols).then(|| (i + 1, 1, 0)),
                    (r > 0).then(|| (i - cols, 0, -1)),
                    (r + 1 < rows).then(|| (i + cols, 0, 1)),
                ];
                for (j, dc, dr) in near.into_iter().flatten() {
                    if free[j] && region[j] == u32::MAX && link(unlinked, cols, c, r, dc, dr) {
                        region[j] = label;
                        stack.push(j);
                    }
                }
            }
            sizes.push(size);
        }
        let mut order: Vec<usize> = (0..sizes.len()).collect();
        order.sort_by_key(|&k| std::cmp::Reverse(sizes[k]));
        let mut relabel = vec![0u32; sizes.len()];
        for (new, &old) in order.iter().enumerate() {
            relabel[old] = new as u32;
        }
        region
            .iter()
            .map(|&l| {
                if l == u32::MAX {
                    l
                } else {
                    relabel[l as usize]
                }
            })
            .collect()
    }

    #[test]
    fn union_find_labels_regions_as_the_flood_fill_did() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        for case in 0..300 {
            let (cols, rows) = (rng.random_range(1..30), rng.random_range(1..30));
            let density = rng.random_range(0.0..1.0);
            let free: Vec<bool> = (0..cols * rows).map(|_| rng.random_bool(density)).collect();
            let unlinked: Vec<u8> = (0..cols * rows)
                .map(|_| {
                    if rng.random_bool(0.2) {
                        rng.random_range(0..16)
                    } else {
                        0
                    }
                })
                .collect();
            let moves = open_moves(cols, rows, &free, &unlinked);
            let (region, count) = label_regions(cols, rows, &free, &moves);
            let flood = flood_labels(cols, rows, &free, &unlinked);
            assert_eq!(region, flood, "case {case}");
            let labels = flood.iter().filter(|&&l| l != u32::MAX);
            assert_eq!(count, labels.max().map_or(0, |&l| l as usize + 1));
            for i in 0..cols * rows {
                let (c, r) = ((i % cols) as isize, (i / cols) as isize);
                let steps = [
                    (1, 0),
                    (-1, 0),
                    (0, 1),
                    (0, -1),
                    (1, 1),
                    (1, -1),
                    (-1, 1),
                    (-1, -1),
                ];
                for (bit, (dc, dr)) in steps.into_iter().enumerate() {
                    let (nc, nr) = (c + dc, r + dr);
                    let inside = |c: isize, r: isize| {
                        c >= 0 && r >= 0 && c < cols as isize && r < rows as isize
                    };
                    let at = |c: isize, r: isize| r as usize * cols + c as usize;
                    let open = free[i]
                        && inside(nc, nr)
                        && free[at(nc, nr)]
                        && link(&unlinked, cols, c as usize, r as usize, dc, dr)
                        && (dc == 0 || dr == 0 || (free[at(nc, r)] && free[at(c, nr)]));
                    assert_eq!(
                        moves[i] >> bit & 1 == 1,
                        open,
                        "case {case} cell {i} move {bit}"
                    );
                }
            }
        }
    }

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

    #[test]
    fn close_moves_are_the_open_moves_from_or_into_a_close_cell() {
        for seed in 0..4u64 {
            let mut config = crate::config::SimConfig::default();
            config.maze.cols = 5 + seed as u32;
            let config = config.validate().expect("valid");
            let scene = crate::sim::maze_scene(&config, seed);
            let grid = FreeGrid::new(&scene, 5.0, 5.0, 8.0);
            let cols = grid.size().0 as isize;
            // E, W, N, S, NE, SE, NW, SW.
            let offsets = [1, -1, cols, -cols, cols + 1, 1 - cols, cols - 1, -cols - 1];
            assert!(grid.close_moves().iter().any(|&c| c != 0));
            assert!(grid.close_moves() != grid.moves());
            for (i, (&m, &c)) in grid.moves().iter().zip(grid.close_moves()).enumerate() {
                for (k, off) in offsets.into_iter().enumerate() {
                    let expect = m >> k & 1 == 1
                        && (grid.is_close(i) || grid.is_close((i as isize + off) as usize));
                    assert_eq!(c >> k & 1 == 1, expect, "seed {seed}, cell {i}, move {k}");
                }
            }
        }
    }
}
