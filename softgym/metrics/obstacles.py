"""Whether a robot got past a terrain's obstacles: their xy footprint and the test of a final
centre of mass against it (voxel lengths).
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["crossed_obstacles", "final_xy", "obstacle_footprint"]


def obstacle_footprint(terrain: Any) -> tuple[float, float, float, float] | None:
    """The xy extent ``(x0, x1, y0, y1)`` (voxel lengths) of a terrain's boxes, or None without any.

    A robot whose final centre of mass lies outside it has crossed every obstacle
    (for the ``wall`` task: it is past the fence's outer face).
    """
    if not terrain.boxes:
        return None
    lo = np.array([b.lo for b in terrain.boxes], dtype=np.float64)
    hi = np.array([b.hi for b in terrain.boxes], dtype=np.float64)
    return (
        float(lo[:, 0].min()),
        float(hi[:, 0].max()),
        float(lo[:, 1].min()),
        float(hi[:, 1].max()),
    )


def final_xy(trace: np.ndarray | None, voxel_size: float) -> tuple[float, float]:
    """Final centre-of-mass (x, y) in voxel lengths of a trace (rows ``x, y, z, t`` in m and
    s); NaN without one.
    """
    if trace is None or len(trace) == 0:
        return (float("nan"), float("nan"))
    return (float(trace[-1, 0]) / voxel_size, float(trace[-1, 1]) / voxel_size)


def crossed_obstacles(xy: tuple[float, float], footprint: tuple[float, float, float, float]) -> bool:
    """Whether the point ``xy`` lies outside ``footprint`` (:func:`obstacle_footprint`)."""
    x, y = xy
    x0, x1, y0, y1 = footprint
    return bool(x < x0 or x > x1 or y < y0 or y > y1)
