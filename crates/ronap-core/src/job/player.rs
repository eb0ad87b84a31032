//! HTML players of episodes (`ronap run --html`, `ronap replay --html`, the disagreements of
//! `ronap compare`): the episode stepped again in the model through the actions it took (from
//! the steps a run recorded, or a step log read back, every logged pose held to the model's),
//! recorded frame by frame into a [`Trace`] that [`crate::render::player`] packs into a page.

use crate::eval::{team_outcome, EpisodeRecord, Evaluator, Outcome, TeamRecord};
use crate::io::{LoggedStep, RunWriter};
use crate::job::replay::drive_team;
use crate::job::{ReplayError, RobotLog};
use crate::render::{
    check_logged_step, player_page, Acted, AnimationError, PlayerPage, Recorder, Trace,
};
use crate::sim::{Action, Episode, Pose};

/// The trace of lone `episode` (as placed) replayed from its logged `steps`, each logged pose
/// held to the model's.
pub fn play_lone(episode: Episode, steps: &[LoggedStep]) -> Result<Trace, AnimationError> {
    let seed = episode.seed();
    let actions: Vec<Action> = steps.iter().map(|s| s.action).collect();
    let poses: Vec<Pose> = steps.iter().map(|s| s.pose).collect();
    let (recorder, episode) = drive_lone(episode, &actions, Some(&poses))?;
    let outcome = Outcome::of(episode.status());
    let headline = lone_headline(&episode, recorder.goals(0), outcome, None);
    Ok(recorder.finish(format!("seed {seed}"), headline))
}

/// The trace of the team episode of `seed` replayed from its robots' `logs` (one for every
/// robot), each logged pose held to the model's.
pub fn play_team(
    evaluator: &Evaluator,
    seed: u64,
    logs: &[RobotLog],
) -> Result<Trace, ReplayError> {
    let mut recorder: Option<Recorder> = None;
    let mut outcomes = Vec::new();
    let mut figures = (0, 0, 0);
    drive_team(evaluator, seed, logs, &mut |team, step| {
        let robots: Vec<&Episode> = team.robots().iter().collect();
        let presence = |k: usize| (team.present(k), team.running(k));
        match (step, recorder.as_mut()) {
            (None, _) => recorder = Some(Recorder::new(&robots, team.movers(), true)),
            (Some(step), Some(r)) => {
                let acted: Vec<Option<Acted>> = step
                    .actions
                    .iter()
                    .enumerate()
                    .map(|(k, a)| {
                        a.map(|action| Acted {
                            action,
                            reward: team.rewards()[k],
                            collided: team.collided(k),
                        })
                    })
                    .collect();
                r.step(&robots, team.movers(), &acted, &presence);
            }
            (Some(_), None) => {}
        }
        outcomes = robots.iter().map(|r| Outcome::of(r.status())).collect();
        figures = (
            team.steps(),
            robots.iter().map(|r| r.collisions()).sum::<u32>(),
            robots.iter().map(|r| r.robot_collisions()).sum::<u32>(),
        );
        Ok(())
    })?;
    let Some(recorder) = recorder else {
        unreachable!("drive_team shows the placed team before it steps");
    };
    let outcome = team_outcome(&outcomes);
    let arrived = outcomes.iter().filter(|o| **o == Outcome::Success).count();
    let headline = vec![
        ("outcome".to_string(), outcome.name().to_string()),
        ("steps".into(), figures.0.to_string()),
        (
            "robots arrived".into(),
            format!("{arrived} of {}", outcomes.len()),
        ),
        ("collisions".into(), figures.1.to_string()),
        ("robot collisions".into(), figures.2.to_string()),
    ];
    Ok(recorder.finish(format!("seed {seed}, {} robots", outcomes.len()), headline))
}

/// Steps lone `episode` through `actions` from its current state, recording every state;
/// `logged`, when given, holds the pose before each action, each to match the model's.
fn drive_lone(
    mut episode: Episode,
    actions: &[Action],
    logged: Option<&[Pose]>,
) -> Result<(Recorder, Episode), AnimationError> {
    if let Some(poses) = logged {
        if poses.len() != actions.len() {
            return Err(AnimationError::Mismatch {
                poses: poses.len(),
                actions: actions.len(),
            });
        }
    }
    let mut recorder = Recorder::new(&[&episode], episode.movers(), false);
    for (k, &action) in actions.iter().enumerate() {
        check_logged_step(&episode, logged, k)?;
        let r = episode.step(action);
        let acted = [Some(Acted {
            action,
            reward: r.reward,
            collided: r.collided,
        })];
        let running = !episode.status().is_done();
        recorder.step(&[&episode], episode.movers(), &acted, &|_| (true, running));
    }
    Ok((recorder, episode))
}

/// The figures above a lone episode's player: its outcome, steps, collisions, path length, total
/// reward, contacts with moving obstacles and the least clearance (among them), goals
/// reached (of `goals`, on a tour) and, from the run's record, SPL and why the policy gave up.
fn lone_headline(
    episode: &Episode,
    goals: usize,
    outcome: Outcome,
    record: Option<&EpisodeRecord>,
) -> Vec<(String, String)> {
    let goals = goals.max(1);
    let mut headline = vec![
        ("outcome".to_string(), outcome.name().to_string()),
        ("steps".into(), episode.steps().to_string()),
        ("collisions".into(), episode.collisions().to_string()),
        (
            "path length".into(),
            format!("{:.1} px", episode.path_length_px()),
        ),
        (
            "total reward".into(),
            format!("{:.3}", episode.total_reward()),
        ),
    ];
    if let Some(d) = episode.dynamic_metrics() {
        headline.push(("moving-obstacle contacts".into(), d.collisions.to_string()));
        let clearance = if d.min_clearance_px.is_finite() {
            format!("{:.1} px", d.min_clearance_px)
        } else {
            "nothing within laser range".into()
        };
        headline.push(("least clearance".into(), clearance));
    }
    if goals > 1 {
        headline.push((
            "goals reached".into(),
            format!("{} of {goals}", episode.goals_reached()),
        ));
    }
    if let Some(r) = record {
        headline.push(("SPL".into(), format!("{:.3}", r.spl)));
        if let Some(reason) = &r.reason {
            headline.push(("why".into(), reason.clone()));
        }
    }
    headline
}

/// The trace of lone episode `record`, whose steps were recorded, run by `policy`.
pub(crate) fn lone_record(
    evaluator: &Evaluator,
    record: &EpisodeRecord,
    policy: &str,
) -> Result<Trace, String> {
    let episode = evaluator
        .worlds()
        .episode(record.seed)
        .map_err(|e| e.to_string())?;
    let actions: Vec<Action> = record.step_log.iter().map(|s| s.action).collect();
    let (recorder, episode) = drive_lone(episode, &actions, None).map_err(|e| e.to_string())?;
    let headline = lone_headline(&episode, recorder.goals(0), record.outcome, Some(record));
    Ok(recorder.finish(format!("seed {}, {policy}", record.seed), headline))
}

/// The trace of team episode `record`, whose robots' steps were recorded, run by `policy`.
pub(crate) fn team_record(
    evaluator: &Evaluator,
    record: &TeamRecord,
    policy: &str,
) -> Result<Trace, String> {
    let logs = RobotLog::of_record(record);
    let mut trace = play_team(evaluator, record.seed, &logs).map_err(|e| e.to_string())?;
    // The run knows what the replay cannot: an infeasible task, a policy that gave up.
    if let Some(first) = trace.headline.first_mut() {
        first.1 = record.outcome.name().to_string();
    }
    if let Some(reason) = record.reason() {
        trace.headline.push(("why".into(), reason.to_string()));
    }
    trace.title = format!("seed {}, {policy}", record.seed);
    Ok(trace)
}

/// The page of one episode's player.
pub fn single_page(trace: Trace) -> Result<Vec<u8>, String> {
    let title = format!("ronap: {}", trace.title);
    let traces = [trace];
    let page = PlayerPage {
        title,
        traces: &traces,
        note: None,
    };
    player_page(&page)
        .map(String::into_bytes)
        .map_err(|e| e.to_string())
}

/// Writes the player of the episode `draw` traces into `writer`'s run, if the run asks for one of
/// that episode (`--html`).
pub(crate) fn write_if_asked(
    writer: &RunWriter,
    seed: u64,
    outcome: Outcome,
    draw: impl FnOnce() -> Result<Trace, String>,
) {
    if writer.wants_player(seed, outcome) {
        let page = draw().and_then(single_page);
        writer.player(seed, outcome, page.as_deref().map_err(Clone::clone));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::Recording;
    use crate::policy::{Builtin, PolicyFactory};
    use crate::sim::Scenes;

    const STEPS: Recording = Recording {
        trajectory: false,
        steps: true,
    };

    #[test]
    fn a_lone_trace_holds_every_logged_pose_and_the_end() {
        let evaluator = Evaluator::new(Default::default(), Scenes::MazePerSeed);
        let mut policy = Builtin::Apf.make().expect("apf");
        let record = evaluator
            .run_episode(policy.as_mut(), 3, STEPS)
            .expect("runs");
        let logged: Vec<LoggedStep> = record
            .step_log
            .iter()
            .map(|s| LoggedStep {
                seed: 3,
                step: s.step,
                pose: s.pose,
                action: s.action,
            })
            .collect();
        let episode = evaluator.worlds().episode(3).expect("placed");
        let trace = play_lone(episode, &logged).expect("replays");
        assert_eq!(trace.frames(), logged.len() + 1);
        for (f, s) in logged.iter().enumerate() {
            let p = trace.position(0, f).expect("frame");
            assert_eq!((p.x, p.y), (s.pose.x, s.pose.y), "frame {f}");
        }
        let end = trace.position(0, logged.len()).expect("last frame");
        assert_eq!((end.x, end.y), (record.end.x, record.end.y));
        assert_eq!(trace.headline[0].1, record.outcome.name());
        // A log moved by a hair is refused at its step.
        let mut bent = logged.clone();
        bent[4].pose.y += 0.01;
        let episode = evaluator.worlds().episode(3).expect("placed");
        assert!(matches!(
            play_lone(episode, &bent),
            Err(AnimationError::Diverged { step: 5, .. })
        ));
        // The page is self-contained: no address to fetch anything from.
        let page = String::from_utf8(single_page(trace).expect("page")).expect("utf-8");
        for outside in ["http:", "https:", "src=", "href=", "@import", "url("] {
            assert!(!page.contains(outside), "the page holds {outside:?}");
        }
    }

    #[test]
    fn a_team_trace_from_a_run_record_is_the_record_replayed() {
        let config = crate::SimConfig::from_toml_str("[[robots]]\ncount = 3")
            .and_then(crate::SimConfig::validate)
            .expect("three robots");
        let size = config.observation_size();
        let evaluator = Evaluator::new(config, Scenes::MazePerSeed);
        let geodesic = crate::policy::factory("geodesic", size).expect("geodesic");
        let team = crate::policy::PerRobotFactory::new(
            vec![geodesic.as_ref(); 3],
            vec!["geodesic".to_string(); 3],
        );
        let mut policy = crate::policy::TeamPolicyFactory::make(&team).expect("policies");
        let names = crate::policy::TeamPolicyFactory::names(&team);
        let record = evaluator
            .run_team_episode(policy.as_mut(), &names, 1, STEPS)
            .expect("runs");
        let trace = team_record(&evaluator, &record, "geodesic").expect("replays");
        assert_eq!(trace.robots(), 3);
        assert_eq!(trace.frames(), record.steps as usize + 1);
        for (k, robot) in record.robots.iter().enumerate() {
            for (f, s) in robot.step_log.iter().enumerate() {
                let p = trace.position(k, f).expect("frame");
                assert_eq!((p.x, p.y), (s.pose.x, s.pose.y), "robot {k} frame {f}");
            }
        }
        assert_eq!(trace.headline[0].1, record.outcome.name());
    }
}
