"""softgym: fast, faithful 3D voxel soft robots for evolution and reinforcement learning."""

from softgym import exceptions
from softgym.engine import Body, Rollout, SimConfig, Simulation, openmp_enabled

__version__ = "0.1.0"

__all__ = [
    "Body",
    "Rollout",
    "SimConfig",
    "Simulation",
    "__version__",
    "exceptions",
    "openmp_enabled",
]
