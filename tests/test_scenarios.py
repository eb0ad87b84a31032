"""The shipped scenarios and scenario files from the command line: each one runs, draws and
replays; a bad file is one clear error naming file, line, key and value, with exit 2."""

import csv
import json
import subprocess

import pytest

SCENARIOS = ["paper-maze", "maze-pedestrians", "maze-appearing", "warehouse-forklifts", "hall-crowd", "map-mover"]


def run(ronap_bin, *args):
    return subprocess.run([ronap_bin, *map(str, args)], capture_output=True, text=True)


@pytest.mark.parametrize("name", SCENARIOS)
def test_a_shipped_scenario_runs_draws_and_replays(tmp_path, ronap_bin, root, name):
    scenario = root / "scenarios" / f"{name}.toml"
    out = tmp_path / "run"
    r = run(ronap_bin, "run", "--scenario", scenario, "--policy", "geodesic-wait", "--seeds", 4,
            "--max-steps", 300, "--png", "all", "--log-steps", "--out", out)
    assert r.returncode == 0, r.stderr
    rows = list(csv.DictReader((out / "episodes.csv").open()))
    assert len(rows) == 4
    summary = json.loads((out / "summary.json").read_text())
    moving = name != "paper-maze"
    # Moving-obstacle metrics appear exactly when the scenario has moving obstacles.
    assert ("dynamic_collisions" in rows[0]) == moving
    assert ("moving" in summary["summary"]) == moving
    assert ("moving-obstacle collisions" in r.stdout) == moving
    assert len(list((out / "png").glob("*.png"))) == 4
    # The run replays from its step log alone (scenario included).
    gif = tmp_path / "replay.gif"
    r = run(ronap_bin, "replay", out / "steps" / "seed-000001.csv", "--out", gif)
    assert r.returncode == 0, r.stderr
    assert gif.read_bytes()[:6] == b"GIF89a"
    # The same scenario, the same bits, on any thread count.
    again = tmp_path / "again"
    r = run(ronap_bin, "run", "--scenario", scenario, "--policy", "geodesic-wait", "--seeds", 4,
            "--max-steps", 300, "--threads", 1, "--out", again)
    assert r.returncode == 0, r.stderr
    assert (again / "episodes.csv").read_bytes() == (out / "episodes.csv").read_bytes()
    picture = tmp_path / "scene.png"
    r = run(ronap_bin, "maze", "--scenario", scenario, "--start-goal", "--out", picture)
    assert r.returncode == 0, r.stderr
    assert picture.read_bytes()[:4] == b"\x89PNG"


def test_the_example_scenario_is_complete_and_runs(tmp_path, ronap_bin):
    r = run(ronap_bin, "config", "--scenario")
    assert r.returncode == 0, r.stderr
    for key in ("[scene]", "[warehouse]", "[[obstacles]]", "[[moving]]", 'motion = "appear"', 'shape = "polygon"'):
        assert key in r.stdout, key
    example = tmp_path / "example.toml"
    example.write_text(r.stdout)
    r = run(ronap_bin, "run", "--scenario", example, "--policy", "apf", "--seeds", 3, "--out", tmp_path / "x")
    assert r.returncode == 0, r.stderr


def test_flags_override_the_scenario(tmp_path, ronap_bin, root):
    out = tmp_path / "run"
    r = run(ronap_bin, "run", "--scenario", root / "scenarios" / "hall-crowd.toml", "--policy", "random",
            "--seeds", 2, "--max-steps", 17, "--out", out)
    assert r.returncode == 0, r.stderr
    config = json.loads((out / "summary.json").read_text())["config"]
    assert config["episode"]["max_steps"] == 17
    assert config["maze"]["cols"] == 1 and len(config["moving"]) == 1
    assert all(row["steps"] == "17" or row["outcome"] != "timeout" for row in csv.DictReader((out / "episodes.csv").open()))


@pytest.mark.parametrize(
    "text, expected",
    [
        ("[scene]\nkind = \"maze\"\n\n[[moving]]\nspeed = 2.0\n", [":5:", "speed", "unknown field"]),
        ("[[moving]]\ncount = \"many\"\n", [":2:", "count", "many"]),
        ("[[moving]]\ncount = 2\n\n[[moving]]\nspeed_px = -1.5\n", [":5:", "moving[1].speed_px = -1.5"]),
        ("[scene]\nkind = \"hangar\"\n", [":2:", "kind", "hangar"]),
        ("[[obstacles]]\nshape = \"polygon\"\npoints = [[0.0, 0.0], [1.0, 1.0]]\n", [":3:", "obstacles[0].points"]),
        ("[scene]\nkind = \"map\"\n", ["scene.file", "needs"]),
    ],
)
def test_a_bad_scenario_is_one_clear_error(tmp_path, ronap_bin, text, expected):
    bad = tmp_path / "bad.toml"
    bad.write_text(text)
    out = tmp_path / "out"
    r = run(ronap_bin, "run", "--scenario", bad, "--policy", "apf", "--seeds", 2, "--out", out)
    assert r.returncode == 2, r.stderr
    message = r.stderr.strip()
    assert message.startswith("error:") and len(message.splitlines()) == 1, message
    for part in expected:
        assert part in message, (part, message)
    if "scene.file" not in message:
        assert "bad.toml" in message
    assert "panicked" not in r.stderr
    assert not out.exists()
