//! Several robots in one episode (docs/model.md "Several robots"): each robot an [`Episode`] of its own
//! configuration (radius, speeds, laser), all in one scene among one set of moving obstacles.
//!
//! Each step the moving obstacles move first, then every robot that is still going makes its
//! action at once: each motion is swept against the walls and the moving obstacles, then against
//! the other robots' motions (two moving discs are tested over their simultaneous straight
//! sweeps, a standing one as a point), and robots whose motions would touch stay where they were
//! and count a robot collision; that repeats until no motion touches, so no robot passes through
//! another at any speed. Each laser sees the other robots as discs. A robot that reached its goal
//! stops there and stays an obstacle, or leaves the scene with `on_arrival = "vanish"`. When no
//! robot has moved for `episode.deadlock_steps` steps, the running ones of a team of two or more
//! end as a deadlock. A team of one steps exactly as the lone robot of the same configuration.
//!
//! The first robot's start and goal are drawn as a lone robot's are (the same stream), the
//! others' from a stream of their own, each clear of the robots placed before it.

mod comm;
mod step;

pub use comm::{Broadcast, Inbox, InboxIter};

use crate::config::{OnArrival, TeamConfig, ValidConfig};
use crate::geometry::{point_segment_distance_squared, Point, PointGrid};
use crate::sim::episode::{Episode, Status};
use crate::sim::moving::{Disc, Movers};
use crate::sim::placement::{needs_region_grid, sample_placement_with, EpisodeError};
use crate::sim::rng::{stream, Stream};
use crate::sim::world::World;
use std::sync::Arc;

/// Space kept between two robots' starts (and two robots' goals), beyond their radii, px.
pub const PLACEMENT_GAP_PX: f64 = 2.0;

/// Side of the cells of the grids that find the robots near a robot, px.
const NEAR_CELL_PX: f64 = 64.0;

/// Several robots in one scene.
#[derive(Clone, Debug)]
pub struct Team {
    robots: Vec<Episode>,
    on_arrival: Vec<OnArrival>,
    movers: Option<Box<Movers>>,
    steps: u32,
    /// Steps since a robot last moved.
    still_for: u32,
    deadlock_steps: u32,
    /// Step at which each robot reached its goal.
    arrived_at: Vec<Option<u32>>,
    /// The previous step's reward of each robot.
    rewards: Vec<f64>,
    /// Whether each robot collided in the previous step.
    collided: Vec<bool>,
    touched: Vec<usize>,
    /// Robots whose policies gave up.
    retired: Vec<bool>,
    /// Each robot's goals as drawn or listed (before any reordering).
    goal_lists: Vec<Vec<Point>>,
    /// How the robots talk.
    comm: TeamConfig,
    /// Each robot's message for the next broadcast.
    outbox: Vec<Vec<f32>>,
    /// The last step's broadcasts, in robot order...
    sent: Vec<Broadcast>,
    /// ... and what each robot received of them, nearest sender first: robot `k`'s are the
    /// places in `sent` at `inbox[inbox_starts[k]..inbox_starts[k + 1]]` (places rather than
    /// copies: a thousand robots hear some ten thousand broadcasts a step).
    inbox: Vec<u32>,
    inbox_starts: Vec<u32>,
    /// The robots in the scene by where they were before the step (motions, messages)...
    grid_before: PointGrid,
    /// ... and where they are after it (sensing).
    grid_after: PointGrid,
    /// The largest robot radius, px.
    max_radius: f64,
    /// A step's buffers (`None` only while a step uses them).
    scratch: Option<Box<step::Scratch>>,
    /// Whether this is a lone robot's team of one, its episode whole ([`Team::lone_mut`]).
    lone: bool,
}

/// Whether discs of radii summing to `reach`, moving at once from `a0` to `a1` and from `b0` to
/// `b1` in straight lines over the same step, come closer than `reach`.
fn sweeps_touch(a0: Point, a1: Point, b0: Point, b1: Point, reach: f64) -> bool {
    // In the frame of b, a moves from a0 - b0 to a1 - b1: the distance of that segment from
    // the origin.
    let from = Point::origin() + (a0 - b0);
    let to = Point::origin() + (a1 - b1);
    point_segment_distance_squared(Point::origin(), from, to) < reach * reach
}

/// `config` with its fixed start and goal moved by up to `jitter_px` in x and y (uniform draws
/// from `rng`: the start's, then the goal's, drawn again until the robot's disc is clear of
/// the still scene at both, up to [`JITTER_TRIES`] times); `None` without jitter.
fn jittered(
    config: &ValidConfig,
    scene: &crate::scene::Scene,
    jitter_px: f64,
    rng: &mut crate::sim::rng::Rng,
) -> Result<Option<ValidConfig>, EpisodeError> {
    use rand::Rng as _;
    if jitter_px <= 0.0 {
        return Ok(None);
    }
    let radius = config.robot.radius_px;
    for _ in 0..JITTER_TRIES {
        let mut c = config.as_sim_config().clone();
        let mut draw = || rng.random_range(-jitter_px..=jitter_px);
        let mut clear = true;
        if let Some(s) = &mut c.episode.start {
            s[0] += draw();
            s[1] += draw();
            clear &= scene.disc_clear(Point::new(s[0], s[1]), radius);
        }
        if let Some(g) = &mut c.episode.goal {
            g[0] += draw();
            g[1] += draw();
            clear &= scene.disc_clear(Point::new(g[0], g[1]), radius);
        }
        if clear {
            return c
                .validate()
                .map(Some)
                .map_err(|e| EpisodeError::Moving(e.to_string()));
        }
    }
    Err(EpisodeError::Moving(format!(
        "no start and goal within jitter_px = {jitter_px} of the fixed ones is clear of the \
         scene in {JITTER_TRIES} draws"
    )))
}

/// Draws of a jittered start and goal before giving up.
const JITTER_TRIES: usize = 100;

impl Team {
    /// The team `config.robots` describes for episode `seed`: robot `k` in `worlds[e]`, where
    /// `e` is its `[[robots]]` entry (each world holds the entry's configuration and the shared
    /// scene). A configuration without `[[robots]]` makes its lone robot's team of one in its
    /// one world (`worlds[0]`): the lone robot's episode whole, its moving obstacles in it, which
    /// steps only when its robot acts ([`Team::step`]).
    pub fn new(
        config: &ValidConfig,
        worlds: &[Arc<World>],
        seed: u64,
    ) -> Result<Self, EpisodeError> {
        if config.robots.is_empty() {
            let world = worlds.first().ok_or(EpisodeError::Moving(
                "a lone robot's team of one needs its world".into(),
            ))?;
            return Ok(Self::of_one(config, world.episode(seed)?));
        }
        let entries = &config.robots;
        let n = entries.iter().map(|e| e.count as usize).sum();
        let mut robots: Vec<Episode> = Vec::with_capacity(n);
        let mut on_arrival = Vec::with_capacity(n);
        let mut others = stream(seed, Stream::Team);
        let mut jitter = stream(seed, Stream::Jitter);
        let mut taken: Vec<(Point, Point, f64)> = Vec::new();
        let mut goal_lists: Vec<Vec<Point>> = Vec::with_capacity(n);
        let mut k = 0;
        for (e, entry) in entries.iter().enumerate() {
            let world = &worlds[e];
            let scene = world.scene();
            let radius = world.config().robot.radius_px;
            for _ in 0..entry.count {
                let jittered = jittered(world.config(), scene, entry.jitter_px, &mut jitter)?;
                let cfg = jittered.as_ref().unwrap_or(world.config());
                let both_fixed = cfg.start_and_goal_fixed();
                let grid = (!both_fixed && needs_region_grid(cfg, scene)).then(|| world.grid());
                // A fixed start is not drawn, so nothing else keeps it apart from the others.
                if let Some([x, y, _]) = cfg.episode.start {
                    let p = Point::new(x, y);
                    let hit = taken
                        .iter()
                        .enumerate()
                        .find(|&(_, &(q, _, r))| (p - q).norm() < radius + r + PLACEMENT_GAP_PX);
                    if let Some((j, &(q, _, r))) = hit {
                        return Err(EpisodeError::Moving(format!(
                            "robot {k}'s start ({x}, {y}) is {:.1} px from robot {j}'s, whose \
                             centres must be {} px apart (both radii and a {PLACEMENT_GAP_PX} px \
                             gap): overlapping robots cannot start",
                            (p - q).norm(),
                            radius + r + PLACEMENT_GAP_PX
                        )));
                    }
                }
                let clear = |start: Point, goal: Point| {
                    taken.iter().all(|&(s, g, r)| {
                        let gap = radius + r + PLACEMENT_GAP_PX;
                        (start - s).norm() >= gap && (goal - g).norm() >= gap
                    })
                };
                // A start or goal a crowd's pattern puts down is the pattern's (a team of one's);
                // a fixed one is the entry's, or `[episode]`'s for a lone robot's team of one
                // (an entry that fixes none): name them so.
                let fixes =
                    entry.start.is_some() || entry.goal.is_some() || !entry.goals.is_empty();
                let of_entry = |err: EpisodeError| {
                    let err = err.of_config(cfg, scene);
                    if fixes {
                        err.of_entry(e)
                    } else {
                        err
                    }
                };
                let placement = if k == 0 {
                    let mut first = stream(seed, Stream::Placement);
                    sample_placement_with(cfg, scene, grid, seed, &mut first, clear)
                } else {
                    sample_placement_with(cfg, scene, grid, seed, &mut others, clear)
                }
                .map_err(|err| match err {
                    // The scene had room for one robot (robot 0 was placed): the team is crowded.
                    EpisodeError::NoPlacement { .. } if k > 0 => EpisodeError::Crowded {
                        robot: k,
                        robots: config.team_size(),
                    },
                    err => of_entry(err),
                })?;
                let mut robot = Episode::placed(cfg, scene.clone(), seed, placement, false)
                    .map_err(of_entry)?;
                let goals: Vec<Point> = if !entry.goals.is_empty() {
                    entry.goals.iter().map(|g| Point::new(g[0], g[1])).collect()
                } else if entry.goal_count <= 1 {
                    vec![placement.goal]
                } else {
                    let mut goals = vec![placement.goal];
                    let tolerance = cfg.episode.goal_tolerance_px;
                    let mut fixed = cfg.as_sim_config().clone();
                    let s = placement.start;
                    fixed.episode.start = Some([s.x, s.y, s.z_deg]);
                    fixed.episode.goal = None;
                    let fixed = fixed
                        .validate()
                        .map_err(|e| EpisodeError::Moving(e.to_string()))?;
                    for _ in 1..entry.goal_count {
                        let apart = |_: Point, g: Point| {
                            goals.iter().all(|q| (g - q).norm() >= 2.0 * tolerance)
                                && taken.iter().all(|&(_, q, r)| {
                                    (g - q).norm() >= radius + r + PLACEMENT_GAP_PX
                                })
                        };
                        let p =
                            sample_placement_with(&fixed, scene, grid, seed, &mut others, apart)?;
                        goals.push(p.goal);
                    }
                    goals
                };
                if goals.len() > 1 {
                    robot.set_goals(&goals);
                }
                taken.push((placement.start.position(), placement.goal, radius));
                goal_lists.push(goals);
                robots.push(robot);
                on_arrival.push(entry.on_arrival);
                k += 1;
            }
        }
        let discs: Vec<Disc> = robots.iter().map(disc).collect();
        let goals: Vec<Point> = robots.iter().map(|r| r.goal()).collect();
        let scene = worlds
            .first()
            .map(|w| w.scene().clone())
            .ok_or(EpisodeError::Moving(
                "a team needs at least one robot".into(),
            ))?;
        let movers = Movers::among(config, &scene, &discs, &goals, seed)
            .map_err(|e| EpisodeError::Moving(e.to_string()))?
            .map(Box::new);
        let mut team = Self::assemble(config, robots, on_arrival, goal_lists, movers);
        let among = team.movers.is_some();
        for (k, r) in team.robots.iter_mut().enumerate() {
            r.set_among_movers(among);
            // Each robot's laser noise from its own stream, fresh for its first sensing among
            // the team below (its placement sensed alone): robot 0's is a lone robot's.
            r.set_noise_streams(seed, k);
        }
        team.sense_all();
        // Their first frames are those sensed among the team: with a history, every past
        // frame is the first.
        for r in &mut team.robots {
            r.fill_history();
        }
        Ok(team)
    }

    /// The team of one of a lone robot's `episode` under `config`: the episode whole, its moving
    /// obstacles in it, stepping as it steps alone ([`Team::lone_mut`]).
    fn of_one(config: &ValidConfig, episode: Episode) -> Self {
        let goals = vec![vec![episode.goal()]];
        Self {
            lone: true,
            ..Self::assemble(config, vec![episode], vec![OnArrival::Stay], goals, None)
        }
    }

    /// The team of `robots` placed, before its first step.
    fn assemble(
        config: &ValidConfig,
        robots: Vec<Episode>,
        on_arrival: Vec<OnArrival>,
        goal_lists: Vec<Vec<Point>>,
        movers: Option<Box<Movers>>,
    ) -> Self {
        let n = robots.len();
        let (width, height) = robots
            .first()
            .map_or((0.0, 0.0), |r| (r.scene().width(), r.scene().height()));
        Self {
            arrived_at: robots
                .iter()
                .map(|r| (r.status() == Status::Success).then_some(0))
                .collect(),
            rewards: vec![0.0; n],
            collided: vec![false; n],
            retired: vec![false; n],
            goal_lists,
            comm: config.team.clone(),
            outbox: vec![vec![0.0; config.team.message_size as usize]; n],
            sent: Vec::new(),
            inbox: Vec::new(),
            inbox_starts: vec![0; n + 1],
            max_radius: robots
                .iter()
                .map(|r| r.config().robot.radius_px)
                .fold(0.0, f64::max),
            robots,
            on_arrival,
            movers,
            steps: 0,
            still_for: 0,
            deadlock_steps: config.episode.deadlock_steps,
            touched: Vec::new(),
            grid_before: PointGrid::new(width, height, NEAR_CELL_PX),
            grid_after: PointGrid::new(width, height, NEAR_CELL_PX),
            scratch: None,
            lone: false,
        }
    }

    /// The episode of a lone robot's team of one (made from a configuration without
    /// `[[robots]]`), which holds all of it, its moving obstacles too, so that it may be moved by
    /// other means (re-posing in data collection); `None` for any other team.
    pub fn lone_mut(&mut self) -> Option<&mut Episode> {
        self.robots.first_mut().filter(|_| self.lone)
    }

    /// The robots, in `[[robots]]` order.
    pub fn robots(&self) -> &[Episode] {
        &self.robots
    }

    /// Robot `k`.
    pub fn robot(&self, k: usize) -> &Episode {
        &self.robots[k]
    }

    /// The moving obstacles, when there are some.
    pub fn movers(&self) -> Option<&Movers> {
        // A lone robot's team of one leaves them in its episode.
        if self.lone {
            self.robots[0].movers()
        } else {
            self.movers.as_deref()
        }
    }

    /// Steps taken.
    pub fn steps(&self) -> u32 {
        self.steps
    }

    /// Each robot's reward in the last step (0 for a robot that did not act).
    pub fn rewards(&self) -> &[f64] {
        &self.rewards
    }

    /// Whether robot `k` collided (with a wall, an obstacle or a robot) in the last step.
    pub fn collided(&self, k: usize) -> bool {
        self.collided.get(k).copied().unwrap_or(false)
    }

    /// The step at which robot `k` reached its goal.
    pub fn arrived_at(&self, k: usize) -> Option<u32> {
        self.arrived_at[k]
    }

    /// What robot `k` does on arriving at its last goal.
    pub fn on_arrival(&self, k: usize) -> OnArrival {
        self.on_arrival[k]
    }

    /// Whether robot `k` is in the scene (a robot that vanished on arrival is not).
    pub fn present(&self, k: usize) -> bool {
        !(self.on_arrival[k] == OnArrival::Vanish && self.robots[k].status() == Status::Success)
    }

    /// Whether every robot's episode is over (or its policy gave up).
    pub fn is_done(&self) -> bool {
        (0..self.robots.len()).all(|k| !self.running(k))
    }

    /// Whether the team ended in a deadlock.
    pub fn deadlocked(&self) -> bool {
        self.robots.iter().any(|r| r.status() == Status::Deadlock)
    }

    /// Robot `k`'s goals as drawn or listed (one, or a goal list).
    pub fn goals(&self, k: usize) -> &[Point] {
        &self.goal_lists[k]
    }

    /// Makes robot `k` visit its goals in `order` (indices into [`Team::goals`]); before the
    /// first step only.
    pub fn order_goals(&mut self, k: usize, order: &[usize]) {
        let goals: Vec<Point> = order
            .iter()
            .filter_map(|&i| self.goal_lists[k].get(i).copied())
            .collect();
        if self.steps == 0 && goals.len() == self.goal_lists[k].len() {
            self.robots[k].set_goals(&goals);
        }
    }

    /// Takes robot `k` out of the running (its policy gave up): it acts no more and stays where
    /// it is, an obstacle to the others; its episode keeps its `Running` status.
    pub fn retire(&mut self, k: usize) {
        self.retired[k] = true;
    }

    /// Whether robot `k` was taken out of the running.
    pub fn retired(&self, k: usize) -> bool {
        self.retired[k]
    }

    /// Whether robot `k` still acts.
    pub fn running(&self, k: usize) -> bool {
        !self.retired[k] && self.robots[k].status() == Status::Running
    }
}

/// Into `at`, for each of `n` robots, its place in the list `robots` (of robot indices), if
/// listed: a look-up for lists that leave some robots out (those no longer in the scene).
fn places_into(at: &mut Vec<Option<u32>>, robots: impl Iterator<Item = usize>, n: usize) {
    at.clear();
    at.resize(n, None);
    for (m, k) in robots.enumerate() {
        at[k] = Some(m as u32);
    }
}

/// Robot `r` as a disc.
fn disc(r: &Episode) -> Disc {
    Disc::facing(
        r.pose().position(),
        r.config().robot.radius_px,
        r.pose().z_deg,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::{TeamConfig, TeamRobotConfig};
    use crate::geometry::Vector;
    use crate::sim::robot::{Action, DiscreteAction};

    /// The unit vector `v` scaled to `len`.
    fn along(v: Vector, len: f64) -> Vector {
        v.normalize() * len
    }

    #[test]
    fn head_on_sweeps_touch_and_parallel_ones_do_not() {
        let o = Point::origin();
        // Two discs of radius 5 swapping places 8 px apart pass through each other mid-step.
        assert!(sweeps_touch(
            o,
            Point::new(8.0, 0.0),
            Point::new(8.0, 0.0),
            o,
            10.0
        ));
        // Side by side, 12 px apart, moving the same way: never closer than 12.
        let up = along(Vector::new(0.0, 1.0), 50.0);
        assert!(!sweeps_touch(
            o,
            o + up,
            Point::new(12.0, 0.0),
            Point::new(12.0, 0.0) + up,
            10.0
        ));
        // At any speed: 1000 px steps crossing still touch.
        assert!(sweeps_touch(
            Point::new(-500.0, 0.0),
            Point::new(500.0, 0.0),
            Point::new(0.0, -500.0),
            Point::new(0.0, 500.0),
            10.0
        ));
    }

    fn team_config(count: u32) -> ValidConfig {
        let c = crate::SimConfig {
            robots: vec![TeamRobotConfig {
                count,
                ..Default::default()
            }],
            ..Default::default()
        };
        c.validate().expect("valid")
    }

    fn worlds(config: &ValidConfig, seed: u64) -> Vec<Arc<World>> {
        let scene = Arc::new(crate::sim::world::maze_scene(config, seed));
        (0..config.robots.len())
            .map(|e| {
                let k: usize = config.robots[..e].iter().map(|r| r.count as usize).sum();
                Arc::new(World::new(config.team_robot(k), scene.clone()))
            })
            .collect()
    }

    /// A team's robots see each other's footprint: a rectangle's side, not its circumscribed
    /// disc.
    #[test]
    fn a_robot_reads_another_robots_rectangle() {
        let at = |x: f64| TeamRobotConfig {
            count: 1,
            start: Some([x, 150.0, 0.0]),
            goal: Some([x, 850.0]),
            ..Default::default()
        };
        let mut c = crate::SimConfig {
            robots: vec![at(150.0), at(190.0)],
            ..Default::default()
        }
        .open_hall(1000.0);
        c.scene.seed = Some(0);
        c.robot.shape = crate::config::Shape::Rectangle;
        c.robot.length_px = Some(20.0);
        c.robot.width_px = Some(10.0);
        let config = c.validate().expect("valid");
        let team = Team::new(&config, &worlds(&config, 0), 0).expect("placed");
        // Robot 0's middle beam (of 17, straight ahead) meets robot 1's rear side at 40 - 10
        // px; its circumscribed disc would read 40 - 11.18.
        let middle = team.robot(0).readings()[8];
        assert!((middle - 30.0).abs() < 1e-9, "{middle}");
    }

    #[test]
    fn robots_start_apart_and_never_overlap() {
        let config = team_config(8);
        for seed in 0..6 {
            let mut team = Team::new(&config, &worlds(&config, seed), seed).expect("placed");
            let ahead = Some(Action::from(DiscreteAction::Ahead));
            let left = Some(Action::from(DiscreteAction::Left));
            for step in 0..300 {
                let actions: Vec<Option<Action>> = (0..8)
                    .map(|k| if (step + k) % 5 == 0 { left } else { ahead })
                    .collect();
                team.step(&actions);
                let r = team.robots();
                for i in 0..r.len() {
                    for j in i + 1..r.len() {
                        if !(team.present(i) && team.present(j)) {
                            continue;
                        }
                        let d = (r[i].pose().position() - r[j].pose().position()).norm();
                        assert!(d >= 10.0 - 1e-9, "seed {seed} step {step}: {i} {j} at {d}");
                    }
                }
            }
        }
    }

    /// A lone robot's configuration and the same robot as a team of one
    /// ([`ValidConfig::as_team`]: `[[robots]]` with one robot of one entry), with `moving` obstacles, laser noise `sigma` and `history` frames
    /// observed.
    fn lone_and_one(
        moving: Vec<crate::config::MovingConfig>,
        sigma: f64,
        history: u32,
    ) -> (ValidConfig, ValidConfig) {
        lone_and_one_at(moving, sigma, history, None)
    }

    /// [`lone_and_one`] with `[episode]`'s start and goal fixed at `fixed`.
    fn lone_and_one_at(
        moving: Vec<crate::config::MovingConfig>,
        sigma: f64,
        history: u32,
        fixed: Option<([f64; 3], [f64; 2])>,
    ) -> (ValidConfig, ValidConfig) {
        let mut lone = crate::SimConfig {
            moving,
            ..Default::default()
        };
        lone.episode.start = fixed.map(|f| f.0);
        lone.episode.goal = fixed.map(|f| f.1);
        lone.laser.noise_sigma_px = sigma;
        lone.observation.history = history;
        lone.episode.max_steps = 400;
        let lone = lone.validate().expect("valid");
        let one = lone.as_team();
        assert_eq!(one.team_size(), 1);
        assert_eq!(one.as_team(), one);
        (lone, one)
    }

    #[test]
    fn a_team_of_one_steps_as_a_lone_robot_bit_for_bit() {
        use crate::config::{MotionKind, MovingConfig};
        use rand::Rng as _;
        let walkers = MovingConfig {
            count: 25,
            motion: MotionKind::RandomWalk,
            ..Default::default()
        };
        let appearing = MovingConfig {
            count: 10,
            motion: MotionKind::Appear,
            then: MotionKind::Linear,
            from_step: 5,
            to_step: 60,
            ..Default::default()
        };
        let cases = [
            lone_and_one(Vec::new(), 0.0, 1),
            lone_and_one(vec![walkers.clone(), appearing.clone()], 0.0, 1),
            lone_and_one(Vec::new(), 1.5, 1),
            // Frames and actions remembered, with and without the obstacles (whose steps the
            // team makes for its robots).
            lone_and_one(Vec::new(), 0.0, 3),
            lone_and_one(vec![walkers.clone(), appearing], 0.0, 3),
            // Placed by `[episode]`, as the team of one is.
            lone_and_one_at(
                Vec::new(),
                0.0,
                1,
                Some(([150.0, 150.0, 0.0], [450.0, 150.0])),
            ),
            lone_and_one_at(
                vec![walkers],
                0.0,
                1,
                Some(([150.0, 150.0, 90.0], [450.0, 350.0])),
            ),
        ];
        let mut steps = 0;
        for (case, (lone_config, one_config)) in cases.iter().enumerate() {
            for (seed, form) in (0..12).flat_map(|seed| [(seed, 0), (seed, 1)]) {
                let lone_world = Arc::new(World::maze(lone_config.clone(), seed));
                let mut lone = lone_world.episode(seed).expect("placed");
                // The team of one of the lone configuration itself (as the evaluator runs a
                // lone robot), or of its `[[robots]]` form (`as_team`).
                let mut team = if form == 0 {
                    Team::new(lone_config, std::slice::from_ref(&lone_world), seed)
                } else {
                    Team::new(one_config, &worlds(one_config, seed), seed)
                }
                .expect("placed");
                // Mostly ahead, so the robot goes places, meets walls and obstacles.
                let mut rng = crate::sim::rng::stream(seed, crate::sim::rng::Stream::Policy);
                let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                while !lone.status().is_done() {
                    let action = if rng.random_bool(0.6) {
                        Action::from(DiscreteAction::Ahead)
                    } else if rng.random_bool(0.5) {
                        DiscreteAction::Left.into()
                    } else {
                        DiscreteAction::Right.into()
                    };
                    let r = lone.step(action);
                    let (pose, reward, collided, status) = (r.pose, r.reward, r.collided, r.status);
                    team.step(&[Some(action)]);
                    let t = team.robot(0);
                    let at = format!("case {case}/{form}, seed {seed}, step {}", lone.steps());
                    assert_eq!(t.pose(), pose, "{at}");
                    assert_eq!(team.rewards()[0].to_bits(), reward.to_bits(), "{at}");
                    assert_eq!(team.collided(0), collided, "{at}");
                    assert_eq!(t.status(), status, "{at}");
                    assert_eq!(bits(t.readings()), bits(lone.readings()), "{at}");
                    assert_eq!(t.observation(), lone.observation(), "{at}");
                    steps += 1;
                }
                assert!(team.is_done());
                assert_eq!(team.robot(0).collisions(), lone.collisions());
                assert_eq!(team.robot(0).dynamic_metrics(), lone.dynamic_metrics());
                assert_eq!(
                    team.robot(0).path_length_px().to_bits(),
                    lone.path_length_px().to_bits()
                );
                assert_eq!(
                    team.robot(0).total_reward().to_bits(),
                    lone.total_reward().to_bits()
                );
            }
        }
        assert!(steps > 10_000, "only {steps} steps compared");
    }

    /// A lone robot's team of one is its episode whole: its moving obstacles stay in it, and it
    /// steps only when the robot acts (a lone episode has no step without an action).
    #[test]
    fn a_lone_robots_team_of_one_steps_only_when_it_acts() {
        use crate::config::{MotionKind, MovingConfig};
        let config = crate::SimConfig {
            moving: vec![MovingConfig {
                count: 8,
                motion: MotionKind::RandomWalk,
                ..Default::default()
            }],
            ..Default::default()
        }
        .validate()
        .expect("valid");
        let world = Arc::new(World::maze(config.clone(), 2));
        let mut team = Team::new(&config, std::slice::from_ref(&world), 2).expect("placed");
        let lone = world.episode(2).expect("placed");
        let at = |t: &Team| {
            t.movers()
                .map(|m| m.items().map(|o| o.position()).collect::<Vec<_>>())
        };
        let before = at(&team);
        assert!(before.is_some() && team.movers().is_some());
        team.step(&[None]);
        assert_eq!((team.steps(), team.robot(0).steps()), (0, 0));
        assert_eq!(at(&team), before);
        assert_eq!(team.robot(0).pose(), lone.pose());
        team.step(&[Some(DiscreteAction::Ahead.into())]);
        assert_eq!((team.steps(), team.robot(0).steps()), (1, 1));
        assert!(team.lone_mut().is_some());
        let one = config.as_team();
        let mut as_team = Team::new(&one, &worlds(&one, 2), 2).expect("placed");
        assert!(as_team.lone_mut().is_none());
    }

    #[test]
    fn the_first_robot_is_placed_as_a_lone_one() {
        let config = team_config(3);
        let team = Team::new(&config, &worlds(&config, 4), 4).expect("placed");
        let alone = World::maze(ValidConfig::default(), 4)
            .episode(4)
            .expect("placed");
        assert_eq!(team.robot(0).start(), alone.start());
        assert_eq!(team.robot(0).goal(), alone.goal());
    }

    /// Two robots facing each other down an open corridor, driving ahead.
    fn corridor(speed: f64) -> (ValidConfig, Vec<Arc<World>>) {
        let mut c = crate::SimConfig::default();
        let robot = |start: [f64; 3], goal: [f64; 2]| TeamRobotConfig {
            start: Some(start),
            goal: Some(goal),
            move_speed_px: Some(speed),
            ..Default::default()
        };
        c.robots = vec![
            robot([50.0, 50.0, 0.0], [350.0, 50.0]),
            robot([350.0, 50.0, 180.0], [50.0, 50.0]),
        ];
        c.episode.deadlock_steps = 10;
        let config = c.validate().expect("valid");
        let scene = Arc::new(crate::Scene::from_boxes(400.0, 100.0, Vec::new(), 50.0));
        let worlds = (0..2)
            .map(|k| Arc::new(World::new(config.team_robot(k), scene.clone())))
            .collect();
        (config, worlds)
    }

    #[test]
    fn head_on_robots_block_each_other_at_any_speed_and_deadlock() {
        for speed in [5.0, 37.0, 1000.0] {
            let (config, worlds) = corridor(speed);
            let mut team = Team::new(&config, &worlds, 0).expect("placed");
            let ahead = Some(Action::from(DiscreteAction::Ahead));
            while !team.is_done() {
                let before = [0, 1].map(|k| team.robot(k).pose().position().x);
                team.step(&[ahead, ahead]);
                let after = [0, 1].map(|k| team.robot(k).pose().position().x);
                // Never through each other: the first stays left of the second.
                assert!(after[0] + 10.0 <= after[1] + 1e-9, "{speed}: {after:?}");
                assert!(before[0] <= after[0] && after[1] <= before[1]);
            }
            assert!(team.deadlocked(), "{speed}");
            assert!(team.robot(0).robot_collisions() > 0);
            if speed == 5.0 {
                // Face to face: each one's middle beam reads the other's disc.
                let gap = (team.robot(1).pose().position() - team.robot(0).pose().position())
                    .norm()
                    - 5.0;
                assert!((team.robot(0).readings()[8] - gap).abs() < 1e-9);
                assert!((team.robot(1).readings()[8] - gap).abs() < 1e-9);
            }
            assert_eq!(team.robot(0).status(), Status::Deadlock);
        }
    }

    #[test]
    fn messages_arrive_one_step_late_and_only_within_range() {
        let mut c = crate::SimConfig::default();
        let at = |x: f64| TeamRobotConfig {
            start: Some([x, 50.0, 0.0]),
            goal: Some([x, 80.0]),
            ..Default::default()
        };
        c.robots = vec![at(50.0), at(150.0), at(450.0)];
        c.team = TeamConfig {
            comm_range_px: 150.0,
            message_size: 1,
            neighbours: 2,
        };
        c.episode.min_goal_distance_px = 10.0;
        let config = c.validate().expect("valid");
        assert_eq!(config.observation_size(), 18 + 2 * 5);
        let scene = Arc::new(crate::Scene::from_boxes(500.0, 100.0, Vec::new(), 50.0));
        let worlds: Vec<_> = (0..3)
            .map(|k| Arc::new(World::new(config.team_robot(k), scene.clone())))
            .collect();
        let mut team = Team::new(&config, &worlds, 0).expect("placed");
        assert!((0..3).all(|k| team.inbox(k).is_empty()));
        let turn = Some(Action::from(DiscreteAction::Left));
        team.set_message(0, &[7.0]);
        // Sent with this step's decisions, received after it.
        team.step(&[turn, turn, turn]);
        let b = team.inbox(1);
        assert_eq!(b.len(), 1);
        assert_eq!((b[0].from, b[0].message.as_slice()), (0, &[7.0f32][..]));
        assert_eq!(team.inbox(0).len(), 1);
        assert_eq!(team.inbox(0)[0].message, vec![0.0]);
        assert!(team.inbox(2).is_empty(), "300 px from the nearest");
        // Robot 1, turned 15 degrees left since, sees robot 0 as it sent: 100 px behind where
        // robot 1 stands, heading 15 degrees to the right of it.
        let slots = &team.robot(1).observation()[18..];
        let z = 15f64.to_radians();
        assert!((f64::from(slots[0]) - (-100.0 * z.cos() / 150.0)).abs() < 1e-6);
        assert!((f64::from(slots[1]) - (100.0 * z.sin() / 150.0)).abs() < 1e-6);
        assert!((f64::from(slots[2]) - 345.0 / 360.0).abs() < 1e-6);
        assert_eq!(&slots[3..5], &[1.0, 7.0]);
        assert_eq!(&slots[5..], &[0.0; 5]);
        // A message is sent once: the next step's is zeros unless set again.
        team.step(&[turn, turn, turn]);
        assert_eq!(team.inbox(1)[0].message, vec![0.0]);
        team.set_message(0, &[8.0]);
        team.step(&[turn, turn, turn]);
        assert_eq!(team.inbox(1)[0].message, vec![8.0]);
    }

    #[test]
    fn robots_that_never_move_end_in_a_deadlock() {
        let mut c = crate::SimConfig {
            robots: vec![TeamRobotConfig {
                count: 2,
                ..Default::default()
            }],
            ..Default::default()
        };
        c.episode.deadlock_steps = 7;
        let config = c.validate().expect("valid");
        let mut team = Team::new(&config, &worlds(&config, 1), 1).expect("placed");
        let turn = Some(Action::from(DiscreteAction::Left));
        for _ in 0..20 {
            team.step(&[turn, turn]);
        }
        assert!(team.deadlocked() && team.is_done());
        assert_eq!(team.steps(), 7);
    }
}
