"""Simulation.advance_to runs the kernel in chunks: bit-identical to one call, interruptible."""

import os
import signal
import threading
import time

import numpy as np
import pytest
from engine_builders import reference_robot, two_material_body

from softgym.engine import SimConfig, Simulation
from softgym.terrain import Terrain

BIG = 10**15  # one chunk: the whole call in one kernel call


def _bodies():
    rng = np.random.default_rng(5)
    grid = rng.integers(1, 3, size=(4, 3, 3)).astype(np.int32)
    return [reference_robot(4), two_material_body(grid, cte=0.02, period=0.3, temp_amplitude=10)]


def _assert_same(a_sim, b_sim, rollouts=True):
    # every state array, and (rollouts) the centre-of-mass traces, equal bit for bit
    a, b = a_sim.get_state(), b_sim.get_state()
    for k in a:
        np.testing.assert_array_equal(a[k], b[k], err_msg=k)
    if rollouts:
        np.testing.assert_array_equal(a_sim.rollout().cm, b_sim.rollout().cm)


@pytest.mark.parametrize("model", ["seed", "corotational"])
def test_chunked_advance_is_bit_identical_to_one_call(model):
    cfg = SimConfig(model=model, self_collision=True)
    one = Simulation(_bodies(), cfg, n_threads=2, terrain=Terrain.fence())
    one.chunk_voxel_steps = BIG
    one.advance_to(1.3)
    chunked = Simulation(_bodies(), cfg, n_threads=2, terrain=Terrain.fence())
    chunked.chunk_voxel_steps = 500  # hundreds of kernel calls
    calls = []
    chunked.advance_to(1.3, progress=calls.append)
    assert len(calls) > 50 and calls == sorted(calls) and calls[-1] == 1.3
    _assert_same(one, chunked)


@pytest.mark.skipif(os.name != "posix", reason="needs POSIX signals")
def test_sigint_stops_a_long_advance_within_a_fraction_of_a_second():
    sim = Simulation([reference_robot(6) for _ in range(4)], n_threads=1)
    timer = threading.Timer(0.3, os.kill, (os.getpid(), signal.SIGINT))
    t0 = time.perf_counter()
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            sim.advance_to(60.0)  # minutes of work uninterrupted
    finally:
        timer.cancel()
    assert time.perf_counter() - t0 < 2.0  # 0.3 s + at most a chunk (about 0.1 s), with slack
    assert 0.0 < sim.time.max() < 60.0


def _many():
    rng = np.random.default_rng(11)
    bodies = []
    for k in range(10):
        grid = rng.integers(1, 3, size=(3, 3, 2)).astype(np.int32)
        bodies.append(two_material_body(grid, cte=0.02, period=0.2 + 0.02 * k, temp_amplitude=10))
    return bodies


@pytest.mark.parametrize("threads", [1, 2])
def test_a_large_batch_advances_group_by_group_to_the_same_bits(threads):
    # 10 robots of 18 voxels; 400 voxel-steps a thread a call would give each robot
    # a few steps: with min_visit_steps = 50 the batch goes in groups of 4 robots a
    # thread, each to the end before the next
    cfg = SimConfig(self_collision=True)
    one = Simulation(_many(), cfg, n_threads=threads)
    one.chunk_voxel_steps = BIG
    one.advance_to(0.6)
    grouped = Simulation(_many(), cfg, n_threads=threads)
    grouped.chunk_voxel_steps = 400
    grouped.min_visit_steps = 50
    calls, spread = [], []

    def seen(t):
        calls.append(t)
        spread.append(float(grouped.time.max() - grouped.time.min()))

    grouped.advance_to(0.6, progress=seen)
    assert calls == sorted(calls) and calls[-1] == 0.6
    assert max(spread) > 0.5  # one group at 0.6 s while another had not started
    _assert_same(one, grouped)


@pytest.mark.parametrize("grouped", [False, True])
def test_an_interrupted_advance_goes_on_to_the_same_state(grouped):
    # a batch in chunks, stopped past 0.4 s; or in groups, stopped when the first group
    # is done and the others are not: a later call ends where one call would have
    bodies, end = (_many, 0.6) if grouped else (_bodies, 1.0)
    ref = Simulation(bodies(), n_threads=1)
    ref.advance_to(end)
    sim = Simulation(bodies(), n_threads=1)
    sim.chunk_voxel_steps = 400 if grouped else 2000
    if grouped:
        sim.min_visit_steps = 50

    def stop(t):
        if (sim.time.max() >= end) if grouped else (t > 0.4):
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        sim.advance_to(end, progress=stop)
    if grouped:
        assert sim.time.min() < end
    else:
        assert 0.4 < sim.time.max() < 1.0  # left at the end of a chunk
    sim.advance_to(end)
    _assert_same(ref, sim, rollouts=grouped)


def test_fixed_voxels_turned_at_the_start_step_alike_in_one_call_and_in_many():
    # the seed step's AVX-512 builds read positions and orientations from rows of their
    # own, refreshed at each call and kept by the voxel update: a fixed voxel's turned
    # orientation (which the update leaves as it is) and every moved position must stay
    # the records' bits over a long call, as many short calls refresh them
    rng = np.random.default_rng(3)
    grid = rng.integers(1, 3, size=(6, 4, 3)).astype(np.int32)
    fixed = rng.random(grid.shape) < 0.15
    body = two_material_body(grid, cte=0.02, period=0.3, temp_amplitude=10, fixed=fixed)
    sims = [Simulation([body], SimConfig(model="seed"), n_threads=1) for _ in range(2)]
    state = sims[0].get_state()
    q = state["quat"] + 0.01 * rng.standard_normal(state["quat"].shape)
    state["quat"] = q / np.linalg.norm(q, axis=1, keepdims=True)
    for sim in sims:
        sim.set_state(state)
    one, chunked = sims
    one.chunk_voxel_steps = BIG
    one.advance_to(0.4)
    chunked.chunk_voxel_steps = 200
    chunked.advance_to(0.4)
    assert not one.diverged.any()
    _assert_same(one, chunked)
    # the fixed voxels kept their turned orientations, bit for bit; the others turned
    kept = (one.get_state()["quat"] == state["quat"]).all(axis=1)
    assert kept.sum() == fixed.sum() > 0
