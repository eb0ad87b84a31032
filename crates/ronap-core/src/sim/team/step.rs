//! One step of a team: every running robot's motion swept against the still scene, the moving
//! obstacles and the other robots' motions, then every robot's sensing among the others.

use super::{disc, places_of, sweeps_touch, Broadcast, Team};
use crate::geometry::Point;
use crate::sim::episode::Status;
use crate::sim::moving::Disc;
use crate::sim::robot::{Action, Motion};

impl Team {
    /// One step: `actions[k]` for each robot (`None`: it does nothing, as a robot whose episode
    /// is over). Moving obstacles move first, then every running robot at once.
    pub fn step(&mut self, actions: &[Option<Action>]) {
        if self.is_done() {
            return;
        }
        self.steps += 1;
        let n = self.robots.len();
        let present: Vec<usize> = (0..n).filter(|&k| self.present(k)).collect();
        // What every robot in the scene broadcasts now, received after the step.
        let sent: Vec<Broadcast> = present
            .iter()
            .map(|&k| Broadcast {
                from: k,
                pose: self.robots[k].pose(),
                goal: self.robots[k].goal(),
                message: std::mem::replace(
                    &mut self.outbox[k],
                    vec![0.0; self.comm.message_size as usize],
                ),
            })
            .collect();
        let discs: Vec<Disc> = present.iter().map(|&k| disc(&self.robots[k])).collect();
        let mut touched = vec![false; n];
        if let Some(movers) = &mut self.movers {
            let scene = self.robots[0].scene().clone();
            movers.advance_among(self.steps, &scene, &discs, &mut self.touched);
            for &i in &self.touched {
                touched[present[i]] = true;
            }
        }
        // Each running robot's motion and what the still scene and the obstacles say of it.
        let running: Vec<bool> = (0..n).map(|k| self.running(k)).collect();
        let mut motions: Vec<Option<Motion>> = vec![None; n];
        let mut wall = vec![false; n];
        let mut moving = vec![false; n];
        for k in 0..n {
            let Some(action) = actions.get(k).copied().flatten().filter(|_| running[k]) else {
                continue;
            };
            let m = self.robots[k].motion(action);
            let r = &self.robots[k];
            wall[k] = !r.robot().motion_clear(r.scene(), r.pose(), &m);
            moving[k] = match &self.movers {
                Some(movers) => !r
                    .robot()
                    .motion_clear_by(r.pose(), &m, |a, b, rad| movers.sweep_clear(a, b, rad)),
                None => false,
            };
            motions[k] = Some(m);
        }
        // Robots against robots, until no remaining motion touches another robot.
        let ends: Vec<Point> = (0..n)
            .map(|k| match &motions[k] {
                Some(m) if !wall[k] && !moving[k] => m.end.position(),
                _ => self.robots[k].pose().position(),
            })
            .collect();
        let starts: Vec<Point> = self.robots.iter().map(|r| r.pose().position()).collect();
        let radii: Vec<f64> = self
            .robots
            .iter()
            .map(|r| r.config().robot.radius_px)
            .collect();
        let mut blocked = vec![false; n];
        let moves = |k: usize, blocked: &[bool]| !blocked[k] && ends[k] != starts[k];
        // Each moving robot's candidates: the robots within its reach of its start, in index
        // order (the exact test below decides).
        self.grid_before
            .fill(present.iter().map(|&k| (k, starts[k])));
        let max_move = present
            .iter()
            .map(|&k| (ends[k] - starts[k]).norm())
            .fold(0.0, f64::max);
        let mut near_start = vec![0usize; n + 1];
        let mut near: Vec<u32> = Vec::new();
        let mut found = Vec::new();
        for k in 0..n {
            near_start[k] = near.len();
            if present.binary_search(&k).is_ok() && moves(k, &blocked) {
                let reach = (ends[k] - starts[k]).norm() + max_move + radii[k] + self.max_radius;
                self.grid_before.near(starts[k], reach, &mut found);
                near.extend(found.iter().filter(|&&j| j as usize != k));
            }
        }
        near_start[n] = near.len();
        loop {
            let mut changed = false;
            for &i in &present {
                if !moves(i, &blocked) {
                    continue;
                }
                for &j in &near[near_start[i]..near_start[i + 1]] {
                    let j = j as usize;
                    let reach = radii[i] + radii[j];
                    let (j0, j1) = if moves(j, &blocked) {
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
                        blocked[i] = true;
                        if moves(j, &blocked) {
                            blocked[j] = true;
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
        let before: Vec<f64> = self.robots.iter().map(|r| r.distance_px()).collect();
        let mut moved_any = false;
        for k in 0..n {
            if let Some(m) = &motions[k] {
                collided[k] = self.robots[k].apply(m, wall[k], moving[k], touched[k], blocked[k]);
                moved_any |= self.robots[k].pose().position() != starts[k];
            }
        }
        self.sense_all();
        self.deliver(sent);
        for k in 0..n {
            self.rewards[k] = 0.0;
            if let Some(m) = &motions[k] {
                self.rewards[k] = self.robots[k].score(before[k], m, collided[k]);
                if self.robots[k].status() == Status::Success {
                    self.arrived_at[k].get_or_insert(self.steps);
                }
            }
        }
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

    /// Every running robot reads its sensors among the others (discs) and the obstacles.
    pub(super) fn sense_all(&mut self) {
        let n = self.robots.len();
        let discs: Vec<(usize, Disc)> = (0..n)
            .filter(|&k| self.present(k))
            .map(|k| (k, disc(&self.robots[k])))
            .collect();
        let of = places_of(discs.iter().map(|(k, _)| *k), n);
        let movers = self.movers.take();
        self.grid_after.fill(discs.iter().map(|(k, d)| (*k, d.at)));
        let mut others = Vec::with_capacity(discs.len());
        let mut found = Vec::new();
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
                .near_any_order(r.pose().position(), reach, &mut found);
            others.clear();
            others.extend(
                found
                    .iter()
                    .filter(|&&j| j as usize != k)
                    .filter_map(|&j| of[j as usize].map(|m| discs[m as usize].1)),
            );
            self.robots[k].sense_among(movers.as_deref(), &others);
        }
        self.movers = movers;
    }
}
