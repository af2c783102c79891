"""Every build of the step kernel gives the same bits (softgym/engine/_dispatch.py).

setup.py builds the kernel for the portable instruction set and for newer
x86-64 levels; the one the CPU runs best is used. Each build is run here on the
same bodies (both presets, self-collision on, large-angle links from a drop)
and its whole final state compared bit for bit with the portable build's.
"""

import os
import subprocess
import sys

import numpy as np
import pytest
from engine_builders import reference_robot, two_material_body

import softgym.engine.simulation as simulation
from softgym.design import default_walker
from softgym.engine import SimConfig, Simulation, available_kernels, kernel_build
from softgym.engine._dispatch import load_kernel
from softgym.exceptions import InvalidParameterError


def _final_state(model):
    grid = np.ones((3, 2, 2), dtype=np.int32)
    grid[2] = 2
    # the walker dropped from 3 voxel lengths: its links go through the large-angle mode
    bodies = [reference_robot(4), two_material_body(grid),
              default_walker().to_body(origin=(0.0, 0.0, 0.03))]  # fmt: skip
    sim = Simulation(bodies, SimConfig(model=model, self_collision=True), n_threads=1)
    sim.run(0.4)
    return sim.get_state()


@pytest.mark.parametrize("model", ["seed", "corotational"])
def test_every_kernel_build_gives_the_portable_builds_bits(monkeypatch, model):
    kernels = available_kernels()
    assert kernels[0] == "baseline"
    results = {}
    for name in kernels:
        monkeypatch.setattr(simulation, "_core", load_kernel(name)[1])
        results[name] = _final_state(model)
    ref = results["baseline"]
    for name, state in results.items():
        assert state.keys() == ref.keys()
        for key in ref:
            assert np.array_equal(state[key], ref[key], equal_nan=True), (name, key)


def test_the_newest_available_build_is_used_and_a_missing_one_is_refused():
    assert kernel_build() == available_kernels()[-1]
    with pytest.raises(InvalidParameterError, match="must be one of"):
        load_kernel("avx9000")


def test_softgym_kernel_forces_a_build_in_a_new_process():
    code = "import softgym.engine as e; print(e.kernel_build())"
    env = {**os.environ, "SOFTGYM_KERNEL": "baseline"}
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         env=env, timeout=120, check=True).stdout.strip()  # fmt: skip
    assert out == "baseline"
