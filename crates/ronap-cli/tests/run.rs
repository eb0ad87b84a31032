//! End-to-end tests of `ronap run`: every output file read back, determinism across thread
//! counts, the success gate, bad input, maps, APF's local minima, and Ctrl-C.

use crate::util::{
    assert_rejected, assert_rejected_leaving_nothing, col, collect_args, json, ok, ronap, rows,
    run_args, shipped, text,
};
use std::path::{Path, PathBuf};
use std::process::Command;

#[test]
fn run_writes_episodes_summary_pictures_and_step_logs() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let o = ronap(&run_args(
        "geodesic",
        &[
            "--seeds",
            "6",
            "--seed-start",
            "10",
            "--png",
            "2",
            "--log-steps",
        ],
        &out,
    ));
    assert!(o.status.success(), "{}", text(&o.stderr));
    let table = text(&o.stdout);
    for row in [
        "episodes",
        "success rate",
        "95% CI",
        "time-outs",
        "collisions per episode",
        "mean steps",
        "mean path length",
        "SPL",
        "wall time",
        "steps per second",
    ] {
        assert!(table.contains(row), "summary lacks {row}: {table}");
    }

    // Asking for no pictures and no players makes no folders for them.
    let none = dir.path().join("none");
    ok(&ronap(&run_args(
        "geodesic",
        &["--seeds", "2", "--png", "0", "--html", "0"],
        &none,
    )));
    assert!(!none.join("png").exists() && !none.join("html").exists());

    let episodes = rows(&out.join("episodes.csv"));
    assert_eq!(episodes.len(), 7);
    let (seed, outcome, steps, path, shortest, spl) = (
        col(&episodes, "seed"),
        col(&episodes, "outcome"),
        col(&episodes, "steps"),
        col(&episodes, "path_length_px"),
        col(&episodes, "shortest_px"),
        col(&episodes, "spl"),
    );
    for (k, r) in episodes[1..].iter().enumerate() {
        assert_eq!(r[seed], (10 + k).to_string());
        assert_eq!(r[outcome], "success");
        let (p, s, v): (f64, f64, f64) = (
            r[path].parse().unwrap(),
            r[shortest].parse().unwrap(),
            r[spl].parse().unwrap(),
        );
        // The driven path is no shorter than the shortest path, and SPL is their ratio.
        assert!(p >= s * 0.99 && s >= 190.0, "path {p} shortest {s}");
        assert!((v - s / p.max(s)).abs() < 1e-3, "spl {v}");

        let log = rows(&out.join("steps").join(format!("seed-{:06}.csv", 10 + k)));
        assert_eq!(log.len() - 1, r[steps].parse::<usize>().unwrap());
        assert!(log[0].contains(&"d_17".to_string()) && log[0].contains(&"action".to_string()));
        let action = col(&log, "action");
        assert!(log[1..]
            .iter()
            .all(|l| ["LEFT", "AHEAD", "RIGHT"].contains(&l[action].as_str())));
    }
    let timing = rows(&out.join("timing.csv"));
    assert_eq!(timing.len(), 7);

    let summary = json(&out.join("summary.json"));
    assert_eq!(summary["summary"]["episodes"], 6);
    assert_eq!(summary["summary"]["successes"], 6);
    assert_eq!(summary["policy"], "geodesic");
    assert_eq!(summary["config"]["laser"]["beams"], 17);
    assert_eq!(summary["interrupted"], false);

    let mut pngs: Vec<PathBuf> = std::fs::read_dir(out.join("png"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    pngs.sort();
    assert_eq!(pngs.len(), 2);
    assert!(pngs[0].ends_with("seed-000010-success.png"), "{pngs:?}");
    let img = image::open(&pngs[0]).unwrap().to_rgb8();
    assert_eq!(img.dimensions(), (1000, 1000));
    let blue = img.pixels().filter(|p| p.0 == [40, 80, 230]).count();
    assert!(blue > 200, "path pixels: {blue}");
}

#[test]
fn episodes_csv_is_identical_on_one_and_two_threads() {
    let dir = tempfile::tempdir().unwrap();
    for policy in ["random", "apf", "geodesic"] {
        let a = dir.path().join(format!("{policy}-1"));
        let b = dir.path().join(format!("{policy}-2"));
        for (out, threads) in [(&a, "1"), (&b, "2")] {
            let o = ronap(&run_args(
                policy,
                &["--seeds", "24", "--threads", threads],
                out,
            ));
            assert!(o.status.success(), "{}", text(&o.stderr));
        }
        let (x, y) = (
            std::fs::read(a.join("episodes.csv")).unwrap(),
            std::fs::read(b.join("episodes.csv")).unwrap(),
        );
        assert_eq!(
            x, y,
            "{policy}: episodes.csv differs between 1 and 2 threads"
        );
        assert_eq!(rows(&a.join("episodes.csv")).len(), 25);
    }
}

#[test]
fn min_success_gates_the_exit_code() {
    let dir = tempfile::tempdir().unwrap();
    let gated = |policy: &str, out: &Path| {
        ronap(&run_args(
            policy,
            &["--seeds", "10", "--min-success", "0.9"],
            out,
        ))
    };
    let out = dir.path().join("r");
    let o = gated("random", &out);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o.stderr));
    assert!(text(&o.stderr).contains("below --min-success"));
    assert!(
        out.join("episodes.csv").exists(),
        "results are written before the gate"
    );
    let o = gated("geodesic", &dir.path().join("g"));
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
}

#[test]
fn bad_input_is_named_and_leaves_no_output() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("never");
    let o = out.to_str().unwrap();
    let file = |name: &str, text: &[u8]| {
        let path = dir.path().join(name);
        std::fs::write(&path, text).unwrap();
        path.to_str().unwrap().to_owned()
    };
    let corrupt = file("corrupt.png", b"\x89PNG not really");
    let yaml = file("bad.yaml", b"image: x.pgm\nresolution: fast\n");
    let radius = file("c.toml", b"[robot]\nradius_px = -3\n");
    let beam = file("d.toml", b"[laser]\nbeams = 17\nbeam = 3\n");
    // Each case: the arguments between `run` and `--out`, and what the error must name.
    let cases: [(String, &[&str]); 8] = [
        ("--policy teleport".into(), &["teleport", "apf"]),
        ("--policy apf --seeds 0".into(), &["--seeds", "0"]),
        (
            "--policy random --seed-start 1 --seeds 18446744073709551615".into(),
            &["--seeds 18446744073709551615", "--seed-start"],
        ),
        (
            "--policy apf --map /no/such/map.png".into(),
            &["/no/such/map.png"],
        ),
        (format!("--policy apf --map {corrupt}"), &["corrupt.png"]),
        (
            format!("--policy apf --map {yaml}"),
            &["bad.yaml", "line 2", "fast"],
        ),
        (
            format!("--policy apf --config {radius}"),
            &["c.toml", "robot.radius_px", "-3"],
        ),
        (
            format!("--policy apf --config {beam}"),
            &["d.toml", "d.toml:3:", "beam"],
        ),
    ];
    for (args, names) in cases {
        let mut args: Vec<&str> = args.split_whitespace().collect();
        args.splice(0..0, ["run"]);
        args.extend(["--out", o]);
        assert_rejected_leaving_nothing(&args, names, &out);
    }
    // An output directory under a regular file cannot be created.
    let under = Path::new(&file("file", b"x")).join("out");
    let args = format!("run --policy apf --seeds 2 --out {}", under.display());
    let args: Vec<&str> = args.split_whitespace().collect();
    assert_rejected_leaving_nothing(&args, &["file/out"], &under);
}

fn save_map(path: &Path, walls: &[(u32, u32, u32, u32)]) {
    let mut img = image::GrayImage::from_pixel(300, 200, image::Luma([255]));
    for &(x0, y0, x1, y1) in walls {
        for y in y0..y1 {
            for x in x0..x1 {
                img.put_pixel(x, y, image::Luma([0]));
            }
        }
    }
    img.save(path).unwrap();
}

fn fixed(dir: &Path, start: [f64; 3], goal: [f64; 2]) -> PathBuf {
    let cfg = dir.join("fixed.toml");
    std::fs::write(
        &cfg,
        format!(
            "[episode]\nstart = [{}, {}, {}]\ngoal = [{}, {}]\n",
            start[0], start[1], start[2], goal[0], goal[1]
        ),
    )
    .unwrap();
    cfg
}

/// The rows of `episodes.csv` of `ronap run` of `policy` for `seeds` seeds on `map` with
/// configuration `cfg`, into `out`.
fn on_map(policy: &str, seeds: &str, map: &Path, cfg: &Path, out: &Path) -> Vec<Vec<String>> {
    let (map, cfg, o) = (
        map.to_str().unwrap(),
        cfg.to_str().unwrap(),
        out.to_str().unwrap(),
    );
    let args = [
        "run", "--policy", policy, "--seeds", seeds, "--map", map, "--config", cfg,
    ];
    let o = ronap(&[&args[..], &["--out", o]].concat());
    assert!(o.status.success(), "{}", text(&o.stderr));
    rows(&out.join("episodes.csv"))
}

#[test]
fn apf_fails_promptly_in_a_local_minimum_and_succeeds_in_the_open() {
    let dir = tempfile::tempdir().unwrap();
    // A cup open to the left (image rows from the top: y 60..140 in the scene is rows 60..140).
    let cup = dir.path().join("cup.png");
    save_map(
        &cup,
        &[(140, 60, 142, 140), (80, 60, 142, 62), (80, 138, 142, 140)],
    );
    let cfg = fixed(dir.path(), [110.0, 100.0, 0.0], [260.0, 100.0]);
    let out = dir.path().join("cup-run");
    let episodes = on_map("apf", "3", &cup, &cfg, &out);
    for r in &episodes[1..] {
        assert_eq!(r[col(&episodes, "outcome")], "stuck");
        assert!(r[col(&episodes, "reason")].contains("local minimum"));
        let steps: u32 = r[col(&episodes, "steps")].parse().unwrap();
        assert!(steps < 100, "took {steps} steps to give up");
    }
    // The same start and goal without the cup: APF goes straight there.
    let open = dir.path().join("open.png");
    save_map(&open, &[]);
    let out = dir.path().join("open-run");
    let episodes = on_map("apf", "3", &open, &cfg, &out);
    assert!(episodes[1..]
        .iter()
        .all(|r| r[col(&episodes, "outcome")] == "success"));
    // The geodesic planner walks out of the cup.
    let out = dir.path().join("cup-geodesic");
    let episodes = on_map("geodesic", "1", &cup, &cfg, &out);
    assert_eq!(episodes[1][col(&episodes, "outcome")], "success");
}

#[test]
fn ros_map_yaml_is_read() {
    let dir = tempfile::tempdir().unwrap();
    let pgm = dir.path().join("room.pgm");
    save_map(&pgm, &[(150, 0, 152, 150)]);
    let yaml = dir.path().join("room.yaml");
    std::fs::write(&yaml, "image: room.pgm\nresolution: 0.05\norigin: [-1.0, -2.0, 0.0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n").unwrap();
    let out = dir.path().join("r");
    let o = ronap(&run_args(
        "geodesic",
        &["--seeds", "4", "--map", yaml.to_str().unwrap()],
        &out,
    ));
    assert!(o.status.success(), "{}", text(&o.stderr));
    let summary = json(&out.join("summary.json"));
    assert_eq!(summary["map"]["Ros"]["resolution_m"], 0.05);
    assert_eq!(summary["summary"]["successes"], 4);
}

/// Runs `ronap` with `args`, sends it `signal` (as `kill` names it) after 1.5 s and waits for it.
#[cfg(unix)]
fn signalled(args: &[&str], signal: &str) -> std::process::Output {
    let child = Command::new(env!("CARGO_BIN_EXE_ronap"))
        .args(args)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(1500));
    let kill = Command::new("kill")
        .args([signal, &child.id().to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
    child.wait_with_output().unwrap()
}

#[cfg(unix)]
#[test]
fn ctrl_c_keeps_the_finished_episodes() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("r");
    let o = signalled(
        &run_args("random", &["--seeds", "1000000", "--threads", "1"], &out),
        "-INT",
    );
    assert_eq!(o.status.code(), Some(130), "{}", text(&o.stderr));
    let episodes = rows(&out.join("episodes.csv"));
    let finished = episodes.len() - 1;
    assert!(finished > 0 && finished < 1_000_000, "{finished}");
    let summary = json(&out.join("summary.json"));
    assert_eq!(summary["interrupted"], true);
    assert_eq!(summary["summary"]["episodes"], finished);
    assert!(text(&o.stdout).contains("interrupted"));
    // Starting afresh there would lose them: refused until resumed (or removed).
    assert_rejected(
        &run_args("random", &["--seeds", "2"], &out),
        &["was interrupted", "ronap run --resume"],
    );
    assert_eq!(rows(&out.join("episodes.csv")).len() - 1, finished);
}

/// `timeout`, job schedulers and service managers stop a program with SIGTERM: a collection so
/// stopped keeps its rows, as after Ctrl-C, and leaves no temporary file.
#[cfg(unix)]
#[test]
fn sigterm_keeps_the_rows_collected() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("rows.csv");
    let o = signalled(
        &collect_args(
            "geodesic",
            &["--samples", "1000000000", "--threads", "1"],
            &out,
        ),
        "-TERM",
    );
    assert_eq!(o.status.code(), Some(130), "{}", text(&o.stderr));
    let saved = rows(&out).len() - 1;
    assert!(saved > 0, "{saved}");
    assert!(
        text(&o.stdout).contains(&format!("interrupted: {saved} of")),
        "{}",
        text(&o.stdout)
    );
    let files: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
    assert_eq!(files.len(), 1, "{files:?}");
}

/// Seeds end at 2^64 - 1: a collection that runs out of them says so and keeps its rows.
#[test]
fn collect_says_when_the_seeds_run_out() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("rows.csv");
    assert_rejected(
        &collect_args(
            "geodesic",
            &["--samples", "300", "--seed-start", "18446744073709551614"],
            &out,
        ),
        &["--seed-start", "the seeds ran out"],
    );
    assert_eq!(rows(&out).len() - 1, 100);
}

#[test]
fn config_prints_a_file_that_run_accepts() {
    let dir = tempfile::tempdir().unwrap();
    let o = ronap(&["config", "--cols", "5"]);
    assert!(o.status.success());
    let cfg = dir.path().join("c.toml");
    std::fs::write(&cfg, &o.stdout).unwrap();
    assert!(text(&o.stdout).contains("# Largest reading d_max, px.\nrange_px = 50.0"));
    let out = dir.path().join("r");
    let o = ronap(&run_args(
        "random",
        &["--seeds", "2", "--config", cfg.to_str().unwrap()],
        &out,
    ));
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert_eq!(json(&out.join("summary.json"))["config"]["maze"]["cols"], 5);
}

#[test]
fn twenty_orca_robots_swap_across_a_circle_all_home_without_contact() {
    // The bar of CrowdNav's and RVO2's circle: on every one of 50 jittered seeds, every robot
    // arrives and no two ever touch.
    let dir = tempfile::tempdir().unwrap();
    let scenario = shipped("circle-robots-20.toml");
    crate::util::ok(&ronap(&[
        "run",
        "--scenario",
        scenario.to_str().unwrap(),
        "--policy",
        "orca",
        "--seeds",
        "50",
        "--out",
        dir.path().to_str().unwrap(),
    ]));
    let episodes = rows(&dir.path().join("episodes.csv"));
    assert_eq!(episodes.len(), 51);
    let (outcome, arrived, contacts) = (
        col(&episodes, "outcome"),
        col(&episodes, "arrived"),
        col(&episodes, "robot_collisions"),
    );
    for row in &episodes[1..] {
        assert_eq!(
            (&row[outcome][..], &row[arrived][..], &row[contacts][..]),
            ("success", "20", "0"),
            "seed {}",
            row[0]
        );
    }
}

#[test]
fn the_crowd_scenarios_run_and_bad_crowd_entries_are_named() {
    let dir = tempfile::tempdir().unwrap();
    for (name, policy) in [
        ("circle-crossing", "orca"),
        ("circle-crossing-visible", "geodesic"),
        ("square-crossing", "geodesic-wait"),
        ("circle-robots-20", "orca"),
        ("crowd-hall", "social-force"),
        ("circle-crossing", "dwa"),
        ("circle-robots-20", "social-force"),
    ] {
        let scenario = shipped(&format!("{name}.toml"));
        let out = dir.path().join(format!("{name}-{policy}"));
        crate::util::ok(&ronap(&[
            "run",
            "--scenario",
            scenario.to_str().unwrap(),
            "--policy",
            policy,
            "--seeds",
            "4",
            "--out",
            out.to_str().unwrap(),
        ]));
        let episodes = rows(&out.join("episodes.csv"));
        assert_eq!(episodes.len(), 5, "{name}");
        if name != "circle-robots-20" {
            // The crossings measure the crowd metrics.
            col(&episodes, "intrusion_ratio");
        }
    }
    let scene = "[maze]\ncols = 2\nrows = 2\n";
    for (body, names) in [
        (
            "[[moving]]\nmotion = \"orca\"\npattern = \"circle\"\n",
            &["bad.toml:6", "moving[0].pattern", "\"circle\"", "pattern_radius_px"][..],
        ),
        (
            "[[moving]]\nmotion = \"orca\"\nspeed_px = -1.0\n",
            &["bad.toml:6", "moving[0].speed_px", "-1"][..],
        ),
        (
            "[[moving]]\nmotion = \"random_walk\"\npattern = \"square\"\npattern_radius_px = 10.0\n",
            &["bad.toml:6", "moving[0].pattern", "\"square\"", "orca"][..],
        ),
        (
            "[[moving]]\nmotion = \"social_force\"\nsocial_force = { lambda = 2.0 }\n",
            &["bad.toml:6", "moving[0].social_force.lambda", "2.0"][..],
        ),
        (
            "[[moving]]\nmotion = \"social_force\"\nmax_speed_px = -3.0\n",
            &["bad.toml:6", "moving[0].max_speed_px", "-3"][..],
        ),
        (
            "[dwa]\nhorizon_steps = 0\n",
            &["bad.toml:5", "dwa.horizon_steps", "0"][..],
        ),
        (
            "[[crowd]]\ncount = 4\nspeed_px = -2.0\n",
            &["bad.toml:6", "crowd[0].speed_px", "-2"][..],
        ),
        (
            "[[crowd]]\npattern = \"square\"\n",
            &["bad.toml:5", "crowd[0].pattern", "\"square\"", "pattern_radius_px"][..],
        ),
        (
            "[[crowd]]\nmotion = \"linear\"\n",
            &["bad.toml:5", "crowd[0].motion", "\"linear\"", "orca"][..],
        ),
        (
            "[episode]\nstart = [20.0, 20.0, 0.0]\n[[crowd]]\nrobot_follows = true\n",
            &["bad.toml:7", "crowd[0].robot_follows", "episode.start"][..],
        ),
    ] {
        let bad = dir.path().join("bad.toml");
        std::fs::write(&bad, format!("{scene}{body}")).unwrap();
        assert_rejected(
            &["run", "--scenario", bad.to_str().unwrap(), "--policy", "orca", "--seeds", "1"],
            names,
        );
    }
    // A pattern that does not fit the scene: no start and goal for the pedestrians.
    for (table, entry) in [("moving", "moving[0]"), ("crowd", "crowd[0]")] {
        let bad = dir.path().join("big.toml");
        std::fs::write(
            &bad,
            format!(
                "{scene}[[moving]]\ncount = 1\n[[{table}]]\ncount = 3\nmotion = \"orca\"\n\
                 pattern = \"circle\"\npattern_radius_px = 5000.0\n"
            ),
        )
        .unwrap();
        let entry = if table == "moving" {
            "moving[1]"
        } else {
            entry
        };
        // The file, the line, the key and the value to blame: one line, exit code 2.
        let key = format!("{entry}.pattern_radius_px = 5000.0");
        let err = assert_rejected(
            &[
                "run",
                "--scenario",
                bad.to_str().unwrap(),
                "--policy",
                "orca",
                "--seeds",
                "1",
            ],
            &["big.toml:10", &key],
        );
        assert!(!err.contains("panick"), "{err}");
    }
}

#[test]
fn split_names_a_seed_space_and_trained_seeds_are_warned_about() {
    let dir = tempfile::tempdir().unwrap();
    let seeds_of = |split: &str, start: &str| {
        let out = dir.path().join(format!("{split}-{start}"));
        let o = ronap(&run_args(
            "geodesic",
            &["--seeds", "3", "--split", split, "--seed-start", start],
            &out,
        ));
        assert!(o.status.success(), "{}", text(&o.stderr));
        let table = rows(&out.join("episodes.csv"));
        let c = col(&table, "seed");
        table[1..].iter().map(|r| r[c].clone()).collect::<Vec<_>>()
    };
    assert_eq!(seeds_of("test", "0"), ["0", "1", "2"]);
    assert_eq!(seeds_of("validation", "5"), ["500005", "500006", "500007"]);
    assert_eq!(seeds_of("train", "0"), ["1000000", "1000001", "1000002"]);
    let over = ronap(&[
        "run",
        "--policy",
        "apf",
        "--split",
        "test",
        "--seed-start",
        "499999",
        "--seeds",
        "2",
    ]);
    assert!(!over.status.success());
    let err = text(&over.stderr);
    assert!(err.contains("0..=499999"), "{err}");
    assert_rejected(
        &["run", "--policy", "apf", "--split", "dev"],
        &["dev", "test, validation or train"],
    );
    // The shipped DQN network records its training and validation seeds: a run on them warns,
    // a run on the test split does not.
    let policy = concat!(
        "mlp:",
        env!("CARGO_MANIFEST_DIR"),
        "/../../policies/dqn.safetensors"
    );
    for (split, warned) in [("validation", true), ("test", false)] {
        let out = dir.path().join(format!("dqn-{split}"));
        let o = ronap(&run_args(policy, &["--seeds", "2", "--split", split], &out));
        assert!(o.status.success(), "{}", text(&o.stderr));
        let err = text(&o.stderr);
        assert_eq!(err.contains("are among those"), warned, "{split}: {err}");
    }
}

#[test]
fn a_crowd_pattern_the_robot_follows_out_of_the_scene_is_named_by_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(shipped("circle-crossing.toml"))
        .unwrap()
        .replace("pattern_radius_px = 80.0", "pattern_radius_px = 8000.0");
    let line = 1 + text
        .lines()
        .position(|l| l.contains("pattern_radius_px"))
        .unwrap();
    let bad = dir.path().join("wide.toml");
    std::fs::write(&bad, text).unwrap();
    let out = dir.path().join("out");
    let o = ronap(&run_args(
        "orca",
        &["--scenario", bad.to_str().unwrap(), "--seeds", "2"],
        &out,
    ));
    let err = crate::util::stderr(&o);
    assert!(!o.status.success());
    for part in [
        format!("wide.toml:{line}"),
        "crowd[0].pattern_radius_px = 8000".to_string(),
        "the robot's start".to_string(),
    ] {
        assert!(err.contains(&part), "{part:?} not in {err}");
    }
    assert!(!out.exists());
}
