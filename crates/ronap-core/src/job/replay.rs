//! Replaying a team episode from its robots' step logs (`ronap run --log-steps` on a scenario
//! with `[[robots]]`): the episode is placed again from its seed, every robot takes its logged
//! action at each step, each logged pose is held to the model's, and the team is drawn as it goes.

use crate::eval::Evaluator;
use crate::geometry::Point;
use crate::io::LoggedStep;
use crate::render::{
    first_person, same_pose, team_frame, team_gif_writer, Animation, AnimationError, GifOptions,
    GifWriter, View,
};
use crate::run::{RunError, TeamRollout};
use crate::sim::{Action, Pose, Team};
use image::RgbImage;

impl RobotLog {
    /// The logs of every robot of `record`, from the steps it recorded.
    pub(crate) fn of_record(record: &crate::eval::TeamRecord) -> Vec<RobotLog> {
        record
            .robots
            .iter()
            .enumerate()
            .map(|(robot, r)| RobotLog {
                robot,
                steps: r
                    .step_log
                    .iter()
                    .map(|s| LoggedStep {
                        seed: record.seed,
                        step: s.step,
                        pose: s.pose,
                        action: s.action,
                    })
                    .collect(),
            })
            .collect()
    }
}

/// One robot's step log, read back.
#[derive(Clone, Debug, PartialEq)]
pub struct RobotLog {
    /// The robot, from 0 in `[[robots]]` order.
    pub robot: usize,
    /// Its logged steps, in order.
    pub steps: Vec<LoggedStep>,
}

/// A team episode that its logs do not reproduce.
#[derive(Debug, thiserror::Error)]
pub enum ReplayError {
    /// The episode could not be placed again.
    #[error("cannot start the team episode of seed {seed}: {source}")]
    Start {
        /// The seed.
        seed: u64,
        /// Why.
        source: RunError,
    },
    /// A log names a robot the team does not have, or a robot has two logs.
    #[error("robot {robot}: {message}")]
    Robot {
        /// The robot.
        robot: usize,
        /// What is wrong.
        message: String,
    },
    /// A logged pose is not where the model, stepping every robot's logged actions, puts it.
    #[error(
        "robot {robot}, step {step}: the log has the robot at ({:.3}, {:.3}, {:.3} deg) but \
         stepping the logged actions from the episode's start puts it at ({:.3}, {:.3}, {:.3} \
         deg): the logs do not come from this scene and configuration, or not all of the \
         episode's robots' logs were given",
        logged.x, logged.y, logged.z_deg, model.x, model.y, model.z_deg
    )]
    Diverged {
        /// The robot.
        robot: usize,
        /// The team step (1-based) whose starting pose differs.
        step: u32,
        /// The pose in the log.
        logged: Pose,
        /// The pose the model gives.
        model: Pose,
    },
    /// A robot's episode ended (or it was taken out) before its log did.
    #[error(
        "robot {robot}, step {step}: its episode already ended ({status}) but its log goes on"
    )]
    EndedEarly {
        /// The robot.
        robot: usize,
        /// The team step (1-based) the model could not take.
        step: u32,
        /// How the model's episode of the robot ended.
        status: &'static str,
    },
    /// The frames could not be drawn or encoded.
    #[error(transparent)]
    Animation(#[from] AnimationError),
}

/// Replays team episode `seed` of `evaluator` from `logs` (one for every robot of the team) and
/// draws it every `options.stride` steps: from above at `options.scale`, as the run's `--gif`
/// drew it, or as robot `options.follow` sees it (the first-person view of a lone robot's
/// replay). A robot whose log ends while it still runs gives up there, as its policy did.
pub fn replay_team(
    evaluator: &Evaluator,
    seed: u64,
    logs: &[RobotLog],
    options: &GifOptions,
) -> Result<Animation, ReplayError> {
    let stride = options.stride.max(1);
    if options.view == View::FirstPerson && options.follow >= logs.len() {
        return Err(ReplayError::Robot {
            robot: options.follow,
            message: format!(
                "the view follows it, but the team has {} robots",
                logs.len()
            ),
        });
    }
    let frame = |team: &Team, paths: &[Vec<Point>]| match options.view {
        View::TopDown => team_frame(team, paths, options.scale),
        View::FirstPerson => first_person(team.robot(options.follow), options.size_px),
    };
    let mut paths: Vec<Vec<Point>> = Vec::new();
    // Each frame is written when the next one is known, so the last can be held longer.
    let mut drawing: Option<(GifWriter<Vec<u8>>, RgbImage)> = None;
    let mut size = (0, 0);
    let last = drive_team(evaluator, seed, logs, &mut |team, step| {
        let Some(step) = step else {
            paths = (0..team.robots().len())
                .map(|k| vec![team.robot(k).pose().position()])
                .collect();
            let first = frame(team, &paths);
            size = first.dimensions();
            // A first-person frame has a lone robot's colours only.
            let robots = match options.view {
                View::TopDown => team.robots().len(),
                View::FirstPerson => 1,
            };
            drawing = Some((team_gif_writer(size.0, size.1, robots)?, first));
            return Ok(());
        };
        for (k, path) in paths.iter_mut().enumerate() {
            let p = team.robot(k).pose().position();
            if team.present(k) && path.last() != Some(&p) {
                path.push(p);
            }
        }
        // The run drew its last frame when the team was done; robots that gave up after the
        // last logged step leave it running here, and the run drew no frame for that step.
        if step.number % stride == 0 || (step.number == step.last && step.finished) {
            if let Some((writer, pending)) = &mut drawing {
                let frame = frame(team, &paths);
                writer
                    .add(pending, options.frame_delay_cs)
                    .map_err(AnimationError::from)?;
                *pending = frame;
            }
        }
        Ok(())
    })?;
    let Some((mut writer, pending)) = drawing else {
        unreachable!("drive_team shows the placed team before it steps");
    };
    writer
        .add(&pending, options.last_frame_delay_cs)
        .map_err(AnimationError::from)?;
    let frames = writer.frames();
    let bytes = writer.finish().map_err(AnimationError::from)?;
    Ok(Animation {
        bytes,
        frames,
        steps: last as usize,
        size,
    })
}

/// One step of a team replay, as [`drive_team`] shows it.
pub(crate) struct ReplayStep<'a> {
    /// The team step just taken, from 1.
    pub number: u32,
    /// The last logged team step.
    pub last: u32,
    /// Whether every robot's episode is over (or its policy gave up).
    pub finished: bool,
    /// Each robot's action in this step (`None`: it did not act).
    pub actions: &'a [Option<Action>],
}

/// What a team replay shows each state to: the team, and the step that led there (`None` for the
/// team as placed).
pub(crate) type TeamWatch<'a> =
    dyn FnMut(&Team, Option<ReplayStep<'_>>) -> Result<(), ReplayError> + 'a;

/// Steps team episode `seed` of `evaluator` through `logs` (one for every robot of the team),
/// holding every logged pose to the model's, and shows `watch` the placed team (with `None`) and
/// the team after each step. A robot whose log ends while it still runs gives up there, as its
/// policy did. Returns the last logged step.
pub(crate) fn drive_team(
    evaluator: &Evaluator,
    seed: u64,
    logs: &[RobotLog],
    watch: &mut TeamWatch<'_>,
) -> Result<u32, ReplayError> {
    let mut rollout = TeamRollout::placed(evaluator.config(), evaluator.worlds().team(seed), seed)
        .map_err(|source| ReplayError::Start { seed, source })?;
    let n = rollout.team().robots().len();
    let mut by_robot: Vec<Option<&[LoggedStep]>> = vec![None; n];
    for log in logs {
        let slot = by_robot
            .get_mut(log.robot)
            .ok_or_else(|| ReplayError::Robot {
                robot: log.robot,
                message: format!("the team has {n} robots"),
            })?;
        if slot.replace(&log.steps).is_some() {
            return Err(ReplayError::Robot {
                robot: log.robot,
                message: "two logs given".into(),
            });
        }
    }
    if let Some(robot) = by_robot.iter().position(Option::is_none) {
        return Err(ReplayError::Robot {
            robot,
            message: format!(
                "no log given: a team episode is replayed from every robot's log ({n} robots)"
            ),
        });
    }
    let last = logs
        .iter()
        .filter_map(|l| l.steps.last().map(|s| s.step))
        .max()
        .unwrap_or(0);
    watch(rollout.team(), None)?;
    let mut next = vec![0usize; n];
    for step in 1..=last {
        let mut actions: Vec<Option<Action>> = vec![None; n];
        for (k, log) in by_robot.iter().enumerate() {
            let team = rollout.team();
            let due = log.and_then(|l| l.get(next[k])).filter(|s| s.step == step);
            let Some(logged) = due else {
                if team.running(k) && log.is_some_and(|l| next[k] >= l.len()) {
                    rollout.retire(k);
                }
                continue;
            };
            let robot = team.robot(k);
            if !team.running(k) {
                return Err(ReplayError::EndedEarly {
                    robot: k,
                    step,
                    status: robot.status().name(),
                });
            }
            if !same_pose(logged.pose, robot.pose()) {
                return Err(ReplayError::Diverged {
                    robot: k,
                    step,
                    logged: logged.pose,
                    model: robot.pose(),
                });
            }
            actions[k] = Some(logged.action);
            next[k] += 1;
        }
        rollout.step(&actions);
        let shown = ReplayStep {
            number: step,
            last,
            finished: rollout.finished(),
            actions: &actions,
        };
        watch(rollout.team(), Some(shown))?;
    }
    for (k, log) in by_robot.iter().enumerate() {
        let left = log.map_or(0, |l| l.len() - next[k].min(l.len()));
        if left > 0 {
            return Err(ReplayError::Robot {
                robot: k,
                message: format!(
                    "{left} logged steps were not replayed: a log's steps are numbered by team \
                     step, 1, 2, 3, ... while the robot runs"
                ),
            });
        }
    }
    Ok(last)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::TeamRobotConfig;
    use crate::eval::{Outcome, Recording};
    use crate::policy::{factory, PerRobotFactory, TeamPolicyFactory};
    use crate::sim::Scenes;

    fn logs_of(record: &crate::eval::TeamRecord) -> Vec<RobotLog> {
        RobotLog::of_record(record)
    }

    #[test]
    fn a_team_replayed_from_its_logs_is_the_team_run_again_frame_for_frame() {
        // APF robots get stuck in a maze and give up while the geodesic ones drive on.
        let config = crate::SimConfig {
            robots: vec![
                TeamRobotConfig {
                    count: 2,
                    policy: Some("apf".into()),
                    ..Default::default()
                },
                TeamRobotConfig {
                    count: 3,
                    ..Default::default()
                },
            ],
            ..Default::default()
        }
        .validate()
        .expect("valid");
        let size = config.observation_size();
        let evaluator = Evaluator::new(config, Scenes::MazePerSeed);
        let (apf, geodesic) = (
            factory("apf", size).expect("apf"),
            factory("geodesic", size).expect("geodesic"),
        );
        let team = PerRobotFactory::new(
            vec![
                apf.as_ref(),
                apf.as_ref(),
                geodesic.as_ref(),
                geodesic.as_ref(),
                geodesic.as_ref(),
            ],
            ["apf", "apf", "geodesic", "geodesic", "geodesic"]
                .map(String::from)
                .to_vec(),
        );
        let names = team.names();
        let options = GifOptions {
            stride: 4,
            scale: 0.2,
            ..GifOptions::default()
        };
        let recording = Recording {
            trajectory: false,
            steps: true,
        };
        let mut gave_up = 0;
        for seed in 0..4 {
            let mut policy = team.make().expect("policies");
            let record = evaluator
                .run_team_episode(policy.as_mut(), &names, seed, recording)
                .expect("runs");
            gave_up += record
                .robots
                .iter()
                .filter(|r| r.outcome == Outcome::Stuck)
                .count();
            for (k, robot) in record.robots.iter().enumerate() {
                assert_eq!(
                    robot.step_log.len() as u32,
                    robot.steps,
                    "seed {seed} robot {k}"
                );
            }
            let logs = logs_of(&record);
            let replayed = replay_team(&evaluator, seed, &logs, &options).expect("replays");
            assert_eq!(replayed.steps, record.steps as usize, "seed {seed}");
            // Every robot's log is needed.
            let mut missing = logs.clone();
            missing.remove(2);
            assert!(matches!(
                replay_team(&evaluator, seed, &missing, &options),
                Err(ReplayError::Robot { robot: 2, .. })
            ));
            // A log moved by a hair at one step is caught there, naming the robot.
            let mut bent = logs.clone();
            let step = &mut bent[3].steps[5];
            step.pose.x += 0.01;
            let at = step.step;
            match replay_team(&evaluator, seed, &bent, &options) {
                Err(ReplayError::Diverged { robot: 3, step, .. }) => assert_eq!(step, at),
                other => panic!("seed {seed}: expected robot 3 to diverge, got {other:?}"),
            }
        }
        assert!(
            gave_up > 0,
            "no robot gave up: the test misses the logs that end early"
        );
    }
}
