//! A team's evaluation into a run directory: team rows in `episodes.csv`, a row per robot in
//! `robots.csv`, the team and per-robot figures in `summary.json`.

use crate::eval::{
    EvalOptions, Figures, RunEnd, RunResult, Summary, Tally, TeamFigures, TeamRecord,
    TeamRunResult, TeamSummary, TeamTally,
};
use crate::io::atomic::OutputError;
use crate::io::figures;
use crate::io::run_dir::{finish, manifest, restore, timing_row, RunWriter, TIMING_COLUMNS};
use crate::io::team_rows::{robot_columns, robot_rows, team_episode_row, TEAM_COLUMNS};
use crate::job::{animate, RunRequest};
use crate::policy::{PolicyError, TeamPolicyFactory};

/// A finished team evaluation.
#[derive(Debug)]
pub struct TeamEvaluation {
    /// How the run stopped (no records are kept: they went to the run files).
    pub result: TeamRunResult,
    /// The team figures.
    pub team: TeamSummary,
    /// The figures of every robot.
    pub summary: Summary,
    /// The run directory's files could not all be written.
    pub write_error: Option<OutputError>,
}

/// Runs a team evaluation (each episode driven by a team policy from `factory`) and, given a
/// `writer`, writes `episodes.csv` (team rows), `robots.csv` and `timing.csv` row by row in seed
/// order as [`crate::job::evaluate_into`] does, pictures and step logs (one per robot) as episodes
/// finish and `summary.json` at the end.
pub fn evaluate_team_into(
    request: RunRequest<'_>,
    factory: &dyn TeamPolicyFactory,
    on_record: &(dyn Fn(&TeamRecord) + Sync),
) -> Result<TeamEvaluation, PolicyError> {
    let RunRequest {
        evaluator,
        options,
        info,
        writer,
        cancel,
    } = request;
    let mut options = options.clone();
    if let Some(w) = &writer {
        options.recording = w.recording();
        options.steps_of = w.gif_seeds().to_vec();
    }
    let config = evaluator.config();
    let metrics = crate::eval::metric::kinds(config);
    let (mut team, mut robots) = (TeamTally::default(), Tally::measuring(metrics));
    let mut write_error = None;
    let mut streams = None;
    let done = writer.as_ref().map_or(0, RunWriter::done);
    let size = config.team_size();
    if let Some(w) = &writer {
        let plan = w.plan(config, &options, info);
        let strings = |h: &[&str]| Some(h.iter().map(|c| c.to_string()).collect());
        let headers = [
            strings(&TEAM_COLUMNS),
            strings(&TIMING_COLUMNS),
            Some(robot_columns(metrics)),
            Some(figures::team_columns(size, metrics)),
        ];
        streams = Some(w.open(&plan, headers));
        if done > 0 {
            if let Err(e) = restore(&w.dir, done, &mut |row| {
                let (_, t, lone) = figures::parse_team(row, size, metrics.len())?;
                team.add(&t);
                for f in &lone {
                    robots.add(f);
                }
                Ok(())
            }) {
                write_error = Some(e);
            }
        }
    }
    let (robot_steps_before, steps_before) = (team.robot_steps(), robots.steps());
    let end = if write_error.is_some() {
        RunEnd {
            episodes: 0,
            cancelled: false,
            error: None,
            wall_time_s: 0.0,
        }
    } else {
        let rest = EvalOptions {
            seeds: options.seeds.after(done),
            ..options.clone()
        };
        // Each robot's beam count, for its step log's columns.
        let beams: Vec<usize> = (0..config.team_size())
            .map(|k| config.team_robot(k).laser.beams as usize)
            .collect();
        let on_finish = |r: &TeamRecord| {
            if let Some(w) = &writer {
                if w.gif_seeds().contains(&r.seed) {
                    let gif = animate::team(evaluator, r);
                    w.animation(
                        r.seed,
                        r.outcome,
                        gif.as_ref().map(|a| &a.bytes[..]).map_err(Clone::clone),
                    );
                }
                w.team_episode(r, &beams);
            }
            on_record(r);
        };
        evaluator.stream_team(factory, &rest, cancel, &on_finish, &mut |r| {
            let t = TeamFigures::of(&r);
            let lone: Vec<Figures> = r
                .robots
                .iter()
                .map(|x| Figures::of(&x.as_episode(r.seed)))
                .collect();
            if let (Some(s), Some(w)) = (&mut streams, &writer) {
                let rows = [
                    vec![team_episode_row(&r)],
                    vec![timing_row(r.seed, r.wall_time_s).to_vec()],
                    robot_rows(&r, metrics),
                    vec![figures::team_row(r.seed, &t, &lone)],
                ];
                if let Err(e) = s.add(w, &rows) {
                    write_error = Some(e);
                    return false;
                }
            }
            team.add(&t);
            for f in &lone {
                robots.add(f);
            }
            true
        })?
    };
    let result = TeamRunResult {
        records: Vec::new(),
        cancelled: end.cancelled && write_error.is_none(),
        error: end.error,
        wall_time_s: end.wall_time_s,
    };
    let wall = result.wall_time_s;
    let team = team.summary(wall, team.robot_steps() - robot_steps_before);
    let summary = robots.summary(wall, robots.steps() - steps_before);
    if let (Some(w), None) = (&writer, &write_error) {
        let run = RunResult {
            records: Vec::new(),
            cancelled: result.cancelled,
            error: result.error.clone(),
            wall_time_s: wall,
        };
        let mut m = manifest(config, &options, info, &run, &summary);
        m.team = Some(team.clone());
        write_error = finish(w, streams, &m, &run).err();
    }
    Ok(TeamEvaluation {
        result,
        team,
        summary,
        write_error,
    })
}
