//! The heading motions, `linear` and `random_walk`, moved together: where every obstacle is and
//! where it heads, one array per quantity, so that the turns, the moves and the fast clearance
//! test of all of them run as one vectorised pass; and the order by band and x that lets a scan
//! or a sweep look only at the obstacles within its reach.

use crate::geometry::{Aabb, Point, Vector};
use crate::sim::moving::Entry;
use crate::sim::rng::{split_mix, SPLIT_MIX_GAMMA};

/// Where the obstacles are and where they head, one array per quantity, so that the turns, the
/// moves and the fast clearance test of every obstacle run as one vectorised pass.
#[derive(Clone, Debug, Default)]
pub(super) struct State {
    pub(super) x: Vec<f64>,
    pub(super) y: Vec<f64>,
    /// Unit heading (`linear`, `random_walk`).
    pub(super) dx: Vec<f64>,
    pub(super) dy: Vec<f64>,
    pub(super) speed: Vec<f64>,
    /// Where the centre may go with no query: a box clear of the still scene shrunk by the body
    /// (empty until first measured). A straight move between two points inside it is clear.
    lo_x: Vec<f64>,
    lo_y: Vec<f64>,
    hi_x: Vec<f64>,
    hi_y: Vec<f64>,
    /// Bounding radius of the body, px.
    pub(super) bound: Vec<f64>,
    /// Squared distance from the robot's centre within which a move must be checked against it.
    pub(super) near_robot2: Vec<f64>,
    /// Whether it moves along its heading this step ([`Entry::walk`], kept up to date as
    /// obstacles appear or are released).
    pub(super) walks: Vec<bool>,
    /// The standard deviation of its turns, rad (0 when absent or not turning; the same).
    pub(super) sigma: Vec<f64>,
    /// Its turn stream: a SplitMix64 state, advanced every step whether it turns or not
    /// ([`State::draw_turns`]).
    stream: Vec<u64>,
    /// This step's turn, rad (0 for the obstacles not turning), and its sine and cosine.
    turn: Vec<f64>,
    sin: Vec<f64>,
    cos: Vec<f64>,
    /// This step's intended centre, and whether it lies in the free box.
    pub(super) ahead_x: Vec<f64>,
    pub(super) ahead_y: Vec<f64>,
    pub(super) fits: Vec<bool>,
    /// Whether the pass has moved it (a walk in its free box and far from the robot).
    pub(super) moved: Vec<bool>,
    /// The obstacles by band of [`BAND_PX`] in y, then by x, as of the end of the last step, and
    /// where each band starts in that order (`band_start`, one past the last band at the end): a
    /// scan looks only at the obstacles of the bands within its reach whose x is within its reach
    /// too. Obstacles move a few px a step, so the order barely changes and an insertion sort
    /// keeps it in a pass.
    keys: Vec<Key>,
    band_start: Vec<u32>,
    /// Steps since `keys` were put in order: an obstacle may since have moved up to `age *
    /// drift` px on either axis, so a scan looks that much further in the old order, and the
    /// order is brought up to date every [`RESORT_EVERY`] steps (or when an obstacle appears).
    pub(super) age: u32,
    /// The furthest an obstacle moves in a step on either axis (its speed), px, with a margin
    /// for rounding.
    pub(super) drift: f64,
    /// The key of the turn streams ([`State::keyed`]).
    key: u64,
}

/// Steps between bringing the obstacles' order by band and x up to date: sorting costs more
/// than a step's scan, and in a few steps obstacles barely move.
pub(super) const RESORT_EVERY: u32 = 8;

/// An obstacle's place in [`State::keys`].
#[derive(Clone, Copy, Debug)]
struct Key {
    band: u32,
    obstacle: u32,
    x: f64,
}

impl Key {
    /// Whether `self` comes after `other`: by band, then by x.
    #[inline]
    pub(super) fn after(&self, other: &Key) -> bool {
        self.band > other.band || (self.band == other.band && self.x > other.x)
    }
}

/// Height of the bands of y by which [`State`] orders the obstacles for scans, px.
const BAND_PX: f64 = 64.0;

/// The band of y (below 0: band 0).
fn band(y: f64) -> u32 {
    // A float cast saturates (and takes NaN to 0), so every y has a band, in order.
    (y.max(0.0) / BAND_PX) as u32
}

/// [`State::pass`] as pulp runs it, compiled once per instruction set.
struct Pass<'a> {
    state: &'a mut State,
    robots: &'a [Point],
}

impl pulp::WithSimd for Pass<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _: S) {
        if self.state.draw_turns() {
            self.state.turn_wide();
        }
        self.state.pass(self.robots);
    }
}

/// Margin by which a centre must lie inside its free box, px: the fast test never accepts what
/// the exact one might refuse by a rounding.
const FIT_MARGIN: f64 = 1e-9;

impl State {
    /// No obstacles yet; obstacle k will turn by draws of its own SplitMix64 stream, starting at
    /// the k-th number of the one `key` starts.
    pub(super) fn keyed(key: u64) -> Self {
        Self {
            key,
            ..Self::default()
        }
    }

    /// Adds an obstacle of `entry` at `position` heading along `dir` at `speed` px a step,
    /// checked against a robot within `near_robot` px.
    pub(super) fn push(
        &mut self,
        entry: &Entry,
        position: Point,
        dir: Vector,
        speed: f64,
        near_robot: f64,
    ) {
        let k = self.stream.len() as u64;
        let first = self.key.wrapping_add((k + 1).wrapping_mul(SPLIT_MIX_GAMMA));
        self.stream.push(split_mix(first));
        self.drift = self.drift.max(speed * (1.0 + 1e-9));
        self.bound.push(entry.body.bounding_radius());
        self.near_robot2.push(near_robot * near_robot);
        let (walks, sigma) = entry.walk();
        self.walks.push(walks);
        self.sigma.push(sigma);
        self.moved.push(false);
        self.x.push(position.x);
        self.y.push(position.y);
        self.dx.push(dir.x);
        self.dy.push(dir.y);
        self.speed.push(speed);
        self.lo_x.push(f64::INFINITY);
        self.lo_y.push(f64::INFINITY);
        self.hi_x.push(f64::NEG_INFINITY);
        self.hi_y.push(f64::NEG_INFINITY);
        self.turn.push(0.0);
        self.sin.push(0.0);
        self.cos.push(1.0);
        self.ahead_x.push(0.0);
        self.ahead_y.push(0.0);
        self.fits.push(false);
    }

    pub(super) fn position(&self, i: usize) -> Point {
        Point::new(self.x[i], self.y[i])
    }

    /// Brings the order by band and x ([`State::keys`]) up to date with where the obstacles are.
    pub(super) fn sort_keys(&mut self) {
        self.age = 0;
        let n = self.x.len();
        if self.keys.len() != n {
            self.keys = (0..n as u32)
                .map(|obstacle| Key {
                    band: 0,
                    obstacle,
                    x: 0.0,
                })
                .collect();
        }
        let (x, y) = (&self.x[..n], &self.y[..n]);
        for key in &mut self.keys {
            let i = key.obstacle as usize;
            key.x = x[i];
            key.band = band(y[i]);
        }
        let keys = &mut self.keys[..];
        for k in 1..keys.len() {
            if keys[k - 1].after(&keys[k]) {
                let key = keys[k];
                let mut j = k;
                while j > 0 && keys[j - 1].after(&key) {
                    keys[j] = keys[j - 1];
                    j -= 1;
                }
                keys[j] = key;
            }
        }
        self.band_start.clear();
        for (k, key) in self.keys.iter().enumerate() {
            while self.band_start.len() <= key.band as usize {
                self.band_start.push(k as u32);
            }
        }
        self.band_start.push(n as u32);
    }

    /// Calls `f` with every obstacle whose centre may lie within `slab` px of `p` on both axes
    /// (and some that do not): those of the bands within reach whose x is within reach, as of
    /// the last sort, reach grown by how far obstacles may have moved since.
    #[inline]
    pub(super) fn near(&self, p: Point, slab: f64, mut f: impl FnMut(usize)) {
        let slab = slab + f64::from(self.age) * self.drift;
        let bands = self.band_start.len().saturating_sub(1);
        let (lo, hi) = (band(p.y - slab) as usize, band(p.y + slab) as usize);
        let (left, right) = (p.x - slab, p.x + slab);
        for b in lo..=hi.min(bands.saturating_sub(1)) {
            let (s, e) = (self.band_start[b] as usize, self.band_start[b + 1] as usize);
            let run = &self.keys[s..e];
            // A band holds a few obstacles: a plain walk beats a binary search to the first.
            for key in run {
                if key.x < left {
                    continue;
                }
                if key.x > right {
                    break;
                }
                f(key.obstacle as usize);
            }
        }
    }

    /// Draws this step's turns, turns every heading by its turn and moves it `speed` ahead into
    /// `ahead`, marking in `fits` those whose move stays in their free box; moves there, and
    /// marks `moved`, the walks that fit and are not near any robot at `robots`. Turns beyond
    /// 1 rad (rare) are applied one by one; the rest is plain integer and floating-point
    /// arithmetic over the arrays in loops with no branch, which vectorise (compiled for the
    /// processor's widest instruction set, the same bits on each).
    pub(super) fn turn_and_look_ahead(&mut self, robots: &[Point]) {
        crate::geometry::ARCH.dispatch(Pass {
            state: self,
            robots,
        });
    }

    /// Draws every obstacle's turn for this step from its own stream: `sigma` times a draw of
    /// [`standard_turn`]. Returns whether a turn is beyond 1 rad ([`State::turn_wide`]).
    #[inline(always)]
    fn draw_turns(&mut self) -> bool {
        let n = self.stream.len();
        let (stream, sigma, turn) = (&mut self.stream[..n], &self.sigma[..n], &mut self.turn[..n]);
        let mut wide = false;
        for i in 0..n {
            let state = stream[i].wrapping_add(SPLIT_MIX_GAMMA);
            stream[i] = state;
            let a = sigma[i] * standard_turn(split_mix(state));
            // An obstacle that does not turn turns by +0 exactly (a `linear` one's heading is
            // then rotated by cos 1, sin +0: unchanged to the bit).
            let a = if sigma[i] > 0.0 { a } else { 0.0 };
            turn[i] = a;
            wide |= a.abs() > 1.0;
        }
        wide
    }

    /// Turns the headings whose turn is beyond 1 rad by it at once (halving the angle for the
    /// series), and sets their turn to 0 so that the pass only renormalises them.
    #[inline(always)]
    fn turn_wide(&mut self) {
        for i in 0..self.turn.len() {
            let a = self.turn[i];
            if a.abs() > 1.0 {
                let (s, c) = sin_cos(a);
                let (dx, dy) = (self.dx[i], self.dy[i]);
                self.dx[i] = dx * c - dy * s;
                self.dy[i] = dx * s + dy * c;
                self.turn[i] = 0.0;
            }
        }
    }

    /// The vectorised part of [`State::turn_and_look_ahead`].
    #[inline(always)]
    pub(super) fn pass(&mut self, robots: &[Point]) {
        let n = self.x.len();
        let (x, y, speed) = (&mut self.x[..n], &mut self.y[..n], &self.speed[..n]);
        let (dx, dy, turn) = (&mut self.dx[..n], &mut self.dy[..n], &self.turn[..n]);
        let (lo_x, lo_y) = (&self.lo_x[..n], &self.lo_y[..n]);
        let (hi_x, hi_y) = (&self.hi_x[..n], &self.hi_y[..n]);
        let (ax, ay) = (&mut self.ahead_x[..n], &mut self.ahead_y[..n]);
        let (fits, moved) = (&mut self.fits[..n], &mut self.moved[..n]);
        let (walks, near2) = (&self.walks[..n], &self.near_robot2[..n]);
        let (sin, cos) = (&mut self.sin[..n], &mut self.cos[..n]);
        // Which walks are far from every robot (from where they are now), robot by robot.
        moved.copy_from_slice(walks);
        for robot in robots {
            for i in 0..n {
                let (rx, ry) = (x[i] - robot.x, y[i] - robot.y);
                moved[i] &= rx * rx + ry * ry >= near2[i];
            }
        }
        // The series alone first: a short loop the compiler interleaves, hiding the latency of
        // the long chains of multiplications.
        for i in 0..n {
            (sin[i], cos[i]) = sin_cos_within_1(turn[i]);
        }
        for i in 0..n {
            let (s, c) = (sin[i], cos[i]);
            let (tx, ty) = (dx[i] * c - dy[i] * s, dx[i] * s + dy[i] * c);
            // A rotation keeps the length to within rounding; one Newton step towards length 1
            // stops the drift without a square root or a division.
            let k = 1.5 - 0.5 * (tx * tx + ty * ty);
            let (ux, uy) = (tx * k, ty * k);
            dx[i] = ux;
            dy[i] = uy;
            let (px, py) = (x[i], y[i]);
            let (qx, qy) = (px + ux * speed[i], py + uy * speed[i]);
            ax[i] = qx;
            ay[i] = qy;
            // The move is clear when both ends lie in the box (it is convex).
            let fit = (qx > lo_x[i])
                & (qx < hi_x[i])
                & (qy > lo_y[i])
                & (qy < hi_y[i])
                & (px > lo_x[i])
                & (px < hi_x[i])
                & (py > lo_y[i])
                & (py < hi_y[i]);
            fits[i] = fit;
            let go = moved[i] & fit;
            moved[i] = go;
            x[i] = if go { qx } else { px };
            y[i] = if go { qy } else { py };
        }
    }

    /// Sets obstacle `i`'s free box to `free` shrunk by `half` (the body's half extents).
    pub(super) fn set_free(&mut self, i: usize, free: Aabb, half: Vector) {
        self.lo_x[i] = free.min.x + half.x + FIT_MARGIN;
        self.lo_y[i] = free.min.y + half.y + FIT_MARGIN;
        self.hi_x[i] = free.max.x - half.x - FIT_MARGIN;
        self.hi_y[i] = free.max.y - half.y - FIT_MARGIN;
    }

    /// Whether `p` lies in obstacle `i`'s free box (a straight move to it is then clear).
    pub(super) fn in_free(&self, i: usize, p: Point) -> bool {
        p.x > self.lo_x[i] && p.x < self.hi_x[i] && p.y > self.lo_y[i] && p.y < self.hi_y[i]
    }
}

/// One over the standard deviation of the sum of eight bytes drawn uniformly from 0..=255:
/// `1 / sqrt(8 (256^2 - 1) / 12) = 1 / sqrt(43690)`.
const BYTE_SUM_INV_SD: f64 = 0.004_784_196_154_532_612;

/// A turn of standard deviation 1 from one 64-bit draw `z`: the sum of its eight bytes, less
/// their mean (1020), over their standard deviation. The sum of eight uniforms (Irwin and Hall)
/// is near normal: symmetric, standard deviation 1, within 4.88 of 0, kurtosis 2.85 (a
/// normal's: 3), in steps of 0.0048. Integer operations and one exact conversion, so the same
/// bits on every processor, and it vectorises.
#[inline(always)]
fn standard_turn(z: u64) -> f64 {
    const BYTES: u64 = 0x00ff_00ff_00ff_00ff;
    const PAIRS: u64 = 0x0000_ffff_0000_ffff;
    let sum = (z & BYTES) + ((z >> 8) & BYTES);
    let sum = (sum & PAIRS) + ((sum >> 16) & PAIRS);
    let sum = (sum & 0xffff_ffff) + (sum >> 32);
    // Exact for any integer below 2^52: its bits as the fraction of 2^52, less 2^52.
    const TWO_52: f64 = 4_503_599_627_370_496.0;
    let sum = f64::from_bits(sum | TWO_52.to_bits()) - TWO_52;
    (sum - 1020.0) * BYTE_SUM_INV_SD
}

/// `(sin a, cos a)` for |a| <= 1 by Taylor series (to a^17 and a^18: the first term left out is
/// below 1e-17), plain multiplications and additions, so the same bits on every platform and one
/// vectorised pass for many turns. Wrong beyond |a| = 1: see [`sin_cos`].
#[inline(always)]
fn sin_cos_within_1(a: f64) -> (f64, f64) {
    let a2 = a * a;
    const S: [f64; 8] = [
        -1.0 / 6.0,
        1.0 / 120.0,
        -1.0 / 5040.0,
        1.0 / 362_880.0,
        -1.0 / 39_916_800.0,
        1.0 / 6_227_020_800.0,
        -1.0 / 1_307_674_368_000.0,
        1.0 / 355_687_428_096_000.0,
    ];
    const C: [f64; 9] = [
        -1.0 / 2.0,
        1.0 / 24.0,
        -1.0 / 720.0,
        1.0 / 40_320.0,
        -1.0 / 3_628_800.0,
        1.0 / 479_001_600.0,
        -1.0 / 87_178_291_200.0,
        1.0 / 20_922_789_888_000.0,
        -1.0 / 6_402_373_705_728_000.0,
    ];
    let mut s = S[7];
    for k in (0..7).rev() {
        s = S[k] + a2 * s;
    }
    let mut c = C[8];
    for k in (0..8).rev() {
        c = C[k] + a2 * c;
    }
    (a * (1.0 + a2 * s), 1.0 + a2 * c)
}

/// `(sin a, cos a)` for any `a`: halved until within 1 rad, then doubled back. Plain arithmetic,
/// so the same on every platform (a random walk's turns beyond 1 rad are rare).
fn sin_cos(a: f64) -> (f64, f64) {
    let mut halvings = 0;
    let mut h = a;
    while h.abs() > 1.0 && halvings < 1100 {
        h *= 0.5;
        halvings += 1;
    }
    let (mut s, mut c) = sin_cos_within_1(h);
    for _ in 0..halvings {
        (s, c) = (2.0 * s * c, c * c - s * s);
    }
    (s, c)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn standard_turns_have_mean_0_and_standard_deviation_1() {
        // Every byte pattern's extremes, then a SplitMix64 stream's draws.
        assert_eq!(standard_turn(0), -1020.0 * BYTE_SUM_INV_SD);
        assert_eq!(standard_turn(u64::MAX), 1020.0 * BYTE_SUM_INV_SD);
        assert_eq!(standard_turn(0x8080_8080_8080_807c), 0.0);
        let mut state = 7u64;
        let draws: Vec<f64> = (0..200_000)
            .map(|_| {
                state = state.wrapping_add(SPLIT_MIX_GAMMA);
                standard_turn(split_mix(state))
            })
            .collect();
        let n = draws.len() as f64;
        let mean = draws.iter().sum::<f64>() / n;
        let var = draws.iter().map(|g| (g - mean).powi(2)).sum::<f64>() / n;
        let kurtosis = draws.iter().map(|g| (g - mean).powi(4)).sum::<f64>() / n / (var * var);
        assert!(mean.abs() < 0.01, "mean {mean}");
        assert!(
            (var.sqrt() - 1.0).abs() < 0.01,
            "standard deviation {}",
            var.sqrt()
        );
        assert!((kurtosis - 2.85).abs() < 0.03, "kurtosis {kurtosis}");
        assert!(draws.iter().all(|g| g.abs() <= 4.88));
    }

    #[test]
    fn sin_cos_matches_the_library() {
        for k in -3000..=3000 {
            let a = k as f64 * 0.0011;
            let (s, c) = sin_cos(a);
            let (s0, c0) = a.sin_cos();
            assert!((s - s0).abs() < 4e-15 && (c - c0).abs() < 4e-15, "{a}");
        }
        for a in [-1.0, 1.0, 20.0, -1e3] {
            let (s, c) = sin_cos(a);
            let (s0, c0) = f64::sin_cos(a);
            assert!((s - s0).abs() < 1e-9 && (c - c0).abs() < 1e-9, "{a}");
        }
    }
}
