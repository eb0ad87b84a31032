"""Scenes and policies as plain Python values."""

from __future__ import annotations

from typing import Any, Mapping

import numpy as np

from . import _ronap
from .config import checked_config


def maze_occupancy(seed: int, scale: float = 1.0, config: Mapping[str, Any] | None = None, **fields: Any) -> np.ndarray:
    """The maze of ``seed`` as a boolean array, True on walls; rows from the top like the
    picture, ``scale`` entries per px."""
    image = _ronap.maze_image(seed, checked_config(config, fields), scale)
    return (image == np.array(_ronap.WALL_RGB, dtype=np.uint8)).all(axis=2)


def maze_image(seed: int, scale: float = 1.0, config: Mapping[str, Any] | None = None, **fields: Any) -> np.ndarray:
    """The maze of ``seed`` as an RGB picture (height, width, 3), white floor and black walls."""
    return _ronap.maze_image(seed, checked_config(config, fields), scale)


def policies() -> dict[str, str]:
    """The built-in policies, name to description."""
    return dict(_ronap.builtin_policies())
