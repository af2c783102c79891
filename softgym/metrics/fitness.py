"""The seed's fitness measures (docs/PHYSICS.md).

Each measure comes twice: a ``*_from_arrays`` function on plain arrays, and
a function on a :class:`~softgym.engine.rollout.Rollout` vectorised over its
robots. Distances are in voxel lengths (divided by the voxel size L), times
in seconds of simulated time counted from t = 0 (settling included).

Diverged robots (``rollout.diverged``) get :data:`WORST_FITNESS`, the seed's
worst value for a maximised objective.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np

from softgym.design.material import BONE_IDS, MUSCLE_IDS, OBSTACLE_IDS, OLD_MATERIAL_IDS, TISSUE_IDS
from softgym.design.robot import RobotDesign
from softgym.exceptions import InvalidParameterError
from softgym.validate import positive

if TYPE_CHECKING:  # only for annotations: softgym.engine's __init__ loads compiled code
    from softgym.engine.rollout import Rollout

__all__ = [
    "L_TOLERANCE",
    "WALK_METRICS",
    "WORST_FITNESS",
    "WORST_MINIMIZED",
    "Composition",
    "LCoefficient",
    "composition_counts",
    "dilute",
    "l_coefficient",
    "l_coefficient_details",
    "l_coefficient_from_arrays",
    "l_coefficients_from_arrays",
    "max_xy_dist",
    "max_xy_dist_from_arrays",
    "norm_final_dist",
    "norm_final_dist_from_arrays",
    "walk_metrics",
    "walk_metrics_from_arrays",
]

#: Worst value of a maximised objective (the seed's ``-10e6``), given to invalid or diverged robots.
WORST_FITNESS = -1e7
#: Worst value of a minimised objective (the seed's ``+10e6``).
WORST_MINIMIZED = 1e7
#: Tolerance (voxel lengths) of the L coefficient's "maximum reached" test: the seed's 0.1.
L_TOLERANCE = 0.1
#: The walking measures every task reports (maximised; diverged robots get :data:`WORST_FITNESS`).
WALK_METRICS: tuple[str, ...] = ("norm_final_dist", "max_xy_dist", "l_coefficient")


def _xy_offset(cm_init, cm_final, voxel_size: float) -> np.ndarray:
    a = np.asarray(cm_init, dtype=np.float64)
    b = np.asarray(cm_final, dtype=np.float64)
    if a.shape != b.shape or a.shape[-1:] != (3,):
        raise InvalidParameterError(
            f"cm_init and cm_final must have the same shape (..., 3), got {a.shape} and {b.shape}"
        )
    return (b[..., :2] - a[..., :2]) / positive("voxel_size", voxel_size)


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


def l_coefficients_from_arrays(
    cm_init,
    cm_final,
    trace_cm,
    trace_t,
    voxel_size: float,
    end_time,
    valid=None,
    tolerance: float = L_TOLERANCE,
) -> tuple[np.ndarray, np.ndarray]:
    """Ev-SoftBots' L coefficient of many robots at once (the one implementation of it).

    ``MaxXYDist = max(|x_end - x_0|, |y_end - y_0|) / L``; ``timeMaxReached``
    is the first sample time ``t_k > 0`` with
    ``| |x_k - x_0| / L - MaxXYDist | < tolerance`` or the same in y, else
    ``end_time``; ``LCoefficient = MaxXYDist * (MaxXYDist / timeMaxReached)``
    (``VX_SimGA.cpp``).

    Parameters
    ----------
    cm_init, cm_final : array_like of shape (n, 3), float64
        Centre of mass (m) at the reference time and at the end.
    trace_cm : array_like of shape (n, k, 3), float64
        Centre-of-mass samples (m), in time order.
    trace_t : array_like of shape (n, k), float64
        Their times (s, from t = 0).
    voxel_size : float
        Lattice dimension L (m).
    end_time : array_like of shape (n,), float64
        Time (s) at the end of each run, used when no sample qualifies; must be > 0
        where that happens.
    valid : array_like of shape (n, k), bool, optional
        Samples that count (default all): e.g. ``t >= init_time``.
    tolerance : float
        In voxel lengths (:data:`L_TOLERANCE`, the seed's 0.1).

    Returns
    -------
    l_coefficient : ndarray of shape (n,), float64
        Voxel lengths^2 per second.
    time_max_xy_dist : ndarray of shape (n,), float64
        ``timeMaxReached`` (s).
    """
    L = positive("voxel_size", voxel_size)
    x0 = np.asarray(cm_init, dtype=np.float64).reshape(-1, 3)
    n = x0.shape[0]
    m = np.asarray(max_xy_dist_from_arrays(x0, np.reshape(cm_final, (-1, 3)), L)).reshape(n)
    tc = np.asarray(trace_cm, dtype=np.float64).reshape(n, -1, 3)
    tt = np.asarray(trace_t, dtype=np.float64).reshape(n, -1)
    t_max = np.array(np.broadcast_to(np.asarray(end_time, dtype=np.float64), (n,)))
    if tt.shape[1]:
        with np.errstate(invalid="ignore"):  # frozen (diverged) robots may hold non-finite samples
            dx = np.abs(tc[..., 0] - x0[:, 0, None]) / L
            dy = np.abs(tc[..., 1] - x0[:, 1, None]) / L
            close = (np.abs(dx - m[:, None]) < tolerance) | (np.abs(dy - m[:, None]) < tolerance)
        close &= tt > 0  # t = 0 cannot be divided by
        if valid is not None:
            close &= np.asarray(valid, dtype=bool).reshape(n, -1)
        hit = close.any(axis=1)
        first = np.argmax(close, axis=1)
        t_max = np.where(hit, tt[np.arange(n), first], t_max)
    with np.errstate(invalid="ignore", divide="ignore"):
        speed = m / t_max
    return m * speed, t_max


def l_coefficient_from_arrays(
    cm_init,
    cm_final,
    trace,
    voxel_size: float,
    end_time: float,
    tolerance: float = L_TOLERANCE,
) -> LCoefficient:
    """Ev-SoftBots' L coefficient of one robot, exactly as ``VX_SimGA.cpp`` computes it.

    One robot of :func:`l_coefficients_from_arrays` (see it for the definition).

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
    L = positive("voxel_size", voxel_size)
    end_time = positive("end_time", end_time)
    m = float(max_xy_dist_from_arrays(cm_init, cm_final, L))
    tr = np.asarray(trace, dtype=np.float64).reshape(-1, 4) if np.size(trace) else np.zeros((0, 4))
    lc, t_max = l_coefficients_from_arrays(
        cm_init, cm_final, tr[None, :, :3], tr[None, :, 3], L, end_time, tolerance=tolerance
    )
    t = float(t_max[0])
    return LCoefficient(max_xy_dist=m, time_max_xy_dist=t, speed=m / t, l_coefficient=float(lc[0]))


def walk_metrics_from_arrays(
    cm_init,
    cm_final,
    trace_cm,
    trace_t,
    voxel_size: float,
    end_time,
    diverged=None,
    valid=None,
    tolerance: float = L_TOLERANCE,
) -> dict[str, np.ndarray]:
    """The seed's walking measures of many robots from plain arrays.

    Parameters
    ----------
    cm_init, cm_final, trace_cm, trace_t, voxel_size, end_time, valid, tolerance
        As for :func:`l_coefficients_from_arrays`.
    diverged : array_like of shape (n,), bool, optional
        Robots that get :data:`WORST_FITNESS` (and an infinite ``time_max_xy_dist``).

    Returns
    -------
    dict of str to ndarray of shape (n,)
        ``norm_final_dist``, ``max_xy_dist`` (voxel lengths), ``l_coefficient``
        (voxel lengths^2 / s), ``time_max_xy_dist`` (s) and ``diverged`` (bool).
    """
    x0 = np.asarray(cm_init, dtype=np.float64).reshape(-1, 3)
    x1 = np.asarray(cm_final, dtype=np.float64).reshape(-1, 3)
    n = x0.shape[0]
    div = np.zeros(n, dtype=bool) if diverged is None else np.asarray(diverged, dtype=bool).copy()
    with np.errstate(invalid="ignore"):
        nfd = np.asarray(norm_final_dist_from_arrays(x0, x1, voxel_size), dtype=np.float64)
        mxy = np.asarray(max_xy_dist_from_arrays(x0, x1, voxel_size), dtype=np.float64)
    end = np.array(np.broadcast_to(np.asarray(end_time, dtype=np.float64), (n,)))
    end[div] = 1.0  # never used: a diverged robot's measures are the worst
    lc, t_max = l_coefficients_from_arrays(
        x0, x1, trace_cm, trace_t, voxel_size, end, valid=valid, tolerance=tolerance
    )
    for values in (nfd, mxy, lc):
        values[div] = WORST_FITNESS
    t_max[div] = np.inf
    return {
        "norm_final_dist": nfd,
        "max_xy_dist": mxy,
        "l_coefficient": lc,
        "time_max_xy_dist": t_max,
        "diverged": div,
    }


def walk_metrics(rollout: Rollout, tolerance: float = L_TOLERANCE) -> dict[str, np.ndarray]:
    """:func:`walk_metrics_from_arrays` of a rollout: samples from ``init_time`` on, ends at ``rollout.time``.

    Returns
    -------
    dict of str to ndarray of shape (n_robots,)
        ``norm_final_dist``, ``max_xy_dist``, ``l_coefficient``, ``time_max_xy_dist``, ``diverged``.
    """
    return walk_metrics_from_arrays(
        rollout.cm_init,
        rollout.cm_final,
        rollout.cm,
        rollout.times,
        rollout.voxel_size,
        rollout.time,
        diverged=rollout.diverged,
        valid=rollout.times >= rollout.init_time,
        tolerance=tolerance,
    )


def _worst(values: np.ndarray, rollout: Rollout) -> np.ndarray:
    out = np.asarray(values, dtype=np.float64).copy()
    out[np.asarray(rollout.diverged, dtype=bool)] = WORST_FITNESS
    return out


def dilute(rollout: Rollout) -> Rollout:
    """The rollout with the seed's own centre of mass, which counts the obstacle voxels.

    The seed's engine averages over every voxel of its world, its 44 fixed wall
    voxels included (docs/PHYSICS.md), so each displacement in its obstacle
    runs is the robot's times ``m_robot / (m_robot + m_walls)`` and its
    MaxXYDist and L coefficient are computed on that diluted path. Use this to
    compare a run with the report's numbers; softgym's own metrics stay
    robot-only.

    Parameters
    ----------
    rollout : Rollout

    Returns
    -------
    Rollout
        ``cm``, ``cm_init`` and ``cm_final`` replaced by the whole-world centre
        of mass; unchanged when the rollout has no obstacle mass.
    """
    wm = rollout.obstacle_mass
    if wm is None or not np.any(wm > 0):
        return rollout
    wc = np.asarray(rollout.obstacle_cm, dtype=np.float64)
    m = np.asarray(rollout.mass, dtype=np.float64)
    tot = (m + wm)[:, None]

    def mix(cm: np.ndarray) -> np.ndarray:
        if cm.ndim == 3:
            return (m[:, None, None] * cm + wm[:, None, None] * wc[:, None, :]) / tot[:, :, None]
        return (m[:, None] * cm + wm[:, None] * wc) / tot

    return replace(rollout, cm=mix(rollout.cm), cm_init=mix(rollout.cm_init),
                   cm_final=mix(rollout.cm_final))


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


def l_coefficient_details(
    rollout: Rollout, tolerance: float = L_TOLERANCE
) -> list[LCoefficient | None]:
    """:class:`LCoefficient` of every robot (None for diverged robots).

    Uses the trace from ``rollout.init_time`` on and ``rollout.time`` as the end time.
    """
    w = walk_metrics(rollout, tolerance)
    out: list[LCoefficient | None] = []
    for i in range(rollout.n_robots):
        if w["diverged"][i]:
            out.append(None)
            continue
        m, t = float(w["max_xy_dist"][i]), float(w["time_max_xy_dist"][i])
        out.append(LCoefficient(m, t, m / t, float(w["l_coefficient"][i])))
    return out


def l_coefficient(rollout: Rollout, tolerance: float = L_TOLERANCE) -> np.ndarray:
    """The L coefficient of every robot; :data:`WORST_FITNESS` for diverged robots.

    Returns
    -------
    ndarray of shape (n_robots,), float64
        ``MaxXYDist^2 / timeMaxReached`` (voxel lengths^2 per second).
    """
    return walk_metrics(rollout, tolerance)["l_coefficient"]


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
