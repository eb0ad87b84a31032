"""Reward shaping (reward.shaping = "geodesic") and observation memory (observation.history)
from Python: the spaces follow, and NavEnv and VecNavEnv agree."""

from __future__ import annotations

import numpy as np
import pytest

import ronap


def test_history_widens_the_observation_and_its_space() -> None:
    env = ronap.NavEnv(config={"observation": {"history": 4}})
    assert env.observation_space.shape == (4 * 18 + 3 * 3,)
    obs, _ = env.reset(seed=3)
    assert obs.shape == (81,)
    assert env.observation_space.contains(obs)
    # At the start the past frames repeat the first one and no action is remembered.
    for j in range(1, 4):
        np.testing.assert_array_equal(obs[j * 18 : (j + 1) * 18], obs[:18])
    assert not obs[72:].any()
    first = obs[:18].copy()
    obs, *_ = env.step(2)
    np.testing.assert_array_equal(obs[18:36], first)
    np.testing.assert_array_equal(obs[72:75], [0.0, 0.0, 1.0])
    assert env.observation_space.contains(obs)

    vec = ronap.VecNavEnv(3, config={"observation": {"history": 4}})
    assert vec.single_observation_space.shape == (81,)
    batch, _ = vec.reset(seed=3)
    np.testing.assert_array_equal(batch[0], env.reset(seed=3)[0])


def test_history_out_of_range_is_refused_naming_the_key() -> None:
    with pytest.raises(ronap.ConfigError, match="observation.history"):
        ronap.NavEnv(config={"observation": {"history": 0}})
    with pytest.raises(ronap.ConfigError, match="observation.history"):
        ronap.NavEnv(config={"observation": {"history": 65}})


def test_geodesic_shaping_changes_the_reward_alike_in_nav_env_and_vec_env() -> None:
    gamma = 0.97
    config = {"reward": {"shaping": "geodesic", "shaping_gamma": gamma}}
    shaped = ronap.NavEnv(config=config)
    plain = ronap.NavEnv()
    vec = ronap.VecNavEnv(1, config=config, autoreset_mode="disabled")
    rng = np.random.default_rng(0)
    shaped.reset(seed=5)
    plain.reset(seed=5)
    vec.reset(seed=5)
    differ = 0
    for _ in range(300):
        a = int(rng.integers(3))
        _, r_shaped, term, trunc, _ = shaped.step(a)
        _, r_plain, *_ = plain.step(a)
        _, r_vec, *_ = vec.step(np.array([a]))
        assert r_vec[0] == pytest.approx(r_shaped, abs=1e-12)
        differ += abs(r_shaped - r_plain) > 1e-9
        if term or trunc:
            break
    # Shaping changes the rewards the learner is given (the core's tests check they telescope).
    assert differ > 0
    with pytest.raises(ronap.ConfigError, match="shaping_gamma"):
        ronap.NavEnv(config={"reward": {"shaping": "geodesic", "shaping_gamma": 1.5}})
    with pytest.raises(ronap.ConfigError, match="shaping"):
        ronap.NavEnv(config={"reward": {"shaping": "straight"}})


@pytest.mark.parametrize(
    "config",
    [
        {"reward": {"shaping": "geodesic", "shaping_gamma": 0.97}},
        {"moving": [{"count": 8, "shape": "disc", "radius_px": 6.0, "motion": "random_walk", "speed_px": 2.0}]},
        {"episode": {"start": [150.0, 150.0, 0.0], "goal": [450.0, 350.0]}, "observation": {"history": 2}},
    ],
)
def test_a_team_of_one_plays_the_lone_robots_episodes(config) -> None:
    """NavEnv and MultiNavEnv share one core, on which a lone robot is a team of one; both
    play what VecNavEnv's batch (the core's lone engine) plays, reward shaping included."""
    # The team's one entry places its robot where `[episode]` placed the lone one.
    episode = dict(config.get("episode", {}))
    entry = {"count": 1, **{k: episode.pop(k) for k in ("start", "goal") if k in episode}}
    team = ronap.MultiNavEnv(config={**config, "episode": episode, "robots": [entry]})
    lone = ronap.NavEnv(config=config)
    vec = ronap.VecNavEnv(1, config=config, autoreset_mode="disabled")
    rng = np.random.default_rng(2)
    for seed in (5, 6):
        t_obs, _ = team.reset(seed=seed)
        l_obs, _ = lone.reset(seed=seed)
        v_obs, _ = vec.reset(seed=seed)
        np.testing.assert_array_equal(t_obs["robot_0"], v_obs[0])
        np.testing.assert_array_equal(l_obs, v_obs[0])
        for _ in range(250):
            a = int(rng.integers(3))
            t_obs, t_r, t_term, t_trunc, _ = team.step({"robot_0": a})
            l_obs, l_r, l_term, l_trunc, _ = lone.step(a)
            v_obs, v_r, v_term, v_trunc, _ = vec.step(np.array([a]))
            np.testing.assert_array_equal(t_obs["robot_0"], v_obs[0])
            np.testing.assert_array_equal(l_obs, v_obs[0])
            assert t_r["robot_0"] == pytest.approx(v_r[0], abs=1e-12)
            assert l_r == pytest.approx(v_r[0], abs=1e-12)
            assert (t_term["robot_0"], t_trunc["robot_0"]) == (l_term, l_trunc) == (v_term[0], v_trunc[0])
            if l_term or l_trunc:
                break


def test_a_team_s_rewards_are_shaped_robot_by_robot_alike_in_both_forms() -> None:
    team = {"robots": [{"count": 3}]}
    shaped = ronap.MultiNavEnv(config={**team, "reward": {"shaping": "geodesic"}})
    plain = ronap.MultiNavEnv(config=team)
    vec = ronap.VecMultiNavEnv(2, config={**team, "reward": {"shaping": "geodesic"}})
    shaped.reset(seed=1)
    plain.reset(seed=1)
    vec.reset(seed=0)  # environment 1 plays seed 1
    rng = np.random.default_rng(3)
    differ = 0
    for _ in range(40):
        chosen = rng.integers(3, size=3)
        actions = {a: int(chosen[k]) for k, a in enumerate(shaped.possible_agents) if a in shaped.agents}
        _, r_shaped, *_ = shaped.step(actions)
        _, r_plain, *_ = plain.step(actions)
        _, r_vec, *_ = vec.step(np.stack([chosen, chosen]))
        assert r_shaped.keys() == r_plain.keys()
        for k, a in enumerate(shaped.possible_agents):
            if a in r_shaped:
                assert r_vec[1, k] == pytest.approx(r_shaped[a], abs=1e-12)
        differ += sum(abs(r_shaped[a] - r_plain[a]) > 1e-9 for a in r_shaped)
        if not shaped.agents:
            break
    assert differ > 0


def test_a_team_refuses_the_lone_robots_fixed_start() -> None:
    with pytest.raises(ronap.ConfigError, match=r"episode\.start.*robots\[i\]\.start"):
        ronap.MultiNavEnv(config={"episode": {"start": [150.0, 150.0, 0.0]}, "robots": [{"count": 1}]})
