//! Model and scene flags: a config file and the flags that override it, resolved once into the
//! core's validated configuration, and where episodes take place.

use crate::args::{fraction, positive, seed, ThreadArgs};
use anyhow::{Context, Result};
use clap::Args;
use ronap_core::config::ConfigFile;
use ronap_core::scene::MapSource;
use ronap_core::sim::{SceneSpec, Scenes};
use ronap_core::{ConfigError, SimConfig, ValidConfig};
use std::path::PathBuf;

/// Scene and model flags.
#[derive(Args, Debug, Clone, Default)]
pub struct SimArgs {
    /// Scenario file (TOML): the scene, static and moving obstacles, robot, laser, episode and
    /// reward (`ronap config --scenario` prints a complete example); flags override it.
    #[arg(long, visible_alias = "config", value_name = "FILE", num_args = 0..=1, default_missing_value = "-")]
    pub scenario: Option<PathBuf>,
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
    /// Whether `--scenario` was given with no file (`ronap config --scenario`: print an example).
    pub fn wants_example(&self) -> bool {
        self.scenario.as_deref() == Some(std::path::Path::new("-"))
    }

    /// The configuration: defaults, then the file, then the flags; checked.
    pub fn config(&self) -> Result<ValidConfig> {
        self.config_with(|_| {})
    }

    /// The first maze flag given (`--cols`, `--rows`, `--cell`, `--loops`, `--wall-thickness`).
    fn maze_flag(&self) -> Option<&'static str> {
        [
            (self.cols.is_some(), "--cols"),
            (self.rows.is_some(), "--rows"),
            (self.cell.is_some(), "--cell"),
            (self.loops.is_some(), "--loops"),
            (self.wall_thickness.is_some(), "--wall-thickness"),
        ]
        .into_iter()
        .find_map(|(given, flag)| given.then_some(flag))
    }

    /// Refuses maze flags for a scene that is not a maze (`map`, the `--map` flag, or the
    /// scenario's `scene.kind`), which would otherwise be silently ignored.
    pub fn check_scene(&self, config: &ValidConfig, map: Option<&std::path::Path>) -> Result<()> {
        let Some(flag) = self.maze_flag() else {
            return Ok(());
        };
        if let Some(map) = map {
            anyhow::bail!(
                "{flag} shapes a maze, but --map {} gives the scene (leave {flag} out)",
                map.display()
            );
        }
        let kind = config.scene.kind;
        if kind != ronap_core::config::SceneKind::Maze {
            let name = match kind {
                ronap_core::config::SceneKind::Warehouse => "warehouse",
                _ => "map",
            };
            anyhow::bail!(
                "{flag} shapes a maze, but the scenario's scene.kind is \"{name}\" (leave {flag} out)"
            );
        }
        Ok(())
    }

    /// Like [`SimArgs::config`], with a command's own flags applied by `more` before the check.
    pub fn config_with(&self, more: impl FnOnce(&mut SimConfig)) -> Result<ValidConfig> {
        if self.wants_example() {
            anyhow::bail!("--scenario needs a FILE (`ronap config --scenario` prints an example)");
        }
        let file = self.scenario.as_deref().map(ConfigFile::read).transpose()?;
        let mut sim = match &file {
            Some(file) => file.parse()?,
            None => SimConfig::default(),
        };
        let m = &mut sim.maze;
        m.cols = self.cols.unwrap_or(m.cols);
        m.rows = self.rows.unwrap_or(m.rows);
        m.cell_px = self.cell.unwrap_or(m.cell_px);
        m.loops = self.loops.unwrap_or(m.loops);
        m.wall_thickness_px = self.wall_thickness.unwrap_or(m.wall_thickness_px);
        more(&mut sim);
        let valid = sim.validate().map_err(|e| match &file {
            Some(file) => match file.locate(e) {
                located @ ConfigError::File { .. } => anyhow::Error::new(located),
                other => anyhow::Error::new(other).context(format!(
                    "invalid configuration from scenario {} and flags",
                    file.path().display()
                )),
            },
            None => anyhow::Error::new(e).context("invalid configuration from flags"),
        })?;
        if let Some(file) = &file {
            check_team_policies(file, &valid)?;
        }
        Ok(valid)
    }
}

/// `e` (an episode that could not start) with the file and line of the scenario entry it blames
/// (`moving[2]`, `crowd[0].pattern_radius_px`) put in front, when it blames one the file sets.
pub fn locate_in_scenario(e: anyhow::Error, scenario: Option<&std::path::Path>) -> anyhow::Error {
    let Some(file) = scenario.and_then(|path| ConfigFile::read(path).ok()) else {
        return e;
    };
    match file.line_of(&e.root_cause().to_string()) {
        Some(at) => e.context(at),
        None => e,
    }
}

/// The policies a scenario's `[[robots]]` entries name, checked as the run will make them (a
/// `py:` policy is checked when it starts), an error naming the file and the line.
fn check_team_policies(file: &ConfigFile, config: &ValidConfig) -> Result<()> {
    let mut first_robot = 0;
    for (i, entry) in config.robots.iter().enumerate() {
        let k = first_robot;
        first_robot += entry.count as usize;
        let Some(name) = entry.policy.as_deref() else {
            continue;
        };
        if name.starts_with("py:") {
            continue;
        }
        let field = format!("robots[{i}].policy");
        if let Err(e) = crate::args::named_policy(&field, name, &config.team_robot(k)) {
            let message = e.chain().map(|c| c.to_string()).collect::<Vec<_>>();
            return Err(anyhow::Error::new(ConfigError::File {
                path: file.path().to_path_buf(),
                line: ronap_core::config::key_line(file.text(), &field),
                message: message.join(": "),
            }));
        }
    }
    Ok(())
}

/// Where episodes take place.
#[derive(Args, Debug, Clone, Default)]
pub struct SceneArgs {
    /// Use the maze (or the scenario's warehouse) of this seed for every episode [default: the
    /// scenario's scene.seed, else each seed its own].
    #[arg(long, visible_alias = "scene-seed", allow_negative_numbers = true, value_name = "SEED", conflicts_with = "map", value_parser = seed)]
    pub maze_seed: Option<u64>,
    /// Run on an image scene (PNG/PGM: dark pixels are obstacles) or a ROS map_server YAML file;
    /// start and goal are drawn per seed.
    #[arg(long, value_name = "FILE")]
    pub map: Option<PathBuf>,
}

impl SceneArgs {
    /// Where episodes take place, as the core describes it: the flags, else the scenario's
    /// `[scene]`.
    pub fn spec(&self, config: &ValidConfig) -> SceneSpec {
        SceneSpec::resolve(&config.scene, self.maze_seed, self.map.as_deref())
    }

    /// The scenes (reading the map, if any), with what the map file was read as; maze flags in
    /// `sim` for a scene that is not a maze are refused.
    pub fn scenes(
        &self,
        sim: &SimArgs,
        config: &ValidConfig,
    ) -> Result<(Scenes, Option<MapSource>)> {
        sim.check_scene(config, self.map.as_deref())?;
        let loaded = self.spec(config).load(config);
        match (&config.scene.file, &self.map) {
            // The map the scenario names: say where the name came from.
            (Some(file), None) => {
                loaded.with_context(|| format!("the scenario's scene.file = {file:?}"))
            }
            _ => Ok(loaded?),
        }
    }
}

/// The worker-thread, scene and model flags of the commands that gather their own experience
/// (`ronap collect`, `ronap train dqn`).
#[derive(Args, Debug, Clone, Default)]
pub struct WorkArgs {
    #[command(flatten)]
    pub threads: ThreadArgs,
    #[command(flatten)]
    pub scenes: SceneArgs,
    #[command(flatten)]
    pub sim: SimArgs,
}

impl WorkArgs {
    /// The validated configuration (the file, the flags, then `more`) and the scenes.
    pub fn resolve_with(&self, more: impl FnOnce(&mut SimConfig)) -> Result<(ValidConfig, Scenes)> {
        let config = self.sim.config_with(more)?;
        let (scenes, _) = self.scenes.scenes(&self.sim, &config)?;
        Ok((config, scenes))
    }
}

/// The seed, worker-thread, scene, model and time-out flags of the commands that evaluate
/// policies on many seeds (`ronap run`, `ronap compare`).
#[derive(Args, Debug, Clone)]
pub struct EvalArgs {
    #[command(flatten)]
    pub seeds: super::SeedArgs,
    #[command(flatten)]
    pub threads: ThreadArgs,
    #[command(flatten)]
    pub episodes: EpisodeArgs,
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
        let (scenes, map) = self.scenes.scenes(&self.sim, &config)?;
        Ok((config, scenes, map))
    }
}
