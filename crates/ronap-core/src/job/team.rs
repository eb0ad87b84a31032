//! A team's evaluation into a run directory: team rows in `episodes.csv`, a row per robot in
//! `robots.csv`, the team and per-robot figures in `summary.json`.

use super::into::{run_into, Episodes, FileRows, Ran, Tallies};
use crate::eval::{
    EvalOptions, Evaluator, Figures, RunEnd, Summary, Tally, TeamFigures, TeamRecord,
    TeamRunResult, TeamSummary, TeamTally,
};
use crate::io::figures;
use crate::io::{finish, manifest, timing_row, RunWriter, TIMING_COLUMNS};
use crate::io::{robot_columns, robot_rows, team_episode_row, OutputError, TEAM_COLUMNS};
use crate::job::{animate, player, RunRequest};
use crate::policy::{PolicyError, TeamPolicyFactory};
use std::sync::atomic::AtomicBool;

/// A finished team evaluation.
#[derive(Debug)]
pub struct TeamEvaluation {
    /// How the run stopped, with the records `keep` kept, in seed order.
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
/// finish and `summary.json` at the end. As [`crate::job::evaluate_into`]: `on_record` hears
/// every episode as it finishes (any order, any thread), `keep` each in seed order on the
/// calling thread, and the records it returns true for are kept in the result.
pub fn evaluate_team_into(
    request: RunRequest<'_>,
    factory: &dyn TeamPolicyFactory,
    on_record: &(dyn Fn(&TeamRecord) + Sync),
    keep: &dyn Fn(&TeamRecord) -> bool,
) -> Result<TeamEvaluation, PolicyError> {
    let config = request.evaluator.config();
    let metrics = crate::eval::metric::kinds(config);
    let mut teams = Teams {
        size: config.team_size(),
        metrics,
        team: TeamTally::default(),
        robots: Tally::measuring(metrics),
        robot_steps_before: 0,
        steps_before: 0,
        keep,
        kept: Vec::new(),
    };
    let episodes = TeamEpisodes {
        evaluator: request.evaluator,
        factory,
        policy: &request.info.policy,
    };
    let Ran {
        result: run,
        options,
        streams,
        mut write_error,
    } = run_into(&request, &episodes, &mut teams, on_record)?;
    let wall = run.wall_time_s;
    let team = teams
        .team
        .summary(wall, teams.team.robot_steps() - teams.robot_steps_before);
    // A team of one is the lone robot: no robot to collide with or deadlock against, and the
    // same figures.
    let summary = Summary {
        among_robots: (teams.size > 1).then(|| teams.team.among_robots()),
        ..teams
            .robots
            .summary(wall, teams.robots.steps() - teams.steps_before)
    };
    if let (Some(w), None) = (&request.writer, &write_error) {
        let mut m = manifest(config, &options, request.info, &run, &summary);
        m.team = Some(team.clone());
        write_error = finish(w, streams, &m, &run).err();
    }
    let result = TeamRunResult {
        records: teams.kept,
        cancelled: run.cancelled,
        error: run.error,
        wall_time_s: wall,
    };
    Ok(TeamEvaluation {
        result,
        team,
        summary,
        write_error,
    })
}

/// Team episodes, by team policies from a factory.
struct TeamEpisodes<'a> {
    evaluator: &'a Evaluator,
    factory: &'a dyn TeamPolicyFactory,
    /// The policy's name, for players' titles.
    policy: &'a str,
}

impl Episodes<TeamRecord> for TeamEpisodes<'_> {
    fn stream(
        &self,
        options: &EvalOptions,
        cancel: &AtomicBool,
        on_finish: &(dyn Fn(&TeamRecord) + Sync),
        sink: &mut dyn FnMut(TeamRecord) -> bool,
    ) -> Result<RunEnd, PolicyError> {
        self.evaluator
            .stream_team(self.factory, options, cancel, on_finish, sink)
    }

    fn files(&self, writer: &RunWriter, r: &TeamRecord) {
        animate::write_if_asked(writer, r.seed, r.outcome, || {
            animate::team(self.evaluator, r)
        });
        player::write_if_asked(writer, r.seed, r.outcome, || {
            player::team_record(self.evaluator, r, self.policy)
        });
        writer.team_episode(r);
    }
}

/// A team's rows and figures: the team's, and every robot's; and the records kept.
struct Teams<'a> {
    size: usize,
    metrics: &'static [crate::eval::metric::Kind],
    team: TeamTally,
    robots: Tally,
    robot_steps_before: u64,
    steps_before: u64,
    keep: &'a dyn Fn(&TeamRecord) -> bool,
    kept: Vec<TeamRecord>,
}

impl Tallies<TeamRecord> for Teams<'_> {
    fn headers(&self) -> [Option<Vec<String>>; 4] {
        let strings = |h: &[&str]| Some(h.iter().map(|c| c.to_string()).collect());
        [
            strings(&TEAM_COLUMNS),
            strings(&TIMING_COLUMNS),
            Some(robot_columns(self.metrics)),
            Some(figures::team_columns(self.size, self.metrics)),
        ]
    }

    fn restore(&mut self, row: &csv::StringRecord) -> Result<(), String> {
        let (_, t, lone) = figures::parse_team(row, self.size, self.metrics.len())?;
        self.team.add(&t);
        for f in &lone {
            self.robots.add(f);
        }
        Ok(())
    }

    fn start(&mut self) {
        (self.robot_steps_before, self.steps_before) =
            (self.team.robot_steps(), self.robots.steps());
    }

    fn add(&mut self, r: TeamRecord, write: &mut dyn FnMut(&[FileRows]) -> bool) -> bool {
        let t = TeamFigures::of(&r);
        let lone: Vec<Figures> = r.robots.iter().map(Figures::of).collect();
        let rows = [
            vec![team_episode_row(&r)],
            vec![timing_row(r.seed, r.wall_time_s).to_vec()],
            robot_rows(&r, self.metrics),
            vec![figures::team_row(r.seed, &t, &lone)],
        ];
        if !write(&rows) {
            return false;
        }
        self.team.add(&t);
        for f in &lone {
            self.robots.add(f);
        }
        if (self.keep)(&r) {
            self.kept.push(r);
        }
        true
    }
}
