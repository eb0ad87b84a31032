//! `orca_step`: one ORCA step of a crowd, the core's `crowd_step`, for holding ronap's ORCA to
//! RVO2 from Python (the `pyrvo` bindings) or using ORCA alone.

use crate::errors::ConfigError;
use pyo3::prelude::*;
use ronap_core::geometry::{crowd_step, Agent, CrowdAgent, CrowdSettings, Real, V2};

/// Each agent's new velocity, agent neighbours and obstacle neighbours.
type Step = (Vec<[f64; 2]>, Vec<Vec<usize>>, Vec<Vec<usize>>);

/// One step of `agents` (rows `[x, y, vx, vy, radius, max_speed, preferred_x, preferred_y]`)
/// among `obstacles` (polygons, corners counter-clockwise) with `settings` `(neighbour_dist,
/// max_neighbours, time_horizon, time_horizon_obstacles, time_step)`, in RVO2's `f32`
/// (`single`) or in `f64`.
#[pyfunction]
pub fn orca_step(
    agents: Vec<[f64; 8]>,
    obstacles: Vec<Vec<[f64; 2]>>,
    settings: (f64, usize, f64, f64, f64),
    single: bool,
) -> PyResult<Step> {
    let (neighbour_dist, _, time_horizon, time_horizon_obstacles, time_step) = settings;
    for (name, v) in [
        ("neighbour_dist", neighbour_dist),
        ("time_horizon", time_horizon),
        ("time_horizon_obstacles", time_horizon_obstacles),
        ("time_step", time_step),
    ] {
        if !(v.is_finite() && v > 0.0) {
            return Err(ConfigError::new_err(format!(
                "{name} = {v}: must be a positive number"
            )));
        }
    }
    for (i, a) in agents.iter().enumerate() {
        if !a.iter().all(|v| v.is_finite()) || a[4] < 0.0 || a[5] < 0.0 {
            return Err(ConfigError::new_err(format!(
                "agents[{i}] = {a:?}: must be finite, with radius and max_speed zero or positive"
            )));
        }
    }
    for (i, polygon) in obstacles.iter().enumerate() {
        if polygon.len() < 2 || !polygon.iter().flatten().all(|v| v.is_finite()) {
            return Err(ConfigError::new_err(format!(
                "obstacles[{i}]: a polygon needs at least two finite corners"
            )));
        }
    }
    Ok(if single {
        step::<f32>(&agents, &obstacles, settings)
    } else {
        step::<f64>(&agents, &obstacles, settings)
    })
}

fn step<T: Real>(
    agents: &[[f64; 8]],
    obstacles: &[Vec<[f64; 2]>],
    settings: (f64, usize, f64, f64, f64),
) -> Step {
    let v = |x: f64, y: f64| V2::new(T::of(x), T::of(y));
    let crowd: Vec<CrowdAgent<T>> = agents
        .iter()
        .map(|a| CrowdAgent {
            agent: Agent {
                position: v(a[0], a[1]),
                velocity: v(a[2], a[3]),
                radius: T::of(a[4]),
            },
            max_speed: T::of(a[5]),
            preferred: v(a[6], a[7]),
        })
        .collect();
    let polygons: Vec<Vec<V2<T>>> = obstacles
        .iter()
        .map(|p| p.iter().map(|c| v(c[0], c[1])).collect())
        .collect();
    let s = CrowdSettings {
        neighbour_dist: T::of(settings.0),
        max_neighbours: settings.1,
        time_horizon: T::of(settings.2),
        time_horizon_obstacles: T::of(settings.3),
        time_step: T::of(settings.4),
    };
    let mut out: Step = (Vec::new(), Vec::new(), Vec::new());
    for c in crowd_step(&crowd, &polygons, &s) {
        out.0.push([c.velocity.x.to_f64(), c.velocity.y.to_f64()]);
        out.1.push(c.agent_neighbours);
        out.2.push(c.obstacle_neighbours);
    }
    out
}
