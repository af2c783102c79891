"""Gymnasium environments of softgym, registered on ``import softgym``.

=========================  ==========================================  =====================
id                         world                                       reward (per step)
=========================  ==========================================  =====================
``SoftWalker-Flat-v0``     flat floor                                  NormFinalDist progress
``SoftWalker-Wall-v0``     the seed's fence (1 voxel high, 2 away)     MaxXYDist progress
``SoftWalker-Stairs-v0``   three rings, each one voxel higher          MaxXYDist progress
=========================  ==========================================  =====================

``gym.make(id)`` gives a :class:`SoftWalkerEnv` (80 steps of 0.05 s);
``gym.make_vec(id, num_envs=N)`` a :class:`SoftWalkerVectorEnv` stepping all N
robots in one engine call (``designs=[...]`` may differ).
"""

import gymnasium as gym

from softgym.envs.vector import SoftWalkerVectorEnv
from softgym.envs.walker import TASKS, SoftWalkerEnv

__all__ = ["ENV_IDS", "TASKS", "SoftWalkerEnv", "SoftWalkerVectorEnv", "register_envs"]

#: Registered ids -> task name.
ENV_IDS: dict[str, str] = {
    "SoftWalker-Flat-v0": "flat",
    "SoftWalker-Wall-v0": "wall",
    "SoftWalker-Stairs-v0": "stairs",
}

#: Default episode: 4 s (the seed's fitness window) of 0.05 s control steps.
MAX_EPISODE_STEPS = 80


def register_envs() -> None:
    """Register the SoftWalker ids with Gymnasium (idempotent)."""
    for env_id, task in ENV_IDS.items():
        if env_id in gym.registry:
            continue
        gym.register(
            id=env_id,
            entry_point="softgym.envs.walker:SoftWalkerEnv",
            vector_entry_point="softgym.envs.vector:SoftWalkerVectorEnv",
            max_episode_steps=MAX_EPISODE_STEPS,
            kwargs={"task": task},
        )


register_envs()
