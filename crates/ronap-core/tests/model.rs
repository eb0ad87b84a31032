//! Integration tests of the model against independent references: parry2d for geometry, the maze
//! drawn as a picture for image scenes, and repeated runs for determinism.

// Test helpers may panic on setup failures: that is a failed test, as intended.
#![allow(clippy::unwrap_used)]

use proptest::prelude::*;
use rand::{Rng, SeedableRng};
use ronap_core::geometry::{unit, ParryScene};
use ronap_core::render::Canvas;
use ronap_core::sim::maze_scene;
use ronap_core::{DiscreteAction, Episode, Laser, Point, Scene, SimConfig, ValidConfig};
use std::sync::Arc;

fn config() -> ValidConfig {
    ValidConfig::default()
}

/// A free point with clearance `r` in `scene`, drawn from `rng`.
fn free_point(scene: &Scene, r: f64, rng: &mut impl Rng) -> Point {
    loop {
        let p = Point::new(
            rng.random_range(0.0..scene.width()),
            rng.random_range(0.0..scene.height()),
        );
        if scene.disc_clear(p, r) {
            return p;
        }
    }
}

#[test]
fn laser_matches_parry2d_to_1e_4_px() {
    let config = config();
    let laser = Laser::new(&config.laser);
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
    let mut readings = vec![0.0; laser.beams()];
    let mut compared = 0;
    for seed in 0..20 {
        let scene = maze_scene(&config, seed);
        let parry = ParryScene::new(scene.boxes()).expect("a maze has walls");
        for _ in 0..200 {
            let p = free_point(&scene, 0.5, &mut rng);
            let z = rng.random_range(0.0..360.0);
            laser.scan(&scene, p, z, &mut readings);
            for (i, &d) in readings.iter().enumerate() {
                let dir = unit(laser.beam_angle_deg(i, z));
                let expected = parry.cast_ray(p, dir, 50.0).unwrap_or(50.0);
                assert!(
                    (d - expected).abs() < 1e-4,
                    "seed {seed} p {p:?} z {z} beam {i}: {d} vs parry {expected}"
                );
                compared += 1;
            }
        }
    }
    assert_eq!(compared, 20 * 200 * 17);
}

#[test]
fn long_rays_and_sweeps_match_parry2d() {
    // Queries longer than the index reach take the all-boxes path; they must agree too.
    let config = config();
    let scene = maze_scene(&config, 3);
    let parry = ParryScene::new(scene.boxes()).expect("walls");
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
    for _ in 0..2000 {
        let a = free_point(&scene, 5.0, &mut rng);
        let dir = unit(rng.random_range(0.0..360.0));
        let len = rng.random_range(0.0..400.0);
        let ours = scene.cast_ray(a, dir, len);
        let theirs = parry.cast_ray(a, dir, len);
        match (ours, theirs) {
            (Some(x), Some(y)) => assert!((x - y).abs() < 1e-6, "{x} vs {y}"),
            (None, None) => {}
            other => panic!("ray from {a:?} disagrees: {other:?}"),
        }
        let b = a + dir * len;
        // Skip near-ties, where the disc would just graze a wall.
        let gap = scene
            .boxes()
            .iter()
            .map(|bx| bx.segment_distance_squared(a, b).sqrt())
            .fold(f64::INFINITY, f64::min);
        if (gap - 5.0).abs() > 1e-6 {
            assert_eq!(
                scene.sweep_clear(a, b, 5.0),
                parry.sweep_clear(a, b, 5.0),
                "{a:?} -> {b:?}"
            );
        }
    }
}

/// The default configuration with a laser of `beams` over `fov_deg` reaching `range_px`.
fn laser_config(beams: u32, fov_deg: f64, range_px: f64) -> ValidConfig {
    let mut sim = SimConfig::default();
    sim.laser.beams = beams;
    sim.laser.fov_deg = fov_deg;
    sim.laser.range_px = range_px;
    sim.validate().unwrap()
}

/// The maze of `seed` drawn with `Canvas` and loaded back as an image scene.
fn image_of_maze(config: &ValidConfig, seed: u64) -> Scene {
    let maze = maze_scene(config, seed);
    let picture = image::DynamicImage::ImageRgb8(Canvas::new(&maze, 1.0).into_image());
    Scene::from_image(&picture, &config.map, config.reach_px())
}

#[test]
fn laser_matches_parry2d_at_long_range_and_many_beams() {
    // Out to the scene's size and past its diagonal, up to the beam cap; mazes (walked by their
    // own cells) and image scenes (walked by a uniform grid).
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(29);
    let mut compared = 0;
    for (range, beams, fov) in [
        (200.0, 64, 180.0),
        (500.0, 17, 180.0),
        (1000.0, 360, 360.0),
        (1000.0, 1080, 270.0),
        (1500.0, 4096, 360.0),
    ] {
        let config = laser_config(beams, fov, range);
        let laser = Laser::new(&config.laser);
        let mut readings = vec![0.0; laser.beams()];
        for seed in 0..3 {
            for scene in [maze_scene(&config, seed), image_of_maze(&config, seed)] {
                let parry = ParryScene::new(scene.boxes()).expect("walls");
                for _ in 0..4 {
                    let p = free_point(&scene, 0.5, &mut rng);
                    let z = rng.random_range(0.0..360.0);
                    laser.scan(&scene, p, z, &mut readings);
                    for (i, &d) in readings.iter().enumerate() {
                        let dir = unit(laser.beam_angle_deg(i, z));
                        let expected = parry.cast_ray(p, dir, range).unwrap_or(range);
                        assert!(
                            (d - expected).abs() < 1e-4,
                            "{range} px, {beams} beams, seed {seed}, p {p:?} z {z} beam {i}: \
                             {d} vs parry {expected}"
                        );
                        compared += 1;
                    }
                }
            }
        }
    }
    assert_eq!(compared, 3 * 2 * 4 * (64 + 17 + 360 + 1080 + 4096));
}

#[test]
fn laser_readings_are_the_least_box_hit_to_the_bit() {
    // Whichever way a scan finds its boxes (the boxes in range, a maze's cells, a uniform grid),
    // each reading is bit for bit the least `Aabb::ray_hit` over every box of the scene.
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(31);
    let mut compared = 0;
    for range in [50.0, 150.0, 500.0, 1000.0, 5000.0] {
        let config = laser_config(90, 360.0, range);
        let laser = Laser::new(&config.laser);
        let mut readings = vec![0.0; laser.beams()];
        let with_box = maze_scene(&config, 4).with_obstacles(
            vec![ronap_core::Aabb::from_corners(
                Point::new(430.0, 440.0),
                Point::new(470.0, 455.0),
            )],
            vec![],
        );
        let scenes = [
            maze_scene(&config, 2),
            image_of_maze(&config, 3),
            with_box,
            ronap_core::sim::warehouse_scene(&config, 5),
        ];
        for scene in &scenes {
            for k in 0..25 {
                // Some poses hug a wall, where a beam can run along a face.
                let p = free_point(scene, if k % 5 == 0 { 1e-3 } else { 1.0 }, &mut rng);
                let z = if k % 3 == 0 {
                    0.0
                } else {
                    rng.random_range(0.0..360.0)
                };
                laser.scan(scene, p, z, &mut readings);
                // Every box against each beam, in turn, as the scan did before it had an index;
                // `refine` hands over each beam's direction exactly as the scan computes it.
                let mut every_box = vec![range; laser.beams()];
                laser.refine(p, z, &mut every_box, |origin, dir, _| {
                    let inv = ronap_core::Vector::new(1.0 / dir.x, 1.0 / dir.y);
                    let mut best = range;
                    for b in scene.boxes() {
                        if let Some(t) = b.ray_hit(origin, inv, best) {
                            best = t;
                        }
                    }
                    Some(best)
                });
                for (i, (d, e)) in readings.iter().zip(&every_box).enumerate() {
                    assert_eq!(
                        d.to_bits(),
                        e.to_bits(),
                        "{range} px, p {p:?} z {z} beam {i}"
                    );
                    compared += 1;
                }
            }
        }
    }
    assert_eq!(compared, 5 * 4 * 25 * 90);
}

#[test]
fn a_laser_may_have_up_to_4096_beams() {
    assert!(SimConfig::default().validate().is_ok());
    let mut sim = SimConfig::default();
    sim.laser.beams = 4096;
    assert!(sim.clone().validate().is_ok());
    sim.laser.beams = 4097;
    let e = sim.validate().unwrap_err().to_string();
    assert!(e.contains("laser.beams") && e.contains("4096"), "{e}");
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// Even at 1000 px a step, the robot never ends inside a wall nor passes through one.
    #[test]
    fn robot_never_enters_or_crosses_a_wall(seed in any::<u64>(), speed in prop_oneof![Just(5.0), Just(1000.0), 1.0f64..300.0]) {
        let mut sim = SimConfig::default();
        sim.robot.move_speed_px = speed;
        sim.robot.max_linear_speed_px = speed;
        let config = sim.validate().unwrap();
        let scene = Arc::new(maze_scene(&config, seed));
        let parry = ParryScene::new(scene.boxes()).unwrap();
        let mut episode = Episode::new(&config, scene.clone(), seed).unwrap();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        for _ in 0..300 {
            let before = episode.pose();
            let (v, w_deg) = if rng.random_bool(0.5) {
                (rng.random_range(-speed..=speed), rng.random_range(-15.0..=15.0))
            } else {
                (0.0, 0.0)
            };
            let r = if v == 0.0 {
                episode.step(DiscreteAction::ALL[rng.random_range(0..3)])
            } else {
                episode.step(ronap_core::Action::Continuous { v, w_deg })
            };
            let after = r.pose;
            prop_assert!(scene.disc_clear(after.position(), 5.0), "inside a wall at {:?}", after);
            if r.collided {
                prop_assert_eq!(after, before);
            } else {
                // The path of the step, cut into 400 chords (a straight step is one line anyway),
                // is clear by parry2d's independent test.
                let chords = ((v.abs() / 2.0).ceil() as usize).clamp(1, 400);
                let path = arc(before, after, v, w_deg, chords);
                for pair in path.windows(2) {
                    let clear = parry.sweep_clear(pair[0], pair[1], 4.99)
                        || scene.boxes().iter().any(|b| {
                            (b.segment_distance_squared(pair[0], pair[1]).sqrt() - 5.0).abs() < 0.02
                        });
                    prop_assert!(clear, "crossed a wall between {:?} and {:?}", before, after);
                }
            }
            if r.status.is_done() {
                break;
            }
        }
    }
}

/// Points along a step from `before` to `after`: the unicycle arc of `(v, w_deg)`, or the straight
/// line for a discrete step (`v == 0`).
fn arc(
    before: ronap_core::Pose,
    after: ronap_core::Pose,
    v: f64,
    w_deg: f64,
    n: usize,
) -> Vec<Point> {
    if v == 0.0 {
        return vec![before.position(), after.position()];
    }
    let z0 = before.z_deg.to_radians();
    (0..=n)
        .map(|k| {
            let f = k as f64 / n as f64;
            let w = (w_deg * f).to_radians();
            let s = v * f;
            if w.abs() < 1e-12 {
                before.position() + unit(before.z_deg) * s
            } else {
                let r = s / w;
                Point::new(
                    before.x + r * ((z0 + w).sin() - z0.sin()),
                    before.y - r * ((z0 + w).cos() - z0.cos()),
                )
            }
        })
        .collect()
}

/// Every bit of every observation, reward and pose of a scripted run.
fn trace(config: &ValidConfig, seed: u64) -> Vec<u64> {
    let scene = Arc::new(maze_scene(config, seed));
    let mut episode = Episode::new(config, scene, seed).unwrap();
    let pattern = [1, 1, 1, 0, 1, 1, 2, 1, 1, 1, 1, 2, 2, 1];
    let mut bits = Vec::new();
    for k in 0..600 {
        let r = episode.step_index(pattern[k % pattern.len()]).unwrap();
        bits.extend(r.observation.iter().map(|v| v.to_bits() as u64));
        bits.extend([
            r.reward.to_bits(),
            r.pose.x.to_bits(),
            r.pose.y.to_bits(),
            r.pose.z_deg.to_bits(),
        ]);
    }
    bits
}

#[test]
fn same_seed_same_bits_on_any_thread() {
    let mut sim = SimConfig::default();
    sim.laser.noise_sigma_px = 2.0;
    let config = sim.validate().unwrap();
    let here = trace(&config, 42);
    let there = std::thread::spawn({
        let config = config.clone();
        move || trace(&config, 42)
    })
    .join()
    .unwrap();
    assert_eq!(here, there);
    assert_ne!(here, trace(&config, 43));
}

#[test]
fn noise_changes_readings_but_not_the_maze_or_placement() {
    let quiet = config();
    let mut sim = SimConfig::default();
    sim.laser.noise_sigma_px = 3.0;
    let noisy = sim.validate().unwrap();
    for seed in 0..10 {
        let a = Episode::new(&quiet, Arc::new(maze_scene(&quiet, seed)), seed).unwrap();
        let b = Episode::new(&noisy, Arc::new(maze_scene(&noisy, seed)), seed).unwrap();
        assert_eq!(a.scene().boxes(), b.scene().boxes());
        assert_eq!((a.start(), a.goal()), (b.start(), b.goal()));
        assert_ne!(a.readings(), b.readings());
    }
}

#[test]
fn image_of_a_maze_reads_like_the_maze_within_a_pixel() {
    let config = config();
    let laser = Laser::new(&config.laser);
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(9);
    for seed in 0..5 {
        let maze = maze_scene(&config, seed);
        let picture = image::DynamicImage::ImageRgb8(Canvas::new(&maze, 1.0).into_image());
        let from_image = Scene::from_image(&picture, &config.map, 50.0);
        let (mut a, mut b) = (vec![0.0; 17], vec![0.0; 17]);
        for _ in 0..300 {
            let p = free_point(&maze, 5.0, &mut rng);
            let z = rng.random_range(0.0..360.0);
            laser.scan(&maze, p, z, &mut a);
            laser.scan(&from_image, p, z, &mut b);
            for i in 0..17 {
                // A reading crossing the maze's boundary edge goes on into the image's outside.
                assert!(
                    (a[i] - b[i]).abs() <= 1.0 + 1e-9,
                    "seed {seed} {p:?} z {z} beam {i}: {} vs {}",
                    a[i],
                    b[i]
                );
            }
        }
    }
}

#[test]
fn png_and_pgm_maps_load_with_threshold_and_resolution() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    // A 20 x 10 image: black column at x = 10, grey (128) column at x = 15.
    let mut img = image::GrayImage::from_pixel(20, 10, image::Luma([255]));
    for y in 0..10 {
        img.put_pixel(10, y, image::Luma([0]));
        img.put_pixel(15, y, image::Luma([128]));
    }
    for ext in ["png", "pgm"] {
        let path = dir.join(format!("map.{ext}"));
        img.save(&path).unwrap();
        let map = ronap_core::config::MapConfig {
            threshold: 127,
            resolution_px: 2.0,
        };
        let scene = Scene::load_image(&path, &map, 50.0).unwrap();
        assert_eq!((scene.width(), scene.height()), (40.0, 20.0));
        // Ray from x = 2 along +x meets the black column at 20 px (pixel 10 at 2 px a pixel).
        assert_eq!(
            scene.cast_ray(Point::new(2.0, 10.0), unit(0.0), 100.0),
            Some(18.0)
        );
        // The grey column is free at threshold 127 but an obstacle at 128.
        assert_eq!(
            scene.cast_ray(Point::new(24.0, 10.0), unit(0.0), 100.0),
            Some(16.0)
        );
        let map = ronap_core::config::MapConfig {
            threshold: 128,
            resolution_px: 2.0,
        };
        let scene = Scene::load_image(&path, &map, 50.0).unwrap();
        assert_eq!(
            scene.cast_ray(Point::new(24.0, 10.0), unit(0.0), 100.0),
            Some(6.0)
        );
    }
    let bad = dir.join("not-an-image.png");
    std::fs::write(&bad, b"hello").unwrap();
    let err = Scene::load_image(&bad, &Default::default(), 50.0).unwrap_err();
    assert!(err.to_string().contains("not-an-image.png"), "{err}");
}
