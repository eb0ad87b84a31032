//! One step of a team: every running robot's motion swept against the still scene, the moving
//! obstacles and the other robots' motions, then every robot's sensing among the others.

use super::{disc, places_into, sweeps_touch, Broadcast, Team};
use crate::geometry::Point;
use crate::sim::episode::Status;
use crate::sim::moving::Disc;
use crate::sim::robot::{Action, Motion};

impl Team {
    /// One step: `actions[k]` for each robot (`None`: it does nothing, as a robot whose episode
    /// is over). Moving obstacles move first, then every running robot at once. A lone robot's
    /// team of one steps only when its robot acts, as its episode has no step without an action.
    pub fn step(&mut self, actions: &[Option<Action>]) {
        if self.is_done() {
            return;
        }
        if self.lone {
            if let Some(action) = actions.first().copied().flatten() {
                self.steps += 1;
                self.step_alone(action);
            }
            return;
        }
        self.steps += 1;
        let n = self.robots.len();
        if let Some(action) = self.alone(actions) {
            self.step_alone(action);
            return;
        }
        // The step's buffers, kept between steps.
        let mut s = self.scratch.take().unwrap_or_default();
        s.present.clear();
        s.present.extend((0..n).filter(|&k| self.present(k)));
        // What every robot in the scene broadcasts now, received after the step.
        let sent = self.broadcasts(s.present.iter().copied());
        s.discs.clear();
        s.discs
            .extend(s.present.iter().map(|&k| disc(&self.robots[k])));
        reset(&mut s.touched, n, false);
        if let Some(movers) = &mut self.movers {
            let scene = self.robots[0].scene().clone();
            movers.advance_among(self.steps, &scene, &s.discs, &mut self.touched);
            for &i in &self.touched {
                s.touched[s.present[i]] = true;
            }
        }
        // Each running robot's motion and what the still scene and the obstacles say of it.
        s.running.clear();
        s.running.extend((0..n).map(|k| self.running(k)));
        reset(&mut s.motions, n, None);
        reset(&mut s.wall, n, false);
        reset(&mut s.moving, n, false);
        for k in 0..n {
            let Some(action) = actions.get(k).copied().flatten().filter(|_| s.running[k]) else {
                continue;
            };
            let m = self.robots[k].motion(action);
            let r = &self.robots[k];
            s.wall[k] = !r.robot().motion_clear(r.scene(), r.pose(), &m);
            s.moving[k] = match &self.movers {
                Some(movers) => !r
                    .robot()
                    .motion_clear_by(r.pose(), &m, |a, b, rad| movers.sweep_clear(a, b, rad)),
                None => false,
            };
            s.motions[k] = Some(m);
        }
        // Robots against robots, until no remaining motion touches another robot.
        s.ends.clear();
        s.ends.extend((0..n).map(|k| match &s.motions[k] {
            Some(m) if !s.wall[k] && !s.moving[k] => m.end.position(),
            _ => self.robots[k].pose().position(),
        }));
        s.starts.clear();
        s.starts
            .extend(self.robots.iter().map(|r| r.pose().position()));
        s.radii.clear();
        s.radii
            .extend(self.robots.iter().map(|r| r.config().robot.radius_px));
        reset(&mut s.blocked, n, false);
        let (ends, starts, radii) = (&s.ends, &s.starts, &s.radii);
        let moves = |k: usize, blocked: &[bool]| !blocked[k] && ends[k] != starts[k];
        // Each moving robot's candidates: the robots within its reach of its start, in index
        // order (the exact test below decides).
        self.grid_before
            .fill(s.present.iter().map(|&k| (k, starts[k])));
        let max_move = s
            .present
            .iter()
            .map(|&k| (ends[k] - starts[k]).norm())
            .fold(0.0, f64::max);
        reset(&mut s.near_start, n + 1, 0);
        s.near.clear();
        for k in 0..n {
            s.near_start[k] = s.near.len();
            if s.present.binary_search(&k).is_ok() && moves(k, &s.blocked) {
                let reach = (ends[k] - starts[k]).norm() + max_move + radii[k] + self.max_radius;
                self.grid_before.near(starts[k], reach, &mut s.found);
                s.near.extend(s.found.iter().filter(|&&j| j as usize != k));
            }
        }
        s.near_start[n] = s.near.len();
        loop {
            let mut changed = false;
            for &i in &s.present {
                if !moves(i, &s.blocked) {
                    continue;
                }
                for &j in &s.near[s.near_start[i]..s.near_start[i + 1]] {
                    let j = j as usize;
                    let reach = radii[i] + radii[j];
                    let (j0, j1) = if moves(j, &s.blocked) {
                        (starts[j], ends[j])
                    } else {
                        (starts[j], starts[j])
                    };
                    // Far apart: neither sweep can reach the other.
                    let span = (ends[i] - starts[i]).norm() + (j1 - j0).norm() + reach;
                    if (starts[i] - starts[j]).norm() > span {
                        continue;
                    }
                    if sweeps_touch(starts[i], ends[i], j0, j1, reach) {
                        s.blocked[i] = true;
                        if moves(j, &s.blocked) {
                            s.blocked[j] = true;
                        }
                        changed = true;
                        break;
                    }
                }
            }
            if !changed {
                break;
            }
        }
        // Make the motions, then read every sensor among everyone's new poses.
        let mut collided = std::mem::take(&mut self.collided);
        collided.clear();
        collided.resize(n, false);
        s.before.clear();
        s.before.extend(self.robots.iter().map(|r| r.distance_px()));
        let mut moved_any = false;
        for (k, c) in collided.iter_mut().enumerate() {
            if let Some(m) = &s.motions[k] {
                *c = self.robots[k].apply(m, s.wall[k], s.moving[k], s.touched[k], s.blocked[k]);
                moved_any |= self.robots[k].pose().position() != s.starts[k];
                if let Some(action) = actions.get(k).copied().flatten() {
                    self.robots[k].remember(action);
                }
            }
        }
        self.scratch = Some(s);
        self.sense_all();
        self.deliver(sent);
        let s = self.scratch.take().unwrap_or_default();
        for (k, &c) in collided.iter().enumerate() {
            self.rewards[k] = 0.0;
            if let Some(m) = &s.motions[k] {
                self.rewards[k] = self.robots[k].score(s.before[k], m, c);
                if self.robots[k].status() == Status::Success {
                    self.arrived_at[k].get_or_insert(self.steps);
                }
            }
        }
        self.scratch = Some(s);
        self.collided = collided;
        self.still_for = if moved_any { 0 } else { self.still_for + 1 };
        // A deadlock is a team's: a team of one that stands still is a lone robot that does,
        // and runs on as one would (to its time-out, or until its policy gives up). In a team of
        // two or more, the robots still running deadlock even when the others are done.
        if n > 1 && self.still_for >= self.deadlock_steps {
            for k in 0..n {
                if self.running(k) {
                    self.robots[k].end(Status::Deadlock);
                }
            }
        }
    }

    /// What robots `from` broadcast now (pose, goal and message), in the buffer of the last
    /// step's broadcasts; each one's next message starts from zeros.
    fn broadcasts(&mut self, from: impl Iterator<Item = usize>) -> Vec<Broadcast> {
        let mut sent = std::mem::take(&mut self.sent);
        sent.clear();
        for k in from {
            let size = self.comm.message_size as usize;
            let message = std::mem::replace(&mut self.outbox[k], vec![0.0; size]);
            let r = &self.robots[k];
            sent.push(Broadcast {
                from: k,
                pose: r.pose(),
                goal: r.goal(),
                message,
            });
        }
        sent
    }

    /// The action of a team of one without moving obstacles whose robot acts this step: such a
    /// step is the lone robot's ([`Team::step_alone`]). `None` for any other step.
    fn alone(&self, actions: &[Option<Action>]) -> Option<Action> {
        if self.robots.len() != 1 || self.movers.is_some() || !self.running(0) {
            return None;
        }
        actions.first().copied().flatten()
    }

    /// A step of a team of one robot, acting alone among still obstacles: the robot's own
    /// episode steps as a lone robot's does, which is what the team's step would do (no other
    /// robot to block it, sense or send to), at a lone robot's speed.
    fn step_alone(&mut self, action: Action) {
        let at = self.robots[0].pose().position();
        // What it broadcasts no one receives, its next message starts from zeros and it hears
        // nothing (a lone robot's team of one never talks).
        if !self.lone {
            self.sent.clear();
            self.outbox[0].fill(0.0);
            self.inbox.clear();
            self.inbox_starts.fill(0);
        }
        let r = self.robots[0].step(action);
        let (reward, collided) = (r.reward, r.collided);
        self.rewards[0] = reward;
        self.collided[0] = collided;
        if self.robots[0].status() == Status::Success {
            self.arrived_at[0].get_or_insert(self.steps);
        }
        let moved = self.robots[0].pose().position() != at;
        self.still_for = if moved { 0 } else { self.still_for + 1 };
    }

    /// Every running robot reads its sensors among the others (discs) and the obstacles.
    pub(super) fn sense_all(&mut self) {
        let n = self.robots.len();
        let mut s = self.scratch.take().unwrap_or_default();
        s.placed.clear();
        s.placed.extend(
            (0..n)
                .filter(|&k| self.present(k))
                .map(|k| (k, disc(&self.robots[k]))),
        );
        places_into(&mut s.of, s.placed.iter().map(|(k, _)| *k), n);
        let movers = self.movers.take();
        self.grid_after
            .fill(s.placed.iter().map(|(k, d)| (*k, d.at)));
        for k in 0..n {
            if !self.running(k) && self.steps > 0 {
                continue;
            }
            // The robots the laser can reach, in any order (sense_among keeps its exact test,
            // and a reading is the least of the distances its beam meets, whatever their
            // order: robots never overlap, so no two robots give a beam the same distance 0).
            let r = &self.robots[k];
            let reach = r.laser().range_px() + r.config().robot.radius_px + self.max_radius;
            self.grid_after
                .near_any_order(r.pose().position(), reach, &mut s.found);
            s.others.clear();
            s.others.extend(
                s.found
                    .iter()
                    .filter(|&&j| j as usize != k)
                    .filter_map(|&j| s.of[j as usize].map(|m| s.placed[m as usize].1)),
            );
            self.robots[k].sense_among(movers.as_deref(), &s.others);
        }
        self.scratch = Some(s);
        self.movers = movers;
    }
}

/// `v` made `n` copies of `value`, keeping its allocation.
fn reset<T: Clone>(v: &mut Vec<T>, n: usize, value: T) {
    v.clear();
    v.resize(n, value);
}

/// Buffers a team's step reuses, so that once the team has stepped a step allocates nothing but
/// the robots' messages (none with `team.message_size = 0`).
#[derive(Clone, Debug, Default)]
pub(super) struct Scratch {
    present: Vec<usize>,
    discs: Vec<Disc>,
    touched: Vec<bool>,
    running: Vec<bool>,
    motions: Vec<Option<Motion>>,
    wall: Vec<bool>,
    moving: Vec<bool>,
    ends: Vec<Point>,
    starts: Vec<Point>,
    radii: Vec<f64>,
    blocked: Vec<bool>,
    near_start: Vec<usize>,
    near: Vec<u32>,
    pub(super) found: Vec<u32>,
    before: Vec<f64>,
    /// The robots in the scene as discs, for sensing, and each robot's place among them.
    placed: Vec<(usize, Disc)>,
    pub(super) of: Vec<Option<u32>>,
    others: Vec<Disc>,
    /// The broadcasts a robot hears, by distance and place in the step's list.
    pub(super) heard: Vec<(f64, u32)>,
}
