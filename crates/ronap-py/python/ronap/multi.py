"""Several robots in one episode: a PettingZoo ``ParallelEnv`` over the Rust team model."""

from __future__ import annotations

import json
from typing import TYPE_CHECKING, Any, Mapping

import numpy as np
from gymnasium import spaces
from gymnasium.vector import AutoresetMode

from . import _ronap
from .config import ScenarioLike, checked_config, checked_path, checked_int, init_arguments, checked_split, split_draw_limit, split_seed, check_split_seeds
from .env import _AUTORESET, _autoreset_mode, CallLog, copy_refused, discrete_actions, kept_actions, reset_mask

if TYPE_CHECKING:
    from pettingzoo import ParallelEnv

    _Base = ParallelEnv[str, np.ndarray, Any]
else:
    try:  # PettingZoo is optional: without it MultiNavEnv still works, as a plain class.
        from pettingzoo import ParallelEnv as _Base
    except ImportError:  # pragma: no cover - exercised only without pettingzoo
        _Base = object


class MultiNavEnv(_Base):
    """The robots of a scenario's ``[[robots]]`` entries in one scene, as a PettingZoo
    ``ParallelEnv``: agents ``robot_0``, ``robot_1``, ... in entry order.

    Each agent observes its own robot as a lone robot would (its laser, which sees the other
    robots, and its goal direction: ``float32[beams + 1]``), then ``team.neighbours`` slots of
    the nearest robots heard last step (position in its frame over ``comm_range_px``, heading
    difference over 360, 1, and the sender's message). Actions: ``Discrete(3)`` (0 LEFT, 1 AHEAD,
    2 RIGHT), or ``Box(-1, 1, (2,))`` with ``continuous=True`` (``v / v_max, w / w_max`` of that
    robot). With ``team.message_size = m > 0`` an action is a dict ``{"action": a, "message":
    float32[m]}``: the message goes out with the robot's pose and goal to every robot within
    ``comm_range_px`` and arrives the next step (in their observations and in ``inbox(agent)``).

    All robots move at once; robots whose motions would touch stay put and count a collision.
    An agent leaves ``agents`` after the step that ends its episode (once all have left,
    ``step({})`` returns empty dicts until ``reset()``): ``terminated`` on success
    (or a collision under ``robot_on_collision="terminate"``), ``truncated`` at the time-out or
    a deadlock (no robot moved for ``episode.deadlock_steps`` steps). A robot that arrived stays
    in the scene as an obstacle, or leaves it with ``on_arrival = "vanish"``.

    Infos hold numbers only (distance, collided, success, pose, goal, steps, collisions, seed,
    robot, present, goals_reached, goals), as torchrl's ``PettingZooWrapper`` and BenchMARL
    need; ``status(agent)`` and ``inbox(agent)`` give the episode status text and the messages
    heard, and ``text_infos=True`` puts them in the infos as ``status`` and ``inbox``.
    ``state()`` is the global state for centralised critics (``state_space``). Copies
    (``pickle``, ``copy.deepcopy``) continue where the original is.

    Configure it as ``NavEnv``: ``scenario`` (a TOML file or a nested dict with ``robots``
    entries), ``config`` and keyword overrides. ``reset(seed=s)`` plays team episode ``s``,
    the same as seed ``s`` of ``ronap run --scenario``; with ``split="train"`` (or
    ``"validation"``, ``"test"``) seeds count from that split's first, as ``ronap run --split``.
    """

    metadata: dict[str, Any] = {"name": "ronap_multi_nav_v0", "render_modes": ["rgb_array"], "render_fps": 30}
    config: dict[str, Any]
    render_mode: str | None
    render_scale: float
    continuous: bool
    message_size: int

    def __init__(
        self,
        render_mode: str | None = None,
        *,
        scenario: ScenarioLike | None = None,
        config: Mapping[str, Any] | None = None,
        continuous: bool = False,
        maze_seed: int | None = None,
        map: str | None = None,
        render_scale: float = 0.5,
        text_infos: bool = False,
        split: str | None = None,
        **fields: Any,
    ) -> None:
        # What pickling needs to build this object again (see __getstate__).
        self._init_args = init_arguments(locals())
        if render_mode not in (None, "rgb_array"):
            raise _ronap.ConfigError(f"render_mode {render_mode!r}: expected None or 'rgb_array'")
        self.split: str | None = checked_split(split)
        checked = checked_config(config, fields, scenario)
        self.text_infos: bool = bool(text_infos)
        self._status: dict[str, str] = {}
        self._inbox: dict[str, list[dict[str, Any]]] = {}
        self._env = _ronap.MultiEnv(checked, maze_seed=maze_seed, map_path=checked_path("map", map), continuous=continuous)
        self._episode: tuple[int, list[tuple[list[Any], Any]]] | None = None
        self.config = json.loads(checked.json)
        self.render_mode = render_mode
        self.render_scale = render_scale
        self.continuous = continuous
        self.message_size = self._env.message_size
        n = self._env.robots
        self.possible_agents: list[str] = [f"robot_{k}" for k in range(n)]
        self.agents: list[str] = []
        self._index = {a: k for k, a in enumerate(self.possible_agents)}
        slots = self._env.slots_size
        # The JSON leaves `observation` out while it holds its defaults.
        history = int(self.config.get("observation", {}).get("history", 1))
        self._observation_spaces = {
            a: _observation_space(size, slots, history)
            for a, size in zip(self.possible_agents, self._env.observation_sizes)
        }
        self._scales = [np.array(limits, np.float64) for limits in self._env.action_scales]
        self._action_spaces = {a: self._make_action_space(k) for k, a in enumerate(self.possible_agents)}
        self._state_parts = [space.shape[0] for space in self._observation_spaces.values()]
        self.state_space: spaces.Box = spaces.Box(-np.inf, np.inf, (sum(self._state_parts),), np.float32)
        self._last_obs: list[np.ndarray] = [np.zeros(n, np.float32) for n in self._state_parts]
        self._rng = np.random.default_rng()
        self.seed_used: int | None = None

    def _make_action_space(self, k: int) -> spaces.Space[Any]:
        base: spaces.Space[Any]
        if self.continuous:
            base = spaces.Box(-1.0, 1.0, self._scales[k].shape, dtype=np.float32)
        else:
            base = spaces.Discrete(3)
        if self.message_size == 0:
            return base
        message = spaces.Box(-np.inf, np.inf, (self.message_size,), dtype=np.float32)
        return spaces.Dict({"action": base, "message": message})

    def observation_space(self, agent: str) -> spaces.Space[Any]:
        return self._observation_spaces[agent]

    def action_space(self, agent: str) -> spaces.Space[Any]:
        return self._action_spaces[agent]

    @property
    def observation_spaces(self) -> dict[str, spaces.Space[Any]]:
        """Every agent's observation space, by agent (PettingZoo's dict attribute)."""
        return dict(self._observation_spaces)

    @property
    def action_spaces(self) -> dict[str, spaces.Space[Any]]:
        """Every agent's action space, by agent (PettingZoo's dict attribute)."""
        return dict(self._action_spaces)

    def reset(
        self, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, np.ndarray], dict[str, dict[str, Any]]]:
        if seed is not None:
            episode_seed = split_seed(self.split, checked_int("seed", seed))
            self._rng = np.random.default_rng(episode_seed)
        else:
            episode_seed = split_seed(self.split, int(self._rng.integers(0, split_draw_limit(self.split))))
        self.seed_used = episode_seed
        obs, infos = self._env.reset(episode_seed)
        self._episode = (episode_seed, [])
        self.agents = list(self.possible_agents)
        self._last_obs = [np.asarray(o, np.float32) for o in obs]
        return (
            {a: obs[k] for k, a in enumerate(self.possible_agents)},
            {a: self._info(a, infos[k]) for k, a in enumerate(self.possible_agents)},
        )

    def _info(self, agent: str, info: dict[str, Any]) -> dict[str, Any]:
        """The agent's info, its text (``status``) and inbox kept aside unless ``text_infos``."""
        self._status[agent] = info["status"]
        self._inbox[agent] = info.get("inbox", [])
        if self.text_infos:
            return info
        del info["status"]
        info.pop("inbox", None)
        return info

    def status(self, agent: str) -> str:
        """The agent's episode status after the latest step: "running", "success", "timeout",
        "collision", "deadlock", ... (in ``infos`` too with ``text_infos=True``)."""
        return self._status[agent]

    def inbox(self, agent: str) -> list[dict[str, Any]]:
        """The messages the agent heard in the latest step, each ``{"from", "pose", "goal",
        "message"}`` (in ``infos`` too with ``text_infos=True``)."""
        return self._inbox[agent]

    def state(self) -> np.ndarray:
        """The global state: every robot's latest observation, in agent order, concatenated
        (``state_space``), for centralised critics; a robot that is done keeps its last one."""
        return np.concatenate(self._last_obs)

    def step(
        self, actions: Mapping[str, Any]
    ) -> tuple[
        dict[str, np.ndarray],
        dict[str, float],
        dict[str, bool],
        dict[str, bool],
        dict[str, dict[str, Any]],
    ]:
        if not self.agents:
            if self._episode is None:
                raise _ronap.RonapError("step() before reset(): call reset(seed=...) first")
            # Every agent is done: nothing moves, nothing is returned (as PettingZoo's own
            # parallel environments do; SuperSuit's black_death steps once more to see it).
            if actions:
                raise _ronap.ActionError(f"actions for {sorted(actions)}: every agent is done; call reset()")
            return {}, {}, {}, {}, {}
        unknown = [a for a in actions if a not in self._index]
        if unknown:
            raise _ronap.ActionError(f"unknown agent {unknown[0]!r}: expected one of {self.possible_agents}")
        n = len(self.possible_agents)
        moves: list[Any] = [None] * n
        messages: list[np.ndarray | None] | None = [None] * n if self.message_size else None
        for agent, action in actions.items():
            if agent not in self.agents:
                continue  # a robot whose episode is over does nothing
            k = self._index[agent]
            if self.message_size and isinstance(action, Mapping):
                if "message" in action and messages is not None:
                    messages[k] = np.ascontiguousarray(action["message"], dtype=np.float32).reshape(-1)
                action = action.get("action")
            moves[k] = self._scale(k, action) if self.continuous else _discrete(agent, action)
        obs, rewards, terminated, truncated, infos = self._env.step(moves, messages)
        if self._episode is not None:
            self._episode[1].append((moves, messages))
        live = self.agents
        self.agents = [a for a in live if not (terminated[self._index[a]] or truncated[self._index[a]])]
        for a in live:
            self._last_obs[self._index[a]] = np.asarray(obs[self._index[a]], np.float32)
        return (
            {a: obs[self._index[a]] for a in live},
            {a: float(rewards[self._index[a]]) for a in live},
            {a: bool(terminated[self._index[a]]) for a in live},
            {a: bool(truncated[self._index[a]]) for a in live},
            {a: self._info(a, infos[self._index[a]]) for a in live},
        )

    def __getstate__(self) -> dict[str, Any]:
        """How to build this environment again and replay its episode so far: the model is
        deterministic, so a copy (``pickle``, ``copy.deepcopy``, SuperSuit's and Ray's workers)
        continues exactly where this one is. A scenario given as a file is read again where the
        copy is made."""
        return {
            "init": self._init_args,
            "episode": self._episode,
            "agents": list(self.agents),
            "rng": self._rng,
            "seed_used": self.seed_used,
            "latest": (self._last_obs, self._status, self._inbox),
        }

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.__init__(**state["init"])  # type: ignore[misc]
        self._rng = state["rng"]
        self.seed_used = state["seed_used"]
        if state["episode"] is not None:
            seed, steps = state["episode"]
            self._env.reset(seed)
            for moves, messages in steps:
                self._env.step(moves, messages)
            self._episode = (seed, list(steps))
        self.agents = list(state["agents"])
        self._last_obs, self._status, self._inbox = state["latest"]

    def _scale(self, k: int, action: Any) -> list[float] | None:
        if action is None:
            return None
        scaled = np.asarray(action, dtype=np.float64)
        if scaled.shape != self._scales[k].shape:
            size = self._scales[k].shape[0]
            raise _ronap.ActionError(f"robot_{k}'s action {action!r}: expected {'two' if size == 2 else size} numbers in [-1, 1]")
        return (scaled * self._scales[k]).tolist()

    def render(self) -> np.ndarray | None:
        if self.render_mode != "rgb_array":
            return None
        return self._env.render(self.render_scale)

    def close(self) -> None:
        pass


def _discrete(agent: str, action: Any) -> Any:
    if action is None:
        return None
    if isinstance(action, (bool, np.bool_)):
        raise _ronap.ActionError(f"{agent}'s action {action!r}: expected 0 (LEFT), 1 (AHEAD) or 2 (RIGHT)")
    if isinstance(action, (float, np.floating)) and not float(action).is_integer():
        raise _ronap.ActionError(f"{agent}'s action {action!r}: expected 0 (LEFT), 1 (AHEAD) or 2 (RIGHT)")
    if isinstance(action, np.ndarray) and action.shape == ():
        action = action.item()
    return int(action) if isinstance(action, (float, np.floating, np.integer)) else action


def _observation_space(size: int, slots: int, history: int) -> spaces.Box:
    """A robot's observation of ``size`` values: ``history`` frames, each its beams and goal
    direction in [0, 1] then ``slots`` neighbour values (unbounded), then three values in [0, 1]
    for each of the ``history - 1`` remembered actions."""
    actions = 3 * (history - 1)
    frame = (size - actions) // history
    low = np.concatenate([np.zeros(frame - slots, np.float32), np.full(slots, -np.inf, np.float32)] * history + [np.zeros(actions, np.float32)])
    high = np.concatenate([np.ones(frame - slots, np.float32), np.full(slots, np.inf, np.float32)] * history + [np.ones(actions, np.float32)])
    return spaces.Box(low, high, dtype=np.float32)


class VecMultiNavEnv:
    """``num_envs`` team episodes stepped together in Rust, across cores, with the GIL released:
    the vectorised form of ``MultiNavEnv`` for learning with shared-parameter policies.

    Arrays are indexed ``[env, robot]``: ``reset(seed)`` and ``step(actions)`` return
    observations ``float32[num_envs, num_agents, obs_size]`` (each robot's ``MultiNavEnv``
    observation, zeros past its length when robots differ), and ``step`` rewards, terminated and
    truncated ``[num_envs, num_agents]``. ``actions`` is ``int[num_envs, num_agents]`` (0 LEFT,
    1 AHEAD, 2 RIGHT; ignored for robots that are done); with ``team.message_size = m > 0``,
    ``messages=float32[num_envs, num_agents, m]`` sends messages. ``infos["active"]`` says which
    robots are still going after the step (mask the others out of a loss), ``infos["success"]``
    which reached their goal, ``infos["collided"]`` which collided in the step, ``infos["acted"]``
    whose action counted, ``infos["reset"]`` which environments started a new episode,
    ``infos["seed"]`` and ``infos["steps"]`` each environment's episode.

    ``autoreset_mode`` (Gymnasium's ``AutoresetMode`` or "next_step", "same_step", "disabled"),
    as ``VecNavEnv``'s: next-step (default) starts an environment's next episode on the step
    after every robot of it is done (its actions are ignored, rewards 0); same-step starts it
    within the ending step, whose rewards, flags and ``active``/``acted``/``collided``/``success``
    infos stay the ending step's while the observations, ``seed``, ``steps`` and ``reset`` are the
    new episode's, the last observations in ``infos["final_obs"]`` (``[num_envs]`` of
    ``[num_agents, obs_size]`` arrays, None for the others; ``infos["_final_obs"]`` the mask);
    disabled leaves it to ``reset(options={"reset_mask": mask})``, which restarts the environments
    ``mask`` selects with their next seeds (stepping an ended environment raises ``RonapError``).
    Environment ``i``'s episodes have seeds ``seed + i``, ``seed + i + num_envs``, ...: the same
    episodes ``MultiNavEnv`` plays with those seeds, in every mode, on any number of threads.
    """

    metadata: dict[str, Any] = {"autoreset_mode": AutoresetMode.NEXT_STEP}
    config: dict[str, Any]
    possible_agents: list[str]
    render_mode: str | None = None
    single_observation_space: spaces.Box
    single_action_space: spaces.Space[Any]

    def __init__(
        self,
        num_envs: int,
        *,
        scenario: ScenarioLike | None = None,
        config: Mapping[str, Any] | None = None,
        maze_seed: int | None = None,
        map: str | None = None,
        threads: int = 0,
        autoreset_mode: AutoresetMode | str = AutoresetMode.NEXT_STEP,
        split: str | None = None,
        **fields: Any,
    ) -> None:
        # What pickling needs to build this object again (see __getstate__).
        self._init_args = init_arguments(locals())
        num_envs = checked_int("num_envs", num_envs, least=1, below=2**31)
        threads = checked_int("threads", threads, below=2**16)
        mode = _autoreset_mode(autoreset_mode)
        self.metadata = {"autoreset_mode": mode}
        self.split: str | None = checked_split(split)
        checked = checked_config(config, fields, scenario)
        self._vec = _ronap.VecMultiEnv(
            int(num_envs),
            checked,
            maze_seed=maze_seed,
            map_path=checked_path("map", map),
            threads=int(threads),
            autoreset=_AUTORESET[mode],
        )
        self.config = json.loads(checked.json)
        self.num_envs: int = self._vec.num_envs
        self.num_agents: int = self._vec.robots
        self.possible_agents = [f"robot_{k}" for k in range(self.num_agents)]
        self.message_size: int = self._vec.message_size
        d = self._vec.observation_size
        self.single_observation_space = spaces.Box(-np.inf, np.inf, (d,), np.float32)
        self.single_action_space = spaces.Discrete(3)
        self._started = False
        self.seed_used: int | None = None
        self._log = CallLog()

    def reset(
        self, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, np.ndarray]]:
        """Restarts every environment: environment ``i`` plays seeds ``seed + i``, ``seed + i +
        num_envs``, ... (counted from the split's first seed with ``split=``); ``seed=None``
        draws the first seed at random (as Gymnasium's vector environments do); the episode seed
        of environment 0 is reported as ``seed_used``. ``options={"reset_mask": mask}`` restarts
        only the environments the ``[num_envs]`` bools select, each with its next seed (what
        ``autoreset_mode="disabled"`` leaves to the caller)."""
        mask = reset_mask("VecMultiNavEnv", options, self.num_envs, self._started)
        if mask is not None and self._started:
            if seed is not None:
                raise _ronap.ConfigError("reset(seed=..., options={'reset_mask': ...}): a masked reset takes each environment's next seed, not a seed")
            flags = [bool(m) for m in mask]
            obs, infos = self._vec.restart([None] * self.num_envs, flags)
            self._logged(("restart", flags, None))
            check_split_seeds(self.split, infos["seed"])
            return obs, infos
        if seed is None:
            seed = int(np.random.default_rng().integers(0, min(2**62, split_draw_limit(self.split, self.num_envs))))
        seed = split_seed(self.split, checked_int("seed", seed))
        self.seed_used = seed
        self._started = True
        self._log = CallLog()
        return self._vec.reset(seed)

    def _logged(self, call: tuple[str, Any, Any]) -> None:
        """Keeps `call` for copies (``CallLog``), from the last full reset."""
        self._log.keep(call)

    def step(
        self, actions: Any, messages: Any = None
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict[str, np.ndarray]]:
        if not self._started:
            raise _ronap.RonapError("step() before reset()")
        shape = (self.num_envs, self.num_agents)
        a = discrete_actions(actions, shape)
        flat_messages = None
        if messages is not None:
            m = np.ascontiguousarray(messages, dtype=np.float32)
            if m.shape != (*shape, self.message_size):
                raise _ronap.ActionError(f"messages of shape {m.shape}: expected {(*shape, self.message_size)}")
            flat_messages = m.reshape(-1)
        obs, rewards, terminated, truncated, infos = self._vec.step(a.reshape(-1), flat_messages)
        self._logged(("step", kept_actions(a.reshape(-1)), None if flat_messages is None else flat_messages.copy()))
        check_split_seeds(self.split, infos["seed"])
        if "final_obs" in infos:
            ended = infos["_final_obs"]
            final_obs = np.full(self.num_envs, None, dtype=object)
            for i in np.flatnonzero(ended):
                final_obs[i] = infos["final_obs"][i].copy()
            infos["final_obs"] = final_obs
        return obs, rewards, terminated, truncated, infos

    def __getstate__(self) -> dict[str, Any]:
        """Its arguments, seed and the actions since the last reset, replayed where the copy is
        made (``pickle``, ``copy.deepcopy``): the copy continues exactly where this one is."""
        if self._log.calls is None:
            raise copy_refused("VecMultiNavEnv")
        return {"init": self._init_args, "seed": self.seed_used if self._started else None, "calls": self._log.calls}

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.__init__(**state["init"])  # type: ignore[misc]
        if state["seed"] is not None:
            self._vec.reset(state["seed"])
            self.seed_used = state["seed"]
            self._started = True
            # Each call (kind, ...); a copy made before masked resets holds (actions, messages).
            calls = [c if len(c) == 3 else ("step", *c) for c in state["calls"]]
            kept = []
            for kind, first, second in calls:
                if kind == "step":
                    self._vec.step(first.astype(np.int64), second)
                    first = kept_actions(first)
                else:
                    self._vec.restart([None] * self.num_envs, first)
                kept.append((kind, first, second))
            self._log = CallLog(kept)

    def close(self) -> None:
        pass
