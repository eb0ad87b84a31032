"""Stable-Baselines3's ``VecEnv`` over ronap's Rust-stepped environments.

``pip install ronap[sb3]`` (Stable-Baselines3 and torch), then::

    from stable_baselines3 import PPO
    import ronap.sb3

    env = ronap.sb3.VecEnv(16, maze_cols=6, maze_rows=6)
    model = PPO("MlpPolicy", env).learn(200_000)

``VecEnv(n, **config)`` takes the keyword arguments of ``ronap.VecNavEnv`` (``scenario``,
``config``, ``section_field=value``, ``maze_seed``, ``map``, ``threads``, ``continuous``,
``render_mode``). It steps all ``n`` environments in one call into Rust, across cores, and
follows SB3's conventions exactly: ``dones`` is terminated or truncated, an environment whose
episode ends is reset within the same step, and its info holds ``terminal_observation``,
``TimeLimit.truncated``, ``is_success`` and ``episode`` (``r``, ``l``, ``t``, as SB3's
``Monitor`` writes, so PPO logs ``ep_rew_mean`` without a wrapper), beside ronap's own info
(status, seed, steps, collisions, distance, ...). Infos of environments whose episode goes on
are empty, which keeps a step cheap. ``env_is_wrapped(Monitor)`` is true for that reason, so
``evaluate_policy`` counts the episodes' own returns and lengths without warning.

Seeds: training plays the train split (``split="train"``, the default): ``env.seed(s)`` before
``reset()`` (as SB3's ``seed=s`` does) gives environment ``i`` the train split's seeds ``s + i``,
``s + i + n``, ... (episode seeds 1000000 + s + i, ...; ``ronap run --split train`` plays them),
so a run is reproducible and never trains on the test split that ``ronap run --seeds N`` and
``ronap.evaluate`` score by default. ``split=None`` takes the seeds as given.

``TeamVecEnv(n, scenario=...)`` does the same for team scenarios (``[[robots]]`` entries) with
one policy shared by every robot: see its class.
"""

from __future__ import annotations

import time
from collections.abc import Iterable, Sequence
from typing import Any

import numpy as np

try:
    from stable_baselines3.common.vec_env.base_vec_env import (
        VecEnv as _VecEnv,
        VecEnvIndices,
        VecEnvObs,
    )
except ImportError:  # pragma: no cover - depends on the installed extras
    raise ImportError("ronap.sb3 needs Stable-Baselines3: pip install 'ronap[sb3]' (or stable-baselines3)") from None

from .env import VecNavEnv
from .multi import VecMultiNavEnv

__all__ = ["TeamVecEnv", "VecEnv"]


class _Shared(_VecEnv):
    """What ``VecEnv`` and ``TeamVecEnv`` share: one Rust vector environment, ``venv``, behind
    every index."""

    venv: Any

    def close(self) -> None:
        self.venv.close()

    def get_attr(self, attr_name: str, indices: VecEnvIndices = None) -> list[Any]:
        """The attribute of the (shared) vector environment, once per index."""
        value = getattr(self.venv, attr_name)
        return [value for _ in self._get_indices(indices)]

    def set_attr(self, attr_name: str, value: Any, indices: VecEnvIndices = None) -> None:
        """Sets the attribute on the vector environment, which every index shares."""
        setattr(self.venv, attr_name, value)

    def env_method(self, method_name: str, *method_args: Any, indices: VecEnvIndices = None, **method_kwargs: Any) -> list[Any]:
        """Calls the vector environment's method once and returns its result for every index."""
        result = getattr(self.venv, method_name)(*method_args, **method_kwargs)
        return [result for _ in self._get_indices(indices)]

    def env_is_wrapped(self, wrapper_class: type, indices: VecEnvIndices = None) -> list[bool]:
        """True for SB3's ``Monitor`` (each episode's end writes its ``episode`` info, as a
        ``Monitor`` would, so ``evaluate_policy`` reads returns from it without a warning);
        false for any other wrapper."""
        from stable_baselines3.common.monitor import Monitor

        wrapped = isinstance(wrapper_class, type) and issubclass(Monitor, wrapper_class)
        return [wrapped for _ in self._get_indices(indices)]


class VecEnv(_Shared):
    """``num_envs`` ronap environments as one Stable-Baselines3 ``VecEnv`` (see the module's
    documentation)."""

    venv: VecNavEnv
    render_mode: str | None
    reset_infos: list[dict[str, Any]]

    def __init__(self, num_envs: int, split: str | None = "train", **config: Any) -> None:
        config.pop("autoreset_mode", None)
        self.venv = VecNavEnv(num_envs, autoreset_mode="same_step", split=split, **config)
        self.render_mode = self.venv.render_mode
        super().__init__(self.venv.num_envs, self.venv.single_observation_space, self.venv.single_action_space)
        self._actions: np.ndarray | None = None
        self._start: float = time.monotonic()

    def reset(self) -> VecEnvObs:
        seeds = self._seeds
        seed: list[int | None] | None = None if all(s is None for s in seeds) else list(seeds)
        obs, infos = self.venv.reset(seed=seed)
        self.reset_infos = self._unbatched(infos, range(self.num_envs))
        self._reset_seeds()
        self._reset_options()
        return obs

    def step_async(self, actions: np.ndarray) -> None:
        self._actions = actions

    def step_wait(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[dict[str, Any]]]:
        if self._actions is None:
            raise RuntimeError("step_wait() without step_async()")
        actions = np.asarray(self._actions)
        if not self.venv.continuous:
            actions = actions.reshape(self.num_envs)
        obs, rewards, terminated, truncated, infos = self.venv.step(actions)
        self._actions = None
        dones = terminated | truncated
        ended = np.flatnonzero(dones)
        out: list[dict[str, Any]] = [{} for _ in range(self.num_envs)]
        if ended.size:
            final = infos["final_info"]
            elapsed = round(time.monotonic() - self._start, 6)
            for i, info in zip(ended, self._unbatched(final, ended)):
                info["terminal_observation"] = infos["final_obs"][i]
                info["TimeLimit.truncated"] = bool(truncated[i] and not terminated[i])
                info["is_success"] = bool(info["success"])
                info["episode"] = {"r": float(info["return"]), "l": int(info["steps"]), "t": elapsed}
                out[i] = info
        return obs, rewards.astype(np.float32), dones, out

    @staticmethod
    def _unbatched(infos: dict[str, Any], indices: Iterable[int]) -> list[dict[str, Any]]:
        """Per-environment info dicts from a vector info dict (the ``_key`` masks left out)."""
        keys = [k for k in infos if not k.startswith("_") and isinstance(infos[k], np.ndarray)]
        return [{k: infos[k][i].item() if infos[k][i].ndim == 0 else infos[k][i] for k in keys} for i in indices]

    def get_images(self) -> Sequence[np.ndarray | None]:
        frames = self.venv.render()
        return [None] * self.num_envs if frames is None else list(frames)

class TeamVecEnv(_Shared):
    """Every robot of ``num_envs`` team episodes as one Stable-Baselines3 environment, for
    training one policy that every robot runs (parameter sharing): SB3 sees ``num_envs x robots``
    environments, slot ``e * robots + k`` being robot ``k`` of team episode ``e``; the episodes
    are stepped in Rust across cores (``ronap.VecMultiNavEnv``). Keyword arguments configure it as
    ``VecMultiNavEnv`` (``scenario``, ``config``, ``section_field=value``, ``maze_seed``, ``map``,
    ``threads``); actions are discrete (0 LEFT, 1 AHEAD, 2 RIGHT); messages are not sent.

    Robots finish at different times, and a team episode restarts only when all are done. A
    robot's slot reports its own episode's end when it arrives, collides (under ``terminate``),
    times out or deadlocks: ``done``, with ``terminal_observation``, ``TimeLimit.truncated``,
    ``is_success`` and ``episode`` (``r``, ``l``, ``t``, as SB3's ``Monitor`` writes) in its
    info. Until its team starts again the slot *waits*: observation zeros, reward 0, its actions
    ignored, ``info["waiting"]`` true; the step that starts the team's next episode ends the
    wait with ``done`` (so no value is carried from one episode into the next) and gives the new
    episode's first observation. This is SuperSuit's ``black_death`` with the waits marked and
    closed; the waiting steps count towards ``total_timesteps``.

    Seeds: ``env.seed(s)`` before ``reset()`` (as SB3's ``seed=`` does) gives team environment
    ``e`` the train split's seeds ``s + e``, ``s + e + num_envs``, ... (``split="train"``, the
    default, as ``VecEnv``): the seeds of ``ronap run --scenario ... --split train``.
    """

    venv: VecMultiNavEnv
    render_mode: str | None = None
    reset_infos: list[dict[str, Any]]

    def __init__(self, num_envs: int, split: str | None = "train", **config: Any) -> None:
        # Its waiting and terminal observations follow next-step autoreset, whatever is asked.
        config.pop("autoreset_mode", None)
        self.venv = VecMultiNavEnv(num_envs, autoreset_mode="next_step", split=split, **config)
        self.teams: int = self.venv.num_envs
        self.robots: int = self.venv.num_agents
        super().__init__(self.teams * self.robots, self.venv.single_observation_space, self.venv.single_action_space)
        self._actions: np.ndarray | None = None
        self._start = time.monotonic()
        self._waiting = np.zeros((self.teams, self.robots), bool)
        self._returns = np.zeros((self.teams, self.robots))
        self._lengths = np.zeros((self.teams, self.robots), np.int64)

    def reset(self) -> VecEnvObs:
        seed = next((s for s in self._seeds if s is not None), None)
        obs, infos = self.venv.reset(seed=seed)
        self._waiting[:] = False
        self._returns[:] = 0.0
        self._lengths[:] = 0
        seeds = infos["seed"]
        self.reset_infos = [{"seed": int(seeds[e]), "robot": k} for e in range(self.teams) for k in range(self.robots)]
        self._reset_seeds()
        self._reset_options()
        return obs.reshape(self.num_envs, -1)

    def step_async(self, actions: np.ndarray) -> None:
        self._actions = actions

    def step_wait(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[dict[str, Any]]]:
        if self._actions is None:
            raise RuntimeError("step_wait() without step_async()")
        actions = np.asarray(self._actions).reshape(self.teams, self.robots)
        self._actions = None
        obs, rewards, terminated, truncated, infos = self.venv.step(actions)
        acted, success, restarted = infos["acted"], infos["success"], infos["reset"]
        ended = acted & (terminated | truncated)
        self._returns += np.where(acted, rewards, 0.0)
        self._lengths += acted
        out_obs = np.where((self._waiting | ended)[..., None], 0.0, obs).astype(np.float32)
        out_rewards = np.where(acted, rewards, 0.0).astype(np.float32)
        dones = ended.copy()
        out: list[dict[str, Any]] = [{} for _ in range(self.num_envs)]
        elapsed = round(time.monotonic() - self._start, 6)
        seeds = infos["seed"]
        for e, k in zip(*np.nonzero(ended)):
            out[e * self.robots + k] = {
                "terminal_observation": obs[e, k].copy(),
                "TimeLimit.truncated": bool(truncated[e, k] and not terminated[e, k]),
                "is_success": bool(success[e, k]),
                "episode": {"r": float(self._returns[e, k]), "l": int(self._lengths[e, k]), "t": elapsed},
                "seed": int(seeds[e]),
                "robot": int(k),
            }
        for e, k in zip(*np.nonzero(self._waiting)):
            out[e * self.robots + k]["waiting"] = True
        self._waiting |= ended
        for e in np.flatnonzero(restarted):
            # Every robot of the team was waiting: the wait ends, the next episode begins.
            out_obs[e] = obs[e]
            dones[e] = True
            for k in range(self.robots):
                out[e * self.robots + k] = {"terminal_observation": np.zeros_like(obs[e, k]), "waiting": True, "TimeLimit.truncated": False}
            self._waiting[e] = False
            self._returns[e] = 0.0
            self._lengths[e] = 0
        return out_obs.reshape(self.num_envs, -1), out_rewards.reshape(-1), dones.reshape(-1), out

    def get_images(self) -> Sequence[np.ndarray | None]:
        return [None] * self.num_envs
