//! Episodes: a robot, a goal and a scene, stepped until success, a time-out or an early end.
//!
//! Everything random in an episode (maze, start, goal, noise) comes from its seed through separate
//! streams ([`crate::sim::rng`]), so the same seed gives the same run bit for bit.

use crate::config::{OnCollision, ValidConfig, ACTION_MEMORY};
use crate::geometry::{wrap_deg, Point, Vector};
use crate::scene::{FreeGrid, Scene};
use crate::sim::kinematics::Velocity;
use crate::sim::lidar::Laser;
use crate::sim::moving::{Body, Disc, Movers};
use crate::sim::noise::RobotNoise;
use crate::sim::placement::{sample_placement, EpisodeError, Placement, PLACEMENT_TRIES};
use crate::sim::rng::{robot_stream, stream, Rng, Stream};
use crate::sim::robot::{Action, DiscreteAction, Motion, Pose, Robot};
use rand::Rng as _;
use std::sync::Arc;

/// How an episode stands.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Status {
    /// Still going.
    #[default]
    Running,
    /// Reached the goal: D < epsilon ("TaskComplete").
    Success,
    /// Ran `max_steps` steps.
    TimeOut,
    /// The summed reward fell to `reward_min`.
    RewardMin,
    /// Collided with `on_collision = terminate`.
    Collision,
    /// A team's robots stood still for `episode.deadlock_steps` steps.
    Deadlock,
}

impl Status {
    /// Every status, each at the index of its discriminant (`ALL[s as usize] == s`).
    pub const ALL: [Self; 6] = [
        Self::Running,
        Self::Success,
        Self::TimeOut,
        Self::RewardMin,
        Self::Collision,
        Self::Deadlock,
    ];

    /// Whether the episode is over: [`Status::is_terminated`] or [`Status::is_truncated`].
    pub fn is_done(self) -> bool {
        self != Status::Running
    }

    /// Gymnasium's `terminated`: the task itself ended, so no value follows this state. Success,
    /// a collision under `on_collision = terminate`, and the summed reward reaching `reward_min`
    /// (the paper's R_min, which ends Algorithm 1's episodes with target `y = r`).
    pub fn is_terminated(self) -> bool {
        matches!(
            self,
            Status::Success | Status::Collision | Status::RewardMin
        )
    }

    /// Gymnasium's `truncated`: a limit outside the task (the `max_steps` time-out) cut the
    /// episode short; the state still has a value.
    pub fn is_truncated(self) -> bool {
        matches!(self, Status::TimeOut | Status::Deadlock)
    }

    /// The name used in logs: `running`, `success`, `timeout`, `reward_min`, `collision`.
    pub fn name(self) -> &'static str {
        match self {
            Status::Running => "running",
            Status::Success => "success",
            Status::TimeOut => "timeout",
            Status::RewardMin => "reward_min",
            Status::Collision => "collision",
            Status::Deadlock => "deadlock",
        }
    }
}

/// What one step did: everything a caller needs, borrowed from the episode.
#[derive(Clone, Copy, Debug)]
pub struct StepResult<'a> {
    /// The observation after the step: `[d_1/d_max, ..., d_m/d_max, direction/360]`.
    pub observation: &'a [f32],
    /// The laser readings after the step, px.
    pub readings: &'a [f64],
    /// This step's reward `r_a + r_b + r_c + r_d`.
    pub reward: f64,
    /// Whether the step's motion would have touched an obstacle (and so did not happen).
    pub collided: bool,
    /// The episode's status after the step.
    pub status: Status,
    /// The pose after the step.
    pub pose: Pose,
    /// Distance to the goal D after the step, px.
    pub distance_px: f64,
    /// Number of steps taken so far, this one included.
    pub step: u32,
}

/// Bearing from `from` to `to`, degrees in [0, 360); 0 when the points coincide.
pub fn bearing_deg(from: Point, to: Point) -> f64 {
    let d = to - from;
    wrap_deg(d.y.atan2(d.x).to_degrees())
}

/// How many calls of [`Episode::prefetch`] bring in what a step reads.
pub(crate) const PREFETCH_STAGES: usize = 5;

/// One episode in progress.
#[derive(Clone, Debug)]
pub struct Episode {
    scene: Arc<Scene>,
    config: ValidConfig,
    robot: Robot,
    laser: Laser,
    seed: u64,
    start: Pose,
    pose: Pose,
    /// The velocity held over the last step (zero at the start and after a blocked step).
    velocity: Velocity,
    goal: Point,
    noise_rng: Rng,
    /// Motion, goal-sensing and beam noise, when the configuration has any.
    noise: Option<Box<RobotNoise>>,
    readings: Vec<f64>,
    /// The other robots near enough to see, gathered afresh each sensing (a kept buffer), and
    /// their headings.
    near_discs: Vec<(Point, f64)>,
    near_headings: Vec<f64>,
    /// The heading the last sensing faced, degrees, and its unit vector (`unit(z_deg)`): a step
    /// ahead from that heading moves along it without working out its sine and cosine again.
    facing: (f64, Vector),
    observation: Vec<f32>,
    distance_px: f64,
    steps: u32,
    collisions: u32,
    total_reward: f64,
    /// The progress term r_b of the last step's reward.
    last_progress: f64,
    path_length_px: f64,
    status: Status,
    /// The moving obstacles, when the configuration has some.
    movers: Option<Box<Movers>>,
    dynamic: DynamicMetrics,
    /// Moving obstacles are about (this episode's own, or its team's).
    among_movers: bool,
    /// Steps another robot of a team blocked.
    robot_collisions: u32,
    /// The goals after the first of a goal list, and how many of them are behind.
    later_goals: Vec<Point>,
    next_goal: usize,
    goals_reached: u32,
}

/// How an episode went among moving obstacles (docs/model.md "Moving obstacles", metrics).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DynamicMetrics {
    /// Steps with contact between the robot and a moving obstacle, either way.
    pub collisions: u32,
    /// Least gap between the robot and any obstacle, still or moving, seen within the laser
    /// range, px (infinite when none came that close).
    pub min_clearance_px: f64,
    /// Steps ending with a moving obstacle closer than `episode.safety_radius_px`.
    pub near_steps: u32,
}

impl Default for DynamicMetrics {
    fn default() -> Self {
        Self {
            collisions: 0,
            min_clearance_px: f64::INFINITY,
            near_steps: 0,
        }
    }
}

impl Episode {
    /// An episode in `scene` for `seed`, with the start and goal the configuration fixes or, where
    /// it does not, drawn from the seed.
    pub fn new(config: &ValidConfig, scene: Arc<Scene>, seed: u64) -> Result<Self, EpisodeError> {
        let placement = sample_placement(config, &scene, None, seed)?;
        Self::with_placement(config, scene, seed, placement)
    }

    /// An episode with a given start and goal; both must leave the robot clear of obstacles.
    pub fn with_placement(
        config: &ValidConfig,
        scene: Arc<Scene>,
        seed: u64,
        placement: Placement,
    ) -> Result<Self, EpisodeError> {
        Self::placed(config, scene, seed, placement, true)
    }

    /// [`Episode::with_placement`]; `own_movers`: whether it holds the configuration's moving
    /// obstacles itself (a team's robots share the team's).
    pub(crate) fn placed(
        config: &ValidConfig,
        scene: Arc<Scene>,
        seed: u64,
        placement: Placement,
        own_movers: bool,
    ) -> Result<Self, EpisodeError> {
        let radius = config.robot.radius_px;
        let inside = |p: Point| scene.bounds().contains(p) && scene.disc_clear(p, radius);
        for (which, p) in [
            ("start", placement.start.position()),
            ("goal", placement.goal),
        ] {
            if !inside(p) {
                return Err(EpisodeError::Blocked {
                    which,
                    entry: None,
                    x: p.x,
                    y: p.y,
                    radius_px: radius,
                });
            }
        }
        let movers = if own_movers {
            Movers::new(
                config,
                &scene,
                placement.start.position(),
                placement.goal,
                seed,
            )
            .map_err(|e| EpisodeError::Moving(e.to_string()))?
            .map(Box::new)
        } else {
            None
        };
        let laser = Laser::new(&config.laser);
        let beams = laser.beams();
        let mut episode = Self {
            robot: Robot::new(&config.robot),
            laser,
            config: config.clone(),
            seed,
            start: placement.start,
            pose: placement.start,
            velocity: Velocity::default(),
            goal: placement.goal,
            noise_rng: stream(seed, Stream::Noise),
            noise: RobotNoise::new(&config.robot, &config.laser, seed, 0).map(Box::new),
            readings: vec![0.0; beams],
            near_discs: Vec::new(),
            near_headings: Vec::new(),
            facing: (f64::NAN, Vector::zeros()),
            observation: vec![0.0; config.observation_size()],
            distance_px: 0.0,
            steps: 0,
            collisions: 0,
            total_reward: 0.0,
            last_progress: 0.0,
            path_length_px: 0.0,
            status: Status::Running,
            scene,
            among_movers: movers.is_some(),
            movers,
            dynamic: DynamicMetrics::default(),
            robot_collisions: 0,
            later_goals: Vec::new(),
            next_goal: 0,
            goals_reached: 0,
        };
        episode.sense();
        episode.fill_history();
        if episode.distance_px < config.episode.goal_tolerance_px {
            episode.status = Status::Success;
        }
        Ok(episode)
    }

    /// Makes the noise streams robot `k`'s of the episode with `seed` (a team's robot's own,
    /// fresh before its first sensing among the team; robot 0's are a lone robot's).
    pub(crate) fn set_noise_streams(&mut self, seed: u64, k: usize) {
        self.noise_rng = robot_stream(seed, Stream::Noise, k);
        self.noise = RobotNoise::new(&self.config.robot, &self.config.laser, seed, k).map(Box::new);
    }

    /// Reads the laser and goal sensors at the current pose and refreshes the observation.
    fn sense(&mut self) {
        let movers = self.movers.take();
        self.sense_among(movers.as_deref(), &[]);
        self.movers = movers;
    }

    /// Reads the sensors among `movers` (a team's, or this episode's own) and the other robots
    /// `others` of a team, which the laser sees as discs.
    pub(crate) fn sense_among(&mut self, movers: Option<&Movers>, others: &[Disc]) {
        let p = self.pose.position();
        let radius = self.config.robot.radius_px;
        let heading = crate::geometry::unit(self.pose.z_deg);
        self.facing = (self.pose.z_deg, heading);
        if let Some(noise) = &mut self.noise {
            if let Some(angles) = noise.jitter(self.readings.len()) {
                self.laser.jitter(angles);
            }
        }
        self.laser
            .scan_toward(&self.scene, p, heading, &mut self.readings);
        if let Some(movers) = movers {
            let gap = movers.sense_toward(&self.laser, p, radius, heading, &mut self.readings);
            self.note_gap(gap);
        }
        let reach = self.laser.range_px() + radius;
        let mut near = std::mem::take(&mut self.near_discs);
        let mut headings = std::mem::take(&mut self.near_headings);
        near.clear();
        headings.clear();
        // Squared distances, without a square root: a disc near the edge of `reach` (which is
        // the range plus the robot's radius) is beyond every beam's range either way.
        for d in others {
            if (d.at - p).norm_squared() <= (reach + d.radius) * (reach + d.radius) {
                near.push((d.at, d.radius));
                headings.push(d.z_deg);
            }
        }
        if !near.is_empty() {
            // The team's robots share this robot's footprint: a disc, or an outline the beams
            // meet within its circumscribed disc.
            let outline = self.robot.outline();
            let mut corners = Vec::with_capacity(outline.len());
            self.laser.refine_round_toward(
                p,
                heading,
                &mut self.readings,
                &near,
                |j, origin, dir, best| {
                    if outline.is_empty() {
                        return Body::Disc(near[j].1).ray(near[j].0, origin, dir, best);
                    }
                    let pose = Pose::new(near[j].0.x, near[j].0.y, headings[j]);
                    Robot::place(outline, pose, &mut corners);
                    crate::sim::robot::ray_convex(&corners, origin, dir, best)
                },
            );
        }
        self.near_discs = near;
        self.near_headings = headings;
        self.laser
            .add_noise(&mut self.readings, &mut self.noise_rng);
        let range = self.laser.range_px();
        if let Some(noise) = &mut self.noise {
            noise.drop_out(&mut self.readings, range);
        }
        self.distance_px = (self.goal - p).norm();
        for (o, r) in self.observation.iter_mut().zip(&self.readings) {
            *o = (r / range) as f32;
        }
        self.observe_goal();
    }

    /// The observation's goal direction: the true one, or as sensed with goal-sensing noise.
    #[inline]
    fn observe_goal(&mut self) {
        let last = self.readings.len();
        let direction = match &self.noise {
            Some(noise) if noise.senses_goal() => self.sensed_direction_deg(),
            _ => self.direction_deg(),
        };
        self.observation[last] = (direction / 360.0) as f32;
    }

    /// The goal's direction from the heading as sensed with goal-sensing noise, degrees.
    #[cold]
    #[inline(never)]
    fn sensed_direction_deg(&mut self) -> f64 {
        let bearing = bearing_deg(self.pose.position(), self.goal);
        let (z, distance) = (self.pose.z_deg, self.distance_px);
        match &mut self.noise {
            Some(noise) => wrap_deg(noise.sense_goal(bearing, distance).0 - z),
            None => self.direction_deg(),
        }
    }

    /// The goal's bearing (degrees in [0, 360)) and distance (px) as the robot last sensed
    /// them: the true ones ([`Episode::bearing_deg`], [`Episode::distance_px`]) unless
    /// `robot.goal_noise_deg` or `robot.goal_noise_px` is set.
    pub fn sensed_goal(&self) -> (f64, f64) {
        self.noise
            .as_ref()
            .and_then(|n| n.last_goal())
            .unwrap_or((self.bearing_deg(), self.distance_px))
    }

    /// Records the gap to the nearest moving obstacle after a step, and to the still scene.
    fn note_gap(&mut self, moving_gap: f64) {
        let radius = self.config.robot.radius_px;
        let safety = self.config.episode.safety_radius_px.unwrap_or(2.0 * radius);
        if self.steps > 0 && moving_gap < safety {
            self.dynamic.near_steps += 1;
        }
        let p = self.pose.position();
        let still = self
            .scene
            .clearance(p, self.config.reach_px())
            .map_or(f64::INFINITY, |d| d - radius);
        let gap = moving_gap.min(still);
        if gap < self.dynamic.min_clearance_px {
            self.dynamic.min_clearance_px = gap;
        }
    }

    /// The paper's re-posing in data collection (docs/model.md "Data log"): the robot jumps to a random free pose,
    /// `x, y` uniform over the scene where the robot fits (and, given `grid`, in the goal's free
    /// region, so the goal stays reachable), heading `theta + 360 lambda3` with
    /// `lambda3 ~ N(0, 0.03^2)`: roughly towards the goal. The goal, step and collision counts stay.
    /// `None` when no such pose turned up in many tries (the robot then stays where it was).
    pub fn repose(&mut self, grid: Option<&FreeGrid>, rng: &mut Rng) -> Option<Pose> {
        let radius = self.config.robot.radius_px;
        let (w, h) = (self.scene.width(), self.scene.height());
        let region = grid.and_then(|g| g.region_at(self.goal));
        for _ in 0..PLACEMENT_TRIES * PLACEMENT_TRIES {
            let p = Point::new(
                rng.random_range(radius..(w - radius).max(radius + 1e-9)),
                rng.random_range(radius..(h - radius).max(radius + 1e-9)),
            );
            let reachable = match (grid, region) {
                (Some(g), Some(r)) => g.region_at(p) == Some(r),
                _ => true,
            };
            if !reachable || !self.scene.disc_clear(p, radius) {
                continue;
            }
            let lambda3 =
                0.03 * rand_distr::Distribution::<f64>::sample(&rand_distr::StandardNormal, rng);
            let z = wrap_deg(bearing_deg(p, self.goal) + 360.0 * lambda3);
            self.pose = Pose::new(p.x, p.y, z);
            // A body put down elsewhere stands still.
            self.velocity = Velocity::default();
            self.sense();
            return Some(self.pose);
        }
        None
    }

    /// Takes one step. On a finished episode nothing moves and the reward is 0.
    pub fn step(&mut self, action: impl Into<Action>) -> StepResult<'_> {
        if self.status.is_done() {
            return self.result(0.0, false);
        }
        let action = action.into();
        let before = self.distance_px;
        let mut touched = false;
        if let Some(movers) = &mut self.movers {
            touched = movers
                .advance(self.steps + 1, &self.scene, self.pose.position())
                .touched_robot;
        }
        let motion = self.motion(action);
        let wall = !self.robot.motion_clear(&self.scene, self.pose, &motion);
        let moving = match &self.movers {
            Some(movers) => !self
                .robot
                .motion_clear_by(self.pose, &motion, |a, b, r| movers.sweep_clear(a, b, r)),
            None => false,
        };
        let collided = self.apply(&motion, wall, moving, touched, false);
        self.remember(action);
        self.sense();
        let reward = self.score(before, &motion, collided);
        self.result(reward, collided)
    }

    /// Asks for the memory the next step reads, one link of the chain a call, `stage` from 0
    /// to [`PREFETCH_STAGES`] - 1: the episode's own fields, then what they point to (the
    /// scene, the readings, the observation, the beams), then the scene's bin around the robot,
    /// its list and its boxes. A batch calls each stage a few environments ahead of the one it
    /// steps, so each link has arrived before the next needs it. Results never change.
    pub(crate) fn prefetch(&self, stage: usize) {
        use crate::geometry::prefetch::{line, lines};
        match stage {
            0 => {
                line(&self.scene);
                line(&self.pose);
                line(&self.readings);
                line(&self.observation);
                line(&self.laser);
                line(&self.robot);
                line(&self.noise_rng);
                line(&self.status);
            }
            1 => {
                line(&*self.scene);
                lines(&self.readings);
                lines(&self.observation);
                self.laser.prefetch();
            }
            s => self.scene.prefetch_near(self.pose.position(), s - 2),
        }
    }

    /// The current frame's values after the paper's (a team's neighbour slots), to fill in.
    pub(crate) fn neighbour_slots_mut(&mut self) -> &mut [f32] {
        let paper = self.readings.len() + 1;
        let frame = self.config.frame_size();
        &mut self.observation[paper..frame]
    }

    /// With `observation.history` above 1, at the start: every past frame is the first one.
    pub(crate) fn fill_history(&mut self) {
        let k = self.config.observation.history as usize;
        let f = self.config.frame_size();
        for j in 1..k {
            self.observation.copy_within(0..f, j * f);
        }
    }

    /// With `observation.history` above 1, before a step's sensing: the frames move one back
    /// (the oldest drops out) and `action` becomes the newest remembered action.
    pub(crate) fn remember(&mut self, action: Action) {
        let k = self.config.observation.history as usize;
        if k < 2 {
            return;
        }
        let f = self.config.frame_size();
        self.observation.copy_within(0..f * (k - 1), f);
        let a = f * k;
        self.observation
            .copy_within(a..a + ACTION_MEMORY * (k - 2), a + ACTION_MEMORY);
        let values = self.robot.kinematics().remembered(action);
        self.observation[a..a + ACTION_MEMORY].copy_from_slice(&values);
    }

    /// Makes `goals` the robot's goals, visited one after the other from the first (a goal
    /// list, docs/model.md "Multi-destination tasks"); the observation follows the current one.
    pub(crate) fn set_goals(&mut self, goals: &[Point]) {
        if let Some((&first, rest)) = goals.split_first() {
            self.goal = first;
            self.later_goals = rest.to_vec();
            self.next_goal = 0;
            self.refresh_goal();
        }
    }

    /// The goals still to visit after the current one.
    pub fn later_goals(&self) -> &[Point] {
        &self.later_goals[self.next_goal..]
    }

    /// Goals reached so far.
    pub fn goals_reached(&self) -> u32 {
        self.goals_reached
    }

    /// Recomputes the goal distance and the observation's goal direction for a new goal.
    fn refresh_goal(&mut self) {
        self.distance_px = (self.goal - self.pose.position()).norm();
        self.observe_goal();
    }

    /// The first half of a step: where `action` would take the robot (no collision check),
    /// with motion noise on the velocity it executes when configured.
    #[inline]
    pub(crate) fn motion(&mut self, action: Action) -> Motion {
        // The unit heading of the last sensing, unless the pose was set since (re-posing in data
        // collection).
        let facing =
            (self.facing.0.to_bits() == self.pose.z_deg.to_bits()).then_some(self.facing.1);
        if self.noise.is_some() {
            return self.noisy_motion(facing, action);
        }
        self.robot
            .motion_from(self.pose, self.velocity, facing, action)
    }

    /// [`Episode::motion`] with motion noise on the executed velocity (out of the step's way:
    /// the noiseless step inlines without it).
    #[cold]
    #[inline(never)]
    fn noisy_motion(&mut self, facing: Option<Vector>, action: Action) -> Motion {
        let noise = &mut self.noise;
        self.robot.motion_executed(
            self.pose,
            self.velocity,
            facing,
            action,
            |k, v| match noise {
                Some(noise) => noise.executed(k, v),
                None => v,
            },
        )
    }

    /// The velocity held over the last step (zero at the start and after a blocked step).
    pub fn velocity(&self) -> Velocity {
        self.velocity
    }

    /// The robot.
    pub(crate) fn robot(&self) -> &Robot {
        &self.robot
    }

    /// Makes `motion` unless it is blocked (by a wall, a moving obstacle or another robot) and
    /// counts the step's contacts; `touched`: a moving obstacle's own motion touched the robot.
    /// Returns whether the step collided. The sensors are read next, then [`Episode::score`].
    pub(crate) fn apply(
        &mut self,
        motion: &Motion,
        wall: bool,
        moving: bool,
        touched: bool,
        robot: bool,
    ) -> bool {
        let collided = wall || moving || touched || robot;
        if wall {
            self.collisions += 1;
        }
        if moving || touched {
            self.dynamic.collisions += 1;
        }
        if robot {
            self.robot_collisions += 1;
        }
        if !(wall || moving || robot) {
            self.path_length_px += (motion.end.position() - self.pose.position()).norm();
            self.pose = motion.end;
            self.velocity = motion.velocity;
        } else {
            // A blocked body stops.
            self.velocity = Velocity::default();
        }
        self.steps += 1;
        collided
    }

    /// The last part of a step, after the sensors are read: the reward (the goal distance was
    /// `before`) and the new status.
    pub(crate) fn score(&mut self, before: f64, motion: &Motion, collided: bool) -> f64 {
        let w = &self.config.reward;
        let success = self.distance_px < self.config.episode.goal_tolerance_px;
        let progress = w.progress_per_px * (before - self.distance_px);
        self.last_progress = progress;
        let mut reward = progress + w.turn * motion.turn_fraction;
        if collided {
            reward += w.collision;
        }
        if success {
            reward += w.success;
        }
        self.total_reward += reward;
        let mut last = success;
        if success {
            self.goals_reached += 1;
            if let Some(&next) = self.later_goals.get(self.next_goal) {
                // On to the next goal of the list.
                self.next_goal += 1;
                self.goal = next;
                self.refresh_goal();
                last = false;
            }
        }
        self.status = if last {
            Status::Success
        } else if collided && self.config.robot.on_collision == OnCollision::Terminate {
            Status::Collision
        } else if self
            .config
            .episode
            .reward_min
            .is_some_and(|m| self.total_reward <= m)
        {
            Status::RewardMin
        } else if self.steps >= self.config.episode.max_steps {
            Status::TimeOut
        } else {
            Status::Running
        };
        reward
    }

    fn result(&self, reward: f64, collided: bool) -> StepResult<'_> {
        StepResult {
            observation: &self.observation,
            readings: &self.readings,
            reward,
            collided,
            status: self.status,
            pose: self.pose,
            distance_px: self.distance_px,
            step: self.steps,
        }
    }

    /// Takes a discrete action by index (0 LEFT, 1 AHEAD, 2 RIGHT); `None` for another index.
    pub fn step_index(&mut self, index: usize) -> Option<StepResult<'_>> {
        DiscreteAction::from_index(index).map(|a| self.step(a))
    }

    /// The scene.
    pub fn scene(&self) -> &Arc<Scene> {
        &self.scene
    }

    /// The validated configuration the episode runs with.
    pub fn config(&self) -> &ValidConfig {
        &self.config
    }

    /// The laser.
    pub fn laser(&self) -> &Laser {
        &self.laser
    }

    /// The episode seed.
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// Start pose.
    pub fn start(&self) -> Pose {
        self.start
    }

    /// Current pose.
    pub fn pose(&self) -> Pose {
        self.pose
    }

    /// Goal position.
    pub fn goal(&self) -> Point {
        self.goal
    }

    /// Current laser readings, px.
    pub fn readings(&self) -> &[f64] {
        &self.readings
    }

    /// Current observation `[d_1/d_max, ..., d_m/d_max, direction/360]`.
    pub fn observation(&self) -> &[f32] {
        &self.observation
    }

    /// Distance to the goal D, px.
    pub fn distance_px(&self) -> f64 {
        self.distance_px
    }

    /// Bearing to the goal theta, degrees in [0, 360).
    pub fn bearing_deg(&self) -> f64 {
        bearing_deg(self.pose.position(), self.goal)
    }

    /// Goal direction relative to the heading, `(theta - z) mod 360`: 0 straight ahead, 90 left.
    pub fn direction_deg(&self) -> f64 {
        wrap_deg(self.bearing_deg() - self.pose.z_deg)
    }

    /// Steps taken.
    pub fn steps(&self) -> u32 {
        self.steps
    }

    /// Steps that collided.
    pub fn collisions(&self) -> u32 {
        self.collisions
    }

    /// Summed reward.
    pub fn total_reward(&self) -> f64 {
        self.total_reward
    }

    /// The progress term r_b (`progress_per_px` per px of straight-line progress) in the last
    /// step's reward; 0 before the first step.
    pub fn last_progress_reward(&self) -> f64 {
        self.last_progress
    }

    /// Distance driven, px.
    pub fn path_length_px(&self) -> f64 {
        self.path_length_px
    }

    /// Current status.
    pub fn status(&self) -> Status {
        self.status
    }

    /// The moving obstacles, when the configuration has some.
    pub fn movers(&self) -> Option<&Movers> {
        self.movers.as_deref()
    }

    /// How the episode has gone among moving obstacles so far; `None` without any.
    pub fn dynamic_metrics(&self) -> Option<DynamicMetrics> {
        self.among_movers.then_some(self.dynamic)
    }

    /// Steps another robot of a team blocked (0 alone).
    pub fn robot_collisions(&self) -> u32 {
        self.robot_collisions
    }

    /// Makes this a robot of a team among moving obstacles (the team holds them).
    pub(crate) fn set_among_movers(&mut self, among: bool) {
        self.among_movers = among;
    }

    /// Ends the episode with `status` (a team's deadlock or time-out).
    pub(crate) fn end(&mut self, status: Status) {
        self.status = status;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::SimConfig;
    use crate::sim::world::maze_scene;

    fn default_episode(seed: u64) -> Episode {
        let config = ValidConfig::default();
        let scene = Arc::new(maze_scene(&config, seed));
        Episode::new(&config, scene, seed).expect("default scene places")
    }

    #[test]
    fn every_status_sits_in_all_at_its_discriminant() {
        for (i, s) in Status::ALL.into_iter().enumerate() {
            assert_eq!(s as usize, i, "{s:?}");
            // A new status stops this match compiling until it joins `ALL` too.
            match s {
                Status::Running
                | Status::Success
                | Status::TimeOut
                | Status::RewardMin
                | Status::Collision
                | Status::Deadlock => {}
            }
        }
        assert_eq!(Status::ALL.len(), Status::Deadlock as usize + 1);
    }

    #[test]
    fn placement_respects_clearance_and_distance() {
        for seed in 0..50 {
            let e = default_episode(seed);
            let r = e.config().robot.radius_px;
            assert!(e.scene().disc_clear(e.start().position(), r));
            assert!(e.scene().disc_clear(e.goal(), r));
            assert!((e.goal() - e.start().position()).norm() >= 200.0);
            assert!((0.0..360.0).contains(&e.start().z_deg));
        }
    }

    #[test]
    fn bearing_follows_the_papers_cases() {
        let o = Point::new(10.0, 10.0);
        assert_eq!(bearing_deg(o, Point::new(20.0, 10.0)), 0.0);
        assert_eq!(bearing_deg(o, Point::new(10.0, 20.0)), 90.0);
        assert_eq!(bearing_deg(o, Point::new(0.0, 10.0)), 180.0);
        assert_eq!(bearing_deg(o, Point::new(10.0, 0.0)), 270.0);
        assert!((bearing_deg(o, Point::new(20.0, 0.0)) - 315.0).abs() < 1e-12);
    }

    #[test]
    fn history_remembers_frames_and_actions_newest_first() {
        let mut c = SimConfig::default();
        c.observation.history = 3;
        let config = c.validate().unwrap();
        assert_eq!(config.observation_size(), 3 * 18 + 2 * 3);
        let scene = Arc::new(maze_scene(&config, 1));
        let mut e = Episode::new(&config, scene.clone(), 1).unwrap();
        let f = 18;
        let first = e.observation()[..f].to_vec();
        // At the start every past frame repeats the first; no action is remembered.
        assert_eq!(&e.observation()[f..2 * f], &first[..]);
        assert_eq!(&e.observation()[2 * f..3 * f], &first[..]);
        assert!(e.observation()[3 * f..].iter().all(|&v| v == 0.0));
        e.step(DiscreteAction::Left);
        let second = e.observation()[..f].to_vec();
        e.step(DiscreteAction::Ahead);
        let o = e.observation();
        assert_eq!(&o[f..2 * f], &second[..]);
        assert_eq!(&o[2 * f..3 * f], &first[..]);
        assert_eq!(&o[3 * f..], &[0.0, 1.0, 0.0, 1.0, 0.0, 0.0]);
        // The current frame is the paper's observation of the same episode without memory.
        let plain = SimConfig::default().validate().unwrap();
        let mut p = Episode::new(&plain, scene, 1).unwrap();
        p.step(DiscreteAction::Left);
        p.step(DiscreteAction::Ahead);
        assert_eq!(&o[..f], p.observation());
    }

    #[test]
    fn reward_terms_add_up() {
        let mut sim = SimConfig::default();
        sim.episode.start = Some([150.0, 150.0, 0.0]);
        sim.episode.goal = Some([450.0, 150.0]);
        let config = sim.validate().unwrap();
        let scene = Arc::new(Scene::from_boxes(1000.0, 1000.0, vec![], 50.0));
        let mut e = Episode::new(&config, scene, 0).unwrap();
        let r = e.step(DiscreteAction::Ahead);
        assert!((r.reward - 0.5).abs() < 1e-9, "{}", r.reward);
        assert_eq!(r.observation.len(), 18);
        assert_eq!(r.observation[17], 0.0);
        let r = e.step(DiscreteAction::Left);
        assert!((r.reward - -0.05).abs() < 1e-9);
        // Goal now 15 deg to the right of the heading: direction 345.
        assert!((e.direction_deg() - 345.0).abs() < 1e-9);
    }

    #[test]
    fn timeout_and_reward_min_end_episodes() {
        let mut sim = SimConfig::default();
        sim.episode.max_steps = 3;
        let config = sim.clone().validate().unwrap();
        let scene = Arc::new(maze_scene(&config, 1));
        let mut e = Episode::new(&config, scene.clone(), 1).unwrap();
        let statuses: Vec<_> = (0..4)
            .map(|_| e.step(DiscreteAction::Left).status)
            .collect();
        assert_eq!(
            statuses,
            [
                Status::Running,
                Status::Running,
                Status::TimeOut,
                Status::TimeOut
            ]
        );
        assert_eq!(e.steps(), 3);

        sim.episode.max_steps = 100;
        sim.episode.reward_min = Some(-0.12);
        let config = sim.validate().unwrap();
        let mut e = Episode::new(&config, scene, 1).unwrap();
        let statuses: Vec<_> = (0..3)
            .map(|_| e.step(DiscreteAction::Left).status)
            .collect();
        assert_eq!(
            statuses,
            [Status::Running, Status::Running, Status::RewardMin]
        );
    }

    #[test]
    fn reaching_the_goal_succeeds() {
        let mut sim = SimConfig::default();
        sim.episode.start = Some([100.0, 100.0, 0.0]);
        sim.episode.goal = Some([118.0, 100.0]);
        let config = sim.validate().unwrap();
        let scene = Arc::new(Scene::from_boxes(1000.0, 1000.0, vec![], 50.0));
        let mut e = Episode::new(&config, scene, 0).unwrap();
        assert_eq!(e.step(DiscreteAction::Ahead).status, Status::Running);
        let r = e.step(DiscreteAction::Ahead);
        assert_eq!(r.status, Status::Success);
        assert!((r.reward - (0.5 + 10.0)).abs() < 1e-9);
    }

    #[test]
    fn a_fixed_start_gets_a_goal_far_enough_in_its_region() {
        let mut sim = SimConfig::default();
        sim.episode.start = Some([150.0, 150.0, 0.0]);
        let config = sim.validate().unwrap();
        for seed in 0..200 {
            let scene = Arc::new(maze_scene(&config, seed));
            let e = Episode::new(&config, scene, seed).unwrap();
            assert_eq!(e.start(), Pose::new(150.0, 150.0, 0.0));
            assert!(
                (e.goal() - e.start().position()).norm() >= 200.0,
                "seed {seed}"
            );
        }
        let mut sim = SimConfig::default();
        sim.episode.goal = Some([850.0, 850.0]);
        let config = sim.validate().unwrap();
        for seed in 0..50 {
            let e = Episode::new(&config, Arc::new(maze_scene(&config, seed)), seed).unwrap();
            assert_eq!(e.goal(), Point::new(850.0, 850.0));
            assert!((e.goal() - e.start().position()).norm() >= 200.0);
        }
    }

    #[test]
    fn blocked_fixed_start_is_named() {
        let mut sim = SimConfig::default();
        sim.episode.start = Some([100.0, 52.0, 0.0]);
        sim.episode.goal = Some([450.0, 450.0]);
        let config = sim.validate().unwrap();
        let scene = Arc::new(Scene::from_boxes(
            1000.0,
            1000.0,
            vec![crate::geometry::Aabb::from_corners(
                Point::new(0.0, 49.0),
                Point::new(1000.0, 51.0),
            )],
            50.0,
        ));
        let e = Episode::new(&config, scene, 0).unwrap_err();
        assert!(
            matches!(e, EpisodeError::Blocked { which: "start", .. }),
            "{e}"
        );
    }
}
