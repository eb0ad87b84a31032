//! The `dwa` policy (docs/model.md "Local planners among moving things"): the dynamic window
//! approach of Fox, Burgard and Thrun (1997). Each step it samples unicycle commands `(v, w)`
//! within `dwa.linear_accel_px` and `dwa.angular_accel_deg` of the last one (and the robot's
//! limits; `v` from 0 up), rolls each out for `dwa.horizon_steps` steps, and scores it:
//!
//! `heading_weight * heading + clearance_weight * clearance + speed_weight * speed`,
//!
//! where `heading` is 1 when the rollout ends facing the lookahead point of the geodesic path
//! (moved on along its direction beyond the reach of any rollout) and 0 facing away, `clearance` the share of the rollout's steps before it first comes within
//! `dwa.safety_margin_px` of the laser's points or of the moving obstacles and other robots it
//! senses (each moving on at its last velocity): Fox et al.'s distance to the nearest obstacle
//! on the trajectory, in steps; and `speed` the speed as a fraction of the largest. A command is
//! admissible when its first step keeps clear of the still scene and its rollout makes no contact
//! or the robot could stop (at `dwa.linear_accel_px` a step; a discrete robot at once) before the
//! first; when none is, the one whose contact comes latest is taken, and when no first step is
//! clear the robot stands and turns towards the aim. With discrete actions the candidates are
//! LEFT, AHEAD and RIGHT, each taken once and followed by AHEAD steps.

use super::follow::Follower;
use super::local::{Local, Planner, Senses};
use super::Decision;
use crate::config::{KinematicsKind, PlannerActions};
use crate::geometry::{unit, wrap_deg, Point};
use crate::sim::{Action, DiscreteAction, Episode, Pose, Robot};

/// The `dwa` policy: the dynamic window approach towards the geodesic path's lookahead point.
pub type Dwa = Local<DwaPlanner>;

/// The dynamic window's search, with the last command it took.
#[derive(Debug, Default)]
pub struct DwaPlanner {
    /// The command taken at the last step: the window lies round it.
    last: (f64, f64),
    /// The laser's hit points, px (scratch).
    points: Vec<Point>,
}

/// How one rollout did.
#[derive(Clone, Copy, Debug)]
struct Rollout {
    /// The steps before it first comes within the margin of anything sensed (the horizon when
    /// it never does).
    free_steps: u32,
    /// Where it ends.
    end: Pose,
    /// Whether its first step is clear of the still scene.
    first_clear: bool,
}

impl DwaPlanner {
    /// The laser's hit points round `me`, into `self.points`.
    fn laser_points(&mut self, me: &Episode) {
        self.points.clear();
        let laser = me.laser();
        let pose = me.pose();
        for (i, &d) in me.readings().iter().enumerate() {
            if d < laser.range_px() {
                let a = laser.beam_angle_deg(i, pose.z_deg);
                self.points.push(pose.position() + unit(a) * d);
            }
        }
    }

    /// Rolls out from `me`'s pose: `first` for one step, `then` for the rest.
    /// The rollout stops where it reaches the goal. A contact is a gap to a thing below the
    /// safety margin (or below the gap the robot already keeps to that thing, less a hundredth
    /// of a px, when that is smaller: a robot already near a wall may stay as near).
    fn roll(
        &self,
        me: &Episode,
        senses: &Senses,
        robot: &Robot,
        first: Action,
        then: Action,
    ) -> Rollout {
        let config = me.config();
        let margin = config.dwa.safety_margin_px;
        let r = config.robot.radius_px;
        let mut pose = me.pose();
        // The body's own velocity carries over from step to step: a model with acceleration
        // limits reaches a candidate's speed only as fast as they allow.
        let mut velocity = me.velocity();
        let p0 = pose.position();
        // Each thing's threshold: the margin, or the gap already kept when that is smaller.
        let limit = |gap0: f64| margin.min(gap0 - 0.01);
        let horizon = config.dwa.horizon_steps;
        let mut free_steps = horizon;
        let mut first_clear = true;
        for k in 0..horizon {
            let action = if k == 0 { first } else { then };
            let motion = robot.motion_from(pose, velocity, None, action);
            velocity = motion.velocity();
            if k == 0 {
                first_clear = robot.motion_clear(me.scene(), pose, &motion);
            }
            pose = motion.end;
            let p = pose.position();
            // Reaching the goal ends the episode: nothing after it counts.
            if (p - me.goal()).norm() < config.episode.goal_tolerance_px {
                break;
            }
            if free_steps < horizon {
                continue;
            }
            let ahead = f64::from(k + 1);
            let touches = self
                .points
                .iter()
                .any(|q| (p - q).norm() - r < limit((p0 - q).norm() - r))
                || senses.agents[1..].iter().any(|o| {
                    let now = Point::new(o.position.x, o.position.y);
                    let at = Point::new(
                        o.position.x + o.velocity.x * ahead,
                        o.position.y + o.velocity.y * ahead,
                    );
                    (p - at).norm() - r - o.radius < limit((p0 - now).norm() - r - o.radius)
                });
            if touches {
                free_steps = k;
            }
        }
        Rollout {
            free_steps,
            end: pose,
            first_clear,
        }
    }
}

impl Planner for DwaPlanner {
    fn range(me: &Episode) -> f64 {
        let config = me.config();
        config.dwa.sense_range_px.unwrap_or(config.laser.range_px)
    }

    fn decide(&mut self, me: &Episode, path: &mut Follower, senses: &Senses) -> Decision {
        let p = me.pose().position();
        let aim = path.aim(p).unwrap_or(me.goal());
        self.laser_points(me);
        let config = me.config();
        let dwa = &config.dwa;
        let robot = &config.robot;
        let top_speed = match dwa.actions {
            PlannerActions::Continuous => robot.max_linear_speed_px,
            PlannerActions::Discrete => robot.move_speed_px,
        };
        // Headings are judged towards the aim put beyond the furthest rollout's end, so that a
        // fast rollout is not faulted for passing it.
        let beyond = 2.0 * f64::from(dwa.horizon_steps) * top_speed;
        let aim = match (aim - p).try_normalize(1e-9) {
            Some(u) if (aim - p).norm() < beyond => p + u * beyond,
            _ => aim,
        };
        // Each candidate: its first action, the one repeated after it, and its speed in px.
        let candidates: Vec<(Action, Action, f64)> = match dwa.actions {
            PlannerActions::Discrete => {
                let ahead = Action::from(DiscreteAction::Ahead);
                [
                    DiscreteAction::Left,
                    DiscreteAction::Ahead,
                    DiscreteAction::Right,
                ]
                .into_iter()
                .map(|a| {
                    // The rollout's mean speed: a turn stands for its first step.
                    let h = f64::from(dwa.horizon_steps);
                    let speed = if a == DiscreteAction::Ahead {
                        robot.move_speed_px
                    } else {
                        robot.move_speed_px * (h - 1.0) / h
                    };
                    (Action::from(a), ahead, speed)
                })
                .collect()
            }
            PlannerActions::Continuous => {
                // The window round the last command, as wide as one step's change: the
                // robot's own limits when its model has them (a diff-drive or omnidirectional
                // base, a car), else the planner's.
                let limited = !matches!(
                    robot.kinematics,
                    KinematicsKind::Discrete | KinematicsKind::Unicycle
                );
                let (v0, w0) = if limited {
                    (me.velocity().v, me.velocity().w_deg)
                } else {
                    self.last
                };
                let accel = robot.accel_max_px.unwrap_or(dwa.linear_accel_px);
                let alpha = match robot.kinematics {
                    KinematicsKind::DiffDrive | KinematicsKind::Omni => {
                        robot.alpha_max_deg.unwrap_or(dwa.angular_accel_deg)
                    }
                    _ => dwa.angular_accel_deg,
                };
                let v_max = robot.max_linear_speed_px;
                let w_max = robot.max_angular_speed_deg;
                let (v_lo, v_hi) = ((v0 - accel).max(0.0), (v0 + accel).min(v_max));
                let (w_lo, w_hi) = ((w0 - alpha).max(-w_max), (w0 + alpha).min(w_max));
                let across = |lo: f64, hi: f64, n: u32, i: u32| {
                    lo + (hi - lo) * f64::from(i) / f64::from(n - 1)
                };
                // An omnidirectional base's sideways speeds too: the ends of its window and
                // the speed nearest none.
                let sideways: Vec<f64> = if robot.kinematics == KinematicsKind::Omni {
                    let (vy0, vy_max) = (me.velocity().vy, robot.lateral_speed_px());
                    let (lo, hi) = ((vy0 - accel).max(-vy_max), (vy0 + accel).min(vy_max));
                    let mut s = vec![lo, 0.0f64.clamp(lo, hi), hi];
                    s.dedup();
                    s
                } else {
                    Vec::new()
                };
                let mut out = Vec::new();
                for i in 0..dwa.speed_samples {
                    let v = across(v_lo, v_hi, dwa.speed_samples, i);
                    for j in 0..dwa.turn_samples {
                        let w_deg = across(w_lo, w_hi, dwa.turn_samples, j);
                        if sideways.is_empty() {
                            let a = Action::Continuous { v, w_deg };
                            out.push((a, a, v));
                        }
                        for &vy in &sideways {
                            let a = Action::Omni { vx: v, vy, w_deg };
                            out.push((a, a, v.hypot(vy)));
                        }
                    }
                }
                out
            }
        };
        let body = Robot::new(robot);
        let mut best: Option<(bool, f64, Action)> = None;
        for (first, then, speed) in candidates {
            let roll = self.roll(me, senses, &body, first, then);
            // Steps it takes to stop from `speed` (a discrete robot stops at once).
            let stopping = match dwa.actions {
                PlannerActions::Continuous => (speed / dwa.linear_accel_px).ceil().max(1.0),
                PlannerActions::Discrete => 1.0,
            };
            let admissible = roll.first_clear
                && (roll.free_steps == dwa.horizon_steps || f64::from(roll.free_steps) >= stopping);
            let score = if admissible {
                let to_aim = aim - roll.end.position();
                let heading = if to_aim.norm() < 1e-9 {
                    1.0
                } else {
                    let bearing = to_aim.y.atan2(to_aim.x).to_degrees();
                    let off = (wrap_deg(bearing - roll.end.z_deg + 180.0) - 180.0).abs();
                    1.0 - off / 180.0
                };
                let clearance = f64::from(roll.free_steps) / f64::from(dwa.horizon_steps);
                dwa.heading_weight * heading
                    + dwa.clearance_weight * clearance
                    + dwa.speed_weight
                        * if top_speed > 0.0 {
                            speed / top_speed
                        } else {
                            0.0
                        }
            } else if roll.first_clear {
                // None admissible: the latest contact, slower first.
                f64::from(roll.free_steps) - speed / (top_speed + 1.0)
            } else {
                f64::NEG_INFINITY
            };
            if best.is_none_or(|(a, s, _)| (admissible, score) > (a, s)) {
                best = Some((admissible, score, first));
            }
        }
        let action = match best {
            Some((_, score, a)) if score > f64::NEG_INFINITY => a,
            // No first step is clear: stand and turn towards the aim.
            _ => {
                let to_aim = aim - p;
                let off = wrap_deg(to_aim.y.atan2(to_aim.x).to_degrees() - me.pose().z_deg + 180.0)
                    - 180.0;
                match dwa.actions {
                    PlannerActions::Continuous => Action::Continuous {
                        v: 0.0,
                        w_deg: off.clamp(-robot.max_angular_speed_deg, robot.max_angular_speed_deg),
                    },
                    PlannerActions::Discrete if off >= 0.0 => DiscreteAction::Left.into(),
                    PlannerActions::Discrete => DiscreteAction::Right.into(),
                }
            }
        };
        self.last = match action {
            Action::Continuous { v, w_deg } | Action::Omni { vx: v, w_deg, .. } => (v, w_deg),
            Action::Discrete(_) | Action::Steer { .. } => (0.0, 0.0),
        };
        Decision::Act(action)
    }

    fn reset(&mut self, episode: &Episode) {
        if episode.steps() == 0 {
            self.last = (0.0, 0.0);
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::config::PlannerActions;
    use crate::policy::local::lone_run;

    #[test]
    fn dwa_reaches_maze_goals_without_touching_a_wall() {
        let s = lone_run(crate::SimConfig::default(), "dwa", 20);
        assert!(s.success_rate >= 0.9, "{s:?}");
        assert!(s.collisions_per_episode <= 0.05, "{s:?}");
    }

    #[test]
    fn with_discrete_actions_dwa_reaches_maze_goals() {
        let mut c = crate::SimConfig::default();
        c.dwa.actions = PlannerActions::Discrete;
        let s = lone_run(c, "dwa", 20);
        assert!(s.success_rate >= 0.8, "{s:?}");
    }
}
