"""Gymnasium environments over the Rust model."""

from __future__ import annotations

import json
from typing import Any, Mapping

import gymnasium as gym
import numpy as np
from gymnasium import spaces
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from . import _ronap
from .config import ScenarioLike, checked_config, checked_int

_SEED_LIMIT = 2**63


class NavEnv(gym.Env):
    """One RoNAP episode at a time.

    Observation: ``float32[beams + 1]``, the laser readings over their range and the goal
    direction over 360 (SPEC's 18 values by default). Actions: ``Discrete(3)`` (0 LEFT, 1 AHEAD,
    2 RIGHT), or with ``continuous=True`` ``Box(-1, 1, (2,))``: ``(v / v_max, w / w_max)``.
    ``terminated`` on success (and on collision with ``robot_on_collision="terminate"``, or at
    ``episode_reward_min``); ``truncated`` on time-out. ``info`` holds distance, collided,
    success, pose, goal, status, steps, collisions and the episode seed, and with moving
    obstacles ``dynamic_collisions`` (steps with contact between the robot and one, so far).

    The configuration: ``scenario`` (the path of a TOML scenario file, as ``ronap run
    --scenario`` takes, or a dict nested like one) gives the base and the scene, else the
    defaults; ``config`` (a nested or dotted dict) overrides it and keyword arguments
    ``section_field=value`` (``laser_beams=9``) override both; ``maze_seed`` (one maze or
    warehouse of that seed) and ``map`` (an image or ROS map file) override the scenario's
    ``[scene]``. A bad value raises ``ConfigError`` naming the field and value, and the file and
    line when a scenario file sets it.

    ``reset(seed=s)`` plays the episode of seed ``s`` (the same as ``ronap run`` seed ``s``);
    ``reset()`` draws the next episode seed from the environment's generator.
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": 30}

    def __init__(
        self,
        render_mode: str | None = None,
        *,
        scenario: ScenarioLike | None = None,
        config: Mapping[str, Any] | None = None,
        continuous: bool = False,
        maze_seed: int | None = None,
        map: str | None = None,
        render_view: str = "top",
        render_scale: float = 0.5,
        **fields: Any,
    ) -> None:
        if render_mode not in (None, "rgb_array"):
            raise _ronap.ConfigError(f"render_mode {render_mode!r}: expected None or 'rgb_array'")
        if render_view not in ("top", "first_person"):
            raise _ronap.ConfigError(f"render_view {render_view!r}: expected 'top' or 'first_person'")
        checked = checked_config(config, fields, scenario)
        self._env = _ronap.Env(checked, maze_seed, None if map is None else str(map), continuous)
        # What pickling needs to build this environment again (see __getstate__).
        self._init_args = dict(
            render_mode=render_mode,
            scenario=scenario,
            config=config,
            continuous=continuous,
            maze_seed=maze_seed,
            map=map,
            render_view=render_view,
            render_scale=render_scale,
            **fields,
        )
        self._episode: tuple[int, list[Any]] | None = None
        self.config = json.loads(checked.json)
        self.render_mode = render_mode
        self.render_view = render_view
        self.render_scale = render_scale
        n = self._env.observation_size
        self.observation_space = spaces.Box(0.0, 1.0, (n,), np.float32)
        self.continuous = continuous
        if continuous:
            # Normalised, as learning libraries expect: (1, 1) is (v_max, w_max).
            robot = self.config["robot"]
            self._action_scale = np.array([robot["max_linear_speed_px"], robot["max_angular_speed_deg"]], np.float64)
            self.action_space = spaces.Box(-1.0, 1.0, (2,), dtype=np.float32)
        else:
            self.action_space = spaces.Discrete(3)

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        if seed is not None:
            seed = checked_int("seed", seed)
        super().reset(seed=seed)
        episode_seed = seed if seed is not None else int(self.np_random.integers(0, _SEED_LIMIT))
        self._episode = (int(episode_seed), [])
        return self._env.reset(int(episode_seed))

    def step(self, action: Any) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        if isinstance(action, (bool, np.bool_)):
            raise _ronap.ActionError(f"action {action!r}: expected 0 (LEFT), 1 (AHEAD) or 2 (RIGHT), not a bool")
        if self.continuous:
            scaled = np.asarray(action, dtype=np.float64)
            if scaled.shape != (2,):
                raise _ronap.ActionError(f"action {action!r}: expected two numbers in [-1, 1]")
            action = (scaled * self._action_scale).tolist()
        result = self._env.step(action)
        if self._episode is not None:
            self._episode[1].append(action)
        return result

    def __getstate__(self) -> dict[str, Any]:
        """How to build this environment again and replay its episode so far: the model is
        deterministic, so the copy continues exactly where this one is (for Ray, multiprocessing
        and copy.deepcopy). A scenario given as a file is read again where the copy is made."""
        return {"init": self._init_args, "episode": self._episode, "np_random": self._np_random}

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.__init__(**state["init"])  # type: ignore[misc]
        self._np_random = state["np_random"]
        if state["episode"] is not None:
            seed, actions = state["episode"]
            self._env.reset(seed)
            for action in actions:
                self._env.step(action)
            self._episode = (seed, list(actions))

    def render(self) -> np.ndarray | None:  # type: ignore[override]
        if self.render_mode != "rgb_array":
            return None
        if self.render_view == "top":
            return self._env.render("top", self.render_scale)
        return self._env.render("first_person", 400.0)


class VecNavEnv(VectorEnv):
    """``num_envs`` RoNAP environments stepped together in Rust, across cores, with the GIL
    released; observations, rewards and flags come back as numpy arrays.

    Next-step autoreset: the step after an episode ends resets that environment (its action is
    ignored) and returns the new episode's first observation with reward 0. ``reset(seed=s)`` gives
    environment ``i`` the episode seeds ``s + i``, ``s + i + n``, ``s + i + 2n``, ...

    ``scenario``, ``config``, keyword arguments, ``maze_seed`` and ``map`` configure every
    environment as they do ``NavEnv``.
    """

    metadata = {"autoreset_mode": AutoresetMode.NEXT_STEP, "render_modes": []}

    def __init__(
        self,
        num_envs: int,
        *,
        scenario: ScenarioLike | None = None,
        config: Mapping[str, Any] | None = None,
        maze_seed: int | None = None,
        map: str | None = None,
        threads: int = 0,
        **fields: Any,
    ) -> None:
        num_envs = checked_int("num_envs", num_envs, least=1, below=2**31)
        threads = checked_int("threads", threads, below=2**16)
        checked = checked_config(config, fields, scenario)
        self.config = json.loads(checked.json)
        self._vec = _ronap.VecEnv(num_envs, checked, maze_seed, None if map is None else str(map), threads)
        self.num_envs = num_envs
        n = self._vec.observation_size
        self.single_observation_space = spaces.Box(0.0, 1.0, (n,), np.float32)
        self.single_action_space = spaces.Discrete(3)
        self.observation_space = batch_space(self.single_observation_space, num_envs)
        self.action_space = batch_space(self.single_action_space, num_envs)
        self._mask = np.ones(num_envs, dtype=bool)
        self._rng = np.random.default_rng()
        self._started = False

    def _infos(self, infos: dict[str, Any]) -> dict[str, Any]:
        for key in list(infos):
            infos["_" + key] = self._mask
        return infos

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        if seed is None:
            seed = int(self._rng.integers(0, _SEED_LIMIT))
        elif not isinstance(seed, (int, np.integer)):
            raise _ronap.ConfigError(f"seed {seed!r}: VecNavEnv takes one int (environment i gets seed + i)")
        else:
            seed = checked_int("seed", seed)
            self._rng = np.random.default_rng(seed)
        obs, infos = self._vec.reset(int(seed))
        self._started = True
        return obs, self._infos(infos)

    def step(self, actions: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        if not self._started:
            raise _ronap.RonapError("step() before reset(): call reset(seed=...) first")
        actions = discrete_actions(actions, (self.num_envs,))
        obs, rewards, terminated, truncated, infos = self._vec.step(actions)
        return obs, rewards, terminated, truncated, self._infos(infos)


def _shaped(actions: Any, shape: tuple[int, ...]) -> np.ndarray:
    """``actions`` as an array, refused (an ``ActionError`` naming a non-array value and its type)
    unless of ``shape``."""
    a = np.asarray(actions)
    if a.shape != shape:
        given = "" if isinstance(actions, np.ndarray) else f" {repr(actions)[:60]} ({type(actions).__name__})"
        raise _ronap.ActionError(f"actions{given} of shape {a.shape}: expected {shape}")
    return a


def discrete_actions(actions: Any, shape: tuple[int, ...]) -> np.ndarray:
    """``actions`` as a contiguous int64 array of ``shape``: integers, or whole floats; an
    ``ActionError`` names a wrong shape, dtype or fractional value (and where it is)."""
    a = _shaped(actions, shape)
    if a.dtype.kind not in "iuf":
        raise _ronap.ActionError(f"actions of dtype {a.dtype}: expected integers 0 (LEFT), 1 (AHEAD) or 2 (RIGHT)")
    if a.dtype.kind == "f":
        whole = (np.isfinite(a) & (a == np.round(a))).reshape(-1)
        if not np.all(whole):
            bad = int(np.argmin(whole))
            where = np.unravel_index(bad, shape)
            raise _ronap.ActionError(
                f"action {float(a.reshape(-1)[bad])} at {tuple(int(i) for i in where)}: expected 0 (LEFT), 1 (AHEAD) or 2 (RIGHT)"
            )
    return np.ascontiguousarray(a, dtype=np.int64)


def continuous_actions(actions: Any, shape: tuple[int, ...]) -> np.ndarray:
    """``actions`` as a contiguous float64 array of ``shape`` (normalised speeds in [-1, 1]); an
    ``ActionError`` names a wrong shape or dtype or a value that is not finite (and where it is)."""
    a = _shaped(actions, shape)
    if a.dtype.kind not in "iuf":
        raise _ronap.ActionError(f"actions of dtype {a.dtype}: expected numbers (v / v_max, w / w_max)")
    finite = np.isfinite(a).reshape(-1)
    if not np.all(finite):
        where = np.unravel_index(int(np.argmin(finite)), shape)
        raise _ronap.ActionError(f"action {float(a[where])} at {tuple(int(i) for i in where)}: expected finite numbers")
    return np.ascontiguousarray(a, dtype=np.float64)
