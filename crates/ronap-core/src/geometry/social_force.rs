//! The social force model (Helbing and Molnár 1995) as the `social_force` pedestrians and the
//! `social-force` policy take it, one step at a time (a step is the unit of time):
//!
//! `v' = v + (v_pref - v) / tau + sum_j A w(phi_j) exp((r_i + r_j - d_ij) / B) n_ij
//!        + sum_W A_W exp((r_i - d_iW) / B_W) n_iW`, then cut to the largest speed,
//!
//! where `n` is the unit vector from the other agent's centre (or the still obstacle's nearest
//! point) to the agent's, `d` the distance between them, and `w(phi) = lambda + (1 - lambda)
//! (1 + cos phi) / 2` weighs an agent by the angle `phi` between the agent's desired direction
//! of motion and the direction to it: 1 straight ahead, `lambda` straight behind.

use crate::config::Forces;
use crate::geometry::{Point, Vector};

/// The agent a force acts on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Walker {
    /// Its centre, px.
    pub position: Point,
    /// Its velocity, px per step.
    pub velocity: Vector,
    /// Its radius, px.
    pub radius: f64,
}

/// The push of another agent at `at` of radius `radius` on `me`, whose desired direction of
/// motion is `desired` (a unit vector, or zero for none: every direction weighs 1).
#[inline]
pub fn agent_force(f: &Forces, me: &Walker, desired: Vector, at: Point, radius: f64) -> Vector {
    let away = me.position - at;
    let d2 = away.norm_squared();
    if !maybe_in_reach(f, d2) {
        return Vector::zeros();
    }
    let d = d2.sqrt();
    if d == 0.0 || d > f.neighbour_dist_px {
        return Vector::zeros();
    }
    let n = away / d;
    // cos phi: the desired direction against the direction to the other (-n).
    let cos_phi = -desired.dot(&n);
    let weight = if desired == Vector::zeros() {
        1.0
    } else {
        f.lambda + (1.0 - f.lambda) * (1.0 + cos_phi) / 2.0
    };
    n * (f.agent_strength_px * weight * push_factor((me.radius + radius - d) / f.agent_range_px))
}

/// Whether another agent at squared distance `d2` may be within reach: most candidates a walker
/// is handed are out of reach, turned away on this before the square root, with room for its
/// rounding, so every one [`agent_force`]'s exact test keeps passes (and NaN does).
#[inline]
pub fn maybe_in_reach(f: &Forces, d2: f64) -> bool {
    (d2 <= f.neighbour_dist_px * f.neighbour_dist_px * (1.0 + 1e-9)) | d2.is_nan()
}

/// The push of a still obstacle whose nearest point to `me` is `nearest`; none from inside it.
#[inline]
pub fn obstacle_force(f: &Forces, me: &Walker, nearest: Point) -> Vector {
    let away = me.position - nearest;
    let d = away.norm();
    if d == 0.0 {
        return Vector::zeros();
    }
    away / d * (f.obstacle_strength_px * push_factor((me.radius - d) / f.obstacle_range_px))
}

/// `exp(x)` with `x` held at most 50 (`e^50`, 5e21): deep overlaps with a short decay length
/// would otherwise overflow to infinity and give NaN velocities.
#[inline]
fn push_factor(x: f64) -> f64 {
    x.min(50.0).exp()
}

/// The velocity after one step of the model: `me` relaxing towards `preferred` under the pushes
/// `push` (the sum of [`agent_force`] and [`obstacle_force`] over what is near), cut to
/// `max_speed`.
pub fn next_velocity(
    f: &Forces,
    me: &Walker,
    preferred: Vector,
    push: Vector,
    max_speed: f64,
) -> Vector {
    let v = me.velocity + (preferred - me.velocity) / f.relaxation_steps + push;
    let speed = v.norm();
    if speed > max_speed && speed > 0.0 {
        v * (max_speed / speed)
    } else {
        v
    }
}

/// The desired direction of motion for the anisotropy: the preferred velocity's, else the
/// velocity's, else none (zero).
pub fn desired_direction(preferred: Vector, velocity: Vector) -> Vector {
    preferred
        .try_normalize(1e-12)
        .or_else(|| velocity.try_normalize(1e-12))
        .unwrap_or_else(Vector::zeros)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: Vector, b: Vector) {
        assert!((a - b).norm() < 1e-12, "{a} vs {b}");
    }

    #[test]
    fn forces_equal_the_hand_computed_ones() {
        let f = Forces::default();
        let me = Walker {
            position: Point::new(0.0, 0.0),
            velocity: Vector::new(3.0, 0.0),
            radius: 6.0,
        };
        let e = Vector::new(1.0, 0.0);
        // Straight ahead at 20 px, radius 6: A exp((12 - 20) / 6), pushing back along -x,
        // with weight 1.
        let ahead = agent_force(&f, &me, e, Point::new(20.0, 0.0), 6.0);
        close(ahead, Vector::new(-8.75 * (-8.0f64 / 6.0).exp(), 0.0));
        // Straight behind: weight lambda = 0.5, pushing along +x.
        let behind = agent_force(&f, &me, e, Point::new(-20.0, 0.0), 6.0);
        close(behind, Vector::new(0.5 * 8.75 * (-8.0f64 / 6.0).exp(), 0.0));
        // To the side (phi = 90 deg): weight (0.5 + 0.5 * 0.5) = 0.75.
        let side = agent_force(&f, &me, e, Point::new(0.0, 20.0), 6.0);
        close(side, Vector::new(0.0, -0.75 * 8.75 * (-8.0f64 / 6.0).exp()));
        // Beyond the neighbour distance: nothing.
        close(
            agent_force(&f, &me, e, Point::new(61.0, 0.0), 6.0),
            Vector::zeros(),
        );
        // A wall 10 px below: 62.5 exp((6 - 10) / 4) upwards.
        let wall = obstacle_force(&f, &me, Point::new(0.0, -10.0));
        close(wall, Vector::new(0.0, 62.5 * (-1.0f64).exp()));
        // Relaxing from (3, 0) to (5, 0) over 2 steps with that push: (4, 62.5/e), cut to 5.
        let v = next_velocity(&f, &me, Vector::new(5.0, 0.0), wall, 5.0);
        let raw = Vector::new(4.0, 62.5 * (-1.0f64).exp());
        close(v, raw * (5.0 / raw.norm()));
        // Unpushed and slow enough, no cut.
        close(
            next_velocity(&f, &me, Vector::new(5.0, 0.0), Vector::zeros(), 5.0),
            Vector::new(4.0, 0.0),
        );
    }

    #[test]
    fn the_desired_direction_falls_back_to_the_velocity() {
        close(
            desired_direction(Vector::new(0.0, 2.0), Vector::new(1.0, 0.0)),
            Vector::new(0.0, 1.0),
        );
        close(
            desired_direction(Vector::zeros(), Vector::new(3.0, 0.0)),
            Vector::new(1.0, 0.0),
        );
        close(
            desired_direction(Vector::zeros(), Vector::zeros()),
            Vector::zeros(),
        );
    }
}
