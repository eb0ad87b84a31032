//! The learning loop from the command line: collect, train, run; weights-file errors; the shipped
//! policies against their reported figures.

use crate::util::{
    assert_rejected, assert_rejected_leaving_nothing, collect_args, ok, repo_root, ronap, run_args,
    summary, text,
};

#[test]
fn collect_train_run_loop() {
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("expert.csv");
    let data_s = data.to_str().unwrap();
    let out = ok(&ronap(&[
        "collect",
        "--expert",
        "geodesic",
        "--mode",
        "drive",
        "--samples",
        "1500",
        "--per-episode",
        "300",
        "--out",
        data_s,
    ]));
    assert!(out.contains("1500 rows from "), "{out}");
    let log = std::fs::read_to_string(&data).unwrap();
    assert_eq!(log.lines().count(), 1501);
    assert!(log.starts_with("laser_0,"));

    // Re-posed rows (the paper's mode) face the goal: direction near 0 or 360.
    let reposed = dir.path().join("reposed.csv");
    ok(&ronap(&collect_args(
        "geodesic",
        &["--samples", "200"],
        &reposed,
    )));
    let text = std::fs::read_to_string(&reposed).unwrap();
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    let col = header.iter().position(|h| *h == "direction").unwrap();
    let facing = text
        .lines()
        .skip(1)
        .filter(|l| {
            let d: f64 = l.split(',').nth(col).unwrap().parse().unwrap();
            d.min(360.0 - d) < 33.0
        })
        .count();
    assert!(facing >= 197, "{facing} of 200 re-posed rows face the goal");

    let weights = dir.path().join("bc.safetensors");
    let weights_s = weights.to_str().unwrap();
    let out = ok(&ronap(&[
        "train",
        "bc",
        "--data",
        data_s,
        "--epochs",
        "3",
        "--batch",
        "64",
        "--hidden",
        "32,32",
        "--activation",
        "relu",
        "--lr",
        "0.003",
        "--out",
        weights_s,
    ]));
    assert!(
        out.contains("train acc") && out.contains("final: train accuracy"),
        "{out}"
    );
    let bytes = std::fs::read(&weights).unwrap();
    let mlp = ronap_core::policy::Mlp::from_bytes(&bytes).unwrap();
    assert_eq!(mlp.inputs(), 18);
    assert!(mlp.metadata["command"].contains("train bc"));

    let run_dir = dir.path().join("run");
    let policy = format!("mlp:{weights_s}@sample:2");
    ok(&ronap(&run_args(&policy, &["--seeds", "10"], &run_dir)));
    assert_eq!(summary(&run_dir)["episodes"], 10);
}

#[test]
fn dqn_trains_and_writes_weights() {
    let dir = tempfile::tempdir().unwrap();
    let weights = dir.path().join("dqn.safetensors");
    let out = ok(&ronap(&[
        "train",
        "dqn",
        "--steps",
        "3000",
        "--envs",
        "8",
        "--batch",
        "32",
        "--hidden",
        "16",
        "--max-steps",
        "200",
        "--report-every",
        "1000",
        "--shaping",
        "geodesic",
        "--eval-every",
        "1000",
        "--eval-seeds",
        "5",
        "--out",
        weights.to_str().unwrap(),
    ]));
    assert!(
        out.contains("mean return") && out.contains("success") && out.contains("validation"),
        "{out}"
    );
    let mlp = ronap_core::policy::Mlp::load(&weights).unwrap();
    assert_eq!(mlp.metadata["output"], "q_values");
    assert_eq!(mlp.metadata["decision"], "sample:0.3");
    // The curves beside the weights: a row per report, validation from the first.
    let log = std::fs::read_to_string(dir.path().join("dqn-training.csv")).unwrap();
    let lines: Vec<&str> = log.lines().collect();
    assert_eq!(
        lines[0],
        "steps,episodes,mean_return,success_rate,epsilon,loss,learning_rate,validation_success"
    );
    assert_eq!(lines.len(), 4, "{log}");
    assert!(lines[1..].iter().all(|l| !l.ends_with(',')), "{log}");
    let png = image::open(dir.path().join("dqn-training.png")).unwrap();
    assert!(png.width() >= 800, "{}", png.width());
    assert!(out.contains("dqn-training.png"), "{out}");
}

#[test]
fn bc_writes_its_accuracy_curves_beside_the_weights() {
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("rows.csv");
    let o = ronap(&collect_args("geodesic", &["--samples", "300"], &data));
    ok(&o);
    let weights = dir.path().join("bc.safetensors");
    ok(&ronap(&[
        "train",
        "bc",
        "--data",
        data.to_str().unwrap(),
        "--epochs",
        "3",
        "--hidden",
        "8",
        "--out",
        weights.to_str().unwrap(),
    ]));
    let log = std::fs::read_to_string(dir.path().join("bc-training.csv")).unwrap();
    assert!(
        log.starts_with("epoch,loss,train_accuracy,test_accuracy\n1,"),
        "{log}"
    );
    assert_eq!(log.lines().count(), 4);
    assert!(image::open(dir.path().join("bc-training.png")).is_ok());
    assert_eq!(
        ronap_core::policy::Mlp::load(&weights).unwrap().metadata["decision"],
        "sample:2"
    );
}

#[test]
fn a_network_trained_with_history_runs_with_it_and_is_refused_without() {
    let dir = tempfile::tempdir().unwrap();
    let scenario = dir.path().join("memory.toml");
    std::fs::write(&scenario, "[observation]\nhistory = 3\n").unwrap();
    let weights = dir.path().join("m.safetensors");
    ok(&ronap(&[
        "train",
        "dqn",
        "--scenario",
        scenario.to_str().unwrap(),
        "--steps",
        "600",
        "--envs",
        "4",
        "--batch",
        "16",
        "--hidden",
        "8",
        "--eval-every",
        "0",
        "--out",
        weights.to_str().unwrap(),
    ]));
    let mlp = ronap_core::policy::Mlp::load(&weights).unwrap();
    assert_eq!(mlp.inputs(), 3 * 18 + 2 * 3);
    assert!(
        mlp.metadata["observation"].contains("observation.history = 3"),
        "{}",
        mlp.metadata["observation"]
    );
    let policy = format!("mlp:{}", weights.display());
    let run_dir = dir.path().join("run");
    ok(&ronap(&[
        "run",
        "--scenario",
        scenario.to_str().unwrap(),
        "--policy",
        &policy,
        "--seeds",
        "3",
        "--max-steps",
        "50",
        "--out",
        run_dir.to_str().unwrap(),
    ]));
    crate::util::assert_rejected(
        &["run", "--policy", &policy, "--seeds", "3"],
        &["60 inputs", "18 values", "observation.history"],
    );
}

#[test]
fn trains_on_the_original_platforms_rows() {
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("original.csv");
    let mut rows = String::new();
    for i in 0..200 {
        let side = if i % 2 == 0 { 100 } else { 498 };
        let (direction, action) = match i % 4 {
            0 => ("10.0", "LEFT"),
            1 => ("350.0", "RIGHT"),
            2 => ("0.5", "AHEAD"),
            _ => ("0.0", "WARNING"),
        };
        rows.push_str(&format!(
            "\"[{side}, 498, 498, 498, 498, 498, 498, 498, 498, 498, 498, 498, 498, 498, 401, 357, 330]\",343.72,{direction},{action}\n"
        ));
    }
    std::fs::write(&data, rows).unwrap();
    let out = ok(&ronap(&[
        "train",
        "bc",
        "--data",
        data.to_str().unwrap(),
        "--epochs",
        "30",
        "--batch",
        "16",
        "--hidden",
        "16",
        "--activation",
        "relu",
        "--lr",
        "0.01",
        "--out",
        dir.path().join("o.safetensors").to_str().unwrap(),
    ]));
    assert!(
        out.contains("150 rows") && out.contains("50 skipped"),
        "{out}"
    );
    assert!(out.contains("original RoNAP format"), "{out}");
}

#[test]
fn bad_weights_and_data_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let junk = dir.path().join("junk.safetensors");
    std::fs::write(&junk, b"not weights").unwrap();
    let out = dir.path().join("r");
    let policy = format!("mlp:{}", junk.display());
    assert_rejected_leaving_nothing(
        &run_args(&policy, &["--seeds", "1"], &out),
        &["junk.safetensors", "not a safetensors file"],
        &out,
    );

    // A network for another observation size.
    let wide = dir.path().join("wide.safetensors");
    let layer = |o, i| ronap_core::policy::Layer {
        weight: nalgebra::DMatrix::zeros(o, i),
        bias: nalgebra::DVector::zeros(o),
    };
    let mlp = ronap_core::policy::Mlp::new(
        vec![layer(4, 25), layer(3, 4)],
        ronap_core::policy::Activation::Relu,
        Default::default(),
    )
    .unwrap();
    std::fs::write(&wide, mlp.to_bytes().unwrap()).unwrap();
    let policy = format!("mlp:{}", wide.display());
    let names = ["takes 25 inputs", "observation has 18"];
    assert_rejected(&["run", "--policy", &policy, "--seeds", "1"], &names);
    let policy = format!("{policy}@hottest");
    assert_rejected(
        &["run", "--policy", &policy],
        &["\"hottest\" is not a decision rule"],
    );

    let bad = dir.path().join("bad.csv");
    std::fs::write(
        &bad,
        "laser_0,heading,bearing,action\n1,2,3,AHEAD\n4,5,x,LEFT\n",
    )
    .unwrap();
    let out = dir.path().join("b.safetensors");
    assert_rejected_leaving_nothing(
        &[
            "train",
            "bc",
            "--data",
            bad.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ],
        &["bad.csv:3", "bearing = \"x\""],
        &out,
    );
}

#[test]
fn an_output_directory_is_refused_before_training() {
    let dir = tempfile::tempdir().unwrap();
    for out in [
        dir.path().to_str().unwrap().to_string(),
        format!("{}/missing/", dir.path().display()),
    ] {
        let o = ronap(&["train", "dqn", "--steps", "1000000", "--out", &out]);
        assert_eq!(o.status.code(), Some(2));
        let e = text(&o.stderr);
        assert!(e.contains("--out") && e.lines().count() == 1, "{e}");
    }
}

#[test]
fn weights_and_data_logs_there_already_are_kept_unless_forced() {
    let dir = tempfile::tempdir().unwrap();
    let kept = dir.path().join("kept");
    std::fs::write(&kept, "made by hand\n").unwrap();
    let k = kept.to_str().unwrap();
    // Refused before any training or recording (a million steps would take minutes), the file
    // as it was.
    for args in [
        &["train", "dqn", "--steps", "1000000", "--out", k][..],
        &[
            "collect",
            "--expert",
            "geodesic",
            "--samples",
            "100000",
            "--out",
            k,
        ],
    ] {
        let o = ronap(args);
        assert_eq!(o.status.code(), Some(2), "{args:?}");
        let e = text(&o.stderr);
        assert!(
            e.contains("--out") && e.contains("exists") && e.contains("--force"),
            "{e}"
        );
        assert_eq!(std::fs::read_to_string(&kept).unwrap(), "made by hand\n");
    }
    // A directory is never a log; a session at the keys never replaces one.
    let d = dir.path().to_str().unwrap();
    assert_rejected(
        &["collect", "--expert", "geodesic", "--out", d, "--force"],
        &["--out", "is a directory"],
    );
    assert_rejected(
        &["collect", "--human", "--out", k, "--force"],
        &["--force with --human", "another --out"],
    );
    let forced = ok(&ronap(&collect_args(
        "geodesic",
        &["--samples", "20", "--force"],
        &kept,
    )));
    assert!(forced.contains("20 rows from "), "{forced}");
    assert_eq!(std::fs::read_to_string(&kept).unwrap().lines().count(), 21);
}

/// The shipped policies reach, on the first 100 of their 1000 held-out evaluation seeds, the
/// success rate their evaluation reports, within 12 points: about three standard deviations of a
/// 100-episode estimate at the rates reported.
#[test]
fn shipped_policies_reach_their_reported_success() {
    for name in ["bc", "dqn"] {
        let root = repo_root().join("policies");
        let report: serde_json::Value = serde_json::from_str(
            &std::fs::read_to_string(root.join(format!("{name}.json"))).unwrap(),
        )
        .unwrap();
        let reported = report["evaluation"]["success_rate"].as_f64().unwrap();
        let policy = report["policy"]
            .as_str()
            .unwrap()
            .replace("policies/", &format!("{}/", root.display()));
        let dir = tempfile::tempdir().unwrap();
        ok(&ronap(&run_args(&policy, &["--seeds", "100"], dir.path())));
        let got = summary(dir.path())["success_rate"].as_f64().unwrap();
        assert!(
            (got - reported).abs() <= 0.12,
            "{name}: {got:.2} on seeds 0..99 vs {reported:.3} reported on 0..999"
        );
    }
}

/// A train fraction of 0 leaves nothing to train on: refused before any data is read. At 1 there
/// is no test split, and the test accuracy shows as `-`, not NaN.
#[test]
fn train_fractions_at_the_ends() {
    assert_rejected(
        &["train", "bc", "--data", "x.csv", "--train-fraction", "0"],
        &["--train-fraction", "0"],
    );
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("expert.csv");
    ok(&ronap(&collect_args(
        "geodesic",
        &["--samples", "200"],
        &data,
    )));
    let net = dir.path().join("net.safetensors");
    let out = ok(&ronap(&[
        "train",
        "bc",
        "--data",
        data.to_str().unwrap(),
        "--train-fraction",
        "1",
        "--epochs",
        "1",
        "--out",
        net.to_str().unwrap(),
    ]));
    assert!(out.contains("test accuracy -"), "{out}");
    assert!(!out.contains("NaN"), "{out}");
}
