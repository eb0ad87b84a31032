//! The `coordinated` team planner (docs/model.md "Teams that finish"): every robot of a team
//! planned together, then driven along the plan.
//!
//! - **Plan.** The scene is cut into square cells wide enough that robots holding different
//!   cells stay clear of each other, even on the move between neighbouring centres
//!   ([`PlanGrid`]: `sqrt 2` times a robot diameter and a margin). Each robot's start and goals
//!   are mapped to cells, and the robots are planned one after the other in space and time,
//!   each around the cells the robots before it hold ([`plan_team`]); the order is re-drawn from
//!   the episode's seed when a robot finds no way.
//! - **Infeasible tasks.** When no order works, each pair of the robot that failed and another
//!   is searched alone, completely: two robots that cannot reach their goals even without the
//!   rest (two robots swapping ends of a corridor too narrow to pass) make the task infeasible,
//!   reported before the first step with the robots and the passage.
//! - **Execution.** Once every robot stands on its start cell, each drives from cell centre to
//!   cell centre (pure pursuit along its open cells, halting on goals and sharp turns), moving
//!   on to its next cell only once the robot planned there before it has left ([`Schedule`]),
//!   so delays (turning, giving way to what moves) never bring two robots into one cell nor
//!   into a deadlock. With another agent within sensing range, the velocity goes through ORCA:
//!   among robots alone a 2-step horizon and no margin (the plan already keeps them apart), near
//!   a moving obstacle the `[orca]` horizon and margin; it becomes the robot's action as for the
//!   `orca` policy, a unicycle turning on the spot first when its way is more than half its
//!   largest turn off its axis.
//! - **Re-planning.** A robot that ends short of its plan, or one free to go on held up for
//!   60 steps, has the running robots planned again from where they stand.
//! - **Fallback.** When no plan is found and none is proved impossible (or a robot's start or
//!   goal has no cell, or after 50 plans), every robot runs the `orca` policy instead.

use super::local::{action, planner_speed, turn_to};
use super::orca::Orca;
use super::team::{PerRobot, RobotError, TeamPolicy, TeamPolicyFactory};
use super::{Decision, Policy, PolicyError};
use crate::config::{OnArrival, PlannerActions};
use crate::geometry::{Agent, Horizon, Point, PointGrid, Vector, V2};
use crate::plan::{
    pair_feasible, pair_plan, plan_team, Limits, Pair, PlanFailure, PlanGrid, Schedule, Stop, Task,
};
use crate::sim::{stream, Action, Avoid, Avoider, Episode, Stream, Team, World};
use std::collections::HashSet;
use std::sync::Arc;

/// The policy's name.
pub const NAME: &str = "coordinated";

/// ORCA's horizon among the robots, steps: short, since the plan keeps them apart.
const TIME_HORIZON_STEPS: f64 = 2.0;
/// How far from its last stop's centre a robot that stopped for good may stand and still hold
/// only that cell (on a goal within it), px.
const CELL_HOLD_PX: f64 = 5.0;
/// Steps a robot free to go on may fail to reach its next stop before the team is planned
/// again.
const STALL_STEPS: u32 = 60;
/// Most plans an episode makes after its first, before its robots fall back to `orca`.
const MAX_REPLANS: u32 = 50;

/// How close a robot must come to a cell centre to count as there, px: continuous actions land
/// on it; a discrete step of `move_speed_px` can miss it by up to half a step.
fn reach_px(me: &Episode, actions: PlannerActions) -> f64 {
    match actions {
        PlannerActions::Continuous => 1.0,
        PlannerActions::Discrete => me.config().robot.move_speed_px / 2.0 + 0.5,
    }
}

/// How far beyond a cell's free disc a robot may stand while it counts as on the cell or on
/// its way between two, px: continuous actions keep to the line between centres (none); a
/// discrete step may end anywhere within `reach` of a centre, so a cell is free only where
/// the robot's disc fits that far off its centre (else its last step onto a cell beside a
/// wall runs into the wall, again and again).
fn overshoot_px(reach: f64, actions: PlannerActions) -> f64 {
    match actions {
        PlannerActions::Continuous => 0.0,
        PlannerActions::Discrete => reach,
    }
}

/// The action that follows velocity `v` on the way to `aim`: for continuous actions, a turn on
/// the spot while the robot's axis (forwards or backwards) is more than half its largest turn
/// off `v` (off the way to `aim` while `v` is about nought), else the `orca` policy's tracking
/// command. Within half a turn, that command's arc ends exactly on the way (its chord turns by
/// half the arc's turn), so the robot neither swings wide of a turn in its plan nor sweeps
/// sideways into a rack beside it.
fn drive(me: &Episode, v: Vector, aim: Vector, actions: PlannerActions) -> Action {
    // The way it goes: its velocity, or, standing, where it is to go.
    let way = if v.norm() > 0.05 { v } else { aim };
    if actions == PlannerActions::Continuous && way.norm() > 1e-9 {
        let error = turn_to(me, way);
        // Off the axis, forwards or backwards.
        let off = if error.abs() > 90.0 {
            error - 180.0 * error.signum()
        } else {
            error
        };
        let w_max = me.config().robot.max_angular_speed_deg;
        if off.abs() > w_max / 2.0 {
            return Action::Continuous {
                v: 0.0,
                w_deg: off.clamp(-w_max, w_max),
            };
        }
    }
    action(me, v, aim, actions)
}

/// The plan being followed.
#[derive(Debug)]
struct Following {
    schedule: Schedule,
    /// Each robot's stops: the cell centre to drive to at each...
    points: Vec<Vec<Point>>,
    /// ... and the cell.
    cells: Vec<Vec<usize>>,
    /// At each stop that reaches a goal, the goal's number among the robot's goals (counted
    /// as the episode counts them) and the point within the goal's tolerance the robot drives
    /// to from the centre and back; such stops are driven onto, never through.
    goals: Vec<Vec<Option<(u32, Point)>>>,
    /// The stop each robot heads to (`u32::MAX` once it left the scene, or for a robot not
    /// planned).
    heading: Vec<u32>,
    /// Whether each robot, at a goal's stop, has reached its centre (and now drives onto the
    /// goal and back).
    at_centre: Vec<bool>,
    /// Whether a robot stopped for good short of its plan's end: the others are planned again
    /// around it.
    stopped_short: bool,
    /// Steps each robot has been free to go on to its next stop without reaching it.
    stalled: Vec<u32>,
    /// Whether every robot has reached its start cell.
    started: bool,
}

impl Following {
    /// Whether robot `k` may move to its stop `p`: its start cell at once; the others once
    /// every robot stands on its start cell (until then robots stand anywhere near theirs, so
    /// the plan's spacing does not hold yet) and the robots before it there have moved on.
    fn open(&self, k: usize, p: usize) -> bool {
        p == 0 || (self.started && self.schedule.may_go(k, p, &self.heading))
    }

    /// Whether robot `k` may drive through its stop `p` without halting on it: neither a goal's
    /// stop nor a sharp turn (more than 45 degrees; cutting it would come too close to the
    /// cells beside).
    fn through(&self, k: usize, p: usize) -> bool {
        let points = &self.points[k];
        if p == 0 || p + 1 >= points.len() || self.goals[k][p].is_some() {
            return false;
        }
        let (a, b) = (points[p] - points[p - 1], points[p + 1] - points[p]);
        a.dot(&b) > 0.75 * a.norm() * b.norm()
    }

    /// The last stop robot `k` may drive on to without halting: from the one it heads to,
    /// through open stops, up to the first it must halt on (a goal's, a sharp turn).
    fn open_end(&self, k: usize) -> usize {
        let h = self.heading[k] as usize;
        let n = self.points[k].len();
        let mut e = h;
        while e + 1 < n && self.through(k, e) && self.open(k, e + 1) {
            e += 1;
        }
        e
    }

    /// Moves each robot's heading on past the stops it has reached: within reach of a stop's
    /// centre (and, at a goal's stop, back there with the goal counted), or, driving through a
    /// stop, past it (beyond the start of the segment that leaves it).
    fn advance(&mut self, team: &Team) {
        self.advance_robots(team);
        if !self.started && self.heading.iter().all(|&h| h >= 1) {
            self.started = true;
            // Now they may drive on.
            self.advance_robots(team);
        }
    }

    /// [`Following::advance`] of each robot.
    fn advance_robots(&mut self, team: &Team) {
        for (k, r) in team.robots().iter().enumerate() {
            if !team.present(k) {
                self.heading[k] = u32::MAX;
                continue;
            }
            let end = self.points[k].len() as u32;
            let p = r.pose().position();
            // A robot that stopped for good holds its last stop's cell when it stands on it
            // (on its goal within that cell); elsewhere, the others plan again around it.
            if !team.running(k) {
                let on_last = self.points[k]
                    .last()
                    .is_some_and(|&c| self.heading[k] + 1 >= end && (c - p).norm() <= CELL_HOLD_PX);
                if self.heading[k] < end && !on_last {
                    self.stopped_short = true;
                }
                self.heading[k] = self.heading[k].max(end);
                continue;
            }
            let config = r.config();
            let reach = reach_px(r, config.orca.actions);
            // Past a stop it drives through, it is within its lookahead of it.
            let through = planner_speed(r, config.orca.speed_px, config.orca.actions);
            loop {
                let h = self.heading[k] as usize;
                let Some(&stop) = self.points[k].get(h) else {
                    break;
                };
                let near = (stop - p).norm() <= reach;
                let reached = match self.goals[k][h] {
                    Some((g, _)) => {
                        if near {
                            self.at_centre[k] = true;
                        }
                        near && r.goals_reached() > g
                    }
                    None => {
                        let passed = h < self.open_end(k)
                            && self.through(k, h)
                            && (stop - p).norm() <= through
                            && {
                                let next = self.points[k][h + 1];
                                (p - stop).dot(&(next - stop)) > 0.0
                            };
                        near || (passed && self.open(k, h))
                    }
                };
                if !reached {
                    break;
                }
                self.heading[k] += 1;
                self.at_centre[k] = false;
                self.stalled[k] = 0;
            }
            let h = self.heading[k] as usize;
            if h < self.points[k].len() && self.open(k, h) {
                self.stalled[k] += 1;
            }
        }
    }

    /// Where robot `me` (`k`) drives this step: `lookahead` px along its plan's open stops
    /// past where it is (pure pursuit), ending on the last open one; where it is while its
    /// next stop is closed; at a goal's stop, from its centre onto the goal and back; its goal
    /// once past its last stop.
    fn aim(&self, k: usize, me: &Episode, lookahead: f64) -> Point {
        let h = self.heading[k] as usize;
        let points = &self.points[k];
        let p = me.pose().position();
        if h >= points.len() {
            return me.goal();
        }
        if !self.open(k, h) {
            return points[h - 1];
        }
        if let Some((g, onto)) = self.goals[k][h] {
            if self.at_centre[k] && me.goals_reached() <= g {
                return onto;
            }
        }
        if h == 0 || self.at_centre[k] {
            return points[h];
        }
        let e = self.open_end(k);
        // Along the segment into stop h from where the robot projects onto it.
        let (a, b) = (points[h - 1], points[h]);
        let ab = b - a;
        let len = ab.norm();
        let along = if len > 0.0 {
            ((p - a).dot(&ab) / len).clamp(0.0, len)
        } else {
            0.0
        };
        let mut left = lookahead + along;
        let mut from = a;
        for &to in &points[h..=e] {
            let seg = (to - from).norm();
            if left <= seg && seg > 0.0 {
                return from + (to - from) * (left / seg);
            }
            left -= seg;
            from = to;
        }
        points[e]
    }
}

/// Whether robot `k`'s step `v` towards its start cell keeps clear of the other robots (the
/// plan's spacing holds only once every robot is on its cell): by a hair of those standing,
/// and, of those with a lower number also on their way to their start cells and driving, by as
/// far as they may drive in the step too (they go first; one that stood still last step does
/// not hold the others up). A step that draws no nearer to a robot is always clear of it.
/// `agents` and `slot` as [`Coordinated`] keeps them.
fn initial_step_clear(
    agents: &[Agent<f64>],
    slot: &[Option<usize>],
    k: usize,
    v: Vector,
    heading: &[u32],
    speed: f64,
) -> bool {
    let Some(me) = slot[k].map(|s| agents[s]) else {
        return true;
    };
    let a = Point::new(me.position.x, me.position.y);
    let b = a + v;
    slot.iter().enumerate().all(|(j, slot)| {
        let Some(other) = slot.filter(|_| j != k).map(|s| agents[s]) else {
            return true;
        };
        let q = Point::new(other.position.x, other.position.y);
        // It may drive on this step if it drove the last one.
        let moving = j < k && heading[j] == 0 && other.velocity.x.hypot(other.velocity.y) > 1e-3;
        let need = me.radius + other.radius + 0.5 + if moving { speed } else { 0.0 };
        // Clear of it all along, or at least drawing no nearer.
        crate::geometry::point_segment_distance_squared(q, a, b) >= need * need
            || (b - q).norm_squared() >= (a - q).norm_squared()
    })
}

/// A planning of the running robots: which robots, their tasks, and their plans or the
/// planner's failure.
struct Planned {
    robots: Vec<usize>,
    tasks: Vec<Task>,
    plans: Result<Vec<Vec<Stop>>, PlanFailure>,
}

impl Planned {
    /// The robots planned and their plans, when the planner found them.
    fn found(self) -> Option<(Vec<usize>, Vec<Vec<Stop>>)> {
        Some((self.robots, self.plans.ok()?))
    }
}

/// The `coordinated` team planner.
#[derive(Default)]
pub struct Coordinated {
    following: Option<Following>,
    /// When the plan failed without proof of infeasibility: every robot on `orca`.
    fallback: Option<PerRobot>,
    infeasible: Option<String>,
    /// The grid the team is planned on.
    grid: Option<PlanGrid>,
    /// The robots' worlds (for the fallback).
    worlds: Vec<Arc<World>>,
    /// The episode's generator of priority orders.
    rng: Option<crate::sim::Rng>,
    /// Plans made since the first.
    replans: u32,
    /// Each robot's cells that no goal of it may be planned on (tried and found blocked).
    banned: Vec<HashSet<usize>>,
    /// Every robot's centre at the last decision (its velocity is its displacement since), then
    /// every moving obstacle's.
    last: Vec<Option<Point>>,
    agents: Vec<Agent<f64>>,
    /// The agents by where they are, and the largest one's radius.
    agent_grid: PointGrid,
    max_agent_radius: f64,
    /// Scratch: the agents near one robot.
    near: Vec<u32>,
    /// How many of `agents` are robots (the moving obstacles follow them).
    robot_agents: usize,
    /// The place of each robot in `agents`.
    slot: Vec<Option<usize>>,
    /// Each robot's velocity chosen at the last decision: its own velocity in ORCA, as in RVO2,
    /// so a unicycle that turned on the spot last step (and moved nowhere) asks ORCA the same
    /// question again rather than flipping between two answers.
    chosen: Vec<Vector>,
    avoider: Avoider,
}

impl std::fmt::Debug for Coordinated {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Coordinated")
            .field("following", &self.following)
            .field("infeasible", &self.infeasible)
            .finish_non_exhaustive()
    }
}

/// The cell side of a team's plan: robots on different cells, each within `reach` of its
/// centre or of the line between two centres, stay clear: `sqrt 2 (2 r + 2 reach + 1)`.
pub fn cell_px(max_radius: f64, reach: f64) -> f64 {
    std::f64::consts::SQRT_2 * (2.0 * max_radius + 2.0 * reach + 1.0)
}

/// Where a robot drives to at a stop on `cell`'s centre `c` that reaches goal `goal`: just far
/// enough towards the goal to come within `tolerance - 1` px of it.
fn stop_point(c: Point, goal: Option<Point>, tolerance: f64) -> Point {
    let Some(g) = goal else {
        return c;
    };
    let off = g - c;
    let d = off.norm();
    let within = (tolerance - 1.0).max(0.0);
    if d <= within {
        c
    } else {
        c + off * ((d - within) / d)
    }
}

/// The tasks of the running robots of `team` on `grid` (and which robot each is for): starts
/// on distinct cells, last goals of robots that stay on distinct cells, none on a `blocked`
/// cell, no goal of robot `k` on its `banned[k]` cells; `None` when a start or goal has no such cell near it.
fn tasks(
    grid: &PlanGrid,
    team: &Team,
    blocked: &HashSet<usize>,
    banned: &[HashSet<usize>],
) -> Option<(Vec<usize>, Vec<Task>)> {
    let reach = grid.cell_px() * 1.5;
    let mut starts_taken = blocked.clone();
    let mut parks_taken = blocked.clone();
    let mut robots = Vec::new();
    let mut out = Vec::new();
    for (k, r) in team.robots().iter().enumerate() {
        if !team.running(k) {
            continue;
        }
        let start = grid
            .nearest_free(r.pose().position(), reach)
            .into_iter()
            .find(|c| starts_taken.insert(*c))?;
        let vanish = team.on_arrival(k) == OnArrival::Vanish;
        let points = goal_points(team, k);
        let mut goals = Vec::new();
        for (g, p) in points.iter().enumerate() {
            let last = g + 1 == points.len();
            // A goal's cell: the nearest whose way onto the goal's tolerance is clear.
            let tolerance = r.config().episode.goal_tolerance_px;
            let radius = r.config().robot.radius_px;
            let mut cells = grid
                .nearest_free(*p, reach)
                .into_iter()
                .filter(|c| !blocked.contains(c) && !banned.get(k).is_some_and(|b| b.contains(c)))
                .filter(|&c| {
                    let from = grid.center(c);
                    r.scene()
                        .sweep_clear(from, stop_point(from, Some(*p), tolerance), radius)
                });
            let cell = if last && !vanish {
                cells.find(|c| parks_taken.insert(*c))?
            } else {
                cells.next()?
            };
            goals.push(cell);
        }
        robots.push(k);
        out.push(Task {
            start,
            goals,
            vanish,
        });
    }
    Some((robots, out))
}

/// The cells a robot standing at `p` for good blocks: those whose centres lie within a cell of
/// it (a robot on its way between two cells beyond passes it at least the grid's clearance).
fn blocked_by(grid: &PlanGrid, p: Point) -> impl Iterator<Item = usize> + '_ {
    grid.nearest_free(p, grid.cell_px()).into_iter()
}

/// Robot `k`'s goals still to visit, in visiting order (all of them before the first step).
fn goal_points(team: &Team, k: usize) -> Vec<Point> {
    let r = team.robot(k);
    std::iter::once(r.goal())
        .chain(r.later_goals().iter().copied())
        .collect()
}

/// The cells robot `task` passes through on a shortest way to its last goal, alone.
fn way_cells(grid: &PlanGrid, task: &Task) -> Vec<usize> {
    let Some(&goal) = task.goals.last() else {
        return Vec::new();
    };
    let d = grid.moves_to(goal);
    let mut at = task.start;
    let mut out = vec![at];
    while d[at] != 0 && d[at] != u32::MAX {
        let Some((_, next)) = grid.neighbours(at).find(|&(_, j)| d[j] + 1 == d[at]) else {
            break;
        };
        at = next;
        out.push(at);
    }
    out
}

/// Why the robots `a` and `b` cannot both arrive: the stretch of `a`'s way that `b`'s shares.
fn passage(grid: &PlanGrid, tasks: &[Task], a: usize, b: usize) -> String {
    let wa = way_cells(grid, &tasks[a]);
    let wb: std::collections::HashSet<usize> = way_cells(grid, &tasks[b]).into_iter().collect();
    let shared: Vec<Point> = wa
        .iter()
        .filter(|c| wb.contains(c))
        .map(|&c| grid.center(c))
        .collect();
    let (lo, hi) = shared.iter().fold(
        (
            Point::new(f64::INFINITY, f64::INFINITY),
            Point::new(f64::NEG_INFINITY, f64::NEG_INFINITY),
        ),
        |(lo, hi), p| {
            (
                Point::new(lo.x.min(p.x), lo.y.min(p.y)),
                Point::new(hi.x.max(p.x), hi.y.max(p.y)),
            )
        },
    );
    let place = if shared.is_empty() {
        String::new()
    } else {
        format!(
            " between ({:.0}, {:.0}) and ({:.0}, {:.0})",
            lo.x, lo.y, hi.x, hi.y
        )
    };
    format!(
        "robots {a} and {b} cannot pass each other{place} (no way for the two alone: a \
         complete search on {:.1} px cells)",
        grid.cell_px()
    )
}

impl Coordinated {
    /// Plans `team` before its first step: sets `following`, or `infeasible`, or `fallback`.
    fn plan(&mut self, team: &Team, worlds: &[Arc<World>]) -> Result<(), RobotError> {
        self.following = None;
        self.fallback = None;
        self.infeasible = None;
        self.replans = 0;
        self.banned = vec![HashSet::new(); team.robots().len()];
        self.worlds = worlds.to_vec();
        let actions = worlds[0].config().orca.actions;
        let max_radius = team
            .robots()
            .iter()
            .map(|r| r.config().robot.radius_px)
            .fold(0.0, f64::max);
        let reach = team
            .robots()
            .iter()
            .map(|r| reach_px(r, actions))
            .fold(0.0, f64::max);
        let anchors: Vec<Point> = team.robots().iter().map(|r| r.pose().position()).collect();
        let grid = PlanGrid::best(
            worlds[0].scene(),
            max_radius + 0.5 + overshoot_px(reach, actions),
            cell_px(max_radius, reach),
            &anchors,
        );
        self.rng = Some(stream(team.robot(0).seed(), Stream::Policy));
        let planned = self.plan_from_here(&grid, team);
        if let Some(Planned {
            tasks,
            plans: Err(failure),
            ..
        }) = &planned
        {
            let f = failure.robot;
            let single = |k: usize| tasks[k].goals.len() == 1;
            if single(f) {
                for j in (0..tasks.len()).filter(|&j| j != f && single(j)) {
                    if pair_feasible(&grid, &tasks[f], &tasks[j]) == Pair::Infeasible {
                        let (a, b) = (f.min(j), f.max(j));
                        self.infeasible = Some(passage(&grid, tasks, a, b));
                        return Ok(());
                    }
                }
            }
        }
        let planned = planned.and_then(|p| match p.plans {
            // Two robots the priority orders could not plan (the one planned first would have
            // had to wait for the other): the two planned together.
            Err(_) if p.tasks.len() == 2 => {
                let [a, b] = pair_plan(&grid, &p.tasks[0], &p.tasks[1])?;
                Some((p.robots, vec![a, b]))
            }
            _ => p.found(),
        });
        self.follow(&grid, team, planned)?;
        self.grid = Some(grid);
        Ok(())
    }

    /// Plans the running robots of `team` from where they stand, around the robots that stopped
    /// for good: the robots planned, their tasks and their plans (`None`: a start or goal has no
    /// cell).
    fn plan_from_here(&mut self, grid: &PlanGrid, team: &Team) -> Option<Planned> {
        let mut blocked = HashSet::new();
        for (k, r) in team.robots().iter().enumerate() {
            if team.present(k) && !team.running(k) {
                blocked.extend(blocked_by(grid, r.pose().position()));
            }
        }
        let (robots, tasks) = tasks(grid, team, &blocked, &self.banned)?;
        let blocked: Vec<usize> = blocked.into_iter().collect();
        let rng = self
            .rng
            .get_or_insert_with(|| stream(team.robot(0).seed(), Stream::Policy));
        let plans = plan_team(grid, &tasks, &blocked, &Limits::default(), rng);
        Some(Planned {
            robots,
            tasks,
            plans,
        })
    }

    /// Follows `planned` (the robots planned and their plans), or falls back to `orca`.
    fn follow(
        &mut self,
        grid: &PlanGrid,
        team: &Team,
        planned: Option<(Vec<usize>, Vec<Vec<Stop>>)>,
    ) -> Result<(), RobotError> {
        let Some((robots, plans)) = planned else {
            self.following = None;
            let worlds = self.worlds.clone();
            return self.fall_back(team, &worlds);
        };
        let n = team.robots().len();
        let mut by_robot: Vec<Vec<Stop>> = vec![Vec::new(); n];
        for (k, stops) in robots.into_iter().zip(plans) {
            by_robot[k] = stops;
        }
        self.following = Some(Following {
            schedule: Schedule::new(&by_robot),
            cells: by_robot
                .iter()
                .map(|stops| stops.iter().map(|s| s.cell).collect())
                .collect(),
            points: by_robot
                .iter()
                .map(|stops| self::points(grid, stops))
                .collect(),
            goals: by_robot
                .iter()
                .enumerate()
                .map(|(k, stops)| goal_stops(grid, team, k, stops))
                .collect(),
            at_centre: vec![false; n],
            heading: (0..n)
                .map(|k| if team.running(k) { 0 } else { u32::MAX })
                .collect(),
            stopped_short: false,
            stalled: vec![0; n],
            started: false,
        });
        Ok(())
    }

    /// Plans the running robots again from where they stand (a robot stopped for good short of
    /// its plan's end), or falls back to `orca`.
    fn replan(&mut self, team: &Team) -> Result<(), RobotError> {
        self.replans += 1;
        let Some(grid) = self.grid.take() else {
            return Ok(());
        };
        let planned = if self.replans > MAX_REPLANS {
            None
        } else {
            self.plan_from_here(&grid, team).and_then(Planned::found)
        };
        self.follow(&grid, team, planned)?;
        self.grid = Some(grid);
        Ok(())
    }

    fn fall_back(&mut self, team: &Team, worlds: &[Arc<World>]) -> Result<(), RobotError> {
        if worlds.is_empty() {
            return Ok(());
        }
        let policies: Vec<Box<dyn Policy>> = (0..team.robots().len())
            .map(|_| Box::new(Orca::default()) as Box<dyn Policy>)
            .collect();
        let mut p = PerRobot::new(policies);
        p.reset(team, worlds)?;
        self.fallback = Some(p);
        Ok(())
    }

    /// Every present robot and moving obstacle as an ORCA agent, with its velocity since the
    /// last decision.
    fn sense(&mut self, team: &Team) {
        let n = team.robots().len();
        let movers = team.movers().map_or(0, |m| m.items().len());
        self.last.resize(n + movers, None);
        self.chosen.resize(n, Vector::zeros());
        self.agents.clear();
        self.slot.clear();
        let mut seen = |slot: usize, at: Option<Point>, radius: f64, agents: &mut Vec<_>| {
            let last = std::mem::replace(&mut self.last[slot], at);
            at.map(|at| {
                agents.push(Agent {
                    position: V2::from(at),
                    velocity: V2::from(last.map_or(Vector::zeros(), |l| at - l)),
                    radius,
                });
                agents.len() - 1
            })
        };
        for (k, r) in team.robots().iter().enumerate() {
            let at = team.present(k).then(|| r.pose().position());
            let s = seen(k, at, r.config().robot.radius_px, &mut self.agents);
            self.slot.push(s);
        }
        self.robot_agents = self.agents.len();
        if let Some(m) = team.movers() {
            for (i, o) in m.items().enumerate() {
                let at = o.present().then(|| o.position());
                seen(n + i, at, o.body().bounding_radius(), &mut self.agents);
            }
        }
        // Cells of the largest sensing range.
        let scene = team.robot(0).scene();
        let range = team
            .robots()
            .iter()
            .map(|r| {
                let c = r.config();
                c.orca.sense_range_px.unwrap_or(c.laser.range_px)
            })
            .fold(1.0, f64::max);
        if self.agent_grid.cell() != range {
            self.agent_grid = PointGrid::new(scene.width(), scene.height(), range);
        }
        self.agent_grid.fill(
            self.agents
                .iter()
                .enumerate()
                .map(|(i, a)| (i, Point::new(a.position.x, a.position.y))),
        );
        self.max_agent_radius = self.agents.iter().map(|a| a.radius).fold(0.0, f64::max);
    }
}

/// The cell centres robot `k` drives to along `stops`.
fn points(grid: &PlanGrid, stops: &[Stop]) -> Vec<Point> {
    stops.iter().map(|s| grid.center(s.cell)).collect()
}

/// At each of robot `k`'s `stops` that reaches a goal: the goal's number as the episode counts
/// goals, and the point within the goal's tolerance that the robot drives onto.
fn goal_stops(grid: &PlanGrid, team: &Team, k: usize, stops: &[Stop]) -> Vec<Option<(u32, Point)>> {
    let r = team.robot(k);
    let goals = goal_points(team, k);
    let tolerance = r.config().episode.goal_tolerance_px;
    stops
        .iter()
        .map(|s| {
            let g = s.goal?;
            let onto = stop_point(grid.center(s.cell), goals.get(g).copied(), tolerance);
            Some((r.goals_reached() + g as u32, onto))
        })
        .collect()
}

impl TeamPolicy for Coordinated {
    fn reset(&mut self, team: &Team, worlds: &[Arc<World>]) -> Result<(), RobotError> {
        // Its plans turn robots on the spot between waypoints, which a car cannot.
        if let Some(k) = (0..team.robots().len()).find(|&k| {
            team.robot(k).config().robot.kinematics == crate::config::KinematicsKind::Ackermann
        }) {
            return Err((
                k,
                PolicyError::Failed(
                    "coordinated cannot drive a car-like robot (kinematics = \"ackermann\"): \
                     its plans turn robots on the spot; use geodesic or dwa"
                        .into(),
                ),
            ));
        }
        self.last.clear();
        self.plan(team, worlds)
    }

    fn infeasible(&self) -> Option<&str> {
        self.infeasible.as_deref()
    }

    fn act(&mut self, team: &Team, decisions: &mut [Option<Decision>]) -> Result<(), RobotError> {
        if let Some(p) = &mut self.fallback {
            return p.act(team, decisions);
        }
        self.sense(team);
        let Some(f) = &mut self.following else {
            for (k, d) in decisions.iter_mut().enumerate() {
                if team.running(k) {
                    *d = Some(Decision::GiveUp("the team was not planned".into()));
                }
            }
            return Ok(());
        };
        f.advance(team);
        // A robot held up for long (by a moving obstacle, or short of a goal another robot
        // stands by) has the team planned again; one stuck by its goal's cell tries another.
        let stalled: Vec<usize> = (0..f.stalled.len())
            .filter(|&k| f.stalled[k] > STALL_STEPS)
            .collect();
        for &k in &stalled {
            let h = f.heading[k] as usize;
            if f.at_centre[k] {
                if let Some(&c) = f.cells[k].get(h) {
                    self.banned[k].insert(c);
                }
            }
        }
        if f.stopped_short || !stalled.is_empty() {
            self.replan(team)?;
            if let Some(p) = &mut self.fallback {
                return p.act(team, decisions);
            }
            let Some(f2) = &mut self.following else {
                return Ok(());
            };
            f2.advance(team);
        }
        let Some(f) = &mut self.following else {
            return Ok(());
        };
        for (k, d) in decisions.iter_mut().enumerate() {
            if !team.running(k) {
                continue;
            }
            let me = team.robot(k);
            let config = me.config();
            let actions = config.orca.actions;
            let speed = planner_speed(me, config.orca.speed_px, actions);
            let p = me.pose().position();
            let aim = f.aim(k, me, speed);
            let to = aim - p;
            let dist = to.norm();
            let preferred = if dist <= 1e-9 || team.collided(k) {
                // Blocked last step (an arc into a wall): turn towards the aim first.
                Vector::zeros()
            } else {
                to * (speed.min(dist) / dist)
            };
            let range = config.orca.sense_range_px.unwrap_or(config.laser.range_px);
            // Alone, it follows its plan as planned: the plan's moves keep clear of the still
            // scene, and ORCA's obstacle lines would only nudge it off them.
            // The agents that may lie within its range, from the grid.
            let near = &mut self.near;
            let agents = &self.agents;
            let alone = |slot: usize, near: &mut Vec<u32>| {
                let at = agents[slot].position;
                let centre = Point::new(at.x, at.y);
                self.agent_grid
                    .near(centre, range + self.max_agent_radius, near);
                near.iter().all(|&j| {
                    let a = &agents[j as usize];
                    j as usize == slot || {
                        let d = a.position - at;
                        (d.x * d.x + d.y * d.y).sqrt() > range + a.radius
                    }
                })
            };
            let robot_agents = self.robot_agents;
            let mut mover_near = false;
            let v = match self.slot[k].filter(|&s| !alone(s, near)) {
                Some(slot) => {
                    // Among moving obstacles, which no plan keeps clear, ORCA as the `orca`
                    // policy takes it: its horizon and margin.
                    mover_near = near.iter().any(|&j| j as usize >= robot_agents);
                    if !mover_near && actions == PlannerActions::Discrete {
                        // Among robots alone, the plan's cells (sized for a discrete step's
                        // reach) keep them apart; ORCA would only shorten a velocity below
                        // half a step, which a discrete robot answers by turning on the spot,
                        // never reaching its cell.
                        preferred
                    } else {
                        let (horizon, margin) = if mover_near {
                            (config.orca.time_horizon_steps, config.orca.safety_margin_px)
                        } else {
                            (TIME_HORIZON_STEPS, 0.0)
                        };
                        let seen = self.agents[slot].velocity;
                        self.agents[slot].velocity = V2::from(self.chosen[k]);
                        let v = self.avoider.velocity(
                            me.scene(),
                            &Avoid {
                                agents: &self.agents,
                                me: slot,
                                preferred,
                                horizon: Horizon {
                                    agents: horizon,
                                    obstacles: config.orca.obstacle_time_horizon_steps,
                                    max_speed: speed,
                                    time_step: 1.0,
                                },
                                neighbour_dist: range,
                                max_neighbours: config.orca.max_neighbours as usize,
                                margin,
                                candidates: Some(near),
                            },
                        );
                        self.agents[slot].velocity = seen;
                        v
                    }
                }
                None => preferred,
            };
            let v = if f.heading[k] == 0
                && !initial_step_clear(&self.agents, &self.slot, k, v, &f.heading, speed)
            {
                Vector::zeros()
            } else {
                v
            };
            self.chosen[k] = v;
            // Dodging what moves, it tracks its velocity as the `orca` policy does, arcs and all.
            *d = Some(Decision::Act(if mover_near {
                action(me, v, to, actions)
            } else {
                drive(me, v, to, actions)
            }));
        }
        Ok(())
    }

    fn next_goal(&mut self, k: usize, world: &World, episode: &Episode) -> Result<(), PolicyError> {
        // The plan covers every leg; only the fallback's robots plan each leg afresh.
        match &mut self.fallback {
            Some(p) => p.next_goal(k, world, episode),
            None => Ok(()),
        }
    }
}

/// Whether the planner drives the team of `config` whose entries without a `policy` of their
/// own run `default`: it drives every robot or none, so an entry naming another policy beside
/// it is an error naming the entry's first robot and that policy.
pub fn drives(config: &crate::ValidConfig, default: &str) -> Result<bool, String> {
    let mut first = 0usize;
    let mut entries = Vec::new();
    for e in &config.robots {
        entries.push((first, e.policy.as_deref().unwrap_or(default)));
        first += e.count as usize;
    }
    if !entries.iter().any(|&(_, n)| n == NAME) {
        return Ok(false);
    }
    match entries.iter().find(|&&(_, n)| n != NAME) {
        Some((k, other)) => Err(format!(
            "[[robots]] entry with robot {k}: policy {other} beside coordinated, which plans the \
             whole team: give every robot coordinated (or none)"
        )),
        None => Ok(true),
    }
}

/// Makes [`Coordinated`] team planners, naming every robot's policy `coordinated`.
#[derive(Clone, Debug)]
pub struct CoordinatedFactory {
    robots: usize,
}

impl CoordinatedFactory {
    /// The planner of a team of `robots`.
    pub fn new(robots: usize) -> Self {
        Self { robots }
    }
}

/// As a single robot's policy it cannot start: it plans teams.
impl super::PolicyFactory for CoordinatedFactory {
    fn make(&self) -> Result<Box<dyn Policy>, PolicyError> {
        Err(PolicyError::Failed(
            "coordinated plans a team of [[robots]]; it has no single-robot form".into(),
        ))
    }

    fn name(&self) -> String {
        NAME.to_string()
    }
}

impl TeamPolicyFactory for CoordinatedFactory {
    fn make(&self) -> Result<Box<dyn TeamPolicy>, PolicyError> {
        Ok(Box::new(Coordinated::default()))
    }

    fn names(&self) -> Vec<String> {
        vec![NAME.to_string(); self.robots]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::TeamRobotConfig;
    use crate::eval::{EvalOptions, Evaluator, Outcome};
    use crate::sim::Scenes;
    use std::sync::atomic::AtomicBool;

    /// `robots` robots (leaving on arrival or staying) in an open hall of `side` px, or a
    /// `cols` x `cols` maze, run by `coordinated` on seeds `0..seeds`.
    fn run(
        maze: bool,
        cols: u32,
        robots: u32,
        vanish: bool,
        seeds: u64,
    ) -> Vec<crate::eval::TeamRecord> {
        let mut c = crate::SimConfig::default().hall_or_maze(maze, cols, 100.0);
        c.episode.min_goal_distance_px = 50.0;
        c.robots = vec![TeamRobotConfig {
            count: robots,
            on_arrival: if vanish {
                OnArrival::Vanish
            } else {
                OnArrival::Stay
            },
            ..Default::default()
        }];
        let ev = Evaluator::new(c.validate().expect("valid"), Scenes::MazePerSeed);
        let factory = CoordinatedFactory::new(robots as usize);
        let options = EvalOptions {
            seeds: (0..seeds).collect::<Vec<_>>().into(),
            ..Default::default()
        };
        ev.run_team(&factory, &options, &AtomicBool::new(false), &|_| {})
            .expect("runs")
            .records
    }

    #[test]
    fn in_open_halls_and_mazes_robots_arrive_and_never_touch() {
        for (maze, cols, robots, vanish) in [
            (false, 3, 2, false),
            (false, 4, 12, true),
            (false, 6, 30, false),
            (true, 4, 5, false),
            (true, 5, 12, true),
            (true, 6, 30, false),
        ] {
            let records = run(maze, cols, robots, vanish, 3);
            assert_eq!(records.len(), 3);
            for r in records {
                let what = format!("maze {maze}, {cols} cols, {robots} robots, seed {}", r.seed);
                assert_eq!(r.robot_collisions, 0, "{what}");
                assert_eq!(r.collisions, 0, "{what}: walls");
                assert!(!r.deadlock, "{what}");
                assert_eq!(r.outcome, Outcome::Success, "{what}");
                assert_eq!(r.robots.len(), robots as usize);
            }
        }
    }

    #[test]
    fn the_same_seed_gives_the_same_team_episode() {
        let a = run(true, 5, 10, false, 2);
        let b = run(true, 5, 10, false, 2);
        for (x, y) in a.iter().zip(&b) {
            assert_eq!((x.steps, x.makespan), (y.steps, y.makespan));
            assert_eq!(x.path_length_px.to_bits(), y.path_length_px.to_bits());
        }
    }

    #[test]
    fn a_goal_stop_drives_just_within_the_goal_s_tolerance() {
        let c = Point::new(0.0, 0.0);
        assert_eq!(stop_point(c, None, 10.0), c);
        assert_eq!(stop_point(c, Some(Point::new(5.0, 0.0)), 10.0), c);
        let p = stop_point(c, Some(Point::new(13.0, 0.0)), 10.0);
        assert!((p.x - 4.0).abs() < 1e-12 && p.y == 0.0, "{p:?}");
    }
}
