//! Seed splits: three named, disjoint spaces of episode seeds, so that what a policy trains on,
//! what picks its settings and what scores it never meet by accident.
//!
//! | split | seeds |
//! | --- | --- |
//! | `test` | 0 ..= 499 999 (what `ronap run --seeds N` plays by default) |
//! | `validation` | 500 000 ..= 999 999 |
//! | `train` | 1 000 000 ..= 2^64 - 1 |
//!
//! The boundaries are the ones ronap's own training has always kept (`ronap train dqn`'s
//! episodes from seed 1 000 000, its validation from 500 000), so every seed recorded before the
//! splits had names lies in the split it was used as. A weights file may record the seeds it
//! was trained and chosen on ([`SeedRanges`]); an evaluation on any of them is then warned
//! about (`eval::held_out_warning`).

use std::fmt;
use std::ops::RangeInclusive;

/// One of the three seed spaces.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Split {
    /// Seeds that score policies: 0 ..= 499 999.
    Test,
    /// Seeds that choose among trained policies and settings: 500 000 ..= 999 999.
    Validation,
    /// Seeds that train policies: 1 000 000 and up.
    Train,
}

impl Split {
    /// Every split, in seed order.
    pub const ALL: [Self; 3] = [Self::Test, Self::Validation, Self::Train];

    /// The split's name: `test`, `validation` or `train`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Test => "test",
            Self::Validation => "validation",
            Self::Train => "train",
        }
    }

    /// The split of that name.
    pub fn parse(name: &str) -> Result<Self, String> {
        Self::ALL
            .into_iter()
            .find(|s| s.name() == name)
            .ok_or_else(|| format!("split {name:?}: expected test, validation or train"))
    }

    /// The split's seeds.
    pub fn range(self) -> RangeInclusive<u64> {
        match self {
            Self::Test => 0..=499_999,
            Self::Validation => 500_000..=999_999,
            Self::Train => 1_000_000..=u64::MAX,
        }
    }

    /// The split a seed lies in.
    pub fn of(seed: u64) -> Self {
        Self::ALL
            .into_iter()
            .find(|s| s.range().contains(&seed))
            .unwrap_or(Self::Train)
    }

    /// The first of the `count` seeds of this split from its `offset`-th (`Test` from 0 gives
    /// 0, 1, 2, ...; `Validation` from 0 gives 500 000, ...), or an error naming the split's
    /// seeds when they would leave it.
    pub fn start(self, offset: u64, count: u64) -> Result<u64, String> {
        let range = self.range();
        let start = range.start().checked_add(offset);
        let last = start.and_then(|s| s.checked_add(count.saturating_sub(1)));
        match (start, last) {
            (Some(start), Some(last)) if last <= *range.end() => Ok(start),
            _ => Err(format!(
                "{count} seeds from the {offset}-th of the {} split leave it: it holds seeds \
                 {}..={}",
                self.name(),
                range.start(),
                range.end()
            )),
        }
    }

    /// The seed of this split `index` seeds from its first, or an error when there is none.
    pub fn seed(self, index: u64) -> Result<u64, String> {
        self.start(index, 1)
    }
}

impl fmt::Display for Split {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Seed ranges a policy was trained or chosen on, as a weights file records them: comma
/// separated `A..=B` (both ends in), `A..` (from A on) or single seeds, e.g.
/// `1000000..=1001982,500000..=500999`.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct SeedRanges(pub Vec<RangeInclusive<u64>>);

impl SeedRanges {
    /// Reads the text form; an error names the part that is not a range.
    pub fn parse(text: &str) -> Result<Self, String> {
        let number = |s: &str, part: &str| {
            s.trim()
                .parse::<u64>()
                .map_err(|_| format!("seed range {part:?}: expected A..=B, A.. or a seed"))
        };
        let mut ranges = Vec::new();
        for part in text.split(',').map(str::trim).filter(|p| !p.is_empty()) {
            let range = if let Some((a, b)) = part.split_once("..=") {
                number(a, part)?..=number(b, part)?
            } else if let Some(a) = part.strip_suffix("..") {
                number(a, part)?..=u64::MAX
            } else {
                let s = number(part, part)?;
                s..=s
            };
            ranges.push(range);
        }
        Ok(Self(ranges))
    }

    /// Adds the ranges of `other`.
    pub fn extend(&mut self, other: SeedRanges) {
        self.0.extend(other.0);
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    /// How many of the `count` seeds from `start` lie in these ranges, and the first of them:
    /// counted range by range, however long the run.
    pub fn overlap_range(&self, start: u64, count: u64) -> (u64, Option<u64>) {
        if count == 0 {
            return (0, None);
        }
        let last = start.saturating_add(count - 1);
        let mut shared: Vec<(u64, u64)> = self
            .0
            .iter()
            .filter(|r| *r.start() <= last && *r.end() >= start)
            .map(|r| ((*r.start()).max(start), (*r.end()).min(last)))
            .collect();
        shared.sort_unstable();
        let (mut total, mut reach) = (0u64, None::<u64>);
        for &(a, b) in &shared {
            let a = reach.map_or(a, |r| a.max(r.saturating_add(1)));
            if a <= b {
                total = total.saturating_add(b - a + 1);
            }
            reach = Some(reach.map_or(b, |r| r.max(b)));
        }
        (total, shared.first().map(|s| s.0))
    }

    /// How many of `seeds` lie in these ranges, and the first of them in their order.
    pub fn overlap_list(&self, seeds: impl IntoIterator<Item = u64>) -> (u64, Option<u64>) {
        let mut inside = seeds
            .into_iter()
            .filter(|s| self.0.iter().any(|r| r.contains(s)));
        let first = inside.next();
        (first.map_or(0, |_| 1 + inside.count() as u64), first)
    }
}

impl fmt::Display for SeedRanges {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, r) in self.0.iter().enumerate() {
            if i > 0 {
                f.write_str(",")?;
            }
            match (*r.start(), *r.end()) {
                (a, u64::MAX) => write!(f, "{a}..")?,
                (a, b) if a == b => write!(f, "{a}")?,
                (a, b) => write!(f, "{a}..={b}")?,
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn splits_are_disjoint_and_cover_every_seed() {
        assert_eq!(Split::of(0), Split::Test);
        assert_eq!(Split::of(499_999), Split::Test);
        assert_eq!(Split::of(500_000), Split::Validation);
        assert_eq!(Split::of(1_000_000), Split::Train);
        assert_eq!(Split::of(u64::MAX), Split::Train);
        for s in Split::ALL {
            assert_eq!(Split::parse(s.name()), Ok(s));
            assert_eq!(Split::of(*s.range().start()), s);
            assert_eq!(Split::of(*s.range().end()), s);
        }
        assert!(Split::parse("dev")
            .unwrap_err()
            .contains("test, validation or train"));
    }

    #[test]
    fn a_splits_seeds_count_from_its_first_and_stay_inside() {
        assert_eq!(Split::Validation.start(10, 3), Ok(500_010));
        assert_eq!(Split::Test.start(0, 500_000), Ok(0));
        let err = Split::Test.start(0, 500_001).unwrap_err();
        assert!(err.contains("0..=499999"), "{err}");
        assert!(Split::Train.start(u64::MAX, 2).is_err());
        assert_eq!(Split::Train.seed(5), Ok(1_000_005));
    }

    #[test]
    fn ranges_parse_print_and_count_their_overlap() {
        let r = SeedRanges::parse("1000000..=1001982, 500000..=500999,7,2000000..").unwrap();
        assert_eq!(
            r.to_string(),
            "1000000..=1001982,500000..=500999,7,2000000.."
        );
        assert!(SeedRanges::parse("12-14").unwrap_err().contains("12-14"));
        assert_eq!(r.overlap_range(0, 1000), (1, Some(7)));
        assert_eq!(r.overlap_range(500_000, 2000), (1000, Some(500_000)));
        assert_eq!(r.overlap_list([3, 500_001, 2_000_005]), (2, Some(500_001)));
        assert_eq!(r.overlap_range(100, 0), (0, None));
        // Overlapping ranges count a seed once.
        let twice = SeedRanges::parse("10..=20,15..=30").unwrap();
        assert_eq!(twice.overlap_range(0, 100), (21, Some(10)));
    }
}
