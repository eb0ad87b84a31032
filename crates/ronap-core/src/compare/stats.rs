//! Paired statistics for two policies run on the same seeds: McNemar's exact test on the seeds
//! where exactly one of them succeeded, a bootstrap interval of a paired mean difference, and
//! Holm's step-down adjustment when several pairs are tested at once.

use rand::{Rng as _, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// A p-value (after Holm's adjustment) below this calls a difference real.
pub const ALPHA: f64 = 0.05;

/// Two-sided p-value of McNemar's exact test: under "both policies succeed equally often", each
/// of the `a_only + b_only` discordant seeds is a fair coin, so the p-value is twice the smaller
/// binomial tail (at most 1). No discordant seed at all gives 1.
pub fn mcnemar_exact(a_only: u64, b_only: u64) -> f64 {
    let n = a_only + b_only;
    if n == 0 {
        return 1.0;
    }
    let k = a_only.min(b_only);
    // P(X <= k) for X ~ Binomial(n, 1/2), summed in logs: C(n, i) 2^-n overflows past n ~ 1000.
    let ln_half_n = -(n as f64) * std::f64::consts::LN_2;
    let mut ln_choose = 0.0; // ln C(n, 0)
    let mut terms = Vec::with_capacity(k as usize + 1);
    for i in 0..=k {
        if i > 0 {
            ln_choose += ((n - i + 1) as f64).ln() - (i as f64).ln();
        }
        terms.push(ln_choose + ln_half_n);
    }
    let top = terms.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let tail = top.exp() * terms.iter().map(|t| (t - top).exp()).sum::<f64>();
    (2.0 * tail).min(1.0)
}

/// The fewest discordant seeds with which McNemar's exact test can reach [`ALPHA`]: with `n`,
/// the smallest two-sided p-value is `2^(1 - n)`.
pub fn min_discordant() -> u64 {
    (1..64)
        .find(|&n| 2f64.powi(1 - n as i32) < ALPHA)
        .unwrap_or(64)
}

/// The least number of bootstrap resamples a comparison takes.
pub const MIN_RESAMPLES: usize = 100;

/// The mean of `d` and its 95% percentile bootstrap interval from `resamples` resamples of the
/// seeds with replacement, drawn from a generator seeded with `seed` (so the interval is the same
/// on every run). No interval (`None`) from fewer than two values or no resamples: one seed
/// says nothing about the spread.
pub fn bootstrap_mean95(d: &[f64], resamples: usize, seed: u64) -> (f64, Option<[f64; 2]>) {
    let n = d.len();
    if n == 0 {
        return (0.0, None);
    }
    let mean = d.iter().sum::<f64>() / n as f64;
    if n < 2 || resamples == 0 {
        return (mean, None);
    }
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut means: Vec<f64> = (0..resamples)
        .map(|_| (0..n).map(|_| d[rng.random_range(0..n)]).sum::<f64>() / n as f64)
        .collect();
    means.sort_by(f64::total_cmp);
    (
        mean,
        Some([quantile(&means, 0.025), quantile(&means, 0.975)]),
    )
}

/// The `q` quantile of sorted `v` (linear interpolation between order statistics).
pub fn quantile(v: &[f64], q: f64) -> f64 {
    match v.len() {
        0 => f64::NAN,
        1 => v[0],
        n => {
            let at = q.clamp(0.0, 1.0) * (n - 1) as f64;
            let (lo, hi) = (at.floor() as usize, at.ceil() as usize);
            v[lo] + (v[hi] - v[lo]) * (at - lo as f64)
        }
    }
}

/// Holm's step-down adjustment of `p` (family-wise error over all the tests), in the same order.
pub fn holm(p: &[f64]) -> Vec<f64> {
    let m = p.len();
    let mut order: Vec<usize> = (0..m).collect();
    order.sort_by(|&a, &b| p[a].total_cmp(&p[b]));
    let mut adjusted = vec![0.0; m];
    let mut running: f64 = 0.0;
    for (rank, &i) in order.iter().enumerate() {
        running = running.max(((m - rank) as f64 * p[i]).min(1.0));
        adjusted[i] = running;
    }
    adjusted
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mcnemar_matches_hand_computed_binomial_tails() {
        // 0 vs 5: 2 * (1/2)^5 = 0.0625.
        assert!((mcnemar_exact(0, 5) - 0.0625).abs() < 1e-12);
        // 1 vs 9: 2 * (1 + 10) / 1024 = 0.021484375.
        assert!((mcnemar_exact(1, 9) - 0.021_484_375).abs() < 1e-12);
        assert!((mcnemar_exact(9, 1) - 0.021_484_375).abs() < 1e-12);
        // 2 vs 3: the smaller tail is P(X <= 2) = 16/32, doubled past 1.
        assert!((mcnemar_exact(2, 3) - 1.0).abs() < 1e-12);
        assert_eq!(mcnemar_exact(0, 0), 1.0);
        // 3 vs 12: 2 * (1 + 15 + 105 + 455) / 32768 = 0.03515625.
        assert!((mcnemar_exact(3, 12) - 0.035_156_25).abs() < 1e-12);
    }

    #[test]
    fn mcnemar_stays_finite_for_many_discordant_seeds() {
        let p = mcnemar_exact(4000, 6000);
        assert!(p > 0.0 && p < 1e-50, "{p}");
        let p = mcnemar_exact(5000, 5000);
        assert!((p - 1.0).abs() < 1e-12, "{p}");
        // 480 vs 520 of 1000: a normal approximation with continuity correction gives ~0.218.
        let p = mcnemar_exact(480, 520);
        assert!((p - 0.218).abs() < 0.01, "{p}");
    }

    #[test]
    fn bootstrap_of_a_constant_is_that_constant() {
        let (m, ci) = bootstrap_mean95(&[0.25; 50], 500, 1);
        assert_eq!((m, ci), (0.25, Some([0.25, 0.25])));
        // One seed gives no interval.
        assert_eq!(bootstrap_mean95(&[0.5], 500, 1), (0.5, None));
    }

    #[test]
    fn bootstrap_interval_matches_the_hand_computed_spread() {
        // Half zeros, half ones: mean 0.5, standard error sqrt(0.25 / 400) = 0.025, so the 95%
        // interval is 0.5 -+ 0.049 to within the resampling noise.
        let d: Vec<f64> = (0..400).map(|i| (i % 2) as f64).collect();
        let (m, ci) = bootstrap_mean95(&d, 4000, 7);
        let [lo, hi] = ci.unwrap();
        assert_eq!(m, 0.5);
        assert!(
            (lo - 0.451).abs() < 0.01 && (hi - 0.549).abs() < 0.01,
            "{lo} {hi}"
        );
        // The same seed gives the same interval.
        assert_eq!(bootstrap_mean95(&d, 4000, 7).1, Some([lo, hi]));
    }

    #[test]
    fn bootstrap_of_two_values_spans_their_resample_means() {
        // Resampling {0, 1} twice gives means 0, 1/2 and 1 with chances 1/4, 1/2, 1/4: the 2.5%
        // and 97.5% quantiles of many resamples are 0 and 1.
        let (m, ci) = bootstrap_mean95(&[0.0, 1.0], 2000, 3);
        assert_eq!((m, ci), (0.5, Some([0.0, 1.0])));
    }

    #[test]
    fn holm_adjusts_in_step_down_order() {
        let adjusted = holm(&[0.01, 0.04, 0.03, 0.5]);
        // Sorted 0.01, 0.03, 0.04, 0.5 times 4, 3, 2, 1, kept non-decreasing.
        assert_eq!(adjusted, vec![0.04, 0.09, 0.09, 0.5]);
        assert!(holm(&[]).is_empty());
    }

    #[test]
    fn quantiles_interpolate() {
        let v = [1.0, 2.0, 3.0, 4.0, 5.0];
        assert_eq!(quantile(&v, 0.5), 3.0);
        assert_eq!(quantile(&v, 0.25), 2.0);
        assert_eq!(quantile(&v, 0.125), 1.5);
    }
}
