//! The flags the commands share, and the one place where they become validated values: the value
//! parsers below check each flag as clap reads it, [`sim`] turns the model flags and a config file
//! into one `ValidConfig` (flags win over the file, the file over defaults) and the scene flags
//! into the core's `SceneSpec`, and [`policy`] turns a policy name into a policy factory. The
//! commands (`crate::commands`) see only the results.

pub mod policy;
pub mod sim;

pub use policy::{named_policy, policy_factory, TeamPolicies};
pub use sim::{EpisodeArgs, EvalArgs, SimArgs, WorkArgs};

use clap::Args;
use ronap_core::eval::{held_out_warning, Seeds};
use ronap_core::policy::PolicyFactory;
use ronap_core::sim::Split;

/// Parses a positive, finite number of px.
pub fn positive(s: &str) -> Result<f64, String> {
    let v: f64 = s.parse().map_err(|_| format!("{s:?} is not a number"))?;
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err("must be a positive number".into())
    }
}

/// Parses a finite number of at least 0.
#[cfg_attr(not(feature = "learn"), allow(dead_code))] // only `train` takes one today
pub fn non_negative(s: &str) -> Result<f64, String> {
    let v: f64 = s.parse().map_err(|_| format!("{s:?} is not a number"))?;
    if v.is_finite() && v >= 0.0 {
        Ok(v)
    } else {
        Err("must be zero or a positive number".into())
    }
}

/// Parses a whole number of at least 1.
pub fn count(s: &str) -> Result<u64, String> {
    match s.parse::<u64>() {
        Ok(n) if n >= 1 => Ok(n),
        Err(e) if *e.kind() == std::num::IntErrorKind::PosOverflow => {
            Err("must be at most 18446744073709551615".into())
        }
        _ => Err("must be a whole number of at least 1".into()),
    }
}

/// Parses a seed: a whole number from 0 to 2^64 - 1.
pub fn seed(s: &str) -> Result<u64, String> {
    s.parse::<u64>()
        .map_err(|_| "a seed must be a whole number from 0 to 18446744073709551615".into())
}

/// Parses a fraction in (0, 1].
#[cfg_attr(not(feature = "learn"), allow(dead_code))] // only `train` takes one today
pub fn share(s: &str) -> Result<f64, String> {
    match fraction(s)? {
        0.0 => Err("must be above 0 and at most 1".into()),
        v => Ok(v),
    }
}

/// Parses a fraction in [0, 1].
pub fn fraction(s: &str) -> Result<f64, String> {
    let v: f64 = s.parse().map_err(|_| format!("{s:?} is not a number"))?;
    if (0.0..=1.0).contains(&v) {
        Ok(v)
    } else {
        Err("must be between 0 and 1".into())
    }
}

/// The seeds `first`, `first + 1`, ... (`count` of them) held in memory, or a one-line error
/// naming the flags when the range passes 2^64 or cannot be held.
pub fn seed_range(first: u64, count: u64) -> anyhow::Result<Vec<u64>> {
    let end = first.checked_add(count).ok_or_else(|| {
        anyhow::anyhow!("--seed-start {first} --seeds {count}: the seed range passes 2^64")
    })?;
    let mut seeds = Vec::new();
    seeds.try_reserve_exact(count as usize).map_err(|_| {
        anyhow::anyhow!(
            "--seeds {count}: too many seeds to hold in memory for one run; split it with \
             --seed-start"
        )
    })?;
    seeds.extend(first..end);
    Ok(seeds)
}

/// Parses a seed split's name.
pub fn split(s: &str) -> Result<Split, String> {
    Split::parse(s)
}

/// The episodes' seeds: how many, from which, in which split.
#[derive(Args, Debug, Clone, Copy)]
pub struct SeedArgs {
    /// Number of episodes; episode i has seed seed-start + i.
    #[arg(long, allow_negative_numbers = true, value_name = "N", default_value_t = 1000, value_parser = count)]
    pub seeds: u64,
    /// First seed (with --split, counted from the split's first seed).
    #[arg(long, allow_negative_numbers = true, value_name = "SEED", default_value_t = 0, value_parser = seed)]
    pub seed_start: u64,
    /// Play the seeds of a named split, which never meet: test (0..=499999), validation
    /// (500000..=999999) or train (1000000 and up) [default: the seeds as given; the default
    /// ones are the test split's].
    #[arg(long, value_name = "SPLIT", value_parser = split)]
    pub split: Option<Split>,
}

impl SeedArgs {
    /// The first seed: `--seed-start`, or with `--split` that many seeds into the split; an
    /// error when the range passes 2^64 or leaves the split.
    pub fn first(&self) -> anyhow::Result<u64> {
        let first = match self.split {
            Some(split) => split.start(self.seed_start, self.seeds).map_err(|e| {
                anyhow::anyhow!(
                    "--split {split} --seed-start {} --seeds {}: {e}",
                    self.seed_start,
                    self.seeds
                )
            })?,
            None => self.seed_start,
        };
        first.checked_add(self.seeds).ok_or_else(|| {
            anyhow::anyhow!(
                "--seed-start {first} --seeds {}: the seed range passes 2^64",
                self.seeds
            )
        })?;
        Ok(first)
    }

    /// The seeds, as a range.
    pub fn range(&self) -> anyhow::Result<Seeds> {
        Ok(Seeds::Range {
            start: self.first()?,
            count: self.seeds,
        })
    }
}

/// Warns on stderr when some of `seeds` are among those the policy was trained or chosen on.
pub fn warn_if_not_held_out(name: &str, factory: &dyn PolicyFactory, seeds: &Seeds) {
    if let Some(w) = held_out_warning(name, &factory.seeds_seen(), seeds) {
        eprintln!("warning: {w}");
    }
}

/// The worker-thread flag.
#[derive(Args, Debug, Clone, Copy, Default)]
pub struct ThreadArgs {
    /// Worker threads [default: all cores].
    #[arg(long, allow_negative_numbers = true, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub threads: Option<u32>,
}

impl ThreadArgs {
    /// The number of worker threads: the flag's, or all cores.
    pub fn count(self) -> usize {
        self.threads.map_or_else(
            || std::thread::available_parallelism().map_or(1, |n| n.get()),
            |n| n as usize,
        )
    }
}
