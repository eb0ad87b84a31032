//! Where an episode starts and where it must go: a start pose and a goal drawn from the seed's
//! placement stream (or fixed by the configuration), with clearance for the robot and in one
//! connected free region.

use crate::config::{Pattern, RobotPattern, ValidConfig};
use crate::geometry::{Point, Vector};
use crate::scene::{FreeGrid, Scene};
use crate::sim::rng::{stream, Rng, Stream};
use crate::sim::robot::Pose;
use rand::Rng as _;

/// Attempts at drawing a start (and, for each, a goal) before giving up on a scene.
pub(crate) const PLACEMENT_TRIES: usize = 64;

/// An episode that cannot start.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum EpisodeError {
    /// The scene has no free space for the robot.
    #[error("the scene has no free space for a robot of radius {radius_px} px")]
    NoFreeSpace {
        /// Robot radius, px.
        radius_px: f64,
    },
    /// No start and goal at least `min_goal_distance_px` apart were found in one region (the
    /// message leaves the seed to its callers, which name it).
    #[error(
        "found no start and goal {min_goal_distance_px} px apart in one free region of the scene \
         (which is {span_px:.0} px corner to corner){}",
        if *min_goal_distance_px > 0.05 * span_px { "; lower episode.min_goal_distance_px" } else { "" }
    )]
    NoPlacement {
        /// The episode seed.
        seed: u64,
        /// The distance asked for, px.
        min_goal_distance_px: f64,
        /// Diagonal of the scene, px.
        span_px: f64,
    },
    /// A team's robot found no start and goal clear of the robots placed before it.
    #[error(
        "no room for robot {robot} of a team of {robots}: found no start and goal clear of the \
         {robot} robots placed before it (fewer robots, a smaller robots radius_px or a larger \
         scene)"
    )]
    Crowded {
        /// The robot (from 0).
        robot: usize,
        /// Robots in the team.
        robots: usize,
    },
    /// The moving obstacles could not be placed.
    #[error("{0}")]
    Moving(String),
    /// The configuration describes a team (`[[robots]]`) where one robot was asked for.
    #[error(
        "the scenario has {robots} robots ([[robots]]): run teams with `ronap run --scenario`; \
         this drives one robot (remove [[robots]] for the one robot of [robot])"
    )]
    Team {
        /// Robots in the team.
        robots: usize,
    },
    /// A crowd's pattern the robot follows put its start or goal where it is not free.
    #[error(
        "crowd[{entry}].pattern_radius_px = {pattern_radius_px}: the robot's {which} on that \
         pattern, ({x}, {y}), is not free: a robot of radius {radius_px} px there touches an \
         obstacle or leaves the {width} x {height} px scene (a smaller pattern_radius_px, or a \
         pattern_center inside the scene)"
    )]
    PatternBlocked {
        /// The `[[crowd]]` entry.
        entry: usize,
        /// Its `pattern_radius_px`.
        pattern_radius_px: f64,
        /// `start` or `goal`.
        which: &'static str,
        /// x, px.
        x: f64,
        /// y, px.
        y: f64,
        /// Robot radius, px.
        radius_px: f64,
        /// Scene width, px.
        width: f64,
        /// Scene height, px.
        height: f64,
    },
    /// A fixed start or goal touches an obstacle or lies outside the scene.
    #[error("{}.{which} = ({x}, {y}) is not free: a robot of radius {radius_px} px there touches an obstacle or leaves the scene", section(*.entry))]
    Blocked {
        /// `start` or `goal`.
        which: &'static str,
        /// The `[[robots]]` entry it is of, `None` for `[episode]`'s.
        entry: Option<usize>,
        /// x, px.
        x: f64,
        /// y, px.
        y: f64,
        /// Robot radius, px.
        radius_px: f64,
    },
}

/// The configuration table a fixed start or goal is in: `[[robots]]` entry `entry`, or
/// `[episode]`.
fn section(entry: Option<usize>) -> String {
    entry.map_or_else(|| "episode".into(), |e| format!("robots[{e}]"))
}

impl EpisodeError {
    /// This error blamed on the crowd pattern that places `config`'s robot in `scene`, when one
    /// does ([`EpisodeError::of_pattern`]); else as it is.
    pub(crate) fn of_config(self, config: &ValidConfig, scene: &Scene) -> Self {
        match config.robot_pattern() {
            Some(p) if p.pattern != Pattern::Random => {
                self.of_pattern(p, scene.width(), scene.height())
            }
            _ => self,
        }
    }

    /// This error with a start or goal that is not free blamed on the crowd pattern that put
    /// it there (`pattern`), in a scene of `width` x `height` px.
    pub(crate) fn of_pattern(self, pattern: &RobotPattern, width: f64, height: f64) -> Self {
        match self {
            Self::Blocked {
                which,
                entry: None,
                x,
                y,
                radius_px,
            } => Self::PatternBlocked {
                entry: pattern.entry,
                pattern_radius_px: pattern.radius_px,
                which,
                x,
                y,
                radius_px,
                width,
                height,
            },
            other => other,
        }
    }

    /// This error with a fixed start or goal named as `[[robots]]` entry `entry`'s.
    pub(crate) fn of_entry(mut self, entry: usize) -> Self {
        if let Self::Blocked { entry: of, .. } = &mut self {
            *of = Some(entry);
        }
        self
    }
}

/// Where an episode starts and where it must go.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placement {
    /// Start pose.
    pub start: Pose,
    /// Goal position.
    pub goal: Point,
}

/// Whether start and goal must be drawn through a [`FreeGrid`] to land in one connected region.
///
/// A maze whose corridors and openings (`cell - wall thickness` wide) are wider than the robot is
/// one region by construction (every cell is reachable, property-tested), so its start and goal are
/// drawn uniformly over the scene with no grid; any other scene needs the grid.
pub fn needs_region_grid(config: &ValidConfig, scene: &Scene) -> bool {
    match scene.maze() {
        Some((_, cell)) if !scene.has_added_obstacles() => {
            cell - config.maze.wall_thickness_px <= 2.0 * config.robot.radius_px
        }
        _ => true,
    }
}

/// The free-space grid of `scene` for the configured robot: the one placement and planners use.
pub fn free_grid(config: &ValidConfig, scene: &Scene) -> FreeGrid {
    FreeGrid::new(
        scene,
        config.robot.radius_px,
        config.episode.grid_px,
        config.robot.radius_px,
    )
}

/// The start and goal of episode `seed`: each one the configuration fixes, the others drawn from
/// the seed. A drawn start goes anywhere the robot fits, a drawn goal at least
/// `min_goal_distance_px` from the start, and both in one connected free region: the fixed
/// point's region, or else the largest region of `grid` when [`needs_region_grid`] says so (and
/// anywhere in the maze when it does not). `grid`, when given, must be [`free_grid`] of the scene;
/// it is built here if needed and not given.
pub fn sample_placement(
    config: &ValidConfig,
    scene: &Scene,
    grid: Option<&FreeGrid>,
    seed: u64,
) -> Result<Placement, EpisodeError> {
    let mut rng = stream(seed, Stream::Placement);
    sample_placement_with(config, scene, grid, seed, &mut rng, |_, _| true)
}

/// [`sample_placement`] drawing from `rng` and keeping only a start and goal that `accept`
/// takes (a team's robots keep clear of each other's).
pub fn sample_placement_with(
    config: &ValidConfig,
    scene: &Scene,
    grid: Option<&FreeGrid>,
    seed: u64,
    rng: &mut Rng,
    accept: impl Fn(Point, Point) -> bool,
) -> Result<Placement, EpisodeError> {
    let radius = config.robot.radius_px;
    let e = &config.episode;
    let (start, goal) = config.fixed_start_goal(scene.width(), scene.height());
    let fixed_start = start.map(|s| Pose::new(s[0], s[1], s[2]));
    let fixed_goal = goal.map(|g| Point::new(g[0], g[1]));
    if let (Some(start), Some(goal)) = (fixed_start, fixed_goal) {
        return Ok(Placement { start, goal });
    }
    let owned;
    let grid = if needs_region_grid(config, scene) {
        match grid {
            Some(g) => Some(g),
            None => {
                owned = free_grid(config, scene);
                Some(&owned)
            }
        }
    } else {
        None
    };
    let blocked = |which: &'static str, p: Point| EpisodeError::Blocked {
        which,
        entry: None,
        x: p.x,
        y: p.y,
        radius_px: radius,
    };
    // The region everything must share.
    let region = match (grid, fixed_start, fixed_goal) {
        (None, _, _) => 0,
        (Some(g), Some(s), _) => g
            .region_at(s.position())
            .ok_or_else(|| blocked("start", s.position()))?,
        (Some(g), None, Some(p)) => g.region_at(p).ok_or_else(|| blocked("goal", p))?,
        (Some(_), None, None) => 0,
    };
    let cells = grid.map_or(&[][..], |g| g.region_cells(region));
    if grid.is_some() && cells.is_empty() {
        return Err(EpisodeError::NoFreeSpace { radius_px: radius });
    }
    let draw = |rng: &mut Rng| -> Option<Point> {
        let p = match grid {
            Some(g) => {
                let (cols, _) = g.size();
                let k = cells[rng.random_range(0..cells.len())] as usize;
                let c = g.center(k % cols, k / cols);
                c + Vector::new(rng.random_range(-0.5..0.5), rng.random_range(-0.5..0.5))
                    * g.cell_px()
            }
            None => Point::new(
                rng.random_range(radius..scene.width() - radius),
                rng.random_range(radius..scene.height() - radius),
            ),
        };
        let in_region = grid.is_none_or(|g| g.region_at(p) == Some(region));
        (in_region && scene.disc_clear(p, radius)).then_some(p)
    };
    let min_d = e.min_goal_distance_px;
    for _ in 0..PLACEMENT_TRIES {
        let start = match fixed_start {
            Some(s) => s.position(),
            None => match draw(rng) {
                Some(p) => p,
                None => continue,
            },
        };
        for _ in 0..PLACEMENT_TRIES {
            let goal = match fixed_goal {
                Some(g) => Some(g),
                None => draw(rng),
            };
            if let Some(goal) = goal.filter(|g| (g - start).norm() >= min_d && accept(start, *g)) {
                let start = fixed_start
                    .unwrap_or_else(|| Pose::new(start.x, start.y, rng.random_range(0.0..360.0)));
                return Ok(Placement { start, goal });
            }
            if fixed_goal.is_some() {
                break;
            }
        }
    }
    Err(EpisodeError::NoPlacement {
        seed,
        min_goal_distance_px: min_d,
        span_px: scene.width().hypot(scene.height()),
    })
}
