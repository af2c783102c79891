import numpy as np
import pytest

from softgym.design.robot import RobotDesign, default_walker
from softgym.engine.rollout import Rollout
from softgym.exceptions import InvalidParameterError
from softgym.metrics.fitness import (
    WORST_FITNESS,
    WORST_MINIMIZED,
    Composition,
    composition_counts,
    l_coefficient,
    l_coefficient_details,
    l_coefficient_from_arrays,
    max_xy_dist,
    max_xy_dist_from_arrays,
    norm_final_dist,
    norm_final_dist_from_arrays,
)

L = 0.01


def make_rollout(cm, times, cm_init, cm_final, diverged, end_time=5.0):
    cm = np.asarray(cm, dtype=float)
    n = cm.shape[0]
    return Rollout(
        times=np.asarray(times, dtype=float),
        cm=cm,
        cm_init=np.asarray(cm_init, dtype=float),
        init_reached=np.ones(n, dtype=bool),
        cm_final=np.asarray(cm_final, dtype=float),
        positions=np.zeros((n, 3)),
        orientations=np.tile([1.0, 0, 0, 0], (n, 1)),
        voxel_offsets=np.arange(n + 1, dtype=np.int64),
        grid_index=np.zeros((n, 3), dtype=np.int64),
        dt=np.full(n, 1e-3),
        steps=np.full(n, int(end_time / 1e-3)),
        time=np.full(n, end_time),
        diverged=np.asarray(diverged, dtype=bool),
        diverged_time=np.where(diverged, 2.0, np.inf),
        mass=np.ones(n),
        voxel_size=L,
        init_time=1.0,
        trace_interval=0.5,
    )


def walking_rollout():
    """Robot 0 walks +x and stops at 3 voxels; robot 1 goes diagonally; robot 2 diverged."""
    times = np.tile([0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0], (3, 1))
    x0 = [0.0, 0.0, 0.0, 0.01, 0.0295, 0.03, 0.03]  # voxels 0 0 0 1 2.95 3 3 (from t = 1)
    cm = np.zeros((3, 7, 3))
    cm[0, :, 0] = x0
    cm[1, :, 0] = np.linspace(0, 0.03, 7)
    cm[1, :, 1] = np.linspace(0, -0.04, 7)
    cm[:, :, 2] = 0.025
    cm_init = cm[:, 2].copy()
    cm_final = cm[:, -1].copy()
    return make_rollout(cm, times, cm_init, cm_final, [False, False, True], end_time=3.0)


def test_array_measures_by_hand():
    a = [0.0, 0.0, 0.01]
    b = [0.03, -0.04, 0.02]
    assert norm_final_dist_from_arrays(a, b, L) == pytest.approx(5.0)
    assert max_xy_dist_from_arrays(a, b, L) == pytest.approx(4.0)
    many = norm_final_dist_from_arrays(np.zeros((2, 3)), [[0.06, 0.08, 9.0], [0.0, 0.0, 0.0]], 0.02)
    assert many == pytest.approx([5.0, 0.0])
    with pytest.raises(InvalidParameterError, match="voxel_size"):
        norm_final_dist_from_arrays(a, b, 0.0)
    with pytest.raises(InvalidParameterError, match="same shape"):
        max_xy_dist_from_arrays(a, [0.0, 0.0], L)


def test_rollout_measures_and_diverged_robots():
    r = walking_rollout()
    # robot 1: from t=1 (1/3 of the way) to the end: dx = 2 voxels, dy = -8/3 voxels
    assert norm_final_dist(r) == pytest.approx([3.0, np.hypot(2.0, 8.0 / 3.0), WORST_FITNESS])
    assert max_xy_dist(r) == pytest.approx([3.0, 8.0 / 3.0, WORST_FITNESS])
    assert WORST_FITNESS == -1e7 and WORST_MINIMIZED == 1e7


def test_l_coefficient_by_hand():
    r = walking_rollout()
    d = l_coefficient_details(r)
    # robot 0: MaxXYDist 3; first trace time with | |dx| - 3 | < 0.1 is t = 2.0 (2.95 voxels)
    assert d[0].max_xy_dist == pytest.approx(3.0)
    assert d[0].time_max_xy_dist == 2.0
    assert d[0].speed == pytest.approx(1.5)
    assert d[0].l_coefficient == pytest.approx(4.5)
    # robot 1: y reaches 8/3 voxels only at the end sample t = 3.0
    assert d[1].time_max_xy_dist == 3.0
    assert d[1].l_coefficient == pytest.approx((8.0 / 3.0) ** 2 / 3.0)
    assert d[2] is None
    assert l_coefficient(r) == pytest.approx([4.5, (8.0 / 3.0) ** 2 / 3.0, WORST_FITNESS])


def test_l_coefficient_tolerance_and_default_time():
    init = [0.0, 0.0, 0.0]
    final = [0.05, 0.0, 0.0]  # 5 voxels
    trace = [[0.0, 0.0, 0.0, 1.0], [0.0489, 0.0, 0.0, 2.0], [0.0491, 0.0, 0.0, 3.0]]
    # 4.89 is 0.11 away (not within 0.1), 4.91 is within: t = 3
    assert l_coefficient_from_arrays(init, final, trace, L, 5.0).time_max_xy_dist == 3.0
    # nothing close enough: the end time
    res = l_coefficient_from_arrays(init, final, trace[:2], L, 4.8)
    assert res.time_max_xy_dist == 4.8 and res.l_coefficient == pytest.approx(25.0 / 4.8)
    # no trace at all
    assert l_coefficient_from_arrays(init, final, np.zeros((0, 4)), L, 5.0).speed == pytest.approx(
        1.0
    )
    # the y axis counts too
    trace_y = [[0.0, -0.03, 0.0, 1.5]]
    res = l_coefficient_from_arrays(init, [0.01, -0.03, 0.0], trace_y, L, 5.0)
    assert res.max_xy_dist == pytest.approx(3.0) and res.time_max_xy_dist == 1.5
    # a wider tolerance accepts the earlier sample
    assert (
        l_coefficient_from_arrays(init, final, trace, L, 5.0, tolerance=0.2).time_max_xy_dist == 2.0
    )


def test_composition_counts():
    g = np.zeros((4, 4, 4), dtype=np.int8)
    g[0, :, 0] = [1, 2, 2, 3]
    g[1, :, 0] = [4, 6, 7, 8]
    g[2, :, 0] = [9, 9, 5, 5]
    c = composition_counts(g)
    assert c == Composition(n_voxels=10, n_muscle=5, n_old_materials=5, n_bone=2, n_tissue=5)
    w = composition_counts(default_walker())
    assert (w.n_voxels, w.n_muscle, w.n_old_materials, w.n_bone) == (216, 180, 216, 0)
    assert composition_counts(RobotDesign(g), muscle_ids=(3,)).n_muscle == 1
    with pytest.raises(InvalidParameterError):
        composition_counts(np.full((2, 2, 2), -1))


def test_dilute_gives_the_seeds_centre_of_mass_with_its_walls():
    # the seed's CM counts its 44 one-kg wall voxels: every displacement shrinks
    # by m / (m + 44) and the metrics follow
    import numpy as np

    from softgym.design import default_walker
    from softgym.engine import Simulation
    from softgym.metrics import dilute, norm_final_dist, walk_metrics
    from softgym.terrain import Terrain

    r = Simulation([default_walker()], terrain=Terrain.fence(center=(3, 3))).run(2.0)
    assert r.obstacle_mass[0] == pytest.approx(44.0, rel=1e-12)
    d = dilute(r)
    m = r.mass[0]
    np.testing.assert_allclose(norm_final_dist(d), norm_final_dist(r) * m / (m + r.obstacle_mass[0]), rtol=1e-9)
    w = walk_metrics(d)
    assert 0 < w["max_xy_dist"][0] < walk_metrics(r)["max_xy_dist"][0]
    flat = Simulation([default_walker()]).run(0.2)
    assert flat.obstacle_mass[0] == 0.0 and dilute(flat) is flat
