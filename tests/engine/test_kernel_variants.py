"""The builds of the compiled engine agree (softgym/engine/_dispatch.py).

setup.py compiles the engine's kernel for the portable instruction set and for
newer x86-64 levels; the newest one the CPU runs is loaded. Each build runs
here in its own process (``SOFTGYM_KERNEL``) on the same bodies (both presets,
self-collision on, large-angle links from a drop). The builds that fuse
multiply-adds (x86-64-v3, v4) must give the same final state bit for bit; the
portable build, which rounds every product, must stay within rounding-level
distance of them (the bodies here are not chaotic over 0.4 s).
"""

import os
import subprocess
import sys

import numpy as np
import pytest

from softgym.engine import FUSED_KERNELS, available_kernels, kernel_build
from softgym.engine._dispatch import install
from softgym.exceptions import InvalidParameterError

CHILD = """
import sys
import numpy as np
from softgym.design import default_walker
from softgym.engine import Body, SimConfig, Simulation, kernel_build

grid = np.ones((3, 2, 2), dtype=np.int32)
grid[2] = 2
two = Body(grid=grid, youngs_modulus=[0.0, 5e6, 5e6], density=[0.0, 1e6, 1e6],
           poisson=[0.0, 0.35, 0.35], cte=[0.0, 0.01, -0.01], mu_static=[0.0, 1.0, 1.0],
           mu_kinetic=[0.0, 0.5, 0.5])
# the walker dropped from 3 voxel lengths: its links go through the large-angle mode
bodies = [two, default_walker().to_body(), default_walker().to_body(origin=(0.0, 0.0, 0.03))]
# a filled 4^3 lattice, dropped: its links along the slower axes join runs of consecutive
# voxels, which the AVX-512 geometry loads as rows (softgym_seed_rows8)
grid = np.ones((4, 4, 4), dtype=np.int32)
grid[2:] = 2
bodies.append(Body(grid=grid, youngs_modulus=[0.0, 5e6, 5e6], density=[0.0, 1e6, 1e6],
                   poisson=[0.0, 0.35, 0.35], cte=[0.0, 0.01, -0.01], mu_static=[0.0, 1.0, 1.0],
                   mu_kinetic=[0.0, 0.5, 0.5], origin=(0.0, 0.0, 0.03)))
# voxels in pairs along x (a gap after each): 16 links along x span 48 voxels, more than
# the AVX2 push's windows take (softgym_push8x2: those sides go link by link)
grid = np.zeros((24, 3, 2), dtype=np.int32)
grid[0::3] = 1
grid[1::3] = 2
bodies.append(Body(grid=grid, youngs_modulus=[0.0, 5e6, 5e6], density=[0.0, 1e6, 1e6],
                   poisson=[0.0, 0.35, 0.35], cte=[0.0, 0.01, -0.01], mu_static=[0.0, 1.0, 1.0],
                   mu_kinetic=[0.0, 0.5, 0.5], origin=(0.0, 0.1, 0.0)))
out = {}
for model in ("seed", "corotational"):
    sim = Simulation(bodies, SimConfig(model=model, self_collision=True), n_threads=1)
    sim.run(0.4)
    out.update({f"{model}/{k}": v for k, v in sim.get_state().items()})
# the seed voxel update's corner cases (with AVX-512 it steps 8 voxels at a time and leaves
# a block to its scalar loop): fixed voxels inside a block, a voxel that runs away in its
# first step (diverged_code 2), the seed's fence as its wall voxels (the lanes) and as
# boxes with surface contact (the scalar loop)
import dataclasses
from softgym.terrain import Terrain
fixed = np.zeros((3, 3, 3), dtype=bool)
fixed[1, 1, 0] = fixed[2, 0, 1] = True
grid = np.ones((3, 3, 3), dtype=np.int32)
grid[2] = 2
clamped = Body(grid=grid, youngs_modulus=[0.0, 5e6, 5e6], density=[0.0, 1e6, 1e6],
               poisson=[0.0, 0.35, 0.35], cte=[0.0, 0.01, -0.01], mu_static=[0.0, 1.0, 1.0],
               mu_kinetic=[0.0, 0.5, 0.5], fixed=fixed)
walker = default_walker().to_body()
fence = Terrain.fence(inner=10, center=(3, 3))
for model in ("seed", "corotational"):
    cfg = SimConfig(model=model, self_collision=True)
    sim = Simulation([clamped, walker, walker], cfg, n_threads=1)
    state = sim.get_state()
    state["vel"][sim.voxel_offsets[2] + 40] = [1e10, 0.0, 0.0]
    sim.set_state(state)
    sim.run(0.2)
    out.update({f"corners-{model}/{k}": v for k, v in sim.get_state().items()})
    for name, terrain in (("fence", fence),
                          ("boxes", dataclasses.replace(fence, box_contact="surface"))):
        sim = Simulation([walker], cfg, n_threads=1, terrain=terrain)
        sim.run(0.2)
        out.update({f"{name}-{model}/{k}": v for k, v in sim.get_state().items()})
np.savez(sys.argv[1], **out)
print(kernel_build())
"""


def _run(kernel, path):
    env = {**os.environ, "SOFTGYM_KERNEL": kernel}
    res = subprocess.run([sys.executable, "-c", CHILD, str(path)], capture_output=True,
                         text=True, env=env, timeout=300)  # fmt: skip
    assert res.returncode == 0, res.stderr[-2000:]
    assert res.stdout.strip() == kernel
    with np.load(path) as z:
        return {k: z[k] for k in z.files}


def test_the_fused_builds_agree_bit_for_bit_and_the_portable_one_to_rounding(tmp_path):
    kernels = available_kernels()
    assert kernels[0] == "baseline"
    ref = _run("baseline", tmp_path / "baseline.npz")
    assert any(np.abs(v).sum() > 0 for k, v in ref.items() if k.endswith("/vel"))
    for model in ("seed", "corotational"):  # the third ran away
        assert ref[f"corners-{model}/diverged_code"].tolist() == [0, 0, 2], model
    fused = None
    for name in kernels[1:]:
        assert name in FUSED_KERNELS
        state = _run(name, tmp_path / f"{name}.npz")
        assert state.keys() == ref.keys()
        if fused is None:
            fused = state
            for key in ref:
                if key.endswith(("/steps", "/diverged", "/diverged_code")):
                    assert np.array_equal(state[key], ref[key]), (name, key)
                elif key.startswith(("seed/", "corotational/")) and np.issubdtype(
                        ref[key].dtype, np.floating):  # (the corner cases vibrate: bits only)
                    np.testing.assert_allclose(state[key], ref[key], rtol=1e-6, atol=1e-9,
                                               err_msg=f"{name} {key}")  # fmt: skip
        else:
            for key in fused:
                assert np.array_equal(state[key], fused[key], equal_nan=True), (name, key)


def test_the_newest_available_build_is_used():
    if os.environ.get("SOFTGYM_KERNEL"):
        pytest.skip("SOFTGYM_KERNEL forces a build in this run")
    assert kernel_build() == available_kernels()[-1]
    assert install("baseline") == kernel_build()  # chosen once per process


def test_an_unknown_or_missing_build_is_refused_in_one_line():
    code = "import softgym.engine"
    for value, message in (("avx9000", "must be one of"),
                           ("x86-64-v4", "needs an x86-64-v4 CPU|was not built")):  # fmt: skip
        if value in available_kernels():
            continue
        env = {**os.environ, "SOFTGYM_KERNEL": value}
        res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                             env=env, timeout=120)  # fmt: skip
        assert res.returncode != 0
        assert InvalidParameterError.__name__ in res.stderr
        assert any(m in res.stderr for m in message.split("|")), res.stderr[-500:]


def test_a_normal_build_has_no_cycle_probes():
    # the probes around the seed step's passes (include/softgym_prof.h) are compiled in
    # only for `benchmarks/profile_engine.py --cycles`; an installed kernel has none
    from softgym.engine import _core, _seed

    assert _core.cycle_counts() is None
    assert _seed.cycle_counts() is None
    assert _core.CYCLE_STAGES == ("contacts", "links", "collide", "integrate", "drive_record")
    assert len(_seed.CYCLE_PASSES) == 6


@pytest.mark.parametrize("model", ["seed", "corotational"])
def test_the_rotation_matrices_are_their_quaternions_whenever_the_kernel_returns(model):
    # the seed step of the AVX-512 build does not read or store the voxels' rotation
    # matrices (its scatter takes voxel 1's from the geometry); advance_robot stores them
    # before it returns, so every reader outside a step sees its quaternions' matrices
    from softgym.design import default_walker
    from softgym.engine import SimConfig, Simulation, _core

    sim = Simulation(default_walker().to_body(origin=(0.0, 0.0, 0.02)),
                     SimConfig(model=model), n_threads=1)  # fmt: skip
    state = sim.get_state()  # the voxels spun a little, each its own way
    state["angvel"][:] = np.random.default_rng(3).normal(0.0, 20.0, state["angvel"].shape)
    sim.set_state(state)
    for seconds in (0.05, 0.2):
        sim.advance(seconds)
        quat = np.array(sim.get_state()["quat"])
        assert np.abs(quat[:, 1:]).max() > 1e-4  # the voxels turned
        expect = np.empty((quat.shape[0], 9))
        _core.refresh_rotations(np.ascontiguousarray(quat), expect)
        np.testing.assert_array_equal(sim.get_state()["rot"], expect)
