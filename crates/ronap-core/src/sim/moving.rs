//! Moving and appearing obstacles (SPEC "Moving obstacles"): discs and boxes that move before the
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

    /// The box the body covers at `center` (a disc's bounding box).
    pub fn aabb(&self, center: Point) -> Aabb {
        let h = match *self {
            Body::Disc(r) => Vector::new(r, r),
            Body::Box(h) => h,
        };
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
    fn ray(&self, center: Point, origin: Point, dir: Vector, max: f64) -> Option<f64> {
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

/// How one obstacle moves, with its state.
#[derive(Clone, Debug)]
enum Motion {
    Still,
    /// `linear` (no turning) or `random_walk` (turning by N(0, sigma^2) rad each step).
    Heading {
        dir: Vector,
        sigma_rad: f64,
    },
    Waypoints {
        points: std::sync::Arc<[Point]>,
        target: usize,
        forward: bool,
        mode: Patrol,
    },
}

/// One moving obstacle in an episode.
#[derive(Clone, Debug)]
pub struct Mover {
    body: Body,
    position: Point,
    speed: f64,
    motion: Motion,
    /// `appear`: the step it appears in, until it has.
    appears_at: Option<u32>,
    /// Its fixed start overlaps the robot: absent until the robot is clear of it.
    held: bool,
    min_gap: f64,
    /// A disc round `free_center` clear of the still scene: moves that stay inside it need no
    /// query (radius 0 until first measured).
    free_center: Point,
    free_radius: f64,
}

impl Mover {
    /// Whether the body can move from its position to `to` without touching the still scene.
    /// Exact: the cached free disc only answers when the whole sweep lies inside it.
    #[inline]
    fn still_clear(&mut self, scene: &Scene, to: Point) -> bool {
        let bound = self.body.bounding_radius();
        let inside = |c: Point, r: f64| {
            let room = r - bound;
            room > 0.0 && (to - c).norm_squared() < room * room
        };
        if inside(self.free_center, self.free_radius) {
            return true;
        }
        let from = self.position;
        self.free_center = from;
        self.free_radius = scene.free_radius(from);
        inside(from, self.free_radius) || self.body.sweep_clear(scene, from, to)
    }
}

/// `(sin a, cos a)`, for the small turns of a random walk: a Taylor series where it is exact to
/// within 1e-15 (|a| <= 0.5), `sin_cos` beyond. Plain arithmetic, so the same on every platform.
#[inline]
fn small_sin_cos(a: f64) -> (f64, f64) {
    if a.abs() > 0.5 {
        return a.sin_cos();
    }
    let a2 = a * a;
    // Up to a^13 / 13! and a^14 / 14! (Horner form, multiplications only): the first term left
    // out is below 3e-17 for |a| <= 0.5.
    const S: [f64; 6] = [
        -1.0 / 6.0,
        1.0 / 120.0,
        -1.0 / 5040.0,
        1.0 / 362_880.0,
        -1.0 / 39_916_800.0,
        1.0 / 6_227_020_800.0,
    ];
    const C: [f64; 7] = [
        -1.0 / 2.0,
        1.0 / 24.0,
        -1.0 / 720.0,
        1.0 / 40_320.0,
        -1.0 / 3_628_800.0,
        1.0 / 479_001_600.0,
        -1.0 / 87_178_291_200.0,
    ];
    let s =
        a * (1.0 + a2 * (S[0] + a2 * (S[1] + a2 * (S[2] + a2 * (S[3] + a2 * (S[4] + a2 * S[5]))))));
    let c = 1.0
        + a2 * (C[0]
            + a2 * (C[1] + a2 * (C[2] + a2 * (C[3] + a2 * (C[4] + a2 * (C[5] + a2 * C[6]))))));
    (s, c)
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
        self.appears_at.is_none() && !self.held
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
    items: Vec<Mover>,
    rng: Rng,
    /// Largest bounding radius plus step, for the quick distance tests.
    reach: f64,
    robot_radius: f64,
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
        if config.moving.is_empty() {
            return Ok(None);
        }
        let robot_radius = config.robot.radius_px;
        let mut rng = stream(seed, Stream::Moving);
        let mut items = Vec::new();
        let mut reach: f64 = 0.0;
        for (entry, m) in config.moving.iter().enumerate() {
            let err = |message: String| MovingError { entry, message };
            let body = match m.shape {
                MovingShape::Disc => Body::Disc(m.radius_px),
                MovingShape::Box => Body::Box(Vector::new(m.size_px[0], m.size_px[1]) / 2.0),
            };
            reach = reach.max(body.bounding_radius() + m.speed_px);
            for _ in 0..m.count {
                let mover =
                    Self::make(m, body, scene, start, goal, robot_radius, &mut rng).map_err(err)?;
                items.push(mover);
            }
        }
        Ok(Some(Self {
            items,
            rng,
            reach,
            robot_radius,
        }))
    }

    fn make(
        m: &MovingConfig,
        body: Body,
        scene: &Scene,
        start: Point,
        goal: Point,
        robot_radius: f64,
        rng: &mut Rng,
    ) -> Result<Mover, String> {
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
                    body.gap(p, start, robot_radius) >= m.min_robot_distance_px
                        && body.gap(p, goal, robot_radius) >= m.min_robot_distance_px
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
        let held = appears_at.is_none() && body.gap(position, start, robot_radius) < 0.0;
        let motion = match kind {
            MotionKind::Still | MotionKind::Appear => Motion::Still,
            MotionKind::Linear | MotionKind::RandomWalk => {
                let deg = match m.direction_deg {
                    Some(d) => d,
                    None => rng.random_range(0.0..360.0),
                };
                Motion::Heading {
                    dir: unit(deg),
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
        Ok(Mover {
            body,
            position,
            speed: m.speed_px,
            motion,
            appears_at,
            held,
            min_gap: m.min_robot_distance_px,
            free_center: position,
            free_radius: 0.0,
        })
    }

    /// The obstacles.
    pub fn items(&self) -> &[Mover] {
        &self.items
    }

    /// Adds where each obstacle is now to `tracks` (one per obstacle, made on the first call).
    pub fn record(&self, tracks: &mut Vec<Track>) {
        if tracks.is_empty() {
            tracks.extend(self.items.iter().map(|m| Track {
                body: m.body,
                points: Vec::new(),
            }));
        }
        for (t, m) in tracks.iter_mut().zip(&self.items) {
            t.points.push(m.present().then_some(m.position));
        }
    }

    /// Moves every obstacle one step (step `step` of the episode, from 1), with the robot (a disc
    /// of the configured radius) standing at `robot`.
    pub fn advance(&mut self, step: u32, scene: &Scene, robot: Point) -> Advance {
        let mut out = Advance::default();
        let radius = self.robot_radius;
        let rng = &mut self.rng;
        for m in &mut self.items {
            if let Some(at) = m.appears_at {
                if step >= at {
                    let (body, min_gap) = (m.body, m.min_gap);
                    let far = |p: Point| body.gap(p, robot, radius) >= min_gap;
                    if let Some(p) = free_spot(body, scene, rng, far) {
                        m.position = p;
                        m.appears_at = None;
                    }
                }
                continue;
            }
            if m.held {
                if m.body.gap(m.position, robot, radius) < 0.0 {
                    continue;
                }
                m.held = false;
            }
            let from = m.position;
            let to = match &mut m.motion {
                Motion::Still => continue,
                Motion::Heading { dir, sigma_rad } => {
                    if *sigma_rad > 0.0 {
                        let turn: f64 = StandardNormal.sample(rng);
                        let (s, c) = small_sin_cos(*sigma_rad * turn);
                        let turned = Vector::new(dir.x * c - dir.y * s, dir.x * s + dir.y * c);
                        // A rotation keeps the length to within rounding; renormalise only once that
                        // drifts (rarely), sparing a square root and a division in most steps.
                        let n2 = turned.norm_squared();
                        *dir = if (n2 - 1.0).abs() > 1e-12 {
                            turned / n2.sqrt()
                        } else {
                            turned
                        };
                    }
                    let heading = *dir;
                    let ahead = from + heading * m.speed;
                    if m.still_clear(scene, ahead) {
                        ahead
                    } else {
                        // Reflect off what is in the way: the x component, the y, or both.
                        let flips = [
                            Vector::new(-1.0, 1.0),
                            Vector::new(1.0, -1.0),
                            Vector::new(-1.0, -1.0),
                        ];
                        let Some(flipped) = flips
                            .iter()
                            .map(|f| heading.component_mul(f))
                            .find(|d| m.body.sweep_clear(scene, from, from + d * m.speed))
                        else {
                            continue;
                        };
                        if let Motion::Heading { dir, .. } = &mut m.motion {
                            *dir = flipped;
                        }
                        from + flipped * m.speed
                    }
                }
                Motion::Waypoints {
                    points,
                    target,
                    forward,
                    mode,
                } => {
                    let mut at = from;
                    let mut left = m.speed;
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
            let near = m.speed + m.body.bounding_radius() + radius;
            if (from - robot).norm_squared() < near * near
                && m.body.sweep_touches(from, to, robot, radius)
            {
                out.touched_robot = true;
                continue;
            }
            m.position = to;
        }
        out
    }

    /// Whether a disc of `radius` can move in a straight line from `a` to `b` without touching a
    /// present obstacle.
    pub fn sweep_clear(&self, a: Point, b: Point, radius: f64) -> bool {
        let reach = self.reach + radius + (b - a).norm();
        let r2 = reach * reach;
        self.items.iter().all(|m| {
            !m.present()
                || (m.position - a).norm_squared() > r2
                || match m.body {
                    Body::Disc(r) => {
                        point_segment_distance_squared(m.position, a, b) >= (r + radius).powi(2)
                    }
                    Body::Box(_) => {
                        m.body.aabb(m.position).segment_distance_squared(a, b) >= radius * radius
                    }
                }
        })
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
        let mut near = [0u32; 64];
        let mut count = 0;
        let mut overflow = false;
        let mut least_gap = f64::INFINITY;
        let range = laser.range_px();
        for (i, m) in self.items.iter().enumerate() {
            if !m.present() {
                continue;
            }
            let bound = m.body.bounding_radius();
            let d2 = (m.position - position).norm_squared();
            let far = range + self.robot_radius + bound;
            if d2 > far * far {
                continue;
            }
            let d = d2.sqrt();
            if d - bound <= range + self.robot_radius {
                least_gap = least_gap.min(m.body.gap(m.position, position, self.robot_radius));
                if d - bound <= range {
                    if count < near.len() {
                        near[count] = i as u32;
                        count += 1;
                    } else {
                        overflow = true;
                    }
                }
            }
        }
        if count == 0 {
            return least_gap;
        }
        // More obstacles in range than the list holds (rare): read every present one.
        let all: Vec<u32>;
        let list = if overflow {
            all = (0..self.items.len() as u32)
                .filter(|&i| self.items[i as usize].present())
                .collect();
            &all[..]
        } else {
            &near[..count]
        };
        laser.refine(position, heading_deg, out, |origin, dir, best| {
            let mut nearest: Option<f64> = None;
            for &i in list {
                let m = &self.items[i as usize];
                if let Some(t) = m.body.ray(m.position, origin, dir, nearest.unwrap_or(best)) {
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

    #[test]
    fn small_sin_cos_matches_the_library() {
        for k in -1000..=1000 {
            let a = k as f64 * 0.0011;
            let (s, c) = small_sin_cos(a);
            let (s0, c0) = a.sin_cos();
            assert!((s - s0).abs() < 1e-15 && (c - c0).abs() < 1e-15, "{a}");
        }
    }
}
