"""The CLI and the Python module, end to end: the same run gives the same files from either, a run
written by either replays with `ronap replay`, and a failing Python policy is named by the CLI."""

import json
import subprocess

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


def _summary(path):
    return json.loads((path / "summary.json").read_text())


def test_cli_and_python_write_the_same_run(tmp_path, ronap_bin):
    cli, py = tmp_path / "cli", tmp_path / "py"
    subprocess.run(
        [ronap_bin, "run", "--policy", "apf", "--seeds", "12", "--out", str(cli), "--log-steps", "--png", "3", "--maze-seed", "4"],
        check=True,
        capture_output=True,
    )
    ronap.evaluate("apf", range(12), out=str(py), log_steps=True, png=3, maze_seed=4)
    assert (cli / "episodes.csv").read_bytes() == (py / "episodes.csv").read_bytes()
    for seed in range(12):
        name = f"steps/seed-{seed:06}.csv"
        assert (cli / name).read_bytes() == (py / name).read_bytes(), name
    assert sorted(p.name for p in (cli / "png").iterdir()) == sorted(p.name for p in (py / "png").iterdir())
    a, b = _summary(cli), _summary(py)
    # One schema, whoever wrote it.
    assert a.keys() == b.keys()
    assert a["schema_version"] == b["schema_version"] == 1
    assert a["scenes"] == b["scenes"] == {"kind": "maze", "seed": 4}
    assert a["config"] == b["config"]
    for key in ("seed_start", "seeds_requested", "interrupted", "error", "policy"):
        assert a[key] == b[key], key
    timing = {"wall_time_s", "steps_per_second"}
    assert {k: v for k, v in a["summary"].items() if k not in timing} == {k: v for k, v in b["summary"].items() if k not in timing}


def test_runs_from_either_front_end_replay(tmp_path, ronap_bin):
    py = tmp_path / "py"
    ronap.evaluate(toward_goal, range(3), out=str(py), log_steps=True)
    cli = tmp_path / "cli"
    subprocess.run([ronap_bin, "run", "--policy", "random", "--seeds", "3", "--max-steps", "40", "--out", str(cli), "--log-steps"], check=True, capture_output=True)
    for run in (py, cli):
        log = run / "steps" / "seed-000002.csv"
        gif = tmp_path / f"{run.name}.gif"
        r = subprocess.run([ronap_bin, "replay", str(log), "--out", str(gif)], capture_output=True, text=True)
        assert r.returncode == 0, r.stderr
        assert gif.read_bytes()[:6] == b"GIF89a"
        steps = len((log).read_text().splitlines()) - 1
        assert f"seed 2, {steps} steps" in r.stdout, r.stdout


def test_a_log_that_does_not_match_its_run_is_refused(tmp_path, ronap_bin):
    run = tmp_path / "run"
    ronap.evaluate("apf", [5], out=str(run), log_steps=True)
    log = run / "steps" / "seed-000005.csv"
    lines = log.read_text().splitlines()
    # Another configuration in the manifest: the logged poses no longer follow.
    summary = _summary(run)
    summary["config"]["robot"]["move_speed_px"] = 4.0
    (run / "summary.json").write_text(json.dumps(summary))
    r = subprocess.run([ronap_bin, "replay", str(log), "--out", str(tmp_path / "x.gif")], capture_output=True, text=True)
    assert r.returncode == 2 and "step" in r.stderr, r.stderr
    assert not (tmp_path / "x.gif").exists()
    assert len(lines) > 2


ODD_RETURNS = '''
import numpy as np

def np_int(obs):
    return np.int64(1)

def whole_float(obs):
    return np.float64(1.0)

def a_bool(obs):
    return True

def nothing(obs):
    return None

def an_array(obs):
    return np.array([1, 2])

def a_fraction(obs):
    return 1.5
'''


def test_cli_python_policies_returning_odd_values(tmp_path, ronap_bin):
    """numpy integers and whole floats are actions (as in ronap.evaluate); bools, None, arrays and
    fractions are refused naming seed, step and the value, exit 2, never a crash of the worker."""
    policy = tmp_path / "odd.py"
    policy.write_text(ODD_RETURNS)
    run = lambda fn, out: subprocess.run(
        [ronap_bin, "run", "--policy", f"py:{policy}:{fn}", "--seeds", "2", "--max-steps", "20",
         "--out", str(tmp_path / out)], capture_output=True, text=True)
    ahead = subprocess.run(
        [ronap_bin, "run", "--policy", "py:" + str(tmp_path / "odd.py") + ":np_int", "--seeds", "2",
         "--max-steps", "20", "--out", str(tmp_path / "int")], capture_output=True, text=True)
    assert ahead.returncode == 0, ahead.stderr
    floats = run("whole_float", "float")
    assert floats.returncode == 0, floats.stderr
    assert (tmp_path / "int" / "episodes.csv").read_bytes() == (tmp_path / "float" / "episodes.csv").read_bytes()
    for fn, shown in [("a_bool", "True"), ("nothing", "None"), ("an_array", "array([1, 2])"), ("a_fraction", "1.5")]:
        r = run(fn, fn)
        assert r.returncode == 2, (fn, r.returncode, r.stderr)
        assert "seed 0, step 1" in r.stderr and f"returned {shown}" in r.stderr, (fn, r.stderr)
        assert "Traceback" not in r.stderr and "panicked" not in r.stderr, r.stderr


BATCHED = '''
import numpy as np

def rows(obs):
    d = obs[:, -1].astype(np.float64) * 360.0
    return np.where((15 < d) & (d < 180), 0, np.where((180 <= d) & (d < 345), 2, 1))

def too_few(obs):
    return np.ones(len(obs) - 1 if len(obs) > 1 else 2, int)
'''


def test_cli_batch_gives_the_same_bytes_as_unbatched(tmp_path, ronap_bin):
    policy = tmp_path / "policy.py"
    policy.write_text(POLICY_FILE + BATCHED)
    base = [ronap_bin, "run", "--seeds", "12", "--max-steps", "300"]
    one = subprocess.run(base + ["--policy", f"py:{policy}:act", "--out", str(tmp_path / "one")], capture_output=True, text=True)
    many = subprocess.run(base + ["--policy", f"py:{policy}:rows", "--batch", "6", "--out", str(tmp_path / "many")], capture_output=True, text=True)
    assert one.returncode == 0 and many.returncode == 0, one.stderr + many.stderr
    assert (tmp_path / "one" / "episodes.csv").read_bytes() == (tmp_path / "many" / "episodes.csv").read_bytes()
    assert "batches of up to 6 episodes" in many.stdout
    bad = subprocess.run(base + ["--policy", f"py:{policy}:too_few", "--batch", "4", "--out", str(tmp_path / "bad")], capture_output=True, text=True)
    assert bad.returncode == 2 and "expected" in bad.stderr and "actions" in bad.stderr, bad.stderr
    refused = subprocess.run(base + ["--policy", "apf", "--batch", "4", "--out", str(tmp_path / "apf")], capture_output=True, text=True)
    assert refused.returncode == 2 and "--batch 4" in refused.stderr, refused.stderr


def test_cli_team_batch_decides_a_teams_robots_in_one_call_with_the_same_episodes(tmp_path, ronap_bin, root):
    policy = tmp_path / "policy.py"
    policy.write_text(POLICY_FILE + BATCHED)
    base = [ronap_bin, "run", "--scenario", str(root / "scenarios" / "warehouse-team.toml"), "--seeds", "3", "--max-steps", "150"]
    one = subprocess.run(base + ["--policy", f"py:{policy}:act", "--out", str(tmp_path / "one")], capture_output=True, text=True)
    many = subprocess.run(base + ["--policy", f"py:{policy}:rows", "--batch", "2", "--out", str(tmp_path / "many")], capture_output=True, text=True)
    assert one.returncode == 0 and many.returncode == 0, one.stderr + many.stderr
    assert "one call a step for the robots of each" in many.stdout
    # The same episodes robot for robot; only the policy's name differs.
    strip = lambda p: [",".join(r.split(",")[:2] + r.split(",")[3:]) for r in p.read_text().splitlines()]
    assert strip(tmp_path / "one" / "robots.csv") == strip(tmp_path / "many" / "robots.csv")
    assert (tmp_path / "one" / "episodes.csv").read_bytes() == (tmp_path / "many" / "episodes.csv").read_bytes()
    bad = subprocess.run(base + ["--policy", f"py:{policy}:too_few", "--batch", "2", "--out", str(tmp_path / "bad")], capture_output=True, text=True)
    assert bad.returncode == 2 and "actions" in bad.stderr, bad.stderr
