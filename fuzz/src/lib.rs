//! What the fuzz targets do with a file once ronap has read it: run a few short episodes in the
//! scene it describes, as `ronap run` would. Bounded, so that a legitimate but slow input (a
//! 1000 x 1000 maze, a thousand robots) is skipped rather than reported as a hang: the targets
//! look for panics, hangs and runaway memory, not for slow configurations.

use ronap_core::eval::{Evaluator, Recording};
use ronap_core::policy::{Builtin, PerRobot, Policy, PolicyFactory};
use ronap_core::{Scenes, SimConfig, ValidConfig};

/// Steps each fuzzed episode runs at most.
pub const MAX_STEPS: u32 = 30;

/// Whether episodes of `config` are quick enough to run on every fuzz input: a free-space grid
/// of at most 200,000 cells, at most 16 robots, 64 moving obstacles and 720 beams, no map file.
pub fn small(config: &SimConfig) -> bool {
    use ronap_core::config::SceneKind;
    let (w, h) = match config.scene.kind {
        SceneKind::Warehouse => config.warehouse.size_px(),
        SceneKind::Map => return false,
        _ => (
            f64::from(config.maze.cols) * config.maze.cell_px,
            f64::from(config.maze.rows) * config.maze.cell_px,
        ),
    };
    let grid = config.episode.grid_px.max(1e-3);
    let cells = (w / grid) * (h / grid);
    let robots: u64 = config.robots.iter().map(|r| u64::from(r.count)).sum();
    let moving: u64 = config.moving.iter().map(|m| u64::from(m.count)).sum();
    let beams = config
        .robots
        .iter()
        .filter_map(|r| r.laser_beams)
        .chain([config.laser.beams])
        .max()
        .unwrap_or(0);
    cells.is_finite()
        && cells <= 200_000.0
        && robots <= 16
        && moving <= 64
        && beams <= 720
        && config.obstacles.len() <= 256
}

/// `config` with episodes cut to [`MAX_STEPS`].
pub fn shortened(mut config: SimConfig) -> SimConfig {
    config.episode.max_steps = config.episode.max_steps.min(MAX_STEPS);
    config
}

/// A built-in policy for `name` (APF for a network or Python file: the fuzz targets do not read
/// other files).
fn policy(name: Option<&str>) -> Box<dyn Policy> {
    let builtin = name.and_then(Builtin::from_name).unwrap_or(Builtin::Apf);
    builtin.make().expect("built-in policies always build")
}

/// Runs seeds 0 and 1 of `config` in `scenes`, a team episode when the configuration has
/// `[[robots]]`: every step, placement and output record the CLI would make. Errors (no room for
/// a start, say) are fine; panics are what the fuzzer finds.
pub fn drive(config: ValidConfig, scenes: Scenes) {
    let team = config.team_size();
    let names: Vec<String> = (0..team)
        .map(|k| {
            config
                .team_entry(k)
                .and_then(|e| e.policy.clone())
                .unwrap_or_else(|| "apf".into())
        })
        .collect();
    let evaluator = Evaluator::new(config, scenes);
    for seed in 0..2 {
        if team > 0 {
            let policies: Vec<Box<dyn Policy>> = names.iter().map(|n| policy(Some(n))).collect();
            let mut team = PerRobot::new(policies);
            let recording = Recording {
                trajectory: true,
                steps: true,
            };
            if let Ok(record) = evaluator.run_team_episode(&mut team, &names, seed, recording) {
                // The figures every output file is written from.
                let _ = ronap_core::eval::TeamFigures::of(&record);
                for robot in &record.robots {
                    let _ = ronap_core::eval::Figures::of(robot);
                }
                let _ = ronap_core::io::robot_rows(&record, &[]);
            }
        } else {
            let mut p = policy(None);
            let recording = Recording {
                trajectory: true,
                steps: true,
            };
            let _ = evaluator.run_episode(p.as_mut(), seed, recording);
        }
    }
}
