"""ronap: fast robot-navigation analysis on the RoNAP model, from Python.

- ``NavEnv`` / ``gymnasium.make("ronap/Nav-v0")``: one environment, Gymnasium API.
- ``VecNavEnv(num_envs)``: a ``gymnasium.vector.VectorEnv`` stepped in Rust across cores.
- ``MultiNavEnv``: several robots of a scenario's ``[[robots]]`` as a PettingZoo ``ParallelEnv``;
  ``VecMultiNavEnv(num_envs)``: many such episodes stepped in Rust, as ``[env, robot]`` arrays.
- ``evaluate(policy, seeds)``: the batch evaluator of ``ronap run`` with a Python callable or a
  built-in policy.
- ``compare(policies, seeds)``: several policies on the same seeds with paired statistics, as
  ``ronap compare``.
- ``export_policy(model, path)`` / ``import_torch(file, path)``: SB3 models, torch modules and
  ``torch.save`` files (legacy ones too, read without torch) as ronap weights files, to run at
  Rust speed as ``mlp:PATH``; ``mlp_outputs(path, obs)`` runs one on a batch.
- ``ronap.sb3.VecEnv(n)``: a Stable-Baselines3 ``VecEnv`` stepped in Rust (``pip install ronap[sb3]``).
- ``maze_occupancy`` / ``maze_image``: scenes as numpy arrays; ``default_config()``, ``policies()``.
- ``orca_step(agents, obstacles, ...)``: one ORCA step of a crowd (RVO2's, held to ``pyrvo``).

``NavEnv``, ``VecNavEnv``, ``evaluate`` and ``make_config`` take ``scenario=``: a TOML scenario
file, as ``ronap run --scenario`` reads, or a dict nested like one (scene, static and moving
obstacles, robot, laser, episode, reward), which keyword arguments (``laser_beams=9``,
``config={...}``, ``maze_seed=``, ``map=``) override.

Every error is a ``RonapError``; configuration errors (``ConfigError``) name the field and value,
and the file and line for a value a scenario file sets. A bad value (``ConfigError``,
``ActionError``) is also a ``ValueError``, a missing file (``MissingFileError``) also a
``FileNotFoundError``.
"""

from ._ronap import (
    ActionError,
    ConfigError,
    OutputError,
    PolicyError,
    RonapError,
    SceneError,
    __version__,
)
from .compare import compare
from .config import MissingFileError, default_config, make_config
from .env import NavEnv, VecNavEnv
from .evaluate import evaluate
from .export import ModelError, export_policy, import_torch, mlp_outputs
from .multi import MultiNavEnv, VecMultiNavEnv
from .orca import orca_step
from .scenes import maze_image, maze_occupancy, policies

__all__ = [
    "ActionError",
    "ConfigError",
    "MissingFileError",
    "ModelError",
    "MultiNavEnv",
    "NavEnv",
    "OutputError",
    "PolicyError",
    "RonapError",
    "SceneError",
    "VecMultiNavEnv",
    "VecNavEnv",
    "__version__",
    "compare",
    "default_config",
    "evaluate",
    "export_policy",
    "import_torch",
    "make_config",
    "maze_image",
    "maze_occupancy",
    "mlp_outputs",
    "orca_step",
    "policies",
]


def _register() -> None:
    import gymnasium

    if "ronap/Nav-v0" not in gymnasium.registry:
        gymnasium.register(
            id="ronap/Nav-v0",
            entry_point="ronap.env:NavEnv",
            vector_entry_point="ronap.env:VecNavEnv",
        )


_register()
