//! `ronap bench`: how fast this machine steps the default scene (or a scenario's, moving obstacles
//! and all), on one thread and on all.

use crate::args::{positive, SimArgs};
use anyhow::{Context, Result};
use clap::Args;
use ronap_core::scene::freespace::FreeGrid;
use ronap_core::sim::placement::{free_grid, needs_region_grid, sample_placement};
use ronap_core::sim::world::{SceneSpec, Worlds};
use ronap_core::{Episode, Laser, Scene, ValidConfig};
use std::io::Write;
use std::sync::Arc;
use std::time::{Duration, Instant};

/// The action pattern stepped: AHEAD x3, LEFT, AHEAD x2, RIGHT, AHEAD.
const PATTERN: [usize; 8] = [1, 1, 1, 0, 1, 1, 2, 1];

/// Arguments of `ronap bench`.
#[derive(Args, Debug)]
pub struct BenchArgs {
    /// Seconds to step for, in each of the two measurements.
    #[arg(long, allow_negative_numbers = true, value_name = "S", default_value_t = 2.0, value_parser = positive)]
    seconds: f64,
    /// Threads for the all-threads figure [default: all cores].
    #[arg(long, allow_negative_numbers = true, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=1024))]
    threads: Option<u32>,
    #[command(flatten)]
    sim: SimArgs,
}

/// Steps episodes in `scene` for `duration`, starting a new placement whenever one ends; returns
/// the number of steps. Placements come from the free grid computed once, so the figure is the
/// stepping and not scene setup.
fn step_for(
    config: &ValidConfig,
    scene: &Arc<Scene>,
    grid: Option<&FreeGrid>,
    first_seed: u64,
    duration: Duration,
) -> Result<u64> {
    let mut seed = first_seed;
    let new_episode = |seed: u64| -> Result<Episode> {
        let placement = sample_placement(config, scene, grid, seed)?;
        Ok(Episode::with_placement(
            config,
            scene.clone(),
            seed,
            placement,
        )?)
    };
    let mut episode = new_episode(seed)?;
    let start = Instant::now();
    let mut steps = 0u64;
    loop {
        for k in 0..4096 {
            let r = episode
                .step_index(PATTERN[k % PATTERN.len()])
                .context("pattern action")?;
            if r.status.is_done() {
                seed += 1;
                episode = new_episode(seed)?;
            }
        }
        steps += 4096;
        if start.elapsed() >= duration {
            return Ok(steps);
        }
    }
}

/// Runs `ronap bench`.
pub fn run(args: BenchArgs) -> Result<std::process::ExitCode> {
    let config = args.sim.config()?;
    let threads = args.threads.map_or_else(
        || std::thread::available_parallelism().map_or(1, |n| n.get()),
        |n| n as usize,
    );
    let duration = Duration::from_secs_f64(args.seconds);
    // The scenario's scene (the maze by default) of seed 0, moving obstacles and all.
    let spec = SceneSpec::resolve(&config.scene, Some(0), None);
    let (scenes, _) = spec.load(&config)?;
    let scene = Worlds::new(config.clone(), scenes).world(0).scene().clone();
    let grid = needs_region_grid(&config, &scene).then(|| free_grid(&config, &scene));
    let movers: u32 = config.moving.iter().map(|m| m.count).sum();
    // Written, not printed: `ronap bench | head` ends quietly instead of panicking.
    let mut out = std::io::stdout().lock();
    writeln!(
        out,
        "ronap bench: {} of {:.0} x {:.0} px, {} moving obstacles, {} beams, {} s per figure",
        spec,
        scene.width(),
        scene.height(),
        movers,
        config.laser.beams,
        args.seconds
    )?;

    let start = Instant::now();
    let steps = step_for(&config, &scene, grid.as_ref(), 0, duration)?;
    let single = steps as f64 / start.elapsed().as_secs_f64();
    writeln!(out, "  one thread       {:>14} steps/s", group(single))?;

    let start = Instant::now();
    let total: u64 = std::thread::scope(|s| {
        let handles: Vec<_> = (0..threads)
            .map(|t| {
                let (config, scene, grid) = (&config, &scene, grid.as_ref());
                s.spawn(move || step_for(config, scene, grid, t as u64 * 1_000_000, duration))
            })
            .collect();
        handles
            .into_iter()
            .map(|h| {
                h.join()
                    .unwrap_or_else(|_| Err(anyhow::anyhow!("a bench thread panicked")))
            })
            .sum::<Result<u64>>()
    })?;
    let all = total as f64 / start.elapsed().as_secs_f64();
    writeln!(
        out,
        "  {threads} thread{}        {:>14} steps/s",
        if threads == 1 { " " } else { "s" },
        group(all)
    )?;

    // Scans from 1000 placements spread over the scene, so the figure is not one lucky pose.
    let laser = Laser::new(&config.laser);
    let poses: Vec<_> = (0..1000)
        .map(|seed| sample_placement(&config, &scene, grid.as_ref(), seed).map(|p| p.start))
        .collect::<Result<_, _>>()?;
    let mut readings = vec![0.0; laser.beams()];
    let rounds = 200;
    let start = Instant::now();
    for _ in 0..rounds {
        for pose in &poses {
            laser.scan(&scene, pose.position(), pose.z_deg, &mut readings);
        }
    }
    let ns = start.elapsed().as_secs_f64() * 1e9 / (rounds * poses.len()) as f64;
    writeln!(
        out,
        "  one laser scan   {:>14.0} ns ({} beams)",
        ns,
        laser.beams()
    )?;
    Ok(std::process::ExitCode::SUCCESS)
}

/// `1234567.8` as `1,234,568`.
fn group(v: f64) -> String {
    let digits = format!("{:.0}", v);
    let mut out = String::new();
    for (i, ch) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i) % 3 == 0 {
            out.push(',');
        }
        out.push(ch);
    }
    out
}
