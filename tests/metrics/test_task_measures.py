"""The task measures (softgym/metrics/task_measures.py) on hand-made samples with known answers.

The measures of the seed's suite (push, gap, yaw, peak height, footprint gain, swim,
carry) are checked in tests/tasks/test_suite.py; these are the ones the suite's second
half added: climbing, a goal, staying on top, thrown, caught and lifted objects, shrinking.
"""

import re

import numpy as np
import pytest

import softgym
from softgym.exceptions import InvalidParameterError
from softgym.metrics import TASK_MEASURES, WORST_FITNESS, task_measure_from_arrays
from softgym.metrics import task_measures as module

L = 0.01
N_AUX = len(softgym.engine.AUX_NAMES)


def _aux(obj=(0.0, 0.0, 0.0), box=(0.0, 0.0, 0.0, 0.0)):
    """One sample of the auxiliary measures: the object's centre of mass and the voxel-centre box."""
    out = np.zeros(N_AUX)
    out[0:3] = obj
    out[3:5] = (1.0, 0.0)  # heading +x
    out[5:9] = box  # x lo, x hi, y lo, y hi
    return out


def _measure(name, cm, aux=None, valid=None, params=None, diverged=None):
    """The measure of one robot from its samples (cm in voxel lengths; the first is the reference)."""
    cm = np.asarray(cm, dtype=np.float64)[None] * L
    aux = (
        np.zeros((1, cm.shape[1], N_AUX))
        if aux is None
        else np.asarray(aux, dtype=np.float64)[None]
    )
    ok = np.ones(cm.shape[:2], dtype=bool) if valid is None else np.asarray(valid, dtype=bool)[None]
    out = task_measure_from_arrays(name, cm[:, 0], aux[:, 0], cm, aux, ok, L, params, diverged)
    return float(out[0])


def test_z_progress_is_the_signed_rise_of_the_end():
    assert _measure("z_progress", [[3, 3, 2.7], [2, 3, 5.0], [1, 3, 4.7]]) == pytest.approx(2.0)
    assert _measure("z_progress", [[3, 3, 2.7], [3, 3, 1.7]]) == pytest.approx(-1.0)


def test_target_progress_is_how_much_nearer_the_centre_of_mass_got():
    target = {"target": np.array([[-7.0, 3.0]])}
    # from 10 to 7 voxel lengths of the target: 3 nearer
    assert _measure("target_progress", [[3, 3, 2.7], [0, 3, 2.7]], params=target) == pytest.approx(
        3.0
    )
    # 4 across from the start at (3, 3): sqrt(100 + 16) from it, farther than 10
    side = _measure("target_progress", [[3, 3, 2.7], [3, 7, 2.7]], params=target)
    assert side == pytest.approx(10.0 - np.hypot(10.0, 4.0))
    with pytest.raises(InvalidParameterError, match="target"):
        _measure("target_progress", [[0, 0, 0], [1, 0, 0]])


def test_top_dist_counts_only_the_samples_still_on_top():
    on_then_off = [[3, 3, 2.5], [1, 3, 2.5], [0, 3, 1.0], [-4, 3, -0.5], [-9, 3, -17.0]]
    assert _measure("top_dist", on_then_off) == pytest.approx(3.0)  # the fall's 12 do not count
    assert _measure("top_dist", [[3, 3, 2.5], [3, 7, 2.5]]) == pytest.approx(
        4.0
    )  # any xy direction
    assert _measure("top_dist", [[3, 3, -1.0], [9, 3, -1.0]]) == 0.0  # never on top
    # an invalid sample (before the reference) is not counted
    assert _measure("top_dist", on_then_off, valid=[True, False, True, True, True]) == 3.0


def test_time_on_top_is_the_fraction_of_valid_samples_above_z_0():
    cm = [[3, 3, 1.6], [3, 3, 1.5], [4, 3, 0.2], [5, 3, -3.0]]
    assert _measure("time_on_top", cm) == pytest.approx(0.75)
    assert _measure("time_on_top", cm, valid=[True, True, False, False]) == 1.0
    assert _measure("time_on_top", [[3, 3, -1.0], [3, 3, -2.0]]) == 0.0


def test_object_measures_thrown_caught_and_lifted():
    start = _aux(obj=(3 * L, 3 * L, 7 * L))
    thrown = [start, _aux(obj=(6 * L, 7 * L, 1 * L))]
    cm = [[3, 3, 2.7], [3, 3, 2.7]]
    assert _measure("object_dist", cm, thrown) == pytest.approx(5.0)  # a 3-4-5 throw
    assert _measure("object_height", cm, thrown) == pytest.approx(1.0)  # on the floor
    lifted = [start, _aux(obj=(3 * L, 3 * L, 9.5 * L)), _aux(obj=(3 * L, 3 * L, 8 * L))]
    cm3 = [[3, 3, 2.7]] * 3
    assert _measure("object_rise", cm3, lifted) == pytest.approx(2.5)  # the peak, not the end
    assert _measure("object_height", cm3, lifted) == pytest.approx(8.0)
    sunk = [start, _aux(obj=(3 * L, 3 * L, 6.5 * L))]
    assert _measure("object_rise", cm, sunk) == 0.0


def test_footprint_loss_is_the_smallest_footprint_below_the_start():
    cm = [[3, 3, 2.7]] * 3
    # footprints (x_hi - x_lo + 1)(y_hi - y_lo + 1): 6 x 6 = 36, then 5 x 6 = 30, then 6 x 7 = 42
    boxes = [_aux(box=(0.5 * L, 5.5 * L, 0.5 * L, 5.5 * L)), _aux(box=(1 * L, 5 * L, 0.5 * L, 5.5 * L)),
             _aux(box=(0.5 * L, 5.5 * L, 0 * L, 6 * L))]  # fmt: skip
    assert _measure("footprint_loss", cm, boxes) == pytest.approx(6.0)
    assert _measure("footprint_gain", cm, boxes) == pytest.approx(6.0)
    assert _measure("footprint_loss", cm[:2], [boxes[0], boxes[2]]) == 0.0


@pytest.mark.parametrize("name", sorted(TASK_MEASURES))
def test_every_measure_is_documented_and_a_diverged_robot_gets_the_worst(name):
    assert re.search(rf"^``{name}``\s", module.__doc__, re.M), (
        f"{name} is not in the module's table"
    )
    params = {"target": np.zeros((1, 2)), "center": np.zeros((1, 2)), "edge": np.zeros(1)}
    cm = [[3, 3, 2.7], [2, 3, 2.7]]
    value = _measure(name, cm, params=params)
    assert np.isfinite(value)
    assert _measure(name, cm, params=params, diverged=[True]) == WORST_FITNESS
