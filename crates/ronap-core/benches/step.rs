//! Criterion benchmarks of the model's hot paths on the default scene (10 x 10 maze, 17 beams).
//!
//! `cargo bench -p ronap-core --bench step`. Targets: one step under 1 us (1,000,000 steps/s on one
//! core), with 100 `random_walk` discs too (`step/100_random_walk_discs`), and a scan among them
//! (`scan/100_discs`) within twice the still-maze scan (`scan/default`); `scan/parry2d` is the
//! same scan through parry2d's general ray cast, for comparison. Among 100 ORCA pedestrians in an
//! open hall (`step/100_orca_pedestrians`) the target is 5 us a step (200,000 steps/s). A 360-beam
//! scan among 500 discs (`scan/360_beams_200px_500_discs`) within 4x of one among 100.

use common::{bench_steps, PATTERN};
use criterion::{criterion_group, criterion_main, BatchSize, Criterion, Throughput};
use ronap_core::geometry::{unit, ParryScene};
use ronap_core::policy::{Decision, Policy};
use ronap_core::scene::FreeGrid;
use ronap_core::sim::maze_scene;
use ronap_core::{Action, DiscreteAction, Episode, Laser, ValidConfig};
use std::hint::black_box;
use std::sync::Arc;

mod common;

/// The default configuration with 100 `random_walk` discs (radius 8 px, 2 px a step).
fn crowd_config() -> ronap_core::SimConfig {
    ronap_core::SimConfig {
        moving: vec![ronap_core::config::MovingConfig {
            count: 100,
            ..Default::default()
        }],
        ..Default::default()
    }
}

/// An open 1000 px hall with 100 ORCA pedestrians (discs of 6 px at 2 px a step) walking to goals
/// drawn in free space, a new one at each arrival.
fn orca_config() -> ronap_core::SimConfig {
    let mut c = ronap_core::SimConfig {
        moving: vec![ronap_core::config::MovingConfig {
            count: 100,
            radius_px: 6.0,
            motion: ronap_core::config::MotionKind::Orca,
            on_arrival: ronap_core::config::Arrival::NewGoal,
            ..Default::default()
        }],
        ..Default::default()
    };
    c.maze.cols = 1;
    c.maze.rows = 1;
    c.maze.cell_px = 1000.0;
    c.episode.min_goal_distance_px = 400.0;
    c
}

fn step(c: &mut Criterion) {
    let mut group = c.benchmark_group("step");
    group.throughput(Throughput::Elements(1));
    for (name, sim) in [
        ("default", ronap_core::SimConfig::default()),
        ("100_random_walk_discs", crowd_config()),
        ("100_orca_pedestrians", orca_config()),
    ] {
        // Long episodes, so the figure is the step and not the occasional new episode.
        let mut sim = sim;
        sim.episode.max_steps = 1_000_000;
        let config = sim.validate().expect("valid");
        bench_steps(&mut group, name, &config, |episode, k| {
            episode
                .step_index(PATTERN[k % PATTERN.len()])
                .map(|r| r.status.is_done())
                .unwrap_or(true)
        });
    }
    group.finish();
}

fn scan(c: &mut Criterion) {
    let config = ValidConfig::default();
    let scene = maze_scene(&config, 0);
    let laser = Laser::new(&config.laser);
    let episode = Episode::new(&config, Arc::new(scene.clone()), 0).expect("default scene");
    let pose = episode.start();
    let mut out = vec![0.0; laser.beams()];
    let crowd = crowd_config().validate().expect("valid");
    let crowded = Episode::new(&crowd, Arc::new(maze_scene(&crowd, 0)), 0).expect("places");
    let movers = crowded.movers().expect("a crowd").clone();
    let mut group = c.benchmark_group("scan");
    // As an episode senses: the heading's sine and cosine once, the still scene, then the discs.
    let radius = config.robot.radius_px;
    group.bench_function("100_discs", |b| {
        b.iter(|| {
            let heading = unit(black_box(pose.z_deg));
            laser.scan_toward(&scene, black_box(pose.position()), heading, &mut out);
            movers.sense_toward(
                &laser,
                black_box(pose.position()),
                radius,
                heading,
                &mut out,
            )
        })
    });
    group.bench_function("default", |b| {
        b.iter(|| {
            laser.scan(
                &scene,
                black_box(pose.position()),
                black_box(pose.z_deg),
                &mut out,
            )
        })
    });
    // A 360-beam, 200 px laser among 100 and among 500 discs (the target: within 4x, a cost per
    // beam that meets a disc rather than per beam and disc).
    for discs in [100, 500] {
        let mut sim = crowd_config();
        sim.moving[0].count = discs;
        sim.laser.beams = 360;
        sim.laser.fov_deg = 360.0;
        sim.laser.range_px = 200.0;
        let c = sim.validate().expect("valid");
        let wide = Laser::new(&c.laser);
        let crowded = Episode::new(&c, Arc::new(maze_scene(&c, 0)), 0).expect("places");
        let movers = crowded.movers().expect("a crowd").clone();
        let mut out = vec![0.0; wide.beams()];
        group.bench_function(format!("360_beams_200px_{discs}_discs"), |b| {
            b.iter(|| {
                let heading = unit(black_box(pose.z_deg));
                wide.scan_toward(&scene, black_box(pose.position()), heading, &mut out);
                movers.sense_toward(&wide, black_box(pose.position()), radius, heading, &mut out)
            })
        });
    }
    let parry = ParryScene::new(scene.boxes()).expect("walls");
    group.bench_function("parry2d", |b| {
        b.iter(|| {
            for (i, o) in out.iter_mut().enumerate() {
                let dir = unit(laser.beam_angle_deg(i, pose.z_deg));
                *o = parry
                    .cast_ray(black_box(pose.position()), dir, 50.0)
                    .unwrap_or(50.0);
            }
        })
    });
    group.finish();
}

fn setup(c: &mut Criterion) {
    let config = ValidConfig::default();
    let mut group = c.benchmark_group("episode_setup");
    group.bench_function("maze_scene", |b| {
        b.iter(|| maze_scene(&config, black_box(3)))
    });
    // What an RL reset of the default scene costs: a new maze and its index, then placement.
    let mut seed = 0u64;
    group.bench_function("reset", |b| {
        b.iter(|| {
            seed += 1;
            Episode::new(&config, Arc::new(maze_scene(&config, seed)), seed).expect("places")
        })
    });
    group.bench_function("free_grid", |b| {
        b.iter_batched(
            || maze_scene(&config, 3),
            |scene| FreeGrid::new(&scene, 5.0, 5.0, 5.0),
            BatchSize::SmallInput,
        )
    });
    let world = ronap_core::World::maze(config.clone(), 3);
    let episode = world.episode(3).expect("placement");
    let (start, goal) = (episode.start().position(), episode.goal());
    let grid = world.grid();
    group.bench_function("distance_field", |b| {
        b.iter(|| ronap_core::plan::DistanceField::new(world.scene(), grid, goal, 5.0, 4.0))
    });
    // What geodesic reward shaping builds for an episode's first potential: the field searched
    // out as far as the start (the same seed's goal and start as above, plain costs).
    group.bench_function("lazy_field_to_start", |b| {
        b.iter(|| {
            let mut field =
                ronap_core::plan::LazyField::new(world.scene(), grid, goal, start, 5.0, 1.0);
            field.distance_at(grid, start)
        })
    });
    group.bench_function("grid_path", |b| {
        b.iter(|| ronap_core::plan::grid_path(world.scene(), grid, start, goal, 5.0, 4.0))
    });
    // What a geodesic episode builds before its first step, averaged over the scenes and starts
    // of 200 seeds as an evaluation meets them (the other benchmarks here use one seed's): a new
    // maze and its index, placement, the free-space grid, and the policy's path (searched over
    // just the cells it could use, charging for closeness to walls).
    let mut next = 0u64;
    group.bench_function("geodesic_episode_over_seeds", |b| {
        b.iter(|| {
            let seed = next % 200;
            next += 1;
            let world = ronap_core::World::maze(config.clone(), seed);
            let episode = world.episode(seed).expect("placement");
            let path = ronap_core::plan::grid_path(
                world.scene(),
                world.grid(),
                episode.start().position(),
                episode.goal(),
                config.robot.radius_px,
                4.0,
            );
            (world, path)
        })
    });
    // What an RL reset with geodesic reward shaping builds, averaged over the scenes and starts
    // of 200 seeds: a new maze and its index, placement, the free-space grid and the shaping's
    // first potential.
    let mut shaped = ronap_core::SimConfig::default();
    shaped.reward.shaping = ronap_core::config::Shaping::Geodesic;
    let shaped = shaped.validate().expect("valid");
    let mut next = 0u64;
    group.bench_function("shaped_reset_over_seeds", |b| {
        b.iter(|| {
            let seed = next % 200;
            next += 1;
            let world = Arc::new(ronap_core::World::maze(shaped.clone(), seed));
            let episode = world.episode(seed).expect("placement");
            let shaper = ronap_core::run::Shaper::start(world, &episode);
            shaper.map(|s| s.potential())
        })
    });
    let field = ronap_core::plan::DistanceField::new(world.scene(), grid, goal, 5.0, 1.0);
    let path = field
        .path(world.scene(), grid, start, 5.0)
        .expect("connected");
    group.bench_function("smooth", |b| {
        b.iter(|| ronap_core::plan::smooth(world.scene(), &path, 5.0))
    });
    group.finish();
    // A shaping potential at each step: the geodesic distance at points 1.5 px apart along the
    // path from start to goal and 20 px beside it, from a whole field and from a lazy one that
    // has already searched what these points need, so only its look-up is timed (per point).
    let mut points = Vec::new();
    for pair in path.windows(2) {
        let (a, b) = (pair[0], pair[1]);
        let n = ((b - a).norm() / 1.5).ceil().max(1.0) as usize;
        for k in 0..n {
            let p = a + (b - a) * (k as f64 / n as f64);
            points.extend([p, p + ronap_core::Vector::new(0.0, 20.0)]);
        }
    }
    let mut group = c.benchmark_group("potential");
    group.throughput(Throughput::Elements(points.len() as u64));
    group.bench_function("whole_field", |b| {
        b.iter(|| {
            points
                .iter()
                .map(|&p| field.distance_at(p))
                .collect::<Vec<_>>()
        })
    });
    let mut lazy = ronap_core::plan::LazyField::new(world.scene(), grid, goal, start, 5.0, 1.0);
    lazy.distance_at(grid, start);
    group.bench_function("lazy_field", |b| {
        b.iter(|| {
            points
                .iter()
                .map(|&p| lazy.distance_at(grid, p))
                .collect::<Vec<_>>()
        })
    });
    // A shaped episode's field, whole and lazy: built at its start, then asked at each pose of a
    // robot driven at random for up to 2000 steps (the default limit), as a learner starts out
    // (per pose).
    let poses = {
        let mut episode = world.episode(3).expect("placement");
        let mut poses = vec![episode.pose().position()];
        let mut x = 0x9E37_79B9_7F4A_7C15u64;
        while !episode.status().is_done() && poses.len() < 2000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            episode.step(Action::from(
                [
                    DiscreteAction::Left,
                    DiscreteAction::Ahead,
                    DiscreteAction::Right,
                ][(x % 3) as usize],
            ));
            poses.push(episode.pose().position());
        }
        poses
    };
    group.throughput(Throughput::Elements(poses.len() as u64));
    group.bench_function("random_walk_whole_field", |b| {
        b.iter(|| {
            let field = ronap_core::plan::DistanceField::new(world.scene(), grid, goal, 5.0, 1.0);
            poses
                .iter()
                .map(|&p| field.distance_at(p))
                .collect::<Vec<_>>()
        })
    });
    group.bench_function("random_walk_lazy_field", |b| {
        b.iter(|| {
            let mut field =
                ronap_core::plan::LazyField::new(world.scene(), grid, goal, start, 5.0, 1.0);
            poses
                .iter()
                .map(|&p| field.distance_at(grid, p))
                .collect::<Vec<_>>()
        })
    });
    group.finish();
}

/// What `ronap collect --expert geodesic` spends on its rows: the expert's label of a state, which
/// plans afresh from it (the field's path, then its first 80 points smoothed). An episode's first
/// 100 rows (fewer if the expert driving reaches the goal first) each way the robot moves on (the
/// expert driving, or re-posed after each action), the episode's whole field included, over the
/// seeds of 16 episodes in turn.
fn label(c: &mut Criterion) {
    use ronap_core::collect::{collect_episode, Posing};
    let config = ValidConfig::default();
    let evaluator = ronap_core::eval::Evaluator::new(config, ronap_core::Scenes::MazePerSeed);
    let mut group = c.benchmark_group("label");
    for (name, posing) in [("drive_100", Posing::Drive), ("repose_100", Posing::Repose)] {
        let mut k = 0u64;
        group.bench_function(name, |b| {
            b.iter(|| {
                k += 1;
                collect_episode(&evaluator, 3_000_000 + k % 16, 100, posing, None)
            })
        });
    }
    group.finish();
}

// The macro defines an undocumented `benches` function.
#[allow(missing_docs)]
mod group {
    use super::*;
    criterion_group!(benches, step, scan, movers, setup, mlp, batch, label);
}
use group::benches;
criterion_main!(benches);

/// The moving-obstacle step alone: 100 `random_walk` discs moved once, and a robot step swept
/// against them.
fn movers(c: &mut Criterion) {
    let crowd = crowd_config().validate().expect("valid");
    let scene = maze_scene(&crowd, 0);
    let e = Episode::new(&crowd, Arc::new(scene.clone()), 0).expect("places");
    let mut movers = e.movers().expect("a crowd").clone();
    let robot = e.start().position();
    let mut step = 0;
    let mut group = c.benchmark_group("movers");
    group.bench_function("advance_100", |b| {
        b.iter(|| {
            step += 1;
            movers.advance(step, &scene, robot)
        })
    });
    let m2 = movers.clone();
    group.bench_function("sweep_clear_100", |b| {
        b.iter(|| {
            m2.sweep_clear(
                black_box(robot),
                black_box(robot + ronap_core::Vector::new(5.0, 0.0)),
                5.0,
            )
        })
    });
    group.finish();
}

/// The shipped behaviour-cloning network (18-64-128-64-32-8-3) on one observation, as the policy
/// runs it: without allocation (`mlp/forward_into`), and through the allocating `forward`.
fn mlp(c: &mut Criterion) {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../policies/bc.safetensors");
    let net = ronap_core::policy::Mlp::load(std::path::Path::new(path)).expect("shipped");
    let config = ValidConfig::default();
    let episode = Episode::new(&config, Arc::new(maze_scene(&config, 0)), 0).expect("places");
    let observation = episode.observation().to_vec();
    let mut scratch = ronap_core::policy::Scratch::default();
    let mut group = c.benchmark_group("mlp");
    group.throughput(Throughput::Elements(1));
    group.bench_function("forward_into", |b| {
        b.iter(|| net.action_into(black_box(&observation), &mut scratch))
    });
    group.bench_function("forward", |b| {
        b.iter(|| net.forward(black_box(&observation)))
    });
    // A whole MLP-policy step: the network chooses from the episode's observation and the
    // episode steps (long episodes, as in `step/default`, so the figure is the step).
    let mut sim = ronap_core::SimConfig::default();
    sim.episode.max_steps = 1_000_000;
    let config = sim.validate().expect("valid");
    let scene = Arc::new(maze_scene(&config, 0));
    let mut seed = 0;
    let mut episode = Episode::new(&config, scene.clone(), seed).expect("default scene");
    // Sixteen observations at once (a worker stepping sixteen episodes side by side), per row.
    let rows: Vec<f32> = (0..16).flat_map(|_| observation.iter().copied()).collect();
    group.throughput(Throughput::Elements(16));
    group.bench_function("forward_rows_16", |b| {
        b.iter(|| {
            net.forward_rows_into(black_box(&rows), 16, &mut scratch)
                .len()
        })
    });
    group.throughput(Throughput::Elements(1));
    group.bench_function("policy_step", |b| {
        b.iter(|| {
            let action = net.action_into(episode.observation(), &mut scratch);
            if episode.step(action).status.is_done() {
                seed += 1;
                episode = Episode::new(&config, scene.clone(), seed).expect("default scene");
            }
        })
    });
    // The same steps as the evaluator takes them for a network's policy: sixteen episodes side
    // by side on one thread, the policy deciding for all sixteen at once (`Policy::act_lanes`),
    // then each episode stepping; per episode step.
    let lanes = ronap_core::policy::SIDE_BY_SIDE;
    let mut policy = ronap_core::policy::MlpPolicy::new(Arc::new(net.clone()));
    let world = ronap_core::World::maze(config.clone(), 0);
    let mut episodes: Vec<Episode> = (0..lanes as u64)
        .map(|s| Episode::new(&config, scene.clone(), s).expect("default scene"))
        .collect();
    for (lane, e) in episodes.iter().enumerate() {
        policy.reset_lane(lane, &world, e).expect("fits");
    }
    let mut decisions = Vec::with_capacity(lanes);
    let mut next_seed = lanes as u64;
    group.throughput(Throughput::Elements(lanes as u64));
    group.bench_function("policy_step_side_by_side", |b| {
        b.iter(|| {
            decisions.clear();
            let asked: Vec<(usize, &Episode)> = episodes.iter().enumerate().collect();
            policy.act_lanes(&asked, &mut decisions).expect("decides");
            for (lane, (e, d)) in episodes.iter_mut().zip(&decisions).enumerate() {
                let Decision::Act(action) = d else {
                    unreachable!("an MLP never gives up")
                };
                if e.step(*action).status.is_done() {
                    next_seed += 1;
                    *e = Episode::new(&config, scene.clone(), next_seed).expect("default scene");
                    policy.reset_lane(lane, &world, e).expect("fits");
                }
            }
        })
    });
    group.finish();
}

/// `VecNavEnv`'s engine without Python: 1024 environments of the default scene (each its own maze)
/// stepped side by side with a fixed action pattern, on one thread and on every core. The figure
/// is per step of all 1024; divide 1024 by it for env-steps/s.
fn batch(c: &mut Criterion) {
    use ronap_core::run::Batch;
    use ronap_core::sim::{Scenes, Worlds};
    let mut group = c.benchmark_group("batch");
    group.throughput(Throughput::Elements(1024));
    for (name, threads) in [("step_1024_one_thread", 1), ("step_1024_all_threads", 0)] {
        let worlds = Worlds::new(ValidConfig::default(), Scenes::MazePerSeed);
        let mut batch = Batch::new(worlds, common::batch_options(1024, threads)).expect("a pool");
        batch.reset(0).expect("places");
        let actions = common::pattern_actions(1024);
        let mut k = 0;
        group.bench_function(name, |b| {
            b.iter(|| {
                k += 1;
                batch
                    .step_actions(&actions[k % actions.len()])
                    .expect("steps")
            })
        });
    }
    group.finish();
}
