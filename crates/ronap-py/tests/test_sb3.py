"""ronap.sb3.VecEnv: an exact Stable-Baselines3 VecEnv, checked step by step against single
NavEnvs of the same seeds, through SB3's own wrappers, and with short PPO runs."""

import numpy as np
import pytest

import ronap

import stable_baselines3  # noqa: E402,F401  (crates/ronap-py/requirements-dev.txt installs it)
import ronap.sb3  # noqa: E402
from stable_baselines3.common.monitor import Monitor  # noqa: E402
from stable_baselines3.common.vec_env import VecCheckNan, VecMonitor, VecNormalize  # noqa: E402


def test_steps_equal_single_environments_with_sb3s_conventions():
    n = 3
    env = ronap.sb3.VecEnv(n, episode_max_steps=15)
    env.seed(100)
    obs = env.reset()
    singles = [ronap.NavEnv(episode_max_steps=15, split="train") for _ in range(n)]  # its default split
    next_seed = [100 + i for i in range(n)]
    for i, single in enumerate(singles):
        o, _ = single.reset(seed=next_seed[i])
        assert np.array_equal(obs[i], o)
        next_seed[i] += n
    ended = 0
    for t in range(50):
        actions = np.array([(t + i) % 3 for i in range(n)])
        obs, rewards, dones, infos = env.step(actions)
        assert rewards.dtype == np.float32 and dones.dtype == np.bool_
        for i, single in enumerate(singles):
            o, r, terminated, truncated, info = single.step(int(actions[i]))
            assert rewards[i] == np.float32(r)
            assert dones[i] == (terminated or truncated)
            if dones[i]:
                ended += 1
                final = infos[i]
                assert np.array_equal(final["terminal_observation"], o)
                assert final["TimeLimit.truncated"] == (truncated and not terminated)
                assert final["is_success"] == info["success"]
                assert final["episode"]["l"] == info["steps"]
                assert final["seed"] == info["seed"] and final["status"] == info["status"]
                o, _ = single.reset(seed=next_seed[i])
                next_seed[i] += n
            else:
                assert infos[i] == {}
            assert np.array_equal(obs[i], o)
    assert ended >= 6


def test_sb3_wrappers_and_a_short_ppo_run():
    from stable_baselines3 import PPO

    # VecMonitor is not needed (the VecEnv writes Monitor's info itself) and says so; it works.
    with pytest.warns(UserWarning, match="already wrapped with a `Monitor`"):
        env = VecMonitor(VecCheckNan(ronap.sb3.VecEnv(4, episode_max_steps=32), raise_exception=True))
    model = PPO("MlpPolicy", env, n_steps=64, batch_size=64, n_epochs=1, seed=0, device="cpu")
    model.learn(512)
    assert len(model.ep_info_buffer) > 0


def test_ppo_logs_episodes_without_a_monitor():
    from stable_baselines3 import PPO

    model = PPO("MlpPolicy", ronap.sb3.VecEnv(2, episode_max_steps=16), n_steps=32, batch_size=32, n_epochs=1, seed=0, device="cpu")
    model.learn(128)
    assert len(model.ep_info_buffer) > 0
    assert all(set(e) == {"r", "l", "t"} for e in model.ep_info_buffer)


def test_same_seed_same_training():
    from stable_baselines3 import PPO

    def train():
        env = ronap.sb3.VecEnv(2, episode_max_steps=16)
        model = PPO("MlpPolicy", env, n_steps=32, batch_size=32, n_epochs=1, seed=5, device="cpu")
        model.learn(128)
        return [p.detach().numpy().copy() for p in model.policy.parameters()]

    assert all(np.array_equal(a, b) for a, b in zip(train(), train()))


def test_attributes_images_and_wrappers():
    env = ronap.sb3.VecEnv(2, render_mode="rgb_array", maze_cols=4, maze_rows=4)
    assert env.get_attr("render_mode") == ["rgb_array", "rgb_array"]
    assert env.get_attr("continuous", indices=[1]) == [False]
    # It writes what a Monitor writes (info["episode"]), so it says it is wrapped by one.
    assert env.env_is_wrapped(Monitor) == [True, True]
    assert env.env_is_wrapped(VecNormalize) == [False, False]
    env.reset()
    images = env.get_images()
    assert len(images) == 2 and images[0].ndim == 3
    assert env.render(mode="rgb_array").ndim == 3
    continuous = ronap.sb3.VecEnv(2, continuous=True)
    continuous.reset()
    obs, *_ = continuous.step(np.zeros((2, 2), np.float32))
    assert obs.shape == (2, 18)
