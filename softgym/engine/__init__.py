"""The batched voxel physics engine of softgym.

One :class:`Simulation` holds many robots (:class:`Body`) in flat arrays and
advances them in parallel; :meth:`Simulation.run` returns a :class:`Rollout`.
"""

from softgym.engine._dispatch import FUSED_KERNELS, available_kernels, install, kernel_build

install()  # the kernel build for this CPU, before any kernel module is imported

from softgym.engine._core import AUX_NAMES  # noqa: E402
from softgym.engine._openmp import omp_max_threads, openmp_enabled  # noqa: E402
from softgym.engine.body import Body  # noqa: E402
from softgym.engine.config import SimConfig  # noqa: E402
from softgym.engine.rollout import Rollout  # noqa: E402
from softgym.engine.simulation import (  # noqa: E402
    Simulation,
    as_body,
    default_num_threads,
    time_step,
    voxel_steps_per_second,
)

__all__ = [
    "AUX_NAMES",
    "FUSED_KERNELS",
    "Body",
    "Rollout",
    "SimConfig",
    "Simulation",
    "as_body",
    "available_kernels",
    "default_num_threads",
    "kernel_build",
    "omp_max_threads",
    "openmp_enabled",
    "time_step",
    "voxel_steps_per_second",
]
