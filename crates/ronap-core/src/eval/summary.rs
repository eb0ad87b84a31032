//! The figures of an evaluation: success rate with its confidence interval, failures by kind,
//! path efficiency (SPL) and speed.

use crate::eval::metric::{Kind, MetricMean};
use crate::eval::{EpisodeRecord, Outcome};
use crate::sim::DynamicMetrics;
use serde::{Deserialize, Serialize};

/// Summary figures of a set of episodes.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Summary {
    /// Episodes finished.
    pub episodes: usize,
    /// Successes.
    pub successes: usize,
    /// Success rate, in [0, 1].
    pub success_rate: f64,
    /// 95% Wilson score interval of the success rate, `[low, high]`.
    pub success_ci95: [f64; 2],
    /// Time-outs.
    pub timeouts: usize,
    /// Episodes the policy gave up (stuck, oscillating, no path).
    pub stuck: usize,
    /// Episodes ended by a collision (`on_collision = terminate`).
    pub collision_ends: usize,
    /// Episodes ended by `reward_min`.
    pub reward_min_ends: usize,
    /// Mean colliding steps per episode.
    pub collisions_per_episode: f64,
    /// Mean steps per episode.
    pub mean_steps: f64,
    /// Mean distance driven per episode, px.
    pub mean_path_length_px: f64,
    /// Mean SPL (success weighted by path length) over all episodes.
    pub spl: f64,
    /// Mean summed reward.
    pub mean_return: f64,
    /// Wall time of the run, seconds.
    pub wall_time_s: f64,
    /// Steps simulated per second of wall time.
    pub steps_per_second: f64,
    /// Figures among moving obstacles, when the episodes had some.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub moving: Option<MovingSummary>,
    /// Figures among the other robots of a team, when the episodes were robots' of a team of two
    /// or more.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub among_robots: Option<AmongRobots>,
    /// The mean of each metric the configuration asked for beyond these (docs/model.md "Crowd
    /// metrics"), in column order.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub metrics: Vec<MetricMean>,
}

/// Summary figures of episodes among moving obstacles.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MovingSummary {
    /// Mean steps with contact between the robot and a moving obstacle, per episode.
    pub dynamic_collisions_per_episode: f64,
    /// Episodes with at least one such contact.
    pub episodes_with_dynamic_collision: usize,
    /// Mean over episodes of the least gap to any obstacle, px (episodes that never came within
    /// the laser range of one are left out).
    pub mean_min_clearance_px: f64,
    /// Mean fraction of steps spent within `safety_radius_px` of a moving obstacle.
    pub near_moving_fraction: f64,
}

/// Summary figures of a team's robots' episodes that a lone robot's have no use for: the steps
/// other robots blocked (wall collisions are `collisions_per_episode`) and the deadlocks.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct AmongRobots {
    /// Mean steps another robot blocked, per robot episode.
    pub robot_collisions_per_episode: f64,
    /// Robot episodes that ended in a deadlock ([`Outcome::Deadlock`]).
    pub deadlocks: usize,
    /// Robot episodes whose team's task was found infeasible ([`Outcome::Infeasible`]).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub infeasible: usize,
}

/// Whether a count is nought (left out of `summary.json`).
fn is_zero(n: &usize) -> bool {
    *n == 0
}

/// The 95% Wilson score interval for `k` successes in `n` trials.
pub fn wilson95(k: usize, n: usize) -> [f64; 2] {
    if n == 0 {
        return [0.0, 1.0];
    }
    let z = 1.959_963_984_540_054_f64;
    let n = n as f64;
    let p = k as f64 / n;
    let denom = 1.0 + z * z / n;
    let centre = (p + z * z / (2.0 * n)) / denom;
    let half = z * (p * (1.0 - p) / n + z * z / (4.0 * n * n)).sqrt() / denom;
    [(centre - half).max(0.0), (centre + half).min(1.0)]
}

/// What a summary needs of one episode: its figures, exactly as the record holds them.
#[derive(Clone, Debug, PartialEq)]
pub struct Figures {
    /// How it ended.
    pub outcome: Outcome,
    /// Steps taken.
    pub steps: u32,
    /// Steps that collided.
    pub collisions: u32,
    /// Distance driven, px.
    pub path_length_px: f64,
    /// SPL.
    pub spl: f64,
    /// Summed reward.
    pub total_reward: f64,
    /// How it went among moving obstacles.
    pub dynamic: Option<DynamicMetrics>,
    /// Its value of each metric asked for beyond these, in column order.
    pub metrics: Vec<Option<f64>>,
}

impl Figures {
    /// The figures of `record`.
    pub fn of(record: &EpisodeRecord) -> Self {
        Self {
            outcome: record.outcome,
            steps: record.steps,
            collisions: record.collisions,
            path_length_px: record.path_length_px,
            spl: record.spl,
            total_reward: record.total_reward,
            dynamic: record.dynamic,
            metrics: record.metrics.clone(),
        }
    }
}

/// The sum of an empty list of floats, where running sums start so that they equal
/// `Iterator::sum` over the same values in the same order, bit for bit.
pub(crate) fn empty_sum() -> f64 {
    std::iter::empty::<f64>().sum()
}

/// A [`Summary`] being gathered episode by episode: counts and running sums in seed order, so a
/// run of millions of episodes needs no list of them and gives the same figures, bit for bit, as
/// [`Summary::new`] over the same records.
#[derive(Clone, Debug)]
pub struct Tally {
    episodes: usize,
    outcomes: [usize; Outcome::ALL.len()],
    steps: u64,
    collisions: f64,
    step_sum: f64,
    path_length_px: f64,
    spl: f64,
    total_reward: f64,
    dynamic: usize,
    dynamic_collisions: f64,
    with_dynamic_collision: usize,
    clearance_px: f64,
    clearances: usize,
    near_fraction: f64,
    /// The metrics asked for beyond the standard ones, and each one's running sum and count of
    /// episodes with a value.
    kinds: &'static [Kind],
    metric_sums: Vec<(f64, usize)>,
}

impl Default for Tally {
    fn default() -> Self {
        Self {
            episodes: 0,
            outcomes: [0; Outcome::ALL.len()],
            steps: 0,
            collisions: empty_sum(),
            step_sum: empty_sum(),
            path_length_px: empty_sum(),
            spl: empty_sum(),
            total_reward: empty_sum(),
            dynamic: 0,
            dynamic_collisions: empty_sum(),
            with_dynamic_collision: 0,
            clearance_px: empty_sum(),
            clearances: 0,
            near_fraction: empty_sum(),
            kinds: &[],
            metric_sums: Vec::new(),
        }
    }
}

impl Tally {
    /// A tally that also sums the metrics of `kinds` (the [`Figures::metrics`] it is given hold
    /// their values in this order).
    pub fn measuring(kinds: &'static [Kind]) -> Self {
        Self {
            kinds,
            metric_sums: vec![(empty_sum(), 0); kinds.len()],
            ..Self::default()
        }
    }

    /// Counts the next episode (in seed order).
    pub fn add(&mut self, f: &Figures) {
        self.episodes += 1;
        if let Some(k) = Outcome::ALL.iter().position(|o| *o == f.outcome) {
            self.outcomes[k] += 1;
        }
        self.steps += u64::from(f.steps);
        self.collisions += f64::from(f.collisions);
        self.step_sum += f64::from(f.steps);
        self.path_length_px += f.path_length_px;
        self.spl += f.spl;
        self.total_reward += f.total_reward;
        if let Some(d) = f.dynamic {
            self.dynamic += 1;
            self.dynamic_collisions += f64::from(d.collisions);
            if d.collisions > 0 {
                self.with_dynamic_collision += 1;
            }
            if d.min_clearance_px.is_finite() {
                self.clearance_px += d.min_clearance_px;
                self.clearances += 1;
            }
            self.near_fraction += f64::from(d.near_steps) / f64::from(f.steps.max(1));
        }
        for (sum, value) in self.metric_sums.iter_mut().zip(&f.metrics) {
            if let Some(v) = value.filter(|v| v.is_finite()) {
                sum.0 += v;
                sum.1 += 1;
            }
        }
    }

    /// How many metrics beyond the standard ones it sums.
    pub fn metrics(&self) -> usize {
        self.kinds.len()
    }

    /// Episodes counted.
    pub fn episodes(&self) -> usize {
        self.episodes
    }

    /// Steps of the episodes counted.
    pub fn steps(&self) -> u64 {
        self.steps
    }

    fn count(&self, o: Outcome) -> usize {
        Outcome::ALL
            .iter()
            .position(|x| *x == o)
            .map_or(0, |k| self.outcomes[k])
    }

    /// The summary of the episodes counted, over a run that took `wall_time_s` to simulate
    /// `steps_in_wall_time` steps (all of them, unless the run was resumed).
    pub fn summary(&self, wall_time_s: f64, steps_in_wall_time: u64) -> Summary {
        let n = self.episodes;
        let mean = |sum: f64| if n == 0 { 0.0 } else { sum / n as f64 };
        let successes = self.count(Outcome::Success);
        let moving = (self.dynamic > 0).then(|| {
            let k = self.dynamic as f64;
            MovingSummary {
                dynamic_collisions_per_episode: self.dynamic_collisions / k,
                episodes_with_dynamic_collision: self.with_dynamic_collision,
                mean_min_clearance_px: if self.clearances == 0 {
                    0.0
                } else {
                    self.clearance_px / self.clearances as f64
                },
                near_moving_fraction: self.near_fraction / k,
            }
        });
        Summary {
            episodes: n,
            successes,
            success_rate: if n == 0 {
                0.0
            } else {
                successes as f64 / n as f64
            },
            success_ci95: wilson95(successes, n),
            timeouts: self.count(Outcome::Timeout),
            stuck: self.count(Outcome::Stuck),
            collision_ends: self.count(Outcome::Collision),
            reward_min_ends: self.count(Outcome::RewardMin),
            collisions_per_episode: mean(self.collisions),
            mean_steps: mean(self.step_sum),
            mean_path_length_px: mean(self.path_length_px),
            spl: mean(self.spl),
            mean_return: mean(self.total_reward),
            wall_time_s,
            steps_per_second: if wall_time_s > 0.0 {
                steps_in_wall_time as f64 / wall_time_s
            } else {
                0.0
            },
            moving,
            among_robots: None,
            metrics: self
                .kinds
                .iter()
                .zip(&self.metric_sums)
                .map(|(k, &(sum, count))| MetricMean {
                    name: k.column.name.to_string(),
                    unit: k.column.unit.to_string(),
                    mean: if count == 0 { 0.0 } else { sum / count as f64 },
                    episodes: count,
                })
                .collect(),
        }
    }
}

impl Summary {
    /// The summary of `records`, whose metrics beyond the standard ones are those of `kinds`
    /// (`metric::kinds` of their configuration), over a run that took `wall_time_s`.
    pub fn new(records: &[EpisodeRecord], kinds: &'static [Kind], wall_time_s: f64) -> Self {
        let mut tally = Tally::measuring(kinds);
        for r in records {
            tally.add(&Figures::of(r));
        }
        tally.summary(wall_time_s, tally.steps())
    }

    /// The summary as an aligned two-column table for a terminal.
    pub fn table(&self) -> String {
        let pct = percent;
        let mut rows: Vec<(&str, String)> = vec![
            ("episodes", self.episodes.to_string()),
            (
                "success rate",
                format!(
                    "{} ({} of {}; 95% CI {} to {})",
                    pct(self.success_rate),
                    self.successes,
                    self.episodes,
                    pct(self.success_ci95[0]),
                    pct(self.success_ci95[1])
                ),
            ),
            ("time-outs", self.timeouts.to_string()),
            ("stuck (gave up)", self.stuck.to_string()),
            (
                "collisions per episode",
                format!("{:.2}", self.collisions_per_episode),
            ),
            ("mean steps", format!("{:.1}", self.mean_steps)),
            (
                "mean path length",
                format!("{:.1} px", self.mean_path_length_px),
            ),
            ("SPL", format!("{:.3}", self.spl)),
            ("mean return", format!("{:.2}", self.mean_return)),
            ("wall time", format!("{:.2} s", self.wall_time_s)),
            ("steps per second", format!("{:.0}", self.steps_per_second)),
        ];
        if let Some(m) = &self.moving {
            let at = rows
                .iter()
                .position(|(k, _)| *k == "mean steps")
                .unwrap_or(rows.len());
            rows.splice(
                at..at,
                [
                    (
                        "moving-obstacle collisions",
                        format!(
                            "{:.2} per episode ({} episodes with one)",
                            m.dynamic_collisions_per_episode, m.episodes_with_dynamic_collision
                        ),
                    ),
                    (
                        "least clearance (mean)",
                        format!("{:.1} px", m.mean_min_clearance_px),
                    ),
                    ("steps near a mover", pct(m.near_moving_fraction)),
                ],
            );
        }
        let at = rows
            .iter()
            .position(|(k, _)| *k == "wall time")
            .unwrap_or(rows.len());
        rows.splice(
            at..at,
            self.metrics.iter().map(|m| {
                let value = if m.episodes == 0 {
                    "none".to_string()
                } else {
                    format!("{:.3} {} (mean of {} episodes)", m.mean, m.unit, m.episodes)
                };
                (m.name.as_str(), value)
            }),
        );
        if let Some(t) = &self.among_robots {
            // A team's robots also collide with each other: both kinds, named apart.
            if let Some(at) = rows
                .iter()
                .position(|(k, _)| *k == "collisions per episode")
            {
                rows[at].0 = "wall collisions per episode";
                rows.insert(
                    at + 1,
                    (
                        "robot collisions per episode",
                        format!("{:.2}", t.robot_collisions_per_episode),
                    ),
                );
                rows.insert(at, ("deadlocks", t.deadlocks.to_string()));
                if t.infeasible > 0 {
                    rows.insert(at + 1, ("infeasible", t.infeasible.to_string()));
                }
            }
        }
        if self.collision_ends > 0 {
            rows.insert(4, ("ended by collision", self.collision_ends.to_string()));
        }
        if self.reward_min_ends > 0 {
            rows.insert(4, ("ended by reward_min", self.reward_min_ends.to_string()));
        }
        let width = rows.iter().map(|(k, _)| k.len()).max().unwrap_or(0);
        rows.iter()
            .map(|(k, v)| format!("{k:<width$}  {v}\n"))
            .collect()
    }
}

/// `x` (0 to 1) as a percentage to one decimal, or to as many more as it takes for a rate short
/// of 1 not to show as 100.0%, nor one above 0 as 0.0% (199,956 successes of 200,000 are 99.98%,
/// not 100.0%).
pub(crate) fn percent(x: f64) -> String {
    let shown = |d: usize| format!("{:.*}", d, 100.0 * x);
    let d = (1..=17)
        .find(|&d| {
            let s = shown(d);
            !((x < 1.0 && s.starts_with("100.")) || (x > 0.0 && s.parse::<f64>() == Ok(0.0)))
        })
        .unwrap_or(17);
    format!("{}%", shown(d))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn figures(outcome: Outcome, collisions: u32) -> Figures {
        Figures {
            outcome,
            steps: 10,
            collisions,
            path_length_px: 5.0,
            spl: 0.0,
            total_reward: -1.0,
            dynamic: None,
            metrics: Vec::new(),
        }
    }

    #[test]
    fn a_rate_short_of_all_or_above_none_never_shows_as_all_or_none() {
        for (x, shown) in [
            (1.0, "100.0%"),
            (0.0, "0.0%"),
            (0.5, "50.0%"),
            (199_956.0 / 200_000.0, "99.98%"),
            (44.0 / 200_000.0, "0.02%"),
            (0.9994, "99.9%"),
            (1.0 - 1e-7, "99.99999%"),
            (0.9996, "99.96%"),
        ] {
            assert_eq!(percent(x), shown, "{x}");
        }
    }

    #[test]
    fn a_team_s_robots_table_names_wall_and_robot_collisions_apart_and_counts_deadlocks() {
        let mut tally = Tally::default();
        for f in [
            figures(Outcome::Deadlock, 1),
            figures(Outcome::Deadlock, 0),
            figures(Outcome::Success, 0),
        ] {
            tally.add(&f);
        }
        let lone = tally.summary(1.0, 30);
        let table = lone.table();
        assert!(table.contains("collisions per episode  0.33\n"), "{table}");
        assert!(!table.contains("robot collisions"), "{table}");
        assert!(!table.contains("deadlocks"), "{table}");
        assert!(!serde_json::to_string(&lone)
            .expect("serialises")
            .contains("among_robots"));

        let team = Summary {
            among_robots: Some(AmongRobots {
                robot_collisions_per_episode: 12.5,
                deadlocks: 2,
                infeasible: 0,
            }),
            ..lone
        };
        let table = team.table();
        let rows: Vec<&str> = table.lines().collect();
        let at = |name: &str| {
            rows.iter()
                .position(|r| r.starts_with(&format!("{name}  ")))
                .unwrap_or_else(|| panic!("no row {name}:\n{table}"))
        };
        assert_eq!(
            rows[at("deadlocks")].split_whitespace().last(),
            Some("2"),
            "{table}"
        );
        assert!(rows[at("wall collisions per episode")].ends_with("  0.33"));
        assert!(rows[at("robot collisions per episode")].ends_with("  12.50"));
        assert_eq!(at("stuck (gave up)") + 1, at("deadlocks"));
        assert_eq!(at("deadlocks") + 1, at("wall collisions per episode"));
        assert!(!table.contains("\ncollisions per episode"), "{table}");
        let json = serde_json::to_value(&team).expect("serialises");
        assert_eq!(json["among_robots"]["deadlocks"], 2);
        let back: Summary = serde_json::from_value(json).expect("reads back");
        assert_eq!(back, team);
    }

    #[test]
    fn wilson_interval_matches_known_values() {
        // 50 of 100: 0.4038 to 0.5962.
        let [lo, hi] = wilson95(50, 100);
        assert!(
            (lo - 0.4038).abs() < 1e-4 && (hi - 0.5962).abs() < 1e-4,
            "{lo} {hi}"
        );
        // 0 of 10: 0 to 0.2775.
        let [lo, hi] = wilson95(0, 10);
        assert_eq!(lo, 0.0);
        assert!((hi - 0.2775).abs() < 1e-4);
        assert!(wilson95(10, 10)[1] > 0.9999);
    }
}
