//! What a comparison found: each policy's figures and per-seed results, the paired statistics
//! of every pair, and results by difficulty. `compare.json` is this, serialised.

use super::difficulty::{Bin, Difficulty, Figure};
use crate::config::ValidConfig;
use crate::eval::{EpisodeRecord, Outcome, Summary, TeamRecord, TeamSummary};
use serde::Serialize;
use std::path::PathBuf;

/// One policy's result on one seed: what the comparison pairs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SeedResult {
    /// The seed.
    pub seed: u64,
    /// How the episode ended.
    pub outcome: Outcome,
    /// Steps taken.
    pub steps: u32,
    /// Colliding steps.
    pub collisions: u32,
    /// Distance driven, px.
    pub path_length_px: f64,
    /// SPL.
    pub spl: f64,
}

/// `x` as a file writes it with `digits` decimals, read back.
fn rounded(x: f64, digits: usize) -> f64 {
    format!("{x:.digits$}").parse().unwrap_or(x)
}

impl SeedResult {
    /// The result in `r`, rounded as `episodes.csv` writes it, so a comparison gives the same
    /// figures whether a run is fresh or read back with `--run`.
    pub(crate) fn of(r: &EpisodeRecord) -> Self {
        let spl = rounded(r.spl, 4);
        let (seed, outcome, steps, collisions) = (r.seed, r.outcome, r.steps, r.collisions);
        Self::rounding(seed, outcome, steps, collisions, r.path_length_px, spl)
    }

    /// The result of team episode `r`: the team's outcome, steps, summed wall collisions and
    /// path length, and its robots' mean SPL (rounded as `episodes.csv` and `robots.csv` write
    /// them).
    pub(crate) fn of_team(r: &TeamRecord) -> Self {
        let spl =
            r.robots.iter().map(|x| rounded(x.spl, 4)).sum::<f64>() / r.robots.len().max(1) as f64;
        let (seed, outcome, steps, collisions) = (r.seed, r.outcome, r.steps, r.collisions);
        Self::rounding(seed, outcome, steps, collisions, r.path_length_px, spl)
    }

    /// A result with its path length rounded as the files write it.
    fn rounding(
        seed: u64,
        outcome: Outcome,
        steps: u32,
        collisions: u32,
        path_length_px: f64,
        spl: f64,
    ) -> Self {
        Self {
            seed,
            outcome,
            steps,
            collisions,
            path_length_px: rounded(path_length_px, 3),
            spl,
        }
    }

    /// Whether the episode succeeded.
    pub fn success(&self) -> bool {
        self.outcome == Outcome::Success
    }
}

/// One policy's figures.
#[derive(Clone, Debug, Serialize)]
pub struct PolicyResult {
    /// The policy as named.
    pub name: String,
    /// Its short name in files and tables (unique in the comparison).
    pub label: String,
    /// Its run directory.
    pub run_dir: Option<PathBuf>,
    /// Whether the run was read from `--run` rather than run again.
    pub reused: bool,
    /// The figures (of every robot, in a team comparison).
    pub summary: Summary,
    /// The team figures, in a team comparison.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub team: Option<TeamSummary>,
    /// Each seed's result, in seed order.
    #[serde(skip)]
    pub seeds: Vec<SeedResult>,
}

/// Two policies on the same seeds.
#[derive(Clone, Debug, Serialize)]
pub struct PairResult {
    /// The first policy's label.
    pub a: String,
    /// The second policy's label.
    pub b: String,
    /// Success rate of `a` minus that of `b`.
    pub success_diff: f64,
    /// Its 95% paired bootstrap interval (none from a single seed).
    pub success_diff_ci95: Option<[f64; 2]>,
    /// Seeds only `a` succeeded on.
    pub a_only: u64,
    /// Seeds only `b` succeeded on.
    pub b_only: u64,
    /// McNemar's exact two-sided p-value on those seeds.
    pub mcnemar_p: f64,
    /// The p-value after Holm's adjustment over all pairs.
    pub holm_p: f64,
    /// Mean SPL of `a` minus that of `b` (paired by seed).
    pub spl_diff: f64,
    /// Its 95% paired bootstrap interval, not adjusted for the number of pairs (none from a
    /// single seed).
    pub spl_diff_ci95: Option<[f64; 2]>,
    /// What a reader should take from it.
    pub verdict: String,
}

/// Results within one bin of a difficulty figure.
#[derive(Clone, Debug, Serialize)]
pub struct BinResult {
    /// The bin.
    #[serde(flatten)]
    pub bin: Bin,
    /// Seeds in it.
    pub seeds: usize,
    /// Each policy's success rate there, in policy order.
    pub success_rate: Vec<f64>,
    /// Each policy's 95% Wilson interval there.
    pub success_ci95: Vec<[f64; 2]>,
    /// Each policy's mean SPL there.
    pub spl: Vec<f64>,
}

/// Results broken down by one difficulty figure.
#[derive(Clone, Debug, Serialize)]
pub struct Breakdown {
    /// The figure.
    pub figure: Figure,
    /// Its bins, lowest values first.
    pub bins: Vec<BinResult>,
    /// Seeds without the figure (no path to the goal).
    pub unbinned: usize,
}

/// A finished comparison: what `compare.json` holds.
#[derive(Clone, Debug, Serialize)]
pub struct Comparison {
    /// The ronap version that made it.
    pub ronap_version: String,
    /// What counts as a success, in words.
    pub success_rule: String,
    /// Where episodes took place.
    pub scenes: String,
    /// The first seed.
    pub seed_start: u64,
    /// Seeds, the same for every policy.
    pub seed_count: usize,
    /// The last seed.
    pub seed_last: u64,
    /// Whether the seeds run from `seed_start` to `seed_last` one by one.
    pub seeds_contiguous: bool,
    /// Each policy's figures, in the order given.
    pub policies: Vec<PolicyResult>,
    /// Every pair, in the order given.
    pub pairs: Vec<PairResult>,
    /// Results by difficulty, when asked for.
    pub by_difficulty: Option<Vec<Breakdown>>,
    /// Each seed's difficulty, when asked for.
    #[serde(skip)]
    pub difficulty: Vec<Option<Difficulty>>,
    /// The command that reproduces it.
    pub command: String,
    /// The whole configuration.
    #[serde(skip)]
    pub config: ValidConfig,
}
