//! End-to-end tests of the GIF outputs: `ronap replay` of a step log and `ronap run --gif`, each
//! decoded back and checked frame by frame; bad input refused with one line and no file.

use crate::util::{assert_rejected, ronap, run_args, text};
use image::AnimationDecoder;
use std::path::Path;

/// The frames of a GIF, decoded by the image crate, as full pictures.
fn frames(path: &Path) -> Vec<image::RgbaImage> {
    let file = std::io::BufReader::new(std::fs::File::open(path).unwrap());
    let decoder = image::codecs::gif::GifDecoder::new(file).unwrap();
    decoder
        .into_frames()
        .map(|f| f.unwrap().into_buffer())
        .collect()
}

/// The centre of the pixels of `colour`, if any.
fn centroid(img: &image::RgbaImage, colour: [u8; 3]) -> Option<(f64, f64)> {
    let (mut n, mut x, mut y) = (0.0, 0.0, 0.0);
    for (px, py, p) in img.enumerate_pixels() {
        if p.0[..3] == colour {
            n += 1.0;
            x += f64::from(px);
            y += f64::from(py);
        }
    }
    (n > 0.0).then(|| (x / n, y / n))
}

/// The steps column of `episodes.csv` for `seed`.
fn steps_of(run: &Path, seed: u64) -> usize {
    let mut r = csv::Reader::from_path(run.join("episodes.csv")).unwrap();
    let header = r.headers().unwrap().clone();
    let at = |name: &str| header.iter().position(|h| h == name).unwrap();
    let (seed_at, steps_at) = (at("seed"), at("steps"));
    r.records()
        .map(|r| r.unwrap())
        .find(|r| r[seed_at] == *seed.to_string())
        .map(|r| r[steps_at].parse().unwrap())
        .unwrap()
}

/// A run of seeds 6..=7 under `policy` with step logs, in `dir/run`.
fn logged_run(dir: &Path, policy: &str) -> std::path::PathBuf {
    let run = dir.join("run");
    let o = ronap(&run_args(
        policy,
        &[
            "--seeds",
            "2",
            "--seed-start",
            "6",
            "--threads",
            "1",
            "--log-steps",
        ],
        &run,
    ));
    assert!(o.status.success(), "{}", text(&o.stderr));
    run
}

#[test]
fn replay_draws_one_frame_per_step_with_the_robot_moving() {
    let dir = tempfile::tempdir().unwrap();
    let run = logged_run(dir.path(), "geodesic");
    let log = run.join("steps").join("seed-000007.csv");
    let o = ronap(&["replay", log.to_str().unwrap()]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let gif = run.join("steps").join("seed-000007-top.gif");
    assert!(
        text(&o.stdout).contains("seed-000007-top.gif"),
        "{}",
        text(&o.stdout)
    );
    let steps = steps_of(&run, 7);
    let frames = frames(&gif);
    // The start and the state after every step.
    assert_eq!(frames.len(), steps + 1);
    assert_eq!(frames[0].dimensions(), (400, 400));
    // The robot (path blue, drawn last) moves from the start towards the goal (green).
    let blue = [40, 80, 230];
    let first = centroid(&frames[0], blue).unwrap();
    let last = centroid(&frames[steps], blue).unwrap();
    assert!(
        (first.0 - last.0).hypot(first.1 - last.1) > 40.0,
        "{first:?} -> {last:?}"
    );
    let changed = frames.windows(2).filter(|w| w[0] != w[1]).count();
    assert!(
        changed * 10 >= steps * 9,
        "{changed} of {steps} frames changed"
    );

    // First person, every third step: frames for states 0, 3, 6, ... and the last.
    let out = dir.path().join("first.gif");
    let o = ronap(&[
        "replay",
        log.to_str().unwrap(),
        "--view",
        "first",
        "--stride",
        "3",
        "--size",
        "120",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let frames = self::frames(&out);
    assert_eq!(frames.len(), 1 + steps.div_ceil(3));
    assert_eq!(frames[0].dimensions(), (120, 120));
    assert_ne!(frames[0], frames[frames.len() - 1]);
}

#[test]
fn run_gif_writes_the_chosen_seeds_episode() {
    let dir = tempfile::tempdir().unwrap();
    let run = dir.path().join("run");
    let o = ronap(&run_args(
        "apf",
        &["--seeds", "3", "--seed-start", "6", "--gif", "7"],
        &run,
    ));
    assert!(o.status.success(), "{}", text(&o.stderr));
    let gifs: Vec<_> = std::fs::read_dir(run.join("gif"))
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    assert_eq!(gifs, ["seed-000007-success.gif"]);
    let frames = frames(&run.join("gif").join(&gifs[0]));
    assert_eq!(frames.len(), steps_of(&run, 7) + 1);
    assert_ne!(frames[0], frames[frames.len() - 1]);
}

#[test]
fn a_run_of_another_model_version_is_refused_naming_both() {
    let dir = tempfile::tempdir().unwrap();
    let run = logged_run(dir.path(), "apf");
    let log = run.join("steps").join("seed-000006.csv");
    let summary = run.join("summary.json");
    let mut manifest: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&summary).unwrap()).unwrap();
    let ours = ronap_core::MODEL_VERSION;
    assert_eq!(manifest["model_version"], serde_json::json!(ours));
    let out = dir.path().join("x.gif");
    let args = |summary: &Path| {
        [
            "replay",
            log.to_str().unwrap(),
            "--summary",
            summary.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ]
        .map(String::from)
    };
    // A run of an older model, and one written before summaries recorded it (model 1).
    let older = dir.path().join("older.json");
    manifest["model_version"] = serde_json::json!(ours - 1);
    std::fs::write(&older, manifest.to_string()).unwrap();
    let unrecorded = dir.path().join("unrecorded.json");
    manifest.as_object_mut().unwrap().remove("model_version");
    std::fs::write(&unrecorded, manifest.to_string()).unwrap();
    for (file, theirs) in [(&older, ours - 1), (&unrecorded, 1)] {
        let args = args(file);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        assert_rejected(
            &args,
            &[
                file.to_str().unwrap(),
                &format!("model version {theirs}"),
                &format!("model version {ours}"),
            ],
        );
    }
    assert!(!out.exists());
    // The run's own summary replays.
    let args = args(&summary);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let o = ronap(&args);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(out.exists());
}

#[test]
fn bad_replays_are_named_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let run = logged_run(dir.path(), "apf");
    let log = run.join("steps").join("seed-000006.csv");
    let log = log.to_str().unwrap();
    let out = dir.path().join("x.gif");
    let o = out.to_str().unwrap();
    assert_rejected(&["replay", "/no/such.csv", "--out", o], &["/no/such.csv"]);
    // A directory where a file goes is named as one, with the file it may mean.
    let steps = run.join("steps");
    assert_rejected(
        &["replay", steps.to_str().unwrap(), "--out", o],
        &["is a directory", "such as", "steps/seed-"],
    );
    assert_rejected(
        &[
            "replay",
            log,
            "--summary",
            run.to_str().unwrap(),
            "--out",
            o,
        ],
        &["--summary", "is a directory", "summary.json"],
    );
    let bad = dir.path().join("bad.csv");
    std::fs::write(&bad, "seed,step,x,y,z,action\n6,1,1,2,3,FLY\n").unwrap();
    assert_rejected(
        &[
            "replay",
            bad.to_str().unwrap(),
            "--summary",
            run.join("summary.json").to_str().unwrap(),
            "--out",
            o,
        ],
        &["bad.csv", "line 2", "FLY"],
    );
    // Outside its run directory a log has no summary.json beside it.
    let lonely = dir.path().join("lonely.csv");
    std::fs::copy(log, &lonely).unwrap();
    assert_rejected(
        &["replay", lonely.to_str().unwrap(), "--out", o],
        &["summary.json", "--summary"],
    );
    // A summary of another setting: the robot meets other walls, and the step where the log
    // leaves the model is named.
    let other = dir.path().join("other");
    let r = ronap(&run_args(
        "random",
        &["--seeds", "1", "--maze-seed", "99"],
        &other,
    ));
    assert!(r.status.success());
    assert_rejected(
        &[
            "replay",
            log,
            "--summary",
            other.join("summary.json").to_str().unwrap(),
            "--out",
            o,
        ],
        &[
            "the log has the robot at",
            "does not come from this scene",
            "seed-000006.csv",
        ],
    );
    assert_rejected(&["replay", log, "--out", "x.png"], &["x.png", ".gif"]);
    assert_rejected(&["replay", log, "--view", "side"], &["--view", "side"]);
    assert_rejected(&["replay", log, "--stride", "0"], &["--stride", "0"]);
    assert_rejected(&["replay", log, "--scale", "9"], &["--scale", "9"]);
    assert!(!out.exists());
    let leftovers: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .filter(|n| !["run", "other", "bad.csv", "lonely.csv"].contains(&n.to_str().unwrap()))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");

    let none = dir.path().join("none");
    assert_rejected(
        &run_args("apf", &["--seeds", "3", "--gif", "3"], &none),
        &["--gif 3", "0..=2"],
    );
    assert!(!none.exists());
}
