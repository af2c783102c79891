"""A task run as control episodes: N robots in one Simulation, actions in, observations out.

:class:`EpisodeBatch` is what the Gymnasium environments adapt (dm_control's
Task half of an Environment): how actions become muscle temperatures, what is
observed, the per-step reward (the progress of the task's reward metric) and
the reported metrics, computed by :mod:`softgym.metrics` from the centre of
mass sampled once per control step, and when an episode ends. The single env
drives a batch of one, the vector env a batch of N, so both compute exactly the
same numbers for a robot. Nothing here knows Gymnasium.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from softgym.design import MAX_GRID_DIM, RobotDesign, check_grid_shape
from softgym.engine import SimConfig, Simulation
from softgym.exceptions import InvalidActionError, InvalidDesignError, InvalidParameterError
from softgym.metrics import (
    WALK_METRICS,
    max_xy_dist_from_arrays,
    norm_final_dist_from_arrays,
    task_measure_from_arrays,
    walk_metrics_from_arrays,
)
from softgym.tasks.task import Task, measure_params
from softgym.terrain import Terrain
from softgym.validate import positive, show

__all__ = [
    "DRIVES",
    "MAX_CONTROL_DT",
    "OBSERVATIONS",
    "MAX_STEPS_PER_EPISODE",
    "OBS_POSITION_BOUND",
    "OBS_VELOCITY_BOUND",
    "EpisodeBatch",
    "observation_size",
]

#: Observed positions relative to the centre of mass are clipped to +-this (voxel lengths).
OBS_POSITION_BOUND = 50.0
#: Observed velocities are clipped to +-this (voxel lengths per second).
OBS_VELOCITY_BOUND = 500.0
#: What drives the muscles: the actions, the design's own sinusoid, or the design's brain
#: (:class:`softgym.tasks.brains.BrainDrive`; actions ignored by the last two).
DRIVES: tuple[str, ...] = ("action", "controller", "brain")
#: What a robot observes: ``"blind"``, its voxels and a clock (:func:`observation_size`), or
#: ``"sensing"``, every sensor of :mod:`softgym.tasks.sensing` (touch, strain, orientation, the
#: task's senses).
OBSERVATIONS: tuple[str, ...] = ("blind", "sensing")
#: RGB colour of movable objects (push, carry) in rendered frames.
OBJECT_COLOR = (0.55, 0.55, 0.6)
#: Most control steps an episode may have: its centre-of-mass samples are allocated up front
#: (32 bytes a step per robot, so 32 MB per robot at the cap).
MAX_STEPS_PER_EPISODE = 1_000_000
#: Longest control step (s): one ``step`` call simulates this long, so it bounds a call's cost
#: (the seed's whole evaluation is 5 s).
MAX_CONTROL_DT = 10.0


def observation_size(grid_shape: Sequence[int]) -> int:
    """Length of the observation vector for a grid: 6 per cell, CM velocity (3), phase (2)."""
    return 6 * int(np.prod(grid_shape)) + 5


def _check_max_episode_steps(value: Any) -> int | None:
    """``max_episode_steps`` as an int in 1..MAX_STEPS_PER_EPISODE, or None (no extra cap).

    Raises
    ------
    InvalidParameterError
        For a bool, a float (``1.5`` is not rounded, nor ``2.0`` accepted), a
        string, or an int out of range.
    """
    if value is None:
        return None
    ok = isinstance(value, (int, np.integer)) and not isinstance(value, (bool, np.bool_))
    if not ok or not 1 <= value <= MAX_STEPS_PER_EPISODE:
        raise InvalidParameterError(
            f"max_episode_steps must be None or an integer in 1..{MAX_STEPS_PER_EPISODE}, "
            f"got {show(value)}"
        )
    return int(value)


class EpisodeBatch:
    """A task's control episodes for N robots in one :class:`~softgym.engine.Simulation`.

    Parameters
    ----------
    designs : list of RobotDesign
        One per robot; each must fit in ``grid_shape``.
    task : Task
        Terrain (placed around each design's grid unless ``terrains`` is
        given) and reward metric.
    grid_shape : tuple of 3 ints
        The lattice of actions and observations: integers (not floats or
        bools), each in 1..:data:`softgym.design.MAX_GRID_DIM`, at most
        :data:`softgym.design.MAX_GRID_VOXELS` cells
        (:func:`softgym.design.check_grid_shape`).
    control_dt, episode_seconds : float
        Seconds per action and per episode (after settling): finite numbers
        > 0, not bools or strings; ``control_dt`` at most
        :data:`MAX_CONTROL_DT`, and the episode has at most
        :data:`MAX_STEPS_PER_EPISODE` control steps.
    max_episode_steps : int or None
        Truncate after this many steps (the smaller of it and
        ``round(episode_seconds / control_dt)``): an int in
        1..:data:`MAX_STEPS_PER_EPISODE`, not a bool or float.
    config : SimConfig
        Engine settings (its ``trace_interval`` is not used: the batch samples
        the centre of mass once per control step).
    terrains : list of Terrain or None
        One per robot (default: the task's).
    n_threads : int or None
        Engine threads.
    drive : {"action", "controller"}
        ``"action"``: each step's action sets the muscle temperatures.
        ``"controller"``: the design's own sinusoidal controller drives them,
        as in :func:`softgym.evaluate` and the seed (actions are checked and
        ignored): the open-loop baseline, whose episode reports exactly
        :func:`softgym.evaluate`'s metrics when ``control_dt`` is the task's
        ``trace_interval``. ``"brain"``: each design's
        :class:`~softgym.design.Brain` sets them from its senses before each
        control step (:attr:`brains`; actions are checked and ignored).
    observe : {"blind", "sensing"}
        What :meth:`observations` returns: the voxels and a clock
        (:func:`observation_size`), or every sensor
        (:func:`softgym.tasks.sensing.sensing_layout`).
    reward_shaping : bool
        Add the task's dense guidance (:attr:`Task.shaping
        <softgym.tasks.Task.shaping>`: each measure's per-step progress times its weight)
        to the reward; the score and metrics stay the task's measure.
    """

    def __init__(
        self,
        designs: list[RobotDesign],
        task: Task,
        grid_shape: Sequence[int],
        control_dt: float,
        episode_seconds: float,
        max_episode_steps: int | None,
        config: SimConfig,
        terrains: list[Terrain] | None = None,
        n_threads: int | None = None,
        drive: str = "action",
        observe: str = "blind",
        reward_shaping: bool = False,
    ) -> None:
        if not isinstance(task, Task):
            raise InvalidParameterError(f"task must be a Task, got {type(task).__name__}")
        if not isinstance(drive, str) or drive not in DRIVES:
            raise InvalidParameterError(f"drive must be one of {DRIVES}, got {show(drive)}")
        if not isinstance(observe, str) or observe not in OBSERVATIONS:
            raise InvalidParameterError(f"observe must be one of {OBSERVATIONS}, got {show(observe)}")
        if not isinstance(reward_shaping, (bool, np.bool_)):
            raise InvalidParameterError(f"reward_shaping must be True or False, got {show(reward_shaping)}")
        self.observe = observe
        self.task = task
        self.drive = drive
        self.metric = task.reward
        #: The shaping terms the reward adds ((measure, weight), the task's; none unless asked).
        self.shaping: tuple[tuple[str, float], ...] = task.shaping if reward_shaping else ()
        try:  # integers only, within the design grid caps, before anything is allocated
            self.grid_shape = check_grid_shape(grid_shape, "grid_shape")
        except InvalidDesignError as exc:
            raise InvalidParameterError(str(exc)) from None
        except ValueError:  # the design check's message could not print an int of > 4300 digits
            raise InvalidParameterError(
                f"grid_shape must be 3 integers (nx, ny, nz), each in 1..{MAX_GRID_DIM}"
            ) from None
        self.n_cells = int(np.prod(self.grid_shape))
        self.control_dt = positive("control_dt", control_dt, unit=" (s)")
        if self.control_dt > MAX_CONTROL_DT:
            raise InvalidParameterError(
                f"control_dt must be at most MAX_CONTROL_DT = {MAX_CONTROL_DT} s "
                f"(the time one step simulates), got {control_dt!r}"
            )
        self.episode_seconds = positive("episode_seconds", episode_seconds, unit=" (s)")
        cap = _check_max_episode_steps(max_episode_steps)
        ratio = self.episode_seconds / self.control_dt  # finite or inf, never NaN
        if cap is None and not ratio < MAX_STEPS_PER_EPISODE + 0.5:
            raise InvalidParameterError(
                f"episode_seconds / control_dt = {ratio:.4g} control steps, more than the cap of "
                f"{MAX_STEPS_PER_EPISODE} (MAX_STEPS_PER_EPISODE); pass a larger control_dt, a "
                f"shorter episode_seconds or max_episode_steps"
            )
        n_steps = max(1, round(min(ratio, MAX_STEPS_PER_EPISODE)))
        if cap is not None:
            n_steps = min(n_steps, cap)
        self.max_steps = n_steps
        self.designs = list(designs)
        for i, d in enumerate(self.designs):
            if any(s > g for s, g in zip(d.shape, self.grid_shape)):
                raise InvalidDesignError(
                    f"design {i} of shape {d.shape} does not fit in grid_shape {self.grid_shape}"
                )
            if d.n_voxels == 0:
                raise InvalidDesignError(f"design {i} has no voxels")
        if terrains is None:
            terrains = [task.terrain_for(d.shape) for d in self.designs]
        self.terrains = list(terrains)
        self.config = config
        self.sim = Simulation(
            self.designs, config=config, n_threads=n_threads, terrain=self.terrains
        )
        n = self.n_robots = len(self.designs)
        self.L = float(config.voxel_size)
        self.settle_seconds = float(config.init_time)
        # per-robot lattice bookkeeping
        self.cells: list[np.ndarray] = []  # flat cell index of each voxel
        self.voxel_muscle: list[np.ndarray] = []  # voxel has a non-zero CTE
        self.muscle_mask = np.zeros((n, self.n_cells), dtype=bool)
        self.filled_mask = np.zeros((n, self.n_cells), dtype=bool)
        for r, d in enumerate(self.designs):
            gi = self.sim.grid_index(r)
            cells = np.ravel_multi_index(tuple(gi.T), self.grid_shape).astype(np.intp)
            cte = self.sim.bodies[r].cte[d.grid[tuple(gi.T)]]
            muscle = cte != 0.0
            self.cells.append(cells)
            self.voxel_muscle.append(muscle)
            self.muscle_mask[r, cells] = muscle
            self.filled_mask[r, cells] = True
        self.amplitude = np.array(
            [d.controller.temp_amplitude for d in self.designs], dtype=np.float64
        )
        self.period = np.array([d.controller.period for d in self.designs], dtype=np.float64)
        self.robot_mass = np.array([self.sim.masses(r).sum() for r in range(n)])
        if observe == "blind":
            self.obs_size = observation_size(self.grid_shape)
        else:
            from softgym.tasks.sensing import sensing_layout

            self.obs_size = sensing_layout(task, self.grid_shape).size
        self._sensing: Any = None
        self._brains: Any = None
        self._settled: dict[str, np.ndarray] | None = None
        self._settled_time = np.zeros(n)
        self.cm0 = np.zeros((n, 3))
        self.steps = np.zeros(n, dtype=np.int64)
        self.metric_value = np.zeros((n, 2))  # norm_final_dist, max_xy_dist
        self.done_diverged = np.zeros(n, dtype=bool)
        # a suite task's measure: its per-robot parameters, the kernel's auxiliary samples
        self._measure = self.metric not in ("norm_final_dist", "max_xy_dist")
        self._params = measure_params(self.terrains)
        self.aux0 = np.zeros((n, 0))
        self._trace_aux = np.zeros((n, self.max_steps + 1, 0))
        self.score_value = np.zeros(n)
        self.shaping_value = np.zeros((n, len(self.shaping)))
        # centre of mass (m) and time since placement (s) at the episode start and each step
        self._trace_cm = np.zeros((n, self.max_steps + 1, 3))
        self._trace_t = np.zeros((n, self.max_steps + 1))
        self._time_offset = np.zeros(n)  # engine clock minus time since placement
        self._colors: dict[int, np.ndarray] = {}
        # batch-wide voxel -> (robot, cell) maps for the observations
        self._voxel_robot = np.repeat(np.arange(n), [c.size for c in self.cells])
        self._voxel_is_muscle = np.concatenate(self.voxel_muscle)
        self._flat_cells = np.concatenate(
            [r * self.n_cells + c for r, c in enumerate(self.cells)]
        ).astype(np.intp)
        self._feat_bound = np.array([OBS_POSITION_BOUND] * 3 + [OBS_VELOCITY_BOUND] * 3)
        self._cell_buf = np.zeros((n * self.n_cells, 6))
        if drive == "brain":
            self._brains = self.brains  # the brains are checked against the task and grid now

    @property
    def flat_cells(self) -> np.ndarray:
        """Each voxel's cell in the batch (robot ``r``'s cell ``c`` is ``r * n_cells + c``), in voxel order."""
        return self._flat_cells

    @property
    def measure_params(self) -> dict[str, np.ndarray]:
        """The task measure's per-robot parameters (:func:`softgym.tasks.task.measure_params`)."""
        return self._params

    @property
    def sensing(self) -> Any:
        """The batch's sensors (:class:`softgym.tasks.sensing.Sensing`), made on first use."""
        if self._sensing is None:
            from softgym.tasks.sensing import Sensing

            self._sensing = Sensing(self)
        return self._sensing

    @property
    def brains(self) -> Any:
        """The designs' brains as one control step (:class:`softgym.tasks.brains.BrainDrive`)."""
        if self._brains is None:
            from softgym.tasks.brains import BrainDrive

            self._brains = BrainDrive(self)
        return self._brains

    # ---------------------------------------------------------------- reset
    def _settle(self) -> None:
        sim = self.sim
        sim.reset()
        if self.drive != "controller":
            for r in range(self.n_robots):
                sim.set_temperature(r, np.zeros(len(self.cells[r])))
        # (the design's controller holds the nominal sizes while settling, as idle muscles do)
        if self.settle_seconds > 0:
            sim.advance(self.settle_seconds)
        self._settled = sim.get_state()
        self._settled_time = sim.time
        # the engine's own reference centre of mass (its first step after init_time), the one
        # softgym.evaluate's metrics start from
        ro = sim.rollout()
        self.cm0 = ro.cm_init
        self.aux0 = ro.aux_init
        if self._measure:
            self._trace_aux = np.zeros((self.n_robots, self.max_steps + 1, self.aux0.shape[1]))

    def _start_trace(self, ids: np.ndarray | slice) -> None:
        self._trace_cm[ids] = 0.0
        self._trace_t[ids] = 0.0
        self._trace_cm[ids, 0] = self.cm0[ids]
        self._trace_t[ids, 0] = self._settled_time[ids]
        if self._measure:
            self._trace_aux[ids] = 0.0
            self._trace_aux[ids, 0] = self.aux0[ids]

    @staticmethod
    def _valid(k: np.ndarray, stride: int = 1) -> np.ndarray:
        # samples 0..k of each robot, every stride-th one and the last
        idx = np.arange(int(k.max()) + 1)[None, :]
        return (idx <= k[:, None]) & ((idx % stride == 0) | (idx == k[:, None]))

    def _task_measure(self, k: np.ndarray, stride: int = 1, name: str | None = None) -> np.ndarray:
        # the suite task's measure (or ``name``) of every robot over its samples 0..k
        kmax = int(k.max()) + 1
        return task_measure_from_arrays(
            self.metric if name is None else name, self.cm0, self.aux0, self._trace_cm[:, :kmax], self._trace_aux[:, :kmax],
            self._valid(k, stride), self.L, self._params,
        )  # fmt: skip

    def reset_all(self) -> None:
        """Every robot back to its settled start state (the first call settles them)."""
        if self._settled is None:
            self._settle()
        else:
            self.sim.set_state(self._settled)
        self.steps[:] = 0
        self.metric_value[:] = 0.0
        self.score_value[:] = 0.0
        self.shaping_value[:] = 0.0
        # a robot that diverged while settling cannot run: its episodes end at the first step
        self.done_diverged[:] = self._settled["diverged"] != 0
        self._time_offset[:] = 0.0
        self._start_trace(slice(None))
        if self._brains is not None:
            self._brains.reset()

    def reset_robots(self, ids: np.ndarray) -> None:
        """Put the robots ``ids`` back to their settled start; the others go on untouched."""
        ids = np.asarray(ids, dtype=np.intp)
        if ids.size == 0:
            return
        if ids.size == self.n_robots or self._settled is None:
            self.reset_all()
            return
        init = self._settled
        # the batch shares one clock: a reset robot restarts from its settled state *now*
        self.sim.restore_robots(init, ids)
        self.steps[ids] = 0
        self.metric_value[ids] = 0.0
        self.score_value[ids] = 0.0
        self.shaping_value[ids] = 0.0
        self.done_diverged[ids] = init["diverged"][ids] != 0
        self._time_offset[ids] = self.sim.time[ids] - self._settled_time[ids]
        self._start_trace(ids)
        if self._brains is not None:
            self._brains.reset(ids)

    # ----------------------------------------------------------------- step
    def validate_actions(self, actions: Any, single: bool = False) -> np.ndarray:
        """Check the actions of a step and return them as float64, clipped to [-1, 1].

        Parameters
        ----------
        actions : array_like of shape (n_robots, n_cells), or (n_cells,) if ``single``
            Real numbers (an int or float dtype once NumPy has made an array
            of them): complex, bool, object and string arrays are refused,
            not converted. The shape must be exactly the one above: an array
            of the right size but another shape is refused, not reshaped.
            Finite values outside [-1, 1] are clipped to it.
        single : bool
            The action of a single env (a batch of one robot), of shape (n_cells,).

        Returns
        -------
        ndarray of shape (n_robots, n_cells), float64
            A new array (``actions`` is not modified).

        Raises
        ------
        InvalidActionError
            For another dtype or shape, or NaN or infinite values; nothing has
            been changed.
        """
        want = (self.n_cells,) if single else (self.n_robots, self.n_cells)
        if single and self.n_robots != 1:
            raise InvalidParameterError(
                f"single=True needs a batch of 1 robot, not {self.n_robots}"
            )
        accepted = f"real numbers of shape {want}, in [-1, 1] (finite values outside are clipped)"
        try:
            a = np.asarray(actions)
        except (TypeError, ValueError, OverflowError) as exc:  # ragged lists...
            raise InvalidActionError(f"action must be {accepted}; got {exc!s:.200}") from None
        if a.dtype.kind not in "iuf":  # b bool, c complex, O object, U/S strings, M/m times...
            raise InvalidActionError(f"action must be {accepted}, got dtype {a.dtype}")
        if a.shape != want:
            raise InvalidActionError(f"action must be {accepted}, got shape {a.shape}")
        a = a.astype(np.float64).reshape(self.n_robots, self.n_cells)
        if not np.isfinite(a).all():
            raise InvalidActionError(
                f"action holds NaN or infinite values (must be {accepted}); the state is unchanged"
            )
        return np.clip(a, -1.0, 1.0)

    def apply(self, actions: np.ndarray, active: np.ndarray | None = None, force: bool = False) -> None:
        """Set every active robot's muscle temperatures ``action * dT`` (degC).

        With ``drive="controller"`` the design's controller keeps the muscles,
        with ``drive="brain"`` its brain (which calls this with ``force=True``).
        """
        if self.drive != "action" and not force:
            return
        # every voxel of the batch at once: its cell's action times its robot's dT
        temps = actions.reshape(-1)[self._flat_cells] * self.amplitude[self._voxel_robot]
        temps[~self._voxel_is_muscle] = 0.0
        self.sim.set_temperatures(temps, None if active is None else np.flatnonzero(active))

    def advance(self) -> None:
        """Advance the whole batch by one control step."""
        self.sim.advance(self.control_dt)

    def update(self, stepped: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Book-keeping after an advance for the robots ``stepped`` (bool mask).

        Returns
        -------
        reward : ndarray of shape (n_robots,), float64
            The progress of the task's reward metric (voxel lengths).
        terminated, truncated : ndarray of shape (n_robots,), bool
        diverged : ndarray of shape (n_robots,), bool
        """
        n = self.n_robots
        reward = np.zeros(n)
        terminated = np.zeros(n, dtype=bool)
        truncated = np.zeros(n, dtype=bool)
        diverged = self.sim.diverged
        cm = self.sim.center_of_mass()
        new = np.column_stack(
            [
                norm_final_dist_from_arrays(self.cm0, cm, self.L),
                max_xy_dist_from_arrays(self.cm0, cm, self.L),
            ]
        )
        col = 0 if self.metric == "norm_final_dist" else 1
        live = stepped & ~self.done_diverged
        newly_div = live & diverged
        ok = live & ~diverged
        if not self._measure:
            reward[ok] = new[ok, col] - self.metric_value[ok, col]
            # a diverged episode forfeits its progress: its return sums to 0
            reward[newly_div] = 0.0 - self.metric_value[newly_div, col]
        self.metric_value[ok] = new[ok]
        self.done_diverged |= newly_div
        self.steps[stepped] += 1
        k = np.minimum(self.steps, self.max_steps)
        rows = np.flatnonzero(ok)
        self._trace_cm[rows, k[rows]] = cm[rows]
        self._trace_t[rows, k[rows]] = self.sim.time[rows] - self._time_offset[rows]
        if self._measure:
            self._trace_aux[rows, k[rows]] = self.sim.aux()[rows]
            score = self._task_measure(k)
            reward[ok] = score[ok] - self.score_value[ok]
            reward[newly_div] = 0.0 - self.score_value[newly_div]
            self.score_value[ok] = score[ok]
            for j, (measure, weight) in enumerate(self.shaping):
                value = self._task_measure(k, name=measure)
                # the guidance's progress, forfeited like the score's on a divergence
                reward[ok] += weight * (value[ok] - self.shaping_value[ok, j])
                reward[newly_div] -= weight * self.shaping_value[newly_div, j]
                self.shaping_value[ok, j] = value[ok]
        terminated[stepped] = self.done_diverged[stepped]
        truncated[stepped] = (self.steps[stepped] >= self.max_steps) & ~terminated[stepped]
        return reward, terminated, truncated, self.done_diverged.copy()

    # ------------------------------------------------------------ observing
    def clock(self) -> np.ndarray:
        """Each robot's time since it was placed (s): settling plus its episode's steps."""
        return self.settle_seconds + self.steps * self.control_dt

    def trace(self, r: int) -> np.ndarray:
        """Robot ``r``'s centre-of-mass samples of its episode so far: rows (x, y, z, t), m and s."""
        k = int(min(self.steps[r], self.max_steps)) + 1
        return np.column_stack([self._trace_cm[r, :k], self._trace_t[r, :k]])

    def observations(self) -> np.ndarray:
        """Observation of every robot, ndarray of shape (n_robots, obs_size), float32."""
        if self.observe == "sensing":
            return self.sensing.observation(self.clock(), self.period).astype(np.float32)
        sim = self.sim
        n, nc = self.n_robots, self.n_cells
        obs = np.empty((n, self.obs_size), dtype=np.float32)
        cm = sim.center_of_mass()
        cm_vel = sim.momentum() / self.robot_mass[:, None]
        inv_l = 1.0 / self.L
        # every voxel of the batch at once: (n_voxels, 6) features, scattered to their cells
        feats = np.empty((self._flat_cells.size, 6))
        feats[:, 0:3] = sim.all_positions
        feats[:, 3:6] = sim.all_velocities
        feats[:, 0:3] -= cm[self._voxel_robot]
        feats[:, 3:6] -= cm_vel[self._voxel_robot]
        feats *= inv_l
        np.clip(feats, -self._feat_bound, self._feat_bound, out=feats)
        cells = self._cell_buf  # empty cells stay zero; filled ones are all overwritten
        cells[self._flat_cells] = feats
        obs[:, : 6 * nc] = cells.reshape(n, 6 * nc)
        obs[:, 6 * nc : 6 * nc + 3] = np.clip(
            cm_vel * inv_l, -OBS_VELOCITY_BOUND, OBS_VELOCITY_BOUND
        )
        theta = 2.0 * np.pi * self.clock() / self.period
        obs[:, -2] = np.sin(theta)
        obs[:, -1] = np.cos(theta)
        return obs

    def metrics(self, stride: int = 1) -> dict[str, np.ndarray]:
        """The task's metrics of every robot's episode so far (:func:`softgym.metrics.walk_metrics_from_arrays`).

        The samples are the centre of mass at the episode start and after each
        control step, timed from the robot's placement (settling included, as
        in the seed); the end is the latest step.

        Parameters
        ----------
        stride : int
            Use every ``stride``-th sample (and the last): with ``stride *
            control_dt`` the task's ``trace_interval``, the samples
            :func:`softgym.evaluate` scores an open-loop run on.

        Returns
        -------
        dict of str to ndarray of shape (n_robots,)
            ``norm_final_dist``, ``max_xy_dist``, ``l_coefficient``,
            ``time_max_xy_dist``, ``diverged``, a suite task's measure and
            ``score`` (the task's reward metric).
        """
        k = np.minimum(self.steps, self.max_steps)
        kmax = int(k.max()) + 1
        rows = np.arange(self.n_robots)
        end = self._trace_t[rows, k]
        out = walk_metrics_from_arrays(
            self.cm0,
            self._trace_cm[rows, k],
            self._trace_cm[:, :kmax],
            self._trace_t[:, :kmax],
            self.L,
            np.maximum(end, self.control_dt),
            diverged=self.done_diverged,
            valid=self._valid(k, stride),
        )
        if self._measure:
            value = self._task_measure(k, stride)
            value[self.done_diverged] = out["norm_final_dist"][self.done_diverged]  # the worst
            out[self.metric] = value
        out["score"] = out[self.metric].copy()
        return out

    def infos(self) -> dict[str, np.ndarray]:
        """Per-robot metrics, score and clock: arrays of shape (n_robots,)."""
        m = self.metrics()
        out = {key: m[key] for key in (*WALK_METRICS, "diverged")}
        if self._measure:
            out[self.metric] = m[self.metric]
        out["score"] = m["score"]
        out["time"] = self.clock()
        return out

    # ------------------------------------------------------------- rendering
    def colors(self, r: int) -> np.ndarray:
        """RGB colour (0-1) of each voxel of robot ``r`` from its palette, shape (n_voxels_r, 3)."""
        if r in self._colors:
            return self._colors[r]
        d = self.designs[r]
        gi = self.sim.grid_index(r)
        mats = d.grid[tuple(gi.T)]
        table = np.zeros((d.palette.max_id + 1, 3))
        for k, mat in d.palette.items():
            table[k] = mat.color[:3]
        self._colors[r] = table[mats]
        return self._colors[r]

    def render_frame(self, renderer: Any, r: int) -> np.ndarray:
        """Robot ``r`` and its terrain drawn by ``renderer`` (a :class:`~softgym.render.VoxelRenderer`)."""
        sim = self.sim
        if not self.terrains[r].objects:
            return renderer.render(
                sim.positions(r),
                sim.orientations(r),
                sim.scales(r),
                self.colors(r),
                grid_index=sim.grid_index(r),
                terrain=self.terrains[r],
            )
        # with its movable objects, in grey
        obj = sim.object_positions(r)
        return renderer.render(
            np.concatenate([sim.positions(r), obj]),
            np.concatenate([sim.orientations(r), sim.object_orientations(r)]),
            np.concatenate([sim.scales(r), sim.object_scales(r)]),
            np.concatenate([self.colors(r), np.tile(OBJECT_COLOR, (len(obj), 1))]),
            terrain=self.terrains[r],
            target=sim.center_of_mass()[r],
        )
