//! The flags that set simulation fields, shared by the commands, and how they combine with a
//! config file into one validated configuration (flags win over the file, the file over defaults).

use anyhow::{Context, Result};
use clap::Args;
use ronap_core::evaluate::Scenes;
use ronap_core::{SimConfig, ValidConfig};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// Parses a positive, finite number of px.
pub fn positive(s: &str) -> Result<f64, String> {
    let v: f64 = s.parse().map_err(|_| format!("{s:?} is not a number"))?;
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err("must be a positive number".into())
    }
}

/// Parses a whole number of at least 1.
pub fn count(s: &str) -> Result<u64, String> {
    match s.parse::<u64>() {
        Ok(n) if n >= 1 => Ok(n),
        _ => Err("must be a whole number of at least 1".into()),
    }
}

/// Parses a seed: a whole number from 0 to 2^64 - 1.
pub fn seed(s: &str) -> Result<u64, String> {
    s.parse::<u64>()
        .map_err(|_| "a seed must be a whole number from 0 to 18446744073709551615".into())
}

/// Parses a fraction in [0, 1].
pub fn fraction(s: &str) -> Result<f64, String> {
    let v: f64 = s.parse().map_err(|_| format!("{s:?} is not a number"))?;
    if (0.0..=1.0).contains(&v) {
        Ok(v)
    } else {
        Err("must be between 0 and 1".into())
    }
}

/// Scene and model flags.
#[derive(Args, Debug, Clone, Default)]
pub struct SimArgs {
    /// TOML file setting any model field (`ronap config` prints them all); flags override it.
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// Maze columns [default: 10].
    #[arg(long, allow_negative_numbers = true, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=1000))]
    pub cols: Option<u32>,
    /// Maze rows [default: 10].
    #[arg(long, allow_negative_numbers = true, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=1000))]
    pub rows: Option<u32>,
    /// Cell side, px [default: 100].
    #[arg(long, allow_negative_numbers = true, value_name = "PX", value_parser = positive)]
    pub cell: Option<f64>,
    /// Fraction of the perfect maze's interior walls removed afterwards, 0 to 1 (0: perfect maze)
    /// [default: 0.4].
    #[arg(long, allow_negative_numbers = true, value_name = "F", value_parser = fraction)]
    pub loops: Option<f64>,
    /// Wall thickness, px [default: 2].
    #[arg(long, allow_negative_numbers = true, value_name = "PX", value_parser = positive)]
    pub wall_thickness: Option<f64>,
}

impl SimArgs {
    /// The configuration: defaults, then the file, then the flags; checked.
    pub fn config(&self) -> Result<ValidConfig> {
        self.config_with(|_| {})
    }

    /// Like [`SimArgs::config`], with a command's own flags applied by `more` before the check.
    pub fn config_with(&self, more: impl FnOnce(&mut SimConfig)) -> Result<ValidConfig> {
        let mut sim = match &self.config {
            Some(path) => {
                let text = std::fs::read_to_string(path)
                    .with_context(|| format!("cannot read config file {}", path.display()))?;
                SimConfig::from_toml_str(&text)
                    .with_context(|| format!("invalid config file {}", path.display()))?
            }
            None => SimConfig::default(),
        };
        let m = &mut sim.maze;
        m.cols = self.cols.unwrap_or(m.cols);
        m.rows = self.rows.unwrap_or(m.rows);
        m.cell_px = self.cell.unwrap_or(m.cell_px);
        m.loops = self.loops.unwrap_or(m.loops);
        m.wall_thickness_px = self.wall_thickness.unwrap_or(m.wall_thickness_px);
        more(&mut sim);
        let source = self.config.as_ref().map_or("flags".to_string(), |p| {
            format!("config file {} and flags", p.display())
        });
        sim.validate()
            .with_context(|| format!("invalid configuration from {source}"))
    }
}

/// Where episodes take place.
#[derive(Args, Debug, Clone, Default)]
pub struct SceneArgs {
    /// Use the maze of this seed for every episode [default: each seed its own maze].
    #[arg(long, allow_negative_numbers = true, value_name = "SEED", conflicts_with = "map", value_parser = seed)]
    pub maze_seed: Option<u64>,
    /// Run on an image scene (PNG/PGM: dark pixels are obstacles) or a ROS map_server YAML file;
    /// start and goal are drawn per seed.
    #[arg(long, value_name = "FILE")]
    pub map: Option<PathBuf>,
}

impl SceneArgs {
    /// The scenes, and the map's source description when there is a map.
    pub fn scenes(
        &self,
        config: &ValidConfig,
    ) -> Result<(Scenes, Option<ronap_core::map::MapSource>)> {
        Ok(match (&self.map, self.maze_seed) {
            (Some(path), _) => {
                let reach = ronap_core::episode::reach_px(config);
                let (scene, source) = ronap_core::map::load(path, &config.map, reach)?;
                (Scenes::Fixed(Arc::new(scene)), Some(source))
            }
            (None, Some(seed)) => (Scenes::Maze(seed), None),
            (None, None) => (Scenes::MazePerSeed, None),
        })
    }

    /// The scenes in words.
    pub fn describe(&self) -> String {
        match (&self.map, self.maze_seed) {
            (Some(p), _) => format!("map {}", p.display()),
            (None, Some(s)) => format!("maze of seed {s}"),
            (None, None) => "a maze per seed".to_string(),
        }
    }
}

/// The worker-thread flag.
#[derive(Args, Debug, Clone, Copy, Default)]
pub struct ThreadArgs {
    /// Worker threads [default: all cores].
    #[arg(long, allow_negative_numbers = true, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub threads: Option<u32>,
}

impl ThreadArgs {
    /// The number of worker threads: the flag's, or all cores.
    pub fn count(self) -> usize {
        self.threads.map_or_else(
            || std::thread::available_parallelism().map_or(1, |n| n.get()),
            |n| n as usize,
        )
    }
}

/// A flag the first Ctrl-C sets (after saying `what` happens now); a second Ctrl-C exits at once
/// with code 130.
pub fn cancel_on_ctrl_c(what: &'static str) -> Arc<AtomicBool> {
    let cancel = Arc::new(AtomicBool::new(false));
    let flag = cancel.clone();
    let _ = ctrlc::set_handler(move || {
        if flag.swap(true, Ordering::SeqCst) {
            std::process::exit(130);
        }
        eprintln!("\nronap: interrupted; {what} (Ctrl-C again to quit now)");
    });
    cancel
}
