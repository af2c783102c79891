"""Gymnasium environments of softgym, registered on ``import softgym``.

=========================  ==========================================  =====================
id                         world                                       reward (per step)
=========================  ==========================================  =====================
``SoftWalker-Flat-v0``     flat floor                                  NormFinalDist progress
``SoftWalker-Wall-v0``     the seed's fence (1 voxel high, 2 away)     MaxXYDist progress
``SoftWalker-Stairs-v0``   three rings, each one voxel higher          MaxXYDist progress
``SoftWalker-<Name>-v0``   the suite's other tasks (softgym.tasks.     the task's score
                           KINDS, six families: StairsDown, Gap,       progress
                           Incline, Goal, Push, Catch, Chimney,
                           Beam, Balance, Shrink, Squeeze...)
=========================  ==========================================  =====================

Beside each, ``SoftWalker-<Name>-Sensing-v0`` observes every sensor and the task's own
senses (:mod:`softgym.tasks.sensing`: touch, strain, orientation, the object of push, the
terrain ahead of gap...) instead of the voxels and a clock. Every task of
:data:`softgym.tasks.TASKS` gets an id (a task added with
:func:`softgym.tasks.register_task` gets one at the next :func:`register_envs`).
``gym.make(id)`` gives a :class:`SoftWalkerEnv` (4 s episodes of 0.05 s control
steps, actions setting the muscles' contractions; the episode length is
set in seconds, so another ``control_dt`` keeps 4 s);
``gym.make_vec(id, num_envs=N)`` a :class:`SoftWalkerVectorEnv` stepping all N
robots in one engine call (``designs=[...]`` may differ). ``task=`` also takes
a Task, a Terrain or a terrain JSON file. ``action_mode="temperature"`` gives the
seed's temperature signal as the action instead of contractions.
:mod:`softgym.envs.sb3` (the ``rl`` extra, imported only on demand) adapts the
vector env to Stable-Baselines3.
"""

import gymnasium as gym

from softgym.envs.vector import SoftWalkerVectorEnv
from softgym.envs.walker import SoftWalkerEnv
from softgym.tasks import TASKS

__all__ = ["ENV_IDS", "SENSING_ENV_IDS", "TASKS", "SoftWalkerEnv", "SoftWalkerVectorEnv", "env_id", "register_envs"]

#: Registered ids -> task name (filled by :func:`register_envs`).
ENV_IDS: dict[str, str] = {}



#: Registered sensing ids (``observe="sensing"``: ``SoftWalker-<Name>-Sensing-v0``) -> task name.
SENSING_ENV_IDS: dict[str, str] = {}


def env_id(task_name: str, sensing: bool = False) -> str:
    """The Gym id of a task name: ``"wall"`` -> ``"SoftWalker-Wall-v0"`` (``sensing=True``:
    ``"SoftWalker-Wall-Sensing-v0"``).

    The plain ids observe the robot's voxels and a clock (the blind
    observation); the sensing ids every sensor and the task's senses
    (:mod:`softgym.tasks.sensing`), the same as ``observe="sensing"``.
    """
    name = task_name.replace("_", " ").title().replace(" ", "")
    return f"SoftWalker-{name}{'-Sensing' if sensing else ''}-v0"


def register_envs() -> None:
    """Register an id for every task of :data:`softgym.tasks.TASKS` (idempotent)."""
    for task in TASKS:
        ENV_IDS.setdefault(env_id(task), task)
        SENSING_ENV_IDS.setdefault(env_id(task, sensing=True), task)
    for ids, extra in ((ENV_IDS, {}), (SENSING_ENV_IDS, {"observe": "sensing"})):
        for eid, task in ids.items():
            if eid in gym.registry:
                continue
            gym.register(
                id=eid,
                entry_point="softgym.envs.walker:SoftWalkerEnv",
                vector_entry_point="softgym.envs.vector:SoftWalkerVectorEnv",
                # no step limit: an episode lasts its task's seconds whatever control_dt
                # (the env truncates itself; gym.make(..., max_episode_steps=k) still adds one)
                max_episode_steps=None,
                kwargs={"task": task, **extra},
            )


register_envs()
