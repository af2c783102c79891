"""The layout builder: pure, complete for the kernel, and what Simulation runs."""

import numpy as np
import pytest
from engine_builders import reference_robot, two_material_body

from softgym.engine import SimConfig, Simulation, _bind, contract
from softgym.engine.layout import Layout, build_layout
from softgym.terrain import Block, Terrain


def _batch():
    rng = np.random.default_rng(5)
    grid = rng.integers(0, 3, size=(4, 3, 3)).astype(np.int32)
    grid[:, 0, 0] = 1  # keep it in one piece along x
    bodies = [reference_robot(3), two_material_body(grid, period=0.3, temp_amplitude=10)]
    terrains = [
        Terrain(objects=(Block.box((6.0, 0.5, 0.0), (2, 2, 2)),), name="box"),
        Terrain.fence(inner=10, height=1, thickness=1, center=(3, 3)),
    ]
    return bodies, terrains


@pytest.mark.parametrize("model", ["seed", "corotational"])
def test_build_layout_is_complete_and_is_what_simulation_runs(model):
    bodies, terrains = _batch()
    cfg = SimConfig(model=model, self_collision=True)
    lay = build_layout(bodies, terrains, cfg)
    assert isinstance(lay, Layout)
    assert set(contract.KERNEL_ARRAYS) <= set(lay.arrays)
    a = lay.arrays
    assert a["vox_start"][-1] == a["pos"].shape[0]
    assert a["link_start"][-1] == a["v1"].shape[0]
    # each robot's links stay inside its own voxel range, sorted by axis
    for r in range(len(bodies)):
        lo, hi = a["link_start"][r], a["link_start"][r + 1]
        v = np.concatenate([a["v1"][lo:hi], a["v2"][lo:hi]])
        assert v.min() >= a["vox_start"][r] and v.max() < a["vox_start"][r + 1]
        assert np.all(np.diff(a["axis"][lo:hi]) >= 0)
        assert list(np.bincount(a["axis"][lo:hi], minlength=3)) == list(a["link_axis_count"][r])
    assert lay.own is not None  # the first terrain's block is not the robot's
    sim = Simulation(bodies, cfg, terrain=terrains)
    assert sim._settings == lay.settings
    for k, v in lay.arrays.items():
        assert sim._a[k].dtype == v.dtype and np.array_equal(sim._a[k], v), k


def test_build_layout_is_pure():
    bodies, terrains = _batch()
    before = [(b.grid.copy(), np.array(b.origin, dtype=float)) for b in bodies]
    first = build_layout(bodies, terrains, SimConfig())
    second = build_layout(bodies, terrains, SimConfig())
    for (g, o), b in zip(before, bodies):
        assert np.array_equal(g, b.grid) and np.array_equal(o, b.origin)
    for k in first.arrays:
        assert first.arrays[k].tobytes() == second.arrays[k].tobytes(), k


@pytest.mark.parametrize("precision", ["single", "double"])
def test_kernel_arrays_start_on_cache_lines_and_keep_their_row_stride(precision):
    # the kernel's vector loops access its arrays 32 or 64 bytes at a time from their
    # starts: every array begins on a 64-byte line; padded link rows keep their stride
    bodies, terrains = _batch()
    cfg = SimConfig(self_collision=True, link_precision=precision)
    a = build_layout(bodies, terrains, cfg).arrays
    for name in contract.KERNEL_ARRAYS:
        if a[name].size:
            assert a[name].ctypes.data % 64 == 0, name
    n = a["v1"].shape[0]
    for name in ("c_seed", "link_last", "k_seed32"):
        x = a[name]
        if x.size:
            assert x.shape[1] == n and x.strides == (_bind.row_stride(n) * x.itemsize, x.itemsize)
    # the copies hold the layout's values: links start in small-angle mode, quaternions
    # at the identity, each robot's first voxel where its body put it
    assert np.all(a["link_sa"] == 1) and np.all(a["quat"][:, 0] == 1.0)
    assert np.all(a["link_last"] == 0.0) and np.all(a["scale"] == cfg.voxel_size)
