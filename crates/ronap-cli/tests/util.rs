//! Helpers every test module shares: running the binary, reading what it printed and wrote, and
//! the checks of a refused input.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The binary under test.
pub const BIN: &str = env!("CARGO_BIN_EXE_ronap");

/// Runs `ronap` with `args`.
pub fn ronap(args: &[&str]) -> Output {
    Command::new(BIN).args(args).output().expect("ronap runs")
}

/// Bytes as text.
pub fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// What `o` printed on stdout.
pub fn stdout(o: &Output) -> String {
    text(&o.stdout)
}

/// What `o` printed on stderr.
pub fn stderr(o: &Output) -> String {
    text(&o.stderr)
}

/// Stdout of a run that must have succeeded (else the exit code and both streams).
pub fn ok(o: &Output) -> String {
    assert!(
        o.status.success(),
        "exit {:?}\nstdout: {}\nstderr: {}",
        o.status.code(),
        stdout(o),
        stderr(o)
    );
    stdout(o)
}

/// The arguments of `ronap run --policy <policy> <more…> --out <out>`.
pub fn run_args<'a>(policy: &'a str, more: &[&'a str], out: &'a Path) -> Vec<&'a str> {
    with_out(&["run", "--policy", policy], more, out)
}

/// The arguments of `ronap collect --expert <expert> <more…> --out <out>`.
pub fn collect_args<'a>(expert: &'a str, more: &[&'a str], out: &'a Path) -> Vec<&'a str> {
    with_out(&["collect", "--expert", expert], more, out)
}

/// `head`, then `more`, then `--out <out>`.
fn with_out<'a>(head: &[&'a str], more: &[&'a str], out: &'a Path) -> Vec<&'a str> {
    let mut args = head.to_vec();
    args.extend_from_slice(more);
    args.extend(["--out", out.to_str().unwrap()]);
    args
}

/// The repository root.
pub fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// A shipped scenario's file, `name` in the repository's `scenarios/`.
pub fn shipped(name: &str) -> PathBuf {
    repo_root().join("scenarios").join(name)
}

/// A JSON file.
pub fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// The figures in a run directory's `summary.json`.
pub fn summary(dir: &Path) -> serde_json::Value {
    json(&dir.join("summary.json"))["summary"].clone()
}

/// A CSV file as rows of fields, the header first.
pub fn rows(path: &Path) -> Vec<Vec<String>> {
    let mut r = csv::Reader::from_path(path).unwrap();
    let header: Vec<String> = r.headers().unwrap().iter().map(String::from).collect();
    let mut out = vec![header];
    for rec in r.records() {
        out.push(rec.unwrap().iter().map(String::from).collect());
    }
    out
}

/// The index of column `name` in a table from [`rows`].
pub fn col(table: &[Vec<String>], name: &str) -> usize {
    table[0]
        .iter()
        .position(|h| h == name)
        .unwrap_or_else(|| panic!("no column {name}"))
}

/// Runs `args` and checks the refusal: exit code 2, one line on stderr naming each of `names`,
/// no panic. Returns the line.
pub fn assert_rejected(args: &[&str], names: &[&str]) -> String {
    let o = ronap(args);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
    assert_eq!(
        err.trim_end().lines().count(),
        1,
        "{args:?}: not one line: {err}"
    );
    for n in names {
        assert!(err.contains(n), "{args:?}: {err:?} does not name {n:?}");
    }
    assert!(!err.contains("panicked"), "{args:?}: {err}");
    err
}

/// [`assert_rejected`], and `out` was not created.
pub fn assert_rejected_leaving_nothing(args: &[&str], names: &[&str], out: &Path) {
    assert_rejected(args, names);
    assert!(!out.exists(), "{args:?} created {}", out.display());
}

/// [`assert_rejected`], and when `out` is given, neither it nor anything else in its directory
/// was created.
pub fn assert_rejected_in_empty_dir(args: &[&str], names: &[&str], out: Option<&Path>) {
    assert_rejected(args, names);
    if let Some(out) = out {
        assert!(!out.exists(), "{args:?} left {}", out.display());
        let leftovers: Vec<_> = std::fs::read_dir(out.parent().unwrap()).unwrap().collect();
        assert!(leftovers.is_empty(), "{args:?} left {leftovers:?}");
    }
}
