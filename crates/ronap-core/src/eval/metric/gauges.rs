//! The evaluator's side of the metric seam: a [`Metric`] of each asked-for [`Kind`] per robot,
//! shown every robot after every step with the agents around it.

use crate::config::ValidConfig;
use crate::eval::metric::{kinds, End, Metric, Other, View};
use crate::geometry::{Point, Vector};
use crate::sim::{Body, Episode, Movers, Team};

/// The metrics of one robot, and where it was when they last saw it.
struct Robot {
    metrics: Vec<Box<dyn Metric>>,
    last: Option<Point>,
    seen_steps: Option<u32>,
}

/// The asked-for metrics of every robot of an episode as it runs.
pub(crate) struct Gauges {
    robots: Vec<Robot>,
    /// Where each moving obstacle was at the last watch (`None`: absent).
    movers: Vec<Option<Point>>,
    /// Scratch: the agents round the robot being shown.
    others: Vec<Other>,
    /// Scratch: each robot's centre now.
    now: Vec<Point>,
}

impl Gauges {
    /// Gauges for `robots` robots under `config`; `None` when it asks for no metric (then nothing
    /// is measured).
    pub(crate) fn start(config: &ValidConfig, robots: usize) -> Option<Self> {
        let kinds = kinds(config);
        (!kinds.is_empty()).then(|| Self {
            robots: (0..robots)
                .map(|_| Robot {
                    metrics: kinds.iter().map(|k| (k.make)(config)).collect(),
                    last: None,
                    seen_steps: None,
                })
                .collect(),
            movers: Vec::new(),
            others: Vec::new(),
            now: Vec::new(),
        })
    }

    /// Shows a team, at its start and after each step.
    pub(crate) fn watch_team(&mut self, team: &Team) {
        self.watch(team.robots(), |k| team.present(k), team.movers());
    }

    /// Shows each robot that acted since the last watch (every robot at the first) the moving
    /// obstacles and the other robots present.
    fn watch(
        &mut self,
        robots: &[Episode],
        present: impl Fn(usize) -> bool,
        movers: Option<&Movers>,
    ) {
        self.now.clear();
        self.now.extend(robots.iter().map(|r| r.pose().position()));
        let mut moving = Vec::new();
        if let Some(movers) = movers {
            self.movers.resize(movers.items().len(), None);
            for (m, last) in movers.items().zip(&mut self.movers) {
                let at = m.present().then(|| m.position());
                if let Some(at) = at {
                    moving.push(Other {
                        at,
                        body: m.body(),
                        velocity: last.map_or(Vector::zeros(), |l| at - l),
                    });
                }
                *last = at;
            }
        }
        for (k, robot) in robots.iter().enumerate() {
            let steps = robot.steps();
            if self.robots[k].seen_steps == Some(steps) || !present(k) {
                continue;
            }
            self.others.clear();
            self.others.extend_from_slice(&moving);
            for (j, other) in robots.iter().enumerate() {
                if j != k && present(j) {
                    let at = self.now[j];
                    self.others.push(Other {
                        at,
                        body: Body::Disc(other.config().robot.radius_px),
                        velocity: self.robots[j].last.map_or(Vector::zeros(), |l| at - l),
                    });
                }
            }
            let me = &self.robots[k];
            let view = View {
                step: steps,
                pose: robot.pose(),
                radius_px: robot.config().robot.radius_px,
                velocity: me.last.map_or(Vector::zeros(), |l| self.now[k] - l),
                goal: robot.goal(),
                others: &self.others,
            };
            for m in &mut self.robots[k].metrics {
                m.observe(&view);
            }
            self.robots[k].seen_steps = Some(steps);
        }
        for (r, &at) in self.robots.iter_mut().zip(&self.now) {
            r.last = Some(at);
        }
    }

    /// Robot `k`'s value of each metric, its episode having ended as `end`.
    pub(crate) fn values(&self, k: usize, end: &End) -> Vec<Option<f64>> {
        self.robots
            .get(k)
            .map(|r| r.metrics.iter().map(|m| m.value(end)).collect())
            .unwrap_or_default()
    }
}

#[cfg(test)]
mod tests {
    use crate::eval::{Evaluator, Recording};
    use crate::policy::factory;
    use crate::sim::Scenes;

    /// Episodes among pedestrians with the crowd metrics on, recording what pictures need.
    fn evaluator() -> Evaluator {
        let mut c = crate::config::maze_pedestrians();
        c.metrics.crowd = true;
        c.metrics.discomfort_px = 8.0;
        Evaluator::new(c.validate().expect("valid"), Scenes::MazePerSeed)
    }

    #[test]
    fn intrusions_agree_with_the_recorded_trajectory_and_tracks() {
        let ev = evaluator();
        let f = factory("geodesic", ev.config().observation_size()).expect("geodesic");
        let recording = Recording {
            trajectory: true,
            steps: false,
        };
        let mut intruded_somewhere = false;
        for seed in 0..6 {
            let mut policy = f.make().expect("policy");
            let r = ev
                .run_episode(policy.as_mut(), seed, recording)
                .expect("runs");
            assert_eq!(r.metrics.len(), 6);
            // Recomputed from the pictures' record: the robot's poses and each pedestrian's
            // centre at every step.
            let radius = ev.config().robot.radius_px;
            let mut intruded = 0;
            let mut least = f64::INFINITY;
            for (i, pose) in r.trajectory.iter().enumerate().skip(1) {
                let gap = r
                    .mover_tracks
                    .iter()
                    .filter_map(|t| t.points[i].map(|at| t.body.gap(at, pose.position(), radius)))
                    .fold(f64::INFINITY, f64::min);
                if gap < 8.0 {
                    intruded += 1;
                    least = least.min(gap);
                }
            }
            let ratio = f64::from(intruded) / f64::from(r.steps.max(1));
            assert_eq!(r.metrics[1], Some(ratio), "seed {seed}");
            assert_eq!(r.metrics[2], (intruded > 0).then_some(least), "seed {seed}");
            intruded_somewhere |= intruded > 0;
            // Time to goal is the steps of a success.
            let success = r.outcome == crate::eval::Outcome::Success;
            assert_eq!(r.metrics[0], success.then_some(f64::from(r.steps)));
        }
        assert!(intruded_somewhere, "no episode came near a pedestrian");
    }

    #[test]
    fn a_team_sees_its_other_robots() {
        let mut c = crate::SimConfig {
            robots: vec![crate::config::TeamRobotConfig {
                count: 6,
                ..Default::default()
            }],
            ..Default::default()
        };
        c.metrics.crowd = true;
        let ev = Evaluator::new(c.validate().expect("valid"), Scenes::MazePerSeed);
        let f = factory("geodesic", ev.config().observation_size()).expect("geodesic");
        let team = crate::policy::PerRobotFactory::new(
            (0..6).map(|_| f.as_ref()).collect(),
            vec!["geodesic".to_string(); 6],
        );
        let mut policy = crate::policy::TeamPolicyFactory::make(&team).expect("team");
        let names = vec!["geodesic".to_string(); 6];
        let recording = Recording {
            trajectory: true,
            steps: false,
        };
        let mut near = 0;
        for seed in 0..4 {
            let r = ev
                .run_team_episode(policy.as_mut(), &names, seed, recording)
                .expect("runs");
            for x in &r.robots {
                assert_eq!(x.metrics.len(), 6);
                let ratio = x.metrics[1].expect("a ratio");
                assert!((0.0..=1.0).contains(&ratio));
                // The least time to collision is that of some other robot's course.
                assert!(x.metrics[3].is_some_and(|t| t >= 0.0) || x.metrics[3].is_none());
                near += usize::from(ratio > 0.0);
            }
        }
        // Six robots in one maze come within the discomfort distance of each other.
        assert!(near > 0);
    }
}
