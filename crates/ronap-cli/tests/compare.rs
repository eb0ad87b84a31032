//! End-to-end tests of `ronap compare`: the table and every file read back, the same episodes as
//! separate `ronap run`s, identical policies, reused runs, difficulty bins and bad input.

use crate::util::{
    assert_rejected, assert_rejected_leaving_nothing, col, json, ok, repo_root, ronap, rows,
    run_args, shipped,
};
use std::path::Path;

/// The pair of policies most tests compare.
const APF_GEODESIC: [&str; 4] = ["--policy", "apf", "--policy", "geodesic"];

/// [`APF_GEODESIC`], binned by difficulty.
const APF_GEODESIC_BY_DIFFICULTY: [&str; 6] = [
    "--policy",
    "apf",
    "--policy",
    "geodesic",
    "--by",
    "difficulty",
];

/// The first pair's verdict in `compare.json` is `verdict`.
fn assert_verdict(pair: &serde_json::Value, verdict: &str) {
    assert_eq!(pair["verdict"].as_str(), Some(verdict), "{pair}");
}

fn compare(out: &Path, extra: &[&str]) -> String {
    let mut args = vec!["compare", "--seeds", "16", "--out", out.to_str().unwrap()];
    args.extend_from_slice(extra);
    ok(&ronap(&args))
}

#[test]
fn compare_prints_the_table_and_writes_the_report_and_the_runs() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("cmp");
    let table = compare(&out, &APF_GEODESIC);
    for needle in [
        "success = the robot's centre comes within 10 px",
        "success (95% CI)",
        "apf vs geodesic",
        "McNemar p",
    ] {
        assert!(table.contains(needle), "{needle:?} not in\n{table}");
    }
    let report = json(&out.join("compare.json"));
    assert_eq!(report["policies"].as_array().unwrap().len(), 2);
    assert_eq!(report["pairs"].as_array().unwrap().len(), 1);
    assert!(report["success_rule"].as_str().unwrap().contains("10 px"));
    let pair = &report["pairs"][0];
    // geodesic succeeds wherever apf does in the default maze.
    assert_eq!(pair["a_only"], 0);
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(md.contains("| apf |") && md.contains("![") && md.contains("ronap compare --seeds 16"));
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert!(html.starts_with("<!DOCTYPE html>") && html.trim_end().ends_with("</html>"));
    assert_eq!(
        html.matches("<table>").count(),
        html.matches("</table>").count()
    );
    // Pictures are inlined as PNGs that decode.
    let b64 = html.split("data:image/png;base64,").nth(1).unwrap();
    let b64 = &b64[..b64.find('"').unwrap()];
    use base64::Engine as _;
    let bytes = base64::engine::general_purpose::STANDARD
        .decode(b64)
        .unwrap();
    image::load_from_memory(&bytes).unwrap();
    for png in ["compare.png", "outcomes.png"] {
        image::open(out.join(png)).unwrap();
    }
    // Nothing half-written is left behind.
    let leftovers: Vec<_> = std::fs::read_dir(&out)
        .unwrap()
        .flatten()
        .filter(|e| e.file_name().to_string_lossy().starts_with('.'))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
    // Each policy's run is the one `ronap run` makes.
    let alone = dir.path().join("alone");
    ok(&ronap(&run_args("apf", &["--seeds", "16"], &alone)));
    assert_eq!(
        std::fs::read(alone.join("episodes.csv")).unwrap(),
        std::fs::read(out.join("runs/apf/episodes.csv")).unwrap()
    );
    let seeds = rows(&out.join("seeds.csv"));
    assert_eq!(seeds.len(), 17);
    assert_eq!(seeds[0][..3], ["seed", "apf_outcome", "apf_spl"]);
}

#[test]
fn two_identical_policies_show_no_difference() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("cmp");
    compare(&out, &["--policy", "apf", "--policy", "apf"]);
    let report = json(&out.join("compare.json"));
    let pair = &report["pairs"][0];
    assert_eq!(
        (pair["a"].as_str(), pair["b"].as_str()),
        (Some("apf"), Some("apf-2"))
    );
    assert_eq!(
        (pair["a_only"].as_u64(), pair["b_only"].as_u64()),
        (Some(0), Some(0))
    );
    assert_eq!(pair["mcnemar_p"].as_f64(), Some(1.0));
    assert_eq!(pair["spl_diff"].as_f64(), Some(0.0));
    assert_verdict(
        pair,
        "success: too few discordant seeds; SPL: not significant",
    );
    // They agree on every seed: no contact sheet.
    assert!(!out.join("disagreements.png").exists());
}

#[test]
fn a_reused_run_gives_the_same_comparison() {
    let dir = tempfile::tempdir().unwrap();
    let fresh = dir.path().join("fresh");
    compare(&fresh, &APF_GEODESIC);
    let reused = dir.path().join("reused");
    let geodesic_run = fresh.join("runs/geodesic");
    let table = compare(
        &reused,
        &["--policy", "apf", "--run", geodesic_run.to_str().unwrap()],
    );
    assert!(table.contains("apf vs geodesic"), "{table}");
    let (a, b) = (
        json(&fresh.join("compare.json")),
        json(&reused.join("compare.json")),
    );
    assert_eq!(a["pairs"], b["pairs"]);
    assert_eq!(b["policies"][1]["reused"], true);
    assert!(!reused.join("runs/geodesic").exists());
    // A run of other seeds, or of another configuration, is refused by name, and a lone robot's
    // run is not read as a team's.
    let two = dir.path().join("two.toml");
    std::fs::write(&two, "[[robots]]\ncount = 2\n").unwrap();
    let reuse = ["--policy", "apf", "--run", geodesic_run.to_str().unwrap()];
    for (more, out, names) in [
        (&["--seeds", "10"][..], "x", &["seeds 0..15", "0..9"][..]),
        (
            &["--seeds", "16", "--max-steps", "900"],
            "y",
            &["episode.max_steps", "2000", "900"],
        ),
        (
            &["--seeds", "16", "--scenario", two.to_str().unwrap()],
            "z",
            &["a lone robot's run", "a team"],
        ),
    ] {
        let out = dir.path().join(out);
        let args = [
            &["compare"][..],
            more,
            &reuse,
            &["--out", out.to_str().unwrap()],
        ]
        .concat();
        assert_rejected(&args, &[&["--run"][..], names].concat());
    }
    // A run made under another model, or whose files were edited, is refused by name: its
    // figures would not be this ronap's, or the two tables would contradict each other.
    let copy = |name: &str, edit: &dyn Fn(&str, &str) -> (String, String)| {
        let run = dir.path().join(name);
        std::fs::create_dir(&run).unwrap();
        for f in std::fs::read_dir(&geodesic_run).unwrap() {
            let f = f.unwrap().path();
            if f.is_file() {
                std::fs::copy(&f, run.join(f.file_name().unwrap())).unwrap();
            }
        }
        let (summary, episodes) = (run.join("summary.json"), run.join("episodes.csv"));
        let (s, e) = edit(
            &std::fs::read_to_string(&summary).unwrap(),
            &std::fs::read_to_string(&episodes).unwrap(),
        );
        std::fs::write(summary, s).unwrap();
        std::fs::write(episodes, e).unwrap();
        run
    };
    let older = copy("older", &|s, e| {
        let s = s.replace(
            &format!("\"model_version\": {}", ronap_core::MODEL_VERSION),
            "\"model_version\": 1",
        );
        (s, e.to_string())
    });
    let not_a_number = copy("nan", &|s, e| {
        let mut lines: Vec<String> = e.lines().map(String::from).collect();
        let spl = lines[0].split(',').position(|h| h == "spl").unwrap();
        let mut cells: Vec<&str> = lines[2].split(',').collect();
        cells[spl] = "nan";
        lines[2] = cells.join(",");
        (s.to_string(), lines.join("\n") + "\n")
    });
    let edited = copy("edited", &|s, e| {
        (s.to_string(), e.replacen(",success,", ",stuck,", 1))
    });
    for (run, names) in [
        (
            &older,
            &["model version 1", "this ronap runs model version"][..],
        ),
        (&not_a_number, &["line 3", "spl", "nan"]),
        (&edited, &["summary.json", "disagree"]),
    ] {
        let out = dir.path().join("never");
        let args = [
            "compare",
            "--seeds",
            "16",
            "--policy",
            "apf",
            "--run",
            run.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ];
        assert_rejected_leaving_nothing(&args, &[&["--run"][..], names].concat(), &out);
    }
}

#[test]
fn by_difficulty_bins_every_seed() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("cmp");
    let table = compare(&out, &APF_GEODESIC_BY_DIFFICULTY);
    assert!(table.contains("by path / straight ratio"), "{table}");
    let report = json(&out.join("compare.json"));
    let by = report["by_difficulty"].as_array().unwrap();
    assert_eq!(by.len(), 3);
    for figure in by {
        let seeds: u64 = figure["bins"]
            .as_array()
            .unwrap()
            .iter()
            .map(|b| b["seeds"].as_u64().unwrap())
            .sum();
        assert_eq!(seeds + figure["unbinned"].as_u64().unwrap(), 16);
    }
    let seeds = rows(&out.join("seeds.csv"));
    let ratio = seeds[0].iter().position(|h| h == "ratio").unwrap();
    assert!(seeds[1..]
        .iter()
        .all(|r| r[ratio].parse::<f64>().unwrap() >= 0.99));
    image::open(out.join("difficulty.png")).unwrap();
}

#[test]
fn a_comparison_that_stopped_short_says_how_to_use_what_it_finished() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("cmp");
    let o = out.to_str().unwrap();
    let script = dir.path().join("p.py");
    std::fs::write(&script, "def act(obs):\n    raise ValueError('broken')\n").unwrap();
    let py = format!("py:{}:act", script.display());
    let args = [
        "compare", "--policy", "apf", "--policy", &py, "--seeds", "4", "--out", o,
    ];
    let failed = ronap(&args);
    assert_eq!(failed.status.code(), Some(2));
    // Mended, the same command names the finished run it would replace and the two ways on.
    std::fs::write(&script, "def act(obs):\n    return 1\n").unwrap();
    let apf = out.join("runs/apf");
    let apf = apf.to_str().unwrap();
    assert_rejected(&args, &[apf, "--run", "--policy apf", "--force"]);
    let reused = [
        "compare", "--run", apf, "--policy", &py, "--seeds", "4", "--out", o,
    ];
    let table = ok(&ronap(&reused));
    assert!(
        table.contains("act vs apf") || table.contains("apf vs act"),
        "{table}"
    );
}

#[test]
fn a_run_and_a_comparison_are_not_written_into_each_other() {
    let dir = tempfile::tempdir().unwrap();
    let (run, cmp) = (dir.path().join("run"), dir.path().join("cmp"));
    let (r, c) = (run.to_str().unwrap(), cmp.to_str().unwrap());
    ok(&ronap(&run_args("apf", &["--seeds", "2"], &run)));
    let pair = [
        "compare", "--policy", "apf", "--policy", "geodesic", "--seeds", "2",
    ];
    ok(&ronap(&[&pair[..], &["--out", c]].concat()));
    assert_rejected(
        &[&pair[..], &["--out", r]].concat(),
        &[
            r,
            "holds a ronap run (its summary.json), not a comparison",
            "--force",
        ],
    );
    assert_rejected(
        &run_args("apf", &["--seeds", "2"], &cmp),
        &[
            c,
            "holds a comparison (its compare.json), not a run",
            "--force",
        ],
    );
}

#[test]
fn bad_input_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("never");
    let o = out.to_str().unwrap();
    assert_rejected(
        &["compare", "--policy", "apf", "--out", o],
        &["at least two"],
    );
    assert_rejected(
        &["compare", "--policy", "apf", "--policy", "nope", "--out", o],
        &["nope"],
    );
    assert_rejected(
        &[
            "compare",
            "--policy",
            "apf",
            "--run",
            "/no/such/run",
            "--out",
            o,
        ],
        &["/no/such/run"],
    );
    assert_rejected(
        &[
            "compare", "--policy", "apf", "--policy", "geodesic", "--by", "luck",
        ],
        &["--by", "luck"],
    );
    assert!(!out.exists());
}

#[test]
fn one_seed_calls_nothing_and_an_earlier_comparison_leaves_nothing_behind() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("cmp");
    compare(&out, &APF_GEODESIC_BY_DIFFICULTY);
    assert!(out.join("difficulty.png").exists());
    let o = ok(&ronap(&[
        "compare",
        "--seeds",
        "1",
        "--seed-start",
        "3",
        "--policy",
        "apf",
        "--policy",
        "geodesic",
        "--out",
        out.to_str().unwrap(),
        "--force",
    ]));
    assert!(o.contains("1 seeds (3 to 3)"), "{o}");
    let pair = &json(&out.join("compare.json"))["pairs"][0];
    assert!(pair["spl_diff_ci95"].is_null(), "{pair}");
    assert_verdict(
        pair,
        "success: too few discordant seeds; SPL: too few seeds",
    );
    // The earlier comparison's difficulty picture is gone with it.
    assert!(!out.join("difficulty.png").exists());
}

#[test]
fn a_fresh_run_never_overwrites_a_reused_one() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("cmp");
    compare(&out, &APF_GEODESIC);
    let apf = out.join("runs/apf");
    let before = std::fs::read(apf.join("episodes.csv")).unwrap();
    // Reuse runs/apf while running another policy whose label is also `apf` into the same --out.
    let weights = dir.path().join("apf.safetensors");
    std::fs::copy(repo_root().join("policies/bc.safetensors"), &weights).unwrap();
    let policy = format!("mlp:{}", weights.display());
    assert_rejected(
        &[
            "compare",
            "--seeds",
            "16",
            "--policy",
            &policy,
            "--run",
            apf.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ],
        &["--run", "give another --out"],
    );
    assert_eq!(std::fs::read(apf.join("episodes.csv")).unwrap(), before);
}

#[test]
fn a_team_scenario_is_compared_on_team_success_with_a_table_per_robot() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("cmp");
    let scenario = shipped("warehouse-team.toml");
    let team = [
        "compare",
        "--scenario",
        scenario.to_str().unwrap(),
        "--policy",
        "geodesic",
        "--policy",
        "random",
    ];
    let more = [
        "--seeds",
        "6",
        "--max-steps",
        "600",
        "--out",
        out.to_str().unwrap(),
    ];
    let o = ok(&ronap(&[&team[..], &more].concat()));
    for part in [
        "team success = each of the 8 robots",
        "Teams (a success: every robot arrived)",
        "Robots (every robot of every team episode)",
        "team success a-b",
        "geodesic vs random",
    ] {
        assert!(o.contains(part), "{part:?} not in {o}");
    }
    let c = json(&out.join("compare.json"));
    let geodesic = &c["policies"][0];
    assert_eq!(geodesic["team"]["robots"], 8);
    assert_eq!(geodesic["team"]["episodes"], 6);
    assert_eq!(geodesic["summary"]["episodes"], 48, "every robot's episode");
    // The pairs count team successes: only-a + both = geodesic's team successes.
    let pair = &c["pairs"][0];
    let (a_only, b_only) = (
        pair["a_only"].as_u64().unwrap(),
        pair["b_only"].as_u64().unwrap(),
    );
    let team_a = geodesic["team"]["team_successes"].as_u64().unwrap();
    let team_b = c["policies"][1]["team"]["team_successes"].as_u64().unwrap();
    assert_eq!(
        team_a as i64 - team_b as i64,
        a_only as i64 - b_only as i64,
        "{pair}"
    );
    // Each policy's run is an ordinary team run directory.
    for label in ["geodesic", "random"] {
        let run = out.join("runs").join(label);
        assert_eq!(rows(&run.join("robots.csv")).len(), 1 + 6 * 8, "{label}");
        assert_eq!(rows(&run.join("episodes.csv")).len(), 1 + 6, "{label}");
    }
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(report.contains("## Teams"), "{report}");
    assert!(out.join("compare.png").exists() && out.join("outcomes.png").exists());
    // The contact sheet draws each policy's team episode where they disagree most.
    let sheet = image::open(out.join("disagreements.png"))
        .unwrap()
        .to_rgb8();
    let coloured = sheet
        .pixels()
        .filter(|p| p.0.iter().max().unwrap() - p.0.iter().min().unwrap() > 60)
        .count();
    // The robots' coloured paths, not only the policies' coloured names above the columns.
    assert!(coloured > 3000, "{coloured} coloured pixels");
    // By difficulty, a team's seeds are binned by their hardest robot's task.
    let binned = dir.path().join("binned");
    let by = [
        "--seeds",
        "4",
        "--max-steps",
        "300",
        "--by",
        "difficulty",
        "--bins",
        "2",
        "--out",
        binned.to_str().unwrap(),
    ];
    let table = ok(&ronap(&[&team[..], &by].concat()));
    assert!(table.contains("by path / straight ratio"), "{table}");
    let seeds = rows(&binned.join("seeds.csv"));
    assert_eq!(seeds.len(), 1 + 4);
    let (ratio, turns) = (col(&seeds, "ratio"), col(&seeds, "turns"));
    for r in &seeds[1..] {
        assert!(r[ratio].parse::<f64>().unwrap() >= 1.0, "{r:?}");
        assert!(
            r[turns].parse::<u32>().unwrap() >= 1,
            "racks to go round: {r:?}"
        );
    }
    image::open(binned.join("difficulty.png")).unwrap();
    // Both team runs read back give the same comparison, and run nothing.
    let runs: Vec<String> = ["geodesic", "random"]
        .iter()
        .map(|l| out.join("runs").join(l).to_str().unwrap().to_string())
        .collect();
    let reused = dir.path().join("reused");
    let again = [
        "compare",
        "--scenario",
        scenario.to_str().unwrap(),
        "--run",
        &runs[0],
        "--run",
        &runs[1],
        "--seeds",
        "6",
        "--max-steps",
        "600",
        "--out",
        reused.to_str().unwrap(),
    ];
    ok(&ronap(&again));
    let r = json(&reused.join("compare.json"));
    assert_eq!(r["pairs"], c["pairs"]);
    for k in 0..2 {
        assert_eq!(r["policies"][k]["reused"], true);
        assert_eq!(r["policies"][k]["team"], c["policies"][k]["team"]);
    }
    assert!(!reused.join("runs/geodesic").exists());
    // A robot row that does not parse is named by file, line, column and value.
    let robots = out.join("runs/random/robots.csv");
    let text = std::fs::read_to_string(&robots).unwrap();
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    let spl = header.iter().position(|h| *h == "spl").unwrap();
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    let mut cells: Vec<String> = lines[3].split(',').map(str::to_string).collect();
    cells[spl] = "most".into();
    lines[3] = cells.join(",");
    std::fs::write(&robots, lines.join("\n") + "\n").unwrap();
    let bad = reused.to_str().unwrap().replace("reused", "bad");
    let mut refused = again;
    refused[refused.len() - 1] = &bad;
    assert_rejected(&refused, &["robots.csv", "line 4", "spl = \"most\""]);
    // A robot's row missing is named with the seed and the count episodes.csv gives.
    lines.remove(3);
    std::fs::write(&robots, lines.join("\n") + "\n").unwrap();
    assert_rejected(&refused, &["robots.csv", "7 rows of seed", "8 robots"]);
}

#[test]
fn every_seed_one_policy_alone_succeeded_on_gets_a_player_unless_capped() {
    let dir = tempfile::tempdir().unwrap();
    let players = |out: &Path| std::fs::read_dir(out.join("players")).map_or(0, |d| d.count());
    let compare = |name: &str, extra: &[&str]| {
        let out = dir.path().join(name);
        let mut args = vec![
            "compare", "--policy", "apf", "--policy", "geodesic", "--seeds", "12",
        ];
        args.extend_from_slice(extra);
        args.extend_from_slice(&["--out", out.to_str().unwrap()]);
        ok(&ronap(&args));
        out
    };
    let all = compare("all", &[]);
    let table = rows(&all.join("seeds.csv"));
    let mixed = table[1..]
        .iter()
        .filter(|r| (r[1] == "success") != (r[4] == "success"))
        .count();
    assert!(mixed > 2, "{table:?}");
    assert_eq!(players(&all), mixed);
    let report = std::fs::read_to_string(all.join("report.md")).unwrap();
    assert!(
        report.contains(&format!("the {mixed} seeds where one policy succeeded")),
        "{report}"
    );
    let two = compare("two", &["--players", "2"]);
    assert_eq!(players(&two), 2);
    assert_rejected(
        &["compare", "--policy", "apf", "--players", "lots"],
        &["lots", "all"],
    );
}
