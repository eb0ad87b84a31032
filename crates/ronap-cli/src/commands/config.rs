//! `ronap config`: the whole configuration as TOML, a comment on every field; with `--scenario`
//! and no file, a complete example scenario (static and moving obstacles of every kind).

use crate::args::SimArgs;
use anyhow::Result;
use clap::Args;
use std::io::Write;
use std::process::ExitCode;

/// Arguments of `ronap config`.
#[derive(Args, Debug)]
pub struct ConfigArgs {
    #[command(flatten)]
    sim: SimArgs,
}

/// Runs `ronap config`.
pub fn run(args: ConfigArgs) -> Result<ExitCode> {
    let config = if args.sim.wants_example() {
        ronap_core::SimConfig::example_scenario().validate()?
    } else {
        args.sim.config()?
    };
    let mut stdout = std::io::stdout().lock();
    stdout.write_all(config.to_documented_toml().as_bytes())?;
    Ok(ExitCode::SUCCESS)
}
