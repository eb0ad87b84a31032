"""Several robots from Python: MultiNavEnv (PettingZoo ParallelEnv) and VecMultiNavEnv."""

import csv
import pathlib
import subprocess

import numpy as np
import pytest
from pettingzoo.test import parallel_api_test, parallel_seed_test

import ronap

ROOT = pathlib.Path(__file__).resolve().parents[3]
WAREHOUSE = ROOT / "scenarios" / "warehouse-team.toml"
CORRIDOR = ROOT / "scenarios" / "corridor-swap.toml"


def corridor(x0: float, x1: float, **fields):
    """Two robots in an 18 px corridor at x0 and x1, each heading for a point past the other."""
    scenario = {
        "scene": {"kind": "maze", "seed": 0},
        "maze": {"cols": 30, "rows": 1, "cell_px": 18.0},
        "episode": {"min_goal_distance_px": 10.0},
        "robots": [
            {"start": [x0, 9.0, 0.0], "goal": [525.0, 9.0]},
            {"start": [x1, 9.0, 180.0], "goal": [15.0, 9.0]},
        ],
    }
    return ronap.MultiNavEnv(scenario=scenario, **fields)


def test_parallel_api_test_passes():
    for path in (WAREHOUSE, CORRIDOR):
        env = ronap.MultiNavEnv(scenario=path)
        parallel_api_test(env, num_cycles=200)
    parallel_api_test(ronap.MultiNavEnv(scenario=WAREHOUSE, continuous=True), num_cycles=50)
    parallel_api_test(corridor(15.0, 100.0, team_message_size=2, team_neighbours=1), num_cycles=50)


def test_a_team_observes_a_history():
    """With ``observation_history=3`` each robot's observation is three frames (its neighbour
    slots in each) and two remembered actions, inside its space, the previous frame moving back a
    place at each step; the robot's newest remembered action is the one it took."""
    env = corridor(15.0, 100.0, team_message_size=1, team_neighbours=1, observation_history=3)
    parallel_api_test(env, num_cycles=30)
    obs, _ = env.reset(seed=0)
    space = env.observation_space("robot_0")
    frame = (space.shape[0] - 6) // 3
    first = obs["robot_0"]
    # At the start every past frame is the first, and no action is remembered.
    assert np.array_equal(first[frame : 2 * frame], first[:frame])
    assert np.array_equal(first[2 * frame : 3 * frame], first[:frame])
    assert not first[3 * frame :].any()
    obs, *_ = env.step({"robot_0": 1, "robot_1": 0})
    after = obs["robot_0"]
    assert space.contains(after)
    assert np.array_equal(after[frame : 2 * frame], first[:frame])
    assert np.array_equal(after[3 * frame : 3 * frame + 3], [0.0, 1.0, 0.0])


def test_seed_test_passes():
    parallel_seed_test(lambda: ronap.MultiNavEnv(scenario=WAREHOUSE), num_cycles=50)


def play(env, seed, steps=60):
    """Obs, rewards and flags of `steps` steps of a fixed action pattern from episode `seed`."""
    obs, _ = env.reset(seed=seed)
    trace = [np.concatenate([obs[a] for a in env.possible_agents])]
    t = 0
    while env.agents and t < steps:
        actions = {a: (t + k) % 3 for k, a in enumerate(env.agents)}
        obs, rew, term, trunc, _ = env.step(actions)
        trace.append(np.concatenate([obs[a] for a in sorted(obs)]))
        trace.append(np.array([rew[a] for a in sorted(rew)] + [term[a] for a in sorted(term)] + [trunc[a] for a in sorted(trunc)]))
        t += 1
    return trace


def test_same_seed_same_bits_and_other_seeds_differ():
    a = play(ronap.MultiNavEnv(scenario=WAREHOUSE), 4)
    b = play(ronap.MultiNavEnv(scenario=WAREHOUSE), 4)
    c = play(ronap.MultiNavEnv(scenario=WAREHOUSE), 5)
    assert len(a) == len(b) and all(np.array_equal(x, y) for x, y in zip(a, b))
    assert not np.array_equal(a[0], c[0])


def test_starts_are_those_of_ronap_run(ronap_bin, tmp_path):
    out = tmp_path / "run"
    subprocess.run(
        [ronap_bin, "run", "--scenario", str(WAREHOUSE), "--policy", "apf", "--seeds", "3", "--seed-start", "7", "--out", str(out)],
        check=True,
        capture_output=True,
    )
    rows = list(csv.DictReader(open(out / "robots.csv")))
    env = ronap.MultiNavEnv(scenario=WAREHOUSE)
    for seed in (7, 8, 9):
        _, infos = env.reset(seed=seed)
        for row in (r for r in rows if int(r["seed"]) == seed):
            x, y, heading = infos[f"robot_{row['robot']}"]["pose"]
            assert f"{x:.3f}" == row["start_x"] and f"{y:.3f}" == row["start_y"]
            assert f"{heading:.3f}" == row["start_heading_deg"]


def test_messages_arrive_a_step_late_and_only_within_range():
    env = corridor(15.0, 100.0, team_message_size=2, team_neighbours=1, team_comm_range_px=200.0)
    space = env.action_space("robot_0")
    assert set(space.spaces) == {"action", "message"}
    obs, infos = env.reset(seed=0)
    assert obs["robot_1"].shape == (18 + 4 + 2,)
    stand = {"action": None}
    obs, _, _, _, infos = env.step({"robot_0": {"action": 0, "message": np.array([7.0, 8.0], np.float32)}, "robot_1": stand})
    # Sent this step, heard after it: robot_1 sees robot_0's message, robot_0 hears robot_1's zeros.
    assert [m["from"] for m in env.inbox("robot_1")] == [0]
    np.testing.assert_array_equal(env.inbox("robot_1")[0]["message"], [7.0, 8.0])
    assert "inbox" not in infos["robot_1"]  # numbers only, unless text_infos=True
    np.testing.assert_array_equal(obs["robot_1"][-2:], [7.0, 8.0])
    assert obs["robot_1"][-3] == 1.0  # the slot is filled
    # Robot 0 is 85 px behind robot 1, which faces it: straight ahead in its frame, 85 / 200.
    assert obs["robot_1"][18] == pytest.approx(85.0 / 200.0, abs=1e-4)
    np.testing.assert_array_equal(obs["robot_0"][-2:], [0.0, 0.0])
    # Next step nothing new was sent by robot_0: robot_1 hears zeros.
    obs, _, _, _, infos = env.step({"robot_0": 1, "robot_1": 1})
    np.testing.assert_array_equal(obs["robot_1"][-2:], [0.0, 0.0])

    far = corridor(15.0, 100.0, team_message_size=2, team_neighbours=1, team_comm_range_px=50.0)
    far.reset(seed=0)
    obs, _, _, _, infos = far.step({"robot_0": {"action": 1, "message": np.array([7.0, 8.0], np.float32)}, "robot_1": 1})
    assert far.inbox("robot_1") == []
    np.testing.assert_array_equal(obs["robot_1"][18:], np.zeros(6, np.float32))


def test_corridor_swap_ends_as_a_deadlock_and_agents_leave():
    env = ronap.MultiNavEnv(scenario=CORRIDOR)
    env.reset(seed=0)
    steps = 0
    while env.agents:
        obs, rew, term, trunc, infos = env.step({a: 1 for a in env.agents})
        steps += 1
        assert steps < 1000
    assert all(trunc.values()) and not any(term.values())
    assert {env.status(a) for a in infos} == {"deadlock"}
    texts = ronap.MultiNavEnv(scenario=CORRIDOR, text_infos=True)
    texts.reset(seed=0)
    while texts.agents:
        *_, infos = texts.step({a: 1 for a in texts.agents})
    assert {i["status"] for i in infos.values()} == {"deadlock"}
    assert all(i["inbox"] == [] or isinstance(i["inbox"], list) for i in infos.values())
    assert env.step({}) == ({}, {}, {}, {}, {})  # all done: nothing left to step
    with pytest.raises(ronap.ActionError, match="every agent is done"):
        env.step({"robot_0": 1})


def test_render_draws_the_scene():
    env = ronap.MultiNavEnv(render_mode="rgb_array", scenario=WAREHOUSE, render_scale=0.5)
    env.reset(seed=1)
    img = env.render()
    assert img.dtype == np.uint8 and img.ndim == 3 and img.shape[2] == 3
    assert len(np.unique(img.reshape(-1, 3), axis=0)) > 8  # walls, floor and eight robot colours


def test_errors_name_what_was_wrong():
    with pytest.raises(ronap.ConfigError, match=r"\[\[robots\]\]"):
        ronap.MultiNavEnv()
    env = ronap.MultiNavEnv(scenario=WAREHOUSE)
    with pytest.raises(ronap.RonapError, match="before reset"):
        env._env.step([None] * 8)
    env.reset(seed=0)
    with pytest.raises(ronap.ActionError, match="robot_9"):
        env.step({"robot_9": 1})
    with pytest.raises(ronap.ActionError, match="robot_0"):
        env.step({"robot_0": 7})
    with pytest.raises(ronap.ActionError, match="robot_0"):
        env.step({"robot_0": 1.5})
    with pytest.raises(ronap.ConfigError, match="num_envs"):
        ronap.VecMultiNavEnv(0, scenario=WAREHOUSE)
    vec = ronap.VecMultiNavEnv(2, scenario=WAREHOUSE)
    with pytest.raises(ronap.RonapError, match="before reset"):
        vec.step(np.ones((2, 8), np.int64))
    vec.reset(0)
    with pytest.raises(ronap.ActionError, match="shape"):
        vec.step(np.ones((2, 7), np.int64))
    with pytest.raises(ronap.ActionError, match="environment 1, robot_3"):
        a = np.ones((2, 8), np.int64)
        a[1, 3] = 5
        vec.step(a)


def test_vector_form_plays_the_same_episodes_on_any_thread_count():
    n, steps = 3, 120
    runs = []
    for threads in (1, 2):
        vec = ronap.VecMultiNavEnv(n, scenario=CORRIDOR, threads=threads, episode_max_steps=50)
        obs, infos = vec.reset(seed=10)
        trace = [obs.copy()]
        for t in range(steps):
            actions = (np.arange(n * vec.num_agents).reshape(n, vec.num_agents) + t) % 3
            obs, rew, term, trunc, infos = vec.step(actions)
            trace += [obs.copy(), rew.copy(), term.copy(), trunc.copy(), infos["active"].copy(), infos["seed"].copy()]
        runs.append(trace)
    assert all(np.array_equal(x, y) for x, y in zip(*runs))
    assert obs.shape == (n, 2, 18) and rew.shape == (n, 2)
    # Episodes of 50 steps at most, restarted on the next step with seed + n.
    assert set(runs[0][-1]) <= {10, 11, 12, 13, 14, 15, 16, 17, 18}
    assert max(runs[0][-1]) >= 13

    # Environment 1's first episode is MultiNavEnv's seed 11, step for step.
    single = ronap.MultiNavEnv(scenario=CORRIDOR, episode_max_steps=50)
    obs1, _ = single.reset(seed=11)
    np.testing.assert_array_equal(runs[0][0][1], np.stack([obs1["robot_0"], obs1["robot_1"]]))
    for t in range(10):
        actions = (np.arange(n * 2).reshape(n, 2) + t) % 3
        o, r, _, _, _ = single.step({f"robot_{k}": int(actions[1, k]) for k in range(2)})
        np.testing.assert_array_equal(runs[0][1 + 6 * t][1], np.stack([o["robot_0"], o["robot_1"]]))
        np.testing.assert_array_equal(runs[0][2 + 6 * t][1], [r["robot_0"], r["robot_1"]])


JOINT = '''
import numpy as np

def act(obs):
    """Every robot AHEAD unless the beam straight ahead sees a wall close, then LEFT."""
    obs = np.asarray(obs)
    assert obs.ndim == 2
    return np.where(obs[:, 8] > 0.3, 1, 0)
'''


def test_evaluate_runs_a_team_with_the_team_planner():
    r = ronap.evaluate("coordinated", seeds=range(3), scenario=WAREHOUSE)
    assert r["team"]["team_success_rate"] == 1.0
    assert r["team"]["deadlocks"] == 0
    assert r["team"]["mean_makespan_ratio"] >= 1.0
    assert [e["seed"] for e in r["episodes"]] == [0, 1, 2]
    first = r["episodes"][0]
    assert first["outcome"] == "success" and len(first["robots"]) == 8
    assert all(x["lower_bound_steps"] <= x["arrived_at"] for x in first["robots"])
    mixed = {"robots": [{"count": 2}, {"policy": "geodesic"}]}
    with pytest.raises(ronap.ConfigError, match="robot 2: policy geodesic beside coordinated"):
        ronap.evaluate("coordinated", seeds=range(1), scenario=mixed)
    swap = ronap.evaluate("coordinated", seeds=range(2), scenario=CORRIDOR)
    assert swap["team"]["infeasible"] == 2
    assert swap["episodes"][0]["robots"][0]["reason"].startswith("robots 0 and 1 cannot pass each other")


def test_a_joint_callable_plays_the_episodes_of_ronap_run_batch(ronap_bin, tmp_path, monkeypatch):
    """A callable deciding for every robot at once ((robots, obs) in, one action per row out)
    plays the same team episodes as `ronap run --batch` with the same function."""
    (tmp_path / "joint.py").write_text(JOINT)
    monkeypatch.syspath_prepend(str(tmp_path))
    import joint

    ronap.evaluate(joint.act, seeds=range(4), scenario=WAREHOUSE, out=str(tmp_path / "py"))
    import os
    import sys

    subprocess.run(
        [ronap_bin, "run", "--scenario", str(WAREHOUSE), "--policy", f"py:{tmp_path / 'joint.py'}:act", "--batch", "1", "--seeds", "4", "--out", str(tmp_path / "cli")],
        check=True,
        capture_output=True,
        env={**os.environ, "RONAP_PYTHON": sys.executable},
    )
    assert (tmp_path / "py" / "episodes.csv").read_bytes() == (tmp_path / "cli" / "episodes.csv").read_bytes()
    py_rows = list(csv.DictReader(open(tmp_path / "py" / "robots.csv")))
    cli_rows = list(csv.DictReader(open(tmp_path / "cli" / "robots.csv")))
    assert len(py_rows) == 32
    for a, b in zip(py_rows, cli_rows):
        a.pop("policy"), b.pop("policy")  # `act` and `py:.../joint.py:act`
        assert a == b


def test_spaces_by_agent_and_a_vector_reset_without_a_seed():
    env = ronap.MultiNavEnv(scenario=WAREHOUSE)
    assert set(env.observation_spaces) == set(env.possible_agents) == set(env.action_spaces)
    assert env.observation_spaces["robot_0"] == env.observation_space("robot_0")
    vec = ronap.VecMultiNavEnv(2, scenario=WAREHOUSE)
    obs, _ = vec.reset(seed=None)
    assert obs.shape[:2] == (2, 8) and isinstance(vec.seed_used, int)
    again, _ = ronap.VecMultiNavEnv(2, scenario=WAREHOUSE).reset(seed=vec.seed_used)
    assert np.array_equal(obs, again)


def _team_episodes(mode, n=3, steps=120):
    """Every episode a VecMultiNavEnv in autoreset ``mode`` plays with every robot AHEAD: per
    seed, its steps' (rewards, terminated, truncated) rows and its last observations."""
    vec = ronap.VecMultiNavEnv(n, scenario=CORRIDOR, episode_max_steps=25, autoreset_mode=mode)
    assert vec.metadata["autoreset_mode"].name.lower() == mode
    obs, infos = vec.reset(seed=10)
    seed = infos["seed"].copy()
    played = {int(s): [] for s in seed}
    last = {}
    ahead = np.ones((n, vec.num_agents), np.int64)
    for _ in range(steps):
        obs, rew, term, trunc, infos = vec.step(ahead)
        ended = ~infos["active"].any(axis=1)
        for i in range(n):
            if infos["acted"][i].any():
                played[int(seed[i])].append((rew[i].tolist(), term[i].tolist(), trunc[i].tolist()))
            if mode == "same_step" and infos.get("_final_obs", np.zeros(n, bool))[i]:
                last[int(seed[i])] = infos["final_obs"][i]
            elif ended[i] and infos["acted"][i].any():
                last[int(seed[i])] = obs[i].copy()
        if mode == "disabled" and ended.any():
            with pytest.raises(ronap.RonapError, match="reset_mask"):
                vec.step(ahead)
            obs, infos = vec.reset(options={"reset_mask": ended})
        for i in np.flatnonzero(infos["reset"]):
            seed[i] = infos["seed"][i]
            played.setdefault(int(seed[i]), [])
    return {s: (p, last[s]) for s, p in played.items() if s in last}


def test_vector_teams_play_the_same_episodes_in_every_autoreset_mode():
    runs = {mode: _team_episodes(mode) for mode in ("next_step", "same_step", "disabled")}
    common = set.intersection(*(set(r) for r in runs.values()))
    assert len(common) >= 6
    for s in common:
        steps, last = runs["next_step"][s]
        for mode in ("same_step", "disabled"):
            assert runs[mode][s][0] == steps, (mode, s)
            np.testing.assert_array_equal(runs[mode][s][1], last)
    vec = ronap.VecMultiNavEnv(2, scenario=CORRIDOR, autoreset_mode="disabled")
    with pytest.raises(ronap.ConfigError, match="first reset"):
        vec.reset(options={"reset_mask": np.array([True, False])})
    with pytest.raises(ronap.ConfigError, match="only 'reset_mask'"):
        vec.reset(options={"mask": np.ones(2, bool)})
    with pytest.raises(ronap.ConfigError, match="autoreset_mode 'later'"):
        ronap.VecMultiNavEnv(2, scenario=CORRIDOR, autoreset_mode="later")


def test_a_vector_team_copy_replays_its_masked_resets():
    import copy

    vec = ronap.VecMultiNavEnv(2, scenario=CORRIDOR, episode_max_steps=5, autoreset_mode="disabled")
    vec.reset(seed=4)
    for _ in range(5):
        vec.step(np.ones((2, 2), np.int64))
    obs, infos = vec.reset(options={"reset_mask": np.array([True, False])})
    assert list(infos["seed"]) == [6, 5] and list(infos["reset"]) == [True, False]
    twin = copy.deepcopy(vec)
    with pytest.raises(ronap.RonapError, match="environment 1"):
        twin.step(np.ones((2, 2), np.int64))
    vec.reset(options={"reset_mask": np.array([False, True])})
    twin.reset(options={"reset_mask": np.array([False, True])})
    a = vec.step(np.ones((2, 2), np.int64))
    b = twin.step(np.ones((2, 2), np.int64))
    for x, y in zip(a[:4], b[:4]):
        np.testing.assert_array_equal(x, y)


def test_a_masked_reset_reports_only_its_environments_as_reset():
    vec = ronap.VecMultiNavEnv(2, scenario=CORRIDOR, episode_max_steps=3)
    vec.reset(seed=0)
    infos = {"reset": np.zeros(2, bool)}
    while not infos["reset"][0]:
        _, _, _, _, infos = vec.step(np.ones((2, 2), np.int64))
    # Environment 0 started its next episode in that step; a reset of environment 1 alone does
    # not report it again.
    _, infos = vec.reset(options={"reset_mask": np.array([False, True])})
    assert list(infos["reset"]) == [False, True]
    # A copy made before masked resets existed, its calls (actions, messages), still replays.
    state = vec.__getstate__()
    state["calls"] = [c[1:] for c in state["calls"] if c[0] == "step"]
    old = ronap.VecMultiNavEnv.__new__(ronap.VecMultiNavEnv)
    old.__setstate__(state)
    assert old._log.calls is not None and all(c[0] == "step" for c in old._log.calls)
