//! Scenes beyond a still maze: static discs and polygons, moving and appearing obstacles, and
//! warehouses, held to parry2d and to the invariants of docs/model.md "Moving obstacles".

// Test helpers may panic on setup failures: that is a failed test, as intended.
#![allow(clippy::unwrap_used)]

use parry2d_f64::math::{Isometry, Point as PPoint, Vector as PVector};
use parry2d_f64::query::{Ray, RayCast};
use parry2d_f64::shape::{Ball, Compound, ConvexPolygon, Cuboid, SharedShape};
use proptest::prelude::*;
use ronap_core::config::{LaserConfig, MotionKind, MovingConfig, MovingShape, ObstacleConfig};
use ronap_core::geometry::unit;
use ronap_core::sim::{maze_scene, Body};
use ronap_core::{Action, Episode, Point, Scene, SimConfig, ValidConfig};
use std::sync::Arc;

fn crowd(count: u32, motion: MotionKind, shape: MovingShape, speed: f64) -> MovingConfig {
    MovingConfig {
        count,
        motion,
        shape,
        speed_px: speed,
        ..MovingConfig::default()
    }
}

fn shapes() -> Vec<ObstacleConfig> {
    vec![
        ObstacleConfig::Disc {
            center: [450.0, 450.0],
            radius_px: 15.0,
        },
        ObstacleConfig::Polygon {
            points: vec![
                [620.0, 300.0],
                [660.0, 320.0],
                [650.0, 345.0],
                [610.0, 320.0],
            ],
        },
        ObstacleConfig::Box {
            min: [250.0, 700.0],
            max: [270.0, 740.0],
        },
    ]
}

/// Every obstacle of an episode, still and moving, as one parry2d compound.
fn parry_of(episode: &Episode) -> Compound {
    let mut parts: Vec<(Isometry<f64>, SharedShape)> = Vec::new();
    for b in episode.scene().boxes() {
        let h = b.extents() / 2.0;
        let c = b.min + h;
        parts.push((
            Isometry::translation(c.x, c.y),
            SharedShape::new(Cuboid::new(PVector::new(h.x, h.y))),
        ));
    }
    for s in episode.scene().shapes() {
        match s.as_disc() {
            Some((c, r)) => parts.push((
                Isometry::translation(c.x, c.y),
                SharedShape::new(Ball::new(r)),
            )),
            None => {
                let pts: Vec<_> = s.corners().iter().map(|p| PPoint::new(p.x, p.y)).collect();
                parts.push((
                    Isometry::identity(),
                    SharedShape::new(ConvexPolygon::from_convex_hull(&pts).unwrap()),
                ));
            }
        }
    }
    for m in episode.movers().into_iter().flat_map(|m| m.items()) {
        if !m.present() {
            continue;
        }
        let c = m.position();
        let shape = match m.body() {
            Body::Disc(r) => SharedShape::new(Ball::new(r)),
            Body::Box(h) => SharedShape::new(Cuboid::new(PVector::new(h.x, h.y))),
        };
        parts.push((Isometry::translation(c.x, c.y), shape));
    }
    Compound::new(parts)
}

fn config_with(moving: Vec<MovingConfig>, obstacles: Vec<ObstacleConfig>) -> ValidConfig {
    SimConfig {
        moving,
        obstacles,
        ..SimConfig::default()
    }
    .validate()
    .unwrap()
}

fn episode(config: &ValidConfig, seed: u64) -> Episode {
    let scene = Arc::new(maze_scene(config, seed));
    Episode::new(config, scene, seed).unwrap()
}

/// Scans of episodes among discs, a polygon, an added box and moving discs and boxes, with `laser`,
/// each reading against parry2d's ray cast into all of them; how many readings were compared.
fn laser_against_parry2d(laser: LaserConfig, seeds: u64, steps: usize) -> usize {
    let range = laser.range_px;
    let config = SimConfig {
        moving: vec![
            crowd(60, MotionKind::RandomWalk, MovingShape::Disc, 3.0),
            crowd(20, MotionKind::Linear, MovingShape::Box, 4.0),
        ],
        obstacles: shapes(),
        laser,
        ..SimConfig::default()
    }
    .validate()
    .unwrap();
    let mut compared = 0;
    for seed in 0..seeds {
        let mut e = episode(&config, seed);
        for step in 0..steps {
            let compound = parry_of(&e);
            let p = e.pose().position();
            for (i, &d) in e.readings().iter().enumerate() {
                let dir = unit(e.laser().beam_angle_deg(i, e.pose().z_deg));
                let ray = Ray::new(PPoint::new(p.x, p.y), PVector::new(dir.x, dir.y));
                let expected = compound
                    .cast_ray(&Isometry::identity(), &ray, range, true)
                    .unwrap_or(range);
                assert!(
                    (d - expected).abs() < 1e-4,
                    "{range} px, seed {seed} step {step} beam {i}: {d} vs parry {expected}"
                );
                compared += 1;
            }
            e.step(Action::from(
                ronap_core::DiscreteAction::from_index(step % 3).unwrap(),
            ));
        }
    }
    compared
}

#[test]
fn the_laser_sees_discs_polygons_and_moving_obstacles_as_parry2d_does() {
    let compared = laser_against_parry2d(LaserConfig::default(), 10, 150);
    assert_eq!(compared, 10 * 150 * 17);
}

#[test]
fn a_long_laser_of_many_beams_sees_them_as_parry2d_does() {
    // The added box takes the maze off its own cells onto the uniform ray grid.
    let laser = LaserConfig {
        beams: 720,
        fov_deg: 360.0,
        range_px: 1000.0,
        ..LaserConfig::default()
    };
    assert_eq!(laser_against_parry2d(laser, 3, 10), 3 * 10 * 720);
}

#[test]
fn moving_obstacles_leave_the_maze_start_and_goal_unchanged() {
    let still = ValidConfig::default();
    let moving = config_with(
        vec![crowd(30, MotionKind::RandomWalk, MovingShape::Disc, 2.0)],
        vec![],
    );
    for seed in 0..30 {
        let a = episode(&still, seed);
        let b = episode(&moving, seed);
        assert_eq!(a.scene().boxes(), b.scene().boxes());
        assert_eq!((a.start(), a.goal()), (b.start(), b.goal()), "seed {seed}");
    }
}

#[test]
fn a_fast_disc_crossing_the_path_still_collides() {
    // A disc crosses the line y = 500 at 1000 px per step, going up along x = 140, in a scene tall
    // enough for the whole jump.
    let run = |robot_x: f64| {
        let mut c = SimConfig::default();
        c.episode.start = Some([robot_x, 500.0, 0.0]);
        c.episode.goal = Some([900.0, 500.0]);
        c.moving = vec![MovingConfig {
            start: Some([140.0, 20.0]),
            motion: MotionKind::Linear,
            direction_deg: Some(90.0),
            speed_px: 1000.0,
            radius_px: 8.0,
            ..MovingConfig::default()
        }];
        let config = c.validate().unwrap();
        let scene = Arc::new(Scene::from_boxes(1000.0, 3000.0, vec![], 50.0));
        let mut e = Episode::new(&config, scene, 0).unwrap();
        let collided = e.step(ronap_core::DiscreteAction::Left).collided;
        let at = e.movers().unwrap().items().next().unwrap().position();
        (collided, at, e.dynamic_metrics().unwrap().collisions)
    };
    // 40 px to the side of its track: it passes.
    let (collided, at, count) = run(100.0);
    assert!(!collided && count == 0);
    assert!((at - Point::new(140.0, 1020.0)).norm() < 1e-9, "{at:?}");
    // On its track: contact, charged to the robot, and the disc stays where it was.
    assert_eq!(run(140.0), (true, Point::new(140.0, 20.0), 1));
    // Just clear of it (8 + 5 px): passes; a hair closer: contact.
    assert!(!run(140.0 - 13.0).0);
    assert!(run(140.0 - 12.9).0);
}

#[test]
fn head_on_robot_and_obstacle_never_pass_through_each_other() {
    for speed in [1.0, 3.0, 7.0, 40.0, 333.0] {
        let mut c = SimConfig::default();
        c.episode.start = Some([100.0, 500.0, 0.0]);
        c.episode.goal = Some([900.0, 500.0]);
        c.robot.move_speed_px = 5.0;
        c.moving = vec![MovingConfig {
            start: Some([600.0, 500.0]),
            motion: MotionKind::Linear,
            direction_deg: Some(180.0),
            speed_px: speed,
            ..MovingConfig::default()
        }];
        let config = c.validate().unwrap();
        let scene = Arc::new(Scene::from_boxes(1000.0, 1000.0, vec![], 50.0));
        let mut e = Episode::new(&config, scene, 0).unwrap();
        for _ in 0..300 {
            e.step(ronap_core::DiscreteAction::Ahead);
            let m = e.movers().unwrap().items().next().unwrap();
            assert!(
                m.position().x > e.pose().x,
                "speed {speed}: the obstacle at {:?} got past the robot at {:?}",
                m.position(),
                e.pose()
            );
            assert!(m.body().gap(m.position(), e.pose().position(), 5.0) >= 0.0);
        }
        assert!(e.dynamic_metrics().unwrap().collisions > 0);
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(40))]

    /// Whatever the robot does, it never ends a step overlapping an obstacle of any shape, still
    /// or moving; an obstacle never appears within `min_robot_distance_px` of it.
    #[test]
    fn no_step_ends_in_an_overlap(seed in 0u64..10_000, speed in 0.5f64..60.0, actions in proptest::collection::vec(0usize..3, 200)) {
        let mut moving = vec![
            crowd(25, MotionKind::RandomWalk, MovingShape::Disc, speed),
            crowd(8, MotionKind::Linear, MovingShape::Box, speed),
            MovingConfig { count: 6, motion: MotionKind::Appear, then: MotionKind::RandomWalk, from_step: 1, to_step: 150, min_robot_distance_px: 40.0, ..MovingConfig::default() },
        ];
        moving[0].radius_px = 4.0 + speed / 10.0;
        let config = config_with(moving, shapes());
        let scene = Arc::new(maze_scene(&config, seed));
        let Ok(mut e) = Episode::new(&config, scene, seed) else { return Ok(()) };
        let r = config.robot.radius_px;
        let mut present: Vec<bool> = e.movers().unwrap().items().map(|m| m.present()).collect();
        for a in actions {
            e.step(ronap_core::DiscreteAction::from_index(a).unwrap());
            let p = e.pose().position();
            prop_assert!(e.scene().disc_clear(p, r), "robot overlaps the still scene at {:?}", p);
            for (i, m) in e.movers().unwrap().items().enumerate() {
                if !m.present() { continue; }
                let gap = m.body().gap(m.position(), p, r);
                prop_assert!(gap >= -1e-9, "obstacle {} overlaps the robot: gap {}", i, gap);
                let in_scene = match m.body() {
                    Body::Disc(r) => e.scene().disc_clear(m.position(), r),
                    Body::Box(_) => e.scene().box_clear(m.body().aabb(m.position())),
                };
                prop_assert!(in_scene, "obstacle {} overlaps the still scene at {:?}", i, m.position());
                if !present[i] {
                    prop_assert!(gap >= 40.0 - 5.0 - 1e-9, "obstacle {} appeared {} px from the robot", i, gap);
                    present[i] = true;
                }
            }
        }
    }
}
