//! `ronap maze`: draw a seeded maze as a picture or as text.

use crate::args::{positive, seed, SimArgs};
use anyhow::{Context, Result};
use clap::Args;
use ronap_core::render::{Canvas, GOAL, START};
use ronap_core::sim::placement::sample_placement;
use ronap_core::sim::world::maze_scene;
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `ronap maze`.
#[derive(Args, Debug)]
pub struct MazeArgs {
    /// Seed of the maze (and of the start and goal with --start-goal).
    #[arg(long, allow_negative_numbers = true, default_value_t = 0, value_parser = seed)]
    seed: u64,
    #[command(flatten)]
    sim: SimArgs,
    /// Also draw a start (red, with a heading tick) and goal (green) drawn from the seed.
    #[arg(long)]
    start_goal: bool,
    /// Write a picture here (.png, or .pgm to use as a --map later); without it, print the maze as
    /// text.
    #[arg(long, value_name = "FILE")]
    out: Option<PathBuf>,
    /// Picture pixels per scene px.
    #[arg(long, allow_negative_numbers = true, value_name = "F", default_value_t = 1.0, value_parser = positive)]
    scale: f64,
}

/// Runs `ronap maze`.
pub fn run(args: MazeArgs) -> Result<ExitCode> {
    let config = args.sim.config()?;
    let scene = maze_scene(&config, args.seed);
    let placement = if args.start_goal {
        Some(
            sample_placement(&config, &scene, None, args.seed)
                .context("cannot place start and goal")?,
        )
    } else {
        None
    };
    match &args.out {
        Some(path) => {
            let pixels = scene.width() * scene.height() * args.scale * args.scale;
            anyhow::ensure!(
                pixels <= 4.0e8,
                "--scale {}: the picture would have {pixels:.0} pixels (at most 400 million)",
                args.scale
            );
            let mut canvas = Canvas::new(&scene, args.scale);
            if let Some(p) = placement {
                // Markers are at least 8 picture pixels across, so they show on large scenes.
                let least = 4.0 / args.scale;
                canvas.fill_disc(p.goal, config.episode.goal_tolerance_px.max(least), GOAL);
                canvas.robot(p.start, config.robot.radius_px.max(least), START);
            }
            ronap_core::io::atomic::save_image(path, &canvas.into_image())?;
        }
        None => {
            let (maze, cell) = scene.maze().context("the scene is not a maze")?;
            let cell_of = |x: f64, y: f64| ((x / cell) as usize, (y / cell) as usize);
            let start = placement.map(|p| cell_of(p.start.x, p.start.y));
            let goal = placement.map(|p| cell_of(p.goal.x, p.goal.y));
            let mut stdout = std::io::stdout().lock();
            stdout.write_all(maze.to_ascii(start, goal).as_bytes())?;
            if let Some(p) = placement {
                writeln!(
                    stdout,
                    "S start ({:.1}, {:.1}) heading {:.1} deg; G goal ({:.1}, {:.1})",
                    p.start.x, p.start.y, p.start.z_deg, p.goal.x, p.goal.y
                )?;
            }
        }
    }
    Ok(ExitCode::SUCCESS)
}
