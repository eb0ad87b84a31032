//! Criterion benchmarks of a step of each kinematic model on the default scene (10 x 10 maze,
//! 17 beams), driven by continuous `(v, w)` commands that sweep arcs (the unicycle's slowest
//! case), so the models compare on the same motion.
//!
//! `cargo bench -p ronap-core --bench kinematics`. Target: a `diff_drive` or `ackermann` step
//! within 20% of the `unicycle` step; the rectangle footprint's step is shown beside them.

use common::bench_steps;
use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use ronap_core::config::{KinematicsKind, Shape};
use ronap_core::{Action, SimConfig};

mod common;

/// Commands in turn: straight, arcs either way, a turn on the spot.
const COMMANDS: [(f64, f64); 6] = [
    (5.0, 0.0),
    (4.0, 10.0),
    (5.0, 0.0),
    (4.0, -10.0),
    (0.0, 15.0),
    (3.0, 5.0),
];

fn model(kind: KinematicsKind, rectangle: bool) -> SimConfig {
    let mut c = SimConfig::default();
    c.robot.kinematics = kind;
    c.episode.max_steps = 1_000_000;
    match kind {
        KinematicsKind::DiffDrive => {
            c.robot.accel_max_px = Some(1.0);
            c.robot.alpha_max_deg = Some(5.0);
            c.robot.wheel_base_px = Some(8.0);
        }
        KinematicsKind::Ackermann => {
            c.robot.wheel_base_px = Some(10.0);
            c.robot.steer_rate_max_deg = Some(15.0);
        }
        _ => {}
    }
    if rectangle {
        c.robot.shape = Shape::Rectangle;
        c.robot.length_px = Some(12.0);
        c.robot.width_px = Some(8.0);
    }
    c
}

fn step(c: &mut Criterion) {
    let mut group = c.benchmark_group("kinematics");
    group.throughput(Throughput::Elements(1));
    for (name, sim) in [
        ("unicycle", model(KinematicsKind::Unicycle, false)),
        ("diff_drive", model(KinematicsKind::DiffDrive, false)),
        ("omni", model(KinematicsKind::Omni, false)),
        ("ackermann", model(KinematicsKind::Ackermann, false)),
        ("unicycle_rectangle", model(KinematicsKind::Unicycle, true)),
    ] {
        let config = sim.validate().expect("valid");
        bench_steps(&mut group, name, &config, |episode, k| {
            let (v, w_deg) = COMMANDS[k % COMMANDS.len()];
            episode
                .step(Action::Continuous { v, w_deg })
                .status
                .is_done()
        });
    }
    group.finish();
}

// The macro defines an undocumented `benches` function.
#[allow(missing_docs)]
mod group {
    use super::*;
    criterion_group!(benches, step);
}
use group::benches;
criterion_main!(benches);
