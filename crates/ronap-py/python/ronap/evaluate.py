"""The batch evaluator of ``ronap run``, with Python policies."""

from __future__ import annotations

from typing import Any, Callable, Iterable, Mapping

from . import _ronap
from .config import ScenarioLike, checked_config, checked_path, checked_int, checked_seeds, located, refuse_sb3_thread_safe


def evaluate(
    policy: str | Callable[[Any], Any],
    seeds: Iterable[int] = range(1000),
    *,
    scenario: ScenarioLike | None = None,
    config: Mapping[str, Any] | None = None,
    maze_seed: int | None = None,
    map: str | None = None,
    threads: int = 0,
    continuous: bool = False,
    out: str | None = None,
    png: int | str | None = None,
    log_steps: bool = False,
    thread_safe: bool = False,
    split: str | None = None,
    batch: int = 0,
    force: bool = False,
    **fields: Any,
) -> dict[str, Any]:
    """Runs ``policy`` over the episodes of ``seeds`` in parallel and returns
    ``{"summary": {...}, "episodes": [{...}, ...]}``, the figures and rows ``ronap run`` reports.

    ``policy`` is a built-in name (``"apf"``, ``"geodesic"``, ``"random"``), a trained network
    (``"mlp:policies/bc.safetensors"``, see ``policies/README.md``) or a callable taking
    the observation (``float32`` array) and returning an action: 0 LEFT, 1 AHEAD, 2 RIGHT (or
    ``(v / v_max, w / w_max)`` in [-1, 1] with ``continuous=True``, as ``NavEnv``'s action space).
    The simulation runs on ``threads`` threads (0: all cores); a Python policy is called by one of
    them at a time, even when it releases the GIL inside (torch, SB3's ``predict``), unless it is
    declared ``thread_safe=True`` (a pure function of the observation, say; refused for a
    Stable-Baselines3 model, whose ``predict`` shares state between calls: use ``batch=N``). With ``out``, writes ``episodes.csv``,
    ``timing.csv``, ``summary.json`` and, as asked, ``png/`` pictures (``png``: a count, ``"failures"``
    or ``"all"``) and ``steps/`` logs, as ``ronap run`` does. ``out`` must be new or empty unless
    ``force=True`` (as ``ronap run --force``): a finished run there is replaced once the first
    episode is done, other files are kept. A Ctrl-C stops the run as ``ronap run``'s does (the files
    keep every finished episode), then raises ``KeyboardInterrupt``.

    The configuration: ``scenario`` (the path of a TOML scenario file, as ``ronap run --scenario``
    takes, or a dict nested like one) gives the base and the scene; ``config`` and keyword
    arguments ``section_field=value`` override it, and ``maze_seed`` / ``map`` override its
    ``[scene]``, as flags do on the command line. ``summary.json`` records the whole configuration
    (obstacles, moving obstacles, scene) and where episodes took place, so ``ronap replay`` can
    replay the run's step logs.

    With moving obstacles, each episode row also has ``dynamic_collisions`` (steps with contact
    between the robot and a moving obstacle), ``min_clearance_px`` (least gap to any obstacle
    seen within laser range, None if none came that close) and ``near_moving_fraction`` (the
    fraction of steps within ``episode_safety_radius_px`` of one), and the summary a ``moving``
    dict of their figures.

    With ``batch=N`` a callable policy decides for many episodes at once: N episodes run side by
    side and the policy is called with a ``(n, observation_size)`` float32 array of the ones waiting
    for an action (n up to N), returning n actions (an array of indices, or ``(n, 2)`` normalised
    speeds with ``continuous=True``), as SB3's ``model.predict(obs, deterministic=True)[0]`` does.
    The episodes and files are the same as unbatched for a policy that decides each row by itself;
    ``threads`` is then N.

    A team scenario (``[[robots]]`` entries) is run as ``ronap run --scenario`` runs it, with
    ``"coordinated"`` (the team planner), any other built-in or network name for the robots whose
    entries name no policy of their own, or a callable that decides for every robot at once: it
    gets a ``(robots, observation_size)`` float32 array of the running robots' observations, in
    robot order, and returns one action per row (the same episodes as ``ronap run --batch`` with
    the same function). It returns ``{"summary": {...}, "team": {...}, "episodes": [...]}``: the
    robots' figures, the team's (team success, deadlocks, makespan against its lower bound, ...),
    and a dict per team episode (its ``episodes.csv`` row, with ``"robots"``: a dict per robot,
    its ``robots.csv`` row).

    ``split="test"`` (or ``"validation"``, ``"train"``) counts ``seeds`` from that split's first
    seed, as ``ronap run --split`` does (the default seeds, ``range(1000)``, are the test split's
    as given). A trained network that records the seeds it was trained and chosen on
    (``training_seeds``, ``validation_seeds``) gives a ``UserWarning`` when some of the run's
    seeds are among them.

    A policy that raises or returns an invalid action or NaN raises ``PolicyError`` naming the seed
    and step.
    """
    seeds = checked_seeds(seeds, split)
    refuse_sb3_thread_safe(policy, thread_safe)
    batch = checked_int("batch", batch, least=0, below=1 << 16)
    checked = checked_config(config, fields, scenario)
    try:
        return _ronap.evaluate(
            policy,
            seeds,
            checked,
            maze_seed=maze_seed,
            map_path=checked_path("map", map),
            threads=threads,
            continuous=continuous,
            out=None if out is None else str(out),
            png=None if png is None else str(png),
            log_steps=log_steps,
            thread_safe=thread_safe,
            batch=batch,
            force=force,
        )
    except _ronap.SceneError as e:
        raise located(e, checked) from None
