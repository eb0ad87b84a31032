//! The grid a team is planned on: square cells wide enough that two robots, each at a cell
//! centre or on the move between two neighbouring centres, stay clear of each other as long as
//! they hold different cells (and do not cross the same corner at once).

use crate::geometry::Point;
use crate::scene::Scene;

/// The eight moves, orthogonal first: `(dcol, drow)`.
pub const MOVES: [(i32, i32); 8] = [
    (1, 0),
    (0, 1),
    (-1, 0),
    (0, -1),
    (1, 1),
    (-1, 1),
    (-1, -1),
    (1, -1),
];

/// Square cells over a scene, each free when a robot's disc fits at its centre, linked to a
/// neighbour (eight of them) when the disc can drive straight from one centre to the other.
#[derive(Clone, Debug)]
pub struct PlanGrid {
    cell_px: f64,
    /// Centre of cell `(0, 0)`.
    origin: Point,
    cols: usize,
    rows: usize,
    free: Vec<bool>,
    /// The open moves of each cell, bit `d` for [`MOVES`]`[d]`.
    links: Vec<u8>,
}

impl PlanGrid {
    /// The grid of `scene` for discs of `radius` px with cells of `cell_px`, cell `(0, 0)`
    /// centred at `origin` (within one cell of the scene's corner).
    pub fn new(scene: &Scene, radius: f64, cell_px: f64, origin: Point) -> Self {
        let mut grid = Self::cells(scene, radius, cell_px, origin);
        for i in 0..grid.len() {
            if !grid.free[i] {
                continue;
            }
            for (d, _) in MOVES.iter().enumerate() {
                if let Some(j) = grid.step(i, d) {
                    if grid.free[j] && scene.sweep_clear(grid.center(i), grid.center(j), radius) {
                        grid.links[i] |= 1 << d;
                    }
                }
            }
        }
        grid
    }

    /// The grid's cells, free or not, without their links.
    fn cells(scene: &Scene, radius: f64, cell_px: f64, origin: Point) -> Self {
        let count = |extent: f64, o: f64| (((extent - o) / cell_px).floor() as usize + 1).max(1);
        let cols = count(scene.width(), origin.x);
        let rows = count(scene.height(), origin.y);
        let mut grid = Self {
            cell_px,
            origin,
            cols,
            rows,
            free: vec![false; cols * rows],
            links: vec![0; cols * rows],
        };
        for i in 0..cols * rows {
            let p = grid.center(i);
            grid.free[i] = p.x >= 0.0
                && p.y >= 0.0
                && p.x <= scene.width()
                && p.y <= scene.height()
                && scene.disc_clear(p, radius);
        }
        grid
    }

    /// The grid whose origin, among cells aligned on each of `anchors` (robots' starts and
    /// goals) and one half a cell off the scene's corner, leaves the most cells free.
    pub fn best(scene: &Scene, radius: f64, cell_px: f64, anchors: &[Point]) -> Self {
        let mut origins: Vec<Point> = vec![Point::new(cell_px / 2.0, cell_px / 2.0)];
        for a in anchors.iter().take(8) {
            origins.push(Point::new(a.x.rem_euclid(cell_px), a.y.rem_euclid(cell_px)));
        }
        let mut best: Option<(usize, Point)> = None;
        for o in origins {
            let g = Self::cells(scene, radius, cell_px, o);
            let free = g.free.iter().filter(|&&f| f).count();
            if best.is_none_or(|(n, _)| free > n) {
                best = Some((free, o));
            }
        }
        let origin = best.map_or(Point::new(cell_px / 2.0, cell_px / 2.0), |(_, o)| o);
        Self::new(scene, radius, cell_px, origin)
    }

    /// Cells.
    pub fn len(&self) -> usize {
        self.cols * self.rows
    }

    /// Columns and rows.
    pub fn size(&self) -> (usize, usize) {
        (self.cols, self.rows)
    }

    /// Cell side, px.
    pub fn cell_px(&self) -> f64 {
        self.cell_px
    }

    /// Whether cell `i` is free (the tests' question; the search asks the links).
    #[cfg(test)]
    pub fn is_free(&self, i: usize) -> bool {
        self.free[i]
    }

    /// The centre of cell `i`.
    pub fn center(&self, i: usize) -> Point {
        let (c, r) = (i % self.cols, i / self.cols);
        Point::new(
            self.origin.x + c as f64 * self.cell_px,
            self.origin.y + r as f64 * self.cell_px,
        )
    }

    /// The cell one move `d` from cell `i`, if inside the grid.
    pub fn step(&self, i: usize, d: usize) -> Option<usize> {
        let (dc, dr) = MOVES[d];
        let c = (i % self.cols) as i64 + i64::from(dc);
        let r = (i / self.cols) as i64 + i64::from(dr);
        (c >= 0 && r >= 0 && (c as usize) < self.cols && (r as usize) < self.rows)
            .then(|| r as usize * self.cols + c as usize)
    }

    /// The cells one open move from `i`, with the move's index.
    pub fn neighbours(&self, i: usize) -> impl Iterator<Item = (usize, usize)> + '_ {
        let links = self.links[i];
        (0..8)
            .filter(move |d| links & (1 << d) != 0)
            .filter_map(move |d| self.step(i, d).map(|j| (d, j)))
    }

    /// The corner a diagonal move `d` from cell `i` crosses (an index over the grid's corners),
    /// `None` for an orthogonal move.
    pub fn corner(&self, i: usize, d: usize) -> Option<usize> {
        let (dc, dr) = MOVES[d];
        if dc == 0 || dr == 0 {
            return None;
        }
        // Corner (c, r) lies below and left of cell (c, r)'s centre.
        let c = (i % self.cols) as i64 + i64::from(dc.max(0));
        let r = (i / self.cols) as i64 + i64::from(dr.max(0));
        Some(r as usize * (self.cols + 1) + c as usize)
    }

    /// The free cells nearest `p` first: those whose centres lie within `reach` px of `p`,
    /// by distance.
    pub fn nearest_free(&self, p: Point, reach: f64) -> Vec<usize> {
        let span = (reach / self.cell_px).ceil() as i64 + 1;
        let c0 = ((p.x - self.origin.x) / self.cell_px).round() as i64;
        let r0 = ((p.y - self.origin.y) / self.cell_px).round() as i64;
        let mut found: Vec<(f64, usize)> = Vec::new();
        for r in r0 - span..=r0 + span {
            for c in c0 - span..=c0 + span {
                if c < 0 || r < 0 || c as usize >= self.cols || r as usize >= self.rows {
                    continue;
                }
                let i = r as usize * self.cols + c as usize;
                let d = (self.center(i) - p).norm();
                if self.free[i] && d <= reach {
                    found.push((d, i));
                }
            }
        }
        found.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        found.into_iter().map(|(_, i)| i).collect()
    }

    /// Each free cell's least number of moves to `goal` (`u32::MAX` where it cannot be reached).
    pub fn moves_to(&self, goal: usize) -> Vec<u32> {
        let mut d = vec![u32::MAX; self.len()];
        let mut queue = std::collections::VecDeque::new();
        d[goal] = 0;
        queue.push_back(goal);
        while let Some(i) = queue.pop_front() {
            // Links are symmetric: the moves into `i` are the moves out of it.
            for (_, j) in self.neighbours(i) {
                if d[j] == u32::MAX {
                    d[j] = d[i] + 1;
                    queue.push_back(j);
                }
            }
        }
        d
    }
}
