"""The engine's contact sensor: gaps to the floor, boxes, objects and the robot itself; it changes nothing."""

import numpy as np

from softgym.design import RobotDesign, default_walker
from softgym.engine import SimConfig, Simulation


def _settled(designs, terrain=None, seconds=1.0):
    sim = Simulation(designs, config=SimConfig(), terrain=terrain, n_threads=1)
    sim.advance(seconds)
    return sim


def test_bottom_voxels_touch_the_floor_and_the_rest_do_not():
    sim = _settled([default_walker()])
    L = sim.config.voxel_size
    gaps = sim.contact_gaps(cap=0.5 * L)
    z = sim.grid_index(0)[:, 2]
    assert np.all(gaps[z == 0] < 0.02 * L)  # resting on the floor (its penalty: a small overlap)
    assert np.all(gaps[z >= 2] > 0.1 * L)
    assert gaps.max() <= 0.5 * L


def _reference(sim, r, terrain, cap):
    # the same gaps from the public views, pair by pair in numpy
    L = sim.config.voxel_size
    p, s, gi = sim.positions(r), sim.scales(r), sim.grid_index(r)
    occ = {tuple(g) for g in gi}
    surface = np.array([sum((tuple(g + d) in occ) for d in np.vstack([np.eye(3, dtype=int),
                        -np.eye(3, dtype=int)])) < 6 for g in gi])  # fmt: skip
    out = np.full(len(p), cap)
    boxes = terrain.as_array(L) if terrain is not None else np.zeros((0, 6))
    op, osz = sim.object_positions(r), sim.object_scales(r)
    for i in np.flatnonzero(surface):
        h = s[i] / 2
        g = [cap, p[i, 2] - h if (terrain is None or terrain.floor) else cap]
        for b in boxes:
            d = np.maximum(np.maximum(b[:3] - p[i], p[i] - b[3:]), 0.0)
            dist = np.linalg.norm(d)
            g.append(dist - h if dist > 0 else -min(np.min(p[i] - b[:3]), np.min(b[3:] - p[i])) - h)
        g += list(np.linalg.norm(op - p[i], axis=1) - h - osz / 2)
        far = (np.abs(gi - gi[i]).sum(axis=1) > 3) & surface
        g += list(np.linalg.norm(p[far] - p[i], axis=1) - h - s[far] / 2)
        out[i] = min(g)
    return np.minimum(out, cap)


def test_gaps_equal_a_pairwise_reference_on_boxes_objects_and_a_bent_body():
    from softgym.tasks import get_task

    for name in ("rough", "push", "carry"):
        task = get_task(name)
        d = default_walker()
        terrain = task.terrain_for(d.shape)
        sim = Simulation([d], config=task.config(), terrain=terrain, n_threads=1)
        sim.advance(2.0)  # walking: bent, on boxes, against the object
        L = sim.config.voxel_size
        got = sim.contact_gaps(cap=0.3 * L)
        want = _reference(sim, 0, terrain, 0.3 * L)
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-12, err_msg=name)
        assert (got < 0.05 * L).any()


def test_reading_the_sensor_changes_no_result():
    a = Simulation([default_walker()] * 2, n_threads=1)
    b = Simulation([default_walker()] * 2, n_threads=1)
    for _ in range(5):
        a.advance(0.1)
        a.contact_gaps()
        b.advance(0.1)
    assert np.array_equal(a.all_positions, b.all_positions)
    # one robot alone or in a batch, 1 or 2 threads: the same gaps
    np.testing.assert_array_equal(a.contact_gaps(n_threads=2)[: a.voxel_offsets[1]],
                                  _settled([default_walker()], seconds=0.5).contact_gaps())  # fmt: skip


def test_own_voxels_count_beyond_three_lattice_steps():
    # no floor, no gravity: a straight bar; only voxels more than 3 steps apart count
    grid = np.full((6, 1, 1), 2, dtype=np.int8)
    sim = Simulation([RobotDesign(grid)], config=SimConfig(floor=False, gravity=0.0), n_threads=1)
    L = sim.config.voxel_size
    gaps = sim.contact_gaps(cap=10 * L)
    np.testing.assert_allclose(gaps / L, [3, 3, 10, 10, 3, 3], rtol=0, atol=1e-9)


def test_the_sweep_order_kept_between_calls_never_changes_the_gaps():
    from softgym.tasks import get_task

    task = get_task("push")
    sim = Simulation([default_walker()] * 3, config=task.config(),
                     terrain=task.terrain_for((6, 6, 6)), n_threads=2)  # fmt: skip
    sim.advance(1.5)
    L = sim.config.voxel_size
    first = sim.contact_gaps(cap=0.3 * L)  # sorts from the lattice order
    again = sim.contact_gaps(cap=0.3 * L)  # from the sorted one
    fresh = Simulation([default_walker()] * 3, config=task.config(),
                       terrain=task.terrain_for((6, 6, 6)), n_threads=1)  # fmt: skip
    fresh.advance(1.5)
    np.testing.assert_array_equal(first, again)
    np.testing.assert_array_equal(first, fresh.contact_gaps(cap=0.3 * L))
