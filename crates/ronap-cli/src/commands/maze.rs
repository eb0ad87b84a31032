//! `ronap maze`: draw a seeded scene (a maze, or a scenario's warehouse or map, with its static and
//! moving obstacles) as a picture, or a maze as text.

use crate::args::{positive, seed, SimArgs};
use anyhow::{Context, Result};
use clap::Args;
use ronap_core::render::{Canvas, GOAL, MOVER, START};
use ronap_core::run::TeamRollout;
use ronap_core::sim::{needs_region_grid, sample_placement, SceneSpec, Worlds};
use ronap_core::ValidConfig;
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `ronap maze`.
#[derive(Args, Debug)]
pub struct MazeArgs {
    /// Seed of the scene (and of the start, goal and moving obstacles) [default: the scenario's
    /// scene.seed, else 0].
    #[arg(long, allow_negative_numbers = true, value_parser = seed)]
    seed: Option<u64>,
    /// With moving obstacles: steps of their motion drawn as faded tracks from where they start
    /// (the robot standing still).
    #[arg(long, allow_negative_numbers = true, value_name = "N", default_value_t = 300, value_parser = clap::value_parser!(u32).range(0..=100_000))]
    track_steps: u32,
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
    args.sim.check_scene(&config, None)?;
    let seed = args.seed.or(config.scene.seed).unwrap_or(0);
    let (scenes, _) = SceneSpec::resolve(&config.scene, Some(seed), None).load(&config)?;
    let worlds = Worlds::new(config.clone(), scenes);
    let world = worlds.world(seed);
    let scene = world.scene().clone();
    if !config.robots.is_empty() {
        return team_picture(&args, &config, &worlds, seed);
    }
    let placement = if args.start_goal {
        let grid = needs_region_grid(&config, &scene).then(|| world.grid());
        Some(sample_placement(&config, &scene, grid, seed).context("cannot place start and goal")?)
    } else {
        None
    };
    // Moving obstacles where they start, and the tracks they follow while the robot stands still.
    let tracks = if config.moving.is_empty() {
        Vec::new()
    } else {
        let mut episode = world
            .episode(seed)
            .context("cannot place the episode's robot and moving obstacles")?;
        let mut tracks = Vec::new();
        for _ in 0..=args.track_steps {
            if let Some(m) = episode.movers() {
                m.record(&mut tracks);
            }
            episode.step(ronap_core::DiscreteAction::Left);
        }
        tracks
    };
    match &args.out {
        Some(path) => {
            check_size(&scene, args.scale)?;
            let mut canvas = Canvas::new(&scene, args.scale);
            canvas.tracks(&tracks);
            // Where each one starts (or first appears), drawn over its track.
            for track in &tracks {
                if let Some(p) = track.first() {
                    canvas.mover(track.body, p, MOVER);
                }
            }
            if let Some(p) = placement {
                // Markers are at least 8 picture pixels across, so they show on large scenes.
                let least = 4.0 / args.scale;
                canvas.fill_disc(p.goal, config.episode.goal_tolerance_px.max(least), GOAL);
                canvas.robot(p.start, config.robot.radius_px.max(least), START);
            }
            ronap_core::io::save_image(path, &canvas.into_image())?;
        }
        None => {
            let (maze, cell) = scene
                .maze()
                .context("the scene is not a maze: give --out FILE.png for a picture")?;
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

/// Refuses a picture of more than 400 million pixels.
fn check_size(scene: &ronap_core::Scene, scale: f64) -> Result<()> {
    let pixels = scene.width() * scene.height() * scale * scale;
    anyhow::ensure!(
        pixels <= 4.0e8,
        "a scene of {:.0} x {:.0} px at --scale {scale} would be a picture of {pixels:.0} pixels \
         (at most 400 million): a smaller --scale, or a smaller scene",
        scene.width(),
        scene.height()
    );
    Ok(())
}

/// A team scenario (`[[robots]]`): every robot at its start and its goals in visiting order, in
/// its own colour (always drawn: a team's scene says little without them). Needs `--out`.
fn team_picture(
    args: &MazeArgs,
    config: &ValidConfig,
    worlds: &Worlds,
    seed: u64,
) -> Result<ExitCode> {
    let path = args
        .out
        .as_ref()
        .context("the scenario has a team ([[robots]]): give --out FILE.png for its picture")?;
    let rollout = TeamRollout::placed(config, worlds.team(seed), seed)
        .context("cannot place the team's robots")?;
    let team = rollout.team();
    check_size(team.robot(0).scene(), args.scale)?;
    let image = ronap_core::render::team_setup(team, args.scale);
    ronap_core::io::save_image(path, &image)?;
    Ok(ExitCode::SUCCESS)
}
