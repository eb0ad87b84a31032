"""Several policies on the same seeds, as ``ronap compare`` compares them."""

from __future__ import annotations

from typing import Any, Callable, Iterable, Mapping, Sequence

from . import _ronap
from .config import ScenarioLike, checked_config, checked_int, checked_path, checked_seeds, refuse_sb3_thread_safe


def compare(
    policies: Sequence[str | Callable[[Any], Any]],
    seeds: Iterable[int] = range(1000),
    *,
    scenario: ScenarioLike | None = None,
    config: Mapping[str, Any] | None = None,
    maze_seed: int | None = None,
    map: str | None = None,
    threads: int = 0,
    continuous: bool = False,
    out: str | None = None,
    runs: Sequence[str] = (),
    by_difficulty: bool = False,
    bins: int = 3,
    resamples: int = 10_000,
    sheet: int = 6,
    players: int | None = None,
    thread_safe: bool = False,
    split: str | None = None,
    force: bool = False,
    **fields: Any,
) -> dict[str, Any]:
    """Runs every policy in ``policies`` on the same ``seeds`` and scenes and compares them, as
    ``ronap compare`` does; returns the figures of its ``compare.json`` as a dict:

    - ``success_rule``: what counts as a success, in words;
    - ``policies``: per policy its ``name``, ``label`` and ``summary`` (success rate with its 95%
      Wilson interval, SPL, collisions, steps, path length, time-outs, gave-up...);
    - ``pairs``: per pair the success difference with a paired bootstrap interval, the seeds only
      one of them succeeded on, McNemar's exact p-value (and Holm-adjusted), the paired SPL
      difference with its bootstrap interval, and a ``verdict``;
    - ``by_difficulty`` (with ``by_difficulty=True``): success per bin of each seed's difficulty
      (shortest path over straight line, narrowest gap, turns).

    When pandas is installed, ``"frame"`` (one row per policy) and ``"pairs_frame"`` (one row per
    pair) hold the same figures as DataFrames.

    Policies are named as for ``evaluate`` (``"apf"``, ``"mlp:policies/bc.safetensors"``...) or
    are callables (observation -> action). ``runs``: directories of finished runs
    (``ronap run`` / ``evaluate(out=...)``) to reuse instead of running their policy again; each
    must record the same configuration, scenes and seeds. With ``out``, writes everything
    ``ronap compare --out`` writes: ``runs/<policy>/``, ``compare.png``, ``outcomes.png``,
    ``disagreements.png``, ``seeds.csv``, ``compare.json``, ``report.md``, ``report.html`` and
    ``players/``: a side-by-side HTML player of every seed where one policy succeeded and another
    failed (about 90 KB a seed for two policies), or of the ``players`` that disagree most.
    ``out`` must be new or empty unless ``force=True`` (as ``ronap compare --force``). The
    configuration, ``split`` and ``thread_safe`` are given as for ``evaluate``.
    """
    seeds = checked_seeds(seeds, split)
    for policy in policies:
        refuse_sb3_thread_safe(policy, thread_safe)
    command = _call(policies, seeds, scenario=scenario, config=config, maze_seed=maze_seed, map=map,
                    continuous=continuous, runs=list(runs), by_difficulty=by_difficulty, bins=bins,
                    resamples=resamples, **fields)
    result: dict[str, Any] = _ronap.compare(
        list(policies),
        seeds,
        checked_config(config, fields, scenario),
        maze_seed=maze_seed,
        map_path=checked_path("map", map),
        threads=threads,
        continuous=continuous,
        out=None if out is None else str(out),
        runs=[str(r) for r in runs],
        by_difficulty=by_difficulty,
        bins=bins,
        resamples=resamples,
        sheet=sheet,
        players=None if players is None else checked_int("players", players),
        thread_safe=thread_safe,
        command=command,
        force=force,
    )
    try:
        import pandas
    except ImportError:
        return result
    rows = [{"policy": p["label"], "name": p["name"], **_flat(p["summary"])} for p in result["policies"]]
    result["frame"] = pandas.DataFrame(rows).set_index("policy")
    result["pairs_frame"] = pandas.DataFrame(result["pairs"])
    return result


def _flat(summary: Mapping[str, Any]) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for k, v in summary.items():
        if k == "success_ci95":
            out["success_ci95_low"], out["success_ci95_high"] = v
        elif isinstance(v, Mapping):
            out.update({f"{k}_{kk}": vv for kk, vv in v.items()})
        else:
            out[k] = v
    return out


def _call(policies: Sequence[Any], seeds: list[int], **given: Any) -> str:
    """The call as Python source, for the report's "Reproduce" section (a callable by its name)."""
    names = [p if isinstance(p, str) else getattr(p, "__name__", "policy") for p in policies]
    if seeds and seeds == list(range(seeds[0], seeds[-1] + 1)):
        seed_text = f"range({seeds[0]}, {seeds[-1] + 1})"
    else:
        seed_text = repr(seeds)
    defaults = {"continuous": False, "runs": [], "by_difficulty": False, "bins": 3, "resamples": 10_000}
    kwargs = [f"{k}={v!r}" for k, v in given.items() if v is not None and defaults.get(k, None) != v]
    return "ronap.compare(" + ", ".join([repr(names), seed_text, *kwargs]) + ")"
