//! End-to-end tests of long runs: outputs streamed as episodes finish, a run killed with
//! SIGKILL finished by `--resume` to the same bytes, one run per directory, a full disk.

use crate::util::{ok, ronap, rows, run_args, shipped, stderr, stdout, BIN};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// Starts `ronap` with `args` in the background.
fn spawn(args: &[&str]) -> Child {
    Command::new(BIN)
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

/// Waits (up to 60 s) until `done` holds while `child` runs, panicking with `what` otherwise.
fn wait_for(child: &mut Child, what: &str, done: impl Fn() -> bool) {
    let deadline = Instant::now() + Duration::from_secs(60);
    while !done() {
        assert!(Instant::now() < deadline, "timed out waiting for {what}");
        if let Some(status) = child.try_wait().unwrap() {
            panic!("the run ended ({status}) before {what}: make it longer");
        }
        std::thread::sleep(Duration::from_millis(10));
    }
}

/// Lines in `path` (0 when it is missing).
fn lines(path: &Path) -> usize {
    std::fs::read(path).map_or(0, |b| b.iter().filter(|&&c| c == b'\n').count())
}

/// The figures of a summary.json without its wall-time fields.
fn summary_without_times(dir: &Path) -> String {
    std::fs::read_to_string(dir.join("summary.json"))
        .unwrap()
        .lines()
        .filter(|l| !l.contains("wall_time_s") && !l.contains("steps_per_second"))
        .collect::<Vec<_>>()
        .join("\n")
}

/// Runs `args` + `--out out_full` to the end; then again into `out_killed`, killed with SIGKILL
/// once its partial episodes.csv holds some rows, and finished with `--resume`. Checks the
/// killed run's partial file and that the resumed run equals the uninterrupted one.
fn kill_and_resume(args: &[&str], files: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    let (full, killed) = (dir.path().join("full"), dir.path().join("killed"));
    let with_out = |out: &PathBuf| {
        let mut a = args.to_vec();
        a.extend(["--out", out.to_str().unwrap()]);
        a.iter().map(|s| s.to_string()).collect::<Vec<_>>()
    };
    let a: Vec<String> = with_out(&full);
    ok(&ronap(&a.iter().map(String::as_str).collect::<Vec<_>>()));

    let a: Vec<String> = with_out(&killed);
    let mut child = spawn(&a.iter().map(String::as_str).collect::<Vec<_>>());
    let partial = killed.join("episodes.csv.partial");
    wait_for(&mut child, "rows in episodes.csv.partial", || {
        lines(&partial) > 2
    });
    child.kill().unwrap();
    child.wait().unwrap();
    assert!(
        !killed.join("episodes.csv").exists(),
        "the run finished before it was killed: make it longer"
    );
    assert!(!killed.join("summary.json").exists());
    // What the killed run left is readable: whole rows, seeds from the first, in order (a torn
    // last line aside).
    let text = std::fs::read_to_string(&partial).unwrap();
    let whole = &text[..text.rfind('\n').unwrap() + 1];
    let mut reader = csv::Reader::from_reader(whole.as_bytes());
    for (k, row) in reader.records().enumerate() {
        assert_eq!(row.unwrap()[0], k.to_string(), "row {k} of {text}");
    }
    // A new run there would throw the finished episodes away: refused, pointing at --resume.
    let a: Vec<String> = with_out(&killed);
    crate::util::assert_rejected(
        &a.iter().map(String::as_str).collect::<Vec<_>>(),
        &["stopped short", "ronap run --resume"],
    );
    assert_eq!(std::fs::read_to_string(&partial).unwrap(), text);

    let o = ronap(&["run", "--resume", killed.to_str().unwrap()]);
    ok(&o);
    assert!(stderr(&o).contains("resuming"), "{}", stderr(&o));
    for file in files {
        assert_eq!(
            std::fs::read(full.join(file)).unwrap(),
            std::fs::read(killed.join(file)).unwrap(),
            "{file} differs after a resume"
        );
    }
    assert_eq!(summary_without_times(&full), summary_without_times(&killed));
    let leftovers: Vec<_> = std::fs::read_dir(&killed)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".partial"))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
}

#[cfg(unix)]
#[test]
fn a_run_killed_with_sigkill_is_resumed_to_the_same_bytes() {
    // About 3 s on two cores here, so the kill lands mid-run on a faster machine too.
    kill_and_resume(
        &[
            "run",
            "--policy",
            "apf",
            "--seeds",
            "20000",
            "--threads",
            "2",
        ],
        &["episodes.csv"],
    );
}

#[cfg(unix)]
#[test]
fn a_team_run_killed_with_sigkill_is_resumed_to_the_same_bytes() {
    // About 30 episodes a second on two cores here (3.5 s): the first rows are flushed after a
    // second (a team episode's rows do not fill a write buffer sooner), well before the end. With
    // the crowd metrics, so each robot's are resumed too.
    let dir = tempfile::tempdir().unwrap();
    let scenario = measuring_crowds(dir.path(), "warehouse-team.toml");
    kill_and_resume(
        &on_two_threads(&scenario, "random", "120"),
        &["episodes.csv", "robots.csv"],
    );
}

/// `ronap run` of `policy` on `scenario` for `seeds` seeds on two threads.
fn on_two_threads<'a>(scenario: &'a Path, policy: &'a str, seeds: &'a str) -> [&'a str; 9] {
    let scenario = scenario.to_str().unwrap();
    [
        "run",
        "--scenario",
        scenario,
        "--policy",
        policy,
        "--seeds",
        seeds,
        "--threads",
        "2",
    ]
}

/// A shipped scenario with the crowd metrics asked for, written into `dir`.
fn measuring_crowds(dir: &Path, name: &str) -> PathBuf {
    let text = std::fs::read_to_string(shipped(name)).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, format!("{text}\n[metrics]\ncrowd = true\n")).unwrap();
    path
}

#[cfg(unix)]
#[test]
fn a_run_measuring_crowd_metrics_is_resumed_to_the_same_bytes() {
    let dir = tempfile::tempdir().unwrap();
    // A lone robot among pedestrians: about 2000 episodes a second on two cores here, so 1.5 s
    // (the first rows are written within 0.1 s), and the kill lands mid-run on a faster machine.
    // (A team's run, with each robot's metrics in robots.csv, is the team test's above.)
    let scenario = measuring_crowds(dir.path(), "maze-pedestrians.toml");
    kill_and_resume(
        &on_two_threads(&scenario, "geodesic-wait", "3000"),
        &["episodes.csv"],
    );
}

#[test]
fn crowd_metrics_reach_every_output_and_bad_values_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let scenario = measuring_crowds(dir.path(), "maze-pedestrians.toml");
    let out = dir.path().join("run");
    let o = ronap(&[
        "run",
        "--scenario",
        scenario.to_str().unwrap(),
        "--policy",
        "geodesic-wait",
        "--seeds",
        "12",
        "--out",
        out.to_str().unwrap(),
    ]);
    let table = ok(&o);
    let names = [
        "time_to_goal",
        "intrusion_ratio",
        "min_separation_px",
        "ttc_min",
        "path_irregularity",
        "jerk",
    ];
    let episodes = rows(&out.join("episodes.csv"));
    let summary = crate::util::summary(&out);
    let means = summary["metrics"].as_array().unwrap();
    for (i, name) in names.iter().enumerate() {
        assert!(table.contains(name), "{name} missing from\n{table}");
        let c = crate::util::col(&episodes, name);
        assert_eq!(means[i]["name"], *name);
        // The mean in summary.json is the mean of the column (written to a few decimals).
        let values: Vec<f64> = episodes[1..]
            .iter()
            .filter(|r| !r[c].is_empty())
            .map(|r| r[c].parse().unwrap())
            .collect();
        assert_eq!(means[i]["episodes"], values.len());
        if !values.is_empty() {
            let mean = values.iter().sum::<f64>() / values.len() as f64;
            let written = means[i]["mean"].as_f64().unwrap();
            assert!(
                (mean - written).abs() < 1e-3 * written.abs().max(1.0),
                "{name}"
            );
        }
    }
    // Without [metrics] the outputs have none of it.
    let plain = dir.path().join("plain");
    let pedestrians = shipped("maze-pedestrians.toml");
    ok(&ronap(&[
        "run",
        "--scenario",
        pedestrians.to_str().unwrap(),
        "--policy",
        "geodesic-wait",
        "--seeds",
        "3",
        "--out",
        plain.to_str().unwrap(),
    ]));
    assert!(!std::fs::read_to_string(plain.join("episodes.csv"))
        .unwrap()
        .contains("intrusion_ratio"));
    assert!(crate::util::summary(&plain).get("metrics").is_none());
    // A bad value: one line naming the file, the line, the key and the value.
    let bad = dir.path().join("bad.toml");
    std::fs::write(&bad, "[metrics]\ncrowd = true\ndiscomfort_px = -2.0\n").unwrap();
    crate::util::assert_rejected(
        &[
            "run",
            "--scenario",
            bad.to_str().unwrap(),
            "--policy",
            "geodesic",
            "--seeds",
            "1",
        ],
        &["bad.toml:3", "metrics.discomfort_px", "-2"],
    );
}

#[test]
fn resuming_a_finished_run_says_so_and_changes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("r");
    ok(&ronap(&run_args("geodesic", &["--seeds", "5"], &out)));
    let before = std::fs::read(out.join("summary.json")).unwrap();
    let o = ronap(&["run", "--resume", out.to_str().unwrap()]);
    let text = ok(&o);
    assert!(text.contains("already complete (5 episodes)"), "{text}");
    assert_eq!(std::fs::read(out.join("summary.json")).unwrap(), before);
    assert_eq!(rows(&out.join("episodes.csv")).len(), 6);

    // A plan of another schema is refused by name; so is a directory without one, and other
    // flags beside --resume.
    let plan = out.join("run.json");
    let text = std::fs::read_to_string(&plan).unwrap();
    std::fs::write(
        &plan,
        text.replace("\"schema_version\": 1", "\"schema_version\": 99"),
    )
    .unwrap();
    crate::util::assert_rejected(
        &["run", "--resume", out.to_str().unwrap()],
        &["run.json", "schema_version 99"],
    );
    std::fs::remove_file(&plan).unwrap();
    crate::util::assert_rejected(
        &["run", "--resume", out.to_str().unwrap()],
        &["cannot resume", "run.json"],
    );
    crate::util::assert_rejected(
        &["run", "--resume", out.to_str().unwrap(), "--seeds", "3"],
        &["--resume", "cannot be used with"],
    );
}

#[test]
fn a_second_run_into_a_directory_in_use_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("busy");
    let o = out.to_str().unwrap();
    let mut first = spawn(&[
        "run",
        "--policy",
        "random",
        "--seeds",
        "1000000",
        "--threads",
        "1",
        "--out",
        o,
    ]);
    wait_for(&mut first, "the first run's plan", || {
        out.join("run.json").exists()
    });
    let err = crate::util::assert_rejected(
        &["run", "--policy", "apf", "--seeds", "5", "--out", o],
        &[
            o,
            "in use by another ronap run",
            &format!("pid {}", first.id()),
        ],
    );
    assert!(err.contains("choose another output directory"), "{err}");
    // Nor may a resume take it over.
    crate::util::assert_rejected(&["run", "--resume", o], &[o, "in use"]);
    wait_for(&mut first, "rows in episodes.csv.partial", || {
        lines(&out.join("episodes.csv.partial")) > 2
    });
    first.kill().unwrap();
    first.wait().unwrap();
    // The first run's rows were not mixed with anything: seeds in order from 0.
    let text = std::fs::read_to_string(out.join("episodes.csv.partial")).unwrap();
    let whole = &text[..text.rfind('\n').unwrap() + 1];
    let mut reader = csv::Reader::from_reader(whole.as_bytes());
    for (k, row) in reader.records().enumerate() {
        assert_eq!(row.unwrap()[0], k.to_string());
    }
    // Once the holder is gone, the directory is free again: no longer in use, only holding a
    // run stopped short (which a new run must not throw away)...
    let err = crate::util::assert_rejected(
        &["run", "--policy", "apf", "--seeds", "3", "--out", o],
        &[o, "stopped short", "--resume"],
    );
    assert!(!err.contains("in use"), "{err}");
    // ...and --force replaces it.
    ok(&ronap(&[
        "run", "--policy", "apf", "--seeds", "3", "--out", o, "--force",
    ]));
    assert_eq!(rows(&out.join("episodes.csv")).len(), 4);
}

/// A 64 KiB tmpfs mounted for the length of a test (root only).
struct SmallDisk(PathBuf);

impl SmallDisk {
    fn mount(at: &Path) -> Option<Self> {
        std::fs::create_dir_all(at).unwrap();
        let mounted = Command::new("mount")
            .args([
                "-t",
                "tmpfs",
                "-o",
                "size=64k",
                "tmpfs",
                at.to_str().unwrap(),
            ])
            .stderr(Stdio::null())
            .status()
            .is_ok_and(|s| s.success());
        mounted.then(|| Self(at.to_path_buf()))
    }
}

impl Drop for SmallDisk {
    fn drop(&mut self) {
        let _ = Command::new("umount").arg(&self.0).status();
    }
}

#[cfg(target_os = "linux")]
#[test]
fn a_full_disk_is_one_clear_error_and_leaves_no_half_written_file() {
    let dir = tempfile::tempdir().unwrap();
    let Some(disk) = SmallDisk::mount(&dir.path().join("small")) else {
        eprintln!("skipped: cannot mount a tmpfs here (needs root)");
        return;
    };
    let out = disk.0.join("run");
    let o = ronap(&run_args(
        "random",
        &["--seeds", "20000", "--max-steps", "20"],
        &out,
    ));
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}\n{}", stdout(&o));
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    for part in [
        "No space left on device",
        "finished episodes are kept",
        "free some space",
        "--resume",
    ] {
        assert!(err.contains(part), "{err:?} lacks {part:?}");
    }
    assert!(!err.contains("panicked"), "{err}");
    // Nothing under a final name: the partial files hold what was finished.
    for name in ["episodes.csv", "timing.csv", "summary.json"] {
        assert!(
            !out.join(name).exists(),
            "{name} was written on a full disk"
        );
    }
    assert!(out.join("episodes.csv.partial").exists());
    drop(disk);
}
