//! `ronap bench`: how fast this machine steps the default scene (or a scenario's or a map's, moving
//! obstacles and all), on one thread and on all, and what a laser scan costs; `--sweep` tabulates
//! the laser's cost over beam counts and ranges. A scenario with `[[robots]]` is timed as a team:
//! the time of one step of all its robots, and team steps per second on all threads.

use crate::args::{positive, SimArgs};
use anyhow::{Context, Result};
use clap::Args;
use ronap_core::config::MAX_BEAMS;
use ronap_core::run::TeamRollout;
use ronap_core::scene::FreeGrid;
use ronap_core::sim::{free_grid, needs_region_grid, sample_placement, SceneSpec, Worlds};
use ronap_core::{Action, DiscreteAction, Episode, Laser, Scene, ValidConfig};
use std::io::Write;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::{Duration, Instant};

/// The action pattern stepped: AHEAD x3, LEFT, AHEAD x2, RIGHT, AHEAD.
const PATTERN: [usize; 8] = [1, 1, 1, 0, 1, 1, 2, 1];

/// Beam counts `--sweep` measures.
const SWEEP_BEAMS: [u32; 4] = [17, 64, 360, 1080];
/// Laser ranges `--sweep` measures, px.
const SWEEP_RANGES_PX: [f64; 3] = [50.0, 200.0, 1000.0];
/// Seconds per figure: without and with `--sweep`.
const SECONDS: f64 = 2.0;
const SWEEP_SECONDS: f64 = 0.2;

/// How long past its duration `ronap bench --policy` looks for a first step before it gives up
/// (thousands of episodes: a policy that ends each at once would otherwise be timed for ever).
const GIVE_UP: Duration = Duration::from_secs(2);

/// Arguments of `ronap bench`.
#[derive(Args, Debug)]
pub struct BenchArgs {
    /// Seconds to measure each figure for, at most 3600 [default: 2, or 0.2 with --sweep].
    #[arg(long, allow_negative_numbers = true, value_name = "S", value_parser = bench_seconds)]
    seconds: Option<f64>,
    /// Threads for the all-threads figure [default: all cores].
    #[arg(long, allow_negative_numbers = true, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=1024))]
    threads: Option<u32>,
    /// Laser beams, 1 to 4096 [default: 17].
    #[arg(long, allow_negative_numbers = true, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=i64::from(MAX_BEAMS)))]
    beams: Option<u32>,
    /// Laser range, px [default: 50].
    #[arg(long, allow_negative_numbers = true, value_name = "PX", value_parser = positive)]
    range: Option<f64>,
    /// Angle the beams cover, centred on the heading, 0 to 360 degrees [default: 180].
    #[arg(long, allow_negative_numbers = true, value_name = "DEG", value_parser = field_of_view)]
    fov: Option<f64>,
    /// Bench on an image scene (PNG/PGM: dark pixels are obstacles) or a ROS map_server YAML file
    /// instead of the maze.
    #[arg(long, value_name = "FILE")]
    map: Option<PathBuf>,
    /// Print ns per ray and steps/s (one thread) for every beam count of 17, 64, 360 and 1080 and
    /// range of 50, 200 and 1000 px, instead of the usual figures.
    #[arg(long, conflicts_with_all = ["beams", "range", "threads"])]
    sweep: bool,
    /// Team scenarios: time this team policy (coordinated, or any policy `ronap run` takes) on
    /// one thread, its planning of each team and its steps with their decisions, instead of the
    /// action pattern.
    #[arg(long, value_name = "NAME", conflicts_with = "sweep")]
    policy: Option<String>,
    #[command(flatten)]
    sim: SimArgs,
}

/// Parses a field of view: 0 to 360 degrees.
fn field_of_view(s: &str) -> Result<f64, String> {
    let v: f64 = s.parse().map_err(|_| format!("{s:?} is not a number"))?;
    if (0.0..=360.0).contains(&v) {
        Ok(v)
    } else {
        Err("must be between 0 and 360 degrees".into())
    }
}

/// What is benched: a configuration, the scene of seed 0 under it, and the free grid placements
/// are drawn from (when the scene needs one).
struct Bench {
    config: ValidConfig,
    spec: SceneSpec,
    scene: Arc<Scene>,
    grid: Option<FreeGrid>,
}

impl Bench {
    /// The flags' configuration with the laser of `beams` and `range_px` (when given), and its
    /// scene: the scenario's (the maze by default) or the map, of seed 0, moving obstacles and all.
    fn new(args: &BenchArgs, beams: Option<u32>, range_px: Option<f64>) -> Result<Self> {
        let config = args.sim.config_with(|sim| {
            let laser = &mut sim.laser;
            laser.beams = beams.unwrap_or(laser.beams);
            laser.range_px = range_px.unwrap_or(laser.range_px);
            laser.fov_deg = args.fov.unwrap_or(laser.fov_deg);
        })?;
        args.sim.check_scene(&config, args.map.as_deref())?;
        let spec = SceneSpec::resolve(&config.scene, Some(0), args.map.as_deref());
        let (scenes, _) = spec
            .load(&config)
            .with_context(|| format!("loading the {spec}"))?;
        let scene = Worlds::new(config.clone(), scenes).world(0).scene().clone();
        let grid = needs_region_grid(&config, &scene).then(|| free_grid(&config, &scene));
        Ok(Self {
            config,
            spec,
            scene,
            grid,
        })
    }

    /// Steps episodes for `duration` on `threads` threads, starting a new placement whenever one
    /// ends; returns steps per second.
    fn steps_per_second(&self, threads: usize, duration: Duration) -> Result<f64> {
        per_second_on(threads, |first_seed| self.step_for(first_seed, duration))
    }

    /// Steps episodes for `duration`, from `first_seed` on; returns the number of steps.
    /// Placements come from the free grid computed once, so the figure is the stepping and not
    /// scene setup.
    fn step_for(&self, first_seed: u64, duration: Duration) -> Result<u64> {
        let (config, scene) = (&self.config, &self.scene);
        let new_episode = |seed: u64| -> Result<Episode> {
            let placement = sample_placement(config, scene, self.grid.as_ref(), seed)?;
            Ok(Episode::with_placement(
                config,
                scene.clone(),
                seed,
                placement,
            )?)
        };
        let mut seed = first_seed;
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

    /// The figures of a team scenario: time per team step (every robot moving at once) on one
    /// thread, and team steps per second with a team per thread on `threads`.
    fn team(
        &self,
        threads: usize,
        duration: Duration,
        out: &mut impl Write,
    ) -> Result<std::process::ExitCode> {
        let robots = self.config.team_size();
        let (steps, seconds) = self.team_steps_for(0, duration)?;
        let per_step = seconds / steps as f64;
        writeln!(
            out,
            "  one thread       {:>14.3} ms per step of all {robots} robots ({} robot-steps/s)",
            per_step * 1e3,
            group(robots as f64 / per_step)
        )?;
        let rate = per_second_on(threads, |first_seed| {
            self.team_steps_for(first_seed, duration).map(|r| r.0)
        })?;
        writeln!(
            out,
            "  {threads} thread{}        {:>14} team steps/s ({} robot-steps/s)",
            if threads == 1 { " " } else { "s" },
            group(rate),
            group(rate * robots as f64)
        )?;
        Ok(std::process::ExitCode::SUCCESS)
    }

    /// The figures of team policy `name` on a team scenario, on one thread: its planning of each
    /// team (resetting it for a new episode) and a team step with every robot's decision, over
    /// team episodes from seed 0 on for about `duration`.
    fn team_policy(
        &self,
        name: &str,
        duration: Duration,
        out: &mut impl Write,
    ) -> Result<std::process::ExitCode> {
        let policies = crate::args::TeamPolicies::new(&self.config, name)?;
        let worlds = Worlds::new(
            self.config.clone(),
            ronap_core::Scenes::Fixed(self.scene.clone()),
        );
        let robots = self.config.team_size();
        let (mut steps, mut stepping, mut teams, mut planning) = (0u64, 0.0, 0u32, 0.0);
        let begin = Instant::now();
        // At least one step, however short the duration, unless the policy takes none (its
        // plans may end every episode at its start): given up on `GIVE_UP` after the duration.
        let more = |steps: u64| {
            let elapsed = begin.elapsed();
            elapsed < duration || (steps == 0 && elapsed < duration + GIVE_UP)
        };
        let mut seed = 0;
        while more(steps) {
            let mut policy = policies.start()?;
            let clock = Instant::now();
            let mut rollout =
                TeamRollout::start(&self.config, worlds.team(seed), seed, policy.as_mut())
                    .with_context(|| format!("starting the team of seed {seed}"))?;
            planning += clock.elapsed().as_secs_f64();
            teams += 1;
            let clock = Instant::now();
            while (steps == 0 || begin.elapsed() < duration) && rollout.advance(policy.as_mut())? {
                steps += 1;
            }
            stepping += clock.elapsed().as_secs_f64();
            seed += 1;
        }
        if steps == 0 {
            anyhow::bail!(
                "--policy {name} took no step: it ended each of the {teams} team episodes it \
                 started (seeds 0 to {}) at once, so there is nothing to time; `ronap run \
                 --scenario FILE --policy {name} --seeds 3` on this scenario shows why",
                seed - 1
            );
        }
        let per_step = stepping / steps.max(1) as f64;
        writeln!(
            out,
            "  planning         {:>14.3} ms per team ({name}, mean of {teams})",
            planning / f64::from(teams) * 1e3
        )?;
        writeln!(
            out,
            "  one thread       {:>14.3} ms per step of all {robots} robots, decisions included \
             ({} robot-steps/s)",
            per_step * 1e3,
            group(robots as f64 / per_step)
        )?;
        Ok(std::process::ExitCode::SUCCESS)
    }

    /// Steps team episodes from `first_seed` on for about `duration`, each robot driving the
    /// action pattern at its own phase; returns the team steps and the seconds they took
    /// (placing a new team when one ends is not counted).
    fn team_steps_for(&self, first_seed: u64, duration: Duration) -> Result<(u64, f64)> {
        let worlds = Worlds::new(
            self.config.clone(),
            ronap_core::Scenes::Fixed(self.scene.clone()),
        );
        let place = |seed: u64| {
            TeamRollout::placed(&self.config, worlds.team(seed), seed)
                .with_context(|| format!("placing the team of seed {seed}"))
        };
        let mut seed = first_seed;
        let mut rollout = place(seed)?;
        let n = self.config.team_size();
        let mut actions: Vec<Option<Action>> = vec![None; n];
        let (mut steps, mut seconds) = (0u64, 0.0);
        let begin = Instant::now();
        while steps == 0 || begin.elapsed() < duration {
            let clock = Instant::now();
            for t in 0..16usize {
                for (k, a) in actions.iter_mut().enumerate() {
                    *a = DiscreteAction::from_index(PATTERN[(t + k) % PATTERN.len()])
                        .map(Action::from);
                }
                rollout.step(&actions);
                steps += 1;
                if rollout.finished() {
                    break;
                }
            }
            seconds += clock.elapsed().as_secs_f64();
            if rollout.finished() {
                seed += 1;
                rollout = place(seed)?;
            }
        }
        Ok((steps, seconds))
    }

    /// Nanoseconds per laser scan, over scans from 1000 placements spread over the scene (so the
    /// figure is not one lucky pose) repeated for about `duration`.
    fn scan_ns(&self, duration: Duration) -> Result<f64> {
        let laser = Laser::new(&self.config.laser);
        let poses: Vec<_> = (0..1000)
            .map(|seed| {
                sample_placement(&self.config, &self.scene, self.grid.as_ref(), seed)
                    .map(|p| p.start)
            })
            .collect::<Result<_, _>>()?;
        let mut readings = vec![0.0; laser.beams()];
        let (mut scans, start) = (0u64, Instant::now());
        while scans == 0 || start.elapsed() < duration {
            for pose in &poses {
                laser.scan(&self.scene, pose.position(), pose.z_deg, &mut readings);
            }
            scans += poses.len() as u64;
        }
        Ok(start.elapsed().as_secs_f64() * 1e9 / scans as f64)
    }
}

/// Runs `count(first_seed)` on each of `threads` threads at once (thread `t` from seed
/// `t * 1,000,000`) and returns the summed count per second of wall time.
fn per_second_on(threads: usize, count: impl Fn(u64) -> Result<u64> + Sync) -> Result<f64> {
    let start = Instant::now();
    let count = &count;
    let total: u64 = std::thread::scope(|s| {
        let handles: Vec<_> = (0..threads)
            .map(|t| s.spawn(move || count(t as u64 * 1_000_000)))
            .collect();
        handles
            .into_iter()
            .map(|h| {
                h.join()
                    .unwrap_or_else(|_| Err(anyhow::anyhow!("a bench thread panicked")))
            })
            .sum::<Result<u64>>()
    })?;
    Ok(total as f64 / start.elapsed().as_secs_f64())
}

/// Runs `ronap bench`.
pub fn run(args: BenchArgs) -> Result<std::process::ExitCode> {
    // Written, not printed: `ronap bench | head` ends quietly instead of panicking.
    let mut out = std::io::stdout().lock();
    if args.sweep {
        sweep(&args, &mut out)?;
        return Ok(std::process::ExitCode::SUCCESS);
    }
    let bench = Bench::new(&args, args.beams, args.range)?;
    let threads = args.threads.map_or_else(
        || std::thread::available_parallelism().map_or(1, |n| n.get()),
        |n| n as usize,
    );
    if args.policy.is_some() && bench.config.team_size() == 0 {
        anyhow::bail!(
            "--policy times a team scenario's policy; this configuration has one robot, whose \
             figures are the action pattern's (a team: [[robots]] entries)"
        );
    }
    let seconds = args.seconds.unwrap_or(SECONDS);
    let duration = Duration::from_secs_f64(seconds);
    let laser = &bench.config.laser;
    let movers: u32 = bench.config.moving.iter().map(|m| m.count).sum();
    writeln!(
        out,
        "ronap bench: {} of {:.0} x {:.0} px, {} moving obstacles, {} beams over {} deg to {} px, \
         {} s per figure",
        bench.spec,
        bench.scene.width(),
        bench.scene.height(),
        movers,
        laser.beams,
        laser.fov_deg,
        laser.range_px,
        seconds
    )?;
    if let (Some(name), true) = (&args.policy, bench.config.team_size() > 0) {
        return bench.team_policy(name, duration, &mut out);
    }
    if bench.config.team_size() > 0 {
        return bench.team(threads, duration, &mut out);
    }

    let single = bench.steps_per_second(1, duration)?;
    writeln!(out, "  one thread       {:>14} steps/s", group(single))?;
    // On one thread the all-threads figure would measure the same again.
    if threads > 1 {
        let all = bench.steps_per_second(threads, duration)?;
        writeln!(out, "  {threads} threads        {:>14} steps/s", group(all))?;
    }
    let ns = bench.scan_ns(duration)?;
    writeln!(
        out,
        "  one laser scan   {:>14.0} ns ({} beams, {:.1} ns per ray)",
        ns,
        laser.beams,
        ns / f64::from(laser.beams)
    )?;
    Ok(std::process::ExitCode::SUCCESS)
}

/// `ronap bench --sweep`: one row per beam count and range.
fn sweep(args: &BenchArgs, out: &mut impl Write) -> Result<()> {
    let seconds = args.seconds.unwrap_or(SWEEP_SECONDS);
    let duration = Duration::from_secs_f64(seconds);
    let mut header = false;
    for beams in SWEEP_BEAMS {
        for range_px in SWEEP_RANGES_PX {
            let bench = Bench::new(args, Some(beams), Some(range_px))?;
            if !header {
                writeln!(
                    out,
                    "ronap bench --sweep: {} of {:.0} x {:.0} px, beams over {} deg, one thread, \
                     {} s per figure",
                    bench.spec,
                    bench.scene.width(),
                    bench.scene.height(),
                    bench.config.laser.fov_deg,
                    seconds
                )?;
                writeln!(
                    out,
                    "  {:>6}  {:>8}  {:>10}  {:>12}",
                    "beams", "range px", "ns per ray", "steps/s"
                )?;
                header = true;
            }
            let ns = bench.scan_ns(duration)? / f64::from(beams);
            let steps = bench.steps_per_second(1, duration)?;
            writeln!(
                out,
                "  {beams:>6}  {range_px:>8}  {ns:>10.1}  {:>12}",
                group(steps)
            )?;
        }
    }
    Ok(())
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

/// Parses `--seconds`: a positive number of seconds, at most an hour (a figure is a mean over
/// its time; a longer one adds nothing but a wait).
fn bench_seconds(s: &str) -> Result<f64, String> {
    match positive(s)? {
        v if v <= 3600.0 => Ok(v),
        _ => Err("must be at most 3600 (an hour)".into()),
    }
}
