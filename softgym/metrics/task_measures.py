"""The task suite's measures beyond walking: climbing, crossing, balancing, objects, shape, swimming.

Each measure is a function of plain arrays that both :func:`softgym.evaluate`
(the engine's samples, :class:`~softgym.engine.Rollout`) and the control
episodes (:class:`softgym.tasks.EpisodeBatch`, one sample per control step)
compute the same way: the centre of mass and the kernel's auxiliary measures
(:data:`softgym.engine.AUX_NAMES`: the terrain objects' centre of mass, the
robot's heading, the bounding box of its voxel centres) at the reference
(``cm_init``, after settling) and at each sample, the last valid sample being
the end. Distances are in voxel lengths, angles in radians; diverged robots
get :data:`~softgym.metrics.WORST_FITNESS`. "On top" means the centre of mass
above z = 0: on the beam, pedestal, stones or mattress of the tasks with no
floor (their tops are at z = 0 or just below, the ground 20 voxel lengths below).

===================  ==========================================================================
measure              value (voxel lengths unless said)
===================  ==========================================================================
``x_progress``       ``(x_end - x_0) / L``: signed progress along +x (uphill on an incline)
``z_progress``       ``(z_end - z_0) / L``: signed rise of the centre of mass (climbing)
``target_progress``  how much nearer the centre of mass got to its target (xy)
``gap_crossed``      how far the robot reaches past the start platform's edge: its farthest
                     voxel centre beyond the square ``|x - c_x|, |y - c_y| <= edge`` (>= 0),
                     0 if its centre of mass ended below the platform's top (in the pit)
``top_dist``         the farthest the centre of mass got from its start (xy) over the samples
                     where it is still on top (above z = 0); 0 if none
``time_on_top``      the fraction of the samples (0 to 1) with the centre of mass on top
                     (above z = 0)
``peak_height``      the highest centre of mass over the episode above its start
``yaw``              ``|heading_end - heading_0|`` unwrapped over the samples (rad): turning
``push_progress``    how much nearer the object got to its target (xy)
``carried_dist``     the object's xy displacement, 0 unless it ends on the robot: over its
                     footprint (the box of its voxel centres) and above its centre of mass
``object_dist``      the object's xy displacement from its start to the end (thrown)
``object_height``    the object's final height: its centre of mass above z = 0 (caught)
``object_rise``      the object's highest centre of mass over the episode above its start,
                     >= 0 (lifted)
``swim_dist``        ``|cm_end - cm_0| / L`` in 3-D
``footprint_gain``   the largest footprint ``(x_hi - x_lo + L)(y_hi - y_lo + L) / L^2`` of the
                     voxel centres over the episode minus the start one (voxel lengths^2)
``footprint_loss``   the start footprint minus the smallest one over the episode, >= 0
                     (voxel lengths^2)
===================  ==========================================================================
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from softgym.exceptions import InvalidParameterError
from softgym.metrics.fitness import WORST_FITNESS

__all__ = ["TASK_MEASURES", "task_measure_from_arrays", "task_measure"]

#: The measures of :func:`task_measure_from_arrays` and the parameters each needs (per robot).
TASK_MEASURES: dict[str, tuple[str, ...]] = {
    "x_progress": (),
    "z_progress": (),
    "target_progress": ("target",),
    "gap_crossed": ("center", "edge"),
    "top_dist": (),
    "time_on_top": (),
    "peak_height": (),
    "yaw": (),
    "push_progress": ("target",),
    "carried_dist": (),
    "object_dist": (),
    "object_height": (),
    "object_rise": (),
    "swim_dist": (),
    "footprint_gain": (),
    "footprint_loss": (),
}

# columns of the auxiliary measures (softgym.engine.AUX_NAMES)
_OBJ = slice(0, 3)
_HEAD = slice(3, 5)
_XLO, _XHI, _YLO, _YHI = 5, 6, 7, 8


def _last(values: np.ndarray, valid: np.ndarray) -> np.ndarray:
    # the last valid sample of each row
    k = valid.shape[1] - 1 - np.argmax(valid[:, ::-1], axis=1)
    return values[np.arange(values.shape[0]), k]


def _footprint(aux: np.ndarray, L: float) -> np.ndarray:
    return (aux[..., _XHI] - aux[..., _XLO] + L) * (aux[..., _YHI] - aux[..., _YLO] + L) / (L * L)


def task_measure_from_arrays(
    name: str,
    cm_init,
    aux_init,
    trace_cm,
    trace_aux,
    valid,
    voxel_size: float,
    params: Mapping[str, Any] | None = None,
    diverged=None,
) -> np.ndarray:
    """One task measure of many robots from their samples.

    Parameters
    ----------
    name : str
        A key of :data:`TASK_MEASURES`.
    cm_init : array_like of shape (n, 3)
        Centre of mass at the reference (m).
    aux_init : array_like of shape (n, n_aux)
        The auxiliary measures at the reference (:data:`softgym.engine.AUX_NAMES`).
    trace_cm : array_like of shape (n, k, 3)
        Centre of mass at each sample (m); the last valid one is the end.
    trace_aux : array_like of shape (n, k, n_aux)
        The auxiliary measures at each sample.
    valid : array_like of shape (n, k), bool
        Samples that belong to the run (from the reference on); each row needs one.
    voxel_size : float
        L (m).
    params : dict of str to array_like, optional
        Per-robot parameters in voxel lengths, from the terrain's ``meta``:
        ``center`` (n, 2) and ``edge`` (n,) for ``gap_crossed``, ``target``
        (n, 2) for ``push_progress`` and ``target_progress``.
    diverged : array_like of shape (n,), bool, optional
        Robots that get :data:`~softgym.metrics.WORST_FITNESS`.

    Returns
    -------
    ndarray of shape (n,), float64

    Raises
    ------
    InvalidParameterError
        For an unknown measure or a missing parameter.
    """
    if name not in TASK_MEASURES:
        raise InvalidParameterError(f"unknown task measure {name!r}; expected one of {list(TASK_MEASURES)}")
    params = dict(params or {})
    missing = [p for p in TASK_MEASURES[name] if p not in params]
    if missing:
        raise InvalidParameterError(f"task measure {name!r} needs the parameters {missing}")
    L = float(voxel_size)
    cm0 = np.asarray(cm_init, dtype=np.float64).reshape(-1, 3)
    a0 = np.asarray(aux_init, dtype=np.float64).reshape(cm0.shape[0], -1)
    cm = np.asarray(trace_cm, dtype=np.float64)
    aux = np.asarray(trace_aux, dtype=np.float64)
    ok = np.asarray(valid, dtype=bool)
    end = _last(cm, ok)
    aend = _last(aux, ok)
    with np.errstate(invalid="ignore", divide="ignore"):
        if name == "x_progress":
            out = (end[:, 0] - cm0[:, 0]) / L
        elif name == "z_progress":
            out = (end[:, 2] - cm0[:, 2]) / L
        elif name == "target_progress":
            t = np.asarray(params["target"], dtype=np.float64).reshape(-1, 2)
            before = np.linalg.norm(cm0[:, 0:2] / L - t, axis=1)
            after = np.linalg.norm(end[:, 0:2] / L - t, axis=1)
            out = before - after
        elif name == "gap_crossed":
            c = np.asarray(params["center"], dtype=np.float64).reshape(-1, 2)
            edge = np.asarray(params["edge"], dtype=np.float64).reshape(-1)
            box = aend[:, _XLO:_YHI + 1] / L  # x lo, x hi, y lo, y hi of the voxel centres
            reach = np.max(
                np.column_stack([box[:, 1] - c[:, 0], c[:, 0] - box[:, 0],
                                 box[:, 3] - c[:, 1], c[:, 1] - box[:, 2]]), axis=1
            ) - edge  # fmt: skip
            out = np.where(end[:, 2] >= 0.0, np.maximum(reach, 0.0), 0.0)
        elif name == "top_dist":
            on = ok & (cm[:, :, 2] > 0.0)
            dist = np.linalg.norm(cm[:, :, 0:2] - cm0[:, None, 0:2], axis=2) / L
            out = np.where(on, dist, 0.0).max(axis=1)
        elif name == "time_on_top":
            on = ok & (cm[:, :, 2] > 0.0)
            out = on.sum(axis=1) / np.maximum(ok.sum(axis=1), 1)
        elif name == "peak_height":
            z = np.where(ok, cm[:, :, 2], -np.inf)
            out = np.maximum(z.max(axis=1) - cm0[:, 2], 0.0) / L
        elif name == "yaw":
            ang = np.arctan2(aux[:, :, 4], aux[:, :, 3])
            prev = np.arctan2(a0[:, 4], a0[:, 3])
            total = np.zeros(cm0.shape[0])
            # unwrapped along the valid samples, from the reference heading
            for k in range(ang.shape[1]):
                cur = np.where(ok[:, k], ang[:, k], prev)
                total += (cur - prev + np.pi) % (2 * np.pi) - np.pi
                prev = cur
            out = np.abs(total)
        elif name == "push_progress":
            t = np.asarray(params["target"], dtype=np.float64).reshape(-1, 2)
            before = np.linalg.norm(a0[:, 0:2] / L - t, axis=1)
            after = np.linalg.norm(aend[:, 0:2] / L - t, axis=1)
            out = before - after
        elif name == "carried_dist":
            moved = np.linalg.norm(aend[:, 0:2] - a0[:, 0:2], axis=1) / L
            # on the robot: over its footprint (the box of its voxel centres) and above its
            # centre of mass; a cap that slid off and lies beside it is not carried
            over = ((aend[:, 0] >= aend[:, _XLO]) & (aend[:, 0] <= aend[:, _XHI])
                    & (aend[:, 1] >= aend[:, _YLO]) & (aend[:, 1] <= aend[:, _YHI]))  # fmt: skip
            out = np.where(over & (aend[:, 2] > end[:, 2]), moved, 0.0)
        elif name == "object_dist":
            out = np.linalg.norm(aend[:, 0:2] - a0[:, 0:2], axis=1) / L
        elif name == "object_height":
            out = aend[:, 2] / L
        elif name == "object_rise":
            z = np.where(ok, aux[:, :, 2], -np.inf)
            out = np.maximum(z.max(axis=1) - a0[:, 2], 0.0) / L
        elif name == "swim_dist":
            out = np.linalg.norm(end - cm0, axis=1) / L
        elif name == "footprint_gain":
            area = np.where(ok, _footprint(aux, L), -np.inf)
            out = np.maximum(area.max(axis=1) - _footprint(a0, L), 0.0)
        else:  # footprint_loss
            area = np.where(ok, _footprint(aux, L), np.inf)
            out = np.maximum(_footprint(a0, L) - area.min(axis=1), 0.0)
    out = np.asarray(out, dtype=np.float64)
    if diverged is not None:
        out[np.asarray(diverged, dtype=bool)] = WORST_FITNESS
    out[~np.isfinite(out)] = WORST_FITNESS
    return out


def task_measure(name: str, rollout: Any, params: Mapping[str, Any] | None = None) -> np.ndarray:
    """:func:`task_measure_from_arrays` of a :class:`~softgym.engine.Rollout`.

    The samples from ``init_time`` on, then the end of the run (``cm_final``,
    ``aux_final``) unless the last sample is already at the end (counted
    once, so that a fraction of the samples, ``time_on_top``, is the same as
    an episode's of the same sampling).
    """
    if rollout.aux is None:
        raise InvalidParameterError("this rollout has no auxiliary measures (rollout.aux)")
    cm = np.concatenate([rollout.cm, rollout.cm_final[:, None, :]], axis=1)
    aux = np.concatenate([rollout.aux, rollout.aux_final[:, None, :]], axis=1)
    times = np.asarray(rollout.times, dtype=np.float64)
    n = rollout.n_robots
    at_end = np.zeros(n, dtype=bool)  # the last sample is the end, after the reference
    if times.shape[1]:
        end = np.asarray(rollout.time, dtype=np.float64).reshape(-1)
        at_end = (times[:, -1] >= end) & (times[:, -1] >= rollout.init_time)
    valid = np.concatenate([times >= rollout.init_time, ~at_end[:, None]], axis=1)
    return task_measure_from_arrays(
        name, rollout.cm_init, rollout.aux_init, cm, aux, valid, rollout.voxel_size,
        params, diverged=rollout.diverged,
    )  # fmt: skip
