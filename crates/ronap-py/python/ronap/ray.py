"""Runs beyond one machine, on Ray: a seed range cut into blocks, each block a Ray task running
ronap's Rust evaluator with the task's CPUs, the blocks streamed back as they finish and written,
in seed order, into one run directory as ``ronap run`` writes it: the same ``episodes.csv``
bytes and the same summary figures as one ``ronap run`` of the same seeds.

    python -m ronap.ray --policy apf --seeds 100000 --out runs/apf [--address auto] [--block 1000]

or ``ronap.ray.evaluate("apf", range(100_000), out="runs/apf")``.

Without an address it starts a Ray instance of its own on this machine, every server bound to
127.0.0.1 (never joining a cluster that ``RAY_ADDRESS`` or a file in Ray's temporary directory
names: a stale one would hang the run); ``--address auto`` joins the cluster this machine
belongs to, ``--address HOST:PORT`` that one.

Policies travel as what they are: a built-in name; ``mlp:FILE`` as the file's bytes (workers
need not share a disk); a Python callable as Ray pickles it (cloudpickle). A map file
(``map=``) must be at the same path on every machine. A task whose worker dies is run again
(``retries``, default 3); a block's rows are kept once, by block, so a retried task never
duplicates an episode and the run is complete only when every seed's rows came. A task that
fails (a policy that raises) stops the run: the finished blocks stay, written in order, and the
error is raised as the ronap exception it was (``isinstance(e, ronap.PolicyError)`` holds).
A team scenario (``[[robots]]``) is refused before Ray starts: its run files (``robots.csv``,
the team's figures) are not written block by block yet; ``ronap.evaluate`` and ``ronap run``
run it.

On a cluster, start Ray with its own tools (``ray start --head`` on one machine and ``ray start
--address HEAD:6379`` on the others, or ``ray up cluster.yaml``), install ronap on every
machine, then run the command above with ``--address auto`` on the head.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import time
from collections.abc import Callable, Iterable, Mapping
from typing import Any

from . import _ronap
from .config import ScenarioLike, checked_config, checked_int, checked_seeds

__all__ = ["evaluate", "main"]


def _block(payload: Any, seeds: list[int], config_json: str, maze_seed: int | None, map: str | None) -> list[Any]:
    """One block, on a worker: the Rust evaluator over `seeds` with the task's CPUs; returns the
    rows of every episode, in seed order."""
    import ray

    cpus = ray.get_runtime_context().get_assigned_resources().get("CPU", 1.0)
    kind, value = payload
    config = _ronap.Config(config_json)

    def run(policy: Any) -> Any:
        return _ronap.evaluate(policy, seeds, config, maze_seed=maze_seed, map_path=map, threads=max(1, int(cpus)), rows=True)

    if kind != "mlp":
        return run(value)["rows"]
    # Only a network needs a file (Ray may end a worker before such a directory is removed).
    with tempfile.TemporaryDirectory(prefix="ronap-block-") as tmp:
        data, rule = value
        path = os.path.join(tmp, "net.safetensors")
        with open(path, "wb") as f:
            f.write(data)
        return run(f"mlp:{path}" + (f"@{rule}" if rule else ""))["rows"]


def _init(address: str | None = None, num_cpus: int | None = None) -> Any:
    """Starts Ray in this process and returns its context: with no ``address``, a Ray instance
    of this machine alone, its servers bound to 127.0.0.1 (``address="local"`` keeps Ray from
    joining a cluster that ``RAY_ADDRESS`` or its temporary directory names); else joins the
    cluster at ``address`` (``"auto"``: the one this machine belongs to).

    Ray binds to its node's address, which on Linux is the outward one unless the node is declared
    no cluster's (as Ray declares it on macOS and Windows); a driver joining a cluster at
    127.0.0.1 must take its node as 127.0.0.1 too. Both are declared while Ray starts."""
    import ray
    from ray._private import ray_constants

    host = "127.0.0.1" if address is None else address.rpartition(":")[0].strip("[]")
    loopback = host in ("localhost", "::1") or host.startswith("127.")
    cluster = getattr(ray_constants, "ENABLE_RAY_CLUSTER", True)
    ray_constants.ENABLE_RAY_CLUSTER = cluster and not loopback
    try:
        if address is None:
            return ray.init(address="local", num_cpus=num_cpus, include_dashboard=False, log_to_driver=False)
        return ray.init(address=address, log_to_driver=False)
    finally:
        ray_constants.ENABLE_RAY_CLUSTER = cluster


def _check_single_robot(checked: Any) -> None:
    """Refuses a team scenario, before any task starts."""
    robots = json.loads(checked.json).get("robots") or []
    if robots:
        team = sum(int(r.get("count", 1)) for r in robots)
        raise _ronap.ConfigError(
            f"robots: a team of {team} ([[robots]]): ronap.ray writes single-robot runs only (a team's robots.csv "
            "and figures are not written block by block yet); run it with ronap.evaluate(...) or `ronap run --scenario`"
        )


def _payload(policy: str | Callable[[Any], Any]) -> tuple[str, Any]:
    """How `policy` travels to the workers."""
    if isinstance(policy, str) and policy.startswith("mlp:"):
        spec = policy[len("mlp:") :]
        path, _, rule = spec.rpartition("@") if "@" in spec else (spec, "", "")
        try:
            with open(path, "rb") as f:
                return ("mlp", (f.read(), rule))
        except OSError as e:
            raise _ronap.ConfigError(f"policy {policy}: cannot read {path}: {e.strerror}") from None
    if isinstance(policy, str) or callable(policy):
        return ("as_is", policy)
    raise _ronap.ConfigError(f"policy {policy!r}: expected a built-in policy name, mlp:FILE or a callable")


def evaluate(
    policy: str | Callable[[Any], Any],
    seeds: Iterable[int] = range(1000),
    *,
    out: str | os.PathLike[str] | None = None,
    block: int = 1000,
    address: str | None = None,
    cpus_per_task: float = 1,
    retries: int = 3,
    scenario: ScenarioLike | None = None,
    config: Mapping[str, Any] | None = None,
    maze_seed: int | None = None,
    map: str | None = None,
    progress: bool = False,
    force: bool = False,
    split: str | None = None,
    **fields: Any,
) -> dict[str, Any]:
    """Runs ``policy`` over ``seeds`` as Ray tasks of ``block`` seeds each (``cpus_per_task``
    CPUs each) and writes the run into ``out`` as ``ronap run --out`` does (a temporary directory,
    removed, when None). Uses the Ray instance this process already started, else connects to the
    cluster at ``address`` (``"auto"``: the one this machine belongs to), else (``None``) starts
    a local one bound to 127.0.0.1, kept for later calls. A team scenario is refused
    (``ConfigError``) before Ray starts. Returns ``{"summary": ..., "table": ..., "out": ...}``;
    the summary's wall time is the run's, Ray's start left out (``progress=True`` prints it, and
    the episodes done, on stderr). ``out`` must be new or empty unless ``force=True``, as for
    ``ronap.evaluate``. The configuration keywords and ``split`` are ``ronap.evaluate``'s, and so is the
    warning when the seeds meet a trained network's own."""
    import ray

    seeds = checked_seeds(seeds, split)
    if not seeds:
        raise _ronap.ConfigError("seeds is empty: give at least one seed")
    block = checked_int("block", block, least=1, below=2**31)
    retries = checked_int("retries", retries, below=1000)
    if not cpus_per_task > 0:
        raise _ronap.ConfigError(f"cpus_per_task = {cpus_per_task!r}: must be above 0")
    checked = checked_config(config, fields, scenario)
    _check_single_robot(checked)
    _ronap.check_policy(policy, checked, seeds)
    payload = _payload(policy)
    if not ray.is_initialized():
        started = time.perf_counter()
        _init(address)
        if progress:  # Ray's start is not the run's: the summary's wall time leaves it out
            how = "started a local Ray instance" if address is None else f"joined the Ray cluster at {address}"
            print(f"{how} in {time.perf_counter() - started:.1f} s", file=sys.stderr)
    remote = ray.remote(_block).options(num_cpus=cpus_per_task, max_retries=retries)
    blocks = [seeds[i : i + block] for i in range(0, len(seeds), block)]
    temporary = tempfile.TemporaryDirectory(prefix="ronap-ray-") if out is None else None
    directory = temporary.name if temporary is not None else os.fspath(out)  # type: ignore[arg-type]
    threads = max(1, int(ray.cluster_resources().get("CPU", 1)))
    run = _ronap.BlockRun(directory, policy, seeds, checked, maze_seed=maze_seed, map_path=map, threads=threads, force=force)
    start = time.perf_counter()
    # A window of tasks under way: enough to keep every CPU busy, few enough that finished blocks
    # waiting for an earlier one stay few.
    window = max(2, int(2 * threads / cpus_per_task))
    pending: dict[Any, int] = {}
    done: dict[int, list[Any]] = {}
    submitted = written = 0
    error: BaseException | None = None
    try:
        while written < len(blocks):
            while submitted < len(blocks) and len(pending) < window:
                ref = remote.remote(payload, blocks[submitted], checked.json, maze_seed, map)
                pending[ref] = submitted
                submitted += 1
            ready, _ = ray.wait(list(pending), num_returns=1)
            k = pending.pop(ready[0])
            done[k] = ray.get(ready[0])
            while written in done:
                run.add(done.pop(written))
                written += 1
                if progress:
                    finished = sum(len(b) for b in blocks[:written])
                    print(f"\r{finished}/{len(seeds)} episodes", end="", file=sys.stderr, flush=True)
    except BaseException as e:  # a failed task or an interrupt: keep what came, in order
        error = e
        for ref in pending:
            ray.cancel(ref, force=True)
    finally:
        if progress:
            print(file=sys.stderr)
        summary, table = run.finish(time.perf_counter() - start)
        if temporary is not None:
            temporary.cleanup()
    if error is not None:
        cause = getattr(error, "cause", None)
        if isinstance(cause, _ronap.RonapError):
            raise cause from None
        raise error
    return {"summary": summary, "table": table, "out": None if temporary is not None else directory}


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(
        prog="python -m ronap.ray",
        description="Runs a policy over a seed range as Ray tasks and writes one run directory, as `ronap run` would.",
        formatter_class=argparse.ArgumentDefaultsHelpFormatter,
    )
    p.add_argument("--policy", required=True, help="a built-in policy (apf, geodesic, random, ...) or mlp:FILE")
    p.add_argument("--seeds", type=int, default=1000, help="how many seeds")
    p.add_argument("--seed-start", type=int, default=0, help="the first seed (with --split, counted from the split's first)")
    p.add_argument("--split", choices=("test", "validation", "train"), default=None, help="play a named split's seeds, as ronap run --split")
    p.add_argument("--out", required=True, help="the run directory to write")
    p.add_argument(
        "--address", default=None, help="the Ray cluster to join (auto: the one this machine is in); none: start a local one on 127.0.0.1"
    )
    p.add_argument("--block", type=int, default=1000, help="seeds per Ray task")
    p.add_argument("--cpus-per-task", type=float, default=1, help="CPUs each task asks for and runs on")
    p.add_argument("--retries", type=int, default=3, help="times a task whose worker died is run again")
    p.add_argument("--scenario", default=None, help="a scenario file, as ronap run --scenario")
    p.add_argument("--maze-seed", type=int, default=None, help="one maze for every episode")
    p.add_argument("--map", default=None, help="an image or ROS map file (same path on every machine)")
    args = p.parse_args(argv)
    import ray

    ours = not ray.is_initialized()
    try:
        result = evaluate(
            args.policy,
            range(args.seed_start, args.seed_start + args.seeds),
            out=args.out,
            block=args.block,
            address=args.address,
            cpus_per_task=args.cpus_per_task,
            retries=args.retries,
            scenario=args.scenario,
            maze_seed=args.maze_seed,
            map=args.map,
            progress=True,
            split=args.split,
        )
    except _ronap.RonapError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2 if isinstance(e, _ronap.ConfigError) else 1
    else:
        print(result["table"], flush=True)
        return 0
    finally:
        # Ray's own shutdown at exit first sleeps 0.5 s for logs the driver does not show.
        if ours and ray.is_initialized():
            ray.shutdown()


if __name__ == "__main__":
    sys.exit(main())
