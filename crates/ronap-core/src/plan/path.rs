//! Shortest paths: a field's grid path pulled straight wherever the disc can travel in a line
//! ([`smooth`]), which brings its length to within a fraction of a percent of the true shortest
//! path; and the shortest-path length of a world, SPL's yardstick.

use crate::geometry::{unit, Point, Vector};
use crate::plan::field::grid_path;
use crate::scene::{FreeGrid, Scene};
use crate::sim::World;

/// Step sizes, px, of [`smooth`]'s corner tightening, coarse to fine.
const TIGHTEN_STEPS_PX: [f64; 7] = [4.0, 2.0, 1.0, 0.5, 0.25, 0.125, 0.0625];

/// Pulls a path straight. From each kept point it jumps to the furthest later point the disc can
/// reach in a straight line (scanning forward until the line is blocked); then each remaining
/// corner moves, in shrinking steps, wherever it shortens the path and the disc stays clear. That
/// removes most of the grid's detour around obstacle corners: the result is within about 2% of
/// the true shortest path (tested on a wall tip, the tightest case in a maze).
pub fn smooth(scene: &Scene, points: &[Point], radius: f64) -> Vec<Point> {
    if points.is_empty() {
        return Vec::new();
    }
    let out = with_midpoints(&jump_ahead(scene, points, radius));
    let mut blockers = Blockers::new(scene, points, out.len(), radius);
    tighten(scene, out, radius, &mut blockers)
}

/// [`smooth`]'s corners moved in shrinking steps, each wherever it shortens the path with the
/// disc clear (moves `blockers` refuse untested), then the corners whose neighbours see each
/// other dropped.
fn tighten(scene: &Scene, mut out: Vec<Point>, radius: f64, blockers: &mut Blockers) -> Vec<Point> {
    let mut directions = directions();
    // Per corner, whether it stayed put when last tried at this step with its neighbours where
    // they are now: tried again it would stay put again (the same points give the same tries), so
    // it is passed over until it or a neighbour moves.
    let mut still = vec![false; out.len()];
    for step in TIGHTEN_STEPS_PX {
        still.fill(false);
        let mut moved = true;
        let mut rounds = 0;
        while moved && rounds < 8 {
            moved = false;
            rounds += 1;
            for k in 1..out.len().saturating_sub(1) {
                if still[k] {
                    continue;
                }
                if try_corner(scene, &mut out, k, step, &mut directions, blockers) {
                    moved = true;
                    still[k - 1] = false;
                    still[k + 1] = false;
                } else {
                    still[k] = true;
                }
            }
        }
    }
    drop_seen_corners(scene, &mut out, radius);
    out
}

/// The points of a path (not empty) that [`smooth`] starts from: from each kept point, the
/// furthest later point the disc can reach in a straight line (scanning forward until the line is
/// blocked).
fn jump_ahead(scene: &Scene, points: &[Point], radius: f64) -> Vec<Point> {
    let mut out = vec![points[0]];
    let mut i = 0;
    while i + 1 < points.len() {
        let mut j = i + 1;
        while j + 1 < points.len() && scene.sweep_clear(points[i], points[j + 1], radius) {
            j += 1;
        }
        out.push(points[j]);
        i = j;
    }
    out
}

/// `points` (not empty) with the midpoint of each segment between: they give the band more
/// joints to bend around a rounded corner with.
fn with_midpoints(points: &[Point]) -> Vec<Point> {
    let mut dense = Vec::with_capacity(points.len() * 2);
    for w in points.windows(2) {
        dense.push(w[0]);
        dense.push(Point::from((w[0].coords + w[1].coords) / 2.0));
    }
    dense.push(points[points.len() - 1]);
    dense
}

/// The 16 directions every corner tries, 22.5 degrees apart; [`try_corner`] adds two of its own.
fn directions() -> Vec<Vector> {
    (0..16).map(|k| unit(k as f64 * 22.5)).collect()
}

/// Tries moving corner `k` of `out` (neither end) by `step` in each of `directions` and towards
/// each neighbour, taking each move that shortens the path with the disc (of `blockers`' radius)
/// clear; whether it moved. A move that one of `blockers` clearly blocks is refused without the
/// scene's tests.
fn try_corner(
    scene: &Scene,
    out: &mut [Point],
    k: usize,
    step: f64,
    directions: &mut Vec<Vector>,
    blockers: &mut Blockers,
) -> bool {
    let radius = blockers.radius;
    let (a, b) = (out[k - 1], out[k + 1]);
    let start = out[k];
    let length = |p: Point| (p - a).norm() + (b - p).norm();
    // Sliding along either segment keeps that segment clear, so the two directions towards the
    // neighbours make progress where a tight corner leaves no other.
    directions.truncate(16);
    for n in [a, b] {
        if let Some(d) = (n - out[k]).try_normalize(1e-12) {
            directions.push(d);
        }
    }
    // The corner's own length, kept as it moves (the same value, bit for bit).
    let mut here = length(out[k]);
    for d in directions.iter() {
        let p = out[k] + d * step;
        // Both legs clear (the disc at `p` first: both legs end there, and a quarter of the tries
        // fail on it; then the shorter, cheaper leg).
        let clear = || {
            let legs = [(a, p), (p, b)];
            let order = if (p - a).norm_squared() <= (b - p).norm_squared() {
                [0, 1]
            } else {
                [1, 0]
            };
            scene.disc_clear(p, radius)
                && order
                    .iter()
                    .all(|&l| scene.sweep_clear(legs[l].0, legs[l].1, radius))
        };
        if length(p) < here - 1e-9 && !blockers.block(scene, k, a, p, b) {
            if clear() {
                out[k] = p;
                here = length(p);
            } else {
                blockers.learn(scene, k, a, p, b);
            }
        }
    }
    // Each move shortens the corner's length, so it never ends back where it began.
    out[k] != start
}

/// Per corner, a box that blocked one of its moves (the last found, near the refused position),
/// tried first on its next moves: [`smooth`]'s corners lie against the walls they bend around,
/// and most of their tries fail on the wall the last failure met.
///
/// A box whose distance from the disc's position or from either leg is less than the radius by a
/// margin blocks the move: the scene's own tests ([`Scene::disc_clear`], [`Scene::sweep_clear`])
/// list every box within the radius and find that one within it too, since their rounding is far
/// below the margin. So refusing such a move gives the same path, bit for bit, as testing it.
/// Moves no remembered box blocks by the margin are tested as before.
struct Blockers {
    /// By corner, the box ([`NO_BOX`] while unknown).
    by_corner: Vec<u32>,
    /// The squared distance within which a box blocks: the radius less the margin, squared;
    /// negative when nothing may be refused so (a radius no more than the margin).
    within2: f64,
    /// The disc's radius, px.
    radius: f64,
    /// How many moves were refused untested.
    refused: usize,
}

/// No box yet, in [`Blockers`].
const NO_BOX: u32 = u32::MAX;

impl Blockers {
    /// For the `corners` of a path smoothed from `points` in `scene` at `radius`: a margin of a
    /// millionth of a pixel, and more for scenes, paths or radii so large that their rounding
    /// nears it.
    fn new(scene: &Scene, points: &[Point], corners: usize, radius: f64) -> Self {
        let far = points
            .iter()
            .map(|p| p.x.abs().max(p.y.abs()))
            .fold(scene.width().max(scene.height()).max(radius), f64::max);
        let within = radius - (1e-6 + far * 1e-12);
        Self {
            by_corner: vec![NO_BOX; corners],
            within2: if within > 0.0 { within * within } else { -1.0 },
            radius,
            refused: 0,
        }
    }

    /// Blockers that refuse nothing: every move tested by the scene, as before they were kept.
    #[cfg(test)]
    fn off(corners: usize, radius: f64) -> Self {
        Self {
            by_corner: vec![NO_BOX; corners],
            within2: -1.0,
            radius,
            refused: 0,
        }
    }

    /// Whether box `i` (if any) comes nearer than the radius less the margin to a leg `p`-`a` or
    /// `p`-`b`: `p` itself first, the cheapest test (each leg's first end).
    fn blocks(&self, scene: &Scene, i: u32, a: Point, p: Point, b: Point) -> bool {
        let Some(o) = scene.boxes().get(i as usize) else {
            return false;
        };
        let r2 = self.within2;
        r2 > 0.0 && (o.segment_nearer_than(p, a, r2) || o.segment_nearer_than(p, b, r2))
    }

    /// Whether corner `k`'s box blocks moving it, between `a` and `b`, to `p`.
    fn block(&mut self, scene: &Scene, k: usize, a: Point, p: Point, b: Point) -> bool {
        let blocked = self.blocks(scene, self.by_corner[k], a, p, b);
        self.refused += usize::from(blocked);
        blocked
    }

    /// After the scene refused moving corner `k` to `p`: remembers a box near `p` that blocks
    /// it by the margin, if there is one.
    fn learn(&mut self, scene: &Scene, k: usize, a: Point, p: Point, b: Point) {
        if self.within2 <= 0.0 {
            return;
        }
        if let Some(&i) = scene
            .boxes_near(p, self.radius)
            .iter()
            .find(|&&i| self.blocks(scene, i, a, p, b))
        {
            self.by_corner[k] = i;
        }
    }
}

/// Drops the corners whose neighbours see each other.
fn drop_seen_corners(scene: &Scene, out: &mut Vec<Point>, radius: f64) {
    let mut k = 1;
    while k + 1 < out.len() {
        if scene.sweep_clear(out[k - 1], out[k + 1], radius) {
            out.remove(k);
        } else {
            k += 1;
        }
    }
}

/// Length of a polyline, px.
pub fn path_length(points: &[Point]) -> f64 {
    points.windows(2).map(|w| (w[1] - w[0]).norm()).sum()
}

/// The shortest collision-free path for a disc of `radius` from `start` to `goal`, smoothed; `None`
/// when they are not connected.
pub fn shortest_path(
    scene: &Scene,
    grid: &FreeGrid,
    start: Point,
    goal: Point,
    radius: f64,
) -> Option<Vec<Point>> {
    let path = grid_path(scene, grid, start, goal, radius, 1.0)?;
    Some(smooth(scene, &path, radius))
}

/// Length of the shortest collision-free path for `world`'s robot from `start` to `goal`, px;
/// `None` when they are not connected.
pub fn shortest_path_px(world: &World, start: Point, goal: Point) -> Option<f64> {
    let radius = world.config().robot.radius_px;
    let path = shortest_path(world.scene(), world.grid(), start, goal, radius)?;
    Some(path_length(&path))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Aabb;

    fn room_with_wall() -> Scene {
        // A 200 x 100 room with a wall from the floor up to y = 70 at x = 100.
        let mut boxes = Scene::from_occupancy(200, 100, &vec![false; 200 * 100], 1.0, 50.0)
            .boxes()
            .to_vec();
        boxes.push(Aabb::from_corners(
            Point::new(99.0, 0.0),
            Point::new(101.0, 70.0),
        ));
        Scene::from_boxes(200.0, 100.0, boxes, 50.0)
    }

    #[test]
    fn open_room_shortest_path_is_the_straight_line() {
        let scene = Scene::from_occupancy(200, 100, &vec![false; 200 * 100], 1.0, 50.0);
        let grid = FreeGrid::new(&scene, 5.0, 5.0, 0.0);
        let (a, b) = (Point::new(20.0, 20.0), Point::new(180.0, 77.0));
        let path = shortest_path(&scene, &grid, a, b, 5.0).unwrap();
        assert_eq!(path, vec![a, b]);
    }

    #[test]
    fn shortest_path_goes_over_the_wall_tip_and_is_near_optimal() {
        let scene = room_with_wall();
        let grid = FreeGrid::new(&scene, 5.0, 5.0, 0.0);
        let (a, b) = (Point::new(50.0, 20.0), Point::new(150.0, 20.0));
        let path = shortest_path(&scene, &grid, a, b, 5.0).unwrap();
        // The true shortest path runs tangent to the circles of radius 5 about the wall tip's
        // corners (99, 70) and (101, 70), with arcs over them and the 2 px between:
        // 149.32 px, found by minimising |a p| + arc(p, top) over points p on the circle.
        let optimum = 149.32;
        let length = path_length(&path);
        assert!(length >= optimum - 0.1, "{length} < {optimum}");
        // The grid-based path stays within 2% of it (1.5% here): the documented SPL accuracy.
        assert!(length < optimum * 1.02, "{length} vs {optimum}: {path:?}");
        for w in path.windows(2) {
            assert!(scene.sweep_clear(w[0], w[1], 5.0));
        }
    }

    /// [`smooth`] as it was before it passed over corners that would stay put and refused moves
    /// a remembered box blocks: every corner tried in every round, every try tested.
    fn smooth_trying_every_corner(scene: &Scene, points: &[Point], radius: f64) -> Vec<Point> {
        let mut out = with_midpoints(&jump_ahead(scene, points, radius));
        let mut directions = directions();
        let mut blockers = Blockers::off(out.len(), radius);
        for step in TIGHTEN_STEPS_PX {
            // Up to 8 rounds, until one moves no corner.
            for _ in 0..8 {
                let mut moved = false;
                for k in 1..out.len().saturating_sub(1) {
                    moved |= try_corner(scene, &mut out, k, step, &mut directions, &mut blockers);
                }
                if !moved {
                    break;
                }
            }
        }
        drop_seen_corners(scene, &mut out, radius);
        out
    }

    /// The bits of a path's points, to compare paths exactly.
    fn bits(points: &[Point]) -> Vec<[u64; 2]> {
        points
            .iter()
            .map(|p| [p.x.to_bits(), p.y.to_bits()])
            .collect()
    }

    /// Calls `check` with what smoothing meets: in the worlds of seeds `0..worlds` (mazes,
    /// warehouses and an image map by turns), grid paths between random free points, whole and
    /// cut to the expert's 80-point prefixes, at the radii the planners use.
    fn each_smoothing_case(worlds: u64, mut check: impl FnMut(&str, &Scene, &[Point], f64)) {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        for (seed, world) in crate::plan::field::tests::mixed_worlds(worlds) {
            let (scene, grid) = (world.scene(), world.grid());
            for _ in 0..6 {
                let free = |rng: &mut rand_chacha::ChaCha8Rng| loop {
                    let p = Point::new(
                        rng.random_range(0.0..scene.width()),
                        rng.random_range(0.0..scene.height()),
                    );
                    if scene.disc_clear(p, 12.0) {
                        return p;
                    }
                };
                let (a, b) = (free(&mut rng), free(&mut rng));
                let Some(path) = grid_path(scene, grid, a, b, 5.0, 4.0) else {
                    continue;
                };
                let case = format!("world {seed}, {a:?} to {b:?}");
                for points in [&path[..], &path[..path.len().min(80)]] {
                    for radius in [5.0, 11.0] {
                        check(&case, scene, points, radius);
                    }
                }
            }
        }
    }

    #[test]
    fn passing_over_corners_that_stay_put_changes_no_bit() {
        let mut corners = 0;
        each_smoothing_case(6, |case, scene, points, radius| {
            let ours = smooth(scene, points, radius);
            let every = smooth_trying_every_corner(scene, points, radius);
            assert_eq!(bits(&ours), bits(&every), "{case}");
            corners += ours.len();
        });
        assert!(corners > 500, "only {corners} points");
    }

    /// Refusing the moves a remembered box clearly blocks gives the path that testing every
    /// move gives, bit for bit, and most failing moves are refused so.
    #[test]
    fn refusing_moves_a_remembered_box_blocks_changes_no_bit() {
        let (mut refused, mut corners) = (0, 0);
        each_smoothing_case(9, |case, scene, points, radius| {
            let start = with_midpoints(&jump_ahead(scene, points, radius));
            let n = start.len();
            let mut blockers = Blockers::new(scene, points, n, radius);
            let ours = tighten(scene, start.clone(), radius, &mut blockers);
            let tested = tighten(scene, start, radius, &mut Blockers::off(n, radius));
            assert_eq!(bits(&ours), bits(&tested), "{case}");
            refused += blockers.refused;
            corners += ours.len();
        });
        assert!(corners > 500, "only {corners} points");
        assert!(refused > 50_000, "only {refused} moves refused untested");
    }

    /// Whenever a box blocks a move by the margin, the scene's own tests refuse the move too. A
    /// leg passes a corner of the scene's one box a hair nearer or further than the radius, long
    /// enough for the sweep to cut it into pieces, at radii within the index's reach and beyond.
    #[test]
    fn a_box_that_blocks_by_the_margin_is_one_the_scene_refuses() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let mut blocked = 0;
        for _ in 0..4000 {
            let min = Point::new(
                rng.random_range(300.0..600.0),
                rng.random_range(300.0..600.0),
            );
            let size = Vector::new(rng.random_range(0.5..80.0), rng.random_range(0.5..80.0));
            let o = Aabb::from_corners(min, min + size);
            let scene = Scene::from_boxes(1000.0, 1000.0, vec![o], 50.0);
            let radius = [5.0, 11.0, 30.0, 70.0][rng.random_range(0..4)];
            let hair =
                [-1e-4, -3e-6, -1.5e-6, -1e-6, -5e-7, 0.0, 1e-7, 1e-5][rng.random_range(0..8)];
            // The leg touches the circle of `radius + hair` about a corner, outside the box.
            let corner = o.corners()[rng.random_range(0..4)];
            let out = (corner - (min + size / 2.0)).normalize();
            let turn = rng.random_range(-1.0..1.0);
            let tangent = Vector::new(-out.y, out.x) + out * (turn * 1e-3);
            let touch = corner + out * (radius + hair);
            let (a, p) = (
                touch - tangent * rng.random_range(20.0..250.0),
                touch + tangent * rng.random_range(20.0..250.0),
            );
            let b = p + out * rng.random_range(1.0..100.0);
            let mut blockers = Blockers::new(&scene, &[a, p, b], 3, radius);
            blockers.by_corner[1] = 0;
            let refused = !(scene.disc_clear(p, radius)
                && scene.sweep_clear(a, p, radius)
                && scene.sweep_clear(p, b, radius));
            if blockers.block(&scene, 1, a, p, b) {
                blocked += 1;
                assert!(refused, "{o:?} at {radius} + {hair}: {a:?} {p:?} {b:?}");
            } else {
                // Only those a hair inside the radius, within the margin, go to the scene.
                assert!(hair > -1.5e-6, "{o:?} at {radius} + {hair}: not blocked");
            }
        }
        assert!(blocked > 1500, "only {blocked} blocked");
    }

    #[test]
    fn disconnected_goal_has_no_path() {
        let mut boxes = room_with_wall().boxes().to_vec();
        boxes.push(Aabb::from_corners(
            Point::new(99.0, 0.0),
            Point::new(101.0, 100.0),
        ));
        let scene = Scene::from_boxes(200.0, 100.0, boxes, 50.0);
        let grid = FreeGrid::new(&scene, 5.0, 5.0, 0.0);
        assert!(shortest_path(
            &scene,
            &grid,
            Point::new(50.0, 20.0),
            Point::new(150.0, 20.0),
            5.0
        )
        .is_none());
    }
}
