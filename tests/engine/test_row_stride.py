"""Rows that a kernel pass reads together lie apart in the cache at every batch size.

The forces pass reads 20 rows of per-link constants and memory at once (c_seed,
link_last; k_seed32 in single precision). With the batch's link count as their row
stride, a batch of 256 reference robots (138,240 links) put every row a multiple of
4096 bytes from the others, all in one set of the 8-way L1, and the batch ran at
two thirds of one robot's speed per voxel. ``_bind.row_stride`` pads the rows; these
tests guard the rule, the layout that uses it and that state I/O keeps it.
"""

import numpy as np
import pytest
from engine_builders import reference_robot
from hypothesis import given
from hypothesis import strategies as st

from softgym.engine import SimConfig, Simulation, _bind


@given(st.integers(min_value=0, max_value=10**7))
def test_row_stride_puts_rows_an_odd_number_of_lines_apart(n):
    s = _bind.row_stride(n)
    assert n <= s < n + 48
    assert s % 16 == 0 and (s // 16) % 2 == 1
    # float64 rows an odd multiple of 128 bytes apart, float32 of 64: the first 32
    # rows of either fall in distinct sets of a 64-set cache (4096-byte way)
    for itemsize in (8, 4):
        sets = {(k * s * itemsize // 64) % 64 for k in range(32)}
        assert len(sets) == 32


@pytest.mark.parametrize("precision", ["double", "single"])
def test_link_rows_are_padded_views_and_state_io_keeps_them(precision):
    # 128 robots of 12 links: 1536 links, 3 pages per float64 row unpadded
    cfg = SimConfig(link_precision=precision)
    sim = Simulation([reference_robot(2)] * 128, cfg, n_threads=1)
    n = sim.n_links
    assert n == 128 * 12 and (n * 8) % 4096 == 0
    names = ("link_last", "k_seed32") if precision == "single" else ("link_last", "c_seed")
    a = sim._a
    for name in names:
        arr = a[name]
        assert arr.shape[1] == n
        assert arr.strides == (_bind.row_stride(n) * arr.itemsize, arr.itemsize)
    sim.advance(0.05)
    state = sim.get_state()
    assert state["link_last"].shape == (n, 9)
    assert np.abs(state["link_last"]).max() > 0
    sim.advance(0.05)
    after = sim.get_state()["link_last"]
    sim.set_state(state)  # back, in place: the padded rows stay
    assert a["link_last"].strides[0] == _bind.row_stride(n) * a["link_last"].itemsize
    np.testing.assert_array_equal(sim.get_state()["link_last"], state["link_last"])
    sim.advance(0.05)
    np.testing.assert_array_equal(sim.get_state()["link_last"], after)  # resumed exactly
    sim.reset()
    assert a["link_last"].strides[0] == _bind.row_stride(n) * a["link_last"].itemsize
    assert not np.any(sim.get_state()["link_last"])


@pytest.mark.parametrize("precision", ["double", "single"])
def test_padding_changes_no_bit(precision):
    # the same robots with their link rows unpadded (contiguous copies, as an older
    # layout had them) and padded step to the same bits
    bodies = [reference_robot(3)] * 3
    cfg = SimConfig(link_precision=precision)
    sims = [Simulation(bodies, cfg, n_threads=1) for _ in range(2)]
    for name in ("link_last", "c_seed" if precision == "double" else "k_seed32"):
        sims[1]._a[name] = np.ascontiguousarray(sims[1]._a[name])
    for sim in sims:
        sim.advance(0.2)
    for key in ("pos", "quat", "link_last"):
        np.testing.assert_array_equal(sims[0].get_state()[key], sims[1].get_state()[key])


@pytest.mark.parametrize(("precision", "name"), [("double", "c_seed"), ("single", "k_seed32")])
def test_kernel_refuses_link_rows_of_two_strides(precision, name):
    sim = Simulation([reference_robot(2)] * 2, SimConfig(link_precision=precision), n_threads=1)
    sim._a[name] = np.ascontiguousarray(sim._a[name])  # link_last stays padded
    with pytest.raises(ValueError, match="one row stride"):
        sim.advance(0.01)
