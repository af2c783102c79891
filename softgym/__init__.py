"""softgym: fast, faithful 3D voxel soft robots for evolution and reinforcement learning."""

from importlib.metadata import version as _version

from softgym import design, envs, exceptions, metrics, tasks  # envs registers the SoftWalker-* ids
from softgym.design import Controller, RobotDesign, default_walker
from softgym.engine import Body, Rollout, SimConfig, Simulation, openmp_enabled
from softgym.evaluate import evaluate
from softgym.tasks import Task, get_task
from softgym.terrain import Terrain

__version__ = _version("softgym")  # pyproject.toml is the one place

__all__ = [
    "Body",
    "Controller",
    "RobotDesign",
    "Rollout",
    "SimConfig",
    "Simulation",
    "Task",
    "Terrain",
    "__version__",
    "default_walker",
    "design",
    "envs",
    "evaluate",
    "exceptions",
    "get_task",
    "metrics",
    "openmp_enabled",
    "tasks",
]
