"""`SoftWalkerVectorEnv`: N walkers stepped together in one engine call.

``gym.make_vec("SoftWalker-Flat-v0", num_envs=N)`` builds this class through
the ids' ``vector_entry_point``: one :class:`~softgym.engine.Simulation` holds
all N robots (their bodies may differ: the spaces depend on the grid only),
so one :meth:`step` sets N sets of muscle temperatures and advances the whole
batch with the engine's threads, without the GIL. A robot computes exactly
what it computes in :class:`~softgym.envs.walker.SoftWalkerEnv` (both adapt a
:class:`softgym.tasks.EpisodeBatch`, and a robot's physics does not depend on its batch).
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from typing import Any

import numpy as np
from gymnasium import logger
from gymnasium.error import ResetNeeded
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from softgym.design.robot import RobotDesign
from softgym.engine import SimConfig, Simulation
from softgym.envs.walker import (
    ActionMap,
    action_space,
    check_render_options,
    check_temperatures,
    load_design,
    make_batch,
    observation_space,
)
from softgym.exceptions import InvalidParameterError
from softgym.tasks import TaskLike
from softgym.terrain import Terrain

__all__ = ["MAX_NUM_ENVS", "SoftWalkerVectorEnv"]

#: Most robots in one vector env (checked before anything is allocated per robot).
MAX_NUM_ENVS = 65_536


def _show(value: Any) -> str:
    # repr for an error message: short, and safe for ints beyond repr's 4300 digits
    try:
        text = repr(value)
    except ValueError:
        text = f"<{type(value).__name__} too large to print>"
    return text if len(text) <= 80 else text[:77] + "..."


class SoftWalkerVectorEnv(VectorEnv):
    """``num_envs`` soft walkers in one batched simulation.

    Every sub-environment is a :class:`~softgym.envs.walker.SoftWalkerEnv`
    (same spaces, rewards, info and episode rules; see its docstring); they
    are stepped together. Autoreset follows Gymnasium's default
    ``AutoresetMode.NEXT_STEP``: the step after a sub-environment terminates or
    truncates ignores its action and returns its first observation of a new
    episode, with reward 0 and both flags False.

    Parameters
    ----------
    num_envs : int
        Number of robots, from 1 to :data:`MAX_NUM_ENVS` (not a bool or float).
    designs : sequence of RobotDesign or paths, optional
        One design per robot (they may differ; each must fit ``grid_shape``).
    design : RobotDesign or path, optional
        One design for every robot (default: the embedded walker). Give
        ``design`` or ``designs``, not both.
    task, episode_seconds, control_dt, actuation, self_collision, grid_shape, sim_config, terrain, render_mode, width, height, drive, action_mode, observe, reward_shaping
        As for :class:`~softgym.envs.walker.SoftWalkerEnv` (a ``terrain``
        is the same world for every robot).
    n_threads : int, optional
        Engine threads (default: :func:`softgym.engine.default_num_threads`).
    max_episode_steps : int, optional
        An extra cap on the steps per episode: None (episodes end after
        ``episode_seconds``, the ids' default) or an int >= 1, not a bool or float.
    autoreset_mode : AutoresetMode or str, optional
        ``NEXT_STEP`` (default) or ``SAME_STEP`` (the enum, its value or its
        name: ``"same_step"``); ``DISABLED`` is not
        supported (an ended robot has no state to go on from).

    Notes
    -----
    All robots share the engine's clock. A robot reset while others go on
    (after a divergence) restarts from its settled start state at the
    current batch time; its control steps then cover the same durations but
    may fall one engine step differently, so its trajectory matches a fresh
    single env to the engine's time resolution rather than bit for bit.
    When every robot ends its episode together (the usual truncation), the
    whole batch is restored exactly.
    """

    metadata: dict[str, Any] = {
        "render_modes": ["rgb_array"],
        "render_fps": 20,
        "autoreset_mode": AutoresetMode.NEXT_STEP,
    }

    def __init__(
        self,
        num_envs: int = 1,
        designs: Sequence[RobotDesign | str | os.PathLike[str]] | None = None,
        design: RobotDesign | str | os.PathLike[str] | None = None,
        task: TaskLike = "flat",
        episode_seconds: float | None = None,
        control_dt: float = 0.05,
        actuation: str | None = None,
        self_collision: bool | None = None,
        grid_shape: Sequence[int] = (6, 6, 6),
        sim_config: SimConfig | None = None,
        terrain: Terrain | None = None,
        render_mode: str | None = None,
        width: int = 320,
        height: int = 240,
        n_threads: int | None = None,
        max_episode_steps: int | None = None,
        autoreset_mode: AutoresetMode | str = AutoresetMode.NEXT_STEP,
        drive: str = "action",
        observe: str = "blind",
        action_mode: str | None = None,
        reward_shaping: bool = False,
    ) -> None:
        try:
            mode = AutoresetMode(autoreset_mode)
        except (ValueError, TypeError):
            mode = None
            if isinstance(autoreset_mode, str):  # "SAME_STEP", "same_step"
                mode = AutoresetMode.__members__.get(autoreset_mode.upper())
        if mode is None:
            raise InvalidParameterError(
                f"autoreset_mode must be NEXT_STEP or SAME_STEP, got {_show(autoreset_mode)}"
            )
        if mode not in (AutoresetMode.NEXT_STEP, AutoresetMode.SAME_STEP):
            raise InvalidParameterError(
                f"autoreset_mode must be NEXT_STEP or SAME_STEP, got {mode.name}"
            )
        self.autoreset_mode = mode
        ok = isinstance(num_envs, (int, np.integer)) and not isinstance(num_envs, (bool, np.bool_))
        if not ok or not 1 <= num_envs <= MAX_NUM_ENVS:
            raise InvalidParameterError(
                f"num_envs must be an integer in 1..{MAX_NUM_ENVS}, got {_show(num_envs)}"
            )
        num_envs = int(num_envs)
        if designs is not None and design is not None:
            raise InvalidParameterError("give design (one for all robots) or designs, not both")
        if designs is None:
            one = load_design(design)
            robots = [one] * num_envs
        else:
            if isinstance(designs, (str, bytes, os.PathLike)) or not isinstance(
                designs, (Sequence, np.ndarray)
            ):
                raise InvalidParameterError(
                    f"designs must be a list of designs or paths, one per robot, "
                    f"got {type(designs).__name__}"
                )
            if len(designs) != num_envs:  # checked before any file is read
                raise InvalidParameterError(
                    f"designs holds {len(designs)} designs for num_envs={num_envs}"
                )
            robots = [load_design(d) for d in designs]
        size = check_render_options(render_mode, width, height)
        self._batch = make_batch(
            robots, task, terrain=terrain, episode_seconds=episode_seconds,
            control_dt=control_dt, actuation=actuation, self_collision=self_collision,
            grid_shape=grid_shape, sim_config=sim_config, n_threads=n_threads,
            max_episode_steps=max_episode_steps, drive=drive, observe=observe,
            reward_shaping=reward_shaping,
        )  # fmt: skip
        b = self._batch
        self._action_map = ActionMap(b, action_mode)
        self.action_mode = self._action_map.mode
        self.num_envs = num_envs
        self.designs = robots
        self.task = b.task
        self.grid_shape = b.grid_shape
        self.control_dt = b.control_dt
        self.episode_seconds = b.episode_seconds
        self.max_steps = b.max_steps
        self.metadata = {
            **type(self).metadata,
            "render_fps": max(1, round(1.0 / b.control_dt)),
            "autoreset_mode": mode,
        }
        self.render_mode = render_mode
        self.width, self.height = size
        self._renderer: Any = None
        self.single_action_space = action_space(b.grid_shape)
        self.action_space = batch_space(self.single_action_space, num_envs)
        self.observe = b.observe
        self.single_observation_space = observation_space(b.grid_shape, b.task, b.observe)
        self.observation_space = batch_space(self.single_observation_space, num_envs)
        self._prev_done = np.zeros(num_envs, dtype=bool)
        self._needs_reset = True

    # ------------------------------------------------------------ properties
    @property
    def sim(self) -> Simulation:
        """The engine's :class:`Simulation` holding every robot."""
        return self._batch.sim

    @property
    def muscle_mask(self) -> np.ndarray:
        """Ndarray of shape (num_envs, n_cells), bool: cells that drive a muscle (a copy)."""
        return self._batch.muscle_mask.copy()

    @property
    def period(self) -> np.ndarray:
        """Ndarray of shape (num_envs,): each robot's controller period (s)."""
        return self._batch.period.copy()

    def action_from_temperatures(self, fraction: Any) -> np.ndarray:
        """The actions giving each muscle the size the temperature ``fraction * dT`` gives it.

        As :meth:`SoftWalkerEnv.action_from_temperatures
        <softgym.envs.walker.SoftWalkerEnv.action_from_temperatures>`, for
        ``fraction`` of shape (num_envs, n_cells); returns float32 of that shape.
        """
        f = check_temperatures(fraction, self.action_space.shape)
        return self._action_map.from_temperatures(f)

    # ------------------------------------------------------------------- API
    def _infos(self, with_mask: bool = False) -> dict[str, Any]:
        raw = self._batch.infos()
        info: dict[str, Any] = {}
        for key, value in raw.items():
            info[key] = value
            info[f"_{key}"] = np.ones(self.num_envs, dtype=bool)
        if with_mask:
            info["muscle_mask"] = self.muscle_mask
            info["_muscle_mask"] = np.ones(self.num_envs, dtype=bool)
        return info

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        """Start a new episode in every sub-environment.

        Parameters
        ----------
        seed : int, optional
            Seeds ``self.np_random`` (the dynamics have no randomness).
        options : dict, optional
            Unused.

        Returns
        -------
        observations : ndarray of shape (num_envs, obs_size), float32
        infos : dict of arrays of shape (num_envs, ...)
        """
        super().reset(seed=seed)
        self._batch.reset_all()
        self._prev_done[:] = False
        self._needs_reset = False
        return self._batch.observations(), self._infos(with_mask=True)

    def step(
        self, actions: Any
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        """Hold each robot's action for ``control_dt`` seconds, all in one engine call.

        Parameters
        ----------
        actions : array_like of shape (num_envs, n_cells), int or float
            In [-1, 1] (finite values outside are clipped). Exactly this
            shape (even for ``num_envs=1``; another shape is not reshaped) and
            a real dtype (complex, bool, object and strings are refused). A
            refused action, or NaN or infinity anywhere, raises
            :class:`~softgym.exceptions.InvalidActionError` before any state
            changes.

        Returns
        -------
        observations : ndarray of shape (num_envs, obs_size), float32
        rewards : ndarray of shape (num_envs,), float64
        terminations, truncations : ndarray of shape (num_envs,), bool
        infos : dict of arrays of shape (num_envs,)

        Raises
        ------
        gymnasium.error.ResetNeeded
            Before the first :meth:`reset` (as the single env).
        """
        b = self._batch
        a = b.validate_actions(actions)
        if self._needs_reset:  # the single env's error for the same misuse
            raise ResetNeeded("call reset() before step(): the episodes have not started")
        restart = self._prev_done.copy()
        live = ~restart
        if live.any():
            b.apply(self._action_map(a), live)
            b.advance()
        b.reset_robots(np.flatnonzero(restart))
        reward, terminated, truncated, _ = b.update(live)
        done = terminated | truncated
        if self.autoreset_mode == AutoresetMode.NEXT_STEP or not done.any():
            self._prev_done = done
            return b.observations(), reward, terminated, truncated, self._infos()
        # SAME_STEP: keep the end of the ended episodes, then restart those robots now
        ended = np.flatnonzero(done)
        end_obs = b.observations()
        end_info = self._infos()
        final_obs = np.full(self.num_envs, None, dtype=object)
        for i in ended:
            final_obs[i] = end_obs[i]
        final_info = {k: v for k, v in end_info.items() if not k.startswith("_")}
        final_info.update({f"_{k}": done.copy() for k in list(final_info)})
        b.reset_robots(ended)
        infos = self._infos()
        infos.update(
            final_obs=final_obs,
            _final_obs=done.copy(),
            final_info=final_info,
            _final_info=done.copy(),
        )
        return b.observations(), reward, terminated, truncated, infos

    def render(self) -> tuple[np.ndarray, ...] | None:
        """One H x W x 3 uint8 frame per sub-environment (``render_mode="rgb_array"``)."""
        if self.render_mode is None:
            logger.warn("render() called without a render_mode; pass render_mode='rgb_array'")
            return None
        if self._renderer is None:
            from softgym.render import VoxelRenderer  # lazy: envs import without the renderer

            self._renderer = VoxelRenderer(self.width, self.height, voxel_size=self._batch.L)
        return tuple(self._batch.render_frame(self._renderer, r) for r in range(self.num_envs))

    def close_extras(self, **kwargs: Any) -> None:
        """Release the renderer (``close()`` may be called any number of times)."""
        self._renderer = None
