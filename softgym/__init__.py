"""softgym: fast, faithful 3D voxel soft robots for evolution and reinforcement learning."""

from softgym import envs, exceptions  # envs registers the SoftWalker-* ids
from softgym.engine import Body, Rollout, SimConfig, Simulation, openmp_enabled
from softgym.evaluate import evaluate

__version__ = "0.1.0"

__all__ = [
    "Body",
    "Rollout",
    "SimConfig",
    "Simulation",
    "__version__",
    "evaluate",
    "envs",
    "exceptions",
    "openmp_enabled",
]
