//! A team's records (docs/model.md "Several robots", metrics): per-robot records beside team
//! figures (team success: every robot arrived; makespan; summed path length; robot collisions;
//! deadlocks), and their summary. The episodes run in `recorder`.

use crate::config::RobotConfig;
use crate::eval::summary::{wilson95, AmongRobots};
use crate::eval::{EpisodeRecord, Outcome, Runs};
use crate::sim::{Laser, Track};
use serde::{Deserialize, Serialize};
use std::sync::Arc;

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
    /// Flow: each robot's arrival step, summed, when all arrived.
    pub sum_of_costs: Option<u64>,
    /// The makespan's lower bound: the longest of the robots' own lower bounds
    /// ([`InTeam::lower_bound_steps`](crate::eval::InTeam::lower_bound_steps)), when each has one.
    pub makespan_lower_bound: Option<u32>,
    /// The flow's lower bound: the robots' own lower bounds summed, when each has one.
    pub sum_of_costs_lower_bound: Option<u64>,
    /// Summed steps robots acted without moving.
    pub waiting_steps: u64,
    /// Summed distance driven, px.
    pub path_length_px: f64,
    /// Summed steps walls blocked.
    pub collisions: u32,
    /// Summed steps other robots blocked.
    pub robot_collisions: u32,
    /// Whether it ended in a deadlock.
    pub deadlock: bool,
    /// Each robot's record (each with its [`InTeam`](crate::eval::InTeam)), in robot order: its
    /// poses (while it is in the scene) when the trajectory was recorded, the steps it acted when
    /// steps were, and its last readings when either was.
    pub robots: Vec<EpisodeRecord>,
    /// Wall time, seconds.
    pub wall_time_s: f64,
    /// What the episode's picture needs beyond its robots' records, when their trajectories
    /// were recorded.
    pub picture: Option<TeamPicture>,
}

/// What a team episode's picture needs beyond its robots' records: the scene, each robot's body
/// and laser, and the moving obstacles' tracks.
#[derive(Clone, Debug)]
pub struct TeamPicture {
    /// The scene.
    pub scene: Arc<crate::Scene>,
    /// Each robot's body, laser and goal tolerance, in robot order.
    pub robots: Vec<RobotLook>,
    /// Each moving obstacle's body and centre at every team step.
    pub mover_tracks: Vec<Track>,
}

/// A robot as an episode's picture draws it (a team's robot, or the lone robot).
#[derive(Clone, Debug)]
pub struct RobotLook {
    /// Its body.
    pub body: RobotConfig,
    /// Its laser.
    pub laser: Laser,
    /// Its goal tolerance, px.
    pub goal_tolerance_px: f64,
}

impl TeamRecord {
    /// Why the team ended as it did, when a robot's record says: the first robot whose outcome
    /// is the team's (an infeasible task names the robots and the passage, a planner that gave
    /// up says why).
    pub fn reason(&self) -> Option<&str> {
        self.robots
            .iter()
            .filter(|x| x.outcome == self.outcome)
            .find_map(|x| x.reason.as_deref())
    }
}

/// `sum / n`, or 0 for none.
fn over(sum: f64, n: usize) -> f64 {
    if n == 0 {
        0.0
    } else {
        sum / n as f64
    }
}

/// Whether a count is nought (left out of `summary.json`).
fn is_zero(n: &usize) -> bool {
    *n == 0
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
    /// Episodes the team's policy found infeasible before the first step.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub infeasible: usize,
    /// Mean makespan over the team successes, steps.
    pub mean_makespan: f64,
    /// Over the team successes: the mean lower bound of the makespan (the longest robot's own
    /// shortest way), steps...
    #[serde(default)]
    pub mean_makespan_lower_bound: f64,
    /// ... the mean ratio of makespan to it...
    #[serde(default)]
    pub mean_makespan_ratio: f64,
    /// ... the mean flow (each robot's arrival step, summed), steps...
    #[serde(default)]
    pub mean_sum_of_costs: f64,
    /// ... and its mean lower bound (the robots' own shortest ways, summed), steps.
    #[serde(default)]
    pub mean_sum_of_costs_lower_bound: f64,
    /// Mean steps a robot acted without moving, per robot episode.
    #[serde(default)]
    pub mean_waiting_steps: f64,
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

/// What a team summary needs of one robot of a team episode.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RobotFigures {
    /// How its episode ended.
    pub outcome: Outcome,
    /// Steps it acted.
    pub steps: u32,
    /// SPL.
    pub spl: f64,
}

/// What a team summary needs of one team episode.
#[derive(Clone, Debug, PartialEq)]
pub struct TeamFigures {
    /// The team's outcome.
    pub outcome: Outcome,
    /// Whether it ended in a deadlock.
    pub deadlock: bool,
    /// The step the last robot arrived at, when all did.
    pub makespan: Option<u32>,
    /// Summed distance driven, px.
    pub path_length_px: f64,
    /// Summed steps walls blocked.
    pub collisions: u32,
    /// Summed steps other robots blocked.
    pub robot_collisions: u32,
    /// Its makespan and flow against their lower bounds, and its waiting.
    pub flow: Flow,
    /// Each robot's figures.
    pub robots: Vec<RobotFigures>,
}

/// A team episode's flow ([`TeamRecord`]'s fields of the same names).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Flow {
    /// Each robot's arrival step, summed, when all arrived.
    pub sum_of_costs: Option<u64>,
    /// The longest of the robots' own lower bounds.
    pub makespan_lower_bound: Option<u32>,
    /// The robots' own lower bounds, summed.
    pub sum_of_costs_lower_bound: Option<u64>,
    /// Summed steps robots acted without moving.
    pub waiting_steps: u64,
}

impl TeamFigures {
    /// The figures of `record`.
    pub fn of(record: &TeamRecord) -> Self {
        Self {
            outcome: record.outcome,
            deadlock: record.deadlock,
            makespan: record.makespan,
            path_length_px: record.path_length_px,
            collisions: record.collisions,
            robot_collisions: record.robot_collisions,
            flow: Flow {
                sum_of_costs: record.sum_of_costs,
                makespan_lower_bound: record.makespan_lower_bound,
                sum_of_costs_lower_bound: record.sum_of_costs_lower_bound,
                waiting_steps: record.waiting_steps,
            },
            robots: record
                .robots
                .iter()
                .map(|r| RobotFigures {
                    outcome: r.outcome,
                    steps: r.steps,
                    spl: r.spl,
                })
                .collect(),
        }
    }
}

/// A [`TeamSummary`] being gathered episode by episode (counts and running sums in seed order,
/// equal bit for bit to [`TeamSummary::new`] over the same records).
#[derive(Clone, Debug)]
pub struct TeamTally {
    episodes: usize,
    robots_per_episode: Option<usize>,
    team_successes: usize,
    robots: usize,
    robot_successes: usize,
    robot_deadlocks: usize,
    infeasible: usize,
    robot_infeasible: usize,
    deadlocks: usize,
    makespans: usize,
    makespan_sum: f64,
    /// Over the team successes with lower bounds: how many, and the sums of the lower bound,
    /// of the makespan's ratio to it, of the flow and of its lower bound.
    bounded: usize,
    makespan_bound_sum: f64,
    makespan_ratio_sum: f64,
    flow_sum: f64,
    flow_bound_sum: f64,
    waiting_steps: u64,
    path_length_px: f64,
    robot_collisions: f64,
    collisions: f64,
    spl: f64,
    robot_steps: u64,
}

impl Default for TeamTally {
    fn default() -> Self {
        let zero = crate::eval::summary::empty_sum();
        Self {
            episodes: 0,
            robots_per_episode: None,
            team_successes: 0,
            robots: 0,
            robot_successes: 0,
            robot_deadlocks: 0,
            infeasible: 0,
            robot_infeasible: 0,
            deadlocks: 0,
            makespans: 0,
            makespan_sum: zero,
            bounded: 0,
            makespan_bound_sum: zero,
            makespan_ratio_sum: zero,
            flow_sum: zero,
            flow_bound_sum: zero,
            waiting_steps: 0,
            path_length_px: zero,
            robot_collisions: zero,
            collisions: zero,
            spl: zero,
            robot_steps: 0,
        }
    }
}

impl TeamTally {
    /// Counts the next team episode (in seed order).
    pub fn add(&mut self, f: &TeamFigures) {
        self.episodes += 1;
        self.robots_per_episode.get_or_insert(f.robots.len());
        if f.outcome == Outcome::Success {
            self.team_successes += 1;
        }
        if f.deadlock {
            self.deadlocks += 1;
        }
        if f.outcome == Outcome::Infeasible {
            self.infeasible += 1;
        }
        if let Some(m) = f.makespan {
            self.makespans += 1;
            self.makespan_sum += f64::from(m);
            if let (Some(lb), Some(flow), Some(flow_lb)) = (
                f.flow.makespan_lower_bound,
                f.flow.sum_of_costs,
                f.flow.sum_of_costs_lower_bound,
            ) {
                self.bounded += 1;
                self.makespan_bound_sum += f64::from(lb);
                self.makespan_ratio_sum += f64::from(m) / f64::from(lb.max(1));
                self.flow_sum += flow as f64;
                self.flow_bound_sum += flow_lb as f64;
            }
        }
        self.waiting_steps += f.flow.waiting_steps;
        self.path_length_px += f.path_length_px;
        self.robot_collisions += f64::from(f.robot_collisions);
        self.collisions += f64::from(f.collisions);
        for r in &f.robots {
            self.robots += 1;
            match r.outcome {
                Outcome::Success => self.robot_successes += 1,
                Outcome::Deadlock => self.robot_deadlocks += 1,
                Outcome::Infeasible => self.robot_infeasible += 1,
                _ => {}
            }
            self.spl += r.spl;
            self.robot_steps += u64::from(r.steps);
        }
    }

    /// Robot steps of the episodes counted.
    pub fn robot_steps(&self) -> u64 {
        self.robot_steps
    }

    /// What the robots' own [`crate::eval::Summary`] adds for a team: the steps other robots
    /// blocked per robot episode, and the robots that ended deadlocked.
    pub fn among_robots(&self) -> AmongRobots {
        AmongRobots {
            robot_collisions_per_episode: if self.robots == 0 {
                0.0
            } else {
                self.robot_collisions / self.robots as f64
            },
            deadlocks: self.robot_deadlocks,
            infeasible: self.robot_infeasible,
        }
    }

    /// The summary of the episodes counted, over a run that took `wall_time_s` to simulate
    /// `robot_steps_in_wall_time` robot steps.
    pub fn summary(&self, wall_time_s: f64, robot_steps_in_wall_time: u64) -> TeamSummary {
        let n = self.episodes;
        let per = |x: f64| if n == 0 { 0.0 } else { x / n as f64 };
        TeamSummary {
            episodes: n,
            robots: self.robots_per_episode.unwrap_or(0),
            team_successes: self.team_successes,
            team_success_rate: per(self.team_successes as f64),
            team_success_ci95: wilson95(self.team_successes, n),
            robot_success_rate: if self.robots == 0 {
                0.0
            } else {
                self.robot_successes as f64 / self.robots as f64
            },
            deadlocks: self.deadlocks,
            infeasible: self.infeasible,
            mean_makespan: if self.makespans == 0 {
                0.0
            } else {
                self.makespan_sum / self.makespans as f64
            },
            mean_makespan_lower_bound: over(self.makespan_bound_sum, self.bounded),
            mean_makespan_ratio: over(self.makespan_ratio_sum, self.bounded),
            mean_sum_of_costs: over(self.flow_sum, self.bounded),
            mean_sum_of_costs_lower_bound: over(self.flow_bound_sum, self.bounded),
            mean_waiting_steps: over(self.waiting_steps as f64, self.robots),
            mean_path_length_px: per(self.path_length_px),
            robot_collisions_per_episode: per(self.robot_collisions),
            collisions_per_episode: per(self.collisions),
            spl: if self.robots == 0 {
                0.0
            } else {
                self.spl / self.robots as f64
            },
            wall_time_s,
            robot_steps_per_second: if wall_time_s > 0.0 {
                robot_steps_in_wall_time as f64 / wall_time_s
            } else {
                0.0
            },
        }
    }
}

impl TeamSummary {
    /// The summary of `records`, over a run that took `wall_time_s`.
    pub fn new(records: &[TeamRecord], wall_time_s: f64) -> Self {
        let mut tally = TeamTally::default();
        for r in records {
            tally.add(&TeamFigures::of(r));
        }
        tally.summary(wall_time_s, tally.robot_steps())
    }

    /// The summary as an aligned two-column table.
    pub fn table(&self) -> String {
        let pct = super::summary::percent;
        let mut rows: Vec<(&str, String)> = vec![
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
                "infeasible",
                format!("{} (each one's reason in robots.csv)", self.infeasible),
            ),
            (
                "mean makespan",
                if self.team_successes > 0 {
                    format!("{:.1} steps (over the team successes)", self.mean_makespan)
                } else {
                    "none (no team success)".to_string()
                },
            ),
            (
                "makespan / bound",
                if self.mean_makespan_lower_bound > 0.0 {
                    format!(
                        "{:.2} (lower bound {:.1} steps: the longest robot's own shortest way)",
                        self.mean_makespan_ratio, self.mean_makespan_lower_bound
                    )
                } else {
                    "none (no team success)".to_string()
                },
            ),
            (
                "sum of costs",
                if self.mean_sum_of_costs_lower_bound > 0.0 {
                    format!(
                        "{:.1} steps (lower bound {:.1}: the robots' own shortest ways)",
                        self.mean_sum_of_costs, self.mean_sum_of_costs_lower_bound
                    )
                } else {
                    "none (no team success)".to_string()
                },
            ),
            (
                "waiting",
                format!("{:.1} steps per robot", self.mean_waiting_steps),
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
        // Only where the team's policy found some.
        if self.infeasible == 0 {
            rows.retain(|(k, _)| *k != "infeasible");
        }
        let width = rows.iter().map(|(k, _)| k.len()).max().unwrap_or(0);
        rows.iter()
            .map(|(k, v)| format!("{k:<width$}  {v}\n"))
            .collect()
    }
}

/// A team's evaluation.
pub type TeamRunResult = Runs<TeamRecord>;

/// A team's outcome from its robots' `outcomes`: success when every robot arrived, else the
/// worst of theirs (infeasible, deadlock, time-out, collision, reward floor, stuck, in that order).
pub(crate) fn team_outcome(outcomes: &[Outcome]) -> Outcome {
    if outcomes.iter().all(|o| *o == Outcome::Success) {
        return Outcome::Success;
    }
    [
        Outcome::Infeasible,
        Outcome::Deadlock,
        Outcome::Timeout,
        Outcome::Collision,
        Outcome::RewardMin,
        Outcome::Stuck,
    ]
    .into_iter()
    .find(|o| outcomes.contains(o))
    .unwrap_or(Outcome::Stuck)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::TeamRobotConfig;
    use crate::eval::{EvalOptions, Evaluator};
    use crate::policy::{factory, PerRobotFactory};
    use crate::sim::Scenes;
    use std::sync::atomic::AtomicBool;

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
        let team = PerRobotFactory::new(
            (0..4).map(|_| f.as_ref()).collect(),
            vec!["geodesic".to_string(); 4],
        );
        let run = |threads| {
            let options = EvalOptions {
                seeds: (0..8).collect::<Vec<_>>().into(),
                threads,
                ..Default::default()
            };
            ev.run_team(&team, &options, &AtomicBool::new(false), &|_| {})
                .expect("runs")
                .records
                .into_iter()
                .map(|r| {
                    let robots: Vec<_> = r
                        .robots
                        .iter()
                        .map(|x| (x.outcome, x.steps, x.path_length_px, x.spl, x.team.clone()))
                        .collect();
                    (r.seed, r.outcome, r.steps, r.makespan, robots)
                })
                .collect::<Vec<_>>()
        };
        let one = run(1);
        assert_eq!(one, run(2));
        assert_eq!(one.len(), 8);
        for (_, outcome, _, makespan, robots) in &one {
            assert_eq!(robots.len(), 4);
            if *outcome == Outcome::Success {
                let arrived = robots.iter().filter_map(|x| x.4.as_ref()?.arrived_at);
                assert_eq!(*makespan, arrived.max());
            }
        }
        // Four geodesic robots in a maze mostly all arrive.
        let options = EvalOptions {
            seeds: (0..8).collect::<Vec<_>>().into(),
            ..Default::default()
        };
        let records = ev
            .run_team(&team, &options, &AtomicBool::new(false), &|_| {})
            .expect("runs")
            .records;
        let summary = TeamSummary::new(&records, 1.0);
        assert!(records.iter().all(|r| r.robots.iter().all(|x| {
            let t = x.team.as_ref().expect("a robot of a team");
            t.goals == 1 && t.tour.is_none()
        })));
        assert!(summary.robot_success_rate > 0.5, "{summary:?}");
    }

    #[test]
    fn the_robots_figures_among_each_other_count_robot_episodes() {
        let robot = |outcome| RobotFigures {
            outcome,
            steps: 40,
            spl: 0.0,
        };
        let episode = |robot_collisions, robots: Vec<RobotFigures>| TeamFigures {
            outcome: Outcome::Deadlock,
            deadlock: true,
            makespan: None,
            path_length_px: 0.0,
            collisions: 3,
            robot_collisions,
            flow: Flow::default(),
            robots,
        };
        let mut tally = TeamTally::default();
        tally.add(&episode(
            30,
            vec![robot(Outcome::Deadlock), robot(Outcome::Deadlock)],
        ));
        tally.add(&episode(
            10,
            vec![robot(Outcome::Success), robot(Outcome::Deadlock)],
        ));
        // 40 blocked steps over 4 robot episodes; 3 of them deadlocked.
        assert_eq!(
            tally.among_robots(),
            AmongRobots {
                robot_collisions_per_episode: 10.0,
                deadlocks: 3,
                infeasible: 0,
            }
        );
        assert_eq!(tally.summary(1.0, 0).robot_collisions_per_episode, 20.0);
        assert_eq!(
            TeamTally::default()
                .among_robots()
                .robot_collisions_per_episode,
            0.0
        );
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
        let team = PerRobotFactory::new(
            (0..3).map(|_| f.as_ref()).collect(),
            vec!["geodesic".to_string(); 3],
        );
        let options = EvalOptions {
            seeds: (0..6).collect::<Vec<_>>().into(),
            ..Default::default()
        };
        let records = ev
            .run_team(&team, &options, &AtomicBool::new(false), &|_| {})
            .expect("runs")
            .records;
        let mut arrived = 0;
        for r in &records {
            for x in &r.robots {
                let place = x.team.as_ref().expect("a robot of a team");
                let t = place.tour.expect("a goal list");
                assert!(
                    t.optimal <= t.nearest + 1e-9 && t.optimal <= t.given + 1e-9,
                    "{t:?}"
                );
                assert_eq!(t.chosen_px(), t.optimal);
                assert_eq!(place.goals, 4);
                assert!(place.goals_reached <= 4);
                if x.outcome == Outcome::Success {
                    arrived += 1;
                    assert_eq!(place.goals_reached, 4);
                    // Never shorter than the optimal tour (less the goals' tolerances).
                    let shortest = x.shortest_px.expect("success");
                    assert!(x.path_length_px >= shortest - 1e-6, "{x:?}");
                } else {
                    assert!(place.goals_reached < 4);
                }
            }
        }
        assert!(arrived > 0);
    }
}
