//! Criterion benchmarks of the `coordinated` team planner (issue targets, one core): planning
//! 100 robots in `hall-robots.toml`'s hall in at most 50 ms, and a step of 1000 robots
//! (`robots-1000.toml`: a 40 x 40 maze, 64-beam 360-degree lasers of range 200 px) in at most
//! 5 ms, the planner's decisions and the team's move together.
//!
//! `cargo bench -p ronap-core --bench coordinated`.

use common::big_maze;
use criterion::{criterion_group, criterion_main, Criterion};
use ronap_core::config::{OnArrival, SimConfig, TeamRobotConfig};
use ronap_core::policy::{Coordinated, TeamPolicy};
use ronap_core::run::TeamRollout;
use ronap_core::sim::{Scenes, Worlds};
use ronap_core::ValidConfig;
use std::time::{Duration, Instant};

mod common;

/// `robots` robots that leave on arrival, in `config`.
fn with_robots(mut c: SimConfig, robots: u32) -> ValidConfig {
    c.robots = vec![TeamRobotConfig {
        count: robots,
        on_arrival: OnArrival::Vanish,
        ..TeamRobotConfig::default()
    }];
    c.validate().expect("valid")
}

/// `hall-robots.toml`: 100 robots in an open 1000 x 1000 px hall, goals 300 px or more away.
fn hall() -> ValidConfig {
    let mut c = SimConfig::default();
    c.maze.cols = 1;
    c.maze.rows = 1;
    c.maze.cell_px = 1000.0;
    c.episode.min_goal_distance_px = 300.0;
    with_robots(c, 100)
}

/// `robots-1000.toml`: 1000 robots in a 40 x 40 maze with 64-beam 360-degree lasers.
fn thousand() -> ValidConfig {
    let mut c = big_maze();
    c.episode.max_steps = 100_000;
    with_robots(c, 1000)
}

fn coordinated(c: &mut Criterion) {
    let mut group = c.benchmark_group("coordinated");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(10));

    let config = hall();
    let worlds = Worlds::new(config.clone(), Scenes::Maze(0));
    let placed = TeamRollout::placed(&config, worlds.team(0), 0).expect("room for all");
    group.bench_function("plan_100_robots_hall", |b| {
        b.iter(|| {
            let mut policy = Coordinated::default();
            let rollout = placed.clone();
            let (team, worlds, _) = rollout.into_parts();
            policy.reset(&team, &worlds).expect("plans");
            policy
        })
    });

    // Steps 1-200 of seed 0, over and over: the rollout starts afresh (untimed) every 200 steps.
    let config = thousand();
    let worlds = Worlds::new(config.clone(), Scenes::Maze(0));
    let start = || {
        let mut policy = Coordinated::default();
        let rollout = TeamRollout::start(&config, worlds.team(0), 0, &mut policy).expect("starts");
        (rollout, policy)
    };
    let (mut rollout, mut policy) = start();
    group.bench_function("step_1000_robots_64_beams_200px", |b| {
        b.iter_custom(|iters| {
            let mut spent = Duration::ZERO;
            for _ in 0..iters {
                if rollout.team().steps() >= 200 {
                    (rollout, policy) = start();
                }
                let clock = Instant::now();
                rollout.advance(&mut policy).expect("steps");
                spent += clock.elapsed();
            }
            spent
        })
    });
    group.finish();
}

// The macro defines an undocumented `benches` function.
#[allow(missing_docs)]
mod group {
    use super::*;
    criterion_group!(benches, coordinated);
}
use group::benches;
criterion_main!(benches);
