//! ORCA held to RVO2 itself: `tests/data/orca-rvo2.json` holds one step of 80 random crowds
//! (2-50 agents, half among boxes) as the `pyrvo` bindings of RVO2 computed it, and as RVO2's
//! sources built in double precision compute it (`scripts/orca-reference.py`). In RVO2's own
//! `f32` the core must choose the same neighbours and the same new velocities (to 1e-6); in
//! `f64`, the precision the simulation uses, the double build's velocities (to 1e-9).

// Test code may panic on setup failures: that is a failed test, as intended.
#![allow(clippy::unwrap_used)]

use ronap_core::geometry::{
    agent_neighbours, crowd_step, new_velocity, Agent, CrowdAgent, CrowdSettings, Horizon,
    Obstacles, Real, Surroundings, V2,
};
use serde_json::Value;

fn v2<T: Real>(v: &Value) -> V2<T> {
    V2::new(T::of(v[0].as_f64().unwrap()), T::of(v[1].as_f64().unwrap()))
}

fn num<T: Real>(v: &Value) -> T {
    T::of(v.as_f64().unwrap())
}

/// One neighbour list, one obstacle-edge list and one new velocity an agent.
type Choice = (Vec<usize>, Vec<usize>, [f64; 2]);

/// One case computed in `T`: each agent's neighbours (agents, obstacle edges) and new velocity.
fn step<T: Real>(case: &Value) -> Vec<Choice> {
    let p = &case["params"];
    let agents: Vec<CrowdAgent<T>> = case["agents"]
        .as_array()
        .unwrap()
        .iter()
        .map(|a| CrowdAgent {
            agent: Agent {
                position: v2(&a["position"]),
                velocity: v2(&a["velocity"]),
                radius: num(&a["radius"]),
            },
            max_speed: num(&a["max_speed"]),
            preferred: v2(&a["preferred"]),
        })
        .collect();
    let boxes: Vec<Vec<V2<T>>> = case["boxes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|b| b.as_array().unwrap().iter().map(v2).collect())
        .collect();
    let settings = CrowdSettings {
        neighbour_dist: num(&p["neighbor_dist"]),
        max_neighbours: p["max_neighbors"].as_u64().unwrap() as usize,
        time_horizon: num(&p["time_horizon"]),
        time_horizon_obstacles: num(&p["time_horizon_obst"]),
        time_step: num(&p["time_step"]),
    };
    crowd_step(&agents, &boxes, &settings)
        .into_iter()
        .map(|c| {
            let v = [c.velocity.x.to_f64(), c.velocity.y.to_f64()];
            (c.agent_neighbours, c.obstacle_neighbours, v)
        })
        .collect()
}

fn cases() -> Vec<Value> {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/orca-rvo2.json");
    let text = std::fs::read_to_string(path).unwrap();
    let data: Value = serde_json::from_str(&text).unwrap();
    data["cases"].as_array().unwrap().clone()
}

fn ids(v: &Value) -> Vec<usize> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_u64().unwrap() as usize)
        .collect()
}

#[test]
fn in_f32_orca_gives_rvo2s_neighbours_and_velocities() {
    let (mut agents, mut worst, mut with_obstacles) = (0, 0.0f64, 0);
    let mut tied_edges_swapped = false;
    for (c, case) in cases().iter().enumerate() {
        let list = case["agents"].as_array().unwrap();
        for (i, (ours, a)) in step::<f32>(case).iter().zip(list).enumerate() {
            assert_eq!(ours.0, ids(&a["agent_neighbours"]), "case {c} agent {i}");
            // Obstacle edges at the same distance (two edges whose nearest point is the corner
            // they share) come in the order of RVO2's obstacle tree: the same edges, sorted.
            let (mut mine, mut theirs) = (ours.1.clone(), ids(&a["obstacle_neighbours"]));
            tied_edges_swapped |= mine != theirs;
            mine.sort_unstable();
            theirs.sort_unstable();
            assert_eq!(mine, theirs, "case {c} agent {i}");
            with_obstacles += usize::from(!ours.1.is_empty());
            let want = &a["new_velocity"];
            for k in 0..2 {
                // RVO2's float, exactly as it printed it.
                let rvo2 = f64::from(want[k].as_f64().unwrap() as f32);
                let d = (ours.2[k] - rvo2).abs();
                worst = worst.max(d);
                assert!(d <= 1e-6, "case {c} agent {i}: {:?} vs {want}", ours.2);
            }
            agents += 1;
        }
    }
    assert!(
        agents > 1000 && with_obstacles > 100,
        "{agents} {with_obstacles}"
    );
    eprintln!(
        "{agents} agents ({with_obstacles} near obstacles): largest difference {worst:e}; tied \
         edges in another order: {tied_edges_swapped}"
    );
}

#[test]
fn in_f64_orca_gives_the_velocities_of_rvo2_built_in_double() {
    // The simulation's precision, held to RVO2's sources built with every float a double
    // (`new_velocity_f64`, see scripts/orca-reference.py). Against RVO2's own float the
    // differences are its rounding, about 1e-7 of a speed of a few units, except where the
    // linear program is ill-conditioned (nearly parallel half-planes meeting at a sharp angle
    // amplify it), which the spread below shows.
    let (mut worst, mut from_float) = (0.0f64, Vec::new());
    for (c, case) in cases().iter().enumerate() {
        let list = case["agents"].as_array().unwrap();
        for (i, (ours, a)) in step::<f64>(case).iter().zip(list).enumerate() {
            let double = &a["new_velocity_f64"];
            let float = &a["new_velocity"];
            let mut d_float = 0.0f64;
            for k in 0..2 {
                let d = (ours.2[k] - double[k].as_f64().unwrap()).abs();
                worst = worst.max(d);
                assert!(d <= 1e-9, "case {c} agent {i}: {:?} vs {double}", ours.2);
                d_float = d_float.max((ours.2[k] - float[k].as_f64().unwrap()).abs());
            }
            from_float.push(d_float);
        }
    }
    from_float.sort_by(f64::total_cmp);
    let at = |q: f64| from_float[((from_float.len() - 1) as f64 * q) as usize];
    eprintln!(
        "f64, {} agents: largest difference from RVO2 in double {worst:e}; from RVO2's float: \
         median {:e}, 99th percentile {:e}, largest {:e}",
        from_float.len(),
        at(0.5),
        at(0.99),
        at(1.0)
    );
}

#[test]
fn twenty_agents_swap_across_a_circle_without_touching() {
    // RVO2's Circle example at ronap's scale: holonomic agents of radius 5 at 5 px a step, each
    // avoiding with a 1 px margin (radius 6). Without it, at a radius a step, agents meeting in
    // the middle overlap by up to 1.9 px (RVO2 itself, through pyrvo, by 1.7): the linear program
    // turns infeasible there and ORCA only minimises the overlap.
    let n = 20;
    let mut agents: Vec<Agent<f64>> = (0..n)
        .map(|k| {
            let a = std::f64::consts::TAU * k as f64 / n as f64;
            Agent {
                position: V2::new(200.0 + 150.0 * a.cos(), 200.0 + 150.0 * a.sin()),
                velocity: V2::zero(),
                radius: 6.0,
            }
        })
        .collect();
    let goals: Vec<V2<f64>> = agents
        .iter()
        .map(|a| V2::new(400.0, 400.0) - a.position)
        .collect();
    let horizon = Horizon {
        agents: 10.0,
        obstacles: 5.0,
        max_speed: 5.0,
        time_step: 1.0,
    };
    let obstacles = Obstacles::default();
    let (mut near, mut lines) = (Vec::new(), Vec::new());
    let mut least = f64::INFINITY;
    let mut steps = 0;
    while steps < 400 {
        let mut next = Vec::new();
        for i in 0..n {
            let to_goal = goals[i] - agents[i].position;
            let d = to_goal.abs();
            let preferred = if d > 5.0 {
                to_goal.scale(5.0 / d)
            } else {
                to_goal
            };
            // RVO2's examples perturb the preferred velocity a little: perfect symmetry can
            // otherwise hold ORCA agents still for ever.
            let a = (i * 7 + steps * 13) as f64;
            let preferred = preferred + V2::new(a.cos(), a.sin()).scale(1e-3);
            agent_neighbours(&agents, i, 150.0, 19, &mut near);
            let others: Vec<Agent<f64>> = near.iter().map(|&(_, j)| agents[j]).collect();
            let around = Surroundings {
                agents: &others,
                obstacles: &obstacles,
                edges: &[],
            };
            next.push(new_velocity(
                &agents[i], preferred, &around, &horizon, &mut lines,
            ));
        }
        for (a, v) in agents.iter_mut().zip(next) {
            a.velocity = v;
            a.position = a.position + v;
        }
        for i in 0..n {
            for j in i + 1..n {
                least = least.min((agents[i].position - agents[j].position).abs() - 10.0);
            }
        }
        steps += 1;
        if (0..n).all(|i| (goals[i] - agents[i].position).abs() < 1.0) {
            break;
        }
    }
    eprintln!("arrived in {steps} steps, least gap {least}");
    assert!(steps < 400, "not every agent arrived");
    assert!(least > 0.0, "agents of radius 5 overlapped by {}", -least);
}
