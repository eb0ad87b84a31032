//! Each model's step against its closed form, its limits, and the trait's use by a kind of
//! robot of one's own.

use super::*;
use crate::config::KinematicsKind;
use crate::sim::robot::{DiscreteAction, Robot};
use rand::{Rng as _, SeedableRng};

/// The unicycle behind the trait, as a kind of robot of one's own would be.
#[derive(Debug)]
struct Wrapped(Unicycle);

impl Kinematics for Wrapped {
    fn command(&self, velocity: Velocity, action: Action) -> (Velocity, f64) {
        self.0.command(velocity, action)
    }

    fn clamp(&self, velocity: Velocity) -> Velocity {
        self.0.clamp(velocity)
    }

    fn remembered(&self, action: Action) -> [f32; ACTION_MEMORY] {
        self.0.remembered(action)
    }
}

fn robot(kind: KinematicsKind, edit: impl FnOnce(&mut RobotConfig)) -> (RobotConfig, Robot) {
    let mut config = RobotConfig {
        kinematics: kind,
        ..RobotConfig::default()
    };
    edit(&mut config);
    config.validate().expect("valid robot");
    let robot = Robot::new(&config);
    (config, robot)
}

fn close(a: Pose, b: Pose, tol: f64) -> bool {
    let dz = (crate::geometry::wrap_deg(a.z_deg - b.z_deg + 180.0) - 180.0).abs();
    (a.x - b.x).abs() < tol && (a.y - b.y).abs() < tol && dz < tol
}

#[test]
fn kinematics_behind_the_trait_move_a_robot_as_the_built_in_does() {
    let config = RobotConfig::default();
    let built_in = Robot::new(&config);
    let own = Robot::with_kinematics(config.radius_px, Arc::new(Wrapped(Unicycle::new(&config))));
    let config_all = crate::SimConfig::default().validate().expect("valid");
    let scene = crate::sim::world::maze_scene(&config_all, 3);
    let actions = [
        Action::from(DiscreteAction::Left),
        DiscreteAction::Ahead.into(),
        DiscreteAction::Right.into(),
        Action::Continuous {
            v: 4.0,
            w_deg: -9.0,
        },
        Action::Continuous {
            v: 50.0,
            w_deg: 90.0,
        },
        Action::Continuous {
            v: -2.0,
            w_deg: 0.0,
        },
    ];
    let mut blocked = 0;
    for i in 0..400 {
        let pose = Pose::new(
            5.0 + f64::from(i * 37 % 990),
            5.0 + f64::from(i * 91 % 990),
            f64::from(i * 13),
        );
        for &a in &actions {
            let (m, n) = (built_in.motion(pose, a), own.motion(pose, a));
            assert_eq!(m, n);
            let clear = built_in.motion_clear(&scene, pose, &m);
            assert_eq!(clear, own.motion_clear(&scene, pose, &n));
            blocked += usize::from(!clear);
            assert_eq!(
                built_in.kinematics().remembered(a),
                own.kinematics().remembered(a)
            );
        }
    }
    // Some of those moves run into walls, so both answers of the check are compared.
    assert!(blocked > 0);
}

/// A velocity held for a step follows the closed-form arc: centre at distance `v / w` to the
/// left of the course, every model alike.
#[test]
fn every_model_follows_the_closed_form_arc_and_line() {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
    for _ in 0..2000 {
        let pose = Pose::new(
            rng.random_range(-500.0..500.0),
            rng.random_range(-500.0..500.0),
            rng.random_range(0.0..360.0),
        );
        let vel = Velocity {
            v: rng.random_range(-6.0..6.0),
            vy: if rng.random_bool(0.5) {
                rng.random_range(-6.0..6.0)
            } else {
                0.0
            },
            w_deg: if rng.random_bool(0.2) {
                0.0
            } else {
                rng.random_range(-40.0..40.0)
            },
            steer_deg: 0.0,
        };
        let end = travel(pose, vel, None);
        // Integrate the body-frame velocity in a million small steps: the closed form agrees.
        let (z0, w) = (pose.z_deg.to_radians(), vel.w_deg.to_radians());
        let expected = if w == 0.0 {
            Pose::new(
                pose.x + vel.v * z0.cos() - vel.vy * z0.sin(),
                pose.y + vel.v * z0.sin() + vel.vy * z0.cos(),
                pose.z_deg,
            )
        } else {
            // x(t) = x0 + int_0^1 R(z0 + w t) (v, vy) dt.
            let (s0, c0, s1, c1) = (z0.sin(), z0.cos(), (z0 + w).sin(), (z0 + w).cos());
            let (int_c, int_s) = ((s1 - s0) / w, -(c1 - c0) / w);
            Pose::new(
                pose.x + vel.v * int_c - vel.vy * int_s,
                pose.y + vel.v * int_s + vel.vy * int_c,
                pose.z_deg + vel.w_deg,
            )
        };
        assert!(
            close(end, expected, 1e-9),
            "{vel:?} from {pose:?}: {end:?} != {expected:?}"
        );
    }
}

#[test]
fn a_diff_drive_speeds_up_and_turns_within_its_limits() {
    let (_, r) = robot(KinematicsKind::DiffDrive, |c| {
        c.accel_max_px = Some(0.5);
        c.alpha_max_deg = Some(3.0);
        c.wheel_base_px = Some(8.0);
    });
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
    let mut vel = Velocity::default();
    for _ in 0..5000 {
        let action = if rng.random_bool(0.3) {
            Action::from(DiscreteAction::ALL[rng.random_range(0..3)])
        } else {
            Action::Continuous {
                v: rng.random_range(-9.0..9.0),
                w_deg: rng.random_range(-30.0..30.0),
            }
        };
        let (next, frac) = r.command(vel, action);
        assert!((next.v - vel.v).abs() <= 0.5 + 1e-12, "{vel:?} -> {next:?}");
        assert!((next.w_deg - vel.w_deg).abs() <= 3.0 + 1e-12);
        let wheel = next.v.abs() + next.w_deg.to_radians().abs() * 4.0;
        assert!(wheel <= 5.0 + 1e-9, "a wheel at {wheel}");
        assert!((0.0..=1.0).contains(&frac));
        assert_eq!((next.vy, next.steer_deg), (0.0, 0.0));
        vel = next;
    }
    // From rest, AHEAD reaches full speed in ten steps of 0.5.
    let mut vel = Velocity::default();
    for k in 1..=12 {
        vel = r.command(vel, DiscreteAction::Ahead.into()).0;
        assert!((vel.v - (0.5 * f64::from(k)).min(5.0)).abs() < 1e-12);
    }
}

#[test]
fn an_omni_base_moves_sideways_within_its_limits() {
    let (_, r) = robot(KinematicsKind::Omni, |c| {
        c.accel_max_px = Some(1.0);
        c.alpha_max_deg = Some(5.0);
        c.max_lateral_speed_px = Some(3.0);
    });
    let pose = Pose::new(100.0, 100.0, 90.0);
    let mut vel = Velocity::default();
    let left = Action::Omni {
        vx: 0.0,
        vy: 3.0,
        w_deg: 0.0,
    };
    let mut p = pose;
    for _ in 0..10 {
        let m = r.motion_from(p, vel, None, left);
        assert!((m.velocity.vy - vel.vy).abs() <= 1.0 + 1e-12);
        vel = m.velocity;
        p = m.end;
    }
    // Facing +y, left is -x: 1 + 2 + 3 * 8 px.
    assert!((p.x - (100.0 - 27.0)).abs() < 1e-9 && (p.y - 100.0).abs() < 1e-9);
    assert_eq!(p.z_deg, 90.0);
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(9);
    for _ in 0..3000 {
        let a = Action::Omni {
            vx: rng.random_range(-9.0..9.0),
            vy: rng.random_range(-9.0..9.0),
            w_deg: rng.random_range(-30.0..30.0),
        };
        let (next, _) = r.command(vel, a);
        assert!(next.v.abs() <= 5.0 && next.vy.abs() <= 3.0 && next.w_deg.abs() <= 15.0);
        assert!((next.v - vel.v).hypot(next.vy - vel.vy) <= 1.0 + 1e-12);
        assert!((next.w_deg - vel.w_deg).abs() <= 5.0 + 1e-12);
        vel = next;
    }
}

#[test]
fn a_car_turns_on_the_bicycle_models_arc_and_never_on_the_spot() {
    let (_, r) = robot(KinematicsKind::Ackermann, |c| {
        c.wheel_base_px = Some(14.0);
        c.steer_max_deg = Some(35.0);
        c.steer_rate_max_deg = Some(10.0);
        c.accel_max_px = Some(1.0);
    });
    let mut vel = Velocity::default();
    let mut pose = Pose::new(0.0, 0.0, 0.0);
    let turn = Action::Steer {
        v: 4.0,
        steer_deg: 30.0,
    };
    for k in 1..=8 {
        let m = r.motion_from(pose, vel, None, turn);
        let v = (f64::from(k)).min(4.0);
        let steer = (10.0 * f64::from(k)).min(30.0);
        assert!((m.velocity.v - v).abs() < 1e-12);
        assert!((m.velocity.steer_deg - steer).abs() < 1e-12);
        let w = v * steer.to_radians().tan() / 14.0;
        assert!((m.velocity.w_deg - w.to_degrees()).abs() < 1e-9);
        vel = m.velocity;
        pose = m.end;
    }
    // Turning on the spot is not a car's: a (0, w) command moves nothing and turns nothing.
    let standing = r.motion(
        Pose::new(0.0, 0.0, 0.0),
        Action::Continuous {
            v: 0.0,
            w_deg: 15.0,
        },
    );
    assert_eq!(standing.end, Pose::new(0.0, 0.0, 0.0));
    // LEFT drives ahead at full lock (the rate limit aside).
    let (left, _) = r.command(
        Velocity {
            steer_deg: 35.0,
            v: 5.0,
            ..Velocity::default()
        },
        DiscreteAction::Left.into(),
    );
    assert_eq!((left.v, left.steer_deg), (5.0, 35.0));
    // A (v, w) command steers to its curvature.
    let (_, r) = robot(KinematicsKind::Ackermann, |c| c.wheel_base_px = Some(14.0));
    let (vel, _) = r.command(
        Velocity::default(),
        Action::Continuous { v: 4.0, w_deg: 5.0 },
    );
    assert!((vel.w_deg - 5.0).abs() < 1e-9, "{vel:?}");
}

#[test]
fn a_model_refuses_another_models_fields_and_a_car_needs_its_wheel_base() {
    let mut c = RobotConfig {
        kinematics: KinematicsKind::DiffDrive,
        steer_max_deg: Some(20.0),
        ..RobotConfig::default()
    };
    let e = c.validate().unwrap_err().to_string();
    assert!(
        e.contains("robot.steer_max_deg") && e.contains("ackermann"),
        "{e}"
    );
    c.steer_max_deg = None;
    c.accel_max_px = Some(-1.0);
    let e = c.validate().unwrap_err().to_string();
    assert!(e.contains("robot.accel_max_px") && e.contains("-1"), "{e}");
    c.kinematics = KinematicsKind::Ackermann;
    c.accel_max_px = None;
    let e = c.validate().unwrap_err().to_string();
    assert!(e.contains("robot.wheel_base_px"), "{e}");
}

#[test]
fn continuous_actions_take_each_models_size() {
    let mut c = RobotConfig::default();
    assert_eq!(
        continuous_action(&c, &[1.0, 2.0]),
        Some(Action::Continuous { v: 1.0, w_deg: 2.0 })
    );
    assert_eq!(continuous_action(&c, &[1.0, 2.0, 3.0]), None);
    c.kinematics = KinematicsKind::Omni;
    assert_eq!(c.action_scale(), vec![5.0, 5.0, 15.0]);
    assert!(continuous_action(&c, &[1.0, 2.0, 3.0]).is_some());
    assert_eq!(continuous_action(&c, &[1.0, f64::NAN, 3.0]), None);
    c.kinematics = KinematicsKind::Ackermann;
    assert_eq!(c.action_scale(), vec![5.0, 30.0]);
    assert_eq!(
        continuous_action(&c, &[1.0, 2.0]),
        Some(Action::Steer {
            v: 1.0,
            steer_deg: 2.0
        })
    );
    assert!(accepts(
        KinematicsKind::Ackermann,
        Action::Continuous { v: 1.0, w_deg: 0.0 }
    ));
    assert!(!accepts(
        KinematicsKind::DiffDrive,
        Action::Steer {
            v: 1.0,
            steer_deg: 0.0
        }
    ));
}

/// Whether the convex polygon `corners` and the box overlap (separating axes: the box's two
/// and the polygon's edge normals).
fn overlaps(corners: &[Point], b: &crate::geometry::Aabb) -> bool {
    let box_corners = [
        b.min,
        Point::new(b.max.x, b.min.y),
        b.max,
        Point::new(b.min.x, b.max.y),
    ];
    let mut axes = vec![Vector::new(1.0, 0.0), Vector::new(0.0, 1.0)];
    for i in 0..corners.len() {
        let e = corners[(i + 1) % corners.len()] - corners[i];
        axes.push(Vector::new(-e.y, e.x));
    }
    axes.iter().all(|a| {
        let project = |ps: &[Point]| {
            ps.iter()
                .map(|p| p.coords.dot(a))
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
                    (lo.min(x), hi.max(x))
                })
        };
        let (p, q) = (project(corners), project(&box_corners));
        p.0 < q.1 && q.0 < p.1
    })
}

/// A rectangle or convex polygon robot of every kinematics, driven by random commands through
/// random mazes, never ends a step overlapping a wall; and it does get close to them (the check
/// is not vacuous).
#[test]
fn a_rectangle_or_polygon_never_ends_a_step_overlapping_an_obstacle() {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
    let mut steps = 0;
    let mut blocked = 0;
    for (i, kind) in KinematicsKind::ALL.into_iter().cycle().take(40).enumerate() {
        let mut config = crate::SimConfig::default();
        config.robot.kinematics = kind;
        if i % 2 == 0 {
            config.robot.shape = crate::config::Shape::Rectangle;
            config.robot.length_px = Some(rng.random_range(6.0..24.0));
            config.robot.width_px = Some(rng.random_range(4.0..12.0));
            config.robot.offset_px = Some(rng.random_range(-4.0..4.0));
        } else {
            // A convex polygon of 3 to 7 corners round the robot's position, uneven radii.
            config.robot.shape = crate::config::Shape::Polygon;
            let n = rng.random_range(3..8);
            let turn = rng.random_range(0.0..360.0);
            config.robot.vertices = (0..n)
                .map(|k| {
                    let a = (turn + 360.0 * f64::from(k) / f64::from(n)).to_radians();
                    let r = rng.random_range(4.0..12.0);
                    [r * a.cos(), r * a.sin()]
                })
                .collect();
            if !crate::config::is_convex_polygon(&config.robot.vertices) {
                continue;
            }
        }
        config.robot.max_linear_speed_px = 8.0;
        config.robot.max_angular_speed_deg = 45.0;
        if kind == KinematicsKind::Ackermann {
            config.robot.wheel_base_px = Some(10.0);
        }
        config.maze.loops = 0.5;
        let valid = config.validate().expect("valid");
        let scene = crate::sim::world::maze_scene(&valid, i as u64);
        let world = crate::sim::world::World::new(valid.clone(), std::sync::Arc::new(scene));
        let Ok(mut episode) = world.episode(i as u64) else {
            continue;
        };
        let robot = valid.robot.clone();
        for _ in 0..400 {
            let a = match rng.random_range(0..3) {
                0 => Action::from(DiscreteAction::ALL[rng.random_range(0..3)]),
                1 => Action::Continuous {
                    v: rng.random_range(-8.0..8.0),
                    w_deg: rng.random_range(-45.0..45.0),
                },
                _ => continuous_action(
                    &robot,
                    &robot
                        .action_scale()
                        .iter()
                        .map(|s| s * rng.random_range(-1.0..1.0))
                        .collect::<Vec<_>>(),
                )
                .expect("an action"),
            };
            let r = episode.step(a);
            let (collided, pose, done) = (r.collided, r.pose, r.status.is_done());
            blocked += usize::from(collided);
            steps += 1;
            let corners = Robot::corners(&robot, pose).expect("a footprint");
            for b in episode.scene().boxes() {
                assert!(
                    !overlaps(&corners, b),
                    "{kind:?} at {pose:?} overlaps {b:?}"
                );
            }
            if done {
                break;
            }
        }
    }
    assert!(
        steps > 5000 && blocked > 100,
        "{steps} steps, {blocked} blocked"
    );
}
