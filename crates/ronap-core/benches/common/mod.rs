//! What the benchmarks share: the `ronap bench` action pattern, the big maze and laser of the
//! 1000-robot team, a timed step of one episode after another, and a batch's set-up.

// Each benchmark uses a part of this module.
#![allow(dead_code)]

use criterion::measurement::WallTime;
use criterion::BenchmarkGroup;
use ronap_core::sim::maze_scene;
use ronap_core::{Episode, SimConfig, ValidConfig};
use std::sync::Arc;

/// The action pattern `ronap bench` uses too: mostly ahead, some turns.
pub const PATTERN: [usize; 8] = [1, 1, 1, 0, 1, 1, 2, 1];

/// How the batch benchmarks run `envs` environments on `threads` threads: next-step autoreset,
/// strided seeds.
pub fn batch_options(envs: usize, threads: usize) -> ronap_core::run::BatchOptions {
    ronap_core::run::BatchOptions {
        envs,
        threads,
        autoreset: ronap_core::run::Autoreset::NextStep,
        seed_order: ronap_core::run::SeedOrder::Strided,
    }
}

/// A step's actions for `rows` robots for each phase of [`PATTERN`], row `j` at phase `k + j`.
pub fn pattern_actions(rows: usize) -> Vec<Vec<ronap_core::Action>> {
    (0..PATTERN.len())
        .map(|k| {
            (0..rows)
                .map(|j| ronap_core::DiscreteAction::ALL[PATTERN[(k + j) % PATTERN.len()]].into())
                .collect()
        })
        .collect()
}

/// The default configuration in a 40 x 40 maze with 64-beam 360-degree lasers of range 200 px
/// (`robots-1000.toml`'s scene and lasers, its robots still to add).
pub fn big_maze() -> SimConfig {
    let mut c = SimConfig::default();
    c.maze.cols = 40;
    c.maze.rows = 40;
    c.laser.beams = 64;
    c.laser.fov_deg = 360.0;
    c.laser.range_px = 200.0;
    c
}

/// Times `step` of an episode of `config` in the maze of seed 0 as `name` in `group`: `step`
/// takes the episode and the iteration's count and says whether the episode is over, when the
/// next seed's episode takes its place.
pub fn bench_steps(
    group: &mut BenchmarkGroup<'_, WallTime>,
    name: &str,
    config: &ValidConfig,
    mut step: impl FnMut(&mut Episode, usize) -> bool,
) {
    let scene = Arc::new(maze_scene(config, 0));
    let mut seed = 0;
    let mut episode = Episode::new(config, scene.clone(), seed).expect("default scene");
    let mut k = 0;
    group.bench_function(name, |b| {
        b.iter(|| {
            k += 1;
            if step(&mut episode, k) {
                seed += 1;
                episode = Episode::new(config, scene.clone(), seed).expect("default scene");
            }
        })
    });
}
