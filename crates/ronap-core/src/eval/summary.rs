//! The figures of an evaluation: success rate with its confidence interval, failures by kind,
//! path efficiency (SPL) and speed.

use crate::eval::{EpisodeRecord, Outcome};
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

impl Summary {
    /// The summary of `records`, over a run that took `wall_time_s`.
    pub fn new(records: &[EpisodeRecord], wall_time_s: f64) -> Self {
        let n = records.len();
        let count = |o: Outcome| records.iter().filter(|r| r.outcome == o).count();
        let mean = |f: &dyn Fn(&EpisodeRecord) -> f64| {
            if n == 0 {
                0.0
            } else {
                records.iter().map(f).sum::<f64>() / n as f64
            }
        };
        let successes = count(Outcome::Success);
        let dynamic: Vec<_> = records
            .iter()
            .filter_map(|r| r.dynamic.map(|d| (d, r.steps)))
            .collect();
        let moving = (!dynamic.is_empty()).then(|| {
            let k = dynamic.len() as f64;
            let clear: Vec<f64> = dynamic
                .iter()
                .map(|(d, _)| d.min_clearance_px)
                .filter(|c| c.is_finite())
                .collect();
            MovingSummary {
                dynamic_collisions_per_episode: dynamic
                    .iter()
                    .map(|(d, _)| d.collisions as f64)
                    .sum::<f64>()
                    / k,
                episodes_with_dynamic_collision: dynamic
                    .iter()
                    .filter(|(d, _)| d.collisions > 0)
                    .count(),
                mean_min_clearance_px: if clear.is_empty() {
                    0.0
                } else {
                    clear.iter().sum::<f64>() / clear.len() as f64
                },
                near_moving_fraction: dynamic
                    .iter()
                    .map(|(d, steps)| d.near_steps as f64 / (*steps).max(1) as f64)
                    .sum::<f64>()
                    / k,
            }
        });
        let steps: u64 = records.iter().map(|r| r.steps as u64).sum();
        Self {
            episodes: n,
            successes,
            success_rate: if n == 0 {
                0.0
            } else {
                successes as f64 / n as f64
            },
            success_ci95: wilson95(successes, n),
            timeouts: count(Outcome::Timeout),
            stuck: count(Outcome::Stuck),
            collision_ends: count(Outcome::Collision),
            reward_min_ends: count(Outcome::RewardMin),
            collisions_per_episode: mean(&|r| r.collisions as f64),
            mean_steps: mean(&|r| r.steps as f64),
            mean_path_length_px: mean(&|r| r.path_length_px),
            spl: mean(&|r| r.spl),
            mean_return: mean(&|r| r.total_reward),
            wall_time_s,
            steps_per_second: if wall_time_s > 0.0 {
                steps as f64 / wall_time_s
            } else {
                0.0
            },
            moving,
        }
    }

    /// The summary as an aligned two-column table for a terminal.
    pub fn table(&self) -> String {
        let pct = |x: f64| format!("{:.1}%", 100.0 * x);
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

#[cfg(test)]
mod tests {
    use super::*;

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
