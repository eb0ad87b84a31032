"""The Gymnasium environments: API conformance, determinism, vector/single agreement, errors."""

import warnings

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import ronap
from helpers import assert_vec_env_is_single_envs


def test_env_checker_passes_without_warnings():
    for kwargs in ({}, {"continuous": True}, {"render_mode": "rgb_array"}):
        env = gym.make("ronap/Nav-v0", **kwargs).unwrapped
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            check_env(env)
        assert [str(w.message) for w in caught] == []


def test_observation_is_the_papers_18_values():
    env = ronap.NavEnv(episode_start=[150.0, 150.0, 0.0], episode_goal=[450.0, 150.0], maze_seed=1)
    obs, info = env.reset(seed=0)
    assert obs.shape == (18,) and obs.dtype == np.float32
    assert np.all((obs >= 0) & (obs <= 1))
    # The goal is straight ahead: direction 0.
    assert obs[17] == 0.0
    assert info["distance"] == pytest.approx(300.0)
    assert info["pose"] == (150.0, 150.0, 0.0)
    obs, reward, terminated, truncated, info = env.step(0)  # LEFT: the goal is now 15 deg right
    assert obs[17] == pytest.approx(345.0 / 360.0)
    assert reward == pytest.approx(-0.05)
    assert not terminated and not truncated


def test_same_seed_same_episode_and_reset_without_seed_moves_on():
    env = ronap.NavEnv()
    a, _ = env.reset(seed=42)
    b, _ = env.reset(seed=42)
    c, _ = env.reset()
    assert np.array_equal(a, b)
    assert not np.array_equal(a, c)


def test_success_terminates_and_timeout_truncates():
    env = ronap.NavEnv(episode_start=[150.0, 150.0, 0.0], episode_goal=[170.0, 150.0], maze_seed=1)
    env.reset(seed=0)
    results = [env.step(1) for _ in range(3)]
    assert results[-1][2] is True and results[-1][4]["success"] is True
    env = ronap.NavEnv(episode_max_steps=3)
    env.reset(seed=5)
    flags = [env.step(0)[2:4] for _ in range(3)]
    assert flags == [(False, False), (False, False), (False, True)]


def test_collision_terminates_when_configured():
    env = ronap.NavEnv(robot_on_collision="terminate", episode_start=[8.0, 150.0, 180.0], episode_goal=[550.0, 550.0], maze_seed=1)
    env.reset(seed=0)
    obs, reward, terminated, truncated, info = env.step(1)
    assert info["collided"] and terminated and not truncated
    assert reward == pytest.approx(-1.0, abs=0.01)


def test_render_top_and_first_person():
    env = ronap.NavEnv(render_mode="rgb_array", render_scale=0.5)
    env.reset(seed=3)
    img = env.render()
    assert img.shape == (500, 500, 3) and img.dtype == np.uint8
    fp = ronap.NavEnv(render_mode="rgb_array", render_view="first_person")
    fp.reset(seed=3)
    view = fp.render()
    assert view.shape == (400, 400, 3)
    # The robot (blue) sits in the middle; the goal arrow is green somewhere.
    assert tuple(view[200, 200]) == (40, 80, 230)
    assert np.any(np.all(view == (30, 170, 60), axis=-1))


def test_continuous_actions():
    env = ronap.NavEnv(continuous=True, episode_start=[150.0, 150.0, 0.0], episode_goal=[450.0, 150.0], maze_seed=1)
    assert isinstance(env.action_space, gym.spaces.Box)
    env.reset(seed=0)
    _, reward, *_ , info = env.step(np.array([1.0, 0.0], dtype=np.float32))
    assert info["pose"][0] == pytest.approx(155.0)
    _, reward, *_ , info = env.step(np.array([0.0, 1.0], dtype=np.float32))
    assert info["pose"][2] == pytest.approx(15.0)
    with pytest.raises(ronap.ActionError):
        env.step(np.array([np.nan, 0.0]))


def test_vector_env_equals_single_envs_bit_for_bit():
    n = 6
    assert_vec_env_is_single_envs(ronap.VecNavEnv(n), [ronap.NavEnv() for _ in range(n)], 100, 200)


def test_vector_env_autoresets_on_the_next_step():
    n, seed = 3, 7
    vec = ronap.VecNavEnv(n, episode_max_steps=4)
    vec.reset(seed=seed)
    for _ in range(4):
        obs, rewards, term, trunc, _ = vec.step(np.ones(n, dtype=np.int64))
    assert trunc.all()
    obs, rewards, term, trunc, _ = vec.step(np.ones(n, dtype=np.int64))
    assert not trunc.any() and np.all(rewards == 0)
    for i in range(n):
        fresh, _ = ronap.NavEnv(episode_max_steps=4).reset(seed=seed + i + n)
        assert np.array_equal(obs[i], fresh)


def test_vector_env_is_a_gymnasium_vector_env():
    vec = ronap.VecNavEnv(4)
    assert isinstance(vec, gym.vector.VectorEnv)
    obs, infos = vec.reset(seed=0)
    assert obs.shape == (4, 18) and obs.dtype == np.float32
    assert vec.observation_space.contains(obs)
    assert set(infos) >= {"distance", "_distance", "collided", "success", "pose"}
    with pytest.raises(ronap.ActionError, match="action 3 for environment 1"):
        vec.step(np.array([0, 3, 0, 0]))


def test_config_errors_name_field_and_value():
    with pytest.raises(ronap.ConfigError, match=r"maze\.cols = 0"):
        ronap.NavEnv(maze_cols=0)
    with pytest.raises(ronap.ConfigError, match=r"laser\.range_px = -5"):
        ronap.NavEnv(config={"laser": {"range_px": -5.0}})
    with pytest.raises(ronap.ConfigError, match="colz"):
        ronap.NavEnv(config={"maze.colz": 3})
    with pytest.raises(ronap.ConfigError, match="mace"):
        ronap.NavEnv(mace_cols=3)
    assert issubclass(ronap.ConfigError, ronap.RonapError)
    assert ronap.make_config(maze_cols=5)["maze"]["cols"] == 5
    assert ronap.make_config({"maze": {"rows": 4}})["maze"]["rows"] == 4


def test_step_errors():
    env = ronap.NavEnv()
    with pytest.raises(ronap.RonapError, match="before reset"):
        env.step(1)
    env.reset(seed=0)
    with pytest.raises(ronap.ActionError, match="action 5"):
        env.step(5)


def test_mazes_as_arrays():
    occ = ronap.maze_occupancy(7)
    assert occ.shape == (1000, 1000) and occ.dtype == bool
    assert occ[0].all() and occ[-1].all() and occ[:, 0].all()
    img = ronap.maze_image(7, scale=0.5)
    assert img.shape == (500, 500, 3)
    small = ronap.maze_occupancy(7, scale=0.5)
    assert np.array_equal(small, np.all(img == 0, axis=-1))
    # Walls run along the cells' borders: the centre of every 100 px cell is floor.
    assert not occ[50::100, 50::100].any()
    assert occ[10:-10, 10:-10].any()
    assert set(ronap.policies()) == {
        "apf",
        "geodesic",
        "geodesic-wait",
        "orca",
        "social-force",
        "dwa",
        "random",
    }


def test_out_of_range_counts_and_seeds_are_config_errors_naming_them():
    cases = [
        (lambda: ronap.VecNavEnv(-1), "num_envs = -1"),
        (lambda: ronap.VecNavEnv(0), "num_envs = 0"),
        (lambda: ronap.VecNavEnv(2.5), "num_envs = 2.5"),
        (lambda: ronap.VecNavEnv(2, threads=-3), "threads = -3"),
        (lambda: ronap.VecNavEnv(2).reset(seed=-1), "seed = -1"),
        (lambda: ronap.NavEnv().reset(seed=-1), "seed = -1"),
        (lambda: ronap.NavEnv().reset(seed=2**64), "seed = 18446744073709551616"),
        (lambda: ronap.evaluate("apf", seeds=[3, -1]), "seeds[1] = -1"),
        (lambda: ronap.evaluate("apf", seeds=[True]), "seeds[0] = True"),
        (lambda: ronap.evaluate("apf", seeds=5), "seeds = 5"),
        (lambda: ronap.compare(["apf", "random"], seeds=[1.5]), "seeds[0] = 1.5"),
    ]
    for make, named in cases:
        with pytest.raises(ronap.ConfigError) as e:
            make()
        assert named in str(e.value), (named, str(e.value))
    # Whole floats and numpy integers are whole numbers.
    assert ronap.evaluate("apf", seeds=[np.int64(1), 2.0])["summary"]["episodes"] == 2


def test_vec_env_refuses_step_before_reset_and_fractional_actions():
    vec = ronap.VecNavEnv(2)
    with pytest.raises(ronap.RonapError, match="before reset"):
        vec.step(np.array([1, 1]))
    vec.reset(seed=0)
    with pytest.raises(ronap.ActionError, match=r"2.5 at \(0,\)"):
        vec.step(np.array([2.5, 1.0]))
    with pytest.raises(ronap.ActionError, match="dtype bool"):
        vec.step(np.array([True, False]))
    vec.step(np.array([1.0, 2.0]))  # whole floats are whole actions
    env = ronap.NavEnv()
    env.reset(seed=0)
    with pytest.raises(ronap.ActionError, match="bool"):
        env.step(True)


def test_nav_env_pickles_mid_episode_and_goes_on_the_same():
    import pickle

    env = ronap.NavEnv(maze_cols=5, continuous=True)
    env.reset(seed=4)
    for t in range(20):
        env.step(np.array([1.0, 0.3 * ((t % 3) - 1)], np.float32))
    copy = pickle.loads(pickle.dumps(env))
    fresh = pickle.loads(pickle.dumps(ronap.NavEnv(maze_cols=5)))
    assert fresh.reset(seed=1)[0].shape == (18,)
    for t in range(30):
        a = np.array([0.5, 0.2], np.float32)
        o1, r1, te1, tr1, i1 = env.step(a)
        o2, r2, te2, tr2, i2 = copy.step(a)
        np.testing.assert_array_equal(o1, o2)
        assert (r1, te1, tr1, i1["pose"]) == (r2, te2, tr2, i2["pose"])
        if te1 or tr1:
            break
    # The seed generator travels too: the next unseeded episodes agree.
    np.testing.assert_array_equal(env.reset()[0], copy.reset()[0])


def test_make_vec_vector_entry_point_steps_in_rust():
    vec = gym.make_vec("ronap/Nav-v0", num_envs=4, vectorization_mode="vector_entry_point", maze_cols=5)
    assert isinstance(vec, ronap.VecNavEnv) and vec.num_envs == 4
    obs, _ = vec.reset(seed=3)
    direct = ronap.VecNavEnv(4, maze_cols=5)
    np.testing.assert_array_equal(obs, direct.reset(seed=3)[0])


def test_nav_env_drives_one_robot_and_names_its_own_keys():
    """NavEnv steps its robot as a team of one; what it refuses and reports stays the lone
    robot's: a team scenario at reset, a blocked fixed start by `episode.start`, nothing after
    the end."""
    from pathlib import Path

    team = Path(__file__).resolve().parents[3] / "scenarios" / "warehouse-team.toml"
    with pytest.raises(ronap.SceneError, match=r"seed 0: the scenario has \d+ robots \(\[\[robots\]\]\)"):
        ronap.NavEnv(scenario=team).reset(seed=0)
    with pytest.raises(ronap.SceneError, match=r"episode\.start = \(0, 0\) is not free"):
        ronap.NavEnv(episode_start=[0.0, 0.0, 0.0]).reset(seed=0)
    env = ronap.NavEnv(episode_max_steps=5)
    env.reset(seed=3)
    for _ in range(5):
        *_, terminated, truncated, info = env.step(1)
    assert truncated and info["status"] == "timeout"
    _, reward, terminated, truncated, info = env.step(1)
    assert reward == 0.0 and not info["collided"] and truncated
