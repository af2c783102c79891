"""Smoke test of an installed softgym (a wheel), run from outside the source tree.

Used by ``.ci/run`` after it installs the wheel into a fresh venv, and by
cibuildwheel's ``test-command``. It checks that ``softgym`` is imported from the
installed package (never a checkout), prints the version and the kernel build that
runs (the one ``SOFTGYM_KERNEL`` names, when set: ``.ci/release`` runs the test under
each build the CPU has), simulates a small batch for a short while and steps one
Gymnasium env.
"""

import os
import sys
import sysconfig
from pathlib import Path

import gymnasium as gym
import numpy as np

import softgym
from softgym.engine import Body, SimConfig, Simulation, kernel_build

site = Path(sysconfig.get_paths()["purelib"]).resolve()
plat = Path(sysconfig.get_paths()["platlib"]).resolve()
here = Path(softgym.__file__).resolve()
assert here.is_relative_to(site) or here.is_relative_to(plat), (
    f"softgym imported from {here}, not from this environment's site-packages {site}"
)
print("softgym", softgym.__version__, "from", here.parent)
print("kernel build:", kernel_build(), "| OpenMP:", softgym.openmp_enabled())
wanted = os.environ.get("SOFTGYM_KERNEL")
assert wanted is None or kernel_build() == wanted, (kernel_build(), wanted)

bodies = [Body.uniform(np.ones((3, 3, 3)), cte=0.01) for _ in range(2)]
rollout = Simulation(bodies, SimConfig(actuation="symmetric")).run(0.2)
assert rollout.cm.shape[0] == 2 and np.isfinite(rollout.cm).all(), rollout.cm
assert not rollout.diverged.any()
print("simulation:", rollout.cm.shape, "final x", rollout.cm[:, -1, 0])

env = gym.make("SoftWalker-Flat-v0")
obs, info = env.reset(seed=0)
obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
assert np.isfinite(obs).all() and np.isfinite(reward)
env.close()
print("SoftWalker-Flat-v0: reset + step, reward", float(reward))
print("wheel smoke test passed on Python", sys.version.split()[0])
