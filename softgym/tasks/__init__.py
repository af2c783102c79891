"""Tasks: what a run of the engine means, shared by ``softgym.evaluate``, the envs and evolution.

A :class:`Task` is a terrain + a duration + a sampling interval + the metrics
it reports (:func:`softgym.metrics.walk_metrics`, a suite task's measure) + the
reward an env derives from them. :data:`TASKS` holds the named ones (``flat``,
``wall``, ``stairs``, ``fence`` an alias of ``wall``, and the suite of
:mod:`softgym.tasks.suite`: ``gap``, ``push``, ``swim``..., each in one of the
:data:`FAMILIES`: locomotion, terrain, climbing, balancing, manipulation,
shape change; :func:`tasks_of_family` names a family's tasks); :func:`get_task` also reads a
:class:`~softgym.terrain.Terrain`, a terrain JSON file or a Task's dict, so a
custom world goes wherever a task name does. :class:`EpisodeBatch` runs a task
as control episodes of N robots (what the Gymnasium envs adapt).

>>> from softgym.tasks import get_task
>>> get_task("fence").name, get_task("stairs").reward
('wall', 'max_xy_dist')
"""

from softgym.tasks.episode import (
    DRIVES,
    OBS_POSITION_BOUND,
    OBS_VELOCITY_BOUND,
    EpisodeBatch,
    observation_size,
)
from softgym.tasks.suite import (
    FAMILIES,
    KINDS,
    Option,
    TaskKind,
    flat_layout,
    stairs_layout,
    tasks_of_family,
    wall_layout,
)
from softgym.tasks.task import (
    ALIASES,
    REWARDS,
    TASKS,
    Task,
    TaskLike,
    get_task,
    measure_params,
    register_task,
    task_names,
)

__all__ = [
    "ALIASES",
    "DRIVES",
    "OBS_POSITION_BOUND",
    "OBS_VELOCITY_BOUND",
    "REWARDS",
    "TASKS",
    "EpisodeBatch",
    "FAMILIES",
    "KINDS",
    "Option",
    "TaskKind",
    "Task",
    "TaskLike",
    "flat_layout",
    "get_task",
    "measure_params",
    "observation_size",
    "register_task",
    "stairs_layout",
    "task_names",
    "tasks_of_family",
    "wall_layout",
]
