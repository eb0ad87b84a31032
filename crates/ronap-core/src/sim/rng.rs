//! Random streams derived from one episode seed.
//!
//! Each purpose (scene, start/goal, sensor noise, policy) draws from its own ChaCha8 stream keyed by
//! the seed, so turning noise on or swapping the policy changes nothing else, and an episode's
//! randomness depends on its seed alone, never on which thread runs it.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

/// The generator every stream uses: ChaCha8, portable and reproducible across platforms.
pub type Rng = ChaCha8Rng;

/// What a random stream is used for. Each purpose is a separate ChaCha stream of the same key.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u64)]
pub enum Stream {
    /// Maze generation.
    Scene = 1,
    /// Start pose and goal.
    Placement = 2,
    /// Laser noise.
    Noise = 3,
    /// Reserved for policies that draw random numbers.
    Policy = 4,
    /// Re-posing after each recorded action in data collection.
    Repose = 5,
    /// Moving obstacles: their starts, directions, turns and appearances.
    Moving = 6,
    /// The starts and goals of a team's robots after the first.
    Team = 7,
    /// The jitter of a `[[robots]]` entry's fixed start and goal.
    Jitter = 8,
    /// Motion noise on the executed velocity.
    Motion = 9,
    /// Goal-sensing noise.
    GoalSense = 10,
    /// Laser beam dropout.
    Dropout = 11,
    /// Laser beam-angle jitter.
    BeamJitter = 12,
    /// The key of the `random_walk` obstacles' turn streams ([`split_mix`]): one draw.
    Walk = 13,
}

/// The generator for `purpose` in the episode with `seed`.
pub fn stream(seed: u64, purpose: Stream) -> Rng {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(purpose as u64);
    rng
}

/// The generator for `purpose` of robot `robot` of a team in the episode with `seed`: robot 0's
/// is the lone robot's ([`stream`]), so a team of one draws what a lone robot draws; each other
/// robot has streams of its own.
pub fn robot_stream(seed: u64, purpose: Stream, robot: usize) -> Rng {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    // Purposes are below 256: robot k's streams sit k * 256 above robot 0's.
    rng.set_stream(purpose as u64 + ((robot as u64) << 8));
    rng
}

/// The increment of a SplitMix64 stream (Steele, Lea and Flood 2014): the golden ratio's
/// fraction, odd, as a 64-bit integer.
pub const SPLIT_MIX_GAMMA: u64 = 0x9e37_79b9_7f4a_7c15;

/// SplitMix64's output function: the number a stream at `state` gives. A stream is `state`
/// advanced by [`SPLIT_MIX_GAMMA`] before each draw. Integer operations only, so the same bits on
/// every processor, and many streams side by side vectorise (the `random_walk` turns, one stream
/// per obstacle).
#[inline(always)]
pub fn split_mix(state: u64) -> u64 {
    let mut z = state;
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::Rng as _;

    #[test]
    fn split_mix_gives_the_reference_numbers() {
        // SplitMix64 seeded with 1234567: the first outputs of the reference implementation
        // (Vigna's splitmix64.c).
        let mut state = 1_234_567u64;
        let mut next = || {
            state = state.wrapping_add(SPLIT_MIX_GAMMA);
            split_mix(state)
        };
        assert_eq!(next(), 6_457_827_717_110_365_317);
        assert_eq!(next(), 3_203_168_211_198_807_973);
        assert_eq!(next(), 9_817_491_932_198_370_423);
    }

    #[test]
    fn streams_are_distinct_and_reproducible() {
        let a: u64 = stream(7, Stream::Scene).random();
        let b: u64 = stream(7, Stream::Scene).random();
        let c: u64 = stream(7, Stream::Noise).random();
        let d: u64 = stream(8, Stream::Scene).random();
        assert_eq!(a, b);
        assert_ne!(a, c);
        assert_ne!(a, d);
        let mut robot_0 = robot_stream(7, Stream::Noise, 0);
        assert_eq!(robot_0.random::<u64>(), c);
        let robots: Vec<u64> = (0..4)
            .map(|k| robot_stream(7, Stream::Noise, k).random())
            .collect();
        for (i, x) in robots.iter().enumerate() {
            assert!(robots[..i].iter().all(|y| y != x), "{robots:?}");
            assert_ne!(*x, a);
        }
    }
}
