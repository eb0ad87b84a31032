//! Moving and appearing obstacles (docs/model.md "Moving obstacles"): discs and boxes that move before the
//! robot in every step, as `linear`, `waypoints`, `random_walk` or `appear` say, all drawn from the
//! episode seed's own moving-obstacle streams (the random walks' turns from one SplitMix64 stream
//! per obstacle, keyed by the walk stream), so adding one never changes the maze, the start or
//! the goal.
//!
//! Contact works both ways and is swept, so no speed carries one through the other: an obstacle
//! whose own motion would touch the robot stays where it was (and the robot is charged a dynamic
//! collision); a robot step is swept against the obstacles' new positions. Obstacles do not
//! collide with each other.
//!
//! [`Movers`] is the engine. The heading motions (`linear`, `random_walk`) are moved together in
//! one vectorised pass (`heading.rs`); every other motion is a [`Behaviour`], one file each
//! (`waypoints.rs`), which sees the other obstacles and the robots through a [`Neighbours`]
//! query: a new motion is a new file implementing it and the line of [`Movers`] that makes it.

mod behaviour;
mod body;
mod heading;
mod pedestrian;
mod waypoints;

pub use behaviour::{Agent, Behaviour, Neighbours};
pub use body::Body;
pub use waypoints::Waypoints;

use crate::config::{MotionKind, MovingConfig, MovingShape, ValidConfig};
use crate::geometry::{point_segment_distance_squared, unit, Point, Vector};
use crate::scene::Scene;
use crate::sim::rng::{stream, Rng, Stream};
use heading::{State, RESORT_EVERY};
use rand::Rng as _;

/// Attempts at finding a free spot for an obstacle.
const SPOT_TRIES: usize = 1000;

/// How one obstacle moves, with the state its heading and speed (kept in [`State`]) leave out.
#[derive(Clone, Copy, Debug)]
enum Motion {
    Still,
    /// `linear` (no turning) or `random_walk` (turning each step by a near-normal draw of
    /// standard deviation `sigma_rad`, rad: `heading::standard_turn`), moved
    /// with every other heading in one pass.
    Heading {
        sigma_rad: f64,
    },
    /// Moved by its [`Behaviour`] (kept beside the entries, in [`Movers::behaviours`]).
    Behaves,
    /// A reactive pedestrian (kept beside the entries, in [`Movers::pedestrians`]).
    Reactive,
}

/// An entry's behaviour: a built-in held as itself, so that its step is called directly and
/// inlined into the obstacles' step (through the trait, the three forklifts of
/// `warehouse-forklifts.toml` cost 12% of `ronap bench --threads 1`'s steps), any other
/// behind the trait.
#[derive(Clone, Debug)]
enum Behave {
    Waypoints(Waypoints),
    Other(Box<dyn Behaviour>),
}

/// What one moving obstacle is, apart from where it is and where it heads.
#[derive(Clone, Debug)]
pub(super) struct Entry {
    pub(super) body: Body,
    motion: Motion,
    /// `appear`: the step it appears in, until it has.
    appears_at: Option<u32>,
    /// Its fixed start overlaps the robot: absent until the robot is clear of it.
    held: bool,
    /// A pedestrian that left the scene at its goal (`on_arrival = "vanish"`).
    gone: bool,
    pub(super) min_gap: f64,
}

impl Entry {
    pub(super) fn present(&self) -> bool {
        self.appears_at.is_none() && !self.held && !self.gone
    }

    /// Whether it moves along its heading this step (present, `linear` or `random_walk`), and
    /// the standard deviation of its turns, rad (0 when it does not turn).
    pub(super) fn walk(&self) -> (bool, f64) {
        match self.motion {
            Motion::Heading { sigma_rad } if self.present() => (true, sigma_rad),
            _ => (false, 0.0),
        }
    }
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
#[error("{table}[{entry}]{}: {message}", field.as_ref().map_or(String::new(), |(f, v)| format!(".{f} = {v}")))]
pub struct MovingError {
    /// `moving` or `crowd`: the kind of entry.
    pub table: &'static str,
    /// The `[[moving]]` (or `[[crowd]]`) entry, from 0.
    pub entry: usize,
    /// The field to blame and its value, when one is.
    pub field: Option<(&'static str, String)>,
    /// What went wrong.
    pub message: String,
}

/// The moving obstacles of one episode.
#[derive(Clone, Debug)]
pub struct Movers {
    entries: Vec<Entry>,
    /// The behaviour of each entry that has one ([`Motion::Behaves`]).
    behaviours: Vec<Option<Behave>>,
    /// The reactive pedestrian of each entry that is one ([`Motion::Reactive`]).
    pedestrians: Vec<Option<pedestrian::Pedestrian>>,
    /// Their planning, when there are some.
    crowd: Option<pedestrian::Crowd>,
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

/// A robot as moving obstacles see it: a disc (and its heading, which turns a footprint other
/// than a disc for the lasers of a team's other robots).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Disc {
    /// Its centre.
    pub at: Point,
    /// Its radius, px.
    pub radius: f64,
    /// Its heading, degrees.
    pub z_deg: f64,
}

impl Disc {
    /// The disc of `radius` at `at`.
    pub fn new(at: Point, radius: f64) -> Self {
        Self::facing(at, radius, 0.0)
    }

    /// The disc of `radius` at `at`, heading `z_deg`.
    pub fn facing(at: Point, radius: f64, z_deg: f64) -> Self {
        Self { at, radius, z_deg }
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
        let mut behaviours = Vec::new();
        let mut pedestrians = Vec::new();
        let robot_goals: Vec<(Disc, Point)> =
            robots.iter().copied().zip(goals.iter().copied()).collect();
        // Pattern pedestrians placed so far: starts and goals, with their radii.
        let mut taken: Vec<(Point, f64)> = Vec::new();
        // Each obstacle turns by draws of its own stream, keyed by the episode's walk stream:
        // the turns are drawn side by side, and take nothing from the moving-obstacle stream.
        let mut state = State::keyed(stream(seed, Stream::Walk).random());
        let mut reach: f64 = 0.0;
        for (entry, m) in config.moving.iter().enumerate() {
            // Entries past the file's own `[[moving]]` ones are its crowds.
            let own = config.as_sim_config().moving.len();
            let (table, index) = match entry.checked_sub(own) {
                Some(k) => ("crowd", k),
                None => ("moving", entry),
            };
            let err = |message: String| MovingError {
                table,
                entry: index,
                field: None,
                message,
            };
            let body = match m.shape {
                MovingShape::Disc => Body::Disc(m.radius_px),
                MovingShape::Box => Body::Box(Vector::new(m.size_px[0], m.size_px[1]) / 2.0),
            };
            // A pedestrian moves at most its largest speed; every other obstacle at its speed.
            let speed = if m.motion.is_reactive() {
                m.max_speed_px.unwrap_or(m.speed_px).max(m.speed_px)
            } else {
                m.speed_px
            };
            reach = reach.max(body.bounding_radius() + speed);
            for _ in 0..m.count {
                let (e, behaviour, position, dir) = if m.motion.is_reactive() {
                    let (start, goal) =
                        pedestrian::place(m, body, scene, &robot_goals, &taken, &mut rng)
                            .ok_or_else(|| MovingError {
                                table,
                                entry: index,
                                field: pedestrian::pattern_field(m),
                                message: pedestrian::unplaced(m, scene),
                            })?;
                    taken.extend([
                        (start, body.bounding_radius()),
                        (goal, body.bounding_radius()),
                    ]);
                    pedestrians.push(Some(pedestrian::Pedestrian::new(m, goal)));
                    let held = robots.iter().any(|r| body.gap(start, r.at, r.radius) < 0.0);
                    let e = Entry {
                        body,
                        motion: Motion::Reactive,
                        appears_at: None,
                        held,
                        gone: false,
                        min_gap: m.min_robot_distance_px,
                    };
                    (e, None, start, Vector::new(1.0, 0.0))
                } else {
                    pedestrians.push(None);
                    Self::make(m, body, scene, robots, goals, &mut rng).map_err(err)?
                };
                let near = speed + body.bounding_radius() + robot_radius;
                state.push(&e, position, dir, speed, near);
                entries.push(e);
                behaviours.push(behaviour);
            }
        }
        state.sort_keys();
        let waiting = entries.iter().filter(|e| !e.present()).count();
        let crowd = pedestrians
            .iter()
            .any(Option::is_some)
            .then(pedestrian::Crowd::default);
        Ok(Some(Self {
            entries,
            behaviours,
            pedestrians,
            crowd,
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
    ) -> Result<(Entry, Option<Behave>, Point, Vector), String> {
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
        let mut behaviour = None;
        let motion = match kind {
            // Pedestrians are made by `pedestrian::place`, never here.
            MotionKind::Still | MotionKind::Appear | MotionKind::Orca | MotionKind::SocialForce => {
                Motion::Still
            }
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
            MotionKind::Waypoints => {
                let points = m.points.iter().map(|p| Point::new(p[0], p[1])).collect();
                let first = if m.start.is_some() { 0 } else { 1 };
                behaviour = Some(Behave::Waypoints(Waypoints::new(points, first, m.mode)));
                Motion::Behaves
            }
        };
        let entry = Entry {
            body,
            motion,
            appears_at,
            held,
            gone: false,
            min_gap: m.min_robot_distance_px,
        };
        Ok((entry, behaviour, position, dir))
    }

    /// Gives obstacle `index` (in entry order) a behaviour of one's own in place of the motion
    /// its entry configured (a motion no configuration names, a library user's): from the next
    /// step it goes where `behaviour` says, under the same contact rules.
    /// Returns `false`, changing nothing, when there is no obstacle `index`.
    pub fn set_behaviour(&mut self, index: usize, behaviour: Box<dyn Behaviour>) -> bool {
        let Some(e) = self.entries.get_mut(index) else {
            return false;
        };
        e.motion = Motion::Behaves;
        (self.state.walks[index], self.state.sigma[index]) = e.walk();
        self.behaviours[index] = Some(Behave::Other(behaviour));
        true
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
    /// In three passes: appearances and releases, then the turns (each obstacle's from its own
    /// stream) and moves of all headings at once (vectorised, with a free box per obstacle
    /// answering most clearance questions); what the free box cannot answer, waypoints and the
    /// contact with the robot are settled one by one.
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
        // A behaviour asks for its neighbours during the moves: an obstacle that just appeared
        // must be where the order says (the order is brought up to date again at the end).
        if appeared && self.behaviours.iter().any(Option::is_some) {
            state.sort_keys();
        }
        if let Some(crowd) = &mut self.crowd {
            let near = Neighbours {
                state,
                entries: &self.entries,
                robots,
            };
            crowd.plan(&near, &mut self.pedestrians, scene, &mut self.rng);
            for &i in crowd.vanished() {
                self.entries[i].gone = true;
            }
        }
        state.turn_and_look_ahead(&self.centres);
        for (i, e) in self.entries.iter().enumerate() {
            if state.moved[i] || !e.present() {
                continue;
            }
            let from = state.position(i);
            let speed = state.speed[i];
            let to = match e.motion {
                Motion::Still => continue,
                Motion::Reactive => match &self.pedestrians[i] {
                    // ORCA keeps it off the still scene, but not always exactly (its linear
                    // program can fail on an obstacle's half-plane): a move into a wall is not
                    // made.
                    Some(p) if p.next != Vector::zeros() => {
                        let to = from + p.next;
                        if !e.body.sweep_clear(scene, from, to) {
                            continue;
                        }
                        to
                    }
                    _ => continue,
                },
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
                Motion::Behaves => {
                    let Some(behaviour) = self.behaviours[i].as_mut() else {
                        continue;
                    };
                    let me = Agent {
                        index: i,
                        position: from,
                        body: e.body,
                        speed_px: speed,
                    };
                    let near = Neighbours {
                        state,
                        entries: &self.entries,
                        robots,
                    };
                    let to = match behaviour {
                        Behave::Waypoints(w) => w.next(&me, &near, scene, &mut self.rng),
                        Behave::Other(b) => b.next(&me, &near, scene, &mut self.rng),
                    };
                    match to {
                        // No behaviour moves further than its speed: scans rely on it.
                        Some(to) if (to - from).norm() > speed => {
                            from + (to - from) * (speed / (to - from).norm())
                        }
                        Some(to) => to,
                        None => continue,
                    }
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
        // More obstacles in range than the list holds (a long or crowded laser): every present
        // one in range, gathered again.
        let all: Vec<u32>;
        let list = if overflow {
            let mut within = Vec::new();
            st.near(position, slab, |i| {
                let (px, py) = (st.x[i] - position.x, st.y[i] - position.y);
                let d = (px * px + py * py).sqrt();
                if self.entries[i].present() && d - st.bound[i] <= range {
                    within.push(i as u32);
                }
            });
            all = within;
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
        // Many, or boxes: each obstacle asked only by the beams whose direction passes within
        // its bounding circle (the same least hit per beam as asking every beam of every one).
        let targets: Vec<(Point, f64)> = list
            .iter()
            .map(|&i| (st.position(i as usize), st.bound[i as usize]))
            .collect();
        laser.refine_round_toward(position, heading, out, &targets, |j, origin, dir, best| {
            let i = list[j] as usize;
            self.entries[i].body.ray(targets[j].0, origin, dir, best)
        });
        least_gap
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

    /// Heads for the first robot at full speed.
    #[derive(Clone, Debug)]
    struct Chase;

    impl Behaviour for Chase {
        fn next(
            &mut self,
            me: &Agent,
            near: &Neighbours<'_>,
            _: &Scene,
            _: &mut Rng,
        ) -> Option<Point> {
            let robot = near.robots().first()?;
            let d = robot.at - me.position;
            Some(me.position + d * (me.speed_px / d.norm()).min(1.0))
        }

        fn boxed_clone(&self) -> Box<dyn Behaviour> {
            Box::new(self.clone())
        }
    }

    #[test]
    fn a_behaviour_of_ones_own_moves_its_obstacle_under_the_contact_rules() {
        let config = crate::SimConfig {
            moving: vec![MovingConfig {
                count: 6,
                motion: MotionKind::Still,
                speed_px: 3.0,
                ..Default::default()
            }],
            ..Default::default()
        }
        .validate()
        .expect("valid");
        let scene = Scene::from_boxes(400.0, 400.0, Vec::new(), config.reach_px());
        let robot = Point::new(200.0, 200.0);
        let mut movers = Movers::new(&config, &scene, robot, Point::new(20.0, 20.0), 5)
            .expect("places")
            .expect("has movers");
        assert!(movers.set_behaviour(0, Box::new(Chase)));
        assert!(!movers.clone().set_behaviour(6, Box::new(Chase)));
        let start = movers.items().next().expect("six").position();
        let still: Vec<Point> = movers.items().skip(1).map(|m| m.position()).collect();
        let radius = config.robot.radius_px;
        let (mut touched, mut closest) = (0, f64::INFINITY);
        for step in 1..=400 {
            touched += usize::from(movers.advance(step, &scene, robot).touched_robot);
            let at = movers.items().next().expect("six").position();
            let gap = Body::Disc(8.0).gap(at, robot, radius);
            assert!(
                gap >= 0.0,
                "step {step}: the chaser overlaps the robot at {at}"
            );
            closest = closest.min(gap);
        }
        // It came to the robot, was then held off it, and the still ones stayed put.
        assert!((start - robot).norm() > 20.0);
        assert!(closest < 3.0, "closest gap {closest}");
        assert!(touched > 300, "touched {touched} times");
        let now: Vec<Point> = movers.items().skip(1).map(|m| m.position()).collect();
        assert_eq!(still, now);
        // A clone carries the behaviour on.
        let mut copy = movers.clone();
        assert!(copy.advance(401, &scene, robot).touched_robot);
    }

    #[test]
    fn neighbours_are_the_present_obstacles_within_the_distance() {
        let config = crate::SimConfig {
            moving: vec![MovingConfig {
                count: 200,
                speed_px: 4.0,
                ..Default::default()
            }],
            ..Default::default()
        }
        .validate()
        .expect("valid");
        let scene = maze_scene(&config, 2);
        let robot = Point::new(150.0, 150.0);
        let mut movers = Movers::new(&config, &scene, robot, Point::new(850.0, 850.0), 2)
            .expect("places")
            .expect("has movers");
        let mut found = 0;
        for step in 1..=30 {
            movers.advance(step, &scene, robot);
            let near = Neighbours {
                state: &movers.state,
                entries: &movers.entries,
                robots: &[],
            };
            for (p, d) in [
                (robot, 120.0),
                (Point::new(500.0, 500.0), 60.0),
                (robot, 0.0),
            ] {
                let mut got = Vec::new();
                near.obstacles_within(p, d, |i, at, _| got.push((i, at)));
                got.sort_by_key(|&(i, _)| i);
                let want: Vec<(usize, Point)> = movers
                    .items()
                    .enumerate()
                    .filter(|(_, m)| m.present() && (m.position() - p).norm() <= d)
                    .map(|(i, m)| (i, m.position()))
                    .collect();
                assert_eq!(got, want, "step {step} at {p} within {d}");
                found += got.len();
            }
        }
        assert!(found > 30, "found only {found}");
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
}
