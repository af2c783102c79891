"""The seed's fitness measures (SEED_REFERENCE §1.8, §2.3, §3.1, §3.6).

Each measure comes twice: a ``*_from_arrays`` function on plain arrays, and
a function on a :class:`~softgym.engine.rollout.Rollout` vectorised over its
robots. Distances are in voxel lengths (divided by the voxel size L), times
in seconds of simulated time counted from t = 0 (settling included).

Diverged robots (``rollout.diverged``) get :data:`WORST_FITNESS`, the seed's
worst value for a maximised objective.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from softgym.design.material import BONE_IDS, MUSCLE_IDS, OBSTACLE_IDS, OLD_MATERIAL_IDS, TISSUE_IDS
from softgym.design.robot import RobotDesign
from softgym.exceptions import InvalidParameterError

if TYPE_CHECKING:  # only for annotations: softgym.engine's __init__ loads compiled code
    from softgym.engine.rollout import Rollout

__all__ = [
    "WORST_FITNESS",
    "WORST_MINIMIZED",
    "Composition",
    "LCoefficient",
    "composition_counts",
    "l_coefficient",
    "l_coefficient_details",
    "l_coefficient_from_arrays",
    "max_xy_dist",
    "max_xy_dist_from_arrays",
    "norm_final_dist",
    "norm_final_dist_from_arrays",
]

#: Worst value of a maximised objective (the seed's ``-10e6``), given to invalid or diverged robots.
WORST_FITNESS = -1e7
#: Worst value of a minimised objective (the seed's ``+10e6``).
WORST_MINIMIZED = 1e7


def _positive(name: str, value: float) -> float:
    v = float(value)
    if not (np.isfinite(v) and v > 0):
        raise InvalidParameterError(f"{name} must be a finite value > 0, got {value!r}")
    return v


def _xy_offset(cm_init, cm_final, voxel_size: float) -> np.ndarray:
    a = np.asarray(cm_init, dtype=np.float64)
    b = np.asarray(cm_final, dtype=np.float64)
    if a.shape != b.shape or a.shape[-1:] != (3,):
        raise InvalidParameterError(
            f"cm_init and cm_final must have the same shape (..., 3), got {a.shape} and {b.shape}"
        )
    return (b[..., :2] - a[..., :2]) / _positive("voxel_size", voxel_size)


def norm_final_dist_from_arrays(cm_init, cm_final, voxel_size: float) -> np.ndarray | float:
    """The seed's ``NormFinalDist``: XY distance between two centre-of-mass positions.

    Parameters
    ----------
    cm_init, cm_final : array_like of shape (..., 3), float64
        Centre of mass (m) at the fitness reference time and at the end.
    voxel_size : float
        Lattice dimension L (m).

    Returns
    -------
    float or ndarray of shape (...,)
        ``sqrt(dx^2 + dy^2) / L`` (voxel lengths).
    """
    d = np.hypot(*np.moveaxis(_xy_offset(cm_init, cm_final, voxel_size), -1, 0))
    return float(d) if np.ndim(d) == 0 else d


def max_xy_dist_from_arrays(cm_init, cm_final, voxel_size: float) -> np.ndarray | float:
    """Ev-SoftBots' ``MaxXYDist``: ``max(|dx|, |dy|) / L`` of the final position (§3.6).

    This is the larger axis displacement at the end of the run, not a maximum over time.

    Parameters
    ----------
    cm_init, cm_final : array_like of shape (..., 3), float64
        Centre of mass (m) at the reference time and at the end.
    voxel_size : float
        Lattice dimension L (m).

    Returns
    -------
    float or ndarray of shape (...,)
        Voxel lengths.
    """
    d = np.abs(_xy_offset(cm_init, cm_final, voxel_size)).max(axis=-1)
    return float(d) if np.ndim(d) == 0 else d


@dataclass(frozen=True)
class LCoefficient:
    """Ev-SoftBots' L coefficient and its parts (§3.6).

    Attributes
    ----------
    max_xy_dist : float
        ``MaxXYDist`` (voxel lengths).
    time_max_xy_dist : float
        First trace time (s, from t = 0) at which either axis displacement
        was within the tolerance of ``max_xy_dist``; the end time if none.
    speed : float
        ``max_xy_dist / time_max_xy_dist`` (voxel lengths per second).
    l_coefficient : float
        ``max_xy_dist * speed``.
    """

    max_xy_dist: float
    time_max_xy_dist: float
    speed: float
    l_coefficient: float


def l_coefficient_from_arrays(
    cm_init,
    cm_final,
    trace,
    voxel_size: float,
    end_time: float,
    tolerance: float = 0.1,
) -> LCoefficient:
    """Ev-SoftBots' L coefficient of one robot, exactly as ``VX_SimGA.cpp`` computes it.

    ``MaxXYDist = max(|x_end - x_0|, |y_end - y_0|) / L``; ``timeMaxReached``
    is the first trace time ``t_k`` with
    ``| |x_k - x_0| / L - MaxXYDist | < tolerance`` or the same in y, else
    ``end_time``; ``Speed = MaxXYDist / timeMaxReached`` and
    ``LCoefficient = MaxXYDist * Speed``.

    Parameters
    ----------
    cm_init, cm_final : array_like of shape (3,), float64
        Centre of mass (m) at the reference time and at the end.
    trace : array_like of shape (n_points, 4), float64
        Rows (x, y, z, t): centre of mass (m) and absolute time (s), in time
        order (``Rollout.trace(i, since=rollout.init_time)``). May be empty.
    voxel_size : float
        Lattice dimension L (m).
    end_time : float
        Simulated time (s) at the end of the run, used when no trace point qualifies.
    tolerance : float
        In voxel lengths (0.1 in the seed).

    Returns
    -------
    LCoefficient
    """
    L = _positive("voxel_size", voxel_size)
    end_time = _positive("end_time", end_time)
    x0 = np.asarray(cm_init, dtype=np.float64)
    m = float(max_xy_dist_from_arrays(x0, cm_final, L))
    tr = np.asarray(trace, dtype=np.float64).reshape(-1, 4) if np.size(trace) else np.zeros((0, 4))
    t_max = end_time
    if tr.shape[0]:
        dx = np.abs(tr[:, 0] - x0[0]) / L
        dy = np.abs(tr[:, 1] - x0[1]) / L
        close = (np.abs(dx - m) < tolerance) | (np.abs(dy - m) < tolerance)
        hit = np.flatnonzero(close & (tr[:, 3] > 0))  # t = 0 cannot be divided by
        if hit.size:
            t_max = float(tr[hit[0], 3])
    speed = m / t_max
    return LCoefficient(max_xy_dist=m, time_max_xy_dist=t_max, speed=speed, l_coefficient=m * speed)


def _worst(values: np.ndarray, rollout: Rollout) -> np.ndarray:
    out = np.asarray(values, dtype=np.float64).copy()
    out[np.asarray(rollout.diverged, dtype=bool)] = WORST_FITNESS
    return out


def norm_final_dist(rollout: Rollout) -> np.ndarray:
    """``NormFinalDist`` of every robot of a rollout.

    Returns
    -------
    ndarray of shape (n_robots,), float64
        XY displacement of the centre of mass from ``cm_init`` (first step
        after ``init_time``) to ``cm_final``, in voxel lengths;
        :data:`WORST_FITNESS` for diverged robots.
    """
    return _worst(
        norm_final_dist_from_arrays(rollout.cm_init, rollout.cm_final, rollout.voxel_size), rollout
    )


def max_xy_dist(rollout: Rollout) -> np.ndarray:
    """``MaxXYDist`` of every robot; :data:`WORST_FITNESS` for diverged robots.

    Returns
    -------
    ndarray of shape (n_robots,), float64
    """
    return _worst(
        max_xy_dist_from_arrays(rollout.cm_init, rollout.cm_final, rollout.voxel_size), rollout
    )


def l_coefficient_details(rollout: Rollout, tolerance: float = 0.1) -> list[LCoefficient | None]:
    """:class:`LCoefficient` of every robot (None for diverged robots).

    Uses the trace from ``rollout.init_time`` on and ``rollout.time`` as the end time.
    """
    out: list[LCoefficient | None] = []
    for i in range(rollout.n_robots):
        if rollout.diverged[i]:
            out.append(None)
            continue
        out.append(
            l_coefficient_from_arrays(
                rollout.cm_init[i],
                rollout.cm_final[i],
                rollout.trace(i, since=rollout.init_time),
                rollout.voxel_size,
                float(rollout.time[i]),
                tolerance,
            )
        )
    return out


def l_coefficient(rollout: Rollout, tolerance: float = 0.1) -> np.ndarray:
    """The L coefficient of every robot; :data:`WORST_FITNESS` for diverged robots.

    Returns
    -------
    ndarray of shape (n_robots,), float64
        ``MaxXYDist^2 / timeMaxReached`` (voxel lengths^2 per second).
    """
    return np.array(
        [
            WORST_FITNESS if d is None else d.l_coefficient
            for d in l_coefficient_details(rollout, tolerance)
        ],
        dtype=np.float64,
    )


@dataclass(frozen=True)
class Composition:
    """Voxel counts of a design (the seed's size/energy objectives).

    Attributes
    ----------
    n_voxels : int
        Robot voxels (filled, obstacle ids excluded): the seed's ``num_voxels``.
    n_muscle : int
        Muscle voxels (ids 3, 4, 8, 9): the seed's ``energy``.
    n_old_materials : int
        Voxels of the seed's original materials 1-4: the ``old_materials`` objective.
    n_bone : int
        Bone voxels (id 2).
    n_tissue : int
        Passive tissue voxels (ids 1, 2, 6, 7).
    """

    n_voxels: int
    n_muscle: int
    n_old_materials: int
    n_bone: int
    n_tissue: int


def composition_counts(
    design: RobotDesign | np.ndarray,
    *,
    muscle_ids: Sequence[int] = MUSCLE_IDS,
    old_material_ids: Sequence[int] = OLD_MATERIAL_IDS,
    bone_ids: Sequence[int] = BONE_IDS,
    tissue_ids: Sequence[int] = TISSUE_IDS,
    obstacle_ids: Sequence[int] = OBSTACLE_IDS,
) -> Composition:
    """Count a design's voxels by role.

    Parameters
    ----------
    design : RobotDesign or ndarray of shape (nx, ny, nz), integer
        A design or its grid of material ids.
    muscle_ids, old_material_ids, bone_ids, tissue_ids, obstacle_ids : sequence of int
        Which ids count as what (the seed's by default).

    Returns
    -------
    Composition
    """
    grid = design.grid if isinstance(design, RobotDesign) else np.asarray(design)
    if grid.size == 0:
        return Composition(0, 0, 0, 0, 0)
    if not np.issubdtype(grid.dtype, np.integer) or grid.min() < 0:
        raise InvalidParameterError("grid must hold non-negative integer material ids")
    hist = np.bincount(grid.ravel().astype(np.intp), minlength=max(128, int(grid.max()) + 1))

    def count(ids: Sequence[int]) -> int:
        return int(hist[list(ids)].sum()) if len(ids) else 0

    return Composition(
        n_voxels=int(hist[1:].sum()) - count(obstacle_ids),
        n_muscle=count(muscle_ids),
        n_old_materials=count(old_material_ids),
        n_bone=count(bone_ids),
        n_tissue=count(tissue_ids),
    )
