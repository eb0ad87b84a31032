//! Optimal Reciprocal Collision Avoidance (van den Berg, Guy, Lin and Manocha 2011), after the
//! RVO2 library (Apache-2.0, University of North Carolina at Chapel Hill), its reference: the
//! half-planes of velocities that avoid each neighbour for a time horizon, and the linear
//! programs that pick the permitted velocity nearest the preferred one. Each step mirrors RVO2's
//! arithmetic in order, generic over the float ([`Real`]): computed in `f32` it gives RVO2's
//! velocities (the tests hold it to the `pyrvo` bindings' outputs); the simulation computes in
//! `f64`.
//!
//! Pure geometry: agents, obstacles and neighbour lists come from the caller (see
//! [`agent_neighbours`] and [`obstacle_neighbours`] for RVO2's choice of them).

mod program;
mod real;
mod step;

pub use real::{left_of, Real, V2};
pub use step::{crowd_step, CrowdAgent, CrowdChoice, CrowdSettings};

use program::{linear_program2, linear_program3};

/// A half-plane of permitted velocities: those on the left of the directed line through `point`
/// along `direction` (unit).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Line<T> {
    /// A point on the line.
    pub point: V2<T>,
    /// Its unit direction; the permitted side is on its left.
    pub direction: V2<T>,
}

/// An agent as its neighbours see it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Agent<T> {
    /// Its centre.
    pub position: V2<T>,
    /// Its velocity, per time unit.
    pub velocity: V2<T>,
    /// Its radius.
    pub radius: T,
}

/// What an agent avoids with: its time horizons, its speed limit and the simulation's step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Horizon<T> {
    /// Time over which velocities are kept clear of the other agents.
    pub agents: T,
    /// Time over which velocities are kept clear of still obstacles.
    pub obstacles: T,
    /// The largest speed.
    pub max_speed: T,
    /// The simulation's time step (for agents already overlapping).
    pub time_step: T,
}

/// One vertex of a still obstacle and the edge from it to the next (RVO2's `Obstacle`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Vertex<T> {
    /// Where it is.
    pub point: V2<T>,
    /// The next vertex of its polygon (counter-clockwise).
    pub next: usize,
    /// The previous vertex.
    pub previous: usize,
    /// Unit direction of the edge to the next vertex.
    pub direction: V2<T>,
    /// Whether the polygon is convex at this vertex.
    pub convex: bool,
}

/// Still obstacles: polygons, each a counter-clockwise loop of `Vertex`es (a two-vertex one is
/// a line segment, both sides of which are obstacles).
#[derive(Clone, Debug, PartialEq)]
pub struct Obstacles<T> {
    /// Every vertex of every polygon.
    pub vertices: Vec<Vertex<T>>,
}

impl<T> Default for Obstacles<T> {
    fn default() -> Self {
        Self {
            vertices: Vec::new(),
        }
    }
}

impl<T: Real> Obstacles<T> {
    /// Adds the polygon of `points` (counter-clockwise; two points: a segment), as RVO2's
    /// `addObstacle` does. Fewer than two points add nothing.
    pub fn add(&mut self, points: &[V2<T>]) {
        let n = points.len();
        if n < 2 {
            return;
        }
        let first = self.vertices.len();
        for i in 0..n {
            let next = if i == n - 1 { 0 } else { i + 1 };
            let previous = if i == 0 { n - 1 } else { i - 1 };
            let convex = n == 2 || left_of(points[previous], points[i], points[next]) >= T::ZERO;
            self.vertices.push(Vertex {
                point: points[i],
                next: first + next,
                previous: first + previous,
                direction: (points[next] - points[i]).normalize(),
                convex,
            });
        }
    }
}

/// The squared distance from `p` to the segment `a`-`b`, as RVO2 measures an obstacle edge.
fn dist_sq_segment<T: Real>(a: V2<T>, b: V2<T>, p: V2<T>) -> T {
    let r = (p - a).dot(b - a) / (b - a).abs_sq();
    if r < T::ZERO {
        (p - a).abs_sq()
    } else if r > T::ONE {
        (p - b).abs_sq()
    } else {
        (p - (a + (b - a).scale(r))).abs_sq()
    }
}

/// The obstacle edges (by their first vertex) an agent at `position` with `radius` and
/// `horizon` avoids: those it faces (on their right, outside) within `horizon.obstacles *
/// horizon.max_speed + radius`, nearest first (ties in vertex order), as RVO2 chooses them.
pub fn obstacle_neighbours<T: Real>(
    obstacles: &Obstacles<T>,
    position: V2<T>,
    radius: T,
    horizon: &Horizon<T>,
    out: &mut Vec<(T, usize)>,
) {
    out.clear();
    let range = horizon.obstacles * horizon.max_speed + radius;
    let range_sq = range * range;
    for (i, v) in obstacles.vertices.iter().enumerate() {
        let next = obstacles.vertices[v.next].point;
        let left = left_of(v.point, next, position);
        let dist_sq_line = left * left / (next - v.point).abs_sq();
        if left < T::ZERO && dist_sq_line < range_sq {
            let d = dist_sq_segment(v.point, next, position);
            if d < range_sq {
                out.push((d, i));
            }
        }
    }
    sort_nearest(out);
}

/// The neighbours of agent `me` among `agents`: the `max` nearest within `range` (other than
/// itself), nearest first (ties in index order), as RVO2 chooses them.
pub fn agent_neighbours<T: Real>(
    agents: &[Agent<T>],
    me: usize,
    range: T,
    max: usize,
    out: &mut Vec<(T, usize)>,
) {
    agent_neighbours_among(agents, me, 0..agents.len(), range, max, out);
}

/// [`agent_neighbours`] among the agents `candidates` (indices into `agents`, each at most once,
/// in any order; a superset of those within `range`, as a spatial grid gives): the same answer.
pub fn agent_neighbours_among<T: Real>(
    agents: &[Agent<T>],
    me: usize,
    candidates: impl Iterator<Item = usize>,
    range: T,
    max: usize,
    out: &mut Vec<(T, usize)>,
) {
    out.clear();
    if max == 0 {
        return;
    }
    let p = agents[me].position;
    let range_sq = range * range;
    // RVO2's insertion into a list kept sorted and at most `max` long (its `insertAgentNeighbor`),
    // ordered by (distance, index) so that the candidates' order does not matter: the same as
    // sorting every agent in range and keeping the first `max`.
    for j in candidates {
        if j == me {
            continue;
        }
        let d = (p - agents[j].position).abs_sq();
        if d < range_sq {
            insert_nearest(out, (d, j), max);
        }
    }
}

/// Puts `new` into `list` (sorted nearest first, at most `max` long, `max` > 0) where it belongs,
/// dropping the farthest when full; nothing when it is farther than all of a full list.
fn insert_nearest<T: Real>(list: &mut Vec<(T, usize)>, new: (T, usize), max: usize) {
    if list.len() == max {
        match list.last() {
            Some(last) if nearest_first(&new, last).is_lt() => {
                list.pop();
            }
            _ => return,
        }
    }
    let mut at = list.len();
    while at > 0 && nearest_first(&new, &list[at - 1]).is_lt() {
        at -= 1;
    }
    list.insert(at, new);
}

/// `(distance, index)` pairs nearest first, ties by index (a stable insertion order).
fn nearest_first<T: Real>(a: &(T, usize), b: &(T, usize)) -> std::cmp::Ordering {
    a.0.partial_cmp(&b.0)
        .unwrap_or(std::cmp::Ordering::Equal)
        .then(a.1.cmp(&b.1))
}

/// Sorts `(distance, index)` pairs nearest first, ties by index.
fn sort_nearest<T: Real>(pairs: &mut [(T, usize)]) {
    pairs.sort_unstable_by(nearest_first);
}

/// What [`new_velocity`] needs besides the agent: its neighbours and the obstacles.
pub struct Surroundings<'a, T> {
    /// The other agents, nearest first (as [`agent_neighbours`] lists them).
    pub agents: &'a [Agent<T>],
    /// The still obstacles.
    pub obstacles: &'a Obstacles<T>,
    /// The obstacle edges to avoid, nearest first (as `obstacle_neighbours` lists them).
    pub edges: &'a [usize],
}

/// The velocity ORCA gives `me` wanting `preferred`: the one nearest `preferred` (at most
/// `horizon.max_speed` long) that keeps clear of every neighbour for the time horizons, or when
/// none does, the one that least violates the agents' half-planes while keeping the obstacles'.
/// `lines` is scratch space (it ends holding the half-planes used, obstacles' first).
pub fn new_velocity<T: Real>(
    me: &Agent<T>,
    preferred: V2<T>,
    around: &Surroundings<'_, T>,
    horizon: &Horizon<T>,
    lines: &mut Vec<Line<T>>,
) -> V2<T> {
    lines.clear();
    obstacle_lines(me, around, horizon, lines);
    let obstacle_lines = lines.len();
    let inv_horizon = T::ONE / horizon.agents;
    for other in around.agents {
        lines.push(agent_line(me, other, inv_horizon, horizon.time_step));
    }
    let mut result = V2::zero();
    let fail = linear_program2(lines, horizon.max_speed, preferred, false, &mut result);
    if fail < lines.len() {
        linear_program3(lines, obstacle_lines, fail, horizon.max_speed, &mut result);
    }
    result
}

/// The half-plane of `me`'s velocities that avoids `other` reciprocally (each taking half).
fn agent_line<T: Real>(me: &Agent<T>, other: &Agent<T>, inv_horizon: T, time_step: T) -> Line<T> {
    let relative_position = other.position - me.position;
    let relative_velocity = me.velocity - other.velocity;
    let dist_sq = relative_position.abs_sq();
    let combined_radius = me.radius + other.radius;
    let combined_radius_sq = combined_radius * combined_radius;
    let direction;
    let u;
    if dist_sq > combined_radius_sq {
        // No collision. The vector from the cut-off centre to the relative velocity.
        let w = relative_velocity - relative_position.scale(inv_horizon);
        let w_length_sq = w.abs_sq();
        let dot = w.dot(relative_position);
        if dot < T::ZERO && dot * dot > combined_radius_sq * w_length_sq {
            // Project on the cut-off circle.
            let w_length = w_length_sq.sqrt();
            let unit_w = w.over(w_length);
            direction = V2::new(unit_w.y, -unit_w.x);
            u = unit_w.scale(combined_radius * inv_horizon - w_length);
        } else {
            // Project on the legs.
            let leg = (dist_sq - combined_radius_sq).sqrt();
            let (x, y) = (relative_position.x, relative_position.y);
            direction = if relative_position.det(w) > T::ZERO {
                V2::new(x * leg - y * combined_radius, x * combined_radius + y * leg).over(dist_sq)
            } else {
                (-V2::new(
                    x * leg + y * combined_radius,
                    -x * combined_radius + y * leg,
                ))
                .over(dist_sq)
            };
            u = direction.scale(relative_velocity.dot(direction)) - relative_velocity;
        }
    } else {
        // Already overlapping: project on the cut-off circle of one time step.
        let inv_time_step = T::ONE / time_step;
        let w = relative_velocity - relative_position.scale(inv_time_step);
        let w_length = w.abs();
        let unit_w = w.over(w_length);
        direction = V2::new(unit_w.y, -unit_w.x);
        u = unit_w.scale(combined_radius * inv_time_step - w_length);
    }
    Line {
        point: me.velocity + u.scale(T::HALF),
        direction,
    }
}

/// Adds the half-planes of `me`'s velocities that avoid each obstacle edge of `around`.
fn obstacle_lines<T: Real>(
    me: &Agent<T>,
    around: &Surroundings<'_, T>,
    horizon: &Horizon<T>,
    lines: &mut Vec<Line<T>>,
) {
    let inv_horizon = T::ONE / horizon.obstacles;
    let radius = me.radius;
    let radius_sq = radius * radius;
    let vertices = &around.obstacles.vertices;
    for &edge in around.edges {
        let mut o1 = &vertices[edge];
        let mut o2 = &vertices[o1.next];
        let relative_position1 = o1.point - me.position;
        let relative_position2 = o2.point - me.position;
        // Already covered by an earlier obstacle's half-plane?
        let covered = lines.iter().any(|l| {
            (relative_position1.scale(inv_horizon) - l.point).det(l.direction)
                - inv_horizon * radius
                >= -T::EPSILON
                && (relative_position2.scale(inv_horizon) - l.point).det(l.direction)
                    - inv_horizon * radius
                    >= -T::EPSILON
        });
        if covered {
            continue;
        }
        let dist_sq1 = relative_position1.abs_sq();
        let dist_sq2 = relative_position2.abs_sq();
        let obstacle_vector = o2.point - o1.point;
        let s = (-relative_position1).dot(obstacle_vector) / obstacle_vector.abs_sq();
        let dist_sq_line = (-relative_position1 - obstacle_vector.scale(s)).abs_sq();
        let origin = V2::zero();
        if s < T::ZERO && dist_sq1 <= radius_sq {
            // Touching the left vertex: ignored if it is not convex.
            if o1.convex {
                lines.push(Line {
                    point: origin,
                    direction: relative_position1.left().normalize(),
                });
            }
            continue;
        }
        if s > T::ONE && dist_sq2 <= radius_sq {
            // Touching the right vertex: ignored if not convex or if the next edge sees to it.
            if o2.convex && relative_position2.det(o2.direction) >= T::ZERO {
                lines.push(Line {
                    point: origin,
                    direction: relative_position2.left().normalize(),
                });
            }
            continue;
        }
        if s >= T::ZERO && s <= T::ONE && dist_sq_line <= radius_sq {
            // Touching the edge.
            lines.push(Line {
                point: origin,
                direction: -o1.direction,
            });
            continue;
        }
        // No contact: the legs. Seen obliquely, both legs come from one vertex; at a vertex that
        // is not convex a leg extends the cut-off line.
        let leg_left = |rel: V2<T>, dist_sq: T| {
            let leg = (dist_sq - radius_sq).sqrt();
            V2::new(rel.x * leg - rel.y * radius, rel.x * radius + rel.y * leg).over(dist_sq)
        };
        let leg_right = |rel: V2<T>, dist_sq: T| {
            let leg = (dist_sq - radius_sq).sqrt();
            V2::new(rel.x * leg + rel.y * radius, -rel.x * radius + rel.y * leg).over(dist_sq)
        };
        let mut left_leg;
        let mut right_leg;
        if s < T::ZERO && dist_sq_line <= radius_sq {
            if !o1.convex {
                continue;
            }
            o2 = o1;
            left_leg = leg_left(relative_position1, dist_sq1);
            right_leg = leg_right(relative_position1, dist_sq1);
        } else if s > T::ONE && dist_sq_line <= radius_sq {
            if !o2.convex {
                continue;
            }
            o1 = o2;
            left_leg = leg_left(relative_position2, dist_sq2);
            right_leg = leg_right(relative_position2, dist_sq2);
        } else {
            left_leg = if o1.convex {
                leg_left(relative_position1, dist_sq1)
            } else {
                -o1.direction
            };
            right_leg = if o2.convex {
                leg_right(relative_position2, dist_sq2)
            } else {
                o1.direction
            };
        }
        // A leg never points into the neighbouring edge at a convex vertex: that edge's cut-off
        // line is taken instead, and a velocity projected on such a "foreign" leg adds nothing.
        let left_neighbour = &vertices[o1.previous];
        let mut left_foreign = false;
        let mut right_foreign = false;
        if o1.convex && left_leg.det(-left_neighbour.direction) >= T::ZERO {
            left_leg = -left_neighbour.direction;
            left_foreign = true;
        }
        if o2.convex && right_leg.det(o2.direction) <= T::ZERO {
            right_leg = o2.direction;
            right_foreign = true;
        }
        let same = std::ptr::eq(o1, o2);
        let left_cutoff = (o1.point - me.position).scale(inv_horizon);
        let right_cutoff = (o2.point - me.position).scale(inv_horizon);
        let cutoff_vector = right_cutoff - left_cutoff;
        let v = me.velocity;
        let t = if same {
            T::HALF
        } else {
            (v - left_cutoff).dot(cutoff_vector) / cutoff_vector.abs_sq()
        };
        let t_left = (v - left_cutoff).dot(left_leg);
        let t_right = (v - right_cutoff).dot(right_leg);
        let r = radius * inv_horizon;
        if (t < T::ZERO && t_left < T::ZERO) || (same && t_left < T::ZERO && t_right < T::ZERO) {
            // Project on the left cut-off circle.
            let unit_w = (v - left_cutoff).normalize();
            lines.push(Line {
                direction: V2::new(unit_w.y, -unit_w.x),
                point: left_cutoff + unit_w.scale(r),
            });
            continue;
        }
        if t > T::ONE && t_right < T::ZERO {
            // Project on the right cut-off circle.
            let unit_w = (v - right_cutoff).normalize();
            lines.push(Line {
                direction: V2::new(unit_w.y, -unit_w.x),
                point: right_cutoff + unit_w.scale(r),
            });
            continue;
        }
        // Project on the left leg, the right leg or the cut-off line, whichever is nearest.
        let dist_sq_cutoff = if t < T::ZERO || t > T::ONE || same {
            T::INFINITY
        } else {
            (v - (left_cutoff + cutoff_vector.scale(t))).abs_sq()
        };
        let dist_sq_left = if t_left < T::ZERO {
            T::INFINITY
        } else {
            (v - (left_cutoff + left_leg.scale(t_left))).abs_sq()
        };
        let dist_sq_right = if t_right < T::ZERO {
            T::INFINITY
        } else {
            (v - (right_cutoff + right_leg.scale(t_right))).abs_sq()
        };
        if dist_sq_cutoff <= dist_sq_left && dist_sq_cutoff <= dist_sq_right {
            let direction = -o1.direction;
            lines.push(Line {
                direction,
                point: left_cutoff + direction.left().scale(r),
            });
            continue;
        }
        if dist_sq_left <= dist_sq_right {
            if left_foreign {
                continue;
            }
            lines.push(Line {
                direction: left_leg,
                point: left_cutoff + left_leg.left().scale(r),
            });
            continue;
        }
        if right_foreign {
            continue;
        }
        let direction = -right_leg;
        lines.push(Line {
            direction,
            point: right_cutoff + direction.left().scale(r),
        });
    }
}
