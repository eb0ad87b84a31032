//! Worlds and scenes: a validated configuration and a scene, with the scene's free-space grid
//! computed on first use and shared by placement, planners and path metrics; and [`Scenes`], which
//! says where each seed's episode takes place.

use crate::config::{ObstacleConfig, SceneConfig, SceneKind, ValidConfig};
use crate::geometry::{Aabb, Point, Shape};
use crate::scene::map::{self, MapError, MapSource};
use crate::scene::{FreeGrid, Maze, Scene, Warehouse};
use crate::sim::episode::Episode;
use crate::sim::placement::{free_grid, needs_region_grid, sample_placement, EpisodeError};
use crate::sim::rng::{stream, Stream};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::sync::{Arc, OnceLock};

/// The scene for an episode seed: a maze drawn from the seed's scene stream, with the
/// configuration's static obstacles.
pub fn maze_scene(config: &ValidConfig, scene_seed: u64) -> Scene {
    let maze = Maze::from_config(&config.maze, &mut stream(scene_seed, Stream::Scene));
    with_static_obstacles(
        config,
        Scene::from_maze(maze, &config.maze, config.reach_px()),
    )
}

/// The warehouse of a seed: clutter drawn from the seed's scene stream, with the configuration's
/// static obstacles.
pub fn warehouse_scene(config: &ValidConfig, scene_seed: u64) -> Scene {
    let w = Warehouse::generate(
        &config.warehouse,
        config.robot.radius_px,
        &mut stream(scene_seed, Stream::Scene),
    );
    let scene = Scene::from_boxes(w.width_px, w.height_px, w.boxes(), config.reach_px());
    with_static_obstacles(config, scene)
}

/// `scene` with the static obstacles of `config.obstacles` added.
pub fn with_static_obstacles(config: &ValidConfig, scene: Scene) -> Scene {
    let mut boxes = Vec::new();
    let mut shapes = Vec::new();
    for o in &config.obstacles {
        let p = |v: [f64; 2]| Point::new(v[0], v[1]);
        match o {
            ObstacleConfig::Box { min, max } => boxes.push(Aabb::from_corners(p(*min), p(*max))),
            ObstacleConfig::Disc { center, radius_px } => {
                shapes.push(Shape::disc(p(*center), *radius_px))
            }
            ObstacleConfig::Polygon { points } => {
                let corners: Vec<Point> = points.iter().map(|&v| p(v)).collect();
                // A validated polygon is convex with an area, so its hull exists.
                shapes.extend(Shape::polygon(&corners));
            }
        }
    }
    scene.with_obstacles(boxes, shapes)
}

/// A scene under a configuration.
#[derive(Debug)]
pub struct World {
    config: ValidConfig,
    scene: Arc<Scene>,
    grid: OnceLock<FreeGrid>,
}

impl World {
    /// The world of `scene` under `config`.
    pub fn new(config: ValidConfig, scene: Arc<Scene>) -> Self {
        Self {
            config,
            scene,
            grid: OnceLock::new(),
        }
    }

    /// The maze world of `scene_seed`.
    pub fn maze(config: ValidConfig, scene_seed: u64) -> Self {
        let scene = Arc::new(maze_scene(&config, scene_seed));
        Self::new(config, scene)
    }

    /// The warehouse world of `scene_seed`.
    pub fn warehouse(config: ValidConfig, scene_seed: u64) -> Self {
        let scene = Arc::new(warehouse_scene(&config, scene_seed));
        Self::new(config, scene)
    }

    /// The configuration.
    pub fn config(&self) -> &ValidConfig {
        &self.config
    }

    /// The scene.
    pub fn scene(&self) -> &Arc<Scene> {
        &self.scene
    }

    /// The free-space grid for the configured robot (computed once, on first use).
    pub fn grid(&self) -> &FreeGrid {
        self.grid
            .get_or_init(|| free_grid(&self.config, &self.scene))
    }

    /// The episode of `seed`: start and goal as the configuration fixes them or drawn from the seed.
    pub fn episode(&self, seed: u64) -> Result<Episode, EpisodeError> {
        if self.config.team_size() > 0 {
            return Err(EpisodeError::Team {
                robots: self.config.team_size(),
            });
        }
        let both_fixed = self.config.start_and_goal_fixed();
        let grid =
            (!both_fixed && needs_region_grid(&self.config, &self.scene)).then(|| self.grid());
        let blame = |e: EpisodeError| e.of_config(&self.config, &self.scene);
        let placement = sample_placement(&self.config, &self.scene, grid, seed).map_err(blame)?;
        Episode::with_placement(&self.config, self.scene.clone(), seed, placement).map_err(blame)
    }
}

/// Where episodes take place.
#[derive(Clone, Debug)]
pub enum Scenes {
    /// Each seed gets its own maze, generated from the seed.
    MazePerSeed,
    /// One maze, from this seed, for every episode.
    Maze(u64),
    /// Each seed gets its own warehouse, its clutter drawn from the seed.
    WarehousePerSeed,
    /// One warehouse, from this seed, for every episode.
    Warehouse(u64),
    /// One given scene (an image or ROS map) for every episode.
    Fixed(Arc<Scene>),
}

/// Where episodes take place, as a user says it and a run's manifest records it: the one
/// description every front end turns into [`Scenes`].
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum SceneSpec {
    /// Each seed its own maze.
    MazePerSeed,
    /// The maze of `seed` for every episode.
    Maze {
        /// The maze's seed.
        seed: u64,
    },
    /// Each seed its own warehouse.
    WarehousePerSeed,
    /// The warehouse of `seed` for every episode.
    Warehouse {
        /// The warehouse's seed.
        seed: u64,
    },
    /// An image (PNG/PGM) or ROS `map_server` YAML file for every episode.
    Map {
        /// The map file, as given.
        file: PathBuf,
    },
}

impl SceneSpec {
    /// The scenes a scenario's `[scene]` section says, overridden by a map file or a scene seed
    /// given apart from it (command-line flags, keyword arguments).
    pub fn resolve(scene: &SceneConfig, seed: Option<u64>, map_file: Option<&Path>) -> Self {
        if let Some(file) = map_file {
            return Self::Map {
                file: file.to_path_buf(),
            };
        }
        let seed = seed.or(scene.seed);
        match (scene.kind, seed, &scene.file) {
            (SceneKind::Map, _, Some(file)) => Self::Map { file: file.clone() },
            (SceneKind::Warehouse, Some(seed), _) => Self::Warehouse { seed },
            (SceneKind::Warehouse, None, _) => Self::WarehousePerSeed,
            (_, Some(seed), _) => Self::Maze { seed },
            (_, None, _) => Self::MazePerSeed,
        }
    }

    /// The scenes, reading the map file if there is one (and what it was read as).
    pub fn load(&self, config: &ValidConfig) -> Result<(Scenes, Option<MapSource>), MapError> {
        Ok(match self {
            Self::Map { file } => {
                let (scene, source) = map::load(file, &config.map, config.reach_px())?;
                let scene = with_static_obstacles(config, scene);
                (Scenes::Fixed(Arc::new(scene)), Some(source))
            }
            Self::Maze { seed } => (Scenes::Maze(*seed), None),
            Self::MazePerSeed => (Scenes::MazePerSeed, None),
            Self::Warehouse { seed } => (Scenes::Warehouse(*seed), None),
            Self::WarehousePerSeed => (Scenes::WarehousePerSeed, None),
        })
    }
}

impl std::fmt::Display for SceneSpec {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::MazePerSeed => f.write_str("a maze per seed"),
            Self::Maze { seed } => write!(f, "maze of seed {seed}"),
            Self::WarehousePerSeed => f.write_str("a warehouse per seed"),
            Self::Warehouse { seed } => write!(f, "warehouse of seed {seed}"),
            Self::Map { file } => write!(f, "map {}", file.display()),
        }
    }
}

/// The worlds of a run's episodes: each seed's own maze world, or one world shared by every seed
/// (so its free-space grid is built once).
#[derive(Clone, Debug)]
pub struct Worlds {
    config: ValidConfig,
    scenes: Scenes,
    shared: Option<Arc<World>>,
    /// A team's worlds (one per `[[robots]]` entry) in the shared scene, made on first use.
    team_shared: std::sync::OnceLock<Vec<Arc<World>>>,
}

impl Worlds {
    /// The worlds of `scenes` under `config`.
    pub fn new(config: ValidConfig, scenes: Scenes) -> Self {
        let shared = match &scenes {
            Scenes::MazePerSeed | Scenes::WarehousePerSeed => None,
            Scenes::Maze(seed) => Some(Arc::new(World::maze(config.clone(), *seed))),
            Scenes::Warehouse(seed) => Some(Arc::new(World::warehouse(config.clone(), *seed))),
            Scenes::Fixed(scene) => Some(Arc::new(World::new(config.clone(), scene.clone()))),
        };
        Self {
            config,
            scenes,
            shared,
            team_shared: std::sync::OnceLock::new(),
        }
    }

    /// The configuration.
    pub fn config(&self) -> &ValidConfig {
        &self.config
    }

    /// Where episodes take place.
    pub fn scenes(&self) -> &Scenes {
        &self.scenes
    }

    /// The world of episode `seed`.
    pub fn world(&self, seed: u64) -> Arc<World> {
        match &self.shared {
            Some(w) => w.clone(),
            None if matches!(self.scenes, Scenes::WarehousePerSeed) => {
                Arc::new(World::warehouse(self.config.clone(), seed))
            }
            None => Arc::new(World::maze(self.config.clone(), seed)),
        }
    }

    /// A team's worlds for episode `seed`: one per `[[robots]]` entry, each with the entry's
    /// configuration ([`ValidConfig::team_robot`]) in the seed's scene (made once for a scene
    /// every seed shares, so each entry's free-space grid is built once). A lone robot's team of
    /// one has the lone robot's world.
    pub fn team(&self, seed: u64) -> Vec<Arc<World>> {
        if self.config.robots.is_empty() {
            return vec![self.world(seed)];
        }
        let make = |scene: &Arc<Scene>| {
            let mut first = 0;
            self.config
                .robots
                .iter()
                .map(|entry| {
                    let world = Arc::new(World::new(self.config.team_robot(first), scene.clone()));
                    first += entry.count as usize;
                    world
                })
                .collect::<Vec<_>>()
        };
        match &self.shared {
            Some(w) => self.team_shared.get_or_init(|| make(w.scene())).clone(),
            None => make(self.world(seed).scene()),
        }
    }

    /// The episode of `seed` in its world.
    pub fn episode(&self, seed: u64) -> Result<Episode, EpisodeError> {
        self.world(seed).episode(seed)
    }

    /// The start-up check every front end makes before it writes anything: a scene with no room
    /// for a start and goal fails the same way for every seed, so the first seed tells.
    pub fn check_start(&self, seed: u64) -> Result<(), EpisodeError> {
        self.episode(seed).map(drop)
    }
}
