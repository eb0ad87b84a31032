"""Seed splits: named, disjoint seed spaces in every entry point, training on the train split by
default, and a warning when an evaluation meets a network's training or validation seeds."""

from __future__ import annotations

import warnings
from pathlib import Path

import pytest

import ronap

ROOT = Path(__file__).resolve().parents[3]
DQN = f"mlp:{ROOT / 'policies' / 'dqn.safetensors'}"
WAREHOUSE = str(ROOT / "scenarios" / "warehouse-team.toml")


def test_split_seeds_count_from_the_splits_first_in_every_environment():
    for split, first in (("test", 0), ("validation", 500_000), ("train", 1_000_000)):
        _, info = ronap.NavEnv(split=split).reset(seed=7)
        assert info["seed"] == first + 7
        _, plain = ronap.NavEnv().reset(seed=first + 7)
        assert plain["pose"] == info["pose"]  # the same episode, named two ways
    vec = ronap.VecNavEnv(3, split="validation")
    _, infos = vec.reset(seed=10)
    assert list(infos["seed"]) == [500_010, 500_011, 500_012]
    multi = ronap.MultiNavEnv(scenario=WAREHOUSE, split="train")
    _, infos = multi.reset(seed=2)
    assert multi.seed_used == 1_000_002 and infos["robot_0"]["seed"] == 1_000_002
    team = ronap.VecMultiNavEnv(2, scenario=WAREHOUSE, split="train")
    _, infos = team.reset(3)
    assert list(infos["seed"]) == [1_000_003, 1_000_004]


def test_drawn_seeds_stay_in_the_split_and_bad_splits_are_named():
    env = ronap.NavEnv(split="validation")
    env.reset(seed=0)
    for _ in range(20):
        _, info = env.reset()
        assert 500_000 <= info["seed"] <= 999_999
    with pytest.raises(ValueError, match="dev"):
        ronap.NavEnv(split="dev")
    with pytest.raises(ronap.ConfigError, match=r"test split holds 500000 seeds"):
        ronap.NavEnv(split="test").reset(seed=500_000)
    with pytest.raises(ronap.ConfigError, match=r"seeds\[1\]"):
        ronap.evaluate("apf", [0, 600_000], split="test")


def test_sb3_training_plays_the_train_split_by_default():
    import ronap.sb3

    env = ronap.sb3.VecEnv(2)
    env.seed(0)  # as PPO(seed=0) does
    env.reset()
    assert [i["seed"] for i in env.reset_infos] == [1_000_000, 1_000_001]
    team = ronap.sb3.TeamVecEnv(1, scenario=WAREHOUSE)
    team.seed(0)
    team.reset()
    assert {i["seed"] for i in team.reset_infos} == {1_000_000}
    plain = ronap.sb3.VecEnv(2, split=None)
    plain.seed(0)
    plain.reset()
    assert [i["seed"] for i in plain.reset_infos] == [0, 1]


def test_evaluate_splits_and_warns_on_a_networks_own_seeds():
    result = ronap.evaluate("geodesic", range(3), split="validation")
    assert [e["seed"] for e in result["episodes"]] == [500_000, 500_001, 500_002]
    with pytest.warns(UserWarning, match="trained or chosen on"):
        ronap.evaluate(DQN, range(2), split="validation")
    with pytest.warns(UserWarning, match="trained or chosen on"):
        ronap.compare([DQN, "apf"], range(2), split="train")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        ronap.evaluate(DQN, range(2))  # the test split: held out
        ronap.evaluate(DQN, range(2), split="test")
