"""The batch evaluator from Python (the CLI side of the same runs is in the top-level tests/)."""

import json
import pathlib
import signal
import threading
import time

import numpy as np
import pytest

import ronap
from helpers import toward_goal


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


class _Overlaps:
    """A policy that releases the GIL inside each call (as torch does) and counts the calls that
    overlap."""

    def __init__(self):
        self.inside = 0
        self.most = 0
        self.lock = threading.Lock()

    def __call__(self, obs):
        with self.lock:
            self.inside += 1
            self.most = max(self.most, self.inside)
        time.sleep(0.0005)
        with self.lock:
            self.inside -= 1
        return 1


def test_a_python_policy_is_never_called_concurrently_unless_thread_safe():
    policy = _Overlaps()
    one = ronap.evaluate(policy, range(8), threads=2, episode_max_steps=40)
    assert policy.most == 1
    # Declared thread-safe, two workers do call it at once; the episodes are the same.
    free = _Overlaps()
    two = ronap.evaluate(free, range(8), threads=2, episode_max_steps=40, thread_safe=True)
    assert free.most == 2
    strip = lambda res: [{k: v for k, v in r.items() if k != "wall_time_s"} for r in res["episodes"]]
    assert strip(one) == strip(two)


def test_evaluate_input_errors():
    with pytest.raises(ronap.ConfigError, match="teleport"):
        ronap.evaluate("teleport", range(2))
    with pytest.raises(ronap.ConfigError, match="empty"):
        ronap.evaluate("apf", [])
    with pytest.raises(ronap.MissingFileError, match="nowhere.png"):  # also a FileNotFoundError
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
    assert (tmp_path / "none" / "episodes.csv").exists()
    assert not (tmp_path / "none" / "png").exists()  # no pictures asked for: no folder for them
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


def _toward_goal_rows(obs):
    d = obs[:, -1].astype(np.float64) * 360.0
    return np.where((15 < d) & (d < 180), 0, np.where((180 <= d) & (d < 345), 2, 1))


def test_batched_python_policy_gives_the_same_files_with_fewer_calls(tmp_path):
    calls, rows = [], []

    def batched(obs):
        assert obs.dtype == np.float32 and obs.ndim == 2 and obs.shape[1] == 18
        calls.append(1)
        rows.append(obs.shape[0])
        return _toward_goal_rows(obs)

    one = ronap.evaluate(toward_goal, range(24), threads=1, episode_max_steps=300, out=str(tmp_path / "one"))
    many = ronap.evaluate(batched, range(24), batch=8, episode_max_steps=300, out=str(tmp_path / "many"))
    assert (tmp_path / "one" / "episodes.csv").read_bytes() == (tmp_path / "many" / "episodes.csv").read_bytes()
    steps = sum(r["steps"] for r in one["episodes"])
    assert len(calls) < steps / 3, (len(calls), steps)
    assert max(rows) == 8
    assert many["summary"]["episodes"] == 24


def test_batched_continuous_policy_matches_unbatched():
    one = ronap.evaluate(lambda obs: (1.0, 0.3), range(6), threads=1, continuous=True, episode_max_steps=40)
    many = ronap.evaluate(lambda obs: np.tile([1.0, 0.3], (len(obs), 1)), range(6), batch=4, continuous=True, episode_max_steps=40)
    strip = lambda res: [{k: v for k, v in r.items() if k != "wall_time_s"} for r in res["episodes"]]
    assert strip(one) == strip(many)


@pytest.mark.parametrize(
    "policy, message",
    [
        (lambda obs: np.ones(len(obs) + 1, int), r"seed \d+, step 1: .*shape"),
        (lambda obs: np.full(len(obs), 5), r"action 5 for row"),
        (lambda obs: np.full(len(obs), 0.5), r"0.5"),
        (lambda obs: None, r"returned None"),
        (lambda obs: (_ for _ in ()).throw(ValueError("no idea")), r"raised ValueError\('no idea'\)"),
    ],
)
def test_bad_batched_policies_raise_policy_error(policy, message):
    with pytest.raises(ronap.PolicyError, match=message):
        ronap.evaluate(policy, range(4), batch=2)


def test_batch_is_for_callables_and_counted():
    with pytest.raises(ronap.ConfigError, match="batch = 4"):
        ronap.evaluate("apf", range(4), batch=4)
    with pytest.raises(ronap.ConfigError, match="batch = -1"):
        ronap.evaluate(toward_goal, range(4), batch=-1)


def _files(directory):
    root = pathlib.Path(directory)
    return {p.relative_to(root): p.read_bytes() for p in sorted(root.rglob("*")) if p.is_file()}


def test_out_holding_a_run_or_other_files_needs_force(tmp_path):
    out = tmp_path / "run"
    ronap.evaluate("apf", range(3), out=str(out))
    assert sorted(p.name for p in out.iterdir()) == ["episodes.csv", "run.json", "summary.json", "timing.csv"]
    before = _files(out)
    with pytest.raises(ronap.OutputError, match="holds a finished run.*force=True"):
        ronap.evaluate("geodesic", range(3), out=str(out))
    assert _files(out) == before
    ronap.evaluate("geodesic", range(2), out=str(out), force=True)
    assert json.loads((out / "summary.json").read_text())["policy"] == "geodesic"

    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "notes.txt").write_text("keep me")
    with pytest.raises(ronap.OutputError, match="notes.txt.*force=True"):
        ronap.evaluate("apf", range(2), out=str(mine))
    ronap.evaluate("apf", range(2), out=str(mine), force=True)
    assert (mine / "notes.txt").read_text() == "keep me"


def test_a_forced_run_failing_at_once_leaves_the_old_run(tmp_path):
    out = tmp_path / "run"
    ronap.evaluate("apf", range(3), out=str(out))
    before = _files(out)

    def broken(obs):
        raise ValueError("broken")

    with pytest.raises(ronap.PolicyError, match="broken"):
        ronap.evaluate(broken, range(3), out=str(out), force=True, threads=1)
    assert _files(out) == before


def test_ctrl_c_stops_the_run_keeping_its_files_then_raises(tmp_path):
    import _thread

    # The Ctrl-C comes a second after the run's first decision (a fixed second after the call
    # could come before the run starts, on a loaded machine, with nothing yet to keep).
    timer = threading.Timer(1.0, _thread.interrupt_main)

    def slow(obs):
        if not timer.is_alive() and not timer.finished.is_set():
            timer.start()
        time.sleep(0.002)
        return 1

    out = tmp_path / "run"
    # A shell that starts the tests in the background leaves SIGINT ignored, and Python then
    # never installs its handler: interrupt_main would do nothing and the run go on for ever.
    handler = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        with pytest.raises(KeyboardInterrupt):
            ronap.evaluate(slow, range(1_000_000), out=str(out), threads=1)
    finally:
        timer.cancel()
        signal.signal(signal.SIGINT, handler)
    summary = json.loads((out / "summary.json").read_text())
    assert summary["interrupted"] is True
    rows = (out / "episodes.csv").read_text().splitlines()
    assert summary["summary"]["episodes"] == len(rows) - 1 > 0
    assert not list(out.glob("*.partial")) and not (out / ".ronap.lock").exists()


ROOT = pathlib.Path(__file__).resolve().parents[3]


def test_crowd_crossing_with_orca_reports_the_crowd_metrics():
    scenario = str(ROOT / "scenarios" / "circle-crossing-visible.toml")
    orca = ronap.evaluate("orca", range(30), scenario=scenario)
    geodesic = ronap.evaluate("geodesic", range(30), scenario=scenario)
    means = {m["name"]: m for m in orca["summary"]["metrics"]}
    assert set(means) == {
        "time_to_goal",
        "intrusion_ratio",
        "min_separation_px",
        "ttc_min",
        "path_irregularity",
        "jerk",
    }
    # Every episode's metrics are in its row, and the summary's mean is their mean.
    ratios = [r["intrusion_ratio"] for r in orca["episodes"]]
    assert len(ratios) == 30 and all(0.0 <= x <= 1.0 for x in ratios)
    assert means["intrusion_ratio"]["mean"] == pytest.approx(sum(ratios) / 30)
    times = [r["time_to_goal"] for r in orca["episodes"] if r["outcome"] == "success"]
    assert means["time_to_goal"]["episodes"] == len(times) > 0
    # ORCA keeps further from the pedestrians than driving straight through them.
    g = {m["name"]: m for m in geodesic["summary"]["metrics"]}
    assert means["intrusion_ratio"]["mean"] < g["intrusion_ratio"]["mean"]
    assert orca["summary"]["success_rate"] >= 0.9
    # Without [metrics] a run has none.
    assert "metrics" not in ronap.evaluate("geodesic", range(2))["summary"]


CROWD_SCENARIOS = [
    "circle-crossing",
    "circle-crossing-visible",
    "square-crossing",
    "crowd-hall",
]


@pytest.mark.parametrize("name", CROWD_SCENARIOS)
@pytest.mark.parametrize("policy", ["orca", "social-force", "dwa"])
def test_every_crowd_scenario_runs_with_every_local_planner(name, policy):
    scenario = str(ROOT / "scenarios" / f"{name}.toml")
    result = ronap.evaluate(policy, range(3), scenario=scenario)
    assert result["summary"]["episodes"] == 3
    assert len(result["episodes"]) == 3
    # The crowd scenarios measure the crowd metrics, each a number in range.
    for row in result["episodes"]:
        assert 0.0 <= row["intrusion_ratio"] <= 1.0
    # The same seeds give the same episodes.
    again = ronap.evaluate(policy, range(3), scenario=scenario)
    assert [r["outcome"] for r in again["episodes"]] == [
        r["outcome"] for r in result["episodes"]
    ]


@pytest.mark.parametrize(
    ("table", "body", "field"),
    [
        (
            "moving",
            'motion = "social_force"\nsocial_force = { lambda = 2.0 }\n',
            "moving[0].social_force.lambda",
        ),
        ("moving", 'motion = "orca"\nspeed_px = -1.0\n', "moving[0].speed_px"),
        ("moving", 'motion = "orca"\npattern = "circle"\n', "moving[0].pattern"),
        ("crowd", 'count = 3\nspeed_px = -1.0\n', "crowd[0].speed_px"),
        ("crowd", 'count = 3\npattern = "circle"\n', "crowd[0].pattern"),
    ],
)
def test_a_bad_crowd_entry_is_one_error_naming_file_line_and_field(
    tmp_path, table, body, field
):
    bad = tmp_path / "bad.toml"
    bad.write_text(f"[maze]\ncols = 2\nrows = 2\n[[{table}]]\n{body}")
    with pytest.raises(Exception) as caught:
        ronap.evaluate("orca", range(1), scenario=str(bad))
    message = str(caught.value)
    assert "bad.toml:6" in message and field in message, message
