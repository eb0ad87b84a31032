//! ORCA's linear programs (RVO2's `linearProgram1` to `3`): the velocity nearest an optimum
//! within a speed circle and a set of half-planes, and, when none fits, the one that least
//! violates them.

use super::{Line, Real, V2};

/// The best point on line `line_no` within the circle of `radius` and the half-planes before it:
/// nearest `opt` or, with `direction_opt`, furthest along the unit `opt`. `false` when there is
/// none.
fn linear_program1<T: Real>(
    lines: &[Line<T>],
    line_no: usize,
    radius: T,
    opt: V2<T>,
    direction_opt: bool,
    result: &mut V2<T>,
) -> bool {
    let line = lines[line_no];
    let dot = line.point.dot(line.direction);
    let discriminant = dot * dot + radius * radius - line.point.abs_sq();
    if discriminant < T::ZERO {
        // The speed circle rules out the whole line.
        return false;
    }
    let sqrt_discriminant = discriminant.sqrt();
    let mut t_left = -dot - sqrt_discriminant;
    let mut t_right = -dot + sqrt_discriminant;
    for other in &lines[..line_no] {
        let denominator = line.direction.det(other.direction);
        let numerator = other.direction.det(line.point - other.point);
        if denominator.abs() <= T::EPSILON {
            // (Almost) parallel lines.
            if numerator < T::ZERO {
                return false;
            }
            continue;
        }
        let t = numerator / denominator;
        if denominator >= T::ZERO {
            // The other line bounds this one on the right.
            if t < t_right {
                t_right = t;
            }
        } else if t > t_left {
            // On the left.
            t_left = t;
        }
        if t_left > t_right {
            return false;
        }
    }
    let at = |t: T| line.point + line.direction.scale(t);
    *result = if direction_opt {
        if opt.dot(line.direction) > T::ZERO {
            at(t_right)
        } else {
            at(t_left)
        }
    } else {
        let t = line.direction.dot(opt - line.point);
        if t < t_left {
            at(t_left)
        } else if t > t_right {
            at(t_right)
        } else {
            at(t)
        }
    };
    true
}

/// The best point within the circle of `radius` and every half-plane of `lines`: nearest `opt`
/// or, with `direction_opt`, furthest along the unit `opt`. Returns the number of the line it
/// failed on (`result` then holds the best point before it), or `lines.len()`.
pub(super) fn linear_program2<T: Real>(
    lines: &[Line<T>],
    radius: T,
    opt: V2<T>,
    direction_opt: bool,
    result: &mut V2<T>,
) -> usize {
    *result = if direction_opt {
        opt.scale(radius)
    } else if opt.abs_sq() > radius * radius {
        opt.normalize().scale(radius)
    } else {
        opt
    };
    for (i, line) in lines.iter().enumerate() {
        if line.direction.det(line.point - *result) > T::ZERO {
            // The result breaks this half-plane: the best point on its line.
            let before = *result;
            if !linear_program1(lines, i, radius, opt, direction_opt, result) {
                *result = before;
                return i;
            }
        }
    }
    lines.len()
}

/// When [`linear_program2`] failed on line `begin`: the point within the circle of `radius`
/// that keeps the first `obstacle_lines` half-planes and least violates the others (the
/// largest distance it lies outside any of them is as small as it can be).
pub(super) fn linear_program3<T: Real>(
    lines: &[Line<T>],
    obstacle_lines: usize,
    begin: usize,
    radius: T,
    result: &mut V2<T>,
) {
    let mut distance = T::ZERO;
    let mut projected: Vec<Line<T>> = Vec::with_capacity(lines.len());
    for i in begin..lines.len() {
        let li = lines[i];
        if li.direction.det(li.point - *result) > distance {
            // The result breaks this half-plane by more than the others.
            projected.clear();
            projected.extend_from_slice(&lines[..obstacle_lines]);
            for lj in &lines[obstacle_lines..i] {
                let determinant = li.direction.det(lj.direction);
                let point = if determinant.abs() <= T::EPSILON {
                    // Parallel lines.
                    if li.direction.dot(lj.direction) > T::ZERO {
                        // Pointing the same way.
                        continue;
                    }
                    (li.point + lj.point).scale(T::HALF)
                } else {
                    li.point
                        + li.direction
                            .scale(lj.direction.det(li.point - lj.point) / determinant)
                };
                projected.push(Line {
                    point,
                    direction: (lj.direction - li.direction).normalize(),
                });
            }
            let before = *result;
            let opt = V2::new(-li.direction.y, li.direction.x);
            if linear_program2(&projected, radius, opt, true, result) < projected.len() {
                // In principle impossible (the result is feasible by construction): only
                // rounding gets here, and the result before is kept.
                *result = before;
            }
            distance = li.direction.det(li.point - *result);
        }
    }
}
