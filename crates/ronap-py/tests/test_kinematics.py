"""Robots as they are built, from Python: each kinematic model's spaces, Gymnasium's checker, the
vectorised and multi-agent environments, and the evaluator scaling each model's actions."""

from pathlib import Path

import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import ronap

SCENARIOS = Path(__file__).resolve().parents[3] / "scenarios"

MODELS = {
    "discrete": {},
    "unicycle": {},
    "diff_drive": {"robot_accel_max_px": 0.5, "robot_alpha_max_deg": 3.0, "robot_wheel_base_px": 8.0},
    "omni": {"robot_accel_max_px": 1.0, "robot_max_lateral_speed_px": 3.0},
    "ackermann": {"robot_wheel_base_px": 14.0, "robot_steer_rate_max_deg": 10.0},
}


@pytest.mark.parametrize("kind", sorted(MODELS))
@pytest.mark.parametrize("continuous", [False, True])
def test_every_model_passes_gymnasiums_checker(kind: str, continuous: bool) -> None:
    env = ronap.NavEnv(continuous=continuous, robot_kinematics=kind, **MODELS[kind])
    check_env(env, skip_render_check=True)
    size = 3 if kind == "omni" else 2
    assert env.action_scale.shape == (size,)
    if continuous:
        assert env.action_space.shape == (size,)
    env.reset(seed=1)
    for _ in range(50):
        *_, info = env.step(env.action_space.sample())
    assert info["steps"] == 50


def test_an_omni_base_moves_sideways_and_a_car_cannot_turn_on_the_spot() -> None:
    env = ronap.NavEnv(continuous=True, scenario=SCENARIOS / "omni-maze.toml")
    assert env.action_space.shape == (3,)
    np.testing.assert_array_equal(env.action_scale, [5.0, 3.0, 15.0])
    _, info = env.reset(seed=0)
    x0, y0, z0 = info["pose"]
    for _ in range(3):
        *_, info = env.step(np.array([0.0, 1.0, 0.0], np.float32))
    x, y, z = info["pose"]
    assert z == z0
    # Sideways: to the left of the heading, unless a wall was in the way.
    left = np.array([-np.sin(np.radians(z0)), np.cos(np.radians(z0))])
    moved = np.array([x - x0, y - y0])
    assert info["collisions"] > 0 or moved @ left > 3.0
    car = ronap.NavEnv(continuous=True, scenario=SCENARIOS / "warehouse-forklift.toml")
    _, info = car.reset(seed=0)
    pose = info["pose"]
    *_, info = car.step(np.array([0.0, 1.0], np.float32))
    assert info["pose"] == pose
    with pytest.raises(ronap.ActionError, match="two numbers"):
        car.step(np.zeros(3))


def test_vectorised_and_team_environments_take_each_models_actions() -> None:
    vec = ronap.VecNavEnv(4, continuous=True, scenario=SCENARIOS / "omni-maze.toml")
    assert vec.single_action_space.shape == (3,)
    vec.reset(seed=0)
    obs, *_ = vec.step(np.zeros((4, 3)))
    assert obs.shape[0] == 4
    with pytest.raises(ronap.ActionError, match=r"\(4, 3\)"):
        vec.step(np.zeros((4, 2)))
    team = ronap.MultiNavEnv(continuous=True, robot_kinematics="omni", scenario=SCENARIOS / "corridor-bay.toml")
    assert all(team.action_space(a).shape == (3,) for a in team.possible_agents)
    team.reset(seed=0)
    team.step({a: np.zeros(3, np.float32) for a in team.agents})


def test_the_evaluator_scales_a_cars_normalised_actions_as_the_environment_does() -> None:
    scenario = SCENARIOS / "warehouse-forklift.toml"

    def policy(obs: np.ndarray) -> np.ndarray:
        return np.array([1.0, 0.25 if obs[-1] < 0.5 else -0.25], np.float32)

    result = ronap.evaluate(policy, seeds=range(3), scenario=scenario, continuous=True)
    env = ronap.NavEnv(continuous=True, scenario=scenario)
    for row in result["episodes"]:
        obs, _ = env.reset(seed=row["seed"])
        steps, done = 0, False
        while not done:
            obs, _, terminated, truncated, info = env.step(policy(obs))
            steps += 1
            done = terminated or truncated
        assert steps == row["steps"], row
