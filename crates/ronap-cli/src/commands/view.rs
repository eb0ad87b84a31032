//! `ronap view`: watch a policy drive one episode live in the terminal ([`crate::tui::view`]).

use crate::args::{policy_factory, seed, EpisodeArgs, TeamPolicies};
use crate::tui::app;
use crate::tui::team_view::TeamWatch;
use crate::tui::terminal::{self, Session};
use crate::tui::view::{start_episode, Ending, Lone, ViewApp, ViewState};
use anyhow::{Context, Result};
use clap::Args;
use ronap_core::eval::Evaluator;
use ronap_core::sim::Scenes;
use ronap_core::ValidConfig;
use std::process::ExitCode;

/// Arguments of `ronap view`.
#[derive(Args, Debug)]
#[command(
    after_help = "Keys: space pause/resume, + and - faster/slower, m whole scene/first \
    person, s one step when paused, r restart, n next seed, Tab next robot (scenarios with \
    [[robots]]), q or Esc quit (Ctrl-C too)."
)]
pub struct ViewArgs {
    /// Policy to watch, as for `ronap run`: apf (the paper's potential field, Algorithm 3),
    /// geodesic (shortest-path follower), geodesic-wait (geodesic that waits for moving
    /// obstacles ahead), orca (ORCA: avoids what moves), social-force, dwa, random,
    /// coordinated (a team planned together),
    /// mlp:FILE.safetensors[@argmax|@sample:T] (a
    /// trained network, optionally with another decision rule), or
    /// py:FILE.py:FUNCTION (a Python function: observation in, action 0/1/2 out).
    #[arg(long, value_name = "NAME")]
    policy: String,
    /// Episode seed: the scene (unless --maze-seed or --map), start and goal, as `ronap run`'s
    /// seed of the same number.
    #[arg(long, allow_negative_numbers = true, value_name = "SEED", default_value_t = 0, value_parser = seed)]
    seed: u64,
    #[command(flatten)]
    episodes: EpisodeArgs,
    /// Steps per second to start with, 1 to 1000 (the + and - keys change it).
    #[arg(long, allow_negative_numbers = true, value_name = "N", default_value_t = 20, value_parser = clap::value_parser!(u32).range(1..=1000))]
    speed: u32,
}

/// Runs `ronap view`.
pub fn run(args: ViewArgs) -> Result<ExitCode> {
    let (config, scenes, _) = args.episodes.resolve()?;
    if config.team_size() > 0 {
        return run_team(args, config, scenes);
    }
    let factory = policy_factory(&args.policy, &config)?;
    let evaluator = Evaluator::new(config, scenes);
    // Before a policy process starts or the terminal changes: a pipe gets an error, not a hang.
    terminal::require_terminal("view")?;
    let mut policy = factory
        .make()
        .with_context(|| format!("cannot start policy {}", args.policy))?;
    let rollout =
        start_episode(&evaluator, policy.as_mut(), args.seed).map_err(anyhow::Error::msg)?;
    let state = ViewState::new(rollout, &args.policy);
    let mut session = Session::start("view")?;
    let mut view = ViewApp::new(Lone::new(state, &evaluator, policy.as_mut()), args.speed);
    let code = app::run(&mut session, &mut view)?;
    drop(session);
    if let Some(Ending::Failed(why)) = &view.watched.state.ending {
        anyhow::bail!("seed {}: {why}", view.watched.state.episode().seed());
    }
    Ok(code)
}

/// `ronap view` of a scenario with `[[robots]]`: the whole team, each robot in its colour.
fn run_team(args: ViewArgs, config: ValidConfig, scenes: Scenes) -> Result<ExitCode> {
    let policies = TeamPolicies::new(&config, &args.policy)?;
    let evaluator = Evaluator::new(config, scenes);
    terminal::require_terminal("view")?;
    let watch = TeamWatch::start(&evaluator, &policies, args.seed)?;
    let mut session = Session::start("view")?;
    let mut view = ViewApp::new(watch, args.speed);
    let code = app::run(&mut session, &mut view)?;
    drop(session);
    if let Some(Ending::Failed(why)) = &view.watched.state.ending {
        anyhow::bail!("seed {}: {why}", view.watched.state.seed);
    }
    Ok(code)
}
