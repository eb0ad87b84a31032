//! Criterion benchmarks of the laser against its range and beam count, in a maze scene and in an
//! image scene (the same maze drawn with `render::Canvas` and loaded back with
//! `Scene::from_image`).
//!
//! `cargo bench -p ronap-core --bench rays`. Each `ray/<scene>/<range>` iteration is one scan of
//! the paper's 17 beams over 180 deg from the next of 64 free poses, so the time per ray is the
//! reported time / 17 (the throughput line counts rays). Targets (issue 13): at most 20 ns a ray in
//! the maze at any range up to its size, at most 40 ns in the image scene at 1000 px.
//! `scan/360_beams_500px` is a full-circle scan of 360 beams reaching 500 px.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use rand::{Rng, SeedableRng};
use ronap_core::render::Canvas;
use ronap_core::sim::maze_scene;
use ronap_core::{Laser, Point, Scene, SimConfig, ValidConfig};
use std::hint::black_box;

/// The default configuration with a laser of `beams` over `fov_deg` reaching `range_px`.
fn laser_config(beams: u32, fov_deg: f64, range_px: f64) -> ValidConfig {
    let mut sim = SimConfig::default();
    sim.laser.beams = beams;
    sim.laser.fov_deg = fov_deg;
    sim.laser.range_px = range_px;
    sim.validate().expect("valid laser")
}

/// The maze of seed 0 and the same maze as an image scene, both indexed for `config`.
fn scenes(config: &ValidConfig) -> [(&'static str, Scene); 2] {
    let maze = maze_scene(config, 0);
    let picture = image::DynamicImage::ImageRgb8(Canvas::new(&maze, 1.0).into_image());
    let image = Scene::from_image(&picture, &config.map, config.reach_px());
    [("maze", maze), ("image", image)]
}

/// 64 poses (position, heading in degrees) at least 5 px clear of every wall.
fn poses(scene: &Scene) -> Vec<(Point, f64)> {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(13);
    let mut out = Vec::new();
    while out.len() < 64 {
        let p = Point::new(
            rng.random_range(0.0..scene.width()),
            rng.random_range(0.0..scene.height()),
        );
        if scene.disc_clear(p, 5.0) {
            out.push((p, rng.random_range(0.0..360.0)));
        }
    }
    out
}

/// Benchmarks `laser` scanning `scene` from each pose in turn.
fn bench_scan(
    group: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    name: &str,
    laser: &Laser,
    scene: &Scene,
) {
    let poses = poses(scene);
    let mut out = vec![0.0; laser.beams()];
    let mut k = 0;
    group.throughput(Throughput::Elements(laser.beams() as u64));
    group.bench_function(name, |b| {
        b.iter(|| {
            k = (k + 1) % poses.len();
            let (p, z) = poses[k];
            laser.scan(scene, black_box(p), black_box(z), &mut out);
        })
    });
}

fn ray(c: &mut Criterion) {
    let mut group = c.benchmark_group("ray");
    for range in [50.0, 500.0, 1000.0] {
        let config = laser_config(17, 180.0, range);
        let laser = Laser::new(&config.laser);
        for (kind, scene) in scenes(&config) {
            bench_scan(&mut group, &format!("{kind}/{range}"), &laser, &scene);
        }
    }
    group.finish();
}

fn scan(c: &mut Criterion) {
    let mut group = c.benchmark_group("scan");
    let config = laser_config(360, 360.0, 500.0);
    let laser = Laser::new(&config.laser);
    let scene = maze_scene(&config, 0);
    bench_scan(&mut group, "360_beams_500px", &laser, &scene);
    group.finish();
}

// The macro defines an undocumented `benches` function.
#[allow(missing_docs)]
mod group {
    use super::*;
    criterion_group!(benches, ray, scan);
}
use group::benches;
criterion_main!(benches);
