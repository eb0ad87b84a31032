//! The command line: the input split at NUL bytes into arguments after `ronap`, parsed as the
//! binary parses them (clap's checks of the command definition run too, in this debug-assertion
//! build), and any error rendered as the binary renders it. Every command but `train`: the fuzz
//! build leaves out ronap-cli's `learn` feature (fuzz/Cargo.toml).
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::ffi::OsStr;
use std::os::unix::ffi::OsStrExt;

fuzz_target!(|data: &[u8]| {
    let args = std::iter::once(OsStr::new("ronap"))
        .chain(data.split(|&b| b == 0).map(OsStr::from_bytes))
        .map(|a| a.to_os_string());
    if let Err(e) = ronap_cli::parse(args) {
        let _ = e.render().to_string();
    }
});
