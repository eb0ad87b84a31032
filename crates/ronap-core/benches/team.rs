//! Criterion benchmark of a big team: 1000 robots, each with a 64-beam 360-degree laser of range
//! 200 px, in a 40 x 40 maze of 100 px cells (issue target: one step of all robots in at most
//! 2 ms on one core). Robots drive the `ronap bench` action pattern, each at its own phase, and
//! stay in the scene; the episode never ends (no time-out, no deadlock). Beside it, the engine of
//! `VecMultiNavEnv`: 64 teams of 8 robots of the default maze stepped side by side, with
//! next-step autoreset, on one thread and on every core.
//!
//! `cargo bench -p ronap-core --bench team`.

use common::{big_maze, PATTERN};
use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use ronap_core::config::{SimConfig, TeamRobotConfig};
use ronap_core::run::{TeamBatch, TeamRollout};
use ronap_core::sim::{Action, DiscreteAction, Scenes, Worlds};
use std::time::Duration;

mod common;

/// `robots` robots with 64-beam 360-degree lasers of range 200 px in a 40 x 40 maze.
fn big_team(robots: u32) -> SimConfig {
    let mut c = big_maze();
    c.episode.max_steps = u32::MAX;
    c.episode.deadlock_steps = u32::MAX;
    c.robots = vec![TeamRobotConfig {
        count: robots,
        ..TeamRobotConfig::default()
    }];
    c
}

fn team(c: &mut Criterion) {
    let mut group = c.benchmark_group("team");
    group
        .sample_size(20)
        .measurement_time(Duration::from_secs(10));
    for robots in [100u32, 1000] {
        let config = big_team(robots).validate().expect("valid");
        let worlds = Worlds::new(config.clone(), Scenes::Maze(0));
        let mut rollout = TeamRollout::placed(&config, worlds.team(0), 0).expect("room for all");
        let n = robots as usize;
        let mut t = 0usize;
        let mut actions: Vec<Option<Action>> = vec![None; n];
        group.throughput(Throughput::Elements(u64::from(robots)));
        group.bench_function(format!("step_{robots}_robots_64_beams_200px"), |b| {
            b.iter(|| {
                t += 1;
                for (k, a) in actions.iter_mut().enumerate() {
                    let i = PATTERN[(t + k) % PATTERN.len()];
                    *a = DiscreteAction::from_index(i).map(Action::from);
                }
                rollout.step(&actions);
            })
        });
    }
    group.finish();
}

/// `VecMultiNavEnv`'s engine without Python: 64 environments of a team of 8 robots in the default
/// maze (each environment its own maze), every robot driving the action pattern at its own
/// phase; the figure is per step of all 512 robots.
fn batch(c: &mut Criterion) {
    let mut group = c.benchmark_group("team_batch");
    group.throughput(Throughput::Elements(512));
    let config = SimConfig {
        robots: vec![TeamRobotConfig {
            count: 8,
            ..TeamRobotConfig::default()
        }],
        ..SimConfig::default()
    };
    let config = config.validate().expect("valid");
    for (name, threads) in [("step_64x8_one_thread", 1), ("step_64x8_all_threads", 0)] {
        let worlds = Worlds::new(config.clone(), Scenes::MazePerSeed);
        let options = common::batch_options(64, threads);
        let mut batch = TeamBatch::new(worlds, options).expect("a pool");
        batch.reset(0).expect("room for every team");
        let actions = common::pattern_actions(512);
        let mut k = 0;
        group.bench_function(name, |b| {
            b.iter(|| {
                k += 1;
                batch
                    .step(&actions[k % actions.len()], None)
                    .expect("steps")
            })
        });
    }
    group.finish();
}

// The macro defines an undocumented `benches` function.
#[allow(missing_docs)]
mod group {
    use super::*;
    criterion_group!(benches, team, batch);
}
use group::benches;
criterion_main!(benches);
