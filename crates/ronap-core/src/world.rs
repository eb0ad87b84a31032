//! A world: a validated configuration and a scene, with the scene's free-space grid computed on
//! first use and shared by placement, planners and path metrics.

use crate::config::ValidConfig;
use crate::episode::{
    free_grid, maze_scene, needs_region_grid, sample_placement, Episode, EpisodeError,
};
use crate::freespace::FreeGrid;
use crate::geometry::Point;
use crate::planning;
use crate::scene::Scene;
use std::sync::{Arc, OnceLock};

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
        let both_fixed = self.config.episode.start.is_some() && self.config.episode.goal.is_some();
        let grid =
            (!both_fixed && needs_region_grid(&self.config, &self.scene)).then(|| self.grid());
        let placement = sample_placement(&self.config, &self.scene, grid, seed)?;
        Episode::with_placement(&self.config, self.scene.clone(), seed, placement)
    }

    /// Length of the shortest collision-free path for the robot from `start` to `goal`, px; `None`
    /// when they are not connected.
    pub fn shortest_path_px(&self, start: Point, goal: Point) -> Option<f64> {
        let path = planning::shortest_path(
            &self.scene,
            self.grid(),
            start,
            goal,
            self.config.robot.radius_px,
        )?;
        Some(planning::path_length(&path))
    }
}
