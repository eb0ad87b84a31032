//! A uniform grid of points for "who is near here" among many moving things (a team's robots):
//! filled in O(n) by a counting sort each step, asked for the points in the cells a circle's
//! bounding box touches. The answer is a superset of the points within the circle, in increasing
//! index order, so callers keep their exact test and their iteration order.

use crate::geometry::Point;

/// Points binned into square cells over `[0, width] x [0, height]` (points outside go to the
/// nearest edge cell, so nothing is ever lost).
#[derive(Clone, Debug, Default)]
pub struct PointGrid {
    cell: f64,
    cols: usize,
    rows: usize,
    /// `starts[c]..starts[c + 1]` are cell `c`'s entries in `items`.
    starts: Vec<u32>,
    items: Vec<u32>,
    /// Each filled point's cell, kept between the counting passes.
    cells: Vec<u32>,
    /// The counting sort's next free slot of each cell (kept to reuse its allocation).
    next: Vec<u32>,
    /// Few points are listed (index, column, row) rather than binned; `None` when binned.
    listed: Option<Vec<(u32, u32, u32)>>,
}

/// Up to this many points are listed rather than binned: a query tests each one's cell against
/// its box, which costs less than clearing and summing every cell of the grid (a team of one or
/// a few robots steps at a lone robot's speed). The answers are the same cells' points.
const LISTED: usize = 8;

impl PointGrid {
    /// An empty grid of `cell` px cells over a `width` x `height` scene.
    pub fn new(width: f64, height: f64, cell: f64) -> Self {
        let cell = if cell.is_finite() && cell > 0.0 {
            cell
        } else {
            1.0
        };
        let span = |len: f64| ((len.max(0.0) / cell).ceil() as usize).clamp(1, 4096);
        let (cols, rows) = (span(width), span(height));
        Self {
            cell,
            cols,
            rows,
            starts: vec![0; cols * rows + 1],
            items: Vec::new(),
            cells: Vec::new(),
            next: Vec::new(),
            listed: None,
        }
    }

    /// The cell side, px.
    pub fn cell(&self) -> f64 {
        self.cell
    }

    /// The column and row of `p`, clamped to the grid.
    fn cell_of(&self, x: f64, y: f64) -> (usize, usize) {
        // Truncation is the floor here: a negative quotient (or NaN) is column 0, and for the
        // rest `as` rounds towards zero (no call to libm's `floor` on the hot path).
        let clamp = |v: f64, n: usize| {
            let c = v / self.cell;
            if c.is_nan() || c < 0.0 {
                0
            } else {
                (c as usize).min(n - 1)
            }
        };
        (clamp(x, self.cols), clamp(y, self.rows))
    }

    /// Replaces the grid's points with `points` (index, position), given in increasing index
    /// order.
    pub fn fill(&mut self, points: impl Iterator<Item = (usize, Point)> + Clone) {
        if points.clone().nth(LISTED).is_none() {
            let mut listed = self.listed.take().unwrap_or_default();
            listed.clear();
            for (i, p) in points {
                let (c, r) = self.cell_of(p.x, p.y);
                listed.push((i as u32, c as u32, r as u32));
            }
            self.listed = Some(listed);
            return;
        }
        self.listed = None;
        self.cells.clear();
        self.starts.fill(0);
        for (_, p) in points.clone() {
            let (c, r) = self.cell_of(p.x, p.y);
            let cell = r * self.cols + c;
            self.cells.push(cell as u32);
            self.starts[cell + 1] += 1;
        }
        for c in 1..self.starts.len() {
            self.starts[c] += self.starts[c - 1];
        }
        self.items.clear();
        self.items.resize(self.cells.len(), 0);
        // Place each point at its cell's next free slot: a stable counting sort.
        self.next.clear();
        self.next.extend_from_slice(&self.starts);
        for ((i, _), &cell) in points.zip(&self.cells) {
            let at = &mut self.next[cell as usize];
            self.items[*at as usize] = i as u32;
            *at += 1;
        }
    }

    /// Into `out` (cleared first): every point in the cells the box of the circle `(centre,
    /// radius)` touches, in increasing index order. A superset of the points within `radius`.
    pub fn near(&self, centre: Point, radius: f64, out: &mut Vec<u32>) {
        self.near_any_order(centre, radius, out);
        out.sort_unstable();
    }

    /// [`PointGrid::near`] in no particular order (cell by cell), for a caller that orders
    /// what it keeps itself.
    pub fn near_any_order(&self, centre: Point, radius: f64, out: &mut Vec<u32>) {
        out.clear();
        let radius = radius.max(0.0);
        let (c0, r0) = self.cell_of(centre.x - radius, centre.y - radius);
        let (c1, r1) = self.cell_of(centre.x + radius, centre.y + radius);
        if let Some(listed) = &self.listed {
            let (c0, r0, c1, r1) = (c0 as u32, r0 as u32, c1 as u32, r1 as u32);
            out.extend(
                listed
                    .iter()
                    .filter(|&&(_, c, r)| (c0..=c1).contains(&c) && (r0..=r1).contains(&r))
                    .map(|&(i, _, _)| i),
            );
            return;
        }
        for r in r0..=r1 {
            let row = r * self.cols;
            let (a, b) = (self.starts[row + c0], self.starts[row + c1 + 1]);
            // A row holds a few points: pushed one by one rather than copied by `memmove`,
            // whose call cost more than the copy.
            for &i in &self.items[a as usize..b as usize] {
                out.push(i);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn near_holds_every_point_within_the_radius_in_index_order() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let points: Vec<Point> = (0..500)
            .map(|_| {
                Point::new(
                    rng.random_range(-20.0..420.0),
                    rng.random_range(-20.0..320.0),
                )
            })
            .collect();
        let mut grid = PointGrid::new(400.0, 300.0, 37.0);
        grid.fill(points.iter().copied().enumerate());
        let mut out = Vec::new();
        for _ in 0..300 {
            let c = Point::new(
                rng.random_range(-50.0..450.0),
                rng.random_range(-50.0..350.0),
            );
            let r = rng.random_range(0.0..150.0);
            grid.near(c, r, &mut out);
            assert!(out.windows(2).all(|w| w[0] < w[1]));
            for (i, p) in points.iter().enumerate() {
                if (p - c).norm() <= r {
                    assert!(out.contains(&(i as u32)), "point {i} at {p} missed");
                }
            }
        }
        // Refilled with fewer points, the old ones are gone.
        grid.fill(points.iter().copied().enumerate().take(3));
        grid.near(Point::new(200.0, 150.0), 1000.0, &mut out);
        assert_eq!(out, vec![0, 1, 2]);
    }

    /// A few points are listed rather than binned; they answer as the binned grid does: the
    /// same points, those in the cells the box touches.
    #[test]
    fn listed_points_answer_as_binned_ones() {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let (mut listed, mut binned) = (
            PointGrid::new(400.0, 300.0, 37.0),
            PointGrid::new(400.0, 300.0, 37.0),
        );
        let (mut a, mut b) = (Vec::new(), Vec::new());
        for _ in 0..200 {
            let n = rng.random_range(1..=LISTED);
            let points: Vec<(usize, Point)> = (0..n)
                .map(|i| {
                    let p = Point::new(
                        rng.random_range(-20.0..420.0),
                        rng.random_range(-20.0..320.0),
                    );
                    (i * 3, p)
                })
                .collect();
            listed.fill(points.iter().copied());
            assert!(listed.listed.is_some());
            // The same points and enough others (indices from 1000) to be binned.
            let extra = (0..=LISTED).map(|i| (1000 + i, Point::new(1.0, 1.0)));
            binned.fill(points.iter().copied().chain(extra));
            assert!(binned.listed.is_none());
            for _ in 0..20 {
                let c = Point::new(
                    rng.random_range(-50.0..450.0),
                    rng.random_range(-50.0..350.0),
                );
                let r = rng.random_range(0.0..150.0);
                listed.near(c, r, &mut a);
                binned.near(c, r, &mut b);
                b.retain(|&i| i < 1000);
                assert_eq!(a, b);
            }
        }
    }
}
