//! Maze generation: the recursive backtracker of docs/model.md "Scene: maze", plus a fraction of extra openings.
//!
//! Cells are `cell_px` squares indexed `(col, row)` from the scene's bottom-left corner (y up), so
//! the top-left cell, where generation starts, is `(0, rows - 1)`. Walls lie on cell edges.

use crate::config::MazeConfig;
use crate::geometry::{Aabb, Point};
use rand::seq::SliceRandom;

/// A maze: which cell edges carry a wall.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Maze {
    cols: usize,
    rows: usize,
    /// `vertical[row * (cols + 1) + c]`: a wall on the line `x = c * cell` beside cell `(c, row)`.
    vertical: Vec<bool>,
    /// `horizontal[r * cols + col]`: a wall on the line `y = r * cell` below cell `(col, r)`.
    horizontal: Vec<bool>,
}

/// A grid line of a maze: the horizontal line `y = row * cell` or the vertical `x = col * cell`.
#[derive(Clone, Copy, Debug)]
enum Line {
    Horizontal(usize),
    Vertical(usize),
}

/// Walls on consecutive edges of one line: `edges` counts columns along a horizontal line, rows
/// along a vertical one.
#[derive(Clone, Debug)]
struct WallRun {
    line: Line,
    edges: std::ops::Range<usize>,
}

/// An interior edge between two cells.
#[derive(Clone, Copy, Debug)]
enum Edge {
    /// The vertical edge at `x = col * cell` in row `row` (col in 1..cols).
    Vertical { col: usize, row: usize },
    /// The horizontal edge at `y = row * cell` in column `col` (row in 1..rows).
    Horizontal { col: usize, row: usize },
}

impl Maze {
    /// A grid with every wall standing.
    pub fn closed(cols: usize, rows: usize) -> Self {
        Self {
            cols,
            rows,
            vertical: vec![true; (cols + 1) * rows],
            horizontal: vec![true; cols * (rows + 1)],
        }
    }

    /// Generates a maze: a perfect maze by recursive backtracking from the top-left cell, then
    /// `loops` of the interior walls it left removed at random. A grid with no cells (`cols` or
    /// `rows` 0) stays empty.
    pub fn generate(cols: usize, rows: usize, loops: f64, rng: &mut impl rand::Rng) -> Self {
        let mut maze = Self::closed(cols, rows);
        if cols == 0 || rows == 0 {
            return maze;
        }
        let mut visited = vec![false; cols * rows];
        let start = (0, rows - 1);
        visited[start.1 * cols + start.0] = true;
        let mut stack = vec![start];
        let mut options = Vec::with_capacity(4);
        while let Some(&(c, r)) = stack.last() {
            options.clear();
            if c > 0 && !visited[r * cols + c - 1] {
                options.push((c - 1, r));
            }
            if c + 1 < cols && !visited[r * cols + c + 1] {
                options.push((c + 1, r));
            }
            if r > 0 && !visited[(r - 1) * cols + c] {
                options.push((c, r - 1));
            }
            if r + 1 < rows && !visited[(r + 1) * cols + c] {
                options.push((c, r + 1));
            }
            if options.is_empty() {
                stack.pop();
                continue;
            }
            let next = options[rng.random_range(0..options.len())];
            maze.open_between((c, r), next);
            visited[next.1 * cols + next.0] = true;
            stack.push(next);
        }
        let mut walls = maze.interior_walls();
        let remove = (loops * walls.len() as f64).round() as usize;
        let (chosen, _) = walls.partial_shuffle(rng, remove);
        for &edge in chosen.iter() {
            maze.set(edge, false);
        }
        maze
    }

    /// Generates the maze `config` describes.
    pub fn from_config(config: &MazeConfig, rng: &mut impl rand::Rng) -> Self {
        Self::generate(
            config.cols as usize,
            config.rows as usize,
            config.loops,
            rng,
        )
    }

    /// Number of cell columns.
    pub fn cols(&self) -> usize {
        self.cols
    }

    /// Number of cell rows.
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// Whether the vertical edge at `x = col * cell`, row `row`, has a wall.
    pub fn vertical_wall(&self, col: usize, row: usize) -> bool {
        self.vertical[row * (self.cols + 1) + col]
    }

    /// Whether the horizontal edge at `y = row * cell`, column `col`, has a wall.
    pub fn horizontal_wall(&self, col: usize, row: usize) -> bool {
        self.horizontal[row * self.cols + col]
    }

    fn set(&mut self, edge: Edge, wall: bool) {
        match edge {
            Edge::Vertical { col, row } => self.vertical[row * (self.cols + 1) + col] = wall,
            Edge::Horizontal { col, row } => self.horizontal[row * self.cols + col] = wall,
        }
    }

    fn has(&self, edge: Edge) -> bool {
        match edge {
            Edge::Vertical { col, row } => self.vertical_wall(col, row),
            Edge::Horizontal { col, row } => self.horizontal_wall(col, row),
        }
    }

    fn open_between(&mut self, a: (usize, usize), b: (usize, usize)) {
        let edge = if a.1 == b.1 {
            Edge::Vertical {
                col: a.0.max(b.0),
                row: a.1,
            }
        } else {
            Edge::Horizontal {
                col: a.0,
                row: a.1.max(b.1),
            }
        };
        self.set(edge, false);
    }

    fn interior_edges(&self) -> impl Iterator<Item = Edge> + '_ {
        let vertical = (0..self.rows)
            .flat_map(move |row| (1..self.cols).map(move |col| Edge::Vertical { col, row }));
        let horizontal = (1..self.rows)
            .flat_map(move |row| (0..self.cols).map(move |col| Edge::Horizontal { col, row }));
        vertical.chain(horizontal)
    }

    fn interior_walls(&self) -> Vec<Edge> {
        self.interior_edges().filter(|&e| self.has(e)).collect()
    }

    /// Number of interior walls standing.
    pub fn interior_wall_count(&self) -> usize {
        self.interior_edges().filter(|&e| self.has(e)).count()
    }

    /// Number of open interior edges (passages between neighbouring cells).
    pub fn passage_count(&self) -> usize {
        self.interior_edges().filter(|&e| !self.has(e)).count()
    }

    /// Whether the outer boundary is closed all round.
    pub fn boundary_closed(&self) -> bool {
        (0..self.rows).all(|r| self.vertical_wall(0, r) && self.vertical_wall(self.cols, r))
            && (0..self.cols)
                .all(|c| self.horizontal_wall(c, 0) && self.horizontal_wall(c, self.rows))
    }

    /// Number of cells reachable from the bottom-left cell through open edges.
    pub fn reachable_cells(&self) -> usize {
        let mut seen = vec![false; self.cols * self.rows];
        let mut stack = vec![(0usize, 0usize)];
        seen[0] = true;
        let mut count = 0;
        while let Some((c, r)) = stack.pop() {
            count += 1;
            let mut visit = |c: usize, r: usize, stack: &mut Vec<(usize, usize)>| {
                if !seen[r * self.cols + c] {
                    seen[r * self.cols + c] = true;
                    stack.push((c, r));
                }
            };
            if c > 0 && !self.vertical_wall(c, r) {
                visit(c - 1, r, &mut stack);
            }
            if c + 1 < self.cols && !self.vertical_wall(c + 1, r) {
                visit(c + 1, r, &mut stack);
            }
            if r > 0 && !self.horizontal_wall(c, r) {
                visit(c, r - 1, &mut stack);
            }
            if r + 1 < self.rows && !self.horizontal_wall(c, r + 1) {
                visit(c, r + 1, &mut stack);
            }
        }
        count
    }

    /// The walls as runs of collinear neighbours, horizontal lines bottom to top and then vertical
    /// lines left to right, each run from its first edge to its last: the order of
    /// [`Maze::wall_boxes`].
    fn wall_runs(&self) -> Vec<WallRun> {
        let mut runs = Vec::new();
        let mut push_runs = |count: usize, present: &dyn Fn(usize) -> bool, line: Line| {
            let mut i = 0;
            while i < count {
                if present(i) {
                    let start = i;
                    while i < count && present(i) {
                        i += 1;
                    }
                    runs.push(WallRun {
                        line,
                        edges: start..i,
                    });
                } else {
                    i += 1;
                }
            }
        };
        for row in 0..=self.rows {
            push_runs(
                self.cols,
                &|c| self.horizontal_wall(c, row),
                Line::Horizontal(row),
            );
        }
        for col in 0..=self.cols {
            push_runs(
                self.rows,
                &|r| self.vertical_wall(col, r),
                Line::Vertical(col),
            );
        }
        runs
    }

    /// The walls as boxes of `thickness` px centred on their cell edges, collinear neighbours
    /// merged into one box. Each box runs `thickness / 2` past its end cells so corners close.
    pub fn wall_boxes(&self, cell: f64, thickness: f64) -> Vec<Aabb> {
        let h = thickness / 2.0;
        self.wall_runs()
            .iter()
            .map(|run| {
                let (from, to) = (run.edges.start as f64 * cell, run.edges.end as f64 * cell);
                match run.line {
                    Line::Horizontal(row) => {
                        let y = row as f64 * cell;
                        Aabb::from_corners(Point::new(from - h, y - h), Point::new(to + h, y + h))
                    }
                    Line::Vertical(col) => {
                        let x = col as f64 * cell;
                        Aabb::from_corners(Point::new(x - h, from - h), Point::new(x + h, to + h))
                    }
                }
            })
            .collect()
    }

    /// Which of [`Maze::wall_boxes`] covers each edge, laid out like the wall bits: `vertical[row
    /// * (cols + 1) + col]` for the edge at `x = col * cell`, `horizontal[row * cols + col]` for
    /// the edge at `y = row * cell`, and `None` where the edge is open.
    pub fn wall_box_of_edges(&self) -> (Vec<Option<u32>>, Vec<Option<u32>>) {
        let mut vertical = vec![None; (self.cols + 1) * self.rows];
        let mut horizontal = vec![None; self.cols * (self.rows + 1)];
        for (i, run) in self.wall_runs().into_iter().enumerate() {
            for e in run.edges {
                match run.line {
                    Line::Horizontal(row) => horizontal[row * self.cols + e] = Some(i as u32),
                    Line::Vertical(col) => vertical[e * (self.cols + 1) + col] = Some(i as u32),
                }
            }
        }
        (vertical, horizontal)
    }

    /// The maze as text, top row first: `+--+` for walls, `S` and `G` in the marked cells.
    pub fn to_ascii(&self, start: Option<(usize, usize)>, goal: Option<(usize, usize)>) -> String {
        let mut out = String::new();
        for row in (0..self.rows).rev() {
            for c in 0..self.cols {
                out.push('+');
                out.push_str(if self.horizontal_wall(c, row + 1) {
                    "--"
                } else {
                    "  "
                });
            }
            out.push_str("+\n");
            for c in 0..=self.cols {
                out.push(if self.vertical_wall(c, row) { '|' } else { ' ' });
                if c < self.cols {
                    let mark = if start == Some((c, row)) {
                        "S "
                    } else if goal == Some((c, row)) {
                        "G "
                    } else {
                        "  "
                    };
                    out.push_str(mark);
                }
            }
            out.push('\n');
        }
        for c in 0..self.cols {
            out.push('+');
            out.push_str(if self.horizontal_wall(c, 0) {
                "--"
            } else {
                "  "
            });
        }
        out.push_str("+\n");
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::{stream, Stream};
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(200))]

        #[test]
        fn perfect_maze_is_a_spanning_tree(seed in any::<u64>(), cols in 1usize..30, rows in 1usize..30) {
            let maze = Maze::generate(cols, rows, 0.0, &mut stream(seed, Stream::Scene));
            prop_assert_eq!(maze.passage_count(), cols * rows - 1);
            prop_assert_eq!(maze.reachable_cells(), cols * rows);
            prop_assert!(maze.boundary_closed());
        }

        #[test]
        fn loops_remove_their_fraction_of_the_remaining_walls(seed in any::<u64>(), loops in 0.0f64..=1.0) {
            let perfect = Maze::generate(10, 10, 0.0, &mut stream(seed, Stream::Scene));
            let looped = Maze::generate(10, 10, loops, &mut stream(seed, Stream::Scene));
            let before = perfect.interior_wall_count();
            let removed = before - looped.interior_wall_count();
            prop_assert_eq!(removed, (loops * before as f64).round() as usize);
            prop_assert_eq!(looped.reachable_cells(), 100);
            prop_assert!(looped.boundary_closed());
            // The loops are removed from the same perfect maze: every wall left stood before.
            for e in looped.interior_edges() {
                prop_assert!(!looped.has(e) || perfect.has(e));
            }
        }
    }

    #[test]
    fn default_maze_removes_forty_percent() {
        // 10 x 10: 180 interior edges, 99 passages in a perfect maze, 81 walls left; 40% is 32.
        let maze = Maze::generate(10, 10, 0.4, &mut stream(3, Stream::Scene));
        assert_eq!(maze.interior_wall_count(), 81 - 32);
    }

    #[test]
    fn boxes_cover_the_walls() {
        let maze = Maze::closed(2, 1);
        let boxes = maze.wall_boxes(100.0, 2.0);
        // Two horizontal runs (bottom, top), three vertical walls.
        assert_eq!(boxes.len(), 5);
        assert!(boxes.contains(&Aabb::from_corners(
            Point::new(-1.0, -1.0),
            Point::new(201.0, 1.0)
        )));
        assert!(boxes.contains(&Aabb::from_corners(
            Point::new(99.0, -1.0),
            Point::new(101.0, 101.0)
        )));
    }

    #[test]
    fn ascii_draws_walls_and_marks() {
        let mut maze = Maze::closed(2, 1);
        maze.open_between((0, 0), (1, 0));
        assert_eq!(
            maze.to_ascii(Some((0, 0)), Some((1, 0))),
            "+--+--+\n|S  G |\n+--+--+\n"
        );
    }
}
