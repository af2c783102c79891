"""The voxel updates' and orientation steps' vector blocks keep the scalar loops' bits.

Where a build has them (``softgym.engine._integrate.vector_blocks``: AVX-512 steps 8
voxels at a time in its voxel rows; AVX2 4 and the portable x86-64 build's SSE2 2, on
the records), both models' voxel updates and orientation steps run
blocks of voxels in vector lanes, and leave to the scalar loops the rest: a block with
a fixed voxel, one where a voxel runs away, one whose quaternion needs the exact
renormalisation, the robot's last voxels. ``set_vector_blocks(False)`` runs the scalar
loops only; each available build, in its own process, must give the same final state
bit for bit both ways on bodies that reach every one of those cases.
"""

import os
import platform
import subprocess
import sys

import pytest

from softgym.engine import available_kernels

CHILD = """
import sys
import numpy as np
from softgym.design import default_walker
from softgym.engine import Body, SimConfig, Simulation, kernel_build
from softgym.engine import _integrate

def material_block(shape, **kw):
    grid = np.ones(shape, dtype=np.int32)
    grid[shape[0] // 2:] = 2
    return Body(grid=grid, youngs_modulus=[0.0, 5e6, 5e6], density=[0.0, 1e6, 1e6],
                poisson=[0.0, 0.35, 0.35], cte=[0.0, 0.01, -0.01], mu_static=[0.0, 1.0, 1.0],
                mu_kinetic=[0.0, 0.5, 0.5], **kw)

fixed = np.zeros((3, 3, 3), dtype=bool)
fixed[1, 1, 0] = fixed[2, 0, 1] = True
walker = default_walker().to_body()
bodies = [walker, default_walker().to_body(origin=(0.0, 0.0, 0.03)),  # dropped: it slides
          material_block((3, 3, 3), fixed=fixed), material_block((5, 3, 3)),
          material_block((4, 4, 4), origin=(0.0, 0.0, 0.02))]

def run(model, precision):
    cfg = SimConfig(model=model, self_collision=True, link_precision=precision)
    sim = Simulation(bodies, cfg, n_threads=1)
    state = sim.get_state()
    # voxels spun fast enough to leave the seed's Newton renormalisation (its exact one),
    # and one that runs away in its first step
    state["angvel"][sim.voxel_offsets[3] + 5] = [400.0, -300.0, 250.0]
    state["angvel"][sim.voxel_offsets[4] + 17] = [0.0, 900.0, 0.0]
    state["vel"][sim.voxel_offsets[1] + 40] = [1e10, 0.0, 0.0]
    sim.set_state(state)
    sim.run(0.15)
    return sim.get_state()

differ = 0
arrays = 0
for model, precision in (("seed", "single"), ("seed", "double"), ("corotational", None)):
    _integrate.set_vector_blocks(True)
    a = run(model, precision)
    _integrate.set_vector_blocks(False)
    b = run(model, precision)
    assert a["diverged_code"].tolist() == [0, 2, 0, 0, 0], a["diverged_code"]
    for key in a:
        arrays += 1
        differ += not np.array_equal(a[key], b[key], equal_nan=True)
_integrate.set_vector_blocks(True)
blocks = _integrate.vector_blocks()
print(kernel_build(), blocks["seed_voxels"], blocks["corotational_voxels"], blocks["orientation"],
      differ, arrays)
"""

# the lanes each build's blocks have on x86-64 (the seed and corotational voxel updates,
# the orientation step on the records: the AVX-512 build steps the orientations in its
# voxel rows)
LANES = {"baseline": (2, 2, 2), "x86-64-v3": (4, 4, 4), "x86-64-v4": (8, 8, 0)}


@pytest.mark.parametrize("kernel", available_kernels())
def test_the_vector_blocks_give_the_scalar_loops_bits(kernel):
    env = {**os.environ, "SOFTGYM_KERNEL": kernel}
    res = subprocess.run([sys.executable, "-c", CHILD], capture_output=True, text=True,
                         env=env, timeout=300)  # fmt: skip
    assert res.returncode == 0, res.stderr[-2000:]
    name, *lanes, differ, arrays = res.stdout.split()
    assert name == kernel
    if platform.machine().lower() in ("x86_64", "amd64"):
        assert tuple(int(n) for n in lanes) == LANES[kernel]
    assert int(arrays) > 0
    assert int(differ) == 0, f"{differ} of {arrays} state arrays differ with the blocks off"
