//! Rays through a maze, paying per cell crossed: the maze's own cells and wall bits as the grid.
//!
//! A maze's walls are boxes centred on cell edges, `wall_thickness_px / 2` deep either side
//! ([`Maze::wall_boxes`]). A ray walks the cells it crosses (Amanatides and Woo, "A fast voxel
//! traversal algorithm for ray tracing", 1987) and, where it leaves a cell, looks up the wall on
//! the edge it crosses: a wall there ends the walk. Lengths in px.
//!
//! Which boxes the walk tests, and why that finds the nearest: inside one cell the ray is a
//! segment, and its distance to any line is least at one of its two ends. So a wall box can meet
//! the segment inside the cell only (a) on the edge the ray leaves by, (b) near an end of the
//! segment that lies within the walls' half thickness of another edge, or (c) in a corner of the
//! cell that the segment cuts, which needs an end within twice the half thickness of that corner.
//! The walk tests the wall of each edge it crosses, every wall meeting at a grid corner within
//! twice the half thickness of a crossing, and at the start the walls of each side the origin is
//! within reach of; it stops at the first cell whose tests gave a hit no further than where the ray
//! leaves it. Every hit is [`Aabb::ray_hit`] of the same ray, so the answer is exactly the least
//! over all the walls. The closed outer boundary keeps a ray from inside from leaving the maze
//! before its first wall.

use crate::geometry::{Aabb, Point, Vector};
use crate::scene::maze::Maze;

/// A ray being walked: from `origin` along `dir` (`inv_dir` its component-wise inverse) up to
/// `max_t`.
#[derive(Clone, Copy)]
struct Ray {
    origin: Point,
    dir: Vector,
    inv_dir: Vector,
    max_t: f64,
}

/// A maze's walls by the edges they stand on, for ray casts.
#[derive(Clone, Debug)]
pub struct MazeRays {
    cols: usize,
    rows: usize,
    cell_px: f64,
    inv_cell_px: f64,
    /// How far a wall box reaches from its edge (half its thickness and a rounding margin), px.
    reach_px: f64,
    /// The box on each edge, [`NO_WALL`] where there is none: first the vertical edges, at
    /// `row * (cols + 1) + col` the edge at `x = col * cell_px` beside cell `(col, row)`; then
    /// from [`MazeRays::horizontal`] on the horizontal ones, at `row * (cols + 1) + col` the edge
    /// at `y = row * cell_px` below cell `(col, row)` (`col == cols` holds no edge). Both by
    /// the index of the grid corner at the edge's lower or left end.
    edges: Vec<u32>,
    /// Where the horizontal edges start in [`MazeRays::edges`].
    horizontal: usize,
    /// `corners[j * (cols + 1) + i]`: the walls on the edges meeting at grid corner `(i, j)`,
    /// each once, then [`NO_WALL`].
    corners: Vec<[u32; 4]>,
    boxes: Vec<Aabb>,
}

/// What every ray from one origin shares ([`MazeRays::start`]).
#[derive(Clone, Copy, Debug)]
pub struct Start {
    origin: Point,
    /// Whether the origin lies in the maze (else rays test every wall).
    inside: bool,
    /// The origin less the lower-left corner of its cell.
    offset: Vector,
    /// The origin's cell's lower-left grid corner, `row * (cols + 1) + col`: the index of the
    /// cell's left and lower edges in their halves of [`MazeRays::edges`].
    cell: isize,
    /// The walls a ray may meet before it reaches an edge of the origin's cell: those of each side
    /// the origin is within reach of, and of the corners at the side's ends (`NO_WALL` beyond
    /// `near_count`; a wall may repeat).
    near: [u32; 16],
    near_count: usize,
}

/// An open edge.
const NO_WALL: u32 = u32::MAX;

impl MazeRays {
    /// The walls of `maze` with cells of `cell_px` and walls `wall_thickness_px` thick, as
    /// [`Maze::wall_boxes`] gives them. `None` when the walls are a quarter cell thick or more, or
    /// the outer boundary is open: the walk's reasoning needs thin walls and a closed maze.
    pub fn new(maze: &Maze, cell_px: f64, wall_thickness_px: f64) -> Option<Self> {
        let (cols, rows) = (maze.cols(), maze.rows());
        // Rounding in the walk moves a crossing by far less than this margin.
        let reach_px = wall_thickness_px / 2.0 + cell_px * 1e-6;
        if cols == 0 || rows == 0 || 4.0 * reach_px >= cell_px || !maze.boundary_closed() {
            return None;
        }
        let (vertical, horizontal) = maze.wall_box_of_edges();
        let edge = |b: Option<u32>| b.unwrap_or(NO_WALL);
        let mut edges: Vec<u32> = vertical.into_iter().map(edge).collect();
        let horizontal_from = edges.len();
        for row in horizontal.chunks(cols) {
            edges.extend(row.iter().copied().map(edge));
            edges.push(NO_WALL);
        }
        let mut rays = Self {
            cols,
            rows,
            cell_px,
            inv_cell_px: 1.0 / cell_px,
            reach_px,
            edges,
            horizontal: horizontal_from,
            corners: Vec::new(),
            boxes: maze.wall_boxes(cell_px, wall_thickness_px),
        };
        rays.corners = (0..=rows)
            .flat_map(|j| (0..=cols).map(move |i| (i, j)))
            .map(|(i, j)| {
                let mut walls = [NO_WALL; 4];
                let mut n = 0;
                for w in rays.corner_edges(i, j) {
                    if w != NO_WALL && !walls[..n].contains(&w) {
                        walls[n] = w;
                        n += 1;
                    }
                }
                walls
            })
            .collect();
        Some(rays)
    }

    /// The boxes of the walls, in the order of [`Maze::wall_boxes`].
    pub fn boxes(&self) -> &[Aabb] {
        &self.boxes
    }

    /// What every ray from `origin` shares: its cell and the walls it is within reach of.
    #[inline]
    pub fn start(&self, origin: Point) -> Start {
        let c = self.cell_px;
        let inside = origin.x >= 0.0
            && origin.y >= 0.0
            && origin.x <= self.cols as f64 * c
            && origin.y <= self.rows as f64 * c;
        // A float cast truncates, which is the floor here.
        let col = ((origin.x * self.inv_cell_px) as isize).min(self.cols as isize - 1);
        let row = ((origin.y * self.inv_cell_px) as isize).min(self.rows as isize - 1);
        let offset = origin - Point::new(col as f64 * c, row as f64 * c);
        let cols = self.cols as isize;
        let mut start = Start {
            origin,
            inside,
            offset,
            cell: row * (cols + 1) + col,
            near: [NO_WALL; 16],
            near_count: 0,
        };
        let gaps = [offset.x, c - offset.x, offset.y, c - offset.y];
        if inside && gaps.iter().any(|&g| g <= self.reach_px) {
            let (col, row) = (col as usize, row as usize);
            // Each side by the corners at its two ends (whose walls include the side's own).
            let sides = [
                [(col, row), (col, row + 1)],
                [(col + 1, row), (col + 1, row + 1)],
                [(col, row), (col + 1, row)],
                [(col, row + 1), (col + 1, row + 1)],
            ];
            for (gap, ends) in gaps.into_iter().zip(sides) {
                if gap <= self.reach_px {
                    for (i, j) in ends {
                        for wall in self.corners[j * (self.cols + 1) + i] {
                            if wall != NO_WALL && start.near_count < start.near.len() {
                                start.near[start.near_count] = wall;
                                start.near_count += 1;
                            }
                        }
                    }
                }
            }
        }
        start
    }

    /// The nearest [`Aabb::ray_hit`] over every wall of the ray `start.origin + t * dir`, `t` in
    /// `[0, max_t]`, with `inv_dir = 1 / dir` per component: `Some(0.0)` when the origin is in a
    /// wall, `None` when no wall lies within `max_t`. From outside the maze, every wall is tested.
    #[inline(always)]
    pub fn cast(&self, start: &Start, dir: Vector, inv_dir: Vector, max_t: f64) -> Option<f64> {
        let o = start.origin;
        if !start.inside {
            return self.every_box(o, inv_dir, max_t);
        }
        let c = self.cell_px;
        let mut best = f64::INFINITY;
        for &wall in &start.near[..start.near_count] {
            self.test(wall, o, inv_dir, max_t, &mut best);
        }
        // Per axis, the step between cells, and the `t` of the next cell line ahead and between
        // lines. An axis the ray runs parallel to never steps: its next line is further than any
        // other (and finite, so that how far along an edge the walk crosses it stays a number).
        let (ahead_x, ahead_y) = (isize::from(inv_dir.x > 0.0), isize::from(inv_dir.y > 0.0));
        let (step_x, step_y) = (2 * ahead_x - 1, 2 * ahead_y - 1);
        let axis = |gap: f64, inv: f64| {
            if inv.is_finite() {
                (gap * inv.abs(), c * inv.abs())
            } else {
                (f64::MAX, 0.0)
            }
        };
        let offset = start.offset;
        let gap_x = if ahead_x == 1 { c - offset.x } else { offset.x };
        let gap_y = if ahead_y == 1 { c - offset.y } else { offset.y };
        let (mut next_x, delta_x) = axis(gap_x, inv_dir.x);
        let (mut next_y, delta_y) = axis(gap_y, inv_dir.y);
        let across = Vector::new(dir.y.abs(), dir.x.abs());
        // The lower-left corner of the cell the walk is in; the edges ahead on either axis, as
        // offsets from it into `edges`; and how a step across y moves it (across x: `step_x`).
        let stride = self.cols as isize + 1;
        let mut cell = start.cell;
        let (ahead_vertical, ahead_horizontal) =
            (ahead_x, self.horizontal as isize + ahead_y * stride);
        let cell_by_y = step_y * stride;
        // A crossing comes within `reach` of an end of its edge when it lies further than this
        // from the edge's middle.
        let (half, reach) = (c / 2.0, 2.0 * self.reach_px);
        let off_middle = half - reach;
        let mut limit = max_t;
        // One crossing of the edge `edge` at `t`, `ahead` from its end ahead on the other axis:
        // the wall on it if the walk stops there (a wall, or the ray's end), else `None`.
        let mut cross = |x_first: bool, edge: isize, t: f64, ahead: f64| {
            // The closed boundary ends every walk inside the maze before it leaves the grid
            // (`get` keeps a stray index from panicking all the same).
            let Some(&wall) = self.edges.get(edge as usize) else {
                return Some(NO_WALL);
            };
            if (ahead - half).abs() > off_middle {
                let ray = Ray {
                    origin: o,
                    dir,
                    inv_dir,
                    max_t,
                };
                self.crossing_corners(x_first, edge as usize, t, &ray, &mut best);
                limit = best.min(max_t);
            }
            (wall != NO_WALL || limit <= t).then_some(wall)
        };
        // A branch on the axis crossed next: the processor guesses it well enough that the
        // walk's steps overlap, where selects would chain each step to the last.
        let wall = loop {
            // How far along the crossed edge, from its end ahead on the other axis, the ray
            // crosses it: the `t` to the next line across, times the speed across.
            if next_x < next_y {
                let ahead = (next_y - next_x) * across.x;
                if let Some(wall) = cross(true, cell + ahead_vertical, next_x, ahead) {
                    break wall;
                }
                next_x += delta_x;
                cell += step_x;
            } else {
                let ahead = (next_x - next_y) * across.y;
                if let Some(wall) = cross(false, cell + ahead_horizontal, next_y, ahead) {
                    break wall;
                }
                next_y += delta_y;
                cell += cell_by_y;
            }
        };
        // The ray leaves its last cell through a wall (which it meets by then), or it ends.
        if wall != NO_WALL {
            self.test(wall, o, inv_dir, max_t, &mut best);
        }
        (best <= max_t).then_some(best)
    }

    /// Tests the walls meeting at each end of the crossed edge (`edge` in [`MazeRays::edges`], a
    /// vertical one when `vertical`, crossed at `t`) that the crossing comes within reach of.
    #[cold]
    fn crossing_corners(&self, vertical: bool, edge: usize, t: f64, ray: &Ray, best: &mut f64) {
        let Ray {
            origin,
            dir,
            inv_dir: inv,
            max_t,
        } = *ray;
        let (c, reach, stride) = (self.cell_px, 2.0 * self.reach_px, self.cols + 1);
        // The grid corner at the edge's lower or left end (the edge's index in its half of
        // `edges`), the step to its other end, and where along the edge the ray crosses.
        let corner = if vertical {
            edge
        } else {
            edge.wrapping_sub(self.horizontal)
        };
        let (i, j) = (corner % stride, corner / stride);
        let (other, along) = if vertical {
            (corner + stride, origin.y + t * dir.y - j as f64 * c)
        } else {
            (corner + 1, origin.x + t * dir.x - i as f64 * c)
        };
        for (end, near) in [(corner, along < reach), (other, along > c - reach)] {
            // (A walk inside the maze only crosses edges with both ends on the grid.)
            if let Some(walls) = self.corners.get(end).filter(|_| near) {
                for &w in walls.iter().take_while(|&&w| w != NO_WALL) {
                    self.test(w, origin, inv, max_t, best);
                }
            }
        }
    }

    /// Lowers `best` to the hit on box `b`, if any.
    #[inline]
    fn test(&self, b: u32, origin: Point, inv_dir: Vector, max_t: f64, best: &mut f64) {
        if let Some(t) = self.boxes[b as usize].ray_hit(origin, inv_dir, max_t) {
            if t < *best {
                *best = t;
            }
        }
    }

    /// The walls on the (up to four) edges meeting at grid corner `(i, j)`, [`NO_WALL`] for the
    /// open ones (a wall may repeat).
    fn corner_edges(&self, i: usize, j: usize) -> [u32; 4] {
        let (cols, rows, stride) = (self.cols, self.rows, self.cols + 1);
        let mut walls = [NO_WALL; 4];
        if j > 0 && i <= cols {
            walls[0] = self.edges[(j - 1) * stride + i];
        }
        if j < rows && i <= cols {
            walls[1] = self.edges[j * stride + i];
        }
        if i > 0 && j <= rows {
            walls[2] = self.edges[self.horizontal + j * stride + i - 1];
        }
        if i < cols && j <= rows {
            walls[3] = self.edges[self.horizontal + j * stride + i];
        }
        walls
    }

    /// The nearest hit testing every box.
    #[cold]
    fn every_box(&self, origin: Point, inv_dir: Vector, max_t: f64) -> Option<f64> {
        let mut best = f64::INFINITY;
        for b in 0..self.boxes.len() {
            self.test(b as u32, origin, inv_dir, max_t, &mut best);
        }
        (best <= max_t).then_some(best)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::unit;
    use crate::sim::{stream, Stream};
    use rand::{Rng, SeedableRng};

    #[test]
    fn a_walk_gives_the_bits_every_wall_gives() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(23);
        let mut hits = 0;
        for (seed, (cols, rows, cell, thickness, loops)) in [
            (10, 10, 100.0, 2.0, 0.4),
            (7, 3, 30.0, 7.0, 0.0),
            (12, 9, 17.3, 0.5, 1.0),
            (1, 1, 50.0, 12.0, 0.0),
            (40, 25, 25.0, 2.0, 0.7),
        ]
        .into_iter()
        .enumerate()
        {
            let maze = Maze::generate(cols, rows, loops, &mut stream(seed as u64, Stream::Scene));
            let walls = MazeRays::new(&maze, cell, thickness).expect("thin walls");
            let boxes = maze.wall_boxes(cell, thickness);
            let (w, h) = (cols as f64 * cell, rows as f64 * cell);
            for k in 0..20_000 {
                // Origins on grid lines and corners, at wall faces, anywhere, and outside.
                let grid_point = |rng: &mut rand_chacha::ChaCha8Rng, n: usize| {
                    rng.random_range(0..=n) as f64 * cell
                };
                let origin = match k % 6 {
                    0 => Point::new(grid_point(&mut rng, cols), grid_point(&mut rng, rows)),
                    1 => Point::new(grid_point(&mut rng, cols), rng.random_range(0.0..h)),
                    2 => Point::new(
                        grid_point(&mut rng, cols) + thickness / 2.0,
                        rng.random_range(0.0..h),
                    ),
                    3 => Point::new(
                        rng.random_range(-0.5 * w..1.5 * w),
                        rng.random_range(-0.5 * h..1.5 * h),
                    ),
                    _ => Point::new(rng.random_range(0.0..w), rng.random_range(0.0..h)),
                };
                let deg = if k % 3 == 0 {
                    rng.random_range(0..8) as f64 * 45.0
                } else {
                    rng.random_range(0.0..360.0)
                };
                let dir = unit(deg);
                let inv = Vector::new(1.0 / dir.x, 1.0 / dir.y);
                let max_t = [0.0, 1.0, cell / 2.0, 3.0 * cell, 2.0 * (w + h)][k % 5];
                let ours = walls.cast(&walls.start(origin), dir, inv, max_t);
                let all = crate::geometry::nearest_box_hit(&boxes, origin, inv, max_t);
                assert_eq!(
                    ours.map(f64::to_bits),
                    all.map(f64::to_bits),
                    "maze {seed} from {origin:?} at {deg} deg up to {max_t}: {ours:?} vs {all:?}"
                );
                hits += usize::from(all.is_some());
            }
        }
        assert!(hits > 50_000, "only {hits} rays hit a wall");
    }

    #[test]
    fn thick_walls_and_open_mazes_are_refused() {
        let maze = Maze::closed(3, 3);
        assert!(MazeRays::new(&maze, 100.0, 2.0).is_some());
        assert!(MazeRays::new(&maze, 100.0, 50.0).is_none());
        let empty = Maze::closed(0, 4);
        assert!(MazeRays::new(&empty, 100.0, 2.0).is_none());
    }
}
