//! The `ronap` binary's integration tests, one test binary with shared helpers ([`util`]): each
//! module drives the binary as a user would and reads back what it printed and wrote.

// Test helpers may panic on setup failures: that is a failed test, as intended.
#![allow(clippy::unwrap_used)]

mod args;
mod cli;
mod compare;
mod keep;
mod kinematics;
mod learn;
mod limits;
mod reference;
mod replay;
mod run;
mod stream;
mod team;
mod tui;
mod util;
