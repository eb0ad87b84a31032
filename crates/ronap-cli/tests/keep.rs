//! Runs that keep their word: stopped by `timeout` with the summary kept, a finished run never
//! overwritten without `--force`, failed resumes that change nothing, no lock or partial file
//! after a clean end, and a crash-consistency suite (SIGKILL at many moments, and every write
//! boundary failed in turn through the `RONAP_FAULT` hook) whose runs always resume to the bytes
//! of an uninterrupted run.

use crate::util::{assert_rejected, json, ok, repo_root, ronap, stderr, BIN};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// Every file under `dir` (relative path to bytes).
fn snapshot(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    fn walk(root: &Path, dir: &Path, out: &mut BTreeMap<PathBuf, Vec<u8>>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                walk(root, &path, out);
            } else {
                let rel = path.strip_prefix(root).unwrap().to_path_buf();
                out.insert(rel, std::fs::read(&path).unwrap());
            }
        }
    }
    let mut out = BTreeMap::new();
    walk(dir, dir, &mut out);
    out
}

/// The names of the files directly in `dir`.
fn names(dir: &Path) -> Vec<String> {
    let mut n: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    n.sort();
    n
}

/// A summary.json without its wall-time figures (which differ from run to run).
fn figures(dir: &Path) -> serde_json::Value {
    let mut s = json(&dir.join("summary.json"));
    for key in ["wall_time_s", "steps_per_second", "episodes_per_second"] {
        if let Some(m) = s["summary"].as_object_mut() {
            m.remove(key);
        }
    }
    s
}

/// `ronap run` with `args` + `--out out`.
fn run_into(args: &[&str], out: &Path) -> std::process::Output {
    let mut a = args.to_vec();
    a.extend(["--out", out.to_str().unwrap()]);
    ronap(&a)
}

#[cfg(unix)]
#[test]
fn timeout_stops_a_run_with_its_summary_kept_every_time() {
    // `timeout` signals the process and then its process group: two signals at once, which
    // must count as one. 50 tries of each signal, ten runs at a time, each signalled after 0.5 s:
    // ronap has its handler in place within 0.02 s on an idle machine (20 of 20 such runs kept
    // their summary), and this leaves room for ten starting at once beside other tests.
    let dir = tempfile::tempdir().unwrap();
    for signal in ["TERM", "INT"] {
        for round in 0..5 {
            let children: Vec<_> = (0..10)
                .map(|i| {
                    let out = dir.path().join(format!("{signal}-{round}-{i}"));
                    let child = Command::new("timeout")
                        .args(["-s", signal, "0.5", BIN, "run", "--policy", "random"])
                        .args(["--seeds", "100000000", "--threads", "1", "--out"])
                        .arg(&out)
                        .stdout(Stdio::null())
                        .stderr(Stdio::piped())
                        .spawn()
                        .unwrap();
                    (out, child)
                })
                .collect();
            for (out, child) in children {
                let o = child.wait_with_output().unwrap();
                let err = stderr(&o);
                assert!(!err.contains("panicked"), "{err}");
                assert!(
                    out.join("summary.json").exists(),
                    "{signal} try {round}: no summary.json in {}: {:?}\n{err}",
                    out.display(),
                    names(&out)
                );
                let s = json(&out.join("summary.json"));
                assert_eq!(s["interrupted"], true);
                // A clean end leaves no lock and no partial file; the exact figures stay for
                // a resume.
                assert_eq!(
                    names(&out),
                    [
                        "episodes.csv",
                        "figures.csv",
                        "run.json",
                        "summary.json",
                        "timing.csv"
                    ],
                    "{signal}"
                );
            }
        }
    }
}

#[test]
fn a_finished_run_is_refused_unless_forced_and_forcing_keeps_other_files() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("r");
    let o = out.to_str().unwrap();
    ok(&run_into(
        &["run", "--policy", "geodesic", "--seeds", "5"],
        &out,
    ));
    // A clean end leaves only the run's files: no lock, no partial file, no figures.
    assert_eq!(
        names(&out),
        ["episodes.csv", "run.json", "summary.json", "timing.csv"]
    );
    let before = snapshot(&out);
    let err = assert_rejected(
        &["run", "--policy", "apf", "--seeds", "5", "--out", o],
        &[o, "finished run", "--force", "--out"],
    );
    assert!(!err.contains("--resume"), "{err}");
    assert_eq!(
        snapshot(&out),
        before,
        "a refused run changed the directory"
    );
    ok(&run_into(
        &["run", "--policy", "apf", "--seeds", "3", "--force"],
        &out,
    ));
    assert_eq!(json(&out.join("summary.json"))["policy"], "apf");
    assert_eq!(crate::util::rows(&out.join("episodes.csv")).len(), 4);

    // A directory of other files: refused, and with --force written into, its files kept.
    let mine = dir.path().join("mine");
    std::fs::create_dir_all(&mine).unwrap();
    std::fs::write(mine.join("notes.txt"), "keep me").unwrap();
    let m = mine.to_str().unwrap();
    assert_rejected(
        &["run", "--policy", "apf", "--seeds", "2", "--out", m],
        &[m, "notes.txt", "--force"],
    );
    assert_eq!(names(&mine), ["notes.txt"]);
    ok(&run_into(
        &["run", "--policy", "apf", "--seeds", "2", "--force"],
        &mine,
    ));
    assert_eq!(
        std::fs::read_to_string(mine.join("notes.txt")).unwrap(),
        "keep me"
    );

    // ronap compare guards its directory the same way.
    let cmp = dir.path().join("cmp");
    let c = cmp.to_str().unwrap();
    let args = [
        "compare", "--policy", "apf", "--policy", "geodesic", "--seeds", "4", "--sheet", "0",
        "--out", c,
    ];
    ok(&ronap(&args));
    let before = snapshot(&cmp);
    assert_rejected(&args, &[c, "compare.json", "--force"]);
    assert_eq!(snapshot(&cmp), before);
    let mut forced = args.to_vec();
    forced.push("--force");
    ok(&ronap(&forced));
}

/// A Python policy file that raises at its first step.
fn failing_policy(dir: &Path) -> String {
    let path = dir.join("fails.py");
    std::fs::write(&path, "def act(obs):\n    raise ValueError('broken')\n").unwrap();
    format!("py:{}:act", path.display())
}

#[test]
fn a_forced_run_that_fails_before_its_first_episode_leaves_the_old_run() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("r");
    ok(&run_into(
        &["run", "--policy", "geodesic", "--seeds", "5", "--png", "2"],
        &out,
    ));
    let before = snapshot(&out);
    let policy = failing_policy(dir.path());
    let o = run_into(
        &[
            "run",
            "--policy",
            &policy,
            "--seeds",
            "5",
            "--force",
            "--threads",
            "1",
        ],
        &out,
    );
    assert!(!o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("broken"), "{}", stderr(&o));
    assert_eq!(snapshot(&out), before, "the failed run touched the old one");
}

/// Runs `policy` over many seeds on one thread into `out`, interrupted (SIGINT) once it has
/// finished some episodes.
#[cfg(unix)]
fn interrupted(policy: &str, out: &Path) {
    let mut child = Command::new(BIN)
        .args([
            "run",
            "--policy",
            policy,
            "--seeds",
            "100000000",
            "--threads",
            "1",
        ])
        .arg("--out")
        .arg(out)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let partial = out.join("episodes.csv.partial");
    let deadline = Instant::now() + Duration::from_secs(60);
    while std::fs::read(&partial).map_or(0, |b| b.iter().filter(|&&c| c == b'\n').count()) < 3 {
        assert!(
            Instant::now() < deadline,
            "no rows in {}",
            partial.display()
        );
        assert!(child.try_wait().unwrap().is_none(), "the run ended early");
        std::thread::sleep(Duration::from_millis(10));
    }
    Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    child.wait().unwrap();
    assert_eq!(json(&out.join("summary.json"))["interrupted"], true);
}

#[cfg(unix)]
#[test]
fn a_failed_resume_leaves_the_directory_as_it_was() {
    let dir = tempfile::tempdir().unwrap();
    // Bad weights: the network file was damaged since the run stopped.
    let weights = dir.path().join("bc.safetensors");
    std::fs::copy(repo_root().join("policies/bc.safetensors"), &weights).unwrap();
    let out = dir.path().join("mlp");
    let policy = format!("mlp:{}", weights.display());
    interrupted(&policy, &out);
    std::fs::write(&weights, b"not a network").unwrap();
    let before = snapshot(&out);
    let o = ronap(&["run", "--resume", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("bc.safetensors"), "{}", stderr(&o));
    assert_eq!(
        snapshot(&out),
        before,
        "a failed resume changed the directory"
    );

    // A Python policy whose file is gone.
    let script = dir.path().join("slow.py");
    std::fs::write(
        &script,
        "import time\ndef act(obs):\n    time.sleep(0.001)\n    return 1\n",
    )
    .unwrap();
    let out = dir.path().join("py");
    let policy = format!("py:{}:act", script.display());
    interrupted(&policy, &out);
    std::fs::remove_file(&script).unwrap();
    let before = snapshot(&out);
    let o = ronap(&["run", "--resume", out.to_str().unwrap()]);
    assert!(!o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("slow.py"), "{}", stderr(&o));
    assert_eq!(
        snapshot(&out),
        before,
        "a failed resume changed the directory"
    );

    // Rows edited by hand: a row written twice (a seed lost, another doubled), or an outcome
    // that no longer matches the exact figures the summary is made from.
    let out = dir.path().join("edited");
    interrupted("geodesic", &out);
    let rows = ["episodes.csv", "episodes.csv.partial"]
        .map(|f| out.join(f))
        .into_iter()
        .find(|f| f.exists())
        .unwrap();
    let text = std::fs::read_to_string(&rows).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let twice = [&lines[..3], &lines[2..]].concat().join("\n") + "\n";
    let outcome = text.replacen("\n1,success,", "\n1,timeout,", 1);
    assert_ne!(outcome, text, "seed 1 did not succeed: {}", lines[2]);
    for (edited, names) in [
        (twice, &["line 4", "seed 1", "seed 2"][..]),
        (outcome, &["line 3", "outcome timeout", "success"]),
    ] {
        std::fs::write(&rows, &edited).unwrap();
        let before = snapshot(&out);
        let o = ronap(&["run", "--resume", out.to_str().unwrap()]);
        assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
        for n in names {
            assert!(stderr(&o).contains(n), "{n:?} not in {}", stderr(&o));
        }
        assert_eq!(snapshot(&out), before, "a refused resume changed the run");
        std::fs::write(&rows, &text).unwrap();
    }
}

/// The run the crash-consistency tests stop and finish.
const CRASH_RUN: [&str; 7] = [
    "run",
    "--policy",
    "geodesic",
    "--seeds",
    "200",
    "--threads",
    "2",
];

/// Checks what a stopped run left in `out` (no final-named file half-written: a run file under
/// its final name is the whole run's), finishes it (`--resume`, or the same run again when it
/// had not written its plan) and checks it equals the uninterrupted run in `full`.
fn finish_and_compare(out: &Path, full: &Path, what: &str) {
    for file in ["episodes.csv", "timing.csv"] {
        if let Ok(bytes) = std::fs::read(out.join(file)) {
            if file == "episodes.csv" {
                assert_eq!(
                    bytes,
                    std::fs::read(full.join(file)).unwrap(),
                    "{what}: {file}"
                );
            } else {
                assert_eq!(
                    bytes.iter().filter(|&&c| c == b'\n').count(),
                    201,
                    "{what}: {file} half-written"
                );
            }
        }
    }
    if out.join("summary.json").exists() {
        assert_eq!(figures(out), figures(full), "{what}: summary.json");
    }
    if out.join("run.json").exists() {
        let o = ronap(&["run", "--resume", out.to_str().unwrap()]);
        assert!(o.status.success(), "{what}: resume failed: {}", stderr(&o));
    } else {
        let o = run_into(&CRASH_RUN, out);
        assert!(
            o.status.success(),
            "{what}: a new run failed: {}",
            stderr(&o)
        );
    }
    assert_eq!(
        std::fs::read(out.join("episodes.csv")).unwrap(),
        std::fs::read(full.join("episodes.csv")).unwrap(),
        "{what}: episodes.csv after finishing"
    );
    assert_eq!(
        figures(out),
        figures(full),
        "{what}: summary.json after finishing"
    );
    assert_eq!(
        names(out),
        ["episodes.csv", "run.json", "summary.json", "timing.csv"],
        "{what}: files left after finishing"
    );
}

#[cfg(unix)]
#[test]
fn a_run_killed_at_any_moment_resumes_to_the_same_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let full = dir.path().join("full");
    let clock = Instant::now();
    ok(&run_into(&CRASH_RUN, &full));
    let span = clock.elapsed().as_secs_f64() * 1.2;
    // 50 moments spread over the run's life (start-up to the last rename), from a fixed stream.
    let mut x: u64 = 0x9E37_79B9_7F4A_7C15;
    for k in 0..50 {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        let at = Duration::from_secs_f64(span * (x % 10_000) as f64 / 10_000.0);
        let out = dir.path().join(format!("killed-{k}"));
        let mut a = CRASH_RUN.to_vec();
        a.extend(["--out", out.to_str().unwrap()]);
        let mut child = Command::new(BIN)
            .args(&a)
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        std::thread::sleep(at);
        let _ = child.kill();
        child.wait().unwrap();
        if !out.exists() {
            std::fs::create_dir_all(&out).unwrap();
        }
        finish_and_compare(&out, &full, &format!("killed at {at:?}"));
    }
}

#[test]
fn every_write_boundary_failing_resumes_to_the_same_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let full = dir.path().join("full");
    ok(&run_into(&CRASH_RUN, &full));
    for kind in ["create", "write", "rename", "remove"] {
        for n in 1.. {
            let out = dir.path().join(format!("{kind}-{n}"));
            let mut a = CRASH_RUN.to_vec();
            a.extend(["--out", out.to_str().unwrap()]);
            let o = Command::new(BIN)
                .args(&a)
                .env("RONAP_FAULT", format!("{kind}:{n}"))
                .output()
                .unwrap();
            let err = stderr(&o);
            assert!(!err.contains("panicked"), "{kind}:{n}: {err}");
            if o.status.success() {
                // Past the last operation of this kind: the run is whole.
                finish_and_compare(&out, &full, &format!("{kind}:{n} (not reached)"));
                assert!(n > 1, "RONAP_FAULT={kind}:1 failed nothing");
                break;
            }
            assert_eq!(o.status.code(), Some(2), "{kind}:{n}: {err}");
            assert!(err.contains("(injected)"), "{kind}:{n}: {err}");
            assert!(!err.contains("free some space") || kind == "write", "{err}");
            if !out.exists() {
                std::fs::create_dir_all(&out).unwrap();
            }
            finish_and_compare(&out, &full, &format!("RONAP_FAULT={kind}:{n}"));
            assert!(n < 100, "{kind}: the run never stops failing");
        }
    }
}

#[test]
fn what_a_killed_write_left_is_gone_once_the_run_finishes() {
    // A process killed while writing a file leaves its temporary (`.ronap-*.partial`, renamed
    // into place only when whole): the kill test above met one after finishing a run.
    let dir = tempfile::tempdir().unwrap();
    let left = ".ronap-k1ll3d.partial";
    let whole = ["episodes.csv", "run.json", "summary.json", "timing.csv"];

    // A directory holding nothing else is empty to a new run, which removes it.
    let out = dir.path().join("new");
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(out.join(left), b"half a fi").unwrap();
    ok(&run_into(
        &["run", "--policy", "geodesic", "--seeds", "5"],
        &out,
    ));
    assert_eq!(names(&out), whole);

    // A run stopped short (a failed write) and resumed.
    let out = dir.path().join("stopped");
    let o = Command::new(BIN)
        .args([
            "run",
            "--policy",
            "geodesic",
            "--seeds",
            "50",
            "--threads",
            "1",
        ])
        .arg("--out")
        .arg(&out)
        .env("RONAP_FAULT", "rename:2")
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    std::fs::write(out.join(left), b"half a fi").unwrap();
    let o = ronap(&["run", "--resume", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(names(&out), whole);
}
