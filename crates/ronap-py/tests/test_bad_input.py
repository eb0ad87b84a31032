"""Bad input from Python never panics or is silently bent: NaN and infinities in configurations
and actions, numpy arrays of every odd dtype, layout and shape into VecNavEnv.step, and Python
policies that return numpy scalars, bools, None, or raise. Each is a RonapError naming what was
wrong (or, for numpy integers, accepted as the integer it is)."""

import json
import math

import numpy as np
import pytest

import ronap


@pytest.mark.parametrize("value", [float("nan"), float("inf"), -float("inf")])
@pytest.mark.parametrize("key", ["laser_range_px", "maze_cell_px", "robot_move_speed_px", "maze_loops"])
def test_nan_and_infinity_in_a_configuration_name_the_field(key, value):
    with pytest.raises(ronap.ConfigError) as e:
        ronap.NavEnv(**{key: value})
    field = key.replace("_", ".", 1)
    assert field in str(e.value), str(e.value)


def test_nan_in_a_scenario_dict_names_the_key():
    with pytest.raises(ronap.ConfigError, match=r"robot\.radius_px"):
        ronap.NavEnv(scenario={"robot": {"radius_px": float("nan")}})


@pytest.mark.parametrize("bad", [[float("nan"), 0.0], [0.0, float("inf")], [-float("inf"), 0.0]])
def test_continuous_actions_that_are_not_finite_are_refused(bad):
    env = ronap.NavEnv(continuous=True)
    env.reset(seed=0)
    with pytest.raises(ronap.ActionError, match="finite|NaN|inf"):
        env.step(np.array(bad, np.float32))
    # The episode is untouched: a good action still steps it.
    env.step(np.array([1.0, 0.0], np.float32))


@pytest.mark.parametrize(
    "actions",
    [
        np.array([1, 9, 2, 9, 0, 9, 1, 9], np.int64)[::2],  # a strided view
        np.asfortranarray(np.array([[1], [2], [0], [1]], np.int32))[:, 0],
        np.array([1, 2, 0, 1], np.int8),
        np.array([1, 2, 0, 1], np.uint8),
        np.array([1, 2, 0, 1], np.uint64),
        np.array([1, 2, 0, 1], np.int16),
        np.array([1.0, 2.0, 0.0, 1.0], np.float16),
        np.array([1.0, 2.0, 0.0, 1.0], np.float32),
        [1, 2, 0, 1],
        (1, 2, 0, 1),
    ],
    ids=["strided", "fortran-column", "int8", "uint8", "uint64", "int16", "float16", "float32",
         "list", "tuple"],
)
def test_vec_env_takes_any_whole_number_array_layout(actions):
    vec = ronap.VecNavEnv(4)
    vec.reset(seed=0)
    ref = ronap.VecNavEnv(4)
    ref.reset(seed=0)
    obs, rew, *_ = vec.step(actions)
    want, want_rew, *_ = ref.step(np.array([1, 2, 0, 1]))
    assert np.array_equal(obs, want) and np.array_equal(rew, want_rew)


@pytest.mark.parametrize(
    "actions, words",
    [
        (np.array([1, 2, 0]), "4"),
        (np.array([1, 2, 0, 1, 1]), "4"),
        (np.array([[1, 2], [0, 1]]), "shape"),
        (np.array([1, 2, 0, 1]).reshape(4, 1), "shape (4, 1)"),
        (np.array([1, 2, 0, -1]), "-1"),
        (np.array([1, 2, 0, 2**40]), str(2**40)),
        (np.array([1.0, float("nan"), 0.0, 1.0]), "nan"),
        (np.array([1.0, float("inf"), 0.0, 1.0]), "inf"),
        (np.array([1 + 0j, 2, 0, 1]), "complex"),
        (np.array(["1", "2", "0", "1"]), "<U1"),
        (np.array([1, 2, 0, None], dtype=object), "object"),
        (np.array([True, False, True, False]), "bool"),
        (None, "None"),
        ("1201", "str"),
        (np.int64(1), "4"),
    ],
    ids=["short", "long", "2d", "column", "negative", "huge", "nan", "inf", "complex", "strings", "object",
         "bool", "none", "str", "scalar"],
)
def test_vec_env_refuses_bad_actions_naming_them(actions, words):
    vec = ronap.VecNavEnv(4)
    vec.reset(seed=0)
    with pytest.raises(ronap.RonapError) as e:
        vec.step(actions)
    assert words.lower() in str(e.value).lower(), str(e.value)
    # Nothing stepped: the next good step matches a fresh environment's first.
    ref = ronap.VecNavEnv(4)
    ref.reset(seed=0)
    assert np.array_equal(vec.step(np.array([1, 1, 1, 1]))[0], ref.step(np.array([1, 1, 1, 1]))[0])


@pytest.mark.parametrize("action", [np.int64(2), np.int32(2), np.uint8(2), np.float64(2.0), 2.0])
def test_a_python_policy_may_return_numpy_scalars_and_whole_floats(action):
    got = ronap.evaluate(lambda obs: action, [3], threads=1, episode_max_steps=20)
    want = ronap.evaluate(lambda obs: 2, [3], threads=1, episode_max_steps=20)
    strip = lambda res: [{k: v for k, v in r.items() if k != "wall_time_s"} for r in res["episodes"]]
    assert strip(got) == strip(want)


@pytest.mark.parametrize(
    "returned, words",
    [
        (True, "True"),
        (np.bool_(True), "True"),
        (None, "None"),
        (np.array([1, 2]), "[1 2]"),
        (2.5, "2.5"),
        (np.float32("nan"), "NaN"),
        (-1, "-1"),
        (2**70, str(2**70)),
    ],
    ids=["bool", "numpy-bool", "none", "array", "fraction", "nan", "negative", "huge"],
)
def test_bad_policy_returns_are_policy_errors_naming_seed_step_and_value(returned, words):
    with pytest.raises(ronap.PolicyError) as e:
        ronap.evaluate(lambda obs: returned, [3], threads=1)
    text = str(e.value)
    assert "seed 3, step 1" in text and words in text, text


def test_a_policy_that_raises_is_a_policy_error_and_finished_episodes_are_kept(tmp_path):
    calls = []

    def flaky(obs):
        calls.append(1)
        if len(calls) == 250:
            raise RuntimeError("sensor unplugged")
        return 1

    with pytest.raises(ronap.PolicyError, match=r"seed 2, step 50: .*RuntimeError\('sensor unplugged'\)"):
        ronap.evaluate(flaky, range(5), threads=1, episode_max_steps=100, out=str(tmp_path / "run"))
    # The two finished episodes are whole rows; the manifest says why the run stopped.
    rows = (tmp_path / "run" / "episodes.csv").read_text().splitlines()
    assert [r.split(",")[0] for r in rows[1:]] == ["0", "1"]
    summary = json.loads((tmp_path / "run" / "summary.json").read_text())
    assert "sensor unplugged" in summary["error"] and summary["summary"]["episodes"] == 2


def test_huge_counts_and_sizes_are_config_errors():
    for make, named in [
        (lambda: ronap.NavEnv(maze_cols=2**32), "maze.cols"),
        (lambda: ronap.NavEnv(laser_beams=2**31), "laser.beams"),
        (lambda: ronap.NavEnv(episode_max_steps=-5), "episode.max_steps"),
        (lambda: ronap.VecNavEnv(2**40), "num_envs"),
        (lambda: ronap.evaluate("apf", seeds=range(2**64 - 2, 2**64 + 1)), "seeds"),
    ]:
        with pytest.raises(ronap.RonapError) as e:
            make()
        assert named in str(e.value), (named, str(e.value))
    assert math.isfinite(1.0)
