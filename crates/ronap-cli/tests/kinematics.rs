//! Robots as they are built: the shipped scenarios of each kinematic model run and replay from
//! the command line, and a bad robot entry is one line naming the file, line, field and value.

use crate::util::*;

/// `ronap run` of `policy` over seeds 0 to `seeds - 1` of `scenario` into `out`.
fn run<'a>(policy: &'a str, scenario: &'a str, seeds: &'a str, out: &'a str) -> [&'a str; 9] {
    [
        "run",
        "--policy",
        policy,
        "--scenario",
        scenario,
        "--seeds",
        seeds,
        "--out",
        out,
    ]
}

/// Successes of `policy` over seeds 0 to `seeds - 1` of shipped scenario `name`.
fn successes(name: &str, policy: &str, seeds: &str, out: &std::path::Path) -> u64 {
    let scenario = shipped(name);
    let (scenario, out_text) = (scenario.to_str().unwrap(), out.to_str().unwrap());
    ok(&ronap(&run(policy, scenario, seeds, out_text)));
    summary(out)["successes"].as_u64().unwrap()
}

#[test]
fn each_models_scenario_runs_and_its_robot_reaches_goals() {
    let dir = tempfile::tempdir().unwrap();
    for (name, least) in [
        ("diff-drive-maze.toml", 10),
        ("omni-maze.toml", 10),
        ("warehouse-forklift.toml", 9),
    ] {
        let out = dir.path().join(name);
        let got = successes(name, "geodesic", "10", &out);
        assert!(got >= least, "{name}: {got} of 10");
    }
    // dwa searches a diff-drive base's own window.
    let out = dir.path().join("dwa");
    assert!(successes("diff-drive-maze.toml", "dwa", "10", &out) >= 9);
}

#[test]
fn a_cars_logged_episode_reads_back_its_steering_commands_and_replays() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("run");
    let scenario = shipped("warehouse-forklift.toml");
    let args = run(
        "geodesic",
        scenario.to_str().unwrap(),
        "1",
        out.to_str().unwrap(),
    );
    ok(&ronap(&[&args[..], &["--log-steps"]].concat()));
    let log = out.join("steps/seed-000000.csv");
    let table = rows(&log);
    let action = col(&table, "action");
    assert!(
        table[1..].iter().all(|r| r[action].contains(";steer=")),
        "a car is logged with its steering commands"
    );
    let o = ronap(&["replay", log.to_str().unwrap(), "--stride", "20"]);
    assert!(ok(&o).contains("seed 0"), "{}", stdout(&o));
}

#[test]
fn a_bad_robot_entry_is_named_with_its_line() {
    let dir = tempfile::tempdir().unwrap();
    for (text, names) in [
        (
            "[robot]\nkinematics = \"diff_drive\"\nsteer_max_deg = 20.0\n",
            &[":3:", "robot.steer_max_deg", "20", "ackermann"][..],
        ),
        (
            "[robot]\nkinematics = \"hover\"\n",
            &[":2:", "kinematics", "hover", "diff_drive"],
        ),
        (
            "[robot]\nkinematics = \"ackermann\"\n",
            &["robot.wheel_base_px", "ackermann"],
        ),
        (
            "[robot]\nshape = \"rectangle\"\nlength_px = 10.0\n",
            &["robot.width_px", "rectangle"],
        ),
        ("[laser]\ndropout = 1.5\n", &[":2:", "laser.dropout", "1.5"]),
        (
            "[robot]\nshape = \"polygon\"\nvertices = [[0.0, 0.0], [5.0, 5.0], [5.0, 0.0], [0.0, 5.0]]\n",
            &[":3:", "robot.vertices", "convex"],
        ),
        (
            "[robot]\nshape = \"polygon\"\nvertices = [[10.0, 10.0], [20.0, 10.0], [15.0, 20.0]]\n",
            &[":3:", "robot.vertices", "[0, 0]"],
        ),
        (
            "[robot]\nkinematics = \"omni\"\naccel_max_px = -1.0\n",
            &[":3:", "robot.accel_max_px", "-1"],
        ),
    ] {
        let file = dir.path().join("bad.toml");
        std::fs::write(&file, text).unwrap();
        let out = dir.path().join("out");
        let args = run("geodesic", file.to_str().unwrap(), "1", out.to_str().unwrap());
        assert_rejected_leaving_nothing(&args, names, &out);
    }
}

#[test]
fn coordinated_says_it_cannot_drive_a_car() {
    let dir = tempfile::tempdir().unwrap();
    let team = std::fs::read_to_string(shipped("corridor-bay.toml")).unwrap();
    let file = dir.path().join("cars.toml");
    std::fs::write(
        &file,
        format!("{team}\n[robot]\nkinematics = \"ackermann\"\nwheel_base_px = 8.0\n"),
    )
    .unwrap();
    let out = dir.path().join("out");
    let o = ronap(&run(
        "coordinated",
        file.to_str().unwrap(),
        "1",
        out.to_str().unwrap(),
    ));
    assert_ne!(o.status.code(), Some(0));
    let err = stderr(&o);
    assert!(
        err.contains("coordinated cannot drive a car-like robot") && !err.contains("panicked"),
        "{err}"
    );
}
