//! What the local planners (`orca`, `social-force`, `dwa`; docs/model.md "Local planners among
//! moving things") share: sensing the agents round the robot (moving obstacles and other robots,
//! ground truth within a range, velocities from their last displacements), the preferred
//! velocity towards the geodesic path's lookahead point, and turning a chosen velocity into the
//! robot's action.

use super::follow::Follower;
use super::geodesic::planned;
use super::{Decision, Policy, PolicyError};
use crate::config::PlannerActions;
use crate::geometry::{wrap_deg, Agent, Point, Vector, V2};
use crate::sim::{Action, DiscreteAction, Episode, Movers, Team, World};
use std::f64::consts::TAU;

/// How sharply a unicycle's speed falls with the angle between its chord and the velocity it
/// tracks: `cos^ALIGN_POWER`.
const ALIGN_POWER: i32 = 8;

/// A local planner (`orca`, `social-force`, `dwa`): how far it senses, and what it decides from
/// the agents it sensed, following the geodesic path. [`Local`] makes it a [`Policy`] for a lone
/// robot and for every robot of a team.
pub trait Planner: Default + Send {
    /// How far robot `me` senses other agents, px.
    fn range(me: &Episode) -> f64;

    /// The decision for `me`, following `path`, among the agents `senses` holds (`me` first).
    fn decide(&mut self, me: &Episode, path: &mut Follower, senses: &Senses) -> Decision;

    /// An episode (or, mid-episode, the leg to the next goal of a list) begins.
    fn reset(&mut self, _episode: &Episode) {}
}

/// A local planner as a policy: its geodesic path to the goal, the agents round the robot as
/// last sensed, and the planner.
#[derive(Debug, Default)]
pub struct Local<P> {
    path: Option<Follower>,
    senses: Senses,
    planner: P,
}

impl<P: Planner> Local<P> {
    /// The planner's decision for `me`, whose agents are sensed.
    fn decide(&mut self, me: &Episode) -> Decision {
        match &mut self.path {
            Some(path) => self.planner.decide(me, path, &self.senses),
            None => Decision::GiveUp("no path to the goal".into()),
        }
    }
}

impl<P: Planner> Policy for Local<P> {
    fn reset(&mut self, world: &World, episode: &Episode) -> Result<(), PolicyError> {
        self.path = planned(world, episode.pose().position(), episode.goal());
        self.senses.reset(episode);
        self.planner.reset(episode);
        Ok(())
    }

    fn act(&mut self, episode: &Episode) -> Result<Decision, PolicyError> {
        self.senses.lone(episode, P::range(episode));
        Ok(self.decide(episode))
    }

    fn act_in_team(&mut self, team: &Team, k: usize) -> Result<Decision, PolicyError> {
        let me = team.robot(k);
        self.senses.in_team(team, k, P::range(me));
        Ok(self.decide(me))
    }
}

/// The agents round the robot, as last sensed.
#[derive(Debug, Default)]
pub struct Senses {
    /// Where each sensed agent was at the last decision (moving obstacles by index, then the
    /// team's robots by index): its velocity is its displacement since.
    last: Vec<Option<Point>>,
    /// Where this robot was at the last decision.
    last_me: Option<Point>,
    /// Its index in its team (0 alone).
    pub(super) index: usize,
    /// The robot (first) and the agents within range, with their velocities.
    pub(super) agents: Vec<Agent<f64>>,
}

impl Senses {
    /// Forgets the last positions at an episode's start (on to the next goal of a list,
    /// mid-episode, they still hold).
    pub(super) fn reset(&mut self, episode: &Episode) {
        if episode.steps() == 0 {
            self.last.clear();
            self.last_me = None;
        }
    }

    /// Senses round a lone robot within `range`.
    pub(super) fn lone(&mut self, me: &Episode, range: f64) {
        self.sense(me, me.movers(), None, range);
    }

    /// Senses round robot `k` of `team` within `range`.
    pub(super) fn in_team(&mut self, team: &Team, k: usize, range: f64) {
        self.index = k;
        self.sense(team.robot(k), team.movers(), Some((team, k)), range);
    }

    /// The agents round `me` (the moving obstacles `movers`, then the present robots of `team`
    /// by index, `me` among them as robot `index`; none for a lone robot) within `range`, with
    /// their velocities, into `self.agents` (`me` first); remembers where each is for the next
    /// step.
    fn sense(
        &mut self,
        me: &Episode,
        movers: Option<&Movers>,
        team: Option<(&Team, usize)>,
        range: f64,
    ) {
        let team_size = team.map_or(0, |(t, _)| t.robots().len());
        let config = me.config();
        let p = me.pose().position();
        let velocity = self.last_me.map_or(Vector::zeros(), |l| p - l);
        self.last_me = Some(p);
        self.agents.clear();
        self.agents.push(Agent {
            position: V2::from(p),
            velocity: V2::from(velocity),
            radius: config.robot.radius_px,
        });
        let mover_count = movers.map_or(0, |m| m.items().len());
        self.last.resize(mover_count + team_size, None);
        let mut seen = |slot: usize, at: Option<Point>, radius: f64, agents: &mut Vec<_>| {
            let last = std::mem::replace(&mut self.last[slot], at);
            if let Some(at) = at.filter(|a| (a - p).norm() <= range + radius) {
                agents.push(Agent {
                    position: V2::from(at),
                    velocity: V2::from(last.map_or(Vector::zeros(), |l| at - l)),
                    radius,
                });
            }
        };
        if let Some(m) = movers {
            for (i, o) in m.items().enumerate() {
                let at = o.present().then(|| o.position());
                seen(i, at, o.body().bounding_radius(), &mut self.agents);
            }
        }
        if let Some((team, index)) = team {
            for (k, r) in team.robots().iter().enumerate() {
                if k != index && team.present(k) {
                    let radius = r.config().robot.radius_px;
                    seen(
                        mover_count + k,
                        Some(r.pose().position()),
                        radius,
                        &mut self.agents,
                    );
                }
            }
        }
    }
}

/// A planner's speed: `speed_px` when set, else the robot's largest for `actions`.
pub(super) fn planner_speed(me: &Episode, speed_px: Option<f64>, actions: PlannerActions) -> f64 {
    let robot = &me.config().robot;
    speed_px.unwrap_or(match actions {
        PlannerActions::Continuous => robot.max_linear_speed_px,
        PlannerActions::Discrete => robot.move_speed_px,
    })
}

/// The velocity `me` wants: `speed` towards the lookahead point of `path`, slowing to land on
/// the goal, nudged a thousandth of a px (see below); and the way to the lookahead point.
pub(super) fn preferred(
    path: &mut Follower,
    me: &Episode,
    speed: f64,
    index: usize,
) -> (Vector, Vector) {
    let p = me.pose().position();
    let aim = path.aim(p).unwrap_or(me.goal());
    let to_aim = aim - p;
    let to_goal = (me.goal() - p).norm();
    let preferred = match to_aim.try_normalize(1e-12) {
        Some(u) => u * speed.min(to_goal),
        None => Vector::zeros(),
    };
    // A thousandth of a px off, in a direction turning with the step and the robot, as
    // RVO2's examples do: perfect symmetry (robots swapping across a circle) can otherwise
    // hold ORCA agents still for ever.
    let turn = f64::from(me.steps()) * 2.399_963 + index as f64 * 0.618_034 * TAU;
    (
        preferred + crate::geometry::unit(turn.to_degrees()) * 1e-3,
        to_aim,
    )
}

/// The action that tracks velocity `v` (`aim`: where the path leads, for turning on the spot).
pub(super) fn action(me: &Episode, v: Vector, aim: Vector, actions: PlannerActions) -> Action {
    match actions {
        PlannerActions::Continuous => continuous(me, v, aim),
        PlannerActions::Discrete => discrete(me, v, aim).into(),
    }
}

/// The signed turn from the robot's heading to `direction`, degrees in [-180, 180).
pub(super) fn turn_to(me: &Episode, direction: Vector) -> f64 {
    let bearing = direction.y.atan2(direction.x).to_degrees();
    wrap_deg(bearing - me.pose().z_deg + 180.0) - 180.0
}

/// The unicycle command whose step moves the robot by `v`: an arc of constant speed and turn
/// rate ends along its chord, at half the turn from the heading (from the reversed heading when
/// driving backwards), so a turn of twice the velocity's bearing `e` from the heading (or from
/// the reversed heading, for a velocity behind the robot) and a speed of `|v| e / sin e` land
/// exactly on `v` when the turn is within `max_angular_speed_deg`. Beyond it the robot turns as
/// far as it may, at the speed that keeps its chord's advance along `v`. Standing (`v` zero), it
/// turns towards `aim`.
fn continuous(me: &Episode, v: Vector, aim: Vector) -> Action {
    let speed = v.norm();
    if speed <= 1e-9 {
        if aim.norm_squared() == 0.0 {
            return Action::Continuous { v: 0.0, w_deg: 0.0 };
        }
        let w_max = me.config().robot.max_angular_speed_deg;
        return Action::Continuous {
            v: 0.0,
            w_deg: turn_to(me, aim).clamp(-w_max, w_max),
        };
    }
    let error = turn_to(me, v);
    // A velocity behind the robot is driven backwards.
    let (error, sign) = if error.abs() > 90.0 {
        (wrap_deg(error) - 180.0, -1.0)
    } else {
        (error, 1.0)
    };
    let w_max = me.config().robot.max_angular_speed_deg;
    let w_deg = (2.0 * error).clamp(-w_max, w_max);
    let half = (w_deg / 2.0).to_radians();
    // The chord of an arc of length `v` turning by `w` is `v sin(w/2) / (w/2)` long.
    let chord_per_speed = if half.abs() < 1e-9 {
        1.0
    } else {
        half.sin() / half
    };
    // Off the velocity's line by `error - w/2`: slower the further off, so a robot that cannot
    // turn in time does not sweep across what ORCA kept it clear of.
    let along = (error.to_radians() - half).cos().max(0.0).powi(ALIGN_POWER);
    Action::Continuous {
        v: sign * speed * along / chord_per_speed,
        w_deg,
    }
}

/// The discrete action that follows velocity `v`: AHEAD when the heading lies within half a
/// turn of it and it is at least half a step long (the AHEAD step then lies closer to where `v`
/// leads than standing), else a turn towards it (towards `aim` when it is shorter).
fn discrete(me: &Episode, v: Vector, aim: Vector) -> DiscreteAction {
    let robot = &me.config().robot;
    let toward = if v.norm() >= robot.move_speed_px / 2.0 {
        v
    } else {
        aim
    };
    let error = turn_to(me, toward);
    if error.abs() <= robot.turn_speed_deg / 2.0 && toward == v {
        DiscreteAction::Ahead
    } else if error >= 0.0 {
        DiscreteAction::Left
    } else {
        DiscreteAction::Right
    }
}

/// A run of `policy` alone on seeds `0..seeds` of `config`, summed up (for the planners' tests).
#[cfg(test)]
pub(super) fn lone_run(config: crate::SimConfig, policy: &str, seeds: u64) -> crate::eval::Summary {
    use crate::eval::{EvalOptions, Evaluator, Summary};
    let ev = Evaluator::new(
        config.validate().expect("valid"),
        crate::sim::Scenes::MazePerSeed,
    );
    let f = super::factory(policy, ev.config().observation_size()).expect("policy");
    let options = EvalOptions {
        seeds: (0..seeds).collect::<Vec<_>>().into(),
        ..Default::default()
    };
    let cancel = std::sync::atomic::AtomicBool::new(false);
    let run = ev
        .run(f.as_ref(), &options, &cancel, &|_| {})
        .expect("runs");
    Summary::new(&run.records, crate::eval::metric::kinds(ev.config()), 1.0)
}
