//! Moving and appearing obstacles (docs/model.md "Moving obstacles"): discs and boxes that move before the
//! robot in every step, as `linear`, `waypoints`, `random_walk` or `appear` say, all drawn from the
//! episode seed's own moving-obstacle stream, so adding one never changes the maze, the start or
//! the goal.
//!
//! Contact works both ways and is swept, so no speed carries one through the other: an obstacle
//! whose own motion would touch the robot stays where it was (and the robot is charged a dynamic
//! collision); a robot step is swept against the obstacles' new positions. Obstacles do not
//! collide with each other.

use crate::config::{MotionKind, MovingConfig, MovingShape, Patrol, ValidConfig};
use crate::geometry::{point_segment_distance_squared, unit, Aabb, Point, Vector};
use crate::scene::Scene;
use crate::sim::rng::{stream, Rng, Stream};
use rand::Rng as _;
use rand_distr::{Distribution, StandardNormal};

/// Attempts at finding a free spot for an obstacle.
const SPOT_TRIES: usize = 1000;

/// A moving obstacle's body.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Body {
    /// A disc of this radius, px.
    Disc(f64),
    /// An axis-aligned box of these half extents, px.
    Box(Vector),
}

impl Body {
    /// Radius of the smallest disc round the body, px.
    pub fn bounding_radius(&self) -> f64 {
        match *self {
            Body::Disc(r) => r,
            Body::Box(h) => h.norm(),
        }
    }

    /// Half extents of the box the body covers (a disc's bounding box), px.
    pub fn half_extents(&self) -> Vector {
        match *self {
            Body::Disc(r) => Vector::new(r, r),
            Body::Box(h) => h,
        }
    }

    /// The box the body covers at `center` (a disc's bounding box).
    pub fn aabb(&self, center: Point) -> Aabb {
        let h = self.half_extents();
        Aabb::from_corners(center - h, center + h)
    }

    /// The gap between the body at `center` and a disc of `radius` at `p` (negative when they
    /// overlap, for discs).
    pub fn gap(&self, center: Point, p: Point, radius: f64) -> f64 {
        match *self {
            Body::Disc(r) => (p - center).norm() - r - radius,
            Body::Box(_) => self.aabb(center).distance_squared(p).sqrt() - radius,
        }
    }

    /// Whether the body moving from `a` to `b` comes closer than `radius` to the point `p`
    /// (a robot disc of `radius` at `p` would be touched).
    fn sweep_touches(&self, a: Point, b: Point, p: Point, radius: f64) -> bool {
        match *self {
            Body::Disc(r) => point_segment_distance_squared(p, a, b) < (r + radius).powi(2),
            Body::Box(h) => {
                // The point against the box at rest, moving the other way.
                let rest = Aabb::from_corners(Point::from(-h), Point::from(h));
                let d = b - a;
                rest.segment_distance_squared(Point::from(p - a), Point::from(p - a - d))
                    < radius * radius
            }
        }
    }

    /// Whether the body fits at `center` in `scene` without touching a static obstacle.
    fn clear_at(&self, scene: &Scene, center: Point) -> bool {
        let inside = scene.bounds();
        match *self {
            Body::Disc(r) => {
                let b = self.aabb(center);
                inside.contains(b.min) && inside.contains(b.max) && scene.disc_clear(center, r)
            }
            Body::Box(_) => scene.box_clear(self.aabb(center)),
        }
    }

    /// Whether the body can move in a straight line from `a` to `b` in `scene`.
    fn sweep_clear(&self, scene: &Scene, a: Point, b: Point) -> bool {
        match *self {
            Body::Disc(r) => scene.bounds().inflated(-r).contains(b) && scene.sweep_clear(a, b, r),
            Body::Box(h) => scene.box_sweep_clear(a, b, h),
        }
    }

    /// Distance along the unit direction `dir` from `origin` to the body at `center`.
    #[inline]
    pub(crate) fn ray(&self, center: Point, origin: Point, dir: Vector, max: f64) -> Option<f64> {
        match *self {
            Body::Disc(r) => {
                let oc = center - origin;
                let along = oc.dot(&dir);
                let d2 = oc.norm_squared() - along * along;
                let r2 = r * r;
                if d2 > r2 {
                    return None;
                }
                let t = along - (r2 - d2).sqrt();
                let t = if oc.norm_squared() <= r2 { 0.0 } else { t };
                (t >= 0.0 && t <= max).then_some(t)
            }
            Body::Box(_) => {
                let inv = Vector::new(1.0 / dir.x, 1.0 / dir.y);
                self.aabb(center).ray_hit(origin, inv, max)
            }
        }
    }
}

/// How one obstacle moves, with the state its heading and speed (kept in [`State`]) leave out.
#[derive(Clone, Debug)]
enum Motion {
    Still,
    /// `linear` (no turning) or `random_walk` (turning by N(0, sigma^2) rad each step).
    Heading {
        sigma_rad: f64,
    },
    Waypoints {
        points: std::sync::Arc<[Point]>,
        target: usize,
        forward: bool,
        mode: Patrol,
    },
}

/// What one moving obstacle is, apart from where it is and where it heads.
#[derive(Clone, Debug)]
struct Entry {
    body: Body,
    motion: Motion,
    /// `appear`: the step it appears in, until it has.
    appears_at: Option<u32>,
    /// Its fixed start overlaps the robot: absent until the robot is clear of it.
    held: bool,
    min_gap: f64,
}

impl Entry {
    fn present(&self) -> bool {
        self.appears_at.is_none() && !self.held
    }

    /// Whether it moves along its heading this step (present, `linear` or `random_walk`), and
    /// the standard deviation of its turns, rad (0 when it does not turn).
    fn walk(&self) -> (bool, f64) {
        match self.motion {
            Motion::Heading { sigma_rad } if self.present() => (true, sigma_rad),
            _ => (false, 0.0),
        }
    }
}

/// Where the obstacles are and where they head, one array per quantity, so that the turns, the
/// moves and the fast clearance test of every obstacle run as one vectorised pass.
#[derive(Clone, Debug, Default)]
struct State {
    x: Vec<f64>,
    y: Vec<f64>,
    /// Unit heading (`linear`, `random_walk`).
    dx: Vec<f64>,
    dy: Vec<f64>,
    speed: Vec<f64>,
    /// Where the centre may go with no query: a box clear of the still scene shrunk by the body
    /// (empty until first measured). A straight move between two points inside it is clear.
    lo_x: Vec<f64>,
    lo_y: Vec<f64>,
    hi_x: Vec<f64>,
    hi_y: Vec<f64>,
    /// Bounding radius of the body, px.
    bound: Vec<f64>,
    /// Squared distance from the robot's centre within which a move must be checked against it.
    near_robot2: Vec<f64>,
    /// Whether it moves along its heading this step ([`Entry::walk`], kept up to date as
    /// obstacles appear or are released).
    walks: Vec<bool>,
    /// The standard deviation of its turns, rad (0 when absent or not turning; the same).
    sigma: Vec<f64>,
    /// This step's turn, rad (0 for the obstacles not turning), and its sine and cosine.
    turn: Vec<f64>,
    sin: Vec<f64>,
    cos: Vec<f64>,
    /// This step's intended centre, and whether it lies in the free box.
    ahead_x: Vec<f64>,
    ahead_y: Vec<f64>,
    fits: Vec<bool>,
    /// Whether the pass has moved it (a walk in its free box and far from the robot).
    moved: Vec<bool>,
    /// This step's turns beyond 1 rad, as `(obstacle, sin, cos)`, applied after the pass.
    wide: Vec<(usize, f64, f64)>,
    /// The obstacles by band of [`BAND_PX`] in y, then by x, as of the end of the last step, and
    /// where each band starts in that order (`band_start`, one past the last band at the end): a
    /// scan looks only at the obstacles of the bands within its reach whose x is within its reach
    /// too. Obstacles move a few px a step, so the order barely changes and an insertion sort
    /// keeps it in a pass.
    keys: Vec<Key>,
    band_start: Vec<u32>,
    /// Steps since `keys` were put in order: an obstacle may since have moved up to `age *
    /// drift` px on either axis, so a scan looks that much further in the old order, and the
    /// order is brought up to date every [`RESORT_EVERY`] steps (or when an obstacle appears).
    age: u32,
    /// The furthest an obstacle moves in a step on either axis (its speed), px, with a margin
    /// for rounding.
    drift: f64,
}

/// Steps between bringing the obstacles' order by band and x up to date: sorting costs more
/// than a step's scan, and in a few steps obstacles barely move.
const RESORT_EVERY: u32 = 8;

/// An obstacle's place in [`State::keys`].
#[derive(Clone, Copy, Debug)]
struct Key {
    band: u32,
    obstacle: u32,
    x: f64,
}

impl Key {
    /// Whether `self` comes after `other`: by band, then by x.
    #[inline]
    fn after(&self, other: &Key) -> bool {
        self.band > other.band || (self.band == other.band && self.x > other.x)
    }
}

/// Height of the bands of y by which [`State`] orders the obstacles for scans, px.
const BAND_PX: f64 = 64.0;

/// The band of y (below 0: band 0).
fn band(y: f64) -> u32 {
    // A float cast saturates (and takes NaN to 0), so every y has a band, in order.
    (y.max(0.0) / BAND_PX) as u32
}

/// [`State::pass`] as pulp runs it, compiled once per instruction set.
struct Pass<'a> {
    state: &'a mut State,
    robots: &'a [Point],
}

impl pulp::WithSimd for Pass<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _: S) {
        self.state.pass(self.robots);
    }
}

/// Margin by which a centre must lie inside its free box, px: the fast test never accepts what
/// the exact one might refuse by a rounding.
const FIT_MARGIN: f64 = 1e-9;

impl State {
    fn push(&mut self, entry: &Entry, position: Point, dir: Vector, speed: f64, near_robot: f64) {
        self.drift = self.drift.max(speed * (1.0 + 1e-9));
        self.bound.push(entry.body.bounding_radius());
        self.near_robot2.push(near_robot * near_robot);
        let (walks, sigma) = entry.walk();
        self.walks.push(walks);
        self.sigma.push(sigma);
        self.moved.push(false);
        self.x.push(position.x);
        self.y.push(position.y);
        self.dx.push(dir.x);
        self.dy.push(dir.y);
        self.speed.push(speed);
        self.lo_x.push(f64::INFINITY);
        self.lo_y.push(f64::INFINITY);
        self.hi_x.push(f64::NEG_INFINITY);
        self.hi_y.push(f64::NEG_INFINITY);
        self.turn.push(0.0);
        self.sin.push(0.0);
        self.cos.push(1.0);
        self.ahead_x.push(0.0);
        self.ahead_y.push(0.0);
        self.fits.push(false);
    }

    fn position(&self, i: usize) -> Point {
        Point::new(self.x[i], self.y[i])
    }

    /// Brings the order by band and x ([`State::keys`]) up to date with where the obstacles are.
    fn sort_keys(&mut self) {
        self.age = 0;
        let n = self.x.len();
        if self.keys.len() != n {
            self.keys = (0..n as u32)
                .map(|obstacle| Key {
                    band: 0,
                    obstacle,
                    x: 0.0,
                })
                .collect();
        }
        let (x, y) = (&self.x[..n], &self.y[..n]);
        for key in &mut self.keys {
            let i = key.obstacle as usize;
            key.x = x[i];
            key.band = band(y[i]);
        }
        let keys = &mut self.keys[..];
        for k in 1..keys.len() {
            if keys[k - 1].after(&keys[k]) {
                let key = keys[k];
                let mut j = k;
                while j > 0 && keys[j - 1].after(&key) {
                    keys[j] = keys[j - 1];
                    j -= 1;
                }
                keys[j] = key;
            }
        }
        self.band_start.clear();
        for (k, key) in self.keys.iter().enumerate() {
            while self.band_start.len() <= key.band as usize {
                self.band_start.push(k as u32);
            }
        }
        self.band_start.push(n as u32);
    }

    /// Calls `f` with every obstacle whose centre may lie within `slab` px of `p` on both axes
    /// (and some that do not): those of the bands within reach whose x is within reach, as of
    /// the last sort, reach grown by how far obstacles may have moved since.
    #[inline]
    fn near(&self, p: Point, slab: f64, mut f: impl FnMut(usize)) {
        let slab = slab + f64::from(self.age) * self.drift;
        let bands = self.band_start.len().saturating_sub(1);
        let (lo, hi) = (band(p.y - slab) as usize, band(p.y + slab) as usize);
        let (left, right) = (p.x - slab, p.x + slab);
        for b in lo..=hi.min(bands.saturating_sub(1)) {
            let (s, e) = (self.band_start[b] as usize, self.band_start[b + 1] as usize);
            let run = &self.keys[s..e];
            // A band holds a few obstacles: a plain walk beats a binary search to the first.
            for key in run {
                if key.x < left {
                    continue;
                }
                if key.x > right {
                    break;
                }
                f(key.obstacle as usize);
            }
        }
    }

    /// Turns every heading by this step's turn and moves it `speed` ahead into `ahead`, marking
    /// in `fits` those whose move stays in their free box; moves there, and marks `moved`, the
    /// walks that fit and are not near any robot at `robots`. Turns beyond 1 rad are applied one
    /// by one first; the rest is plain arithmetic over the arrays in loops with no branch, which
    /// vectorise (compiled for the processor's widest instruction set, the same bits on each).
    fn turn_and_look_ahead(&mut self, robots: &[Point]) {
        for &(i, s, c) in &self.wide {
            let (dx, dy) = (self.dx[i], self.dy[i]);
            self.dx[i] = dx * c - dy * s;
            self.dy[i] = dx * s + dy * c;
        }
        crate::geometry::ARCH.dispatch(Pass {
            state: self,
            robots,
        });
    }

    /// The vectorised part of [`State::turn_and_look_ahead`].
    #[inline(always)]
    fn pass(&mut self, robots: &[Point]) {
        let n = self.x.len();
        let (x, y, speed) = (&mut self.x[..n], &mut self.y[..n], &self.speed[..n]);
        let (dx, dy, turn) = (&mut self.dx[..n], &mut self.dy[..n], &self.turn[..n]);
        let (lo_x, lo_y) = (&self.lo_x[..n], &self.lo_y[..n]);
        let (hi_x, hi_y) = (&self.hi_x[..n], &self.hi_y[..n]);
        let (ax, ay) = (&mut self.ahead_x[..n], &mut self.ahead_y[..n]);
        let (fits, moved) = (&mut self.fits[..n], &mut self.moved[..n]);
        let (walks, near2) = (&self.walks[..n], &self.near_robot2[..n]);
        let (sin, cos) = (&mut self.sin[..n], &mut self.cos[..n]);
        // Which walks are far from every robot (from where they are now), robot by robot.
        moved.copy_from_slice(walks);
        for robot in robots {
            for i in 0..n {
                let (rx, ry) = (x[i] - robot.x, y[i] - robot.y);
                moved[i] &= rx * rx + ry * ry >= near2[i];
            }
        }
        // The series alone first: a short loop the compiler interleaves, hiding the latency of
        // the long chains of multiplications.
        for i in 0..n {
            (sin[i], cos[i]) = sin_cos_within_1(turn[i]);
        }
        for i in 0..n {
            let (s, c) = (sin[i], cos[i]);
            let (tx, ty) = (dx[i] * c - dy[i] * s, dx[i] * s + dy[i] * c);
            // A rotation keeps the length to within rounding; one Newton step towards length 1
            // stops the drift without a square root or a division.
            let k = 1.5 - 0.5 * (tx * tx + ty * ty);
            let (ux, uy) = (tx * k, ty * k);
            dx[i] = ux;
            dy[i] = uy;
            let (px, py) = (x[i], y[i]);
            let (qx, qy) = (px + ux * speed[i], py + uy * speed[i]);
            ax[i] = qx;
            ay[i] = qy;
            // The move is clear when both ends lie in the box (it is convex).
            let fit = (qx > lo_x[i])
                & (qx < hi_x[i])
                & (qy > lo_y[i])
                & (qy < hi_y[i])
                & (px > lo_x[i])
                & (px < hi_x[i])
                & (py > lo_y[i])
                & (py < hi_y[i]);
            fits[i] = fit;
            let go = moved[i] & fit;
            moved[i] = go;
            x[i] = if go { qx } else { px };
            y[i] = if go { qy } else { py };
        }
    }

    /// Sets this step's turn of obstacle `i` to `a` rad.
    #[inline]
    fn set_turn(&mut self, i: usize, a: f64) {
        if a.abs() <= 1.0 {
            self.turn[i] = a;
        } else {
            // Turned before the vectorised pass, which then only renormalises it.
            self.turn[i] = 0.0;
            let (s, c) = sin_cos(a);
            self.wide.push((i, s, c));
        }
    }

    /// Sets obstacle `i`'s free box to `free` shrunk by `half` (the body's half extents).
    fn set_free(&mut self, i: usize, free: Aabb, half: Vector) {
        self.lo_x[i] = free.min.x + half.x + FIT_MARGIN;
        self.lo_y[i] = free.min.y + half.y + FIT_MARGIN;
        self.hi_x[i] = free.max.x - half.x - FIT_MARGIN;
        self.hi_y[i] = free.max.y - half.y - FIT_MARGIN;
    }

    /// Whether `p` lies in obstacle `i`'s free box (a straight move to it is then clear).
    fn in_free(&self, i: usize, p: Point) -> bool {
        p.x > self.lo_x[i] && p.x < self.hi_x[i] && p.y > self.lo_y[i] && p.y < self.hi_y[i]
    }
}

/// `(sin a, cos a)` for |a| <= 1 by Taylor series (to a^17 and a^18: the first term left out is
/// below 1e-17), plain multiplications and additions, so the same bits on every platform and one
/// vectorised pass for many turns. Wrong beyond |a| = 1: see [`sin_cos`].
#[inline(always)]
fn sin_cos_within_1(a: f64) -> (f64, f64) {
    let a2 = a * a;
    const S: [f64; 8] = [
        -1.0 / 6.0,
        1.0 / 120.0,
        -1.0 / 5040.0,
        1.0 / 362_880.0,
        -1.0 / 39_916_800.0,
        1.0 / 6_227_020_800.0,
        -1.0 / 1_307_674_368_000.0,
        1.0 / 355_687_428_096_000.0,
    ];
    const C: [f64; 9] = [
        -1.0 / 2.0,
        1.0 / 24.0,
        -1.0 / 720.0,
        1.0 / 40_320.0,
        -1.0 / 3_628_800.0,
        1.0 / 479_001_600.0,
        -1.0 / 87_178_291_200.0,
        1.0 / 20_922_789_888_000.0,
        -1.0 / 6_402_373_705_728_000.0,
    ];
    let mut s = S[7];
    for k in (0..7).rev() {
        s = S[k] + a2 * s;
    }
    let mut c = C[8];
    for k in (0..8).rev() {
        c = C[k] + a2 * c;
    }
    (a * (1.0 + a2 * s), 1.0 + a2 * c)
}

/// `(sin a, cos a)` for any `a`: halved until within 1 rad, then doubled back. Plain arithmetic,
/// so the same on every platform (a random walk's turns beyond 1 rad are rare).
fn sin_cos(a: f64) -> (f64, f64) {
    let mut halvings = 0;
    let mut h = a;
    while h.abs() > 1.0 && halvings < 1100 {
        h *= 0.5;
        halvings += 1;
    }
    let (mut s, mut c) = sin_cos_within_1(h);
    for _ in 0..halvings {
        (s, c) = (2.0 * s * c, c * c - s * s);
    }
    (s, c)
}

/// A moving obstacle as pictures and tests see it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mover {
    body: Body,
    position: Point,
    present: bool,
}

impl Mover {
    /// The body.
    pub fn body(&self) -> Body {
        self.body
    }

    /// Where its centre is, px.
    pub fn position(&self) -> Point {
        self.position
    }

    /// Whether it is in the scene (an `appear` obstacle is not, until its step).
    pub fn present(&self) -> bool {
        self.present
    }
}

/// A moving obstacle's body and its centre at each recorded step (`None` while absent): what
/// pictures draw of it.
#[derive(Clone, Debug, PartialEq)]
pub struct Track {
    /// The body.
    pub body: Body,
    /// The centre at each recorded step, `None` while absent.
    pub points: Vec<Option<Point>>,
}

impl Track {
    /// Where it first was present.
    pub fn first(&self) -> Option<Point> {
        self.points.iter().flatten().next().copied()
    }

    /// Where it last was present.
    pub fn last(&self) -> Option<Point> {
        self.points.iter().flatten().next_back().copied()
    }
}

/// Where a moving obstacle could not be placed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("moving[{entry}]: {message}")]
pub struct MovingError {
    /// The `[[moving]]` entry, from 0.
    pub entry: usize,
    /// What went wrong.
    pub message: String,
}

/// The moving obstacles of one episode.
#[derive(Clone, Debug)]
pub struct Movers {
    entries: Vec<Entry>,
    state: State,
    rng: Rng,
    /// Largest bounding radius plus step, for the quick distance tests.
    reach: f64,
    /// The (largest) robot radius obstacles keep clear of.
    robot_radius: f64,
    /// The robots' centres this step (a buffer kept between steps).
    centres: Vec<Point>,
    /// Obstacles not yet present (to appear, or held back off the robot's start).
    waiting: usize,
}

/// A robot as moving obstacles see it: a disc.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Disc {
    /// Its centre.
    pub at: Point,
    /// Its radius, px.
    pub radius: f64,
}

impl Disc {
    /// The disc of `radius` at `at`.
    pub fn new(at: Point, radius: f64) -> Self {
        Self { at, radius }
    }
}

/// What moving the obstacles did in one step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Advance {
    /// An obstacle's motion would have touched the robot (it stayed where it was).
    pub touched_robot: bool,
}

impl Movers {
    /// The obstacles `config.moving` describes for episode `seed` in `scene`, with the robot
    /// starting at `start` and heading for `goal`. `None` when the configuration has none.
    pub fn new(
        config: &ValidConfig,
        scene: &Scene,
        start: Point,
        goal: Point,
        seed: u64,
    ) -> Result<Option<Self>, MovingError> {
        let robot = [Disc::new(start, config.robot.radius_px)];
        Self::among(config, scene, &robot, &[goal], seed)
    }

    /// The obstacles `config.moving` describes for episode `seed` in `scene`, among robots
    /// starting as `robots` (discs; the largest radius is the one obstacles keep clear of)
    /// and heading for `goals`. `None` when the configuration has none.
    pub fn among(
        config: &ValidConfig,
        scene: &Scene,
        robots: &[Disc],
        goals: &[Point],
        seed: u64,
    ) -> Result<Option<Self>, MovingError> {
        if config.moving.is_empty() {
            return Ok(None);
        }
        let robot_radius = robots
            .iter()
            .map(|r| r.radius)
            .fold(config.robot.radius_px, f64::max);
        let mut rng = stream(seed, Stream::Moving);
        let mut entries = Vec::new();
        let mut state = State::default();
        let mut reach: f64 = 0.0;
        for (entry, m) in config.moving.iter().enumerate() {
            let err = |message: String| MovingError { entry, message };
            let body = match m.shape {
                MovingShape::Disc => Body::Disc(m.radius_px),
                MovingShape::Box => Body::Box(Vector::new(m.size_px[0], m.size_px[1]) / 2.0),
            };
            reach = reach.max(body.bounding_radius() + m.speed_px);
            for _ in 0..m.count {
                let (e, position, dir) =
                    Self::make(m, body, scene, robots, goals, &mut rng).map_err(err)?;
                let near = m.speed_px + body.bounding_radius() + robot_radius;
                state.push(&e, position, dir, m.speed_px, near);
                entries.push(e);
            }
        }
        state.sort_keys();
        let waiting = entries.iter().filter(|e| !e.present()).count();
        Ok(Some(Self {
            entries,
            state,
            rng,
            reach,
            robot_radius,
            centres: Vec::new(),
            waiting,
        }))
    }

    /// One obstacle: what it is, where it starts and where it heads.
    fn make(
        m: &MovingConfig,
        body: Body,
        scene: &Scene,
        robots: &[Disc],
        goals: &[Point],
        rng: &mut Rng,
    ) -> Result<(Entry, Point, Vector), String> {
        let kind = if m.motion == MotionKind::Appear {
            m.then
        } else {
            m.motion
        };
        let appears_at =
            (m.motion == MotionKind::Appear).then(|| rng.random_range(m.from_step..=m.to_step));
        let position = match (m.start, m.motion) {
            (_, MotionKind::Appear) => Point::origin(),
            (Some(p), _) => Point::new(p[0], p[1]),
            (None, MotionKind::Waypoints) => Point::new(m.points[0][0], m.points[0][1]),
            (None, _) => {
                let far = |p: Point| {
                    robots.iter().zip(goals).all(|(r, &goal)| {
                        body.gap(p, r.at, r.radius) >= m.min_robot_distance_px
                            && body.gap(p, goal, r.radius) >= m.min_robot_distance_px
                    })
                };
                free_spot(body, scene, rng, far).ok_or_else(|| {
                    format!(
                        "found no free spot at least {} px from the robot's start and goal",
                        m.min_robot_distance_px
                    )
                })?
            }
        };
        // A fixed start on the robot's drawn start: held back until the robot has left it.
        let held = appears_at.is_none()
            && robots
                .iter()
                .any(|r| body.gap(position, r.at, r.radius) < 0.0);
        let mut dir = Vector::new(1.0, 0.0);
        let motion = match kind {
            MotionKind::Still | MotionKind::Appear => Motion::Still,
            MotionKind::Linear | MotionKind::RandomWalk => {
                let deg = match m.direction_deg {
                    Some(d) => d,
                    None => rng.random_range(0.0..360.0),
                };
                dir = unit(deg);
                Motion::Heading {
                    sigma_rad: if kind == MotionKind::RandomWalk {
                        m.turn_sigma_deg.to_radians()
                    } else {
                        0.0
                    },
                }
            }
            MotionKind::Waypoints => Motion::Waypoints {
                points: m.points.iter().map(|p| Point::new(p[0], p[1])).collect(),
                target: if m.start.is_some() { 0 } else { 1 },
                forward: true,
                mode: m.mode,
            },
        };
        let entry = Entry {
            body,
            motion,
            appears_at,
            held,
            min_gap: m.min_robot_distance_px,
        };
        Ok((entry, position, dir))
    }

    /// The obstacles, present or not.
    pub fn items(&self) -> impl ExactSizeIterator<Item = Mover> + '_ {
        self.entries.iter().enumerate().map(|(i, e)| Mover {
            body: e.body,
            position: self.state.position(i),
            present: e.present(),
        })
    }

    /// Adds where each obstacle is now to `tracks` (one per obstacle, made on the first call).
    pub fn record(&self, tracks: &mut Vec<Track>) {
        if tracks.is_empty() {
            tracks.extend(self.entries.iter().map(|e| Track {
                body: e.body,
                points: Vec::new(),
            }));
        }
        for (t, m) in tracks.iter_mut().zip(self.items()) {
            t.points.push(m.present().then_some(m.position()));
        }
    }

    /// Moves every obstacle one step (step `step` of the episode, from 1), with the robot (a disc
    /// of the configured radius) standing at `robot`.
    ///
    /// In three passes: appearances and releases, then this step's turns from the random stream
    /// in obstacle order, then the turns and moves of all headings at once (vectorised, with a
    /// free box per obstacle answering most clearance questions); what the free box cannot
    /// answer, waypoints and the contact with the robot are settled one by one.
    pub fn advance(&mut self, step: u32, scene: &Scene, robot: Point) -> Advance {
        let robot = [Disc::new(robot, self.robot_radius)];
        let mut touched = Vec::new();
        self.advance_among(step, scene, &robot, &mut touched);
        Advance {
            touched_robot: !touched.is_empty(),
        }
    }

    /// [`Movers::advance`] among several robots (discs): `touched` is cleared, then gets the
    /// index of every robot an obstacle's motion would have touched (once per such obstacle).
    pub fn advance_among(
        &mut self,
        step: u32,
        scene: &Scene,
        robots: &[Disc],
        touched: &mut Vec<usize>,
    ) {
        touched.clear();
        self.centres.clear();
        self.centres.extend(robots.iter().map(|r| r.at));
        let state = &mut self.state;
        let mut appeared = false;
        let entries = if self.waiting > 0 {
            &mut self.entries[..]
        } else {
            &mut []
        };
        for (i, e) in entries.iter_mut().enumerate() {
            if let Some(at) = e.appears_at {
                if step >= at {
                    let (body, min_gap) = (e.body, e.min_gap);
                    let far = |p: Point| {
                        robots
                            .iter()
                            .all(|r| body.gap(p, r.at, r.radius) >= min_gap)
                    };
                    if let Some(p) = free_spot(body, scene, &mut self.rng, far) {
                        state.x[i] = p.x;
                        state.y[i] = p.y;
                        e.appears_at = None;
                        (state.walks[i], state.sigma[i]) = e.walk();
                        self.waiting -= 1;
                        // A jump, not a step: the order must be brought up to date.
                        appeared = true;
                    }
                }
            } else if e.held
                && robots
                    .iter()
                    .all(|r| e.body.gap(state.position(i), r.at, r.radius) >= 0.0)
            {
                e.held = false;
                (state.walks[i], state.sigma[i]) = e.walk();
                self.waiting -= 1;
            }
        }
        state.wide.clear();
        for i in 0..state.sigma.len() {
            let sigma = state.sigma[i];
            if sigma > 0.0 {
                let z: f64 = StandardNormal.sample(&mut self.rng);
                state.set_turn(i, sigma * z);
            } else {
                state.turn[i] = 0.0;
            }
        }
        state.turn_and_look_ahead(&self.centres);
        for (i, e) in self.entries.iter_mut().enumerate() {
            if state.moved[i] || !e.present() {
                continue;
            }
            let from = state.position(i);
            let speed = state.speed[i];
            let to = match &mut e.motion {
                Motion::Still => continue,
                Motion::Heading { .. } => {
                    if state.fits[i] {
                        Point::new(state.ahead_x[i], state.ahead_y[i])
                    } else {
                        match Self::bounce(state, i, e.body, scene, from) {
                            Some(to) => to,
                            None => continue,
                        }
                    }
                }
                Motion::Waypoints {
                    points,
                    target,
                    forward,
                    mode,
                } => {
                    let mut at = from;
                    let mut left = speed;
                    // Each leg at least as long as a step is entered once per call.
                    for _ in 0..points.len() * 2 {
                        let goal = points[*target];
                        let d = (goal - at).norm();
                        if d > left {
                            at += (goal - at) * (left / d);
                            break;
                        }
                        at = goal;
                        left -= d;
                        advance_target(target, forward, *mode, points.len());
                        if left <= 0.0 {
                            break;
                        }
                    }
                    at
                }
            };
            // Every motion moves at most `speed` a step.
            let hit = robots.iter().position(|r| {
                (from - r.at).norm_squared() < state.near_robot2[i]
                    && e.body.sweep_touches(from, to, r.at, r.radius)
            });
            if let Some(k) = hit {
                touched.push(k);
                continue;
            }
            // Scans between sorts rely on it (see `State::age`).
            debug_assert!(
                (to.x - from.x).abs() <= state.drift && (to.y - from.y).abs() <= state.drift,
                "obstacle {i} moved from {from} to {to}, more than {} px",
                state.drift
            );
            state.x[i] = to.x;
            state.y[i] = to.y;
        }
        state.age += 1;
        if appeared || state.age >= RESORT_EVERY {
            state.sort_keys();
        }
    }

    /// Where heading obstacle `i` at `from` goes when its move ahead is not known clear: ahead
    /// if it is, else reflected off what is in the way (the x component, the y, or both), else
    /// nowhere. Measures a new free box round `from` first.
    fn bounce(
        state: &mut State,
        i: usize,
        body: Body,
        scene: &Scene,
        from: Point,
    ) -> Option<Point> {
        let (dx, dy, speed) = (state.dx[i], state.dy[i], state.speed[i]);
        // Sought ahead of the obstacle, where it is going: it stays in the box for longer.
        let free = scene.free_box_toward(from, dy.abs() > dx.abs(), Vector::new(dx, dy));
        state.set_free(i, free, body.half_extents());
        let clear = |state: &State, to: Point| {
            (state.in_free(i, from) && state.in_free(i, to)) || body.sweep_clear(scene, from, to)
        };
        let ahead = Point::new(state.ahead_x[i], state.ahead_y[i]);
        if clear(state, ahead) {
            return Some(ahead);
        }
        let flips = [(-dx, dy), (dx, -dy), (-dx, -dy)];
        let (fx, fy) = flips
            .into_iter()
            .find(|&(fx, fy)| clear(state, from + Vector::new(fx, fy) * speed))?;
        state.dx[i] = fx;
        state.dy[i] = fy;
        Some(from + Vector::new(fx, fy) * speed)
    }

    /// Whether a disc of `radius` can move in a straight line from `a` to `b` without touching a
    /// present obstacle.
    pub fn sweep_clear(&self, a: Point, b: Point, radius: f64) -> bool {
        let reach = self.reach + radius + (b - a).norm();
        let r2 = reach * reach;
        let st = &self.state;
        let mut clear = true;
        // Only obstacles whose centre is within `reach` of `a` can touch the sweep: those of
        // the bands and x within reach, as a scan finds them.
        st.near(a, reach, |i| {
            let (px, py) = (st.x[i] - a.x, st.y[i] - a.y);
            let e = &self.entries[i];
            clear &= px * px + py * py > r2
                || !e.present()
                || match e.body {
                    Body::Disc(r) => {
                        point_segment_distance_squared(st.position(i), a, b) >= (r + radius).powi(2)
                    }
                    Body::Box(_) => {
                        e.body.aabb(st.position(i)).segment_distance_squared(a, b)
                            >= radius * radius
                    }
                };
        });
        clear
    }

    /// Shortens the laser readings `out`, taken from `position` at `heading_deg`, to the present
    /// obstacles that are nearer; returns the least gap between the robot (a disc of the
    /// configured radius at `position`) and any present obstacle (infinite when there is none).
    pub fn sense(
        &self,
        laser: &crate::sim::lidar::Laser,
        position: Point,
        heading_deg: f64,
        out: &mut [f64],
    ) -> f64 {
        self.sense_as(laser, position, self.robot_radius, heading_deg, out)
    }

    /// [`Movers::sense`] for a robot of `radius`.
    pub fn sense_as(
        &self,
        laser: &crate::sim::lidar::Laser,
        position: Point,
        radius: f64,
        heading_deg: f64,
        out: &mut [f64],
    ) -> f64 {
        self.sense_toward(laser, position, radius, unit(heading_deg), out)
    }

    /// [`Movers::sense_as`] for the unit heading `heading` (`unit(heading_deg)`), which a caller
    /// that scans the still scene first works out once
    /// ([`Laser::scan_toward`](crate::sim::lidar::Laser::scan_toward)).
    pub fn sense_toward(
        &self,
        laser: &crate::sim::lidar::Laser,
        position: Point,
        radius: f64,
        heading: Vector,
        out: &mut [f64],
    ) -> f64 {
        let mut near = [0u32; 64];
        let mut count = 0;
        let mut overflow = false;
        let mut least_gap = f64::INFINITY;
        let range = laser.range_px();
        let st = &self.state;
        let reach = range + radius;
        // Only obstacles whose centre lies within reach of the laser on both axes (the largest
        // bounding radius, and a px far above any rounding, added) can be; of those, the ones
        // within reach.
        let slab = reach + self.reach + 1.0;
        st.near(position, slab, |i| {
            let (px, py) = (st.x[i] - position.x, st.y[i] - position.y);
            let d2 = px * px + py * py;
            let far = reach + st.bound[i];
            if d2 > far * far || !self.entries[i].present() {
                return;
            }
            let (p, bound) = (st.position(i), st.bound[i]);
            let d = d2.sqrt();
            if d - bound <= range + radius {
                // A disc's gap is `Body::gap`'s, whose norm is `d` to the bit.
                let gap = match self.entries[i].body {
                    Body::Disc(r) => d - r - radius,
                    body => body.gap(p, position, radius),
                };
                least_gap = least_gap.min(gap);
                if d - bound <= range {
                    if count < near.len() {
                        near[count] = i as u32;
                        count += 1;
                    } else {
                        overflow = true;
                    }
                }
            }
        });
        if count == 0 {
            return least_gap;
        }
        // More obstacles in range than the list holds (rare): read every present one.
        let all: Vec<u32>;
        let list = if overflow {
            all = (0..self.entries.len() as u32)
                .filter(|&i| self.entries[i as usize].present())
                .collect();
            &all[..]
        } else {
            &near[..count]
        };
        // Discs only (the common case): what each disc's ray test shares across beams is worked
        // out once, and the beams test them side by side.
        const DISCS: usize = 8;
        if !overflow && count <= DISCS {
            let mut discs = [(Vector::zeros(), 0.0, 0.0); DISCS];
            let mut all_discs = true;
            for (slot, &i) in discs.iter_mut().zip(list) {
                let i = i as usize;
                match self.entries[i].body {
                    Body::Disc(r) => {
                        let oc = st.position(i) - position;
                        *slot = (oc, oc.norm_squared(), r * r);
                    }
                    Body::Box(_) => all_discs = false,
                }
            }
            if all_discs {
                laser.refine_discs(heading, out, &discs[..count]);
                return least_gap;
            }
        }
        laser.refine_toward(position, heading, out, |origin, dir, best| {
            let mut nearest: Option<f64> = None;
            for &i in list {
                let e = &self.entries[i as usize];
                let p = self.state.position(i as usize);
                if let Some(t) = e.body.ray(p, origin, dir, nearest.unwrap_or(best)) {
                    nearest = Some(t);
                }
            }
            nearest
        });
        least_gap
    }
}

/// The next waypoint after reaching `target`.
fn advance_target(target: &mut usize, forward: &mut bool, mode: Patrol, n: usize) {
    match mode {
        Patrol::Loop => *target = (*target + 1) % n,
        Patrol::PingPong => {
            if *forward && *target + 1 == n {
                *forward = false;
            } else if !*forward && *target == 0 {
                *forward = true;
            }
            *target = if *forward { *target + 1 } else { *target - 1 };
        }
    }
}

/// A spot drawn uniformly over `scene` where `body` fits and `ok` holds.
fn free_spot(
    body: Body,
    scene: &Scene,
    rng: &mut Rng,
    ok: impl Fn(Point) -> bool,
) -> Option<Point> {
    let b = body
        .bounding_radius()
        .min(scene.width().min(scene.height()) / 2.0);
    for _ in 0..SPOT_TRIES {
        let p = Point::new(
            rng.random_range(b..(scene.width() - b).max(b + 1e-9)),
            rng.random_range(b..(scene.height() - b).max(b + 1e-9)),
        );
        if ok(p) && body.clear_at(scene, p) {
            return Some(p);
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::LaserConfig;
    use crate::sim::lidar::Laser;
    use crate::sim::world::maze_scene;

    /// What [`Movers::sense_as`] reads, worked out the plain way: every present obstacle
    /// against every beam.
    fn sense_every(
        m: &Movers,
        laser: &Laser,
        p: Point,
        radius: f64,
        z: f64,
        out: &mut [f64],
    ) -> f64 {
        let present: Vec<_> = m.items().filter(|o| o.present()).collect();
        laser.refine(p, z, out, |origin, dir, best| {
            present
                .iter()
                .filter_map(|o| o.body().ray(o.position(), origin, dir, best))
                .fold(None, |n: Option<f64>, t| Some(n.map_or(t, |n| n.min(t))))
        });
        let range = laser.range_px();
        present
            .iter()
            .filter(|o| (o.position() - p).norm() - o.body().bounding_radius() <= range + radius)
            .map(|o| o.body().gap(o.position(), p, radius))
            .fold(f64::INFINITY, f64::min)
    }

    /// What [`Movers::sweep_clear`] answers, worked out the plain way: every present obstacle.
    fn sweep_clear_every(m: &Movers, a: Point, b: Point, radius: f64) -> bool {
        m.items().filter(|o| o.present()).all(|o| match o.body() {
            Body::Disc(r) => {
                point_segment_distance_squared(o.position(), a, b) >= (r + radius).powi(2)
            }
            body @ Body::Box(_) => {
                body.aabb(o.position()).segment_distance_squared(a, b) >= radius * radius
            }
        })
    }

    #[test]
    fn pruned_sensing_reads_what_every_obstacle_gives_bit_for_bit() {
        // Crowds of discs, of boxes and of both, some of them appearing mid-run, more than a
        // scan lists at once for the long laser, stepped so that the order by band and x has to
        // follow them.
        use MotionKind::{Appear, RandomWalk};
        use MovingShape::{Box, Disc};
        for (kinds, beams, range) in [
            (vec![(Disc, RandomWalk)], 17, 50.0),
            (vec![(Disc, RandomWalk), (Disc, Appear)], 360, 400.0),
            (
                vec![(Box, RandomWalk), (Disc, RandomWalk), (Box, Appear)],
                64,
                120.0,
            ),
            (vec![(Disc, RandomWalk), (Disc, RandomWalk)], 64, 1000.0),
        ] {
            let sim = crate::SimConfig {
                moving: kinds
                    .iter()
                    .map(|&(shape, motion)| MovingConfig {
                        count: 60,
                        shape,
                        motion,
                        then: RandomWalk,
                        from_step: 10,
                        to_step: 150,
                        speed_px: 6.0,
                        ..Default::default()
                    })
                    .collect(),
                laser: LaserConfig {
                    beams,
                    fov_deg: 360.0,
                    range_px: range,
                    ..Default::default()
                },
                ..Default::default()
            };
            let config = sim.validate().expect("valid");
            let scene = maze_scene(&config, 3);
            let laser = Laser::new(&config.laser);
            let start = Point::new(125.0, 125.0);
            let mut movers = Movers::new(&config, &scene, start, Point::new(875.0, 875.0), 3)
                .expect("places")
                .expect("has movers");
            let mut rng = crate::sim::rng::stream(9, crate::sim::rng::Stream::Moving);
            let (mut scanned, mut blocked) = (0, 0);
            for step in 0..200 {
                movers.advance(step, &scene, start);
                for _ in 0..5 {
                    let p =
                        Point::new(rng.random_range(0.0..1000.0), rng.random_range(0.0..1000.0));
                    let z = rng.random_range(-180.0..180.0);
                    let mut want = vec![range; beams as usize];
                    let mut got = want.clone();
                    let gap_want = sense_every(&movers, &laser, p, 10.0, z, &mut want);
                    let gap_got = movers.sense_as(&laser, p, 10.0, z, &mut got);
                    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                    assert_eq!(bits(&got), bits(&want), "step {step} at {p} heading {z}");
                    assert_eq!(gap_got.to_bits(), gap_want.to_bits(), "step {step} at {p}");
                    scanned += usize::from(want.iter().any(|&r| r < range));
                    // The robot's sweep, pruned to the obstacles of the bands within reach.
                    let to = p + unit(z) * rng.random_range(0.0..40.0);
                    let clear = sweep_clear_every(&movers, p, to, 10.0);
                    assert_eq!(movers.sweep_clear(p, to, 10.0), clear, "{p} to {to}");
                    blocked += usize::from(!clear);
                }
            }
            assert!(
                scanned > 50,
                "the laser met obstacles in only {scanned} scans"
            );
            assert!(blocked > 20, "only {blocked} sweeps met an obstacle");
        }
    }

    #[test]
    fn sin_cos_matches_the_library() {
        for k in -3000..=3000 {
            let a = k as f64 * 0.0011;
            let (s, c) = sin_cos(a);
            let (s0, c0) = a.sin_cos();
            assert!((s - s0).abs() < 4e-15 && (c - c0).abs() < 4e-15, "{a}");
        }
        for a in [-1.0, 1.0, 20.0, -1e3] {
            let (s, c) = sin_cos(a);
            let (s0, c0) = f64::sin_cos(a);
            assert!((s - s0).abs() < 1e-9 && (c - c0).abs() < 1e-9, "{a}");
        }
    }
}
