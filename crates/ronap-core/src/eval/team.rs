//! Evaluating teams (SPEC "Several robots", metrics): per-robot records beside team figures
//! (team success: every robot arrived; makespan; summed path length; robot collisions;
//! deadlocks), and their summary.

use crate::eval::summary::wilson95;
use crate::eval::{EvalOptions, Evaluator, Outcome};
use crate::geometry::Point;
use crate::plan::shortest_path_px;
use crate::policy::{PolicyError, PolicyFactory};
use crate::run::team::TeamRollout;
use crate::run::RunError;
use crate::sim::robot::Pose;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Instant;

/// One robot of a finished team episode.
#[derive(Clone, Debug, PartialEq)]
pub struct RobotRecord {
    /// Its index in the team.
    pub robot: usize,
    /// The policy that drove it.
    pub policy: String,
    /// How its episode ended.
    pub outcome: Outcome,
    /// Why its policy gave up, for [`Outcome::Stuck`].
    pub reason: Option<String>,
    /// Steps it acted.
    pub steps: u32,
    /// The team step at which it reached its goal.
    pub arrived_at: Option<u32>,
    /// Steps a wall blocked.
    pub collisions: u32,
    /// Steps another robot blocked.
    pub robot_collisions: u32,
    /// Steps with contact with a moving obstacle, when there were some.
    pub dynamic_collisions: Option<u32>,
    /// Distance driven, px.
    pub path_length_px: f64,
    /// Goals it had (1, or a goal list's length).
    pub goals: u32,
    /// Goals it reached.
    pub goals_reached: u32,
    /// A goal list's tour lengths (the driven order's and the optimal one), px.
    pub tour: Option<crate::run::team::TourLengths>,
    /// Its shortest path from start to within epsilon of the goal (on success; through every
    /// goal of a list, the optimal tour less the tolerance at each end of each leg), px.
    pub shortest_px: Option<f64>,
    /// SPL.
    pub spl: f64,
    /// Summed reward.
    pub total_reward: f64,
    /// Start pose.
    pub start: Pose,
    /// Final pose.
    pub end: Pose,
    /// Goal.
    pub goal: Point,
}

impl RobotRecord {
    /// The robot's episode as a lone robot's record (its figures; no trajectory), so the usual
    /// [`crate::eval::Summary`] can sum up a team run's robots.
    pub fn as_episode(&self, seed: u64) -> crate::eval::EpisodeRecord {
        crate::eval::EpisodeRecord {
            seed,
            outcome: self.outcome,
            reason: self.reason.clone(),
            steps: self.steps,
            collisions: self.collisions,
            path_length_px: self.path_length_px,
            shortest_px: self.shortest_px,
            spl: self.spl,
            total_reward: self.total_reward,
            wall_time_s: 0.0,
            start: self.start,
            goal: self.goal,
            end: self.end,
            last_readings: Vec::new(),
            trajectory: Vec::new(),
            mover_tracks: Vec::new(),
            dynamic: None,
            step_log: Vec::new(),
            world: None,
        }
    }
}

/// One finished team episode.
#[derive(Clone, Debug)]
pub struct TeamRecord {
    /// The seed.
    pub seed: u64,
    /// The team's outcome: success when every robot arrived; else a deadlock, a time-out, a
    /// collision end or a policy that gave up, in that order of precedence.
    pub outcome: Outcome,
    /// Team steps taken.
    pub steps: u32,
    /// The step the last robot arrived at, when all did.
    pub makespan: Option<u32>,
    /// Summed distance driven, px.
    pub path_length_px: f64,
    /// Summed steps walls blocked.
    pub collisions: u32,
    /// Summed steps other robots blocked.
    pub robot_collisions: u32,
    /// Whether it ended in a deadlock.
    pub deadlock: bool,
    /// Each robot's record.
    pub robots: Vec<RobotRecord>,
    /// Wall time, seconds.
    pub wall_time_s: f64,
    /// Each robot's centre at every step from the start (while present), when recorded.
    pub paths: Vec<Vec<Point>>,
    /// The scene, when paths were recorded (for pictures).
    pub scene: Option<Arc<crate::Scene>>,
}

/// The figures of a set of team episodes.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TeamSummary {
    /// Team episodes finished.
    pub episodes: usize,
    /// Robots per episode.
    pub robots: usize,
    /// Episodes where every robot arrived.
    pub team_successes: usize,
    /// Their fraction.
    pub team_success_rate: f64,
    /// Its 95% Wilson interval.
    pub team_success_ci95: [f64; 2],
    /// Fraction of all robots that arrived.
    pub robot_success_rate: f64,
    /// Episodes that ended in a deadlock.
    pub deadlocks: usize,
    /// Mean makespan over the team successes, steps.
    pub mean_makespan: f64,
    /// Mean summed path length, px.
    pub mean_path_length_px: f64,
    /// Mean robot collisions (blocked robot steps) per episode.
    pub robot_collisions_per_episode: f64,
    /// Mean wall collisions per episode.
    pub collisions_per_episode: f64,
    /// Mean SPL over all robots.
    pub spl: f64,
    /// Wall time, seconds.
    pub wall_time_s: f64,
    /// Robot steps per second of wall time.
    pub robot_steps_per_second: f64,
}

impl TeamSummary {
    /// The summary of `records`, over a run that took `wall_time_s`.
    pub fn new(records: &[TeamRecord], wall_time_s: f64) -> Self {
        let n = records.len();
        let per = |x: f64| if n == 0 { 0.0 } else { x / n as f64 };
        let team_successes = records
            .iter()
            .filter(|r| r.outcome == Outcome::Success)
            .count();
        let robots: Vec<&RobotRecord> = records.iter().flat_map(|r| &r.robots).collect();
        let makespans: Vec<f64> = records
            .iter()
            .filter_map(|r| r.makespan.map(f64::from))
            .collect();
        let robot_steps: u64 = robots.iter().map(|r| u64::from(r.steps)).sum();
        Self {
            episodes: n,
            robots: records.first().map_or(0, |r| r.robots.len()),
            team_successes,
            team_success_rate: per(team_successes as f64),
            team_success_ci95: wilson95(team_successes, n),
            robot_success_rate: if robots.is_empty() {
                0.0
            } else {
                robots
                    .iter()
                    .filter(|r| r.outcome == Outcome::Success)
                    .count() as f64
                    / robots.len() as f64
            },
            deadlocks: records.iter().filter(|r| r.deadlock).count(),
            mean_makespan: if makespans.is_empty() {
                0.0
            } else {
                makespans.iter().sum::<f64>() / makespans.len() as f64
            },
            mean_path_length_px: per(records.iter().map(|r| r.path_length_px).sum()),
            robot_collisions_per_episode: per(records
                .iter()
                .map(|r| f64::from(r.robot_collisions))
                .sum()),
            collisions_per_episode: per(records.iter().map(|r| f64::from(r.collisions)).sum()),
            spl: if robots.is_empty() {
                0.0
            } else {
                robots.iter().map(|r| r.spl).sum::<f64>() / robots.len() as f64
            },
            wall_time_s,
            robot_steps_per_second: if wall_time_s > 0.0 {
                robot_steps as f64 / wall_time_s
            } else {
                0.0
            },
        }
    }

    /// The summary as an aligned two-column table.
    pub fn table(&self) -> String {
        let pct = |x: f64| format!("{:.1}%", 100.0 * x);
        let rows: Vec<(&str, String)> = vec![
            (
                "episodes",
                format!("{} ({} robots each)", self.episodes, self.robots),
            ),
            (
                "team success",
                format!(
                    "{} ({} of {}; 95% CI {} to {}; every robot arrived)",
                    pct(self.team_success_rate),
                    self.team_successes,
                    self.episodes,
                    pct(self.team_success_ci95[0]),
                    pct(self.team_success_ci95[1])
                ),
            ),
            ("robots arrived", pct(self.robot_success_rate)),
            ("deadlocks", self.deadlocks.to_string()),
            (
                "mean makespan",
                if self.team_successes > 0 {
                    format!("{:.1} steps (over the team successes)", self.mean_makespan)
                } else {
                    "none (no team success)".to_string()
                },
            ),
            (
                "mean summed path",
                format!("{:.1} px", self.mean_path_length_px),
            ),
            (
                "robot collisions",
                format!("{:.2} per episode", self.robot_collisions_per_episode),
            ),
            (
                "wall collisions",
                format!("{:.2} per episode", self.collisions_per_episode),
            ),
            ("SPL (per robot)", format!("{:.3}", self.spl)),
            ("wall time", format!("{:.2} s", self.wall_time_s)),
            (
                "robot steps per second",
                format!("{:.0}", self.robot_steps_per_second),
            ),
        ];
        let width = rows.iter().map(|(k, _)| k.len()).max().unwrap_or(0);
        rows.iter()
            .map(|(k, v)| format!("{k:<width$}  {v}\n"))
            .collect()
    }
}

/// What a team evaluation produced.
#[derive(Debug)]
pub struct TeamRunResult {
    /// Finished team episodes, in seed order.
    pub records: Vec<TeamRecord>,
    /// Whether the cancel flag stopped the run before every seed ran.
    pub cancelled: bool,
    /// The first error (in seed order), if an episode failed.
    pub error: Option<RunError>,
    /// Wall time, seconds.
    pub wall_time_s: f64,
}

impl Evaluator {
    /// Runs the team episode of `seed` with `policies` (one per robot).
    /// With `paths`, keeps every robot's path and the scene (for a picture).
    pub fn run_team_episode(
        &self,
        policies: &mut [Box<dyn crate::policy::Policy>],
        names: &[String],
        seed: u64,
        paths: bool,
    ) -> Result<TeamRecord, RunError> {
        self.watch_team_episode(policies, names, seed, paths, &mut |_| {})
    }

    /// [`Evaluator::run_team_episode`], showing `watch` the team at its start and after every
    /// step (for an animation).
    pub fn watch_team_episode(
        &self,
        policies: &mut [Box<dyn crate::policy::Policy>],
        names: &[String],
        seed: u64,
        paths: bool,
        watch: &mut dyn FnMut(&crate::sim::team::Team),
    ) -> Result<TeamRecord, RunError> {
        let clock = Instant::now();
        let worlds = self.worlds().team(seed);
        let mut rollout = TeamRollout::start(self.config(), worlds, seed, policies)?;
        watch(rollout.team());
        let n = rollout.team().robots().len();
        let mut tracks: Vec<Vec<Point>> = vec![Vec::new(); if paths { n } else { 0 }];
        let note = |team: &crate::sim::team::Team, tracks: &mut Vec<Vec<Point>>| {
            for (k, t) in tracks.iter_mut().enumerate() {
                if team.present(k) {
                    t.push(team.robot(k).pose().position());
                }
            }
        };
        note(rollout.team(), &mut tracks);
        while rollout.advance(policies)? {
            note(rollout.team(), &mut tracks);
            watch(rollout.team());
        }
        let team = rollout.team();
        let mut robots = Vec::new();
        for (k, r) in team.robots().iter().enumerate() {
            let outcome = if team.retired(k) {
                Outcome::Stuck
            } else {
                Outcome::of(r.status())
            };
            let tolerance = r.config().episode.goal_tolerance_px;
            let tour = rollout.tour(k);
            // Each goal counts as reached within the tolerance: a tour of n goals can be cut by
            // up to the tolerance on arriving at each and on leaving each but the last.
            let goals = team.goals(k).len().max(1) as f64;
            let shortest_px = (outcome == Outcome::Success)
                .then(|| match tour {
                    Some(t) => Some(t.optimal).filter(|l| l.is_finite()),
                    None => shortest_path_px(rollout.world(k), r.start().position(), r.goal()),
                })
                .flatten()
                .map(|l| (l - tolerance * (2.0 * goals - 1.0)).max(0.0));
            let spl = match shortest_px {
                Some(l) if r.path_length_px() > 0.0 => l / l.max(r.path_length_px()),
                Some(_) => 1.0,
                None => 0.0,
            };
            robots.push(RobotRecord {
                robot: k,
                policy: names.get(k).cloned().unwrap_or_default(),
                outcome,
                reason: rollout.gave_up(k).map(str::to_string),
                steps: r.steps(),
                arrived_at: team.arrived_at(k),
                collisions: r.collisions(),
                robot_collisions: r.robot_collisions(),
                dynamic_collisions: r.dynamic_metrics().map(|d| d.collisions),
                goals: team.goals(k).len() as u32,
                goals_reached: r.goals_reached(),
                tour,
                path_length_px: r.path_length_px(),
                shortest_px,
                spl,
                total_reward: r.total_reward(),
                start: r.start(),
                end: r.pose(),
                goal: r.goal(),
            });
        }
        let all_arrived = robots.iter().all(|r| r.outcome == Outcome::Success);
        let deadlock = team.deadlocked();
        let worst = [
            Outcome::Deadlock,
            Outcome::Timeout,
            Outcome::Collision,
            Outcome::RewardMin,
            Outcome::Stuck,
        ]
        .into_iter()
        .find(|o| robots.iter().any(|r| r.outcome == *o));
        let outcome = if all_arrived {
            Outcome::Success
        } else {
            worst.unwrap_or(Outcome::Stuck)
        };
        Ok(TeamRecord {
            seed,
            outcome,
            steps: team.steps(),
            makespan: all_arrived.then(|| {
                robots
                    .iter()
                    .filter_map(|r| r.arrived_at)
                    .max()
                    .unwrap_or(0)
            }),
            path_length_px: robots.iter().map(|r| r.path_length_px).sum(),
            collisions: robots.iter().map(|r| r.collisions).sum(),
            robot_collisions: robots.iter().map(|r| r.robot_collisions).sum(),
            deadlock,
            robots,
            wall_time_s: clock.elapsed().as_secs_f64(),
            scene: paths.then(|| team.robot(0).scene().clone()),
            paths: tracks,
        })
    }

    /// Runs `options.seeds` as team episodes, robot `k` driven by a policy from
    /// `factories[k]` (named `names[k]`). Records come back in seed order whatever the thread
    /// count; `on_record` hears each as it finishes; `cancel` stops the run between episodes.
    pub fn run_team(
        &self,
        factories: &[&dyn PolicyFactory],
        names: &[String],
        options: &EvalOptions,
        cancel: &AtomicBool,
        on_record: &(dyn Fn(&TeamRecord) + Sync),
    ) -> Result<TeamRunResult, PolicyError> {
        let clock = Instant::now();
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(options.threads)
            .build()
            .map_err(|e| PolicyError::Failed(format!("cannot start worker threads: {e}")))?;
        let first_policy_error: Mutex<Option<PolicyError>> = Mutex::new(None);
        let results: Vec<Option<Result<TeamRecord, RunError>>> = pool.install(|| {
            options
                .seeds
                .par_iter()
                .with_max_len(1)
                .map(|&seed| {
                    if cancel.load(Ordering::Relaxed) {
                        return None;
                    }
                    let made: Result<Vec<_>, _> = factories.iter().map(|f| f.make()).collect();
                    let mut policies = match made {
                        Ok(p) => p,
                        Err(e) => {
                            cancel.store(true, Ordering::Relaxed);
                            if let Ok(mut slot) = first_policy_error.lock() {
                                slot.get_or_insert(e);
                            }
                            return None;
                        }
                    };
                    let paths = options.recording.trajectory;
                    let result = self
                        .run_team_episode(&mut policies, names, seed, paths)
                        .map(|mut r| {
                            on_record(&r);
                            r.paths = Vec::new();
                            r.scene = None;
                            r
                        });
                    if result.is_err() {
                        cancel.store(true, Ordering::Relaxed);
                    }
                    Some(result)
                })
                .collect()
        });
        if let Some(e) = first_policy_error.into_inner().ok().flatten() {
            return Err(e);
        }
        let mut records = Vec::with_capacity(results.len());
        let mut error = None;
        let mut cancelled = false;
        for r in results {
            match r {
                Some(Ok(record)) => records.push(record),
                Some(Err(e)) => {
                    error.get_or_insert(e);
                }
                None => cancelled = true,
            }
        }
        Ok(TeamRunResult {
            records,
            cancelled: cancelled && error.is_none(),
            error,
            wall_time_s: clock.elapsed().as_secs_f64(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::TeamRobotConfig;
    use crate::policy::factory;
    use crate::sim::world::Scenes;

    fn evaluator(count: u32) -> Evaluator {
        let config = crate::SimConfig {
            robots: vec![TeamRobotConfig {
                count,
                ..Default::default()
            }],
            ..Default::default()
        }
        .validate()
        .expect("valid");
        Evaluator::new(config, Scenes::MazePerSeed)
    }

    #[test]
    fn team_runs_are_the_same_on_one_and_two_threads() {
        let ev = evaluator(4);
        let f = factory("geodesic", ev.config().observation_size()).expect("geodesic");
        let factories: Vec<&dyn PolicyFactory> = (0..4).map(|_| f.as_ref()).collect();
        let names = vec!["geodesic".to_string(); 4];
        let run = |threads| {
            let options = EvalOptions {
                seeds: (0..8).collect(),
                threads,
                ..Default::default()
            };
            ev.run_team(
                &factories,
                &names,
                &options,
                &AtomicBool::new(false),
                &|_| {},
            )
            .expect("runs")
            .records
            .into_iter()
            .map(|r| (r.seed, r.outcome, r.steps, r.makespan, r.robots))
            .collect::<Vec<_>>()
        };
        let one = run(1);
        assert_eq!(one, run(2));
        assert_eq!(one.len(), 8);
        for (_, outcome, _, makespan, robots) in &one {
            assert_eq!(robots.len(), 4);
            if *outcome == Outcome::Success {
                assert_eq!(*makespan, robots.iter().filter_map(|x| x.arrived_at).max());
            }
        }
        // Four geodesic robots in a maze mostly all arrive.
        let options = EvalOptions {
            seeds: (0..8).collect(),
            ..Default::default()
        };
        let records = ev
            .run_team(
                &factories,
                &names,
                &options,
                &AtomicBool::new(false),
                &|_| {},
            )
            .expect("runs")
            .records;
        let summary = TeamSummary::new(&records, 1.0);
        assert!(records
            .iter()
            .all(|r| r.robots.iter().all(|x| x.goals == 1 && x.tour.is_none())));
        assert!(summary.robot_success_rate > 0.5, "{summary:?}");
    }

    #[test]
    fn goal_lists_are_visited_in_the_optimal_order() {
        let config = crate::SimConfig {
            robots: vec![TeamRobotConfig {
                count: 3,
                goal_count: 4,
                order: crate::config::Order::Optimal,
                ..Default::default()
            }],
            ..Default::default()
        }
        .validate()
        .expect("valid");
        let ev = Evaluator::new(config, Scenes::MazePerSeed);
        let f = factory("geodesic", ev.config().observation_size()).expect("geodesic");
        let factories: Vec<&dyn PolicyFactory> = (0..3).map(|_| f.as_ref()).collect();
        let names = vec!["geodesic".to_string(); 3];
        let options = EvalOptions {
            seeds: (0..6).collect(),
            ..Default::default()
        };
        let records = ev
            .run_team(
                &factories,
                &names,
                &options,
                &AtomicBool::new(false),
                &|_| {},
            )
            .expect("runs")
            .records;
        let mut arrived = 0;
        for r in &records {
            for x in &r.robots {
                let t = x.tour.expect("a goal list");
                assert!(
                    t.optimal <= t.nearest + 1e-9 && t.optimal <= t.given + 1e-9,
                    "{t:?}"
                );
                assert_eq!(t.chosen_px(), t.optimal);
                assert_eq!(x.goals, 4);
                assert!(x.goals_reached <= 4);
                if x.outcome == Outcome::Success {
                    arrived += 1;
                    assert_eq!(x.goals_reached, 4);
                    // Never shorter than the optimal tour (less the goals' tolerances).
                    let shortest = x.shortest_px.expect("success");
                    assert!(x.path_length_px >= shortest - 1e-6, "{x:?}");
                } else {
                    assert!(x.goals_reached < 4);
                }
            }
        }
        assert!(arrived > 0);
    }
}
