//! Running an episode and what an evaluation keeps of it. A lone robot's episode is its team of
//! one, so one loop runs both and one recorder watches both: each robot's path, step log and
//! waiting steps, the moving obstacles' tracks, and the metrics the configuration asks for; at
//! the end, each robot's [`EpisodeRecord`] and, for a team, its [`TeamRecord`].

use crate::config::ValidConfig;
use crate::eval::metric::{End, Gauges};
use crate::eval::record::Before;
use crate::eval::team::{RobotLook, TeamPicture, TeamRecord};
use crate::eval::{
    stream_seeds, team_outcome, EpisodeRecord, EvalOptions, Evaluator, Failure, InTeam, Outcome,
    Recording, RunEnd, Runs, StepLog, TeamRunResult,
};
use crate::geometry::Point;
use crate::plan::shortest_path_px;
use crate::policy::{Alone, Policy, PolicyError, TeamPolicy, TeamPolicyFactory};
use crate::run::{RunError, TeamRollout};
use crate::sim::{Pose, Team, Track};
use std::sync::atomic::AtomicBool;
use std::time::Instant;

/// An episode's recording under way (a lone robot's as its team of one's).
pub(crate) struct Recorder {
    clock: Instant,
    recording: Recording,
    /// Each robot's poses (with `recording.trajectory`): its start and after every step it is
    /// present.
    paths: Vec<Vec<Pose>>,
    /// Each robot's step log (with `recording.steps`).
    step_logs: Vec<Vec<StepLog>>,
    /// Each running robot's state before the step under way (with `recording.steps`).
    before: Vec<Option<Before>>,
    mover_tracks: Vec<Track>,
    gauges: Option<Gauges>,
    /// Whether the record is a lone robot's, which has no place in a team (so no waiting steps
    /// to count).
    lone: bool,
    /// Steps each robot acted without moving.
    waiting: Vec<u32>,
    /// Each robot's centre before the step under way.
    at: Vec<Point>,
}

impl Recorder {
    /// Starts recording `rollout`'s episode under `config` (begun at `clock`) as `recording`
    /// asks, for a lone robot's record ([`Recorder::lone`]) or a team's ([`Recorder::team`]).
    pub(crate) fn start(
        config: &ValidConfig,
        recording: Recording,
        clock: Instant,
        rollout: &TeamRollout,
        lone: bool,
    ) -> Self {
        let team = rollout.team();
        let n = team.robots().len();
        let mut recorder = Self {
            clock,
            recording,
            paths: vec![Vec::new(); if recording.trajectory { n } else { 0 }],
            step_logs: vec![Vec::new(); if recording.steps { n } else { 0 }],
            before: Vec::new(),
            mover_tracks: Vec::new(),
            gauges: Gauges::start(config, n),
            lone,
            waiting: vec![0; n],
            at: Vec::with_capacity(n),
        };
        recorder.note(team);
        recorder
    }

    /// Notes the team as it stands: each present robot's pose, the moving obstacles, the
    /// metrics.
    fn note(&mut self, team: &Team) {
        for (k, path) in self.paths.iter_mut().enumerate() {
            if team.present(k) {
                path.push(team.robot(k).pose());
            }
        }
        if let (true, Some(movers)) = (self.recording.trajectory, team.movers()) {
            movers.record(&mut self.mover_tracks);
        }
        if let Some(g) = &mut self.gauges {
            g.watch_team(team);
        }
    }

    /// Notes the team before a step: where each robot is, and each running robot's state for its
    /// step log.
    pub(crate) fn before(&mut self, team: &Team) {
        if !self.lone {
            self.at.clear();
            self.at
                .extend(team.robots().iter().map(|r| r.pose().position()));
        }
        self.before.clear();
        if self.recording.steps {
            let n = team.robots().len();
            self.before
                .extend((0..n).map(|k| team.running(k).then(|| Before::of(team.robot(k)))));
        }
    }

    /// Notes the step `rollout` just made (after [`Recorder::before`]).
    pub(crate) fn after(&mut self, rollout: &TeamRollout) {
        let team = rollout.team();
        let acted = rollout.last_actions();
        for (k, &at) in self.at.iter().enumerate() {
            if acted[k].is_some() && team.robot(k).pose().position() == at {
                self.waiting[k] += 1;
            }
        }
        for (k, b) in self.before.drain(..).enumerate() {
            if let (Some(b), Some(action)) = (b, acted[k]) {
                let step = team.robot(k).steps();
                self.step_logs[k].push(b.logged(step, action, team.collided(k), team.rewards()[k]));
            }
        }
        self.note(team);
    }

    /// Runs `rollout` to its end with `policy`, noting every step, showing `watch` the team
    /// after each; gives the finished rollout.
    pub(crate) fn run(
        &mut self,
        mut rollout: TeamRollout,
        policy: &mut dyn TeamPolicy,
        watch: &mut dyn FnMut(&Team),
    ) -> Result<TeamRollout, RunError> {
        // A lone robot's episode that keeps nothing step by step (its figures are its episode's).
        let keeps_nothing = self.lone
            && !self.recording.trajectory
            && !self.recording.steps
            && self.gauges.is_none();
        loop {
            if keeps_nothing {
                if !rollout.advance(policy)? {
                    return Ok(rollout);
                }
                watch(rollout.team());
                continue;
            }
            self.before(rollout.team());
            if !rollout.advance(policy)? {
                return Ok(rollout);
            }
            self.after(&rollout);
            watch(rollout.team());
        }
    }

    /// Robot `k`'s record of the finished `rollout`. A team's robot computes its own task's
    /// length whatever its outcome (for the lower bounds); a lone robot's only on success, as
    /// it costs more than a random policy's whole episode and scores nothing else.
    fn robot(&mut self, rollout: &TeamRollout, k: usize) -> EpisodeRecord {
        let lone = self.lone;
        let team = rollout.team();
        let r = team.robot(k);
        let outcome = if rollout.infeasible().is_some() {
            Outcome::Infeasible
        } else if team.retired(k) {
            Outcome::Stuck
        } else {
            Outcome::of(r.status())
        };
        let tolerance = r.config().episode.goal_tolerance_px;
        let tour = rollout.tour(k);
        // Each goal counts as reached within the tolerance: a tour of n goals can be cut by up
        // to the tolerance on arriving at each and on leaving each but the last.
        let goals = team.goals(k).len().max(1) as f64;
        let own_px = if lone && outcome != Outcome::Success {
            None
        } else {
            match tour {
                Some(t) => Some(t.optimal).filter(|l| l.is_finite()),
                None => shortest_path_px(rollout.world(k), r.start().position(), r.goal()),
            }
            .map(|l| (l - tolerance * (2.0 * goals - 1.0)).max(0.0))
        };
        let shortest_px = own_px.filter(|_| outcome == Outcome::Success);
        let robot = &r.config().robot;
        let step_px = robot.move_speed_px.max(robot.max_linear_speed_px);
        let lower_bound_steps = own_px.map(|l| (l / step_px).ceil() as u32);
        let spl = match shortest_px {
            Some(l) if r.path_length_px() > 0.0 => l / l.max(r.path_length_px()),
            Some(_) => 1.0,
            None => 0.0,
        };
        let end = End {
            outcome,
            steps: r.steps(),
            arrived_at: team.arrived_at(k),
            path_length_px: r.path_length_px(),
        };
        let keep_readings = lone || self.recording.trajectory || self.recording.steps;
        EpisodeRecord {
            seed: r.seed(),
            outcome,
            reason: rollout
                .infeasible()
                .or(rollout.gave_up(k))
                .map(str::to_string),
            steps: r.steps(),
            collisions: r.collisions(),
            path_length_px: r.path_length_px(),
            shortest_px,
            spl,
            total_reward: r.total_reward(),
            wall_time_s: 0.0,
            start: r.start(),
            goal: r.goal(),
            end: r.pose(),
            last_readings: if keep_readings {
                r.readings().to_vec()
            } else {
                Vec::new()
            },
            trajectory: self
                .paths
                .get_mut(k)
                .map(std::mem::take)
                .unwrap_or_default(),
            mover_tracks: Vec::new(),
            dynamic: r.dynamic_metrics(),
            metrics: self
                .gauges
                .as_ref()
                .map_or_else(Vec::new, |g| g.values(k, &end)),
            step_log: self
                .step_logs
                .get_mut(k)
                .map(std::mem::take)
                .unwrap_or_default(),
            world: None,
            team: (!lone).then(|| InTeam {
                robot: k,
                policy: String::new(),
                arrived_at: team.arrived_at(k),
                robot_collisions: r.robot_collisions(),
                goals: team.goals(k).len() as u32,
                goals_reached: r.goals_reached(),
                tour,
                lower_bound_steps,
                waiting_steps: self.waiting[k],
            }),
        }
    }

    /// The record of a lone robot's finished episode (its team of one's robot), with its world
    /// and the moving obstacles' tracks.
    pub(crate) fn lone(mut self, rollout: TeamRollout) -> EpisodeRecord {
        let mut record = self.robot(&rollout, 0);
        record.mover_tracks = std::mem::take(&mut self.mover_tracks);
        record.world = Some(rollout.world(0).clone());
        record.wall_time_s = self.clock.elapsed().as_secs_f64();
        record
    }

    /// The record of a team's finished episode, robot `k`'s policy named `names[k]`; with the
    /// scene and every robot's look when the recording keeps paths.
    pub(crate) fn team(mut self, rollout: &TeamRollout, names: &[String]) -> TeamRecord {
        let team = rollout.team();
        let robots: Vec<EpisodeRecord> = (0..team.robots().len())
            .map(|k| {
                let mut r = self.robot(rollout, k);
                if let (Some(place), Some(name)) = (&mut r.team, names.get(k)) {
                    place.policy = name.clone();
                }
                r
            })
            .collect();
        let places: Vec<&InTeam> = robots.iter().filter_map(|r| r.team.as_ref()).collect();
        let all_arrived = robots.iter().all(|r| r.outcome == Outcome::Success);
        let makespan = all_arrived.then(|| {
            places
                .iter()
                .filter_map(|t| t.arrived_at)
                .max()
                .unwrap_or(0)
        });
        let sum_of_costs = all_arrived.then(|| {
            places
                .iter()
                .filter_map(|t| t.arrived_at)
                .map(u64::from)
                .sum()
        });
        let makespan_lower_bound = places
            .iter()
            .map(|t| t.lower_bound_steps)
            .collect::<Option<Vec<u32>>>()
            .map(|b| b.into_iter().max().unwrap_or(0));
        let sum_of_costs_lower_bound = places
            .iter()
            .map(|t| t.lower_bound_steps.map(u64::from))
            .sum();
        let waiting_steps = places.iter().map(|t| u64::from(t.waiting_steps)).sum();
        let robot_collisions = places.iter().map(|t| t.robot_collisions).sum();
        let outcomes: Vec<Outcome> = robots.iter().map(|r| r.outcome).collect();
        TeamRecord {
            seed: team.robot(0).seed(),
            outcome: team_outcome(&outcomes),
            steps: team.steps(),
            makespan,
            sum_of_costs,
            makespan_lower_bound,
            sum_of_costs_lower_bound,
            waiting_steps,
            path_length_px: robots.iter().map(|r| r.path_length_px).sum(),
            collisions: robots.iter().map(|r| r.collisions).sum(),
            robot_collisions,
            deadlock: team.deadlocked(),
            robots,
            wall_time_s: self.clock.elapsed().as_secs_f64(),
            picture: self.recording.trajectory.then(|| TeamPicture {
                scene: team.robot(0).scene().clone(),
                robots: team
                    .robots()
                    .iter()
                    .map(|r| RobotLook {
                        body: r.config().robot.clone(),
                        laser: r.laser().clone(),
                        goal_tolerance_px: r.config().episode.goal_tolerance_px,
                    })
                    .collect(),
                mover_tracks: self.mover_tracks,
            }),
        }
    }
}

impl Evaluator {
    /// Runs the episode of `seed` with `policy`: as its team of one, whose episode is the lone
    /// robot's step for step.
    pub fn run_episode(
        &self,
        policy: &mut dyn Policy,
        seed: u64,
        recording: Recording,
    ) -> Result<EpisodeRecord, RunError> {
        let clock = Instant::now();
        RunError::refuse_team(self.config(), seed)?;
        let mut policy = Alone(policy);
        let rollout = TeamRollout::start(self.config(), self.worlds.team(seed), seed, &mut policy)?;
        let mut recorder = Recorder::start(self.config(), recording, clock, &rollout, true);
        let rollout = recorder.run(rollout, &mut policy, &mut |_| {})?;
        Ok(recorder.lone(rollout))
    }

    /// Runs the team episode of `seed` with `policy`, robot `k`'s policy named `names[k]`.
    /// Keeps what `recording` asks for: every robot's path and the scene (for a picture), every
    /// robot's steps (step logs).
    pub fn run_team_episode(
        &self,
        policy: &mut dyn TeamPolicy,
        names: &[String],
        seed: u64,
        recording: Recording,
    ) -> Result<TeamRecord, RunError> {
        self.watch_team_episode(policy, names, seed, recording, &mut |_| {})
    }

    /// [`Evaluator::run_team_episode`], showing `watch` the team at its start and after every
    /// step (for an animation).
    pub fn watch_team_episode(
        &self,
        policy: &mut dyn TeamPolicy,
        names: &[String],
        seed: u64,
        recording: Recording,
        watch: &mut dyn FnMut(&crate::sim::Team),
    ) -> Result<TeamRecord, RunError> {
        let clock = Instant::now();
        let worlds = self.worlds().team(seed);
        let rollout = TeamRollout::start(self.config(), worlds, seed, policy)?;
        watch(rollout.team());
        let mut recorder = Recorder::start(self.config(), recording, clock, &rollout, false);
        let rollout = recorder.run(rollout, policy, watch)?;
        Ok(recorder.team(&rollout, names))
    }

    /// Runs `options.seeds` as team episodes, each driven by a team policy from `factory`,
    /// keeping every record in seed order: [`Evaluator::stream_team`] into a vector.
    pub fn run_team(
        &self,
        factory: &dyn TeamPolicyFactory,
        options: &EvalOptions,
        cancel: &AtomicBool,
        on_record: &(dyn Fn(&TeamRecord) + Sync),
    ) -> Result<TeamRunResult, PolicyError> {
        Runs::collect(|sink| self.stream_team(factory, options, cancel, on_record, sink))
    }

    /// Runs `options.seeds` as team episodes as [`Evaluator::stream`] runs lone ones: each record
    /// to `on_finish` as it ends (any order), then to `sink` in seed order without its picture
    /// and with its robots' records stripped ([`EpisodeRecord::strip`]), with flat memory; `sink`
    /// returning `false` or `cancel` stops the run after a prefix of seeds.
    pub fn stream_team(
        &self,
        factory: &dyn TeamPolicyFactory,
        options: &EvalOptions,
        cancel: &AtomicBool,
        on_finish: &(dyn Fn(&TeamRecord) + Sync),
        sink: &mut dyn FnMut(TeamRecord) -> bool,
    ) -> Result<RunEnd, PolicyError> {
        let names = factory.names();
        // A team's policy is made afresh for every episode.
        let work = |_: &mut Option<()>, i: usize| {
            let mut policy = factory.make().map_err(Failure::Policy)?;
            let seed = options.seeds.get(i).unwrap_or_default();
            let mut r = self
                .run_team_episode(policy.as_mut(), &names, seed, options.recording_of(seed))
                .map_err(Failure::Run)?;
            on_finish(&r);
            r.robots.iter_mut().for_each(EpisodeRecord::strip);
            r.picture = None;
            Ok(r)
        };
        stream_seeds(options, cancel, &work, sink)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::{MotionKind, MovingConfig};
    use crate::policy::factory;
    use crate::sim::Scenes;

    /// A team's configuration is refused by the lone entry points, one episode at a time and
    /// side by side, with the error a lone episode of it gives (not a policy that left robot 1
    /// without a decision, nor a panic).
    #[test]
    fn a_team_is_refused_where_a_lone_robot_runs() {
        let config = crate::SimConfig {
            robots: vec![crate::config::TeamRobotConfig {
                count: 2,
                ..Default::default()
            }],
            ..Default::default()
        }
        .validate()
        .expect("valid");
        let ev = Evaluator::new(config.clone(), Scenes::MazePerSeed);
        let f = factory("geodesic", config.observation_size()).expect("built in");
        let mut p = f.make().expect("made");
        let team = |e: &RunError| {
            matches!(
                e,
                RunError::Episode {
                    seed: 3,
                    source: crate::sim::EpisodeError::Team { robots: 2 }
                }
            )
        };
        let e = ev
            .run_episode(p.as_mut(), 3, Recording::default())
            .expect_err("a team");
        assert!(team(&e), "{e}");
        let failed = ev.run_side_by_side(
            p.as_mut(),
            &[3, 4],
            2,
            &|_| Recording::default(),
            &mut |_, _| panic!("no episode runs"),
        );
        assert!(
            failed.as_ref().is_some_and(|(i, e)| *i == 0 && team(e)),
            "{failed:?}"
        );
        let e = crate::run::Rollout::new(ev.world(3), 3).expect_err("a team");
        assert!(team(&e), "{e}");
    }

    /// A lone robot's record is its team of one's robot's (the `[[robots]]` form of its
    /// configuration), figure for figure, path for path and step for step, among moving
    /// obstacles too: but for its place in a team, which a lone record does not have, and its
    /// task's length, which a lone robot computes only when it arrived.
    #[test]
    fn a_lone_record_is_its_team_of_ones_robots() {
        let walkers = MovingConfig {
            count: 12,
            motion: MotionKind::RandomWalk,
            ..Default::default()
        };
        let recording = Recording {
            trajectory: true,
            steps: true,
        };
        for moving in [Vec::new(), vec![walkers]] {
            let config = crate::SimConfig {
                moving,
                ..Default::default()
            }
            .validate()
            .expect("valid");
            let lone = Evaluator::new(config.clone(), Scenes::MazePerSeed);
            let team = Evaluator::new(config.as_team(), Scenes::MazePerSeed);
            for name in ["geodesic", "random", "orca"] {
                let f = factory(name, config.observation_size()).expect("built in");
                for seed in 0..4 {
                    let a = lone
                        .run_episode(f.make().expect("made").as_mut(), seed, recording)
                        .expect("runs");
                    let mut policy = crate::policy::PerRobot::new(vec![f.make().expect("made")]);
                    let t = team
                        .run_team_episode(&mut policy, &[name.into()], seed, recording)
                        .expect("runs");
                    let b = &t.robots[0];
                    let at = format!("{name}, seed {seed}");
                    assert_eq!(a.outcome, b.outcome, "{at}");
                    assert_eq!(a.reason, b.reason, "{at}");
                    assert_eq!(a.steps, b.steps, "{at}");
                    assert_eq!(a.collisions, b.collisions, "{at}");
                    assert_eq!(a.path_length_px.to_bits(), b.path_length_px.to_bits());
                    assert_eq!(a.total_reward.to_bits(), b.total_reward.to_bits());
                    assert_eq!(a.spl.to_bits(), b.spl.to_bits(), "{at}");
                    assert_eq!(a.shortest_px, b.shortest_px, "{at}");
                    assert_eq!(a.trajectory, b.trajectory, "{at}");
                    assert_eq!(a.step_log, b.step_log, "{at}");
                    assert_eq!(a.last_readings, b.last_readings, "{at}");
                    assert_eq!(a.dynamic, b.dynamic, "{at}");
                    assert_eq!(a.metrics, b.metrics, "{at}");
                    assert_eq!(
                        Some(&a.mover_tracks),
                        t.picture.as_ref().map(|p| &p.mover_tracks)
                    );
                    assert!(a.team.is_none() && a.world.is_some(), "{at}");
                    assert!(b.team.is_some(), "{at}");
                }
            }
        }
    }
}
