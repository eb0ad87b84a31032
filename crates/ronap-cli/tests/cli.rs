//! End-to-end tests of the `ronap` binary: outputs read back and checked, bad input rejected.

use crate::util::{
    assert_rejected, assert_rejected_in_empty_dir, assert_rejected_leaving_nothing, ok, ronap,
    shipped, stderr, stdout,
};

/// Runs `ronap maze <flags…> --out <out>`.
fn maze_to(flags: &[&str], out: &std::path::Path) -> std::process::Output {
    ronap(&[&["maze"], flags, &["--out", out.to_str().unwrap()]].concat())
}

/// Stdout of `ronap bench --seconds 0.01 <more…>`, a bench too short to time anything but its
/// header and table.
fn quick_bench(more: &[&str]) -> String {
    ok(&ronap(&[&["bench", "--seconds", "0.01"], more].concat()))
}

#[test]
fn maze_prints_text_by_default() {
    let o = ronap(&["maze", "--seed", "7"]);
    assert!(o.status.success(), "{}", stderr(&o));
    insta::assert_snapshot!("maze_seed_7", stdout(&o));
}

#[test]
fn maze_text_marks_start_and_goal() {
    let o = ronap(&[
        "maze",
        "--seed",
        "7",
        "--cols",
        "6",
        "--rows",
        "4",
        "--loops",
        "0",
        "--start-goal",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = stdout(&o);
    assert_eq!(text.matches('S').count(), 2, "{text}"); // the mark and the legend
    assert!(text.contains('G'));
    // 4 rows: 9 maze lines plus the legend.
    assert_eq!(text.lines().count(), 10);
    assert_eq!(text.lines().next().map(str::len), Some(6 * 3 + 1));
}

fn colour_count(img: &image::RgbImage, pred: impl Fn(&image::Rgb<u8>) -> bool) -> usize {
    img.pixels().filter(|p| pred(p)).count()
}

#[test]
fn maze_draws_every_robot_of_a_team_in_its_colour() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("team.png");
    let scenario = shipped("warehouse-team.toml");
    let o = ronap(&[
        "maze",
        "--scenario",
        scenario.to_str().unwrap(),
        "--seed",
        "1",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let img = image::open(&out).unwrap().to_rgb8();
    // The first four robots' colours (tab10 blue, orange, green, red), each at its start.
    for colour in [[31, 119, 180], [255, 127, 14], [44, 160, 44], [214, 39, 40]] {
        let n = colour_count(&img, |p| p.0 == colour);
        assert!(n > 20, "{colour:?}: {n} pixels");
    }
    // Text is a one-robot maze's only: a team's picture needs --out.
    let o = ronap(&["maze", "--scenario", scenario.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--out"), "{}", stderr(&o));
}

#[test]
fn maze_png_has_walls_floor_start_and_goal() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("maze.png");
    let o = maze_to(&["--seed", "7", "--start-goal"], &out);
    assert!(o.status.success(), "{}", stderr(&o));
    let img = image::open(&out).unwrap().to_rgb8();
    assert_eq!(img.dimensions(), (1000, 1000));
    let black = colour_count(&img, |p| p.0 == [0, 0, 0]);
    let white = colour_count(&img, |p| p.0 == [255, 255, 255]);
    let red = colour_count(&img, |p| p.0[0] > 200 && p.0[1] < 60);
    let green = colour_count(&img, |p| p.0[1] > 150 && p.0[0] < 60);
    // The outer frame alone is about 4000 wall pixels; the floor is most of the picture.
    assert!(
        black > 4000 && white > 900_000,
        "black {black} white {white}"
    );
    assert!(red > 20 && green > 200, "red {red} green {green}");
    // The same seed draws the same picture; another seed another.
    let again = dir.path().join("again.png");
    maze_to(&["--seed", "7", "--start-goal"], &again);
    assert_eq!(std::fs::read(&out).unwrap(), std::fs::read(&again).unwrap());
    let other = dir.path().join("other.png");
    maze_to(&["--seed", "8"], &other);
    assert_ne!(std::fs::read(&out).unwrap(), std::fs::read(&other).unwrap());
}

#[test]
fn maze_flags_shape_the_picture() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("small.pgm");
    let o = maze_to(
        &[
            "--cols",
            "4",
            "--rows",
            "3",
            "--cell",
            "50",
            "--wall-thickness",
            "4",
            "--loops",
            "0",
            "--scale",
            "2",
        ],
        &out,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    // A binary PGM (P5), as map servers read it, not the PAM (P7) `image` writes by default.
    assert_eq!(&std::fs::read(&out).unwrap()[..3], b"P5\n");
    let img = image::open(&out).unwrap().to_luma8();
    assert_eq!(img.dimensions(), (400, 300));
    // The bottom-left corner of the frame: 4 px walls, half inside the scene, at 2 pixels a px.
    assert_eq!(img.get_pixel(0, 299).0[0], 0);
    assert_eq!(img.get_pixel(3, 296).0[0], 0);
    assert_eq!(img.get_pixel(4, 295).0[0], 255);
}

#[test]
fn bad_input_is_named_with_exit_code_2_and_no_output() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("m.png");
    let o = out.to_str().unwrap();
    // Each flag with a value it refuses: the error names both.
    for (flag, value) in [
        ("--cols", "0"),
        ("--rows", "-2"),
        ("--cell", "-5"),
        ("--wall-thickness", "0"),
        ("--loops", "1.5"),
        ("--loops", "-0.1"),
        ("--scale", "nan"),
    ] {
        assert_rejected_in_empty_dir(
            &["maze", flag, value, "--out", o],
            &[flag, value],
            Some(&out),
        );
    }
    assert_rejected_in_empty_dir(
        &["maze", "--out", "/nonexistent-dir/m.png"],
        &["/nonexistent-dir/m.png"],
        None,
    );
    let txt = dir.path().join("m.txt");
    assert_rejected_in_empty_dir(
        &["maze", "--out", txt.to_str().unwrap()],
        &["m.txt"],
        Some(&txt),
    );
    assert_rejected_in_empty_dir(&["maze", "--bogus"], &["--bogus"], None);
}

#[test]
fn config_file_errors_name_the_file_and_field() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = dir.path().join("c.toml");
    std::fs::write(&cfg, "[maze]\ncolz = 3\n").unwrap();
    assert_rejected_in_empty_dir(
        &["maze", "--config", cfg.to_str().unwrap()],
        &["c.toml", "colz"],
        None,
    );
    std::fs::write(&cfg, "[maze]\nloops = 2.0\n").unwrap();
    assert_rejected_in_empty_dir(
        &["maze", "--config", cfg.to_str().unwrap()],
        &["c.toml", "maze.loops", "2"],
        None,
    );
    assert_rejected_in_empty_dir(
        &["maze", "--config", "/no/such.toml"],
        &["/no/such.toml"],
        None,
    );
    // A valid file is used, and flags override it.
    std::fs::write(&cfg, "[maze]\ncols = 3\nrows = 2\n").unwrap();
    let o = ronap(&["maze", "--config", cfg.to_str().unwrap(), "--rows", "1"]);
    assert!(o.status.success());
    assert_eq!(
        stdout(&o).lines().collect::<Vec<_>>(),
        [
            "+--+--+--+",
            stdout(&o).lines().nth(1).unwrap(),
            "+--+--+--+"
        ]
    );
}

#[test]
fn bench_reports_steps_per_second_and_scan_time() {
    let o = ronap(&["bench", "--seconds", "0.2", "--threads", "2"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = stdout(&o);
    let figure = |label: &str| -> f64 {
        let line = text
            .lines()
            .find(|l| l.contains(label))
            .unwrap_or_else(|| panic!("{label} in {text}"));
        line.split_whitespace()
            .find_map(|w| w.replace(',', "").parse::<f64>().ok().filter(|v| *v > 10.0))
            .unwrap_or_else(|| panic!("no figure in {line:?}"))
    };
    assert!(figure("one thread") > 0.0);
    assert!(figure("2 threads") > 0.0);
    assert!(figure("laser scan") > 0.0);
}

#[test]
fn bench_takes_its_laser_and_scene_from_the_flags() {
    let text = quick_bench(&[
        "--threads",
        "1",
        "--beams",
        "360",
        "--range",
        "300",
        "--fov",
        "360",
        "--cols",
        "5",
        "--rows",
        "3",
    ]);
    let header = text.lines().next().unwrap();
    assert!(
        header.contains("maze of seed 0 of 500 x 300 px"),
        "{header}"
    );
    assert!(
        header.contains("360 beams over 360 deg to 300 px"),
        "{header}"
    );
    let scan = text.lines().find(|l| l.contains("laser scan")).unwrap();
    assert!(
        scan.contains("(360 beams, ") && scan.contains("ns per ray"),
        "{scan}"
    );

    let office = shipped("office.png");
    let bench = quick_bench(&["--threads", "1", "--map", office.to_str().unwrap()]);
    let header = bench.lines().next().unwrap();
    assert!(header.contains("office.png of 720 x 480 px"), "{header}");

    assert_rejected(&["bench", "--beams", "4097"], &["--beams", "4096"]);
    assert_rejected(&["bench", "--fov", "400"], &["--fov", "360"]);
    assert_rejected(&["bench", "--range", "0"], &["--range"]);
    assert_rejected(
        &["bench", "--sweep", "--beams", "9"],
        &["--sweep", "--beams"],
    );
}

/// Maze flags for a scene that is not a maze are refused by name, not silently ignored.
#[test]
fn maze_flags_are_refused_for_other_scenes() {
    let office = shipped("office.png");
    let office = office.to_str().unwrap();
    let warehouse = shipped("warehouse-forklifts.toml");
    let warehouse = warehouse.to_str().unwrap();
    let map = shipped("map-mover.toml");
    let map = map.to_str().unwrap();
    let out = tempfile::tempdir().unwrap();
    let run = out.path().join("run");
    let run = run.to_str().unwrap();
    for (args, names) in [
        (
            vec![
                "run", "--policy", "apf", "--map", office, "--cols", "5", "--out", run,
            ],
            vec!["--cols", "--map", "office.png"],
        ),
        (
            vec!["bench", "--seconds", "0.01", "--map", office, "--rows", "5"],
            vec!["--rows", "--map"],
        ),
        (
            vec!["maze", "--scenario", warehouse, "--loops", "0.1"],
            vec!["--loops", "scene.kind", "warehouse"],
        ),
        (
            vec!["view", "--policy", "apf", "--scenario", map, "--cell", "50"],
            vec!["--cell", "scene.kind", "map"],
        ),
        (
            vec![
                "train",
                "dqn",
                "--map",
                office,
                "--wall-thickness",
                "3",
                "--out",
                run,
            ],
            vec!["--wall-thickness", "--map"],
        ),
    ] {
        assert_rejected_leaving_nothing(&args, &names, std::path::Path::new(run));
    }
    // A maze flag with a maze still works.
    ok(&ronap(&["maze", "--cols", "3", "--rows", "2"]));
}

#[test]
fn bench_sweep_tabulates_every_beam_count_and_range() {
    let text = quick_bench(&["--sweep", "--cols", "4", "--rows", "4"]);
    let mut lines = text.lines();
    let header = lines.next().unwrap();
    assert!(
        header.contains("maze of seed 0 of 400 x 400 px"),
        "{header}"
    );
    assert_eq!(
        lines.next().unwrap().split_whitespace().collect::<Vec<_>>(),
        ["beams", "range", "px", "ns", "per", "ray", "steps/s"]
    );
    let rows: Vec<(u32, f64, f64, f64)> = lines
        .map(|l| {
            let f: Vec<&str> = l.split_whitespace().collect();
            assert_eq!(f.len(), 4, "{l}");
            (
                f[0].parse().unwrap(),
                f[1].parse().unwrap(),
                f[2].parse().unwrap(),
                f[3].replace(',', "").parse().unwrap(),
            )
        })
        .collect();
    let cells: Vec<(u32, f64)> = rows.iter().map(|r| (r.0, r.1)).collect();
    let mut expected = Vec::new();
    for beams in [17, 64, 360, 1080] {
        for range in [50.0, 200.0, 1000.0] {
            expected.push((beams, range));
        }
    }
    assert_eq!(cells, expected);
    for (beams, range, ns, steps) in rows {
        assert!(
            ns > 0.0 && steps > 0.0,
            "{beams} beams at {range} px: {ns} ns, {steps} steps/s"
        );
    }
}

#[test]
fn help_explains_every_flag_with_its_default() {
    let o = ronap(&["maze", "--help"]);
    assert!(o.status.success());
    insta::assert_snapshot!("maze_help", stdout(&o));
    let o = ronap(&["run", "--help"]);
    assert!(o.status.success());
    insta::assert_snapshot!("run_help", stdout(&o));
    for (args, name) in [
        (&["collect", "--help"][..], "collect_help"),
        (&["train", "bc", "--help"][..], "train_bc_help"),
        (&["train", "dqn", "--help"][..], "train_dqn_help"),
        (&["view", "--help"][..], "view_help"),
        (&["replay", "--help"][..], "replay_help"),
        (&["bench", "--help"][..], "bench_help"),
    ] {
        let o = ronap(args);
        assert!(o.status.success());
        insta::assert_snapshot!(name, stdout(&o));
    }
}

#[test]
fn collect_human_needs_a_terminal_and_writes_nothing_without_one() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("rows.csv");
    let o = out.to_str().unwrap();
    assert_rejected_in_empty_dir(
        &["collect", "--human", "--out", o],
        &["ronap collect --human", "stdout is not one"],
        Some(&out),
    );
    assert_rejected_in_empty_dir(
        &["collect", "--human", "--expert", "geodesic", "--out", o],
        &["--human", "--expert"],
        Some(&out),
    );
    assert_rejected_in_empty_dir(
        &["collect", "--out", o],
        &["--expert", "--human"],
        Some(&out),
    );
    assert_rejected_in_empty_dir(
        &["collect", "--human", "--mode", "drive", "--out", o],
        &["--human", "--mode drive"],
        Some(&out),
    );
}

#[test]
fn view_needs_a_terminal_and_says_so() {
    // Output captured: stdout is a pipe. The command must fail at once, not wait for keys.
    let start = std::time::Instant::now();
    assert_rejected_in_empty_dir(
        &["view", "--policy", "apf", "--seed", "7"],
        &["ronap view", "stdout is not one"],
        None,
    );
    assert!(start.elapsed() < std::time::Duration::from_secs(20));
    assert_rejected_in_empty_dir(&["view", "--policy", "nope"], &["--policy", "nope"], None);
    assert_rejected_in_empty_dir(
        &["view", "--policy", "apf", "--speed", "0"],
        &["--speed", "0"],
        None,
    );
    assert_rejected_in_empty_dir(
        &["view", "--policy", "apf", "--map", "/no/map.png"],
        &["/no/map.png"],
        None,
    );
}
