"""The batched voxel physics engine of softgym.

One :class:`Simulation` holds many robots (:class:`Body`) in flat arrays and
advances them in parallel; :meth:`Simulation.run` returns a :class:`Rollout`.
"""

from softgym.engine._core import AUX_NAMES
from softgym.engine._dispatch import available_kernels, kernel_build
from softgym.engine._openmp import omp_max_threads, openmp_enabled
from softgym.engine.body import Body
from softgym.engine.config import SimConfig
from softgym.engine.rollout import Rollout
from softgym.engine.simulation import (
    Simulation,
    as_body,
    default_num_threads,
    time_step,
    voxel_steps_per_second,
)

__all__ = [
    "AUX_NAMES",
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
