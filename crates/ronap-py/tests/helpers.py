"""What several test modules share: a policy written in Python, and the check that a vector env
steps exactly as single envs do."""

import numpy as np


def toward_goal(obs):
    """Turns toward the goal (the last observation, its direction as a fraction of 360 degrees)
    and drives ahead once it is within 15 degrees."""
    d = float(obs[-1]) * 360.0
    if 15 < d < 180:
        return 0
    if 180 <= d < 345:
        return 2
    return 1


def assert_vec_env_is_single_envs(vec, singles, seed, steps, *, stop_at_an_end=False):
    """Resets ``vec`` with ``seed`` and ``singles[i]`` with ``seed + i``, then steps them all with the
    same random actions ``steps`` times: observations, rewards, ends and distances bit for bit.
    With ``stop_at_an_end``, stops after the first episode end (the vector env resets it on the next
    step; the single ones would not)."""
    n = len(singles)
    obs, _ = vec.reset(seed=seed)
    for i, env in enumerate(singles):
        o, _ = env.reset(seed=seed + i)
        assert np.array_equal(obs[i], o)
    rng = np.random.default_rng(0)
    for _ in range(steps):
        actions = rng.integers(0, 3, n)
        obs, rewards, term, trunc, infos = vec.step(actions)
        for i, env in enumerate(singles):
            o, r, t, tr, info = env.step(int(actions[i]))
            assert np.array_equal(obs[i], o)
            assert rewards[i] == r and term[i] == t and trunc[i] == tr
            assert infos["distance"][i] == info["distance"]
        if stop_at_an_end and (term.any() or trunc.any()):
            break
