"""One step of Optimal Reciprocal Collision Avoidance, as ronap's pedestrians and ``orca`` policy
compute it: RVO2's algorithm, held to RVO2 itself (the ``pyrvo`` bindings) to 1e-6."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from . import _ronap


def orca_step(
    agents: Any,
    obstacles: Sequence[Sequence[Sequence[float]]] = (),
    *,
    neighbour_dist: float,
    max_neighbours: int,
    time_horizon: float,
    time_horizon_obstacles: float,
    time_step: float = 1.0,
    precision: str = "f64",
) -> dict[str, Any]:
    """The new velocity of every agent after one ORCA step, all from the same state, as RVO2's
    ``doStep`` computes it (with the same settings RVO2's ``RVOSimulator`` takes).

    ``agents``: an array of rows ``[x, y, vx, vy, radius, max_speed, preferred_vx, preferred_vy]``.
    ``obstacles``: polygons, each a list of ``[x, y]`` corners counter-clockwise (RVO2's order).
    ``precision``: ``"f64"`` (what the simulation uses) or ``"f32"`` (RVO2's own float: the
    same velocities as RVO2).

    Returns ``{"velocities": (n, 2) array, "agent_neighbours": [[j, ...], ...],
    "obstacle_neighbours": [[edge, ...], ...]}``, neighbours nearest first as RVO2 chooses them.
    """
    if precision not in ("f64", "f32"):
        raise ValueError(f"precision = {precision!r}: must be 'f64' or 'f32'")
    rows = np.asarray(agents, dtype=np.float64).reshape(-1, 8)
    polygons = [[[float(x), float(y)] for x, y in polygon] for polygon in obstacles]
    settings = (
        float(neighbour_dist),
        int(max_neighbours),
        float(time_horizon),
        float(time_horizon_obstacles),
        float(time_step),
    )
    velocities, near, edges = _ronap.orca_step(rows.tolist(), polygons, settings, precision == "f32")
    return {
        "velocities": np.asarray(velocities, dtype=np.float64).reshape(-1, 2),
        "agent_neighbours": near,
        "obstacle_neighbours": edges,
    }
