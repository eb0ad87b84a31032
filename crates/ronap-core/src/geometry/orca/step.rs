//! One ORCA step of a whole crowd as RVO2's `doStep` computes it: each agent's neighbours
//! (agents and obstacle edges, as RVO2 chooses them) and its new velocity, from the same inputs
//! RVO2 takes. For holding ORCA to RVO2 (the tests, and `ronap.orca_step` in Python against the
//! `pyrvo` bindings), and for anyone who wants ORCA alone.

use super::{
    agent_neighbours, new_velocity, obstacle_neighbours, Agent, Horizon, Obstacles, Real,
    Surroundings, V2,
};

/// RVO2's simulation-wide settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CrowdSettings<T> {
    /// How far an agent looks for other agents.
    pub neighbour_dist: T,
    /// Most agents an agent avoids at once (the nearest).
    pub max_neighbours: usize,
    /// Time over which velocities keep clear of other agents.
    pub time_horizon: T,
    /// Time over which velocities keep clear of obstacles.
    pub time_horizon_obstacles: T,
    /// The time step.
    pub time_step: T,
}

/// One agent of a crowd as RVO2 takes it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CrowdAgent<T> {
    /// Position, velocity and radius.
    pub agent: Agent<T>,
    /// Its largest speed.
    pub max_speed: T,
    /// The velocity it would like.
    pub preferred: V2<T>,
}

/// What a step gives one agent.
#[derive(Clone, Debug, PartialEq)]
pub struct CrowdChoice<T> {
    /// The agents it avoided (indices), nearest first.
    pub agent_neighbours: Vec<usize>,
    /// The obstacle edges it avoided (vertex indices, in the order the polygons were given),
    /// nearest first.
    pub obstacle_neighbours: Vec<usize>,
    /// Its new velocity.
    pub velocity: V2<T>,
}

/// One step of `agents` among the polygons `obstacles` (each a list of corners, counter-clockwise
/// as RVO2 wants them): every agent's neighbours and new velocity, all from the same state.
pub fn crowd_step<T: Real>(
    agents: &[CrowdAgent<T>],
    obstacles: &[Vec<V2<T>>],
    settings: &CrowdSettings<T>,
) -> Vec<CrowdChoice<T>> {
    let mut polygons = Obstacles::default();
    for points in obstacles {
        polygons.add(points);
    }
    let bodies: Vec<Agent<T>> = agents.iter().map(|a| a.agent).collect();
    let (mut near, mut edges, mut lines) = (Vec::new(), Vec::new(), Vec::new());
    let mut out = Vec::with_capacity(agents.len());
    for (i, a) in agents.iter().enumerate() {
        let horizon = Horizon {
            agents: settings.time_horizon,
            obstacles: settings.time_horizon_obstacles,
            max_speed: a.max_speed,
            time_step: settings.time_step,
        };
        agent_neighbours(
            &bodies,
            i,
            settings.neighbour_dist,
            settings.max_neighbours,
            &mut near,
        );
        obstacle_neighbours(
            &polygons,
            a.agent.position,
            a.agent.radius,
            &horizon,
            &mut edges,
        );
        let others: Vec<Agent<T>> = near.iter().map(|&(_, j)| bodies[j]).collect();
        let edge_list: Vec<usize> = edges.iter().map(|&(_, e)| e).collect();
        let around = Surroundings {
            agents: &others,
            obstacles: &polygons,
            edges: &edge_list,
        };
        let velocity = new_velocity(&a.agent, a.preferred, &around, &horizon, &mut lines);
        out.push(CrowdChoice {
            agent_neighbours: near.iter().map(|&(_, j)| j).collect(),
            obstacle_neighbours: edge_list,
            velocity,
        });
    }
    out
}
