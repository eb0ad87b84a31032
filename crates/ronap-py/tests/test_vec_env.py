"""VecNavEnv's Gymnasium vector API: per-environment seeds, resets of chosen environments, the
three autoreset modes, continuous actions, infos and pictures, each against single NavEnvs
playing the same seeds."""

import numpy as np
import pytest
from gymnasium.vector import AutoresetMode

import ronap

ACTIONS = [1, 1, 0, 1, 2, 1, 1, 1]


def play(vec, steps):
    """Per environment, the episodes it played as lists of (seed, observation, reward), whatever
    the autoreset mode (disabled: ended environments restarted through reset_mask). Environment
    i's action at step k of an episode is ACTIONS[k + i] (cyclically)."""
    n = vec.num_envs
    episodes = [[] for _ in range(n)]
    obs, info = vec.reset(seed=40)
    for i in range(n):
        episodes[i].append([(int(info["seed"][i]), obs[i].tolist(), 0.0)])
    mode = vec.metadata["autoreset_mode"]
    ended = np.zeros(n, dtype=bool)
    for _ in range(steps):
        if mode == AutoresetMode.DISABLED and ended.any():
            obs, info = vec.reset(options={"reset_mask": ended})
            for i in np.flatnonzero(ended):
                episodes[i].append([(int(info["seed"][i]), obs[i].tolist(), 0.0)])
            ended[:] = False
        actions = np.array([ACTIONS[(info["steps"][i] + i) % len(ACTIONS)] for i in range(n)])
        obs, rewards, terminated, truncated, info = vec.step(actions)
        done = terminated | truncated
        for i in range(n):
            if mode == AutoresetMode.NEXT_STEP and ended[i]:
                episodes[i].append([(int(info["seed"][i]), obs[i].tolist(), 0.0)])
                continue
            if mode == AutoresetMode.SAME_STEP and done[i]:
                last = info["final_obs"][i]
                episodes[i][-1].append((int(info["final_info"]["seed"][i]), last.tolist(), float(rewards[i])))
                episodes[i].append([(int(info["seed"][i]), obs[i].tolist(), 0.0)])
            else:
                episodes[i][-1].append((int(info["seed"][i]), obs[i].tolist(), float(rewards[i])))
        ended = done
    return episodes


def test_every_autoreset_mode_plays_the_same_episodes():
    runs = {
        mode: play(ronap.VecNavEnv(3, episode_max_steps=9, autoreset_mode=mode, threads=1), 40)
        for mode in ("next_step", "same_step", "disabled")
    }
    # Next-step autoreset spends a step on each reset, so compare the episodes every mode ended.
    for i in range(3):
        k = min(len(run[i]) for run in runs.values()) - 1
        assert k >= 3
        assert runs["next_step"][i][:k] == runs["same_step"][i][:k] == runs["disabled"][i][:k]
    # Environment i's k-th episode has seed 40 + i + 3k.
    for i, episodes in enumerate(runs["same_step"]):
        assert [e[0][0] for e in episodes] == [40 + i + 3 * k for k in range(len(episodes))]


def test_episodes_equal_single_environments_of_the_same_seeds():
    vec = ronap.VecNavEnv(2, episode_max_steps=12, autoreset_mode="same_step")
    for i, episodes in enumerate(play(vec, 30)):
        # Environment i stepped the pattern shifted by i: replay its first episode so.
        env = ronap.NavEnv(episode_max_steps=12)
        obs, _ = env.reset(seed=40 + i)
        replay = [obs.tolist()]
        for t in range(len(episodes[0]) - 1):
            obs, *_ = env.step(ACTIONS[(t + i) % len(ACTIONS)])
            replay.append(obs.tolist())
        assert replay == [o for _, o, _ in episodes[0]]


def test_per_environment_seeds_and_resets_of_chosen_environments():
    vec = ronap.VecNavEnv(3)
    obs, info = vec.reset(seed=[7, 100, 3])
    assert info["seed"].tolist() == [7, 100, 3]
    for i, seed in enumerate([7, 100, 3]):
        assert obs[i].tolist() == ronap.NavEnv().reset(seed=seed)[0].tolist()
    for _ in range(5):
        vec.step(np.array([1, 1, 1]))
    before = vec.step(np.array([1, 1, 1]))[4]
    obs, info = vec.reset(seed=[None, 55, None], options={"reset_mask": np.array([True, True, False])})
    # Chosen: env 0 its next seed (7 + 3), env 1 the seed given; env 2 untouched and masked out.
    assert info["seed"][:2].tolist() == [10, 55]
    assert info["_seed"].tolist() == [True, True, False]
    assert info["steps"][:2].tolist() == [0, 0]
    assert info["steps"][2] == before["steps"][2] == 6
    assert obs[1].tolist() == ronap.NavEnv().reset(seed=55)[0].tolist()
    # A masked reset without seeds moves each chosen env on to its next seed.
    _, info = vec.reset(options={"reset_mask": np.array([False, False, True])})
    assert info["seed"][2] == 6


def test_infos_match_the_single_environment():
    vec = ronap.VecNavEnv(2, threads=1)
    _, vinfo = vec.reset(seed=11)
    env = ronap.NavEnv()
    env.reset(seed=12)
    for t in range(6):
        vec.step(np.array([1, ACTIONS[t]]))
        _, _, _, _, vinfo = vec.step(np.array([1, 1]))
        env.step(ACTIONS[t])
        _, _, _, _, info = env.step(1)
    for key in ("distance", "collided", "success", "status", "steps", "collisions", "seed"):
        assert vinfo[key][1] == info[key], key
        assert vinfo["_" + key].all()
    assert tuple(vinfo["pose"][1]) == info["pose"]
    assert tuple(vinfo["goal"][1]) == info["goal"]


def test_continuous_actions_equal_the_single_environment():
    vec = ronap.VecNavEnv(2, continuous=True)
    assert vec.single_action_space.shape == (2,)
    vec.reset(seed=3)
    env = ronap.NavEnv(continuous=True)
    env.reset(seed=4)
    rng = np.random.default_rng(0)
    for _ in range(20):
        a = rng.uniform(-1, 1, (2, 2)).astype(np.float32)
        vobs, vr, *_ = vec.step(a)
        obs, r, *_ = env.step(a[1])
        assert vobs[1].tolist() == obs.tolist() and vr[1] == r
    with pytest.raises(ronap.ActionError, match="shape"):
        vec.step(np.zeros(2))
    with pytest.raises(ronap.ActionError, match="finite"):
        vec.step(np.array([[0.0, np.nan], [0.0, 0.0]]))


def test_render_draws_every_environment_as_the_single_one_does():
    vec = ronap.VecNavEnv(2, render_mode="rgb_array", threads=1)
    vec.reset(seed=20)
    env = ronap.NavEnv(render_mode="rgb_array")
    env.reset(seed=21)
    for t in range(7):
        vec.step(np.array([0, ACTIONS[t]]))
        env.step(ACTIONS[t])
    frames = vec.render()
    assert len(frames) == 2 and frames[0].shape == frames[1].shape
    assert np.array_equal(frames[1], env.render())
    assert ronap.VecNavEnv(2).render() is None


def test_disabled_autoreset_refuses_to_step_an_ended_environment():
    vec = ronap.VecNavEnv(2, episode_max_steps=3, autoreset_mode=AutoresetMode.DISABLED)
    vec.reset(seed=0)
    for _ in range(3):
        vec.step(np.array([1, 1]))
    with pytest.raises(ronap.RonapError, match="environment 0: its episode ended"):
        vec.step(np.array([1, 1]))
    vec.reset(options={"reset_mask": np.array([True, True])})
    vec.step(np.array([1, 1]))


@pytest.mark.parametrize(
    "call, message",
    [
        (lambda v: v.reset(seed=[1, 2]), "2 seeds for 3 environments"),
        (lambda v: v.reset(seed=[1, None, 2]), "needs a seed for every environment"),
        (lambda v: v.reset(seed=[1, -2, 2]), r"seed\[1\] = -2"),
        (lambda v: v.reset(seed="x"), "seed 'x'"),
        (lambda v: v.reset(options={"reset_mask": np.array([True, False, True])}), "first reset"),
        (lambda v: v.reset(options={"reset_mask": [1, 0, 1]}), "expected 3 bools"),
        (lambda v: v.reset(options={"other": 1}), r"options \['other'\]"),
    ],
)
def test_bad_resets_are_config_errors(call, message):
    with pytest.raises(ronap.ConfigError, match=message):
        call(ronap.VecNavEnv(3))


def test_bad_modes_are_config_errors():
    with pytest.raises(ronap.ConfigError, match="autoreset_mode 'later'"):
        ronap.VecNavEnv(2, autoreset_mode="later")
    with pytest.raises(ronap.ConfigError, match="render_mode 'human'"):
        ronap.VecNavEnv(2, render_mode="human")


def test_modes_are_in_the_metadata():
    assert ronap.VecNavEnv(2).metadata["autoreset_mode"] == AutoresetMode.NEXT_STEP
    assert ronap.VecNavEnv(2, autoreset_mode="SameStep").metadata["autoreset_mode"] == AutoresetMode.SAME_STEP
    assert ronap.VecNavEnv.metadata["autoreset_mode"] == AutoresetMode.NEXT_STEP


def test_make_vec_passes_max_episode_steps_as_the_episode_limit():
    import gymnasium as gym

    vec = gym.make_vec("ronap/Nav-v0", num_envs=2, vectorization_mode="vector_entry_point", max_episode_steps=5)
    assert vec.config["episode"]["max_steps"] == 5
    vec.reset(seed=0)
    for _ in range(5):
        _, _, terminated, truncated, info = vec.step(np.array([1, 1]))
    assert (terminated | truncated).all()
