//! Reactive pedestrians (docs/model.md "Crowds that react"): `orca` and `social_force`
//! obstacles, each walking to its goal at `speed_px` among the others (and, with `sees_robots`,
//! the robots) and the still scene, avoiding them by Optimal Reciprocal Collision Avoidance
//! ([`crate::geometry::orca`]) or pushed away from them by the social force model
//! ([`crate::geometry::social_force`]). All choose their velocities at once from where everyone
//! stood after the last step, as RVO2 steps its agents; then each moves under the usual contact
//! rules (a move that would touch a robot, or a wall, is not made). Their starts and goals come
//! from a crowd pattern (`circle`, `square`, `random`), are fixed, or are drawn in free space,
//! all from the obstacles' own random stream.

use super::{free_spot, Body, Disc, Neighbours, SPOT_TRIES};
use crate::config::{AgentOrca, Arrival, Forces, MotionKind, MovingConfig, Pattern};
use crate::geometry::{Agent, Horizon, Point, PointGrid, Vector, V2};
use crate::scene::Scene;
use crate::sim::avoid::{social_force_velocity, Avoid, Avoider};
use crate::sim::rng::Rng;
use rand::Rng as _;
use std::f64::consts::TAU;

/// How a pedestrian chooses its velocity.
#[derive(Clone, Debug)]
enum Model {
    Orca(AgentOrca),
    SocialForce(Forces),
}

/// The least side of the neighbour grid's cells, px.
const MIN_CELL_PX: f64 = 16.0;

/// One reactive pedestrian's goal, settings and chosen velocity.
#[derive(Clone, Debug)]
pub(super) struct Pedestrian {
    goal: Point,
    /// Preferred speed, px per step.
    speed: f64,
    max_speed: f64,
    /// How far a drawn goal keeps from the still scene beyond its body, px.
    goal_keep: f64,
    on_arrival: Arrival,
    sees_robots: bool,
    model: Model,
    /// The velocity chosen for this step.
    pub(super) next: Vector,
}

impl Pedestrian {
    /// How far it looks for other agents, px.
    fn reach(&self) -> f64 {
        match &self.model {
            Model::Orca(o) => o.neighbour_dist_px,
            Model::SocialForce(f) => f.neighbour_dist_px,
        }
    }

    /// Where it heads now.
    pub(super) fn goal(&self) -> Point {
        self.goal
    }

    /// The pedestrian `m` describes, heading for `goal`.
    pub(super) fn new(m: &MovingConfig, goal: Point) -> Self {
        Self {
            goal,
            speed: m.speed_px,
            max_speed: m.max_speed_px.unwrap_or(m.speed_px),
            goal_keep: goal_keep(m),
            on_arrival: m.on_arrival,
            sees_robots: m.sees_robots,
            model: if m.motion == MotionKind::SocialForce {
                Model::SocialForce(m.social_force.clone())
            } else {
                Model::Orca(m.orca.clone())
            },
            next: Vector::zeros(),
        }
    }
}

/// Where a pedestrian of entry `m` (its `body`) starts and heads: by its pattern, fixed, or
/// drawn in free space; a pattern's start and goal keep clear of the robots' starts and goals by
/// `min_robot_distance_px` and of the pedestrians placed before (`taken`: centres and radii,
/// starts and goals). `None` when no such place turned up.
pub(super) fn place(
    m: &MovingConfig,
    body: Body,
    scene: &Scene,
    robots: &[(Disc, Point)],
    taken: &[(Point, f64)],
    rng: &mut Rng,
) -> Option<(Point, Point)> {
    let r = body.bounding_radius();
    let center = pattern_center(m, scene);
    let clear_of_all = |p: Point| {
        robots.iter().all(|(d, goal)| {
            body.gap(p, d.at, d.radius) >= m.min_robot_distance_px
                && body.gap(p, *goal, d.radius) >= m.min_robot_distance_px
        }) && taken
            .iter()
            .all(|&(q, rq)| (p - q).norm() >= r + rq + PLACEMENT_GAP_PX)
    };
    let circle = match m.pattern {
        Some(Pattern::Circle) => true,
        Some(Pattern::Square) => false,
        None | Some(Pattern::Random) => {
            let start = match m.start {
                Some(s) => Point::new(s[0], s[1]),
                None => free_spot(body, scene, rng, clear_of_all)?,
            };
            let keep = goal_keep(m);
            let goal = match m.goal {
                Some(g) => Point::new(g[0], g[1]),
                None => free_spot(body, scene, rng, |p| {
                    clear_of_all(p) && keeps_off(scene, p, r, keep)
                })?,
            };
            return Some((start, goal));
        }
    };
    let radius = m.pattern_radius_px;
    let j = m.jitter_px;
    for _ in 0..SPOT_TRIES {
        let (start, goal) = if circle {
            let a = rng.random_range(0.0..TAU);
            let u = Vector::new(a.cos(), a.sin()) * radius;
            (center + u, center - u)
        } else {
            let side = if rng.random_bool(0.5) { 1.0 } else { -1.0 };
            let from = rng.random_range(-radius..=radius);
            let to = rng.random_range(-radius..=radius);
            (
                center + Vector::new(side * radius, from),
                center + Vector::new(-side * radius, to),
            )
        };
        let mut jitter = || {
            if j > 0.0 {
                Vector::new(rng.random_range(-j..=j), rng.random_range(-j..=j))
            } else {
                Vector::zeros()
            }
        };
        let (start, goal) = (start + jitter(), goal + jitter());
        if clear_of_all(start)
            && clear_of_all(goal)
            && body.clear_at(scene, start)
            && body.clear_at(scene, goal)
        {
            return Some((start, goal));
        }
    }
    None
}

/// How far a drawn goal keeps from the still scene beyond the pedestrian's body, px: a social
/// force walker is held off walls by their push (about four decay lengths against its drive),
/// so a goal nearer than that could never be reached; an ORCA walker needs no gap.
fn goal_keep(m: &MovingConfig) -> f64 {
    if m.motion == MotionKind::SocialForce {
        4.0 * m.social_force.obstacle_range_px
    } else {
        0.0
    }
}

/// Whether a body of bounding radius `r` at `p` keeps `keep` px from the still scene.
fn keeps_off(scene: &Scene, p: Point, r: f64, keep: f64) -> bool {
    keep <= 0.0 || scene.clearance(p, r + keep).is_none()
}

/// The field to blame when no pedestrian of entry `m` could be placed: its pattern's size.
pub(super) fn pattern_field(m: &MovingConfig) -> Option<(&'static str, String)> {
    matches!(m.pattern, Some(Pattern::Circle | Pattern::Square))
        .then(|| ("pattern_radius_px", format!("{:?}", m.pattern_radius_px)))
}

/// The centre of entry `m`'s crowd pattern: `pattern_center`, else the centre of `scene`.
fn pattern_center(m: &MovingConfig, scene: &Scene) -> Point {
    m.pattern_center
        .map_or(Point::new(scene.width() / 2.0, scene.height() / 2.0), |c| {
            Point::new(c[0], c[1])
        })
}

/// Why no pedestrian of entry `m` could be placed in `scene`.
pub(super) fn unplaced(m: &MovingConfig, scene: &Scene) -> String {
    let clear = format!(
        "at least {} px from the robots' starts and goals and clear of the other pedestrians'",
        m.min_robot_distance_px
    );
    let c = pattern_center(m, scene);
    let (cx, cy) = (c.x, c.y);
    let (w, h) = (scene.width(), scene.height());
    match m.pattern {
        Some(p @ (Pattern::Circle | Pattern::Square)) => {
            let shape = if p == Pattern::Circle {
                "a circle of that radius"
            } else {
                "a square of that half side"
            };
            format!(
                "{shape} round ({cx}, {cy}) gives no free start and goal in the {w} x {h} px \
                 scene {clear}"
            )
        }
        _ => format!("found no free start and goal in the {w} x {h} px scene {clear}"),
    }
}

/// Least gap between two pedestrians placed by a pattern, px.
const PLACEMENT_GAP_PX: f64 = 2.0;

/// What the pedestrians' planning keeps between steps: where everyone was after the last step
/// (their velocities are the displacements since), and scratch space.
#[derive(Clone, Debug, Default)]
pub(super) struct Crowd {
    last: Vec<Option<Point>>,
    last_robots: Vec<Point>,
    agents: Vec<Agent<f64>>,
    /// The obstacle each agent is (`None`: a robot).
    owners: Vec<Option<usize>>,
    avoider: Avoider,
    /// The pedestrian agents binned by position, for their neighbours.
    grid: Option<PointGrid>,
    /// The agents near the one planning (scratch).
    near: Vec<u32>,
    /// The entries of the pedestrians that vanished at their goals in the last planning.
    vanished: Vec<usize>,
}

impl Crowd {
    /// The entries of the pedestrians that vanished at their goals in the last
    /// [`Crowd::plan`].
    pub(super) fn vanished(&self) -> &[usize] {
        &self.vanished
    }

    /// Chooses this step's velocity of every present pedestrian (`pedestrians[i]` of entry `i`)
    /// from where everyone stands (`near`: the obstacles and the robots); a pedestrian at its
    /// goal stays, vanishes (listed in [`Crowd::vanished`], for its entry to be gone) or draws a
    /// new goal from `rng`.
    pub(super) fn plan(
        &mut self,
        near: &Neighbours,
        pedestrians: &mut [Option<Pedestrian>],
        scene: &Scene,
        rng: &mut Rng,
    ) {
        let Neighbours {
            state,
            entries,
            robots,
        } = *near;
        self.vanished.clear();
        self.last.resize(entries.len(), None);
        self.agents.clear();
        self.owners.clear();
        // Velocities are the displacements since the last planning (a step ago).
        for (i, e) in entries.iter().enumerate() {
            let now = e.present().then(|| state.position(i));
            let last = std::mem::replace(&mut self.last[i], now);
            if let Some(at) = now {
                let velocity = last.map_or(Vector::zeros(), |l| at - l);
                self.agents.push(Agent {
                    position: V2::from(at),
                    velocity: V2::from(velocity),
                    radius: e.body.bounding_radius(),
                });
                self.owners.push(Some(i));
            }
        }
        let pedestrian_agents = self.agents.len();
        // Each pedestrian's neighbours come from the cells of a grid as wide as the furthest
        // any looks: a superset of those in reach, so every answer is as from all of them.
        let reach = pedestrians
            .iter()
            .flatten()
            .map(Pedestrian::reach)
            .fold(0.0, f64::max);
        let grid = self.grid.get_or_insert_with(|| {
            PointGrid::new(scene.width(), scene.height(), reach.max(MIN_CELL_PX))
        });
        grid.fill(
            self.agents
                .iter()
                .enumerate()
                .map(|(a, g)| (a, Point::new(g.position.x, g.position.y))),
        );
        if pedestrians.iter().flatten().any(|p| p.sees_robots) {
            // Pedestrians move before the robots within a step and a pedestrian's move is
            // checked against a robot where it stands: each robot is avoided both where it will
            // be (an agent moving as it did in its last step) and where it stands (at rest).
            for (k, r) in robots.iter().enumerate() {
                // A robot that vanished shifts the others down: no velocity for that step.
                let velocity = match self.last_robots.get(k) {
                    Some(&l) if self.last_robots.len() == robots.len() => r.at - l,
                    _ => Vector::zeros(),
                };
                for v in [velocity, Vector::zeros()] {
                    self.agents.push(Agent {
                        position: V2::from(r.at),
                        velocity: V2::from(v),
                        radius: r.radius,
                    });
                    self.owners.push(None);
                }
            }
        }
        self.last_robots.clear();
        self.last_robots.extend(robots.iter().map(|r| r.at));
        for a in 0..pedestrian_agents {
            let Some(i) = self.owners[a] else { continue };
            let Some(p) = pedestrians[i].as_mut() else {
                continue;
            };
            let me = self.agents[a];
            let at = Point::new(me.position.x, me.position.y);
            let to_goal = p.goal - at;
            let preferred = if to_goal.norm() < me.radius {
                match p.on_arrival {
                    Arrival::Stay => Vector::zeros(),
                    Arrival::Vanish => {
                        self.vanished.push(i);
                        p.next = Vector::zeros();
                        continue;
                    }
                    Arrival::NewGoal => {
                        // Away from the robots, as its first goal was.
                        let (body, gap) = (entries[i].body, entries[i].min_gap);
                        let keep = p.goal_keep;
                        let far = |q: Point| {
                            robots.iter().all(|r| body.gap(q, r.at, r.radius) >= gap)
                                && keeps_off(scene, q, body.bounding_radius(), keep)
                        };
                        if let Some(g) = free_spot(body, scene, rng, far) {
                            p.goal = g;
                        }
                        Vector::zeros()
                    }
                }
            } else {
                to_goal * (p.speed.min(to_goal.norm()) / to_goal.norm())
            };
            grid.near_any_order(at, p.reach(), &mut self.near);
            p.next = match &p.model {
                Model::Orca(orca) => {
                    let horizon = Horizon {
                        agents: orca.time_horizon_steps,
                        obstacles: orca.obstacle_time_horizon_steps,
                        max_speed: p.max_speed,
                        time_step: 1.0,
                    };
                    // The robots are agents only to those that see them.
                    let visible = if p.sees_robots {
                        self.near
                            .extend(pedestrian_agents as u32..self.agents.len() as u32);
                        self.agents.len()
                    } else {
                        pedestrian_agents
                    };
                    self.avoider.velocity(
                        scene,
                        &Avoid {
                            agents: &self.agents[..visible],
                            me: a,
                            preferred,
                            horizon,
                            neighbour_dist: orca.neighbour_dist_px,
                            max_neighbours: orca.max_neighbours as usize,
                            margin: orca.safety_margin_px,
                            candidates: Some(&self.near),
                        },
                    )
                }
                Model::SocialForce(forces) => {
                    let agents = &self.agents;
                    let others = self
                        .near
                        .iter()
                        .map(|&b| b as usize)
                        .filter(|&b| b != a)
                        .map(|b| {
                            let o = &agents[b];
                            (Point::new(o.position.x, o.position.y), o.radius)
                        });
                    let robots = robots
                        .iter()
                        .filter(|_| p.sees_robots)
                        .map(|r| (r.at, r.radius));
                    social_force_velocity(
                        forces,
                        &me,
                        preferred,
                        p.max_speed,
                        others.chain(robots),
                        scene,
                    )
                }
            };
        }
    }
}

// Kept here rather than in mod.rs, which is long already: what the player shows of pedestrians.
impl super::Movers {
    /// Each obstacle's goal, when it is a reactive pedestrian (`None` for the others).
    pub fn pedestrian_goals(&self) -> impl Iterator<Item = Option<Point>> + '_ {
        self.pedestrians
            .iter()
            .map(|p| p.as_ref().map(Pedestrian::goal))
            .chain(std::iter::repeat_n(
                None,
                self.entries.len().saturating_sub(self.pedestrians.len()),
            ))
            .take(self.entries.len())
    }
}

#[cfg(test)]
mod tests {
    use crate::config::{MotionKind, MovingConfig, Pattern};
    use crate::sim::episode::Episode;
    use crate::sim::robot::DiscreteAction;
    use crate::sim::world::maze_scene;
    use std::sync::Arc;

    /// An open 400 px hall with `count` ORCA pedestrians crossing a circle of radius 120, the
    /// robot turning on the spot in a corner.
    fn crossing(count: u32, sees_robots: bool) -> crate::SimConfig {
        let mut c = crate::SimConfig::default().open_hall(400.0);
        c.scene.seed = Some(0);
        c.episode.start = Some([20.0, 20.0, 0.0]);
        c.episode.goal = Some([380.0, 380.0]);
        c.moving = vec![MovingConfig {
            count,
            radius_px: 6.0,
            motion: MotionKind::Orca,
            speed_px: 4.0,
            pattern: Some(Pattern::Circle),
            pattern_radius_px: 120.0,
            jitter_px: 2.0,
            sees_robots,
            ..Default::default()
        }];
        c
    }

    fn episode(c: &crate::SimConfig, seed: u64) -> Episode {
        let c = c.clone().validate().expect("valid");
        let scene = Arc::new(maze_scene(&c, 0));
        Episode::new(&c, scene, seed).expect("episode")
    }

    /// Crowds of `c` (pedestrians crossing a circle round (200, 200)) on `seeds`, each run for
    /// `steps` steps: how many reached the opposite point (within 10 px), and the least gap
    /// between two of them at any step.
    fn crossings(c: &crate::SimConfig, seeds: u64, steps: usize) -> (usize, f64) {
        let (mut arrived, mut least) = (0, f64::INFINITY);
        for seed in 0..seeds {
            let mut e = episode(c, seed);
            let goals: Vec<_> = e
                .movers()
                .expect("movers")
                .items()
                .map(|m| crate::geometry::Point::new(400.0, 400.0) - m.position().coords)
                .collect();
            for _ in 0..steps {
                e.step(DiscreteAction::Left);
                let m: Vec<_> = e.movers().expect("movers").items().collect();
                for i in 0..m.len() {
                    for j in i + 1..m.len() {
                        least = least.min((m[i].position() - m[j].position()).norm() - 12.0);
                    }
                }
            }
            let m: Vec<_> = e.movers().expect("movers").items().collect();
            arrived += m
                .iter()
                .zip(&goals)
                .filter(|(m, g)| (m.position() - **g).norm() < 10.0)
                .count();
        }
        (arrived, least)
    }

    #[test]
    fn pedestrians_cross_a_circle_without_overlapping_and_arrive() {
        let (arrived, least) = crossings(&crossing(16, true), 40, 150);
        // Each walks to the opposite point (within its radius, give or take the jitter).
        eprintln!("{arrived} of 640 arrived; least gap {least}");
        assert!(arrived >= 608, "{arrived} of 640 arrived");
        assert!(least >= 0.0, "pedestrians overlapped by {}", -least);
    }

    #[test]
    fn social_force_walkers_cross_a_circle_and_arrive() {
        let mut c = crossing(8, true);
        c.moving[0].motion = MotionKind::SocialForce;
        let (arrived, least) = crossings(&c, 20, 200);
        eprintln!("{arrived} of 160 arrived; least gap {least}");
        assert!(arrived >= 150, "{arrived} of 160 arrived");
        // The push keeps them apart, if not as strictly as ORCA.
        assert!(least >= -2.0, "walkers overlapped by {}", -least);
    }

    #[test]
    fn social_force_walkers_with_drawn_goals_keep_walking() {
        let c = crate::SimConfig {
            moving: vec![MovingConfig {
                count: 40,
                radius_px: 6.0,
                motion: MotionKind::SocialForce,
                speed_px: 3.0,
                on_arrival: crate::config::Arrival::NewGoal,
                pattern: Some(Pattern::Random),
                ..Default::default()
            }],
            ..crossing(1, false)
        };
        let mut e = episode(&c, 5);
        let start: Vec<_> = e
            .movers()
            .expect("movers")
            .items()
            .map(|m| m.position())
            .collect();
        let mut moved = vec![0.0; start.len()];
        for _ in 0..600 {
            let before: Vec<_> = e
                .movers()
                .expect("movers")
                .items()
                .map(|m| m.position())
                .collect();
            e.step(DiscreteAction::Left);
            for (k, m) in e.movers().expect("movers").items().enumerate() {
                moved[k] += (m.position() - before[k]).norm();
                assert!(
                    e.scene().disc_clear(m.position(), 6.0),
                    "walker {k} in a wall"
                );
            }
        }
        // Walking on from goal to goal, none is held for long against a wall: each covers at
        // least half of what 600 steps at 3 px would.
        for (k, d) in moved.iter().enumerate() {
            assert!(*d >= 900.0, "walker {k} walked only {d} px");
        }
    }

    /// Property: in open space, ORCA pedestrians that see the robot never overlap each other or
    /// the robot, over 1000 random crowds (2-20 walkers of radius 3-8 px at 1-5 px a step with
    /// goals drawn anew at each arrival, 60 steps each, the robot turning on the spot).
    #[test]
    fn orca_pedestrians_that_see_everyone_never_overlap() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(45);
        let mut least = f64::INFINITY;
        for config in 0..1000u64 {
            let radius = rng.random_range(3.0..8.0);
            let mut c = crossing(1, true);
            c.moving[0] = MovingConfig {
                count: rng.random_range(2..=20),
                radius_px: radius,
                motion: MotionKind::Orca,
                speed_px: rng.random_range(1.0..5.0),
                on_arrival: crate::config::Arrival::NewGoal,
                sees_robots: true,
                min_robot_distance_px: 10.0,
                ..Default::default()
            };
            let mut e = episode(&c, config);
            let robot = e.pose().position();
            for _ in 0..60 {
                e.step(DiscreteAction::Left);
                let m: Vec<_> = e.movers().expect("movers").items().collect();
                for i in 0..m.len() {
                    let p = m[i].position();
                    least = least.min((p - robot).norm() - radius - 5.0);
                    for q in &m[i + 1..] {
                        least = least.min((p - q.position()).norm() - 2.0 * radius);
                    }
                }
            }
        }
        eprintln!("least gap over 1000 crowds: {least}");
        assert!(least >= 0.0, "agents overlapped by {}", -least);
    }

    /// The same crowd episodes, bit for bit, on one thread and on several.
    #[test]
    fn crowds_give_the_same_records_on_any_thread_count() {
        use crate::eval::{EvalOptions, Evaluator};
        use crate::policy::factory;
        use crate::sim::world::Scenes;
        use std::sync::atomic::AtomicBool;
        let mut c = crossing(12, true);
        c.moving[0].motion = MotionKind::SocialForce;
        c.moving.push(MovingConfig {
            on_arrival: crate::config::Arrival::NewGoal,
            pattern: Some(Pattern::Random),
            ..crossing(8, false).moving[0].clone()
        });
        c.metrics.crowd = true;
        let ev = Evaluator::new(c.validate().expect("valid"), Scenes::MazePerSeed);
        let records = |threads: usize| {
            let f = factory("orca", ev.config().observation_size()).expect("policy");
            let options = EvalOptions {
                seeds: (0..12).collect::<Vec<_>>().into(),
                threads,
                ..Default::default()
            };
            let run = ev
                .run(f.as_ref(), &options, &AtomicBool::new(false), &|_| {})
                .expect("runs");
            run.records
                .iter()
                .map(|r| format!("{r:?}").replace(&format!("{:?}", r.wall_time_s), ""))
                .collect::<Vec<_>>()
        };
        assert_eq!(records(1), records(2));
        assert_eq!(records(1), records(4));
    }

    #[test]
    fn max_speed_px_is_a_pedestrians_only() {
        let c = crate::SimConfig {
            moving: vec![MovingConfig {
                motion: MotionKind::Linear,
                speed_px: 2.0,
                max_speed_px: Some(10.0),
                ..Default::default()
            }],
            ..Default::default()
        };
        let mut e = episode(&c, 1);
        let position = |e: &Episode| {
            e.movers()
                .expect("movers")
                .items()
                .next()
                .expect("one")
                .position()
        };
        let before = position(&e);
        e.step(DiscreteAction::Left);
        let after = position(&e);
        assert!((after - before).norm() <= 2.0 + 1e-9, "{before} {after}");
    }

    #[test]
    fn a_crowd_never_changes_the_maze_start_or_goal() {
        let plain = episode(&crate::SimConfig::default(), 3);
        let mut c = crate::SimConfig {
            moving: crossing(5, false).moving,
            ..Default::default()
        };
        c.moving[0].pattern_radius_px = 60.0;
        c.moving[0].min_robot_distance_px = 0.0;
        let crowd = episode(&c, 3);
        assert_eq!(plain.start(), crowd.start());
        assert_eq!(plain.goal(), crowd.goal());
        assert_eq!(plain.scene().boxes(), crowd.scene().boxes());
    }

    #[test]
    fn a_crowd_entry_with_the_robot_on_its_pattern_is_the_same_episode_spelt_out() {
        // CrowdNav's circle crossing, written with [episode] start and goal and a [[moving]]
        // entry, and as a [[crowd]] the robot follows: the same start, goal and pedestrians.
        let spelt = crossing(6, false);
        let mut short = spelt.clone();
        let m = short.moving.remove(0);
        short.episode.start = None;
        short.episode.goal = None;
        short.crowd = vec![crate::config::CrowdConfig {
            count: m.count,
            pattern: Pattern::Circle,
            radius_px: m.radius_px,
            speed_px: m.speed_px,
            pattern_radius_px: 180.0,
            jitter_px: m.jitter_px,
            robot_follows: true,
            ..Default::default()
        }];
        let mut spelt = spelt;
        spelt.moving[0].pattern_radius_px = 180.0;
        spelt.episode.start = Some([200.0, 20.0, 90.0]);
        spelt.episode.goal = Some([200.0, 380.0]);
        for seed in 0..5 {
            let (mut a, mut b) = (episode(&spelt, seed), episode(&short, seed));
            assert_eq!((a.start(), a.goal()), (b.start(), b.goal()));
            for _ in 0..60 {
                a.step(DiscreteAction::Ahead);
                b.step(DiscreteAction::Ahead);
                let pa: Vec<_> = a
                    .movers()
                    .expect("movers")
                    .items()
                    .map(|m| m.position())
                    .collect();
                let pb: Vec<_> = b
                    .movers()
                    .expect("movers")
                    .items()
                    .map(|m| m.position())
                    .collect();
                assert_eq!(pa, pb);
                assert_eq!(a.pose(), b.pose());
            }
        }
    }
}
