"""Scenarios from Python: a TOML scenario file or a dict of the same structure as the base of
NavEnv, VecNavEnv and evaluate, overridden by keyword arguments as flags override it in the CLI;
errors naming file and line; runs that the CLI replays and reproduces."""

import json
import pathlib
import subprocess

import warnings

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import ronap
from helpers import assert_vec_env_is_single_envs

SCENARIO = """\
# A warehouse with ten people walking about.
[scene]
kind = "warehouse"

[episode]
max_steps = 60

[[moving]]
count = 10
shape = "disc"
radius_px = 6.0
motion = "random_walk"
speed_px = 2.0
"""

# The same scenario as a dict.
SCENARIO_DICT = {
    "scene": {"kind": "warehouse"},
    "episode": {"max_steps": 60},
    "moving": [{"count": 10, "shape": "disc", "radius_px": 6.0, "motion": "random_walk", "speed_px": 2.0}],
}

SEEDS = range(4)


@pytest.fixture
def scenario(tmp_path) -> pathlib.Path:
    path = tmp_path / "walkers.toml"
    path.write_text(SCENARIO)
    return path


def strip(result):
    """The rows of an evaluation without their wall times."""
    return [{k: v for k, v in r.items() if k != "wall_time_s"} for r in result["episodes"]]


def play(env, seed, steps=30):
    """Observations, rewards and infos of `steps` steps of a fixed action pattern."""
    obs, info = env.reset(seed=seed)
    trace = [(obs.copy(), 0.0, info)]
    for k in range(steps):
        obs, reward, terminated, truncated, info = env.step((1, 1, 0, 1, 2)[k % 5])
        trace.append((obs.copy(), reward, info))
        if terminated or truncated:
            break
    return trace


def same(a, b):
    return len(a) == len(b) and all(np.array_equal(x[0], y[0]) and x[1] == y[1] and x[2] == y[2] for x, y in zip(a, b))


def test_nav_env_runs_a_scenario_file_deterministically(scenario):
    env = ronap.NavEnv(scenario=scenario)
    assert env.config["scene"]["kind"] == "warehouse"
    assert env.config["moving"][0]["count"] == 10 and env.config["episode"]["max_steps"] == 60
    assert env.observation_space.shape == (18,)
    a = play(env, seed=7)
    b = play(env, seed=7)
    assert same(a, b)
    assert not np.array_equal(play(env, seed=8)[0][0], a[0][0])
    # Moving obstacles: the info counts contacts with them; without any, the key is absent.
    assert all(isinstance(info["dynamic_collisions"], int) for _, _, info in a)
    assert "dynamic_collisions" not in ronap.NavEnv().reset(seed=7)[1]
    # A string path works as a pathlib one does, and so does gymnasium.make.
    assert same(play(ronap.NavEnv(scenario=str(scenario)), seed=7), a)
    made = gym.make("ronap/Nav-v0", scenario=scenario)
    assert made.unwrapped.config == env.config
    assert same(play(made.unwrapped, seed=7), a)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        check_env(made.unwrapped)
    assert [str(w.message) for w in caught] == []


def test_the_moving_obstacles_are_in_the_scene(scenario):
    # The same warehouse with the walkers standing: the laser readings part as soon as they move.
    still = ronap.NavEnv(scenario=scenario, config={"moving": [dict(SCENARIO_DICT["moving"][0], speed_px=0.0)]})
    differs = False
    for seed in range(6):
        walking, standing = play(ronap.NavEnv(scenario=scenario), seed), play(still, seed)
        assert np.array_equal(walking[0][0], standing[0][0])
        differs |= any(not np.array_equal(w[0], s[0]) for w, s in zip(walking, standing))
    assert differs


def test_vec_env_equals_single_envs_under_a_scenario(scenario):
    n = 3
    vec = ronap.VecNavEnv(n, scenario=scenario, threads=2)
    assert vec.config["moving"][0]["count"] == 10
    singles = [ronap.NavEnv(scenario=scenario) for _ in range(n)]
    assert_vec_env_is_single_envs(vec, singles, 20, 40, stop_at_an_end=True)


def test_evaluate_reports_the_moving_obstacle_metrics(scenario):
    result = ronap.evaluate("apf", SEEDS, scenario=scenario, threads=2)
    rows = result["episodes"]
    assert [r["seed"] for r in rows] == list(SEEDS)
    for r in rows:
        assert isinstance(r["dynamic_collisions"], int) and r["dynamic_collisions"] >= 0
        assert r["min_clearance_px"] is None or r["min_clearance_px"] >= 0.0
        assert 0.0 <= r["near_moving_fraction"] <= 1.0
    moving = result["summary"]["moving"]
    assert set(moving) == {"dynamic_collisions_per_episode", "episodes_with_dynamic_collision", "mean_min_clearance_px", "near_moving_fraction"}
    assert moving["dynamic_collisions_per_episode"] == pytest.approx(np.mean([r["dynamic_collisions"] for r in rows]))
    assert moving["episodes_with_dynamic_collision"] == sum(r["dynamic_collisions"] > 0 for r in rows)
    # Without moving obstacles, neither the columns nor the summary entry.
    plain = ronap.evaluate("apf", [0], episode_max_steps=20)
    assert "moving" not in plain["summary"] and "dynamic_collisions" not in plain["episodes"][0]


def test_a_dict_scenario_equals_the_file(scenario):
    assert ronap.make_config(scenario=SCENARIO_DICT) == ronap.make_config(scenario=scenario)
    from_file = ronap.evaluate("apf", SEEDS, scenario=scenario)
    from_dict = ronap.evaluate("apf", SEEDS, scenario=SCENARIO_DICT)
    assert strip(from_file) == strip(from_dict)
    assert same(play(ronap.NavEnv(scenario=SCENARIO_DICT), seed=3), play(ronap.NavEnv(scenario=scenario), seed=3))


def test_keyword_arguments_override_the_scenario(scenario):
    c = ronap.make_config(scenario=scenario, laser_beams=9, config={"episode": {"max_steps": 25}, "robot.radius_px": 4.0})
    assert (c["laser"]["beams"], c["episode"]["max_steps"], c["robot"]["radius_px"]) == (9, 25, 4.0)
    assert c["moving"][0]["count"] == 10 and c["scene"]["kind"] == "warehouse"
    # Keyword arguments win over config, config over the scenario.
    assert ronap.make_config(scenario=scenario, config={"laser": {"beams": 5}}, laser_beams=7)["laser"]["beams"] == 7
    # A list replaces the scenario's list.
    assert ronap.make_config(scenario=scenario, config={"moving": []})["moving"] == []
    env = ronap.NavEnv(scenario=scenario, laser_beams=9)
    assert env.observation_space.shape == (10,) and env.reset(seed=1)[0].shape == (10,)
    result = ronap.evaluate("apf", [0, 1], scenario=scenario, episode_max_steps=5)
    assert all(r["steps"] <= 5 for r in result["episodes"])
    # Without moving obstacles: the warehouse alone.
    bare = ronap.evaluate("apf", [0], scenario=scenario, config={"moving": []})
    assert "moving" not in bare["summary"]
    # maze_seed picks one warehouse for every episode: the same racks whatever the seed.
    one = ronap.evaluate("apf", [0, 1], scenario=scenario, maze_seed=3)
    other = ronap.evaluate("apf", [0, 1], scenario=scenario, config={"scene": {"seed": 3}})
    assert strip(one) == strip(other)
    assert strip(one) != strip(ronap.evaluate("apf", [0, 1], scenario=scenario))


def write_pgm(path: pathlib.Path, side: int = 400) -> None:
    """A square room: white floor inside a black border, as a binary PGM."""
    img = np.full((side, side), 255, np.uint8)
    img[:4], img[-4:], img[:, :4], img[:, -4:] = 0, 0, 0, 0
    path.write_bytes(f"P5 {side} {side} 255\n".encode() + img.tobytes())


def test_a_map_scene_file_is_relative_to_the_scenario_or_to_the_current_directory(tmp_path, monkeypatch):
    rooms = tmp_path / "rooms"
    rooms.mkdir()
    write_pgm(rooms / "room.pgm")
    (rooms / "room.toml").write_text('[scene]\nkind = "map"\nfile = "room.pgm"\n\n[episode]\nmax_steps = 20\n\n[[moving]]\ncount = 2\n')
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)
    env = ronap.NavEnv(scenario=rooms / "room.toml")
    assert pathlib.Path(env.config["scene"]["file"]) == rooms / "room.pgm"
    obs, info = env.reset(seed=0)
    assert all(0 < c < 400 for c in info["pose"][:2])
    # In a dict, the file is relative to the current directory.
    as_dict = {"scene": {"kind": "map", "file": "room.pgm"}, "episode": {"max_steps": 20}, "moving": [{"count": 2}]}
    with pytest.raises(ronap.SceneError, match="room.pgm"):
        ronap.NavEnv(scenario=as_dict)
    monkeypatch.chdir(rooms)
    assert np.array_equal(ronap.NavEnv(scenario=as_dict).reset(seed=0)[0], obs)
    # map= overrides the scenario's scene, as --map does.
    monkeypatch.chdir(elsewhere)
    env = ronap.NavEnv(scenario=SCENARIO_DICT, map=rooms / "room.pgm")
    assert all(0 < c < 400 for c in env.reset(seed=0)[1]["pose"][:2])


@pytest.mark.parametrize(
    "text, line, words",
    [
        ('[scene]\nkind = "warehouse"\n\n[laser]\nbeams = 9\nbeamz = 3\n', 6, ["beamz"]),
        ('[scene]\nkind = "warehouse"\n\n[laser]\nbeams = "many"\n', 5, ["beams", "many"]),
        ('[scene]\nkind = "warehouse"\n\n[[moving]]\ncount = 2\nmotion = "teleport"\n', 6, ["motion", "teleport"]),
        ('[scene]\nkind = "warehouse"\n\n[[moving]]\ncount = 10\nmotion = "random_walk"\nspeed_px = -1\n', 7, ["moving[0].speed_px", "-1"]),
        ('[[moving]]\ncount = 1\n\n[[moving]]\ncount = 2\nturn_sigma_deg = 400.0\n', 6, ["moving[1].turn_sigma_deg", "400"]),
    ],
)
def test_a_bad_scenario_file_is_named_by_file_and_line(tmp_path, text, line, words):
    path = tmp_path / "bad-scenario.toml"
    path.write_text(text)
    for make in (
        lambda: ronap.NavEnv(scenario=path),
        lambda: ronap.VecNavEnv(2, scenario=path),
        lambda: ronap.evaluate("apf", [0], scenario=path),
    ):
        with pytest.raises(ronap.ConfigError) as caught:
            make()
        message = str(caught.value)
        assert f"bad-scenario.toml:{line}:" in message, message
        for word in words:
            assert word in message, message


def test_scenario_errors_that_are_not_in_the_file(tmp_path, scenario):
    with pytest.raises(ronap.ConfigError, match=r"scenario: no such file: .*missing\.toml"):
        ronap.NavEnv(scenario=tmp_path / "missing.toml")
    # A bad value from a keyword argument is named as such, not put on a line of the file.
    with pytest.raises(ronap.ConfigError) as caught:
        ronap.NavEnv(scenario=scenario, config={"moving": [{"count": 2, "speed_px": -3.0}]})
    assert str(caught.value).startswith("moving[0].speed_px = -3.0"), caught.value
    with pytest.raises(ronap.ConfigError, match=r"^laser\.beams = 0"):
        ronap.NavEnv(scenario=scenario, laser_beams=0)
    # A bad value the file sets that a keyword argument then fixes is no error, as with flags.
    bad = tmp_path / "bad.toml"
    bad.write_text('[laser]\nbeams = 0\n')
    assert ronap.make_config(scenario=bad, laser_beams=5)["laser"]["beams"] == 5
    with pytest.raises(ronap.ConfigError, match=r"bad\.toml:2: laser\.beams = 0"):
        ronap.make_config(scenario=bad)
    with pytest.raises(ronap.ConfigError, match="moving"):
        ronap.NavEnv(scenario=scenario, moving_count=3)


@pytest.mark.parametrize(
    "bad, words",
    [
        ({"maze": {"colz": 3}}, ["maze.colz", "3"]),
        ({"laser": {"beams": "many"}}, ["laser.beams", "many"]),
        ({"moving": [{"count": 2}, {"motion": "teleport"}]}, ["moving[1].motion", "teleport"]),
        ({"moving": [{"speed_px": -1}]}, ["moving[0].speed_px", "-1"]),
        ({"obstacles": [{"shape": "hexagon"}]}, ["obstacles[0]", "hexagon"]),
        ({"scene": {"kind": "castle"}}, ["scene.kind", "castle"]),
        ({"galaxy": {"stars": 3}}, ["galaxy"]),
        ({"moving": {"count": 3}}, ["moving", "sequence"]),
    ],
)
def test_a_bad_scenario_dict_names_key_and_value(bad, words):
    with pytest.raises(ronap.ConfigError) as caught:
        ronap.NavEnv(scenario=bad)
    for word in words:
        assert word in str(caught.value), caught.value


@pytest.mark.parametrize("bad", [3, ["scene"], b"walkers.toml", object()])
def test_a_scenario_of_another_type_is_a_config_error(bad):
    with pytest.raises(ronap.ConfigError, match="scenario"):
        ronap.NavEnv(scenario=bad)
    with pytest.raises(ronap.ConfigError, match="scenario"):
        ronap.evaluate("apf", [0], scenario=bad)


def test_a_run_from_a_scenario_replays_and_reproduces_with_the_cli(tmp_path, scenario, ronap_bin):
    run = tmp_path / "py"
    result = ronap.evaluate("apf", SEEDS, scenario=scenario, out=run, log_steps=True)
    summary = json.loads((run / "summary.json").read_text())
    # The whole configuration and where the episodes took place.
    assert summary["config"] == ronap.make_config(scenario=scenario)
    assert summary["config"]["moving"][0]["count"] == 10
    assert summary["scenes"] == {"kind": "warehouse_per_seed"}
    assert summary["summary"]["moving"] == result["summary"]["moving"]
    header = (run / "episodes.csv").read_text().splitlines()[0].split(",")
    assert header[-3:] == ["dynamic_collisions", "min_clearance_px", "near_moving_fraction"]
    # `ronap replay` rebuilds the run from summary.json and checks every logged pose against it.
    for seed in SEEDS:
        log = run / "steps" / f"seed-{seed:06}.csv"
        r = subprocess.run([ronap_bin, "replay", str(log), "--out", str(tmp_path / f"{seed}.gif")], capture_output=True, text=True)
        assert r.returncode == 0, r.stderr
        assert f"seed {seed}," in r.stdout
    # The CLI on the same scenario file writes the same episodes.
    cli = tmp_path / "cli"
    subprocess.run(
        [ronap_bin, "run", "--scenario", str(scenario), "--policy", "apf", "--seeds", str(len(SEEDS)), "--out", str(cli)],
        check=True,
        capture_output=True,
    )
    assert (cli / "episodes.csv").read_bytes() == (run / "episodes.csv").read_bytes()
    cli_summary = json.loads((cli / "summary.json").read_text())
    assert cli_summary["config"] == summary["config"] and cli_summary["scenes"] == summary["scenes"]
    # And the manifest alone reproduces the run from Python.
    again = tmp_path / "again"
    ronap.evaluate("apf", SEEDS, config=summary["config"], out=again)
    assert (again / "episodes.csv").read_bytes() == (run / "episodes.csv").read_bytes()


def test_a_scene_seed_override_is_recorded(tmp_path, scenario, ronap_bin):
    run = tmp_path / "one"
    ronap.evaluate("apf", [0, 1], scenario=scenario, maze_seed=4, out=run, log_steps=True)
    summary = json.loads((run / "summary.json").read_text())
    assert summary["scenes"] == {"kind": "warehouse", "seed": 4}
    r = subprocess.run([ronap_bin, "replay", str(run / "steps" / "seed-000001.csv"), "--out", str(tmp_path / "x.gif")], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    cli = tmp_path / "cli"
    subprocess.run(
        [ronap_bin, "run", "--scenario", str(scenario), "--maze-seed", "4", "--policy", "apf", "--seeds", "2", "--out", str(cli)],
        check=True,
        capture_output=True,
    )
    assert (cli / "episodes.csv").read_bytes() == (run / "episodes.csv").read_bytes()


def test_a_crowd_pattern_that_leaves_the_scene_is_named_by_file_line_key_and_value(tmp_path):
    from pathlib import Path

    text = (Path(__file__).resolve().parents[3] / "scenarios" / "circle-crossing.toml").read_text()
    bad = tmp_path / "wide.toml"
    bad.write_text(text.replace("pattern_radius_px = 80.0", "pattern_radius_px = 8000.0"))
    line = next(i + 1 for i, l in enumerate(bad.read_text().splitlines()) if "pattern_radius_px" in l)
    want = rf"wide\.toml:{line}: .*crowd\[0\]\.pattern_radius_px = 8000: the robot's start"
    with pytest.raises(ronap.SceneError, match=want):
        ronap.NavEnv(scenario=bad).reset(seed=0)
    with pytest.raises(ronap.SceneError, match=want):
        ronap.evaluate("orca", range(2), scenario=bad)
    with pytest.raises(ronap.SceneError, match=want):
        ronap.VecNavEnv(2, scenario=bad).reset(seed=0)
