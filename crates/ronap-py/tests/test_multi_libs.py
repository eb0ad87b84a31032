"""The multi-agent route through the libraries users run: SuperSuit + SB3, ronap.sb3.TeamVecEnv,
torchrl's PettingZooWrapper; copies of every environment mid-episode; error classes."""

from __future__ import annotations

import copy
import pickle
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

import ronap

ROOT = Path(__file__).resolve().parents[3]
WAREHOUSE = str(ROOT / "scenarios" / "warehouse-team.toml")
HALL = str(ROOT / "scenarios" / "hall-robots.toml")
CORRIDOR = str(ROOT / "scenarios" / "corridor-swap.toml")


def _roll_multi(env: ronap.MultiNavEnv, actions: list[dict[str, int]]) -> list[tuple]:
    out = []
    for a in actions:
        if not env.agents:
            break
        obs, rew, term, trunc, infos = env.step({k: v for k, v in a.items() if k in env.agents})
        out.append((sorted(obs), [obs[k].tobytes() for k in sorted(obs)], sorted(rew.items()), sorted(term.items()), sorted(infos)))
    return out


@pytest.mark.parametrize("how", ["pickle", "deepcopy"])
def test_multi_env_copies_continue_identically_mid_episode(how):
    env = ronap.MultiNavEnv(scenario=WAREHOUSE)
    env.reset(seed=3)
    rng = np.random.default_rng(0)
    _roll_multi(env, [{a: int(rng.integers(3)) for a in env.possible_agents} for _ in range(40)])
    twin = pickle.loads(pickle.dumps(env)) if how == "pickle" else copy.deepcopy(env)
    assert twin.agents == env.agents and twin.seed_used == env.seed_used
    np.testing.assert_array_equal(twin.state(), env.state())
    later = [{a: int(rng.integers(3)) for a in env.possible_agents} for _ in range(120)]
    assert _roll_multi(twin, later) == _roll_multi(env, later)


def test_vector_envs_copy_mid_run():
    rng = np.random.default_rng(1)
    vec = ronap.VecNavEnv(3, maze_cols=5, maze_rows=5)
    vec.reset(seed=11)
    for _ in range(250):  # past several autoresets
        vec.step(rng.integers(0, 3, 3))
    twin = pickle.loads(pickle.dumps(vec))
    actions = [rng.integers(0, 3, 3) for _ in range(200)]
    assert [twin.step(a)[0].tobytes() for a in actions] == [vec.step(a)[0].tobytes() for a in actions]

    team = ronap.VecMultiNavEnv(2, scenario=WAREHOUSE)
    team.reset(5)
    for _ in range(30):
        team.step(rng.integers(0, 3, (2, 8)))
    twin_team = copy.deepcopy(team)
    actions = [rng.integers(0, 3, (2, 8)) for _ in range(60)]
    assert [twin_team.step(a)[1].tobytes() for a in actions] == [team.step(a)[1].tobytes() for a in actions]


# Long enough for every team episode to end at least once (2 envs x robots slots a step): the
# step after the last robot is done is where SuperSuit's wrappers restart it.
@pytest.mark.parametrize("scenario,limit,steps", [(WAREHOUSE, 80, 2048), (HALL, 10, 2400)])
def test_supersuit_parameter_sharing_recipe_trains_ppo(scenario, limit, steps):
    ss = pytest.importorskip("supersuit")
    from stable_baselines3 import PPO

    env = ronap.MultiNavEnv(scenario=scenario, episode_max_steps=limit)
    env = ss.black_death_v3(env)  # robots finish at different times
    env = ss.pettingzoo_env_to_vec_env_v1(env)
    env = ss.concat_vec_envs_v1(env, 2, num_cpus=0, base_class="stable_baselines3")
    model = PPO("MlpPolicy", env, n_steps=16, batch_size=64, n_epochs=1, verbose=0)
    model.learn(steps)
    assert model.num_timesteps >= steps


def test_team_vec_env_closes_each_robots_episode_and_its_wait():
    from stable_baselines3 import PPO
    from stable_baselines3.common.evaluation import evaluate_policy

    import ronap.sb3

    env = ronap.sb3.TeamVecEnv(3, scenario=WAREHOUSE, episode_max_steps=60)
    assert env.num_envs == 3 * 8
    env.seed(4)
    obs = env.reset()
    assert obs.shape == (24, 18)
    team = ronap.MultiNavEnv(scenario=WAREHOUSE, episode_max_steps=60, split="train")
    team.reset(seed=5)  # team episode 1 of env.seed(4): seed 4 + 1
    np.testing.assert_array_equal(obs[8:16], np.stack([team.state()[k * 18 : (k + 1) * 18] for k in range(8)]))
    rng = np.random.default_rng(2)
    episodes = waits_closed = 0
    waiting = np.zeros(24, bool)
    for _ in range(200):
        obs, rewards, dones, infos = env.step(rng.integers(0, 3, 24))
        for i, info in enumerate(infos):
            if waiting[i]:
                assert rewards[i] == 0.0 and info.get("waiting")
            if dones[i] and "episode" in info:
                episodes += 1
                assert not waiting[i] and info["terminal_observation"].shape == (18,)
                assert info["episode"]["l"] <= 60 and "is_success" in info
                assert not obs[i].any()  # the wait begins
                waiting[i] = True
            elif dones[i]:
                assert waiting[i] and info["waiting"]  # the wait ends: a new team episode
                waits_closed += 1
                waiting[i] = False
    assert episodes >= 24 and waits_closed >= 24
    model = PPO("MlpPolicy", env, n_steps=16, batch_size=96, n_epochs=1, seed=0, verbose=0).learn(800)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no "not wrapped with a Monitor" warning
        mean, _ = evaluate_policy(model, env, n_eval_episodes=8)
    assert np.isfinite(mean)


def test_torchrl_pettingzoo_wrapper_constructs_and_rolls_out():
    pytest.importorskip("torchrl")
    from torchrl.envs.libs.pettingzoo import PettingZooWrapper

    env = PettingZooWrapper(
        ronap.MultiNavEnv(scenario=WAREHOUSE, episode_max_steps=30),
        return_state=True,
        use_mask=True,
        categorical_actions=True,
        seed=0,
    )
    td = env.rollout(40, break_when_any_done=False)
    assert td["robot", "observation"].shape == (40, 8, 18)
    assert td["state"].shape == (40, 8 * 18)
    assert td["next", "robot", "info", "success"].shape == (40, 8)
    assert bool(td["next", "robot", "done"].any())


def test_mappo_example_runs():
    pytest.importorskip("torchrl")
    script = ROOT / "examples" / "mappo_torchrl.py"
    out = subprocess.run(
        [sys.executable, str(script), "--scenario", WAREHOUSE, "--iterations", "2", "--steps", "60", "--max-steps", "40"],
        capture_output=True, text=True, timeout=300, check=True,
    ).stdout
    assert out.count("iteration") == 2 and "robots done" in out


def test_error_classes_subclass_the_builtins(tmp_path):
    with pytest.raises(ValueError, match="laser.beams"):
        ronap.NavEnv(laser_beams=-3)
    with pytest.raises(ValueError):
        env = ronap.NavEnv()
        env.reset(seed=0)
        env.step(7)
    for kwargs in ({"scenario": tmp_path / "nope.toml"}, {"map": tmp_path / "nope.png"}):
        with pytest.raises(FileNotFoundError) as caught:
            ronap.NavEnv(**kwargs)
        assert isinstance(caught.value, ronap.ConfigError)
        assert caught.value.filename == str(next(iter(kwargs.values())))
        assert "nope" in str(caught.value) and "no such file" in str(caught.value)
        assert pickle.loads(pickle.dumps(caught.value)).filename == caught.value.filename


def test_thread_safe_is_refused_for_sb3_models():
    from stable_baselines3 import PPO

    import ronap.sb3

    model = PPO("MlpPolicy", ronap.sb3.VecEnv(2, maze_cols=4, maze_rows=4), n_steps=8, batch_size=16)
    for policy in (model.predict, lambda obs: model.predict(obs, deterministic=True)[0]):
        with pytest.raises(ronap.ConfigError, match="Stable-Baselines3"):
            ronap.evaluate(policy, range(2), thread_safe=True, maze_cols=4, maze_rows=4)
    ronap.evaluate(lambda obs: model.predict(obs, deterministic=True)[0], range(2), maze_cols=4, maze_rows=4)


def test_spec_max_episode_steps_is_the_environments_limit():
    import gymnasium as gym

    assert ronap.NavEnv(episode_max_steps=300).spec.max_episode_steps == 300
    made = gym.make("ronap/Nav-v0", episode_max_steps=400)
    assert made.spec.max_episode_steps == 400
    assert gym.make(ronap.NavEnv(episode_max_steps=250).spec).spec.max_episode_steps == 250


def test_one_vocabulary_across_infos_and_results():
    keys = {"seed", "steps", "collisions", "return", "success", "distance", "pose", "goal", "collided"}
    env = ronap.NavEnv(episode_max_steps=5)
    _, info = env.reset(seed=4)
    total = 0.0
    for _ in range(5):
        _, reward, *_, info = env.step(1)
        total += reward
    assert keys <= set(info) and info["status"] == "timeout"
    assert info["return"] == pytest.approx(total)
    vec = ronap.VecNavEnv(2, episode_max_steps=5)
    vec.reset(seed=4)
    _, _, _, _, infos = vec.step(np.ones(2, int))
    assert keys <= set(infos) and infos["return"] is infos["total_reward"]
    row = ronap.evaluate(lambda obs: 1, [4], episode_max_steps=5)["episodes"][0]
    assert {"seed", "steps", "collisions", "return", "outcome"} <= set(row)
    assert row["return"] == pytest.approx(info["return"]) and row["outcome"] == info["status"]
    multi = ronap.MultiNavEnv(scenario=WAREHOUSE)
    _, infos = multi.reset(seed=0)
    assert keys <= set(infos["robot_0"]) and multi.status("robot_0") == "running"


def test_gymnasiums_own_vector_envs_play_vecnavenvs_episodes_with_seed_step():
    import gymnasium as gym

    n = 3
    ours = ronap.VecNavEnv(n, episode_max_steps=12, maze_cols=4, maze_rows=4)
    theirs = gym.make_vec("ronap/Nav-v0", num_envs=n, vectorization_mode="sync", seed_step=n, episode_max_steps=12, maze_cols=4, maze_rows=4)
    a, _ = ours.reset(seed=20)
    b, _ = theirs.reset(seed=20)
    np.testing.assert_array_equal(a, b)
    rng = np.random.default_rng(3)
    seeds_seen = set()
    for _ in range(60):  # several autoresets each
        actions = rng.integers(0, 3, n)
        a, ra, ta, tra, ia = ours.step(actions)
        b, rb, tb, trb, ib = theirs.step(actions)
        np.testing.assert_array_equal(a, b)
        np.testing.assert_array_equal(ra, rb)
        seeds_seen.update(int(s) for s in ia["seed"])
        assert list(ia["seed"]) == list(ib["seed"])
    assert len(seeds_seen) > 2 * n


def test_copies_hold_their_own_actions_and_vector_seeds_stay_in_their_split():
    vec = ronap.VecNavEnv(2, maze_cols=4, maze_rows=4)
    vec.reset(seed=1)
    buffer = np.zeros(2, np.int64)
    for t in range(40):
        buffer[:] = (t % 3, (t + 1) % 3)  # one buffer, rewritten each step, as loops do
        vec.step(buffer)
    twin = copy.deepcopy(vec)
    buffer[:] = (1, 1)
    np.testing.assert_array_equal(twin.step(buffer)[0], vec.step(buffer)[0])
    near_end = ronap.VecNavEnv(2, split="validation", episode_max_steps=3)
    near_end.reset(seed=499_998)
    with pytest.raises(ronap.ConfigError, match="past the validation split"):
        for _ in range(10):
            near_end.step(np.ones(2, int))
    # A copy keeps the spec gymnasium.make gave (its flags, not a default one).
    import gymnasium as gym

    made = pickle.loads(pickle.dumps(gym.make("ronap/Nav-v0", episode_max_steps=50, disable_env_checker=True).unwrapped))
    assert made.spec.disable_env_checker is True and made.spec.max_episode_steps == 50


def test_a_vector_copy_is_refused_past_its_record_and_allowed_again_after_a_reset(monkeypatch):
    """A vector environment keeps the actions since its last full reset for copies to replay, a
    byte per discrete action, up to ``COPY_BYTES``: past it a copy is refused, by name, until the
    next reset(). A copy made before actions were kept as bytes (int64) still replays."""
    import ronap.env

    # Room for the reset and ten steps: VecNavEnv keeps its reset's seeds (8 bytes each),
    # VecMultiNavEnv only its seed.
    for vec, actions, reset_bytes in [
        (ronap.VecNavEnv(4, maze_cols=4, maze_rows=4), np.ones(4, np.int64), 32),
        (ronap.VecMultiNavEnv(2, scenario=CORRIDOR), np.ones((2, 2), np.int64), 0),
    ]:
        monkeypatch.setattr(ronap.env, "COPY_BYTES", reset_bytes + 10 * actions.size)
        vec.reset(seed=3)
        for _ in range(10):  # a byte an action
            vec.step(actions)
        twin = copy.deepcopy(vec)
        np.testing.assert_array_equal(twin.step(actions)[0], vec.step(actions)[0])
        with pytest.raises(ronap.RonapError, match=f"cannot copy a {type(vec).__name__} more than"):
            copy.deepcopy(vec)
        vec.reset(seed=4)
        vec.step(actions)
        twin = copy.deepcopy(vec)
        np.testing.assert_array_equal(twin.step(actions)[0], vec.step(actions)[0])
    # An older copy's int64 actions replay, and are kept as bytes from then on.
    monkeypatch.setattr(ronap.env, "COPY_BYTES", 2**20)
    vec = ronap.VecNavEnv(4, maze_cols=4, maze_rows=4)
    vec.reset(seed=5)
    for t in range(30):
        vec.step(np.array([t % 3, 1, 2, (t + 1) % 3]))
    state = vec.__getstate__()
    state["calls"] = [(k, a.astype(np.int64) if k == "step" else a, b) for k, a, b in state["calls"]]
    old = ronap.VecNavEnv.__new__(ronap.VecNavEnv)
    old.__setstate__(state)
    assert all(a.dtype == np.int8 for k, a, _ in old._log.calls if k == "step")
    np.testing.assert_array_equal(old.step(np.ones(4, np.int64))[0], vec.step(np.ones(4, np.int64))[0])
    # Continuous actions are kept whole (4 environments x 2 float64 a step): one step is past
    # room for ten discrete ones.
    monkeypatch.setattr(ronap.env, "COPY_BYTES", 32 + 40)
    vec = ronap.VecNavEnv(4, maze_cols=4, maze_rows=4, continuous=True)
    vec.reset(seed=3)
    vec.step(np.full((4, 2), 0.5))
    with pytest.raises(ronap.RonapError, match="cannot copy"):
        copy.deepcopy(vec)
