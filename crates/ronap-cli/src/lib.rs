//! `ronap`: the command-line front of ronap-core. Parses arguments, writes files, reports errors;
//! the model itself lives in the core. A library only so that the fuzz target and tests reach the
//! argument parser ([`parse`]); the binary is [`main`].

mod args;
mod commands;
mod output;
mod py_policy;
mod tui;

use clap::{Parser, Subcommand};
use commands::{bench, collect, compare, config, maze, replay, run, view};
use std::io::Write;
use std::process::ExitCode;

/// Exit code for bad input: arguments, config files, maps, output paths.
const EXIT_BAD_INPUT: u8 = 2;

/// What `ronap --version` prints after the name: the package version and the version of the
/// simulation model ([`ronap_core::MODEL_VERSION`]), which says whether recorded runs replay.
static VERSION: std::sync::LazyLock<String> = std::sync::LazyLock::new(|| {
    format!(
        "{} (model version {})",
        env!("CARGO_PKG_VERSION"),
        ronap_core::MODEL_VERSION
    )
});

/// Fast robot-navigation analysis on the RoNAP model: seeded mazes, a 17-beam laser, discrete
/// actions, random start and goal.
#[derive(Parser, Debug)]
#[doc(hidden)]
#[command(
    name = "ronap",
    version = VERSION.as_str(),
    about,
    after_help = "Guides and reference: docs/README.md (getting started, a guide per task, every \
                  command, configuration field and output column).",
    propagate_version = true,
    allow_negative_numbers = true
)]
pub struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Draw a scene: a PNG (white floor, black walls) with --out, else the maze as text.
    Maze(maze::MazeArgs),
    /// Evaluate a policy over many seeded episodes: summary table, CSV logs, PNG trajectories.
    #[command(
        override_usage = "ronap run [OPTIONS] --policy <NAME>\n       ronap run --resume <DIR>"
    )]
    Run(run::RunArgs),
    /// Compare policies on the same seeds: success with 95% intervals, paired tests (McNemar,
    /// bootstrap), pictures and a report (report.html, report.md).
    Compare(compare::CompareArgs),
    /// Record (observation, action) rows for behaviour cloning, in the data-log format: labelled
    /// by an expert planner, or by you at the keys (--human, the paper's Collect Data screen).
    Collect(collect::CollectArgs),
    /// Watch a policy drive one episode live in the terminal: the paper's first-person view, the
    /// whole scene with M, pause, speed and restart keys.
    View(view::ViewArgs),
    /// Render a logged episode (`ronap run --log-steps`) as an animated GIF, from above or
    /// first-person.
    Replay(replay::ReplayArgs),
    /// Measure how fast this machine steps a scene and what its laser costs per ray.
    Bench(bench::BenchArgs),
    /// Train a policy network (behaviour cloning or DQN) and write its weights file.
    #[cfg(feature = "learn")]
    Train(commands::train::TrainArgs),
    /// Print the whole configuration as TOML, a comment on every field: a file to copy and edit
    /// for --config.
    Config(config::ConfigArgs),
}

/// Parses a command line (`args[0]` is the program's name), as `ronap` does, without running it.
pub fn parse<I, T>(args: I) -> Result<Cli, clap::Error>
where
    I: IntoIterator<Item = T>,
    T: Into<std::ffi::OsString> + Clone,
{
    Cli::try_parse_from(args)
}

/// The `ronap` command: parses the process's arguments and runs the command they name.
pub fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            use clap::error::ErrorKind;
            if matches!(e.kind(), ErrorKind::DisplayHelp | ErrorKind::DisplayVersion) {
                let _ = e.print();
                return ExitCode::SUCCESS;
            }
            // One line that names the flag and the value (and clap's tip, if any); the usage
            // block only when nothing was given.
            let text = e.render().to_string();
            if e.kind() == ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand {
                eprint!("{text}");
            } else {
                let line: Vec<&str> = text
                    .lines()
                    .take_while(|l| {
                        !l.starts_with("Usage:") && !l.starts_with("For more information")
                    })
                    .map(str::trim)
                    .filter(|l| !l.is_empty())
                    .collect();
                eprintln!("{}", line.join(" "));
            }
            return ExitCode::from(EXIT_BAD_INPUT);
        }
    };
    let result = match cli.command {
        Command::Maze(args) => maze::run(args),
        Command::Run(args) => run::run(args),
        Command::Compare(args) => compare::run(args),
        Command::View(args) => view::run(args),
        Command::Replay(args) => replay::run(args),
        Command::Bench(args) => bench::run(args),
        Command::Collect(args) => collect::run(args),
        #[cfg(feature = "learn")]
        Command::Train(args) => commands::train::run(args),
        Command::Config(args) => config::run(args),
    };
    match result {
        Ok(code) => code,
        Err(e) if output::is_broken_pipe(&e) => ExitCode::SUCCESS,
        Err(e) => {
            let mut stderr = std::io::stderr().lock();
            // Each cause once: error types that already print their source are not repeated.
            let mut message = String::new();
            for cause in e.chain().map(|c| c.to_string()) {
                if !message.contains(&cause) {
                    if !message.is_empty() {
                        message.push_str(": ");
                    }
                    message.push_str(&cause);
                }
            }
            let _ = writeln!(stderr, "error: {message}");
            ExitCode::from(EXIT_BAD_INPUT)
        }
    }
}
