//! `ronap compare`: several policies on the same seeds, with paired statistics, pictures and a
//! report.

use crate::args::{policy_factory, seed_range, warn_if_not_held_out, EvalArgs, TeamPolicies};
use crate::output::cancel_on_ctrl_c;
use anyhow::{Context, Result};
use clap::{Args, ValueEnum};
use ronap_core::compare::{
    compare, with_runs, CompareError, CompareInfo, CompareOptions, CompareRequest, Contender,
    Progress,
};
use ronap_core::eval::{Evaluator, Seeds};
use ronap_core::io::OutputError;
use ronap_core::policy::{CoordinatedFactory, TeamPolicyFactory, COORDINATED_NAME};
use std::io::Write as _;
use std::path::PathBuf;
use std::process::ExitCode;

/// What results can be broken down by.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum By {
    /// Each seed's scene difficulty: the shortest path's length over the straight line, the
    /// narrowest gap on it and its turns.
    Difficulty,
}

/// Arguments of `ronap compare`.
#[derive(Args, Debug)]
pub struct CompareArgs {
    /// A policy to compare (repeat for each; at least two in all, counting --run): apf, geodesic,
    /// geodesic-wait, orca, social-force, dwa, random, coordinated (teams),
    /// mlp:FILE.safetensors[@RULE] or py:FILE.py:FUNCTION, as for `ronap run`.
    #[arg(long, value_name = "NAME")]
    policy: Vec<String>,
    /// A finished `ronap run` (or a compare's runs/<policy>) directory to reuse instead of running
    /// its policy again: its summary.json must record the same configuration, scenes and seeds.
    /// Its policy joins the comparison if not named by --policy. Repeatable.
    #[arg(long, value_name = "DIR")]
    run: Vec<PathBuf>,
    #[command(flatten)]
    eval: EvalArgs,
    /// Output directory [default: runs/compare-<UTC time>].
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
    /// Write into --out even if it holds a comparison (its runs and report are replaced) or
    /// other files (kept).
    #[arg(long)]
    force: bool,
    /// Also break results down by this [default: none].
    #[arg(long, value_name = "WHAT")]
    by: Option<By>,
    /// Bins per difficulty figure (seeds cut at quantiles into about equal groups).
    #[arg(long, value_name = "N", default_value_t = 3, requires = "by", value_parser = clap::value_parser!(u32).range(1..=20))]
    bins: u32,
    /// Bootstrap resamples for the paired intervals.
    #[arg(long, value_name = "N", default_value_t = 10_000, value_parser = clap::value_parser!(u32).range(100..=1_000_000))]
    resamples: u32,
    /// Seeds in the contact sheet of the most disagreeing seeds (disagreements.png); 0 for none.
    #[arg(long, value_name = "N", default_value_t = 6, value_parser = clap::value_parser!(u32).range(0..=50))]
    sheet: u32,
    /// Side-by-side HTML players (players/seed-<seed>.html, linked from report.html) of the seeds
    /// where one policy succeeded and another failed: all of them, or the N that disagree most
    /// (0: none) [default: all].
    #[arg(long, value_name = "N|all", value_parser = players)]
    players: Option<usize>,
}

/// Parses `--players`: a count, or `all`.
fn players(s: &str) -> Result<usize, String> {
    match s {
        "all" => Ok(usize::MAX),
        _ => s
            .parse::<usize>()
            .map_err(|_| format!("{s:?}: expected a number of seeds or all")),
    }
}

/// Runs `ronap compare`.
pub fn run(args: CompareArgs) -> Result<ExitCode> {
    let (config, scenes, map) = args.eval.episodes.resolve()?;
    // Every policy is made (and every reused run read) before anything runs.
    let chosen = with_runs(&args.policy, &args.run)?;
    let names: Vec<String> = chosen.iter().map(|(n, _)| n.clone()).collect();
    let mut contenders = Vec::new();
    let team = config.team_size() > 0;
    for (name, reuse) in chosen {
        // In a team scenario, `name` drives the robots of entries without a policy of their own.
        let team = if team {
            Some(Box::new(TeamPolicies::new(&config, &name)?) as Box<dyn TeamPolicyFactory>)
        } else {
            None
        };
        let factory = if team.is_some() && name == COORDINATED_NAME {
            Box::new(CoordinatedFactory::new(config.team_size()))
        } else {
            policy_factory(&name, &config.team_robot(0))?
        };
        contenders.push(Contender {
            factory,
            team,
            name,
            reuse,
        });
    }
    let first = args.eval.seeds.first()?;
    let seeds = seed_range(first, args.eval.seeds.seeds)?;
    let end = first + args.eval.seeds.seeds;
    let range = Seeds::Range {
        start: first,
        count: args.eval.seeds.seeds,
    };
    for c in contenders.iter().filter(|c| c.reuse.is_none()) {
        warn_if_not_held_out(&c.name, c.factory.as_ref(), &range);
    }
    let evaluator = Evaluator::new(config.clone(), scenes);
    if team {
        // A team that cannot be placed fails the same way for every seed: say so now.
        ronap_core::sim::Team::new(&config, &evaluator.worlds().team(first), first)
            .with_context(|| format!("cannot start team episodes in this scene (seed {first})"))?;
    } else {
        evaluator
            .worlds()
            .check_start(first)
            .with_context(|| format!("cannot start episodes in this scene (seed {first})"))?;
    }
    let out_dir = args.out.clone().unwrap_or_else(default_out_dir);
    let threads = args.eval.threads.count();
    let options = CompareOptions {
        seeds,
        threads,
        by_difficulty: args.by == Some(By::Difficulty),
        difficulty_bins: args.bins as usize,
        resamples: args.resamples as usize,
        sheet_rows: args.sheet as usize,
        players: args.players.filter(|&n| n != usize::MAX),
        replace: args.force,
    };
    let info = CompareInfo {
        scenes: args.eval.episodes.scenes.spec(&config),
        map,
        command: command_line(),
    };
    let cancel = cancel_on_ctrl_c("finishing running episodes and saving the runs");
    let to_run = contenders.iter().filter(|c| c.reuse.is_none()).count() as u64;
    let bar = crate::output::progress_bar(
        args.eval.seeds.seeds * to_run,
        "{prefix} {wide_bar} {pos}/{len} episodes, {per_sec}, eta {eta}",
        "ronap compare".to_string(),
    );
    let request = CompareRequest {
        evaluator: &evaluator,
        contenders: &contenders,
        options: &options,
        info: &info,
        out: Some(&out_dir),
        cancel: &cancel,
    };
    let result = compare(request, &|p| match p {
        Progress::Running { label, .. } => bar.set_prefix(format!("ronap compare: {label}")),
        Progress::Episode => bar.inc(1),
        Progress::Difficulty { seeds } => bar.set_prefix(format!("difficulty of {seeds} seeds")),
        Progress::Report => bar.set_prefix("pictures and report"),
    });
    bar.finish_and_clear();
    let comparison = match result {
        Ok(c) => c,
        Err(e @ CompareError::Cancelled { .. }) => {
            eprintln!("ronap compare: {e}");
            return Ok(ExitCode::from(130));
        }
        Err(CompareError::Output(e)) => {
            let dir = match &e {
                OutputError::Finished { dir, .. }
                | OutputError::NotARun { dir, .. }
                | OutputError::StoppedShort { dir, .. } => dir.clone(),
                _ => out_dir.clone(),
            };
            return Err(crate::commands::run::refusal_without_resume(e, &dir));
        }
        Err(e) => return Err(e.into()),
    };
    let mut stdout = std::io::stdout().lock();
    writeln!(
        stdout,
        "ronap compare: {}, seeds {first}..{}, {}",
        names.join(" vs "),
        end - 1,
        crate::output::counted(threads as u64, "thread")
    )?;
    write!(stdout, "{}", comparison.table())?;
    writeln!(
        stdout,
        "report in {} (report.html, report.md, compare.png)",
        out_dir.display()
    )?;
    Ok(ExitCode::SUCCESS)
}

/// The command line as typed, quoted for a POSIX shell where needed.
fn command_line() -> String {
    std::env::args()
        .enumerate()
        .map(|(i, a)| {
            let a = if i == 0 { "ronap".to_string() } else { a };
            if !a.is_empty()
                && a.chars()
                    .all(|c| c.is_ascii_alphanumeric() || "-_./:@=,+".contains(c))
            {
                a
            } else {
                format!("'{}'", a.replace('\'', "'\\''"))
            }
        })
        .collect::<Vec<_>>()
        .join(" ")
}

/// `runs/compare-<UTC time>` (`-2`, `-3`... when taken).
fn default_out_dir() -> PathBuf {
    let (y, mo, d, h, mi, s) = crate::output::utc_now();
    crate::output::unused_dir(format!(
        "runs/compare-{y:04}{mo:02}{d:02}-{h:02}{mi:02}{s:02}"
    ))
}
