"""Gymnasium environments over the Rust model."""

from __future__ import annotations

import dataclasses
import json
from typing import Any, Mapping

import gymnasium as gym
import numpy as np
from gymnasium import spaces
from gymnasium.envs.registration import EnvSpec
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from . import _ronap
from .config import ScenarioLike, checked_config, checked_path, checked_int, init_arguments, located, checked_split, split_draw_limit, split_seed, check_split_seeds, COPY_BYTES, COPY_LIMIT


class NavEnv(gym.Env[np.ndarray, Any]):
    """One RoNAP episode at a time.

    Observation: ``float32[beams + 1]``, the laser readings over their range and the goal
    direction over 360 (the model's 18 values by default, docs/model.md); with ``observation_history=k`` the last
    ``k`` of those frames, newest first, then the last ``k - 1`` actions as three values each
    (one-hot LEFT, AHEAD, RIGHT), all in [0, 1]. Actions: ``Discrete(3)`` (0 LEFT, 1 AHEAD,
    2 RIGHT), or with ``continuous=True`` ``Box(-1, 1, (2,))``: ``(v / v_max, w / w_max)``
    (``robot_kinematics="omni"``: ``Box(-1, 1, (3,))``, ``(vx / v_max, vy / vy_max, w / w_max)``;
    ``"ackermann"``: ``(v / v_max, steer / steer_max)``; ``action_scale`` holds the full values).
    Rewards: the model's four terms; with ``reward_shaping="geodesic"`` the straight-line progress
    term becomes potential-based shaping along the geodesic distance (discount
    ``reward_shaping_gamma``, 0.99 by default: set it to your algorithm's).
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
    ``reset()`` draws the next episode seed from the environment's generator. With
    ``split="train"`` (or ``"validation"``, ``"test"``) seeds count from that split's first
    (``reset(seed=0)`` of the train split is episode seed 1000000, as ``ronap run --split train``
    plays it) and drawn seeds stay in it; ``info["seed"]`` is the episode's own seed. With
    ``seed_step=n``, ``reset()`` after ``reset(seed=s)`` plays ``s + n``, ``s + 2n``, ... instead
    of drawing: ``gymnasium.make_vec("ronap/Nav-v0", num_envs=n, vectorization_mode="sync",
    seed_step=n)`` (or an ``AsyncVectorEnv``) then plays the very episodes ``VecNavEnv(n)`` plays.

    The episode limit is ``episode_max_steps`` (default 2000), after which ``truncated`` is
    true and ``info["status"]`` is "timeout". ``gymnasium.make("ronap/Nav-v0",
    max_episode_steps=N)`` wraps Gymnasium's ``TimeLimit`` around it instead, which truncates at
    N without the environment knowing (``info["status"]`` stays "running"): give
    ``episode_max_steps=N`` to make N the environment's own limit.
    """

    metadata: dict[str, Any] = {"render_modes": ["rgb_array"], "render_fps": 30}
    observation_space: spaces.Space[Any]
    action_space: spaces.Space[Any]
    config: dict[str, Any]
    continuous: bool
    render_mode: str | None

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
        split: str | None = None,
        seed_step: int | None = None,
        **fields: Any,
    ) -> None:
        # What pickling needs to build this object again (see __getstate__).
        self._init_args = init_arguments(locals())
        if render_mode not in (None, "rgb_array"):
            raise _ronap.ConfigError(f"render_mode {render_mode!r}: expected None or 'rgb_array'")
        if render_view not in ("top", "first_person"):
            raise _ronap.ConfigError(f"render_view {render_view!r}: expected 'top' or 'first_person'")
        self.split: str | None = checked_split(split)
        self.seed_step: int | None = None if seed_step is None else checked_int("seed_step", seed_step, least=1)
        self._index: int | None = None
        checked = checked_config(config, fields, scenario)
        self._checked = checked
        self._env = _ronap.Env(checked, maze_seed=maze_seed, map_path=checked_path("map", map), continuous=continuous)
        self._episode: tuple[int, list[Any]] | None = None
        self.config = json.loads(checked.json)
        self.render_mode = render_mode
        self.render_view = render_view
        self.render_scale = render_scale
        n = self._env.observation_size
        self.observation_space = spaces.Box(0.0, 1.0, (n,), np.float32)
        self.continuous = continuous
        #: The full value of each dimension of a continuous action: ``(v_max, w_max)``, or the
        #: omnidirectional ``(v_max, vy_max, w_max)`` and car-like ``(v_max, steer_max)``.
        self.action_scale: np.ndarray = np.array(self._env.action_scale, np.float64)
        if continuous:
            # Normalised, as learning libraries expect: (1, 1) is (v_max, w_max).
            self._action_scale = self.action_scale
            self.action_space = spaces.Box(-1.0, 1.0, self.action_scale.shape, dtype=np.float32)
        else:
            self.action_space = spaces.Discrete(3)

    @property  # type: ignore[override]
    def spec(self) -> EnvSpec:
        """Gymnasium's ``EnvSpec`` of this environment: the one ``gymnasium.make`` gave, else
        ``ronap/Nav-v0`` with these arguments; ``max_episode_steps`` is the environment's own
        limit, ``episode_max_steps``."""
        given = self.__dict__.get("_spec")
        limit = int(self.config["episode"]["max_steps"])
        if given is None:
            kwargs = {k: v for k, v in self._init_args.items() if k != "render_mode"}
            return EnvSpec("ronap/Nav-v0", entry_point="ronap.env:NavEnv", vector_entry_point="ronap.env:VecNavEnv", max_episode_steps=limit, kwargs=kwargs)
        return dataclasses.replace(given, max_episode_steps=limit)

    @spec.setter
    def spec(self, value: EnvSpec | None) -> None:
        self.__dict__["_spec"] = value

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        if seed is not None:
            seed = checked_int("seed", seed)
        super().reset(seed=seed)
        if seed is not None:
            index = seed
        elif self.seed_step is not None and self._index is not None:
            index = self._index + self.seed_step
        else:
            index = int(self.np_random.integers(0, split_draw_limit(self.split)))
        name = "seed" if seed is not None else f"the next seed by seed_step ({self.seed_step}), index"
        episode_seed = split_seed(self.split, index, name)
        self._index = index
        self._episode = (int(episode_seed), [])
        try:
            return self._env.reset(int(episode_seed))
        except _ronap.SceneError as e:
            raise located(e, self._checked) from None

    def step(self, action: Any) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        if isinstance(action, (bool, np.bool_)):
            raise _ronap.ActionError(f"action {action!r}: expected 0 (LEFT), 1 (AHEAD) or 2 (RIGHT), not a bool")
        if self.continuous:
            scaled = np.asarray(action, dtype=np.float64)
            if scaled.shape != self._action_scale.shape:
                size = self._action_scale.shape[0]
                raise _ronap.ActionError(f"action {action!r}: expected {'two' if size == 2 else size} numbers in [-1, 1]")
            action = (scaled * self._action_scale).tolist()
        result = self._env.step(action)
        if self._episode is not None:
            self._episode[1].append(action)
        return result

    def __getstate__(self) -> dict[str, Any]:
        """How to build this environment again and replay its episode so far: the model is
        deterministic, so the copy continues exactly where this one is (for Ray, multiprocessing
        and copy.deepcopy). A scenario given as a file is read again where the copy is made."""
        return {
            "init": self._init_args,
            "episode": self._episode,
            "np_random": self._np_random,
            "index": self._index,
            "spec": self.__dict__.get("_spec"),
        }

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.__init__(**state["init"])  # type: ignore[misc]
        self._np_random = state["np_random"]
        self._index = state.get("index")
        self.__dict__["_spec"] = state.get("spec")
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


_AUTORESET = {
    AutoresetMode.NEXT_STEP: "next_step",
    AutoresetMode.SAME_STEP: "same_step",
    AutoresetMode.DISABLED: "disabled",
}


def _autoreset_mode(mode: AutoresetMode | str) -> AutoresetMode:
    """``mode`` as an ``AutoresetMode``: the enum, its value ("NextStep") or its name in any case
    ("next_step", "SAME_STEP")."""
    if isinstance(mode, AutoresetMode):
        return mode
    for m in AutoresetMode:
        if isinstance(mode, str) and mode in (m.value, m.name, m.name.lower()):
            return m
    raise _ronap.ConfigError(f"autoreset_mode {mode!r}: expected 'next_step', 'same_step' or 'disabled' (or a gymnasium AutoresetMode)")


def reset_mask(owner: str, options: dict[str, Any] | None, num_envs: int, started: bool) -> np.ndarray | None:
    """The ``reset_mask`` of a vector environment's ``reset(options=...)``, checked: ``num_envs``
    bools, and every environment on the first reset (``owner`` names the class in errors)."""
    if not options:
        return None
    unknown = sorted(set(options) - {"reset_mask"})
    if unknown:
        raise _ronap.ConfigError(f"options {unknown}: {owner} takes only 'reset_mask'")
    if "reset_mask" not in options:
        return None
    mask = np.asarray(options["reset_mask"])
    if mask.dtype != np.bool_ or mask.shape != (num_envs,):
        raise _ronap.ConfigError(f"reset_mask of dtype {mask.dtype} and shape {mask.shape}: expected {num_envs} bools")
    if not started and not mask.all():
        raise _ronap.ConfigError("reset_mask: the first reset() starts every environment")
    return mask


class CallLog:
    """The calls since a vector environment's last full reset, for a copy to replay (the model is
    deterministic): each ``(kind, array or flags, array or None)``. ``calls`` is None once more
    than ``COPY_LIMIT`` calls or ``COPY_BYTES`` bytes of their arrays would be kept."""

    def __init__(self, calls: Any = ()) -> None:
        self.calls: list[tuple[str, Any, Any]] | None = []
        self._bytes = 0
        for call in calls:
            self.keep(call)

    def keep(self, call: tuple[str, Any, Any]) -> None:
        calls = self.calls
        if calls is None:
            return
        # Once a step, so spelt out (a generator over the call took twice as long).
        size = self._bytes + _kept_bytes(call[1]) + _kept_bytes(call[2])
        if len(calls) >= COPY_LIMIT or size > COPY_BYTES:
            self.calls = None
            return
        calls.append(call)
        self._bytes = size


def _kept_bytes(x: Any) -> int:
    """What a ``CallLog`` counts for one of a call's values: an array by its bytes, a reset's
    seeds or flags (a list) at 8 bytes an entry, None as nothing."""
    return int(x.nbytes) if isinstance(x, np.ndarray) else 8 * len(x) if isinstance(x, list) else 0


def kept_actions(a: np.ndarray) -> np.ndarray:
    """A copy of the actions a step took, to replay: discrete ones (0, 1, 2) as bytes, an eighth
    of their int64 size (an older copy's int64 ones too, once replayed)."""
    return a.astype(np.int8) if a.dtype.kind in "iu" else a.copy()


def copy_refused(cls: str) -> _ronap.RonapError:
    return _ronap.RonapError(
        f"cannot copy a {cls} more than {COPY_LIMIT} steps or {COPY_BYTES >> 20} MiB of actions and resets after its last "
        "reset() of every environment: a copy replays them, and so many are not kept; reset() first"
    )


class VecNavEnv(VectorEnv[np.ndarray, Any, np.ndarray]):
    """``num_envs`` RoNAP environments stepped together in Rust, across cores, with the GIL
    released; observations, rewards and flags come back as numpy arrays.

    Seeds: ``reset(seed=s)`` gives environment ``i`` the episode seeds ``s + i``, ``s + i + n``,
    ``s + i + 2n``, ... (``n`` environments); ``reset(seed=[s0, s1, ...])`` starts environment
    ``i`` at ``s_i`` (then ``s_i + n``, ...), ``None`` in the list meaning its next seed;
    ``reset()`` draws the base seed from the vector environment's generator. ``split=`` counts
    these seeds from a split's first, as ``NavEnv`` does.
    ``reset(options={"reset_mask": mask})`` restarts only the environments ``mask`` selects, each
    with its next seed unless ``seed`` gives one.

    ``autoreset_mode`` (Gymnasium's ``AutoresetMode`` or "next_step", "same_step", "disabled"):
    next-step (default) resets an environment on the step after its episode ends (that step's
    action is ignored, its reward 0); same-step resets it within the ending step and puts the last
    observation and info in ``infos["final_obs"]`` and ``infos["final_info"]``; disabled leaves it
    to ``reset_mask`` (stepping an ended environment raises ``RonapError``). Every mode plays
    the same episodes.

    Actions: one of 0 (LEFT), 1 (AHEAD), 2 (RIGHT) per environment, or with ``continuous=True``
    an ``(n, 2)`` array of ``(v / v_max, w / w_max)`` in [-1, 1]. Infos, one array entry per
    environment: distance, collided, success, pose, goal, status, steps, collisions, seed (and
    dynamic_collisions with moving obstacles). ``render_mode="rgb_array"``: ``render()`` returns
    one picture per environment, as ``NavEnv`` draws it.

    ``scenario``, ``config``, keyword arguments, ``maze_seed`` and ``map`` configure every
    environment as they do ``NavEnv``; ``max_episode_steps`` (as ``gymnasium.make_vec`` passes
    it) sets ``episode_max_steps``.
    """

    metadata: dict[str, Any] = {"autoreset_mode": AutoresetMode.NEXT_STEP, "render_modes": ["rgb_array"], "render_fps": 30}
    observation_space: spaces.Space[Any]
    action_space: spaces.Space[Any]
    single_observation_space: spaces.Space[Any]
    single_action_space: spaces.Space[Any]
    config: dict[str, Any]
    num_envs: int
    continuous: bool
    render_mode: str | None

    def __init__(
        self,
        num_envs: int,
        *,
        scenario: ScenarioLike | None = None,
        config: Mapping[str, Any] | None = None,
        maze_seed: int | None = None,
        map: str | None = None,
        threads: int = 0,
        continuous: bool = False,
        autoreset_mode: AutoresetMode | str = AutoresetMode.NEXT_STEP,
        render_mode: str | None = None,
        render_view: str = "top",
        render_scale: float = 0.5,
        max_episode_steps: int | None = None,
        split: str | None = None,
        **fields: Any,
    ) -> None:
        # What pickling needs to build this object again (see __getstate__).
        self._init_args = init_arguments(locals())
        num_envs = checked_int("num_envs", num_envs, least=1, below=2**31)
        self.split: str | None = checked_split(split)
        threads = checked_int("threads", threads, below=2**16)
        mode = _autoreset_mode(autoreset_mode)
        if render_mode not in (None, "rgb_array"):
            raise _ronap.ConfigError(f"render_mode {render_mode!r}: expected None or 'rgb_array'")
        if render_view not in ("top", "first_person"):
            raise _ronap.ConfigError(f"render_view {render_view!r}: expected 'top' or 'first_person'")
        if max_episode_steps is not None:
            fields = {**fields, "episode_max_steps": max_episode_steps}
        checked = checked_config(config, fields, scenario)
        self._checked = checked
        self.config = json.loads(checked.json)
        self._vec = _ronap.VecEnv(
            num_envs,
            checked,
            maze_seed=maze_seed,
            map_path=checked_path("map", map),
            threads=threads,
            autoreset=_AUTORESET[mode],
            continuous=bool(continuous),
            render=render_mode is not None,
        )
        self.metadata = {**type(self).metadata, "autoreset_mode": mode}
        self.num_envs = num_envs
        self.continuous = bool(continuous)
        self.render_mode = render_mode
        self.render_view = render_view
        self.render_scale = render_scale
        n = self._vec.observation_size
        self.single_observation_space = spaces.Box(0.0, 1.0, (n,), np.float32)
        #: The full value of each dimension of a continuous action (see ``NavEnv.action_scale``).
        self.action_scale: np.ndarray = np.array(self._vec.action_scale, np.float64)
        if self.continuous:
            self._action_scale = self.action_scale
            self.single_action_space = spaces.Box(-1.0, 1.0, self.action_scale.shape, dtype=np.float32)
        else:
            self.single_action_space = spaces.Discrete(3)
        self.observation_space = batch_space(self.single_observation_space, num_envs)
        self.action_space = batch_space(self.single_action_space, num_envs)
        self._rng = np.random.default_rng()
        self._started = False
        self._log = CallLog()

    def _logged(self, call: tuple[str, Any, Any], full_reset: bool = False) -> None:
        """Keeps `call` for copies (``CallLog``), from the last full reset."""
        if full_reset:
            self._log = CallLog()
        self._log.keep(call)

    def _seeds(self, seed: Any, mask: np.ndarray | None) -> list[int | None]:
        """The episode seeds a reset asks for, in the split when there is one."""
        return [None if s is None else split_seed(self.split, s, f"seed of environment {i}") for i, s in enumerate(self._given_seeds(seed, mask))]

    def _given_seeds(self, seed: Any, mask: np.ndarray | None) -> list[int | None]:
        n = self.num_envs
        if seed is None:
            if mask is not None and self._started:
                return [None] * n
            base = int(self._rng.integers(0, split_draw_limit(self.split, n)))
            return [base + i for i in range(n)]
        if isinstance(seed, (int, np.integer)) and not isinstance(seed, (bool, np.bool_)):
            base = checked_int("seed", seed)
            self._rng = np.random.default_rng(base)
            return [checked_int("seed", base + i) for i in range(n)]
        if isinstance(seed, (list, tuple, np.ndarray)):
            if len(seed) != n:
                raise _ronap.ConfigError(f"seed: {len(seed)} seeds for {n} environments")
            seeds = [None if s is None else checked_int(f"seed[{i}]", s) for i, s in enumerate(seed)]
            if not self._started and None in seeds:
                raise _ronap.ConfigError("seed: the first reset() needs a seed for every environment (or seed=None or one int)")
            given = [s for s in seeds if s is not None]
            if given:
                self._rng = np.random.default_rng(given)
            return seeds
        raise _ronap.ConfigError(f"seed {seed!r}: expected None, an int (environment i gets seed + i) or a list of {n} ints or None")

    def reset(
        self, *, seed: int | list[int | None] | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        mask = reset_mask("VecNavEnv", options, self.num_envs, self._started)
        seeds = self._seeds(seed, mask)
        flags = None if mask is None else [bool(m) for m in mask]
        try:
            obs, infos, _ = self._vec.reset(seeds, flags)
        except _ronap.SceneError as e:
            raise located(e, self._checked) from None
        self._logged(("reset", seeds, flags), full_reset=flags is None)
        check_split_seeds(self.split, infos["seed"])
        self._started = True
        return obs, infos

    def step(self, actions: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        if not self._started:
            raise _ronap.RonapError("step() before reset(): call reset(seed=...) first")
        if self.continuous:
            a = continuous_actions(actions, (self.num_envs, self._action_scale.shape[0])) * self._action_scale
        else:
            a = discrete_actions(actions, (self.num_envs,))
        obs, rewards, terminated, truncated, infos, finals = self._vec.step(a)
        self._logged(("step", kept_actions(a), None))
        check_split_seeds(self.split, infos["seed"])
        if finals is not None:
            ended, last, final_infos = finals
            final_obs = np.full(self.num_envs, None, dtype=object)
            for i in np.flatnonzero(ended):
                final_obs[i] = last[i].copy()
            infos["final_obs"] = final_obs
            infos["_final_obs"] = ended
            infos["final_info"] = final_infos
            infos["_final_info"] = ended
        return obs, rewards, terminated, truncated, infos

    def __getstate__(self) -> dict[str, Any]:
        """How to build this vector environment again and bring every environment to where it
        is: its arguments and the resets and actions since the last reset of them all (the
        model is deterministic), for ``pickle`` and ``copy.deepcopy``; refused after more than
        ``COPY_LIMIT`` steps or ``COPY_BYTES`` bytes of actions since the last full reset (the
        record is not kept that long)."""
        if self._log.calls is None:
            raise copy_refused("VecNavEnv")
        return {"init": self._init_args, "calls": self._log.calls, "rng": self._rng, "started": self._started}

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.__init__(**state["init"])  # type: ignore[misc]
        calls = []
        for kind, a, b in state["calls"]:
            if kind == "reset":
                self._vec.reset(a, b)
            else:
                self._vec.step(a if self.continuous else a.astype(np.int64))
                a = kept_actions(a)
            calls.append((kind, a, b))
        self._log = CallLog(calls)
        self._rng = state["rng"]
        self._started = state["started"]

    def render(self) -> tuple[np.ndarray, ...] | None:  # type: ignore[override]
        """One picture per environment (``render_mode="rgb_array"``), else None."""
        if self.render_mode != "rgb_array":
            return None
        scale = self.render_scale if self.render_view == "top" else 400.0
        return tuple(self._vec.render(i, self.render_view, scale) for i in range(self.num_envs))


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
