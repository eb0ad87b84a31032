//! An episode's trace for the HTML player: every robot's state at every step (pose, laser,
//! goal direction and distance, which goal it heads for, whether it is in the scene and still
//! acts) and what each step did (action, reward, collision), and the moving obstacles' places
//! (and reactive pedestrians' goals). Recorded from the model as an episode is stepped again,
//! never from a policy.

use crate::geometry::Point;
use crate::render::chart::policy_colour;
use crate::scene::Scene;
use crate::sim::{Action, Body, Episode, Movers};
use std::sync::Arc;

/// What one robot did in one step, as the model reported it.
#[derive(Clone, Debug, PartialEq)]
pub struct Acted {
    /// The action.
    pub action: Action,
    /// The step's reward.
    pub reward: f64,
    /// Whether the step collided (with a wall, an obstacle or a robot).
    pub collided: bool,
}

/// An action as a trace keeps it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Move {
    /// A discrete action: its index in the trace's action names.
    Named(u16),
    /// A continuous action: linear speed, px per step, and angular speed, degrees per step.
    Speeds(f32, f32),
    /// A car's action: speed, px per step, and steering angle, degrees.
    Steer(f32, f32),
}

/// One robot of a trace: what stays and its state at every frame.
#[derive(Clone, Debug)]
pub(super) struct RobotTrace {
    pub(super) colour: [u8; 3],
    pub(super) radius_px: f64,
    /// A footprint other than a disc: its corners in the robot's frame (empty for a disc).
    pub(super) outline: Vec<[f64; 2]>,
    pub(super) goal_tolerance_px: f64,
    /// Its goals in visiting order.
    pub(super) goals: Vec<Point>,
    /// Each beam's angle from the heading, degrees.
    pub(super) beam_offsets_deg: Vec<f64>,
    pub(super) range_px: f64,
    pub(super) x: Vec<f64>,
    pub(super) y: Vec<f64>,
    pub(super) z_deg: Vec<f64>,
    /// `beams` readings a frame, frame after frame.
    pub(super) readings: Vec<f64>,
    pub(super) bearing_deg: Vec<f64>,
    pub(super) distance_px: Vec<f64>,
    pub(super) direction_deg: Vec<f64>,
    pub(super) goals_reached: Vec<u32>,
    /// Bit 1: in the scene; bit 2: still acts; bit 4: the step from this frame collided.
    pub(super) flags: Vec<u8>,
    /// The action taken from each frame, if any.
    pub(super) action: Vec<Option<Move>>,
    pub(super) reward: Vec<f32>,
}

/// One moving obstacle of a trace.
#[derive(Clone, Debug)]
pub(super) struct MoverTrace {
    pub(super) body: Body,
    pub(super) x: Vec<f64>,
    pub(super) y: Vec<f64>,
    pub(super) present: Vec<bool>,
    /// A reactive pedestrian's goal at each frame.
    pub(super) goal: Vec<Option<Point>>,
}

/// A recorded episode, ready for the HTML player (`ronap run --html`).
#[derive(Clone, Debug)]
pub struct Trace {
    pub(super) scene: Arc<Scene>,
    pub(super) robots: Vec<RobotTrace>,
    pub(super) movers: Vec<MoverTrace>,
    pub(super) actions: Vec<String>,
    pub(super) frames: usize,
    /// What the page shows above the player: the outcome first, then the metrics.
    pub headline: Vec<(String, String)>,
    /// The title of this episode's player (the seed, the policy).
    pub title: String,
    /// Whether the robots are a team (each in its own colour) rather than a lone robot.
    pub team: bool,
}

impl Trace {
    /// Number of frames: the start and the state after each step.
    pub fn frames(&self) -> usize {
        self.frames
    }

    /// Number of robots.
    pub fn robots(&self) -> usize {
        self.robots.len()
    }

    /// Robot `k`'s position at frame `f`, px (as recorded, before the page's quantisation).
    pub fn position(&self, k: usize, f: usize) -> Option<Point> {
        let r = self.robots.get(k)?;
        Some(Point::new(*r.x.get(f)?, *r.y.get(f)?))
    }
}

/// Records a trace as an episode is stepped: [`Recorder::new`] with the robots as placed, then
/// [`Recorder::step`] after each step.
pub struct Recorder {
    trace: Trace,
}

impl Recorder {
    /// Starts the trace of `robots` (all in one scene) as placed, with `movers`; a `team` draws
    /// each robot in its own colour, a lone robot in the path colour of the pictures.
    pub fn new(robots: &[&Episode], movers: Option<&Movers>, team: bool) -> Self {
        let scene = robots.first().map_or_else(
            || Arc::new(Scene::from_boxes(1.0, 1.0, Vec::new(), 1.0)),
            |r| r.scene().clone(),
        );
        let robots_traced = robots
            .iter()
            .enumerate()
            .map(|(k, r)| {
                let colour = if team {
                    policy_colour(k).0
                } else {
                    crate::render::PATH.0
                };
                let laser = r.laser();
                let mut goals = vec![r.goal()];
                goals.extend_from_slice(r.later_goals());
                RobotTrace {
                    colour,
                    radius_px: r.config().robot.radius_px,
                    outline: r.config().robot.outline(),
                    goal_tolerance_px: r.config().episode.goal_tolerance_px,
                    goals,
                    beam_offsets_deg: (0..laser.beams())
                        .map(|i| laser.beam_angle_deg(i, 0.0))
                        .collect(),
                    range_px: laser.range_px(),
                    x: Vec::new(),
                    y: Vec::new(),
                    z_deg: Vec::new(),
                    readings: Vec::new(),
                    bearing_deg: Vec::new(),
                    distance_px: Vec::new(),
                    direction_deg: Vec::new(),
                    goals_reached: Vec::new(),
                    flags: Vec::new(),
                    action: Vec::new(),
                    reward: Vec::new(),
                }
            })
            .collect();
        let movers_traced = movers
            .map(|m| {
                m.items()
                    .map(|item| MoverTrace {
                        body: item.body(),
                        x: Vec::new(),
                        y: Vec::new(),
                        present: Vec::new(),
                        goal: Vec::new(),
                    })
                    .collect()
            })
            .unwrap_or_default();
        let mut recorder = Self {
            trace: Trace {
                scene,
                robots: robots_traced,
                movers: movers_traced,
                actions: Vec::new(),
                frames: 0,
                headline: Vec::new(),
                title: String::new(),
                team,
            },
        };
        recorder.frame(robots, movers, &|_| (true, true));
        recorder
    }

    /// Records the step just taken: what each robot did (`acted[k]`, `None` when it did not act)
    /// and the state it led to; `presence(k)` says whether robot `k` is in the scene and still
    /// acts.
    pub fn step(
        &mut self,
        robots: &[&Episode],
        movers: Option<&Movers>,
        acted: &[Option<Acted>],
        presence: &dyn Fn(usize) -> (bool, bool),
    ) {
        for (k, r) in self.trace.robots.iter_mut().enumerate() {
            let Some(done) = acted.get(k).and_then(Option::as_ref) else {
                continue;
            };
            let last = r.action.len() - 1;
            r.action[last] = match done.action {
                Action::Discrete(a) => {
                    let name = a.name();
                    let index = match self.trace.actions.iter().position(|n| n == name) {
                        Some(i) => i,
                        None => {
                            self.trace.actions.push(name.to_string());
                            self.trace.actions.len() - 1
                        }
                    };
                    // Discrete actions are a handful of names.
                    Some(Move::Named(index as u16))
                }
                // A player shows two numbers: an omnidirectional robot's sideways speed is left
                // out.
                Action::Continuous { v, w_deg } | Action::Omni { vx: v, w_deg, .. } => {
                    Some(Move::Speeds(v as f32, w_deg as f32))
                }
                Action::Steer { v, steer_deg } => Some(Move::Steer(v as f32, steer_deg as f32)),
            };
            r.reward[last] = done.reward as f32;
            if done.collided {
                r.flags[last] |= 4;
            }
        }
        self.frame(robots, movers, presence);
    }

    /// Appends the state of `robots` and `movers` as a frame.
    fn frame(
        &mut self,
        robots: &[&Episode],
        movers: Option<&Movers>,
        presence: &dyn Fn(usize) -> (bool, bool),
    ) {
        for (k, (t, r)) in self.trace.robots.iter_mut().zip(robots).enumerate() {
            let pose = r.pose();
            t.x.push(pose.x);
            t.y.push(pose.y);
            t.z_deg.push(pose.z_deg);
            let beams = t.beam_offsets_deg.len();
            let readings = r.readings();
            t.readings
                .extend((0..beams).map(|i| readings.get(i).copied().unwrap_or(0.0)));
            t.bearing_deg.push(r.bearing_deg());
            t.distance_px.push(r.distance_px());
            t.direction_deg.push(r.direction_deg());
            t.goals_reached.push(r.goals_reached());
            let (present, running) = presence(k);
            t.flags.push(u8::from(present) | (u8::from(running) << 1));
            t.action.push(None);
            t.reward.push(0.0);
        }
        if let Some(m) = movers {
            let goals = m.pedestrian_goals();
            for ((t, item), goal) in self.trace.movers.iter_mut().zip(m.items()).zip(goals) {
                let p = item.position();
                t.x.push(p.x);
                t.y.push(p.y);
                t.present.push(item.present());
                t.goal.push(goal);
            }
        }
        self.trace.frames += 1;
    }

    /// How many goals robot `k` has to visit.
    pub fn goals(&self, k: usize) -> usize {
        self.trace.robots.get(k).map_or(0, |r| r.goals.len())
    }

    /// The trace, titled `title`, with `headline` (the outcome, then the metrics) above it.
    pub fn finish(mut self, title: String, headline: Vec<(String, String)>) -> Trace {
        self.trace.title = title;
        self.trace.headline = headline;
        self.trace
    }
}
