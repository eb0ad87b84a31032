//! What an evaluation keeps of each robot's episode: how it ended, its figures, and on request its
//! trajectory and steps; one record for a lone robot and for each robot of a team (which adds
//! its place in the team).

use crate::geometry::Point;
use crate::sim::{Action, DynamicMetrics, Pose, Status, Track, World};
use serde::Serialize;
use std::sync::Arc;

/// How an episode ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Outcome {
    /// Reached the goal.
    Success,
    /// Ran out of steps.
    Timeout,
    /// The policy gave up (trapped, oscillating, no path).
    Stuck,
    /// Collided with `on_collision = terminate`.
    Collision,
    /// The summed reward fell to `reward_min`.
    RewardMin,
    /// A team's robots stood still for `episode.deadlock_steps` steps.
    Deadlock,
    /// The team's policy found before the first step that no plan can do the task.
    Infeasible,
}

impl Outcome {
    /// Every outcome, success first.
    pub const ALL: [Outcome; 7] = [
        Outcome::Success,
        Outcome::Timeout,
        Outcome::Stuck,
        Outcome::Collision,
        Outcome::RewardMin,
        Outcome::Deadlock,
        Outcome::Infeasible,
    ];

    /// The outcome named `name` (as [`Outcome::name`] writes it).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|o| o.name() == name)
    }

    /// How an episode with `status` ended; a running one ended because the policy gave up.
    pub fn of(status: Status) -> Self {
        match status {
            Status::Success => Outcome::Success,
            Status::TimeOut => Outcome::Timeout,
            Status::Collision => Outcome::Collision,
            Status::RewardMin => Outcome::RewardMin,
            Status::Deadlock => Outcome::Deadlock,
            Status::Running => Outcome::Stuck,
        }
    }

    /// The name in logs and tables.
    pub fn name(self) -> &'static str {
        match self {
            Outcome::Success => "success",
            Outcome::Timeout => "timeout",
            Outcome::Stuck => "stuck",
            Outcome::Collision => "collision",
            Outcome::RewardMin => "reward_min",
            Outcome::Deadlock => "deadlock",
            Outcome::Infeasible => "infeasible",
        }
    }
}

/// One logged step (docs/model.md "Data log").
#[derive(Clone, Debug, PartialEq)]
pub struct StepLog {
    /// Step number, from 1.
    pub step: u32,
    /// Pose before the action.
    pub pose: Pose,
    /// Laser readings before the action, px.
    pub readings: Vec<f64>,
    /// Bearing to the goal theta, degrees.
    pub bearing_deg: f64,
    /// Distance to the goal D, px.
    pub distance_px: f64,
    /// Goal direction relative to the heading, degrees.
    pub direction_deg: f64,
    /// The action taken.
    pub action: Action,
    /// Whether it collided.
    pub collided: bool,
    /// Its reward.
    pub reward: f64,
}

/// A robot's state before a step, as its step log keeps it.
pub(crate) struct Before {
    pose: Pose,
    readings: Vec<f64>,
    bearing_deg: f64,
    distance_px: f64,
    direction_deg: f64,
}

impl Before {
    /// What `robot` senses now, before it steps.
    pub(crate) fn of(robot: &crate::sim::Episode) -> Self {
        Self {
            pose: robot.pose(),
            readings: robot.readings().to_vec(),
            bearing_deg: robot.bearing_deg(),
            distance_px: robot.distance_px(),
            direction_deg: robot.direction_deg(),
        }
    }

    /// The step log row of step `step`, taken from this state with `action`.
    pub(crate) fn logged(self, step: u32, action: Action, collided: bool, reward: f64) -> StepLog {
        StepLog {
            step,
            pose: self.pose,
            readings: self.readings,
            bearing_deg: self.bearing_deg,
            distance_px: self.distance_px,
            direction_deg: self.direction_deg,
            action,
            collided,
            reward,
        }
    }
}

/// What to keep of each episode beyond its figures.
#[derive(Clone, Copy, Debug, Default)]
pub struct Recording {
    /// The poses (for trajectory pictures).
    pub trajectory: bool,
    /// Every step (for data logs).
    pub steps: bool,
}

/// One robot's finished episode: a lone robot's, or one robot's of a team episode (whose
/// [`crate::eval::TeamRecord`] holds one per robot, each with its [`InTeam`]).
#[derive(Clone, Debug)]
pub struct EpisodeRecord {
    /// The seed (a team's robots share their episode's).
    pub seed: u64,
    /// How it ended.
    pub outcome: Outcome,
    /// Why the policy gave up, for [`Outcome::Stuck`].
    pub reason: Option<String>,
    /// Steps taken.
    pub steps: u32,
    /// Steps that collided.
    pub collisions: u32,
    /// Distance driven, px.
    pub path_length_px: f64,
    /// Shortest collision-free path length from start to within epsilon of the goal, px (`None`
    /// when the goal is unreachable).
    pub shortest_px: Option<f64>,
    /// Success weighted by path length: `shortest / max(shortest, driven)` on success, else 0.
    pub spl: f64,
    /// Summed reward.
    pub total_reward: f64,
    /// Wall time of the episode (setup, planning and stepping), seconds; a team's robots have
    /// none of their own (their team's record has it).
    pub wall_time_s: f64,
    /// Start pose.
    pub start: Pose,
    /// Goal.
    pub goal: Point,
    /// Final pose.
    pub end: Pose,
    /// Final laser readings, px (a team's robots': when the trajectory or steps are recorded).
    pub last_readings: Vec<f64>,
    /// Poses from start to end (a team's robot: while it is in the scene), when recorded.
    pub trajectory: Vec<Pose>,
    /// Each moving obstacle's body and centre at each pose of `trajectory`, when recorded (a
    /// team's are its picture's, [`crate::eval::TeamPicture::mover_tracks`]).
    pub mover_tracks: Vec<Track>,
    /// How the episode went among moving obstacles; `None` without any.
    pub dynamic: Option<DynamicMetrics>,
    /// The value of each metric the configuration asks for beyond the standard ones, in the
    /// order of [`crate::eval::metric::kinds`] (empty when it asks for none).
    pub metrics: Vec<Option<f64>>,
    /// Steps, when recorded.
    pub step_log: Vec<StepLog>,
    /// The world the episode ran in (a lone robot's); dropped by [`EpisodeRecord::strip`], since
    /// a per-seed world holds its scene and grids.
    pub world: Option<Arc<World>>,
    /// Its place in its team, for a robot of a team episode; `None` for a lone robot.
    pub team: Option<InTeam>,
}

/// What a robot's record holds as one of a team: which robot it is, and the figures a team's
/// `robots.csv` gives beyond a lone robot's.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct InTeam {
    /// Its index in the team.
    pub robot: usize,
    /// The policy that drove it.
    pub policy: String,
    /// The team step at which it reached its goal.
    pub arrived_at: Option<u32>,
    /// Steps another robot blocked.
    pub robot_collisions: u32,
    /// Goals it had (1, or a goal list's length).
    pub goals: u32,
    /// Goals it reached.
    pub goals_reached: u32,
    /// A goal list's tour lengths (the driven order's and the optimal one), px.
    pub tour: Option<crate::run::TourLengths>,
    /// The fewest steps its own task takes alone: its shortest path (through every goal of a
    /// list, cut by the tolerance as `shortest_px` is) at its largest step, whatever the
    /// outcome; `None` without a path.
    pub lower_bound_steps: Option<u32>,
    /// Steps it acted without moving (waiting, turning on the spot, blocked).
    pub waiting_steps: u32,
}

impl EpisodeRecord {
    /// Drops the recorded trajectory, steps and world (after they have been written out), and a
    /// team's robot's last readings (kept only for its picture and step log).
    pub fn strip(&mut self) {
        if self.team.is_some() {
            self.last_readings = Vec::new();
        }
        self.trajectory = Vec::new();
        self.mover_tracks = Vec::new();
        self.step_log = Vec::new();
        self.world = None;
    }
}
