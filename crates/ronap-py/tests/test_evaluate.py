"""The batch evaluator from Python, and Python policies from the CLI."""

import json
import pathlib
import subprocess

import numpy as np
import pytest

import ronap

POLICY_FILE = '''
def act(obs):
    d = float(obs[-1]) * 360.0
    if 15 < d < 180:
        return 0
    if 180 <= d < 345:
        return 2
    return 1

def boom(obs):
    raise ValueError("no idea")
'''


def toward_goal(obs):
    d = float(obs[-1]) * 360.0
    if 15 < d < 180:
        return 0
    if 180 <= d < 345:
        return 2
    return 1


def test_builtin_policies_report_like_ronap_run():
    result = ronap.evaluate("geodesic", range(8))
    s = result["summary"]
    assert s["episodes"] == 8 and s["successes"] == 8 and s["success_rate"] == 1.0
    assert 0.9 < s["spl"] <= 1.0
    rows = result["episodes"]
    assert [r["seed"] for r in rows] == list(range(8))
    assert all(r["outcome"] == "success" and r["shortest_px"] <= r["path_length_px"] * 1.01 for r in rows)
    apf = ronap.evaluate("apf", range(20))
    assert any(r["outcome"] == "stuck" for r in apf["episodes"])


def test_python_policy_runs_and_is_deterministic():
    a = ronap.evaluate(toward_goal, range(12), threads=2)
    b = ronap.evaluate(toward_goal, range(12), threads=1)
    strip = lambda res: [{k: v for k, v in r.items() if k != "wall_time_s"} for r in res["episodes"]]
    assert strip(a) == strip(b)
    assert a["summary"]["episodes"] == 12


@pytest.mark.parametrize(
    "policy, message",
    [
        (lambda obs: (_ for _ in ()).throw(ValueError("no idea")), r"seed 3, step 1: .*raised ValueError\('no idea'\)"),
        (lambda obs: 7, r"seed 3, step 1: .*returned 7"),
        (lambda obs: float("nan"), r"seed 3, step 1: .*returned NaN"),
        (lambda obs: "left", r"seed 3, step 1: .*returned left"),
    ],
)
def test_bad_python_policies_raise_policy_error_naming_seed_and_step(policy, message):
    with pytest.raises(ronap.PolicyError, match=message):
        ronap.evaluate(policy, [3], threads=1)


def test_cli_and_python_agree_bit_for_bit(tmp_path, ronap_bin):
    policy = tmp_path / "policy.py"
    policy.write_text(POLICY_FILE)
    cli_out, py_out = tmp_path / "cli", tmp_path / "py"
    subprocess.run(
        [ronap_bin, "run", "--policy", f"py:{policy}:act", "--seeds", "6", "--out", str(cli_out), "--log-steps"],
        check=True,
        capture_output=True,
    )
    ronap.evaluate(toward_goal, range(6), out=str(py_out), log_steps=True)
    assert (cli_out / "episodes.csv").read_bytes() == (py_out / "episodes.csv").read_bytes()
    for seed in range(6):
        name = f"steps/seed-{seed:06}.csv"
        assert (cli_out / name).read_bytes() == (py_out / name).read_bytes(), name
    summary = json.loads((py_out / "summary.json").read_text())
    assert summary["summary"]["episodes"] == 6 and summary["policy"] == "toward_goal"


def test_builtin_files_match_the_cli(tmp_path, ronap_bin):
    subprocess.run([ronap_bin, "run", "--policy", "apf", "--seeds", "10", "--out", str(tmp_path / "cli")], check=True, capture_output=True)
    ronap.evaluate("apf", range(10), out=str(tmp_path / "py"), png="failures")
    assert (tmp_path / "cli" / "episodes.csv").read_bytes() == (tmp_path / "py" / "episodes.csv").read_bytes()
    assert any((tmp_path / "py" / "png").iterdir())


def test_cli_reports_a_failing_python_policy(tmp_path, ronap_bin):
    policy = tmp_path / "policy.py"
    policy.write_text(POLICY_FILE)
    r = subprocess.run(
        [ronap_bin, "run", "--policy", f"py:{policy}:boom", "--seeds", "3", "--out", str(tmp_path / "o")],
        capture_output=True,
        text=True,
    )
    assert r.returncode == 2
    assert "seed 0, step 1" in r.stderr and "ValueError('no idea')" in r.stderr
    r = subprocess.run(
        [ronap_bin, "run", "--policy", f"py:{policy}:missing", "--seeds", "3", "--out", str(tmp_path / "m")],
        capture_output=True,
        text=True,
    )
    assert r.returncode == 2 and "missing" in r.stderr
    assert not (tmp_path / "m").exists()


def test_evaluate_input_errors():
    with pytest.raises(ronap.ConfigError, match="teleport"):
        ronap.evaluate("teleport", range(2))
    with pytest.raises(ronap.ConfigError, match="empty"):
        ronap.evaluate("apf", [])
    with pytest.raises(ronap.SceneError, match="nowhere.png"):
        ronap.evaluate("apf", range(2), map="nowhere.png")


def test_continuous_python_policy_uses_normalised_actions():
    straight = ronap.evaluate(lambda obs: (1.0, 0.0), [1], threads=1, continuous=True, episode_max_steps=10)
    # Full speed ahead for 10 steps: 50 px, unless a wall stops it.
    row = straight["episodes"][0]
    assert row["path_length_px"] <= 50.0 + 1e-9
    assert row["path_length_px"] == pytest.approx(50.0) or row["collisions"] > 0


def test_png_choice_matches_the_cli(tmp_path):
    # png=0 means no pictures (it once meant "failures"); "failures" draws only failures.
    ronap.evaluate("apf", range(10), out=str(tmp_path / "none"), png=0)
    assert list((tmp_path / "none" / "png").iterdir()) == []
    result = ronap.evaluate("apf", range(10), out=str(tmp_path / "fail"), png="failures")
    failed = {r["seed"] for r in result["episodes"] if r["outcome"] != "success"}
    drawn = {int(p.name.split("-")[1]) for p in (tmp_path / "fail" / "png").iterdir()}
    assert drawn == failed and failed
    with pytest.raises(ronap.ConfigError, match="png"):
        ronap.evaluate("apf", range(2), out=str(tmp_path / "bad"), png="some")


def test_evaluate_runs_a_shipped_network():
    root = pathlib.Path(__file__).resolve().parents[3]
    weights = root / "policies" / "bc.safetensors"
    result = ronap.evaluate(f"mlp:{weights}", range(20))
    assert result["summary"]["episodes"] == 20
    assert result["summary"]["success_rate"] > 0.5
    with pytest.raises(ronap.ConfigError, match="not a decision rule"):
        ronap.evaluate(f"mlp:{weights}@hottest", range(2))
