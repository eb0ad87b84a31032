//! Model and scene flags: a config file and the flags that override it, resolved once into the
//! core's validated configuration, and where episodes take place.

use crate::args::{fraction, positive, seed};
use anyhow::{Context, Result};
use clap::Args;
use ronap_core::scene::map::MapSource;
use ronap_core::sim::world::{SceneSpec, Scenes};
use ronap_core::{SimConfig, ValidConfig};
use std::path::PathBuf;

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
    /// Where episodes take place, as the core describes it.
    pub fn spec(&self) -> SceneSpec {
        SceneSpec::from_options(self.maze_seed, self.map.as_deref())
    }

    /// The scenes (reading the map, if any), with what the map file was read as.
    pub fn scenes(&self, config: &ValidConfig) -> Result<(Scenes, Option<MapSource>)> {
        Ok(self.spec().load(config)?)
    }
}

/// The scene, model and time-out flags of the commands that run episodes as evaluated
/// (`ronap run`, `ronap view`).
#[derive(Args, Debug, Clone, Default)]
pub struct EpisodeArgs {
    #[command(flatten)]
    pub scenes: SceneArgs,
    #[command(flatten)]
    pub sim: SimArgs,
    /// Steps before a time-out [default: 2000].
    #[arg(long, allow_negative_numbers = true, value_name = "N", value_parser = clap::value_parser!(u32).range(1..))]
    pub max_steps: Option<u32>,
}

impl EpisodeArgs {
    /// The validated configuration (the file, then the flags) and the scenes, with what the map
    /// file was read as.
    pub fn resolve(&self) -> Result<(ValidConfig, Scenes, Option<MapSource>)> {
        let config = self.sim.config_with(|sim| {
            if let Some(n) = self.max_steps {
                sim.episode.max_steps = n;
            }
        })?;
        let (scenes, map) = self.scenes.scenes(&config)?;
        Ok((config, scenes, map))
    }
}
