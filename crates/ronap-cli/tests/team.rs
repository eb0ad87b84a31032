//! End-to-end tests of team runs (`ronap run --scenario` with `[[robots]]`): the shipped corridor
//! swap deadlocks and says so, robots.csv beside team rows, the same bytes on one and two
//! threads, and bad entries named.

use crate::util::{
    assert_rejected, col, collect_args, ok, repo_root, ronap, rows, run_args, shipped, summary,
};
use std::path::Path;

fn run_team(scenario: &Path, out: &Path, extra: &[&str]) -> String {
    let mut args = vec![
        "run",
        "--scenario",
        scenario.to_str().unwrap(),
        "--policy",
        "geodesic",
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    ok(&ronap(&args))
}

#[test]
fn the_corridor_swap_deadlocks_and_is_reported_as_one() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("swap");
    let table = run_team(
        &shipped("corridor-swap.toml"),
        &out,
        &["--seeds", "3", "--png", "1"],
    );
    image::open(out.join("png/seed-000000-deadlock.png")).unwrap();
    assert!(table.contains("2 robots (2 x geodesic)"), "{table}");
    assert!(table.contains("deadlocks               3"), "{table}");
    let episodes = rows(&out.join("episodes.csv"));
    assert_eq!(episodes.len(), 4);
    let (outcome, deadlock) = (col(&episodes, "outcome"), col(&episodes, "deadlock"));
    for r in &episodes[1..] {
        assert_eq!(
            (r[outcome].as_str(), r[deadlock].as_str()),
            ("deadlock", "true")
        );
    }
    let robots = rows(&out.join("robots.csv"));
    assert_eq!(robots.len(), 1 + 3 * 2);
    let rc = col(&robots, "robot_collisions");
    assert!(robots[1..]
        .iter()
        .all(|r| r[rc].parse::<u32>().unwrap() > 0));
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["team"]["deadlocks"], 3);
}

/// The value of row `name` of a printed two-column table.
fn row<'a>(table: &'a str, name: &str) -> &'a str {
    table
        .lines()
        .find_map(|l| l.strip_prefix(&format!("{name}  ")))
        .unwrap_or_else(|| panic!("no row {name:?} in:\n{table}"))
        .trim()
}

#[test]
fn the_corridor_swap_s_robots_table_counts_their_deadlocks_and_robot_collisions() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("swap");
    let printed = run_team(&shipped("corridor-swap.toml"), &out, &["--seeds", "2"]);
    let (team, robots_table) = printed.split_once("per robot:\n").unwrap();
    assert_eq!(row(team, "deadlocks"), "2");

    // Every robot row of robots.csv, as the per-robot table sums them up.
    let robots = rows(&out.join("robots.csv"));
    assert_eq!(robots.len(), 1 + 2 * 2);
    let [outcome, walls, others] =
        ["outcome", "collisions", "robot_collisions"].map(|c| col(&robots, c));
    let deadlocked = robots[1..]
        .iter()
        .filter(|r| r[outcome] == "deadlock")
        .count();
    let mean = |c: usize| {
        robots[1..]
            .iter()
            .map(|r| r[c].parse::<f64>().unwrap())
            .sum::<f64>()
            / 4.0
    };
    assert_eq!(deadlocked, 4, "{robots:?}");
    assert!(mean(others) > 0.0);
    assert_eq!(row(robots_table, "episodes"), "4");
    assert_eq!(row(robots_table, "deadlocks"), "4");
    assert!(row(robots_table, "success rate").starts_with("0.0% (0 of 4;"));
    assert_eq!(
        row(robots_table, "robot collisions per episode"),
        format!("{:.2}", mean(others))
    );
    assert_eq!(
        row(robots_table, "wall collisions per episode"),
        format!("{:.2}", mean(walls))
    );
    // Every robot episode counted once: 4 = successes + time-outs + stuck + deadlocks.
    let counted: usize = ["time-outs", "stuck (gave up)", "deadlocks"]
        .iter()
        .map(|n| row(robots_table, n).parse::<usize>().unwrap())
        .sum();
    assert_eq!(counted, 4, "{robots_table}");
    assert!(
        !robots_table.contains("\ncollisions per episode"),
        "{robots_table}"
    );

    let among = &summary(&out)["among_robots"];
    assert_eq!(among["deadlocks"], 4);
    assert_eq!(
        among["robot_collisions_per_episode"].as_f64(),
        Some(mean(others))
    );
}

#[test]
fn a_lone_run_s_table_and_summary_have_nothing_of_a_team() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("lone");
    let printed = ok(&ronap(&run_args("apf", &["--seeds", "3"], &out)));
    assert!(row(&printed, "collisions per episode")
        .parse::<f64>()
        .is_ok());
    for name in ["deadlocks", "robot collisions", "wall collisions"] {
        assert!(!printed.contains(name), "{name} in:\n{printed}");
    }
    let json = std::fs::read_to_string(out.join("summary.json")).unwrap();
    assert!(!json.contains("among_robots"), "{json}");
}

#[test]
fn team_runs_are_the_same_on_one_and_two_threads() {
    let dir = tempfile::tempdir().unwrap();
    let scenario = dir.path().join("team.toml");
    std::fs::write(
        &scenario,
        "[scene]\nkind = \"maze\"\n\n[[robots]]\ncount = 6\n\n[[robots]]\ncount = 2\npolicy = \"apf\"\non_arrival = \"vanish\"\n",
    )
    .unwrap();
    let (a, b) = (dir.path().join("a"), dir.path().join("b"));
    run_team(&scenario, &a, &["--seeds", "6", "--threads", "1"]);
    run_team(&scenario, &b, &["--seeds", "6", "--threads", "2"]);
    for f in ["episodes.csv", "robots.csv"] {
        assert_eq!(
            std::fs::read(a.join(f)).unwrap(),
            std::fs::read(b.join(f)).unwrap(),
            "{f}"
        );
    }
    let robots = rows(&a.join("robots.csv"));
    let policy = col(&robots, "policy");
    assert_eq!(
        robots[1..].iter().filter(|r| r[policy] == "apf").count(),
        6 * 2
    );
}

#[test]
fn goal_lists_report_every_order_s_tour() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("wh");
    run_team(&shipped("warehouse-team.toml"), &out, &["--seeds", "2"]);
    let robots = rows(&out.join("robots.csv"));
    assert_eq!(robots.len(), 1 + 2 * 8);
    let [goals, chosen, given, nearest, optimal] = [
        "goals",
        "tour_px",
        "given_tour_px",
        "nearest_tour_px",
        "optimal_tour_px",
    ]
    .map(|c| col(&robots, c));
    for r in &robots[1..] {
        assert_eq!(r[goals], "3");
        let px = |i: usize| r[i].parse::<f64>().unwrap();
        assert_eq!(px(chosen), px(optimal));
        assert!(px(optimal) <= px(given) + 1e-6 && px(optimal) <= px(nearest) + 1e-6);
    }
}

#[test]
fn one_robot_commands_refuse_a_team_by_name() {
    let swap = shipped("corridor-swap.toml");
    let s = swap.to_str().unwrap();
    // Expert demonstrations are one robot's (compare and run take teams).
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("rows.csv");
    assert_rejected(
        &collect_args("geodesic", &["--samples", "10", "--scenario", s], &out),
        &["2 robots", "ronap run --scenario"],
    );
    assert!(!out.exists());
}

#[test]
fn bad_robot_entries_are_named() {
    let dir = tempfile::tempdir().unwrap();
    for (text, names) in [
        ("[[robots]]\ncount = 0\n", vec!["robots[0].count", "0"]),
        (
            "[[robots]]\ncount = 2\nstart = [50.0, 50.0, 0.0]\n",
            vec!["robots[0].start", "count = 1"],
        ),
        (
            "[[robots]]\nradius_px = -3.0\n",
            vec!["robots[0].radius_px", "-3"],
        ),
        ("[[robots]]\nspeed = 3.0\n", vec!["speed"]),
        (
            "[[robots]]\non_arrival = \"fly\"\n",
            vec!["on_arrival", "fly"],
        ),
        (
            "[[robots]]\ngoal_count = 0\n",
            vec!["robots[0].goal_count", "0"],
        ),
        (
            "[[robots]]\norder = \"shortest\"\n",
            vec!["order", "shortest"],
        ),
        (
            "[[robots]]\nstart = [150.0, 150.0, 0.0]\n\n[[robots]]\nstart = [155.0, 150.0, 0.0]\n",
            vec![
                "robot 1's start",
                "5.0 px from robot 0's",
                "overlapping robots cannot start",
            ],
        ),
        (
            "[[robots]]\nstart = [5000.0, 5000.0, 0.0]\n",
            vec!["robots[0].start", "(5000, 5000)", "is not free"],
        ),
    ] {
        let f = dir.path().join("bad.toml");
        std::fs::write(&f, text).unwrap();
        let out = dir.path().join("never");
        assert_rejected(
            &[
                "run",
                "--policy",
                "geodesic",
                "--scenario",
                f.to_str().unwrap(),
                "--out",
                out.to_str().unwrap(),
            ],
            &names,
        );
        assert!(!out.exists());
    }
}

#[test]
fn gif_animates_a_team_episode_with_every_robot_in_its_colour() {
    use image::AnimationDecoder;
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("swap");
    run_team(
        &shipped("corridor-swap.toml"),
        &out,
        &["--seeds", "2", "--gif", "1"],
    );
    let gif = out.join("gif/seed-000001-deadlock.gif");
    let file = std::io::BufReader::new(std::fs::File::open(&gif).unwrap());
    let frames: Vec<image::RgbaImage> = image::codecs::gif::GifDecoder::new(file)
        .unwrap()
        .into_frames()
        .map(|f| f.unwrap().into_buffer())
        .collect();
    let episodes = rows(&out.join("episodes.csv"));
    let steps: usize = episodes[2][col(&episodes, "steps")].parse().unwrap();
    // The start and a frame after every step.
    assert_eq!(frames.len(), steps + 1);
    // Robot 0 (blue) starts at the left end, robot 1 (orange) at the right.
    let xs = |img: &image::RgbaImage, colour: [u8; 3]| -> Vec<u32> {
        img.enumerate_pixels()
            .filter(|(_, _, p)| p.0[..3] == colour)
            .map(|(x, _, _)| x)
            .collect()
    };
    let (blue, orange) = ([31, 119, 180], [255, 127, 14]);
    let first = &frames[0];
    let (b, o) = (xs(first, blue), xs(first, orange));
    assert!(!b.is_empty() && !o.is_empty());
    assert!(b.iter().max() < o.iter().min(), "{b:?} {o:?}");
    // They drove towards each other.
    let last = frames.last().unwrap();
    assert!(xs(last, blue).iter().max() > b.iter().max());
    assert!(xs(last, orange).iter().min() < o.iter().min());
    // A seed outside the run is refused before anything runs.
    let swap = shipped("corridor-swap.toml");
    let no = dir.path().join("no");
    assert_rejected(
        &[
            "run",
            "--scenario",
            swap.to_str().unwrap(),
            "--policy",
            "geodesic",
            "--seeds",
            "2",
            "--gif",
            "5",
            "--out",
            no.to_str().unwrap(),
        ],
        &["--gif 5: not one of this run's seeds (0..=1)"],
    );
    assert!(!dir.path().join("no").exists());
}

#[test]
fn bench_times_a_team_step_of_every_robot() {
    let dir = tempfile::tempdir().unwrap();
    let scenario = dir.path().join("team.toml");
    std::fs::write(
        &scenario,
        "[scene]\nkind = \"maze\"\n\n[laser]\nbeams = 64\nfov_deg = 360.0\nrange_px = 200.0\n\n[[robots]]\ncount = 12\n",
    )
    .unwrap();
    let text = ok(&ronap(&[
        "bench",
        "--scenario",
        scenario.to_str().unwrap(),
        "--seconds",
        "0.1",
        "--threads",
        "2",
    ]));
    assert!(text.contains("64 beams over 360 deg to 200 px"), "{text}");
    let one = text.lines().find(|l| l.contains("one thread")).unwrap();
    assert!(one.contains("ms per step of all 12 robots"), "{one}");
    let ms: f64 = one.split_whitespace().nth(2).unwrap().parse().unwrap();
    assert!(ms > 0.0, "{one}");
    let two = text.lines().find(|l| l.contains("2 threads")).unwrap();
    assert!(
        two.contains("team steps/s") && two.contains("robot-steps/s"),
        "{two}"
    );
}

#[test]
fn bench_times_a_team_policys_planning_and_steps() {
    let scenario = shipped("corridor-bay.toml");
    let text = ok(&ronap(&[
        "bench",
        "--scenario",
        scenario.to_str().unwrap(),
        "--policy",
        "coordinated",
        "--seconds",
        "0.2",
    ]));
    let figure = |name: &str| -> f64 {
        let line = text.lines().find(|l| l.contains(name)).unwrap();
        line.split_whitespace().nth(1).unwrap().parse().unwrap()
    };
    assert!(figure("planning") > 0.0, "{text}");
    assert!(text.contains("ms per team (coordinated, mean of"), "{text}");
    let one = text.lines().find(|l| l.contains("one thread")).unwrap();
    assert!(one.contains("decisions included"), "{one}");
    // A lone robot has no team policy to time: one line says so.
    assert_rejected(
        &["bench", "--policy", "geodesic", "--seconds", "0.1"],
        &["--policy", "team"],
    );
    // A policy that ends every episode at its start (the swap's plan is infeasible) has no step
    // to time: one line says so after a short search, where the bench once looked for ever.
    let swap = shipped("corridor-swap.toml");
    let args = [
        "bench",
        "--scenario",
        swap.to_str().unwrap(),
        "--policy",
        "coordinated",
        "--seconds",
        "0.01",
    ];
    assert_rejected(&args, &["--policy coordinated took no step", "ronap run"]);
}

#[test]
fn log_steps_writes_a_log_per_robot_and_replay_plays_the_team_again() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("team");
    let scenario = shipped("warehouse-team.toml");
    run_team(&scenario, &out, &["--seeds", "2", "--log-steps"]);
    let robots = rows(&out.join("robots.csv"));
    let (seed, robot, taken) = (
        col(&robots, "seed"),
        col(&robots, "robot"),
        col(&robots, "steps"),
    );
    let steps = out.join("steps");
    assert_eq!(robots.len(), 1 + 2 * 8);
    for r in &robots[1..] {
        let seed: u64 = r[seed].parse().unwrap();
        let log = steps.join(format!("seed-{seed:06}-robot-{}.csv", r[robot]));
        // One row per step the robot acted, as robots.csv counts them (and the header).
        assert_eq!(
            (rows(&log).len() - 1).to_string(),
            r[taken],
            "{}",
            log.display()
        );
    }
    let one = steps.join("seed-000001-robot-2.csv");
    let said = ok(&ronap(&["replay", one.to_str().unwrap(), "--stride", "5"]));
    assert!(said.contains("8 robots"), "{said}");
    let gif = steps.join("seed-000001-team-top.gif");
    assert!(std::fs::read(&gif).unwrap().starts_with(b"GIF89a"));
    // The first-person view is the given log's robot's.
    let said = ok(&ronap(&[
        "replay",
        one.to_str().unwrap(),
        "--view",
        "first",
    ]));
    assert!(said.contains("frames of 240 x 240"), "{said}");
    let first = steps.join("seed-000001-robot-2-first.gif");
    assert!(std::fs::read(&first).unwrap().starts_with(b"GIF89a"));
    // A robot's log bent at one step no longer replays, and the error names the robot.
    let bent = steps.join("seed-000001-robot-5.csv");
    let text = std::fs::read_to_string(&bent).unwrap();
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    let mut cells: Vec<String> = lines[4].split(',').map(String::from).collect();
    let x: f64 = cells[2].parse().unwrap();
    cells[2] = format!("{:.3}", x + 0.5);
    lines[4] = cells.join(",");
    std::fs::write(&bent, lines.join("\n") + "\n").unwrap();
    let o = ronap(&["replay", one.to_str().unwrap()]);
    assert_ne!(o.status.code(), Some(0));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("robot 5, step 4"), "{err}");
}

/// A team of one (`[[robots]] count = 1`) is the lone robot, run for run: every column the two
/// run files share holds the same text, seed by seed, and so do the summary's figures, the
/// pictures and the animations.
#[test]
fn a_team_of_one_runs_as_the_lone_robot_column_for_column() {
    let dir = tempfile::tempdir().unwrap();
    let pedestrians = std::fs::read_to_string(shipped("maze-pedestrians.toml")).unwrap();
    // The robot follows the crowd's circle there.
    let crossing = std::fs::read_to_string(shipped("circle-crossing.toml")).unwrap();
    for (name, base, policy) in [
        ("maze", String::new(), "apf"),
        ("maze", String::new(), "geodesic"),
        ("pedestrians", pedestrians.clone(), "geodesic-wait"),
        ("pedestrians", pedestrians, "orca"),
        ("crossing", crossing, "social-force"),
    ] {
        let lone_file = dir.path().join(format!("{name}-{policy}-lone.toml"));
        let team_file = dir.path().join(format!("{name}-{policy}-team.toml"));
        std::fs::write(&lone_file, &base).unwrap();
        std::fs::write(&team_file, format!("{base}\n[[robots]]\ncount = 1\n")).unwrap();
        let run = |file: &std::path::Path, out: &str| {
            let out = dir.path().join(out);
            ok(&ronap(&[
                "run",
                "--scenario",
                file.to_str().unwrap(),
                "--policy",
                policy,
                "--seeds",
                "30",
                "--png",
                "3",
                "--gif",
                "2",
                "--log-steps",
                "--out",
                out.to_str().unwrap(),
            ]));
            out
        };
        let lone = run(&lone_file, &format!("{name}-{policy}-lone"));
        let team = run(&team_file, &format!("{name}-{policy}-team"));
        let episodes = rows(&lone.join("episodes.csv"));
        let robots = rows(&team.join("robots.csv"));
        assert_eq!(episodes.len(), robots.len(), "{name} {policy}");
        let shared: Vec<&String> = episodes[0]
            .iter()
            .filter(|c| robots[0].contains(c))
            .collect();
        assert!(shared.len() >= 12, "{shared:?}");
        for column in shared {
            let (a, b) = (col(&episodes, column), col(&robots, column));
            for (e, r) in episodes.iter().zip(&robots).skip(1) {
                assert_eq!(e[a], r[b], "{name} {policy}: seed {} {column}", e[0]);
            }
        }
        let figures = |dir: &std::path::Path| {
            let mut s = summary(dir);
            for k in ["wall_time_s", "steps_per_second"] {
                s.as_object_mut().unwrap().remove(k);
            }
            s
        };
        assert_eq!(figures(&lone), figures(&team), "{name} {policy}: summary");
        let pictures = |dir: &std::path::Path, folder: &str| {
            let mut found: Vec<_> = std::fs::read_dir(dir.join(folder))
                .unwrap()
                .map(|e| e.unwrap().path())
                .collect();
            found.sort();
            found
                .iter()
                .map(|p| (p.file_name().unwrap().to_owned(), std::fs::read(p).unwrap()))
                .collect::<Vec<_>>()
        };
        for (folder, count) in [("png", 3), ("gif", 1)] {
            let (a, b) = (pictures(&lone, folder), pictures(&team, folder));
            assert_eq!(a.len(), count, "{name} {policy} {folder}: {:?}", a.len());
            assert!(a == b, "{name} {policy}: the {folder} files differ");
        }
        // Replayed from its step log, a team of one is the lone robot in either view.
        for view in ["top", "first"] {
            let replayed = |log: std::path::PathBuf| {
                let gif = dir.path().join(format!("{name}-{policy}-{view}.gif"));
                let args = ["replay", log.to_str().unwrap(), "--view", view, "--out"];
                ok(&ronap(&[&args[..], &[gif.to_str().unwrap()]].concat()));
                std::fs::read(gif).unwrap()
            };
            let a = replayed(lone.join("steps/seed-000002.csv"));
            let b = replayed(team.join("steps/seed-000002-robot-0.csv"));
            assert!(a == b, "{name} {policy}: the replayed {view} views differ");
        }
    }
}

/// Every shipped scenario of one robot, given `[[robots]] count = 1`, runs as its lone robot:
/// every column `robots.csv` shares with `episodes.csv` holds the same text, seed by seed.
#[test]
fn every_shipped_lone_scenario_is_its_team_of_one() {
    let dir = tempfile::tempdir().unwrap();
    // The scenarios with the maps they name, copied.
    let copies = dir.path().join("scenarios");
    std::fs::create_dir(&copies).unwrap();
    let shipped_dir = repo_root().join("scenarios");
    for entry in std::fs::read_dir(&shipped_dir).unwrap() {
        let path = entry.unwrap().path();
        std::fs::copy(&path, copies.join(path.file_name().unwrap())).unwrap();
    }
    let mut compared = 0;
    for entry in std::fs::read_dir(&shipped_dir).unwrap() {
        let name = entry.unwrap().file_name().to_string_lossy().into_owned();
        let path = copies.join(&name);
        let text = std::fs::read_to_string(&path).unwrap_or_default();
        let Some(name) = name.strip_suffix(".toml") else {
            continue;
        };
        if text.contains("[[robots]]") {
            continue;
        }
        let team_file = copies.join(format!("{name}-team-of-one.toml"));
        std::fs::write(&team_file, format!("{text}\n[[robots]]\ncount = 1\n")).unwrap();
        let run = |file: &Path, out: &str| {
            let out = dir.path().join(out);
            let args = [
                "run",
                "--scenario",
                file.to_str().unwrap(),
                "--policy",
                "geodesic",
            ];
            let more = ["--seeds", "4", "--out", out.to_str().unwrap()];
            let o = ronap(&[&args[..], &more].concat());
            (o, out)
        };
        let (lone, lone_out) = run(&path, &format!("{name}-lone"));
        let (team, team_out) = run(&team_file, &format!("{name}-team"));
        ok(&lone);
        ok(&team);
        let episodes = rows(&lone_out.join("episodes.csv"));
        let robots = rows(&team_out.join("robots.csv"));
        assert_eq!(episodes.len(), robots.len(), "{name}");
        let shared: Vec<&String> = episodes[0]
            .iter()
            .filter(|c| robots[0].contains(c))
            .collect();
        assert!(shared.len() >= 12, "{name}: {shared:?}");
        for column in shared {
            let (a, b) = (col(&episodes, column), col(&robots, column));
            for (e, r) in episodes.iter().zip(&robots).skip(1) {
                assert_eq!(e[a], r[b], "{name}: seed {} {column}", e[0]);
            }
        }
        compared += 1;
    }
    assert!(compared >= 10, "only {compared} scenarios");
}

/// `ronap run --scenario FILE --policy coordinated --seeds N` into `out`: its table.
fn coordinated(scenario: &Path, out: &Path, seeds: &str, more: &[&str]) -> String {
    let mut args = vec!["run", "--scenario", scenario.to_str().unwrap(), "--policy"];
    args.extend([
        "coordinated",
        "--seeds",
        seeds,
        "--out",
        out.to_str().unwrap(),
    ]);
    args.extend(more);
    ok(&ronap(&args))
}

/// Every team of the run's `seeds` episodes came home without touching a robot or a wall.
fn assert_all_home_untouched(table: &str, seeds: u32) {
    let want = format!("team success            100.0% ({seeds} of {seeds}");
    assert!(table.contains(&want), "{table}");
    assert_eq!(row(table, "robot collisions"), "0.00 per episode");
    assert_eq!(row(table, "wall collisions"), "0.00 per episode");
}

#[test]
fn coordinated_names_the_corridor_swap_infeasible_before_its_first_step() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("swap");
    let table = coordinated(&shipped("corridor-swap.toml"), &out, "3", &[]);
    assert_eq!(
        row(&table, "infeasible"),
        "3 (each one's reason in robots.csv)"
    );
    assert_eq!(row(&table, "deadlocks"), "0");
    let episodes = rows(&out.join("episodes.csv"));
    let (outcome, steps) = (col(&episodes, "outcome"), col(&episodes, "steps"));
    for r in &episodes[1..] {
        assert_eq!(
            (r[outcome].as_str(), r[steps].as_str()),
            ("infeasible", "0")
        );
    }
    let robots = rows(&out.join("robots.csv"));
    let (outcome, reason) = (col(&robots, "outcome"), col(&robots, "reason"));
    for r in &robots[1..] {
        assert_eq!(r[outcome], "infeasible");
        assert!(
            r[reason].starts_with("robots 0 and 1 cannot pass each other between ("),
            "{}",
            r[reason]
        );
    }
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(json["team"]["infeasible"], 3);
    assert_eq!(summary(&out)["among_robots"]["infeasible"], 6);
}

#[test]
fn coordinated_brings_both_robots_through_the_corridor_with_a_bay() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("bay");
    let table = coordinated(&shipped("corridor-bay.toml"), &out, "3", &[]);
    assert_all_home_untouched(&table, 3);
}

#[test]
fn coordinated_brings_both_discrete_robots_through_the_corridor_with_a_bay() {
    // The paper's actions: turns of 15 degrees on the spot and steps of 5 px. The robot
    // planned first must wait in the corridor while the other gives way in the bay, which a
    // priority order cannot plan; the two are planned together.
    let dir = tempfile::tempdir().unwrap();
    let scenario = dir.path().join("corridor-bay-discrete.toml");
    let text = std::fs::read_to_string(shipped("corridor-bay.toml")).unwrap();
    assert!(!text.contains("[orca]"), "the scenario has an [orca] table");
    let text = format!("{text}\n[orca]\nactions = \"discrete\"\n");
    std::fs::write(&scenario, text).unwrap();
    let table = coordinated(&scenario, &dir.path().join("bay"), "3", &[]);
    assert_all_home_untouched(&table, 3);
}

#[test]
fn coordinated_brings_every_warehouse_team_home_with_no_deadlock() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("warehouse");
    let warehouse = shipped("warehouse-team.toml");
    let table = coordinated(&warehouse, &out, "10", &[]);
    assert!(
        table.contains("team success            100.0% (10 of 10"),
        "{table}"
    );
    assert_eq!(row(&table, "deadlocks"), "0");
    // The same bytes again, and on one thread.
    let again = dir.path().join("again");
    coordinated(&warehouse, &again, "10", &["--threads", "1"]);
    for f in ["episodes.csv", "robots.csv"] {
        assert_eq!(
            std::fs::read(out.join(f)).unwrap(),
            std::fs::read(again.join(f)).unwrap(),
            "{f}"
        );
    }
}

#[test]
fn coordinated_is_refused_for_a_lone_robot_and_beside_another_policy() {
    assert_rejected(
        &["run", "--policy", "coordinated", "--seeds", "1"],
        &["--policy coordinated: a team planner, for scenarios with [[robots]]"],
    );
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("mixed.toml");
    std::fs::write(
        &file,
        "[[robots]]\ncount = 2\n\n[[robots]]\npolicy = \"geodesic\"\n",
    )
    .unwrap();
    assert_rejected(
        &[
            "run",
            "--scenario",
            file.to_str().unwrap(),
            "--policy",
            "coordinated",
            "--seeds",
            "1",
        ],
        &["robot 2: policy geodesic beside coordinated"],
    );
}
