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
