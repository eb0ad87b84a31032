//! One file per subcommand: its flags (clap) and the few lines that hand the validated values to
//! the core and report what came back.

pub mod bench;
pub mod collect;
pub mod compare;
pub mod config;
pub mod maze;
pub mod replay;
pub mod run;
#[cfg(feature = "learn")]
pub mod train;
pub mod view;
