//! A uniform bin grid over a scene's boxes, for sensor and collision queries near one point.
//!
//! Each square bin lists every box that comes within `reach` px of some point of the bin. A query
//! about a point then reads a single bin and gets every box within `reach` of that point (and a few
//! more), with no deduplication: a laser scan of range `reach` costs one lookup. Queries that reach
//! further than the index was built for, or start outside it, fall back to all boxes.

use crate::geometry::{Aabb, Point};

/// Most bins an index has (16 MB of bin starts).
pub const MAX_BINS: usize = 4_000_000;

/// Bins over a set of boxes.
#[derive(Clone, Debug)]
pub struct BinIndex {
    origin: Point,
    bin_px: f64,
    cols: usize,
    rows: usize,
    reach_px: f64,
    /// `starts[b]..starts[b + 1]` is bin `b`'s slice of `items`.
    starts: Vec<u32>,
    items: Vec<u32>,
    all: Vec<u32>,
}

impl BinIndex {
    /// Bins of side `bin_px` over `bounds` grown by `reach_px`, for `boxes`. Bins grow as needed
    /// to keep their number under [`MAX_BINS`].
    pub fn new(boxes: &[Aabb], bounds: Aabb, reach_px: f64, bin_px: f64) -> Self {
        let area = bounds.inflated(reach_px);
        let size = area.extents();
        let bin_px = bin_px.max((size.x * size.y / MAX_BINS as f64).sqrt());
        let cols = ((size.x / bin_px).ceil() as usize).max(1);
        let rows = ((size.y / bin_px).ceil() as usize).max(1);
        let bin_of = |v: f64, lo: f64, n: usize| -> usize {
            (((v - lo) / bin_px).floor().max(0.0) as usize).min(n - 1)
        };
        // The bins a box reaches: a rectangle of bin columns by a band of bin rows.
        let span = |b: &Aabb| {
            let grown = b.inflated(reach_px);
            let outside = grown.max.x < area.min.x
                || grown.max.y < area.min.y
                || grown.min.x > area.max.x
                || grown.min.y > area.max.y;
            (!outside).then(|| {
                let columns =
                    bin_of(grown.min.x, area.min.x, cols)..=bin_of(grown.max.x, area.min.x, cols);
                let band =
                    bin_of(grown.min.y, area.min.y, rows)..=bin_of(grown.max.y, area.min.y, rows);
                (columns, band)
            })
        };
        // Two passes (count, then fill) build the compressed rows without per-bin vectors; each
        // box touches a row of bins at a time as one slice (a loop that vectorises).
        let spans: Vec<_> = boxes.iter().map(span).collect();
        let mut counts = vec![0u32; cols * rows + 1];
        for (columns, rs) in spans.iter().flatten() {
            for r in rs.clone() {
                let row = r * cols + 1;
                for n in &mut counts[row + columns.start()..=row + columns.end()] {
                    *n += 1;
                }
            }
        }
        for i in 1..counts.len() {
            counts[i] += counts[i - 1];
        }
        let starts = counts;
        let mut fill = starts.clone();
        let mut items = vec![0u32; starts[cols * rows] as usize];
        for (i, (columns, rs)) in spans
            .iter()
            .enumerate()
            .filter_map(|(i, s)| Some((i, s.as_ref()?)))
        {
            for r in rs.clone() {
                let row = r * cols;
                for next in &mut fill[row + columns.start()..=row + columns.end()] {
                    items[*next as usize] = i as u32;
                    *next += 1;
                }
            }
        }
        Self {
            origin: area.min,
            bin_px,
            cols,
            rows,
            reach_px,
            starts,
            items,
            all: (0..boxes.len() as u32).collect(),
        }
    }

    /// The distance the index answers for: [`BinIndex::near`] holds every box within it.
    pub fn reach_px(&self) -> f64 {
        self.reach_px
    }

    /// Indices of every box within `radius` of `p` (and possibly some further away).
    #[inline]
    pub fn near(&self, p: Point, radius: f64) -> &[u32] {
        match self.bin(p, radius) {
            Some(b) => self.bin_items(b),
            None => &self.all,
        }
    }

    /// The bin [`BinIndex::near`] reads for `p` and `radius`, or `None` when it reads every box.
    #[inline]
    fn bin(&self, p: Point, radius: f64) -> Option<usize> {
        let fx = (p.x - self.origin.x) / self.bin_px;
        let fy = (p.y - self.origin.y) / self.bin_px;
        if radius > self.reach_px || !(fx >= 0.0 && fy >= 0.0) {
            return None;
        }
        // Through i64, a few instructions, where a float's conversion to usize takes a dozen on
        // the baseline x86-64 (both truncate towards zero; a huge value saturates, off the grid).
        let (c, r) = (fx as i64, fy as i64);
        (c < self.cols as i64 && r < self.rows as i64).then(|| r as usize * self.cols + c as usize)
    }

    #[inline]
    fn bin_items(&self, b: usize) -> &[u32] {
        &self.items[self.starts[b] as usize..self.starts[b + 1] as usize]
    }

    /// Asks for the memory a query about `p` reads, one link of the chain a call: `stage` 0 the
    /// bin's bounds, 1 the bin's list (which needs the bounds), 2 and on the boxes listed (which
    /// need the list), each through `item`. Results never change; see [`super::prefetch`].
    pub(crate) fn prefetch_near(&self, p: Point, stage: usize, item: impl Fn(u32)) {
        let Some(b) = self.bin(p, self.reach_px) else {
            return;
        };
        match stage {
            0 => {
                super::prefetch::line(&self.starts[b]);
                super::prefetch::line(&self.starts[b + 1]);
            }
            1 => super::prefetch::lines(self.bin_items(b)),
            _ => self.bin_items(b).iter().for_each(|&i| item(i)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn near_holds_every_box_within_reach() {
        let boxes: Vec<Aabb> = (0..50)
            .map(|i| {
                let x = (i * 37 % 100) as f64 * 10.0;
                let y = (i * 53 % 100) as f64 * 10.0;
                Aabb::from_corners(Point::new(x, y), Point::new(x + 3.0 + i as f64, y + 2.0))
            })
            .collect();
        let bounds = Aabb::from_corners(Point::new(0.0, 0.0), Point::new(1000.0, 1000.0));
        let index = BinIndex::new(&boxes, bounds, 50.0, 10.0);
        for k in 0..2000 {
            let p = Point::new(
                (k * 7919 % 1100) as f64 - 50.0 + 0.37,
                (k * 104729 % 1100) as f64 - 50.0 + 0.61,
            );
            let near = index.near(p, 50.0);
            for (i, b) in boxes.iter().enumerate() {
                if b.distance_squared(p) <= 50.0 * 50.0 {
                    assert!(near.contains(&(i as u32)), "box {i} missing near {p:?}");
                }
            }
        }
        // Too far for the index: every box.
        assert_eq!(index.near(Point::new(5.0, 5.0), 60.0).len(), 50);
        assert_eq!(index.near(Point::new(-500.0, 5.0), 10.0).len(), 50);
    }
}
