"""`SoftWalkerEnv`: a Gymnasium environment of one voxel soft robot walking.

The physics is :class:`~softgym.engine.Simulation` (the batched engine); this
module adds the task on top (dm_control's Physics / Task split): how actions
become muscle temperatures, what is observed, the reward and when an episode
ends. :class:`_WalkerBatch` holds that logic for a batch of robots in one
Simulation; the single env drives a batch of one and
:class:`softgym.envs.vector.SoftWalkerVectorEnv` a batch of N, so both compute
exactly the same numbers for a robot.
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import logger, spaces

from softgym.design.robot import RobotDesign, default_walker
from softgym.engine.config import SimConfig
from softgym.engine.simulation import Simulation
from softgym.exceptions import InvalidActionError, InvalidDesignError, InvalidParameterError
from softgym.metrics.fitness import WORST_FITNESS
from softgym.terrain import Terrain

__all__ = [
    "OBS_POSITION_BOUND",
    "OBS_VELOCITY_BOUND",
    "TASKS",
    "SoftWalkerEnv",
    "action_space",
    "load_design",
    "make_config",
    "observation_size",
    "observation_space",
    "task_terrain",
]

#: Task name -> metric whose per-step progress is the reward.
TASKS: dict[str, str] = {"flat": "norm_final_dist", "wall": "max_xy_dist", "stairs": "max_xy_dist"}

#: Observed positions relative to the centre of mass are clipped to +-this (voxel lengths).
OBS_POSITION_BOUND = 50.0
#: Observed velocities are clipped to +-this (voxel lengths per second).
OBS_VELOCITY_BOUND = 500.0

# tolerance of the L coefficient's "max reached" test (voxel lengths, the seed's 0.1)
_L_TOLERANCE = 0.1
# the engine's own centre-of-mass trace is not used (the env keeps one per control step);
# a huge sampling interval keeps its buffers at constant size however long the env runs
_NO_ENGINE_TRACE = 1.0e9

def load_design(design: RobotDesign | str | os.PathLike[str] | None) -> RobotDesign:
    """A design from a :class:`RobotDesign`, a path to its JSON file, or None (the default walker)."""
    if design is None:
        return default_walker()
    if isinstance(design, RobotDesign):
        return design
    if isinstance(design, (str, os.PathLike)):
        return RobotDesign.load(design)
    raise InvalidDesignError(
        f"design must be a RobotDesign, a path to a design JSON file or None, got {type(design).__name__}"
    )


def observation_size(grid_shape: Sequence[int]) -> int:
    """Length of the observation vector for a grid: 6 per cell, CM velocity (3), phase (2)."""
    return 6 * int(np.prod(grid_shape)) + 5


def _footprint(design: RobotDesign) -> tuple[tuple[float, float], float]:
    filled = np.argwhere(design.grid > 0)
    lo = filled.min(axis=0)[:2]
    hi = filled.max(axis=0)[:2] + 1
    center = (float(lo[0] + hi[0]) / 2.0, float(lo[1] + hi[1]) / 2.0)
    return center, float(max(hi - lo))


def task_terrain(task: str, design: RobotDesign) -> Terrain:
    """The default terrain of a task, centred on the design's footprint.

    ``"flat"``: the floor. ``"wall"``: the seed's fence (1 voxel high and
    thick, a 10-voxel interior: a 2-voxel gap around a 6-wide robot; wider
    robots get a wider interior, their width + 4). ``"stairs"``: three
    concentric rings, each 2 voxels wide and 1 voxel higher than the one
    inside it (:meth:`Terrain.stairs`), around the same interior.
    """
    center, width = _footprint(design)
    inner = max(10.0, width + 4.0)
    if task == "flat":
        return Terrain.flat()
    if task == "wall":
        return Terrain.fence(inner=inner, center=center)
    if task == "stairs":
        return Terrain.stairs(inner=inner, center=center)
    raise InvalidParameterError(f"task must be one of {sorted(TASKS)}, got {task!r}")


def warn_if_cut_short(limit: int | None, control_dt: float, episode_seconds: float) -> None:
    """Warn when a step limit ends episodes before ``episode_seconds``.

    The ids register ``max_episode_steps=80`` (4 s at the default 0.05 s per
    step); with a finer ``control_dt`` that limit shortens the episode
    unless ``max_episode_steps`` is passed too. ``make_vec`` hands the limit
    to the vector env, which warns; ``gym.make`` applies it in a
    ``TimeLimit`` wrapper the env cannot see (its docstring says so).
    """
    full = max(1, round(episode_seconds / control_dt))
    if limit is not None and int(limit) < full:
        logger.warn(
            f"max_episode_steps={int(limit)} ends episodes after {int(limit) * control_dt:.4g} s "
            f"of the {episode_seconds:.4g} s episode (control_dt={control_dt:.4g} s); pass "
            f"max_episode_steps={full} for full episodes"
        )


def _check_positive(name: str, value: Any) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InvalidParameterError(f"{name} must be a number, got {value!r}") from None
    if not (math.isfinite(v) and v > 0):
        raise InvalidParameterError(f"{name} must be finite and > 0, got {value!r}")
    return v


def make_config(
    sim_config: SimConfig | None, actuation: str | None, self_collision: bool | None
) -> SimConfig:
    """The env's engine settings: ``sim_config`` (the seed's by default) with overrides."""
    cfg = SimConfig() if sim_config is None else sim_config
    if not isinstance(cfg, SimConfig):
        raise InvalidParameterError(f"sim_config must be a SimConfig, got {type(cfg).__name__}")
    changes: dict[str, Any] = {"trace_interval": _NO_ENGINE_TRACE}
    if actuation is not None:
        changes["actuation"] = actuation
    if self_collision is not None:
        changes["self_collision"] = bool(self_collision)
    return cfg.replace(**changes)


class _WalkerBatch:
    """Task logic for N robots in one :class:`Simulation` (shared by the single and vector envs).

    Parameters
    ----------
    designs : list of RobotDesign
        One per robot; each must fit in ``grid_shape``.
    task : {"flat", "wall", "stairs"}
    grid_shape : tuple of 3 ints
    control_dt, episode_seconds : float
        Seconds per action and per episode.
    max_episode_steps : int or None
        Truncate after this many steps (the smaller of it and
        ``round(episode_seconds / control_dt)``).
    config : SimConfig
    terrains : list of Terrain or None
        One per robot (default: the task's, centred on each robot).
    n_threads : int or None
        Engine threads.
    """

    def __init__(
        self,
        designs: list[RobotDesign],
        task: str,
        grid_shape: tuple[int, int, int],
        control_dt: float,
        episode_seconds: float,
        max_episode_steps: int | None,
        config: SimConfig,
        terrains: list[Terrain] | None,
        n_threads: int | None,
    ) -> None:
        if task not in TASKS:
            raise InvalidParameterError(f"task must be one of {sorted(TASKS)}, got {task!r}")
        self.task = task
        self.metric = TASKS[task]
        self.grid_shape = tuple(int(s) for s in grid_shape)
        if len(self.grid_shape) != 3 or min(self.grid_shape) < 1:
            raise InvalidParameterError(f"grid_shape must be 3 positive ints, got {grid_shape!r}")
        self.n_cells = int(np.prod(self.grid_shape))
        self.control_dt = _check_positive("control_dt", control_dt)
        self.episode_seconds = _check_positive("episode_seconds", episode_seconds)
        n_steps = max(1, round(self.episode_seconds / self.control_dt))
        if max_episode_steps is not None:
            if int(max_episode_steps) < 1:
                raise InvalidParameterError(
                    f"max_episode_steps must be >= 1, got {max_episode_steps}"
                )
            warn_if_cut_short(max_episode_steps, self.control_dt, self.episode_seconds)
            n_steps = min(n_steps, int(max_episode_steps))
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
            terrains = [task_terrain(task, d) for d in self.designs]
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
        self.obs_size = observation_size(self.grid_shape)
        self._settled: dict[str, np.ndarray] | None = None
        self.cm0 = np.zeros((n, 3))
        self.steps = np.zeros(n, dtype=np.int64)
        self.metric_value = np.zeros((n, 2))  # norm_final_dist, max_xy_dist
        self.done_diverged = np.zeros(n, dtype=bool)
        self._trace = np.zeros((n, self.max_steps + 1, 2))  # |dx|, |dy| (voxel lengths)
        self._colors: dict[int, np.ndarray] = {}
        # batch-wide voxel -> (robot, cell) maps for the observations
        self._voxel_robot = np.repeat(np.arange(n), [c.size for c in self.cells])
        self._voxel_is_muscle = np.concatenate(self.voxel_muscle)
        self._flat_cells = np.concatenate(
            [r * self.n_cells + c for r, c in enumerate(self.cells)]
        ).astype(np.intp)
        self._feat_bound = np.array([OBS_POSITION_BOUND] * 3 + [OBS_VELOCITY_BOUND] * 3)
        self._cell_buf = np.zeros((n * self.n_cells, 6))

    # ---------------------------------------------------------------- reset
    def _settle(self) -> None:
        sim = self.sim
        sim.reset()
        for r in range(self.n_robots):
            sim.set_temperature(r, np.zeros(len(self.cells[r])))
        if self.settle_seconds > 0:
            sim.advance(self.settle_seconds)
        self._settled = sim.get_state()
        self.cm0 = sim.center_of_mass()

    def reset_all(self) -> None:
        """Every robot back to its settled start state (the first call settles them)."""
        if self._settled is None:
            self._settle()
        else:
            self.sim.set_state(self._settled)
        self.steps[:] = 0
        self.metric_value[:] = 0.0
        # a robot that diverged while settling cannot run: its episodes end at the first step
        self.done_diverged[:] = self._settled["diverged"] != 0
        self._trace[:] = 0.0

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
        self.done_diverged[ids] = init["diverged"][ids] != 0
        self._trace[ids] = 0.0

    # ----------------------------------------------------------------- step
    def validate_actions(self, actions: Any) -> np.ndarray:
        """Actions as float64 (n_robots, n_cells), clipped to [-1, 1]; NaN/inf raise."""
        try:
            a = np.asarray(actions, dtype=np.float64)
        except (TypeError, ValueError):
            raise InvalidActionError(
                f"action must be numeric, got {type(actions).__name__}"
            ) from None
        want = (self.n_robots, self.n_cells)
        if a.shape != want and a.size == self.n_robots * self.n_cells:
            a = a.reshape(want)
        if a.shape != want:
            raise InvalidActionError(
                f"action must have shape {want[1:] if self.n_robots == 1 else want}, got {np.shape(actions)}"
            )
        if not np.isfinite(a).all():
            raise InvalidActionError("action holds NaN or infinite values; the state is unchanged")
        return np.clip(a, -1.0, 1.0)

    def apply(self, actions: np.ndarray, active: np.ndarray | None = None) -> None:
        """Set every active robot's muscle temperatures ``action * dT`` (degC)."""
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
        terminated, truncated : ndarray of shape (n_robots,), bool
        diverged : ndarray of shape (n_robots,), bool
        """
        n = self.n_robots
        reward = np.zeros(n)
        terminated = np.zeros(n, dtype=bool)
        truncated = np.zeros(n, dtype=bool)
        diverged = self.sim.diverged
        cm = self.sim.center_of_mass()
        d = (cm[:, :2] - self.cm0[:, :2]) / self.L
        new = np.column_stack([np.hypot(d[:, 0], d[:, 1]), np.abs(d).max(axis=1)])
        col = 0 if self.metric == "norm_final_dist" else 1
        live = stepped & ~self.done_diverged
        newly_div = live & diverged
        ok = live & ~diverged
        reward[ok] = new[ok, col] - self.metric_value[ok, col]
        # a diverged episode forfeits its progress: its return sums to 0
        reward[newly_div] = 0.0 - self.metric_value[newly_div, col]
        self.metric_value[ok] = new[ok]
        self.done_diverged |= newly_div
        self.steps[stepped] += 1
        k = np.minimum(self.steps, self.max_steps)
        rows = np.flatnonzero(ok)
        self._trace[rows, k[rows]] = np.abs(d[rows])
        terminated[stepped] = self.done_diverged[stepped]
        truncated[stepped] = (self.steps[stepped] >= self.max_steps) & ~terminated[stepped]
        return reward, terminated, truncated, self.done_diverged.copy()

    # ------------------------------------------------------------ observing
    def clock(self) -> np.ndarray:
        """Each robot's time since it was placed (s): settling plus its episode's steps."""
        return self.settle_seconds + self.steps * self.control_dt

    def observations(self) -> np.ndarray:
        """Observation of every robot, ndarray of shape (n_robots, obs_size), float32."""
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

    def l_coefficient(self) -> np.ndarray:
        """The seed's L coefficient of every robot over its episode so far (voxel lengths^2/s).

        ``MaxXYDist^2 / t_max``, ``t_max`` the first sampled time (one sample
        per control step, from the episode start, counted from the robot's
        placement so the settling second is included as in the seed) at which
        either axis displacement was within 0.1 voxel of ``MaxXYDist``.
        """
        n = self.n_robots
        m = self.metric_value[:, 1]
        kmax = int(min(self.steps.max(), self.max_steps)) + 1
        tr = self._trace[:, :kmax]
        close = (np.abs(tr[..., 0] - m[:, None]) < _L_TOLERANCE) | (
            np.abs(tr[..., 1] - m[:, None]) < _L_TOLERANCE
        )
        idx = np.arange(kmax)
        times = self.settle_seconds + idx * self.control_dt
        close &= (idx[None, :] <= np.minimum(self.steps, self.max_steps)[:, None]) & (times > 0)[
            None, :
        ]
        first = np.argmax(close, axis=1)
        t_max = np.where(close.any(axis=1), times[first], np.maximum(self.clock(), self.control_dt))
        out = m * m / t_max
        out[self.done_diverged] = WORST_FITNESS
        return out[:n]

    def infos(self) -> dict[str, np.ndarray]:
        """Per-robot metrics: arrays of shape (n_robots,)."""
        nfd = self.metric_value[:, 0].copy()
        mxy = self.metric_value[:, 1].copy()
        nfd[self.done_diverged] = WORST_FITNESS
        mxy[self.done_diverged] = WORST_FITNESS
        return {
            "norm_final_dist": nfd,
            "max_xy_dist": mxy,
            "l_coefficient": self.l_coefficient(),
            "diverged": self.done_diverged.copy(),
            "time": self.clock(),
        }

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


class SoftWalkerEnv(gym.Env):
    """A 3-D voxel soft robot that must walk, on flat ground, out of a fence or up stairs.

    ## Description

    One robot (by default the embedded 6x6x6 walker, :func:`~softgym.design.default_walker`)
    is simulated by softgym's lattice engine with the seed study's settings
    (evosoro / Ev-SoftBots: 1 cm voxels, thermal muscles, floor friction,
    self-collision). Instead of the seed's global sinusoid, the agent sets
    every muscle voxel's temperature at each control step. The ids:

    * ``SoftWalker-Flat-v0``: flat floor; reward on the seed's ``NormFinalDist``.
    * ``SoftWalker-Wall-v0``: the seed's fence (a square wall 1 voxel high and
      thick, 2 voxels from the robot); reward on Ev-SoftBots' ``MaxXYDist``.
    * ``SoftWalker-Stairs-v0``: three concentric rings, each one voxel higher
      than the one inside it; reward on ``MaxXYDist``.

    The spaces depend on ``grid_shape`` only, never on the body, so any two
    bodies of one grid share them (and one vector env can hold both).

    ## Action Space

    ``Box(-1, 1, (nx * ny * nz,), float32)``: one entry per grid cell, in
    C order (x slowest, z fastest: ``action.reshape(grid_shape)[i, j, k]``
    drives voxel ``(i, j, k)``). A muscle voxel (a material with a non-zero
    CTE) gets the temperature ``T = action * dT`` (degC), ``dT`` the design's
    controller amplitude (14 degC by default), so its size follows
    ``L (1 + CTE T)`` under the configured actuation law (``"seed"``: muscles
    only contract, and a command that would expand one keeps its last size,
    the seed's rule, so only commands back towards 0 relax a contracted
    muscle; ``"symmetric"``: they also expand). Entries of empty and
    passive cells are ignored (``env.muscle_mask`` and ``info["muscle_mask"]``
    of :meth:`reset` tell which count). Each action is held for
    ``control_dt`` seconds. ``action = sin(2 pi t / period)`` on every cell
    is the seed's open-loop drive sampled every control step
    (:class:`softgym.controllers.Sinusoid`); with ``control_dt <= 0.005`` it
    walks the engine's built-in sinusoid's distance to within 1 %, while the
    default 0.05 s (5 samples per 0.25 s period) changes the seed's gait.

    Finite actions outside [-1, 1] are clipped; an action holding NaN or
    infinity, or of the wrong shape, raises
    :class:`~softgym.exceptions.InvalidActionError` before the state is touched.

    ## Observation Space

    ``Box(low, high, (6 * nx * ny * nz + 5,), float32)`` (1301 for 6x6x6):

    | Index                          | Observation                                        | Unit                | Bound |
    |--------------------------------|----------------------------------------------------|---------------------|-------|
    | ``6 c + 0 .. 6 c + 2``         | cell ``c``'s voxel centre minus the centre of mass (x, y, z) | voxel lengths | +-50 |
    | ``6 c + 3 .. 6 c + 5``         | cell ``c``'s voxel velocity minus the CM velocity   | voxel lengths / s   | +-500 |
    | ``6 n .. 6 n + 2``             | centre-of-mass velocity (x, y, z)                  | voxel lengths / s   | +-500 |
    | ``6 n + 3``                    | ``sin(2 pi t / period)``                           |                     | +-1   |
    | ``6 n + 4``                    | ``cos(2 pi t / period)``                           |                     | +-1   |

    ``c`` is the cell's C-order index, ``n = nx * ny * nz`` (so
    ``obs[:6 * n].reshape(nx, ny, nz, 6)`` is a grid of features); empty cells
    are zeros. Vectors are in the world frame (z up). ``t`` is the robot's
    time since it was placed (settling included), ``period`` its controller's.
    Values beyond the bounds are clipped (only a diverging robot reaches them).

    ## Rewards

    The per-step progress of the task metric, in voxel lengths: on Flat the
    increase of ``NormFinalDist = |CM_xy(t) - CM_xy(t0)| / L``; on Wall and
    Stairs the increase of ``MaxXYDist = max(|dx|, |dy|) / L`` (the seed's
    obstacle fitness); ``t0`` is the episode start (after settling). The
    return of an episode is therefore the metric at its end: with the default
    4 s episode, the seed's fitness over its window t in (1, 5] s. A diverged
    episode forfeits its progress: the diverging step's reward makes its
    return 0.

    ## Starting State

    The robot is placed with its grid's corner at the origin, at rest on the
    floor, and settles for ``SimConfig.init_time`` (1 s, the seed's
    ``InitCmTime``) with its muscles idle inside :meth:`reset` (the settled
    state is computed once and reused). The start is deterministic: the
    engine has no noise, and ``seed`` only seeds ``np_random``.

    ## Episode End

    * Termination: the robot diverged (non-finite state or runaway strain);
      ``info["diverged"]`` is True. Its state stays frozen. A robot that
      diverges while settling (an unstable design or ``sim_config``) starts
      with ``info["diverged"]`` True and terminates at its first step.
    * Truncation: after ``episode_seconds`` (``round(episode_seconds /
      control_dt)`` steps, 80 by default); ``gym.make`` also wraps a
      ``TimeLimit`` of the registered 80 steps, so pass
      ``max_episode_steps=`` as well for longer episodes.

    ## Info

    ``norm_final_dist``, ``max_xy_dist`` (voxel lengths, since the episode
    start), ``l_coefficient`` (the seed's ``MaxXYDist^2 / t_max``, from one
    sample per control step), ``diverged`` (bool) and ``time`` (s since the
    robot was placed). Diverged episodes report
    :data:`softgym.metrics.WORST_FITNESS` for the metrics, as the seed does.
    :meth:`reset`'s info also holds ``muscle_mask`` (bool, one per cell).

    ## Arguments

    ```python
    gym.make("SoftWalker-Wall-v0", design=None, episode_seconds=4.0, control_dt=0.05,
             actuation=None, self_collision=None, grid_shape=(6, 6, 6), render_mode=None)
    ```

    * ``design``: a :class:`~softgym.design.RobotDesign` or the path of its JSON file; None: the default walker.
    * ``task``: ``"flat"``, ``"wall"`` or ``"stairs"`` (set by the id).
    * ``episode_seconds``: controlled time per episode (4 s: the seed's fitness window).
    * ``control_dt``: seconds each action is held (0.05 s, about 78 engine steps of the default walker).
    * ``actuation``: ``"seed"`` (muscles only contract) or ``"symmetric"``; None keeps ``sim_config``'s (the seed's).
    * ``self_collision``: voxel-voxel contact within the robot; None keeps ``sim_config``'s (on).
    * ``grid_shape``: the lattice the spaces are built on; the design must fit in it (placed at its corner).
    * ``sim_config``: a :class:`~softgym.engine.SimConfig` (default the seed's). Its
      ``trace_interval`` is ignored: the env keeps its own centre-of-mass samples.
    * ``terrain``: a :class:`~softgym.terrain.Terrain` replacing the task's.
    * ``render_mode``: None or ``"rgb_array"`` (an H x W x 3 uint8 frame, see
      :class:`softgym.render.VoxelRenderer`); ``width``, ``height``: frame size (320 x 240).
    * ``n_threads``: engine threads (1: a single robot cannot use more).
    * ``max_episode_steps``: an extra cap on the steps per episode (None).

    ## Version History

    * v0: initial version.
    """

    metadata: dict[str, Any] = {"render_modes": ["rgb_array"], "render_fps": 20}

    def __init__(
        self,
        design: RobotDesign | str | os.PathLike[str] | None = None,
        task: str = "flat",
        episode_seconds: float = 4.0,
        control_dt: float = 0.05,
        actuation: str | None = None,
        self_collision: bool | None = None,
        grid_shape: Sequence[int] = (6, 6, 6),
        sim_config: SimConfig | None = None,
        terrain: Terrain | None = None,
        render_mode: str | None = None,
        width: int = 320,
        height: int = 240,
        n_threads: int | None = 1,
        max_episode_steps: int | None = None,
    ) -> None:
        super().__init__()
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise InvalidParameterError(
                f"render_mode must be None or one of {self.metadata['render_modes']}, got {render_mode!r}"
            )
        self.design = load_design(design)
        config = make_config(sim_config, actuation, self_collision)
        self._batch = _WalkerBatch(
            [self.design],
            task,
            tuple(grid_shape),
            control_dt,
            episode_seconds,
            max_episode_steps,
            config,
            None if terrain is None else [terrain],
            n_threads,
        )
        b = self._batch
        self.task = b.task
        self.grid_shape = b.grid_shape
        self.control_dt = b.control_dt
        self.episode_seconds = b.episode_seconds
        self.max_steps = b.max_steps
        self.metadata = {**type(self).metadata, "render_fps": max(1, round(1.0 / b.control_dt))}
        self.render_mode = render_mode
        self.width, self.height = int(width), int(height)
        self._renderer: Any = None
        self.action_space = action_space(b.grid_shape)
        self.observation_space = observation_space(b.grid_shape)
        self._needs_reset = True

    # ------------------------------------------------------------ properties
    @property
    def sim(self) -> Simulation:
        """The engine's :class:`Simulation` of this env (one robot)."""
        return self._batch.sim

    @property
    def terrain(self) -> Terrain:
        """The world's boxes (voxel lengths)."""
        return self._batch.terrains[0]

    @property
    def muscle_mask(self) -> np.ndarray:
        """Ndarray of shape (n_cells,), bool: cells whose action entry drives a muscle (a copy)."""
        return self._batch.muscle_mask[0].copy()

    @property
    def period(self) -> float:
        """Period (s) of the design's controller: the phase observation's period."""
        return float(self._batch.period[0])

    @property
    def time(self) -> float:
        """Seconds since the robot was placed (settling included)."""
        return float(self._batch.clock()[0])

    # ------------------------------------------------------------------- API
    def _info(self, with_mask: bool = False) -> dict[str, Any]:
        raw = self._batch.infos()
        info: dict[str, Any] = {
            "norm_final_dist": float(raw["norm_final_dist"][0]),
            "max_xy_dist": float(raw["max_xy_dist"][0]),
            "l_coefficient": float(raw["l_coefficient"][0]),
            "diverged": bool(raw["diverged"][0]),
            "time": float(raw["time"][0]),
        }
        if with_mask:
            info["muscle_mask"] = self.muscle_mask
        return info

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        """Start an episode: the robot at rest after settling (deterministic).

        Parameters
        ----------
        seed : int, optional
            Seeds ``self.np_random`` (the dynamics have no randomness).
        options : dict, optional
            Unused.

        Returns
        -------
        observation : ndarray of shape (obs_size,), float32
        info : dict
        """
        super().reset(seed=seed)
        self._batch.reset_all()
        self._needs_reset = False
        return self._batch.observations()[0], self._info(with_mask=True)

    def step(self, action: Any) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        """Hold ``action`` for ``control_dt`` seconds.

        Parameters
        ----------
        action : array_like of shape (n_cells,)
            In [-1, 1] (finite values outside are clipped).

        Returns
        -------
        observation, reward, terminated, truncated, info

        Raises
        ------
        InvalidActionError
            If the action has the wrong shape or holds NaN or infinity (the
            state is unchanged).
        """
        b = self._batch
        a = b.validate_actions(action)
        if self._needs_reset:
            raise gym.error.ResetNeeded("call reset() before step()")
        b.apply(a)
        b.advance()
        reward, terminated, truncated, _ = b.update(np.ones(1, dtype=bool))
        return (
            b.observations()[0],
            float(reward[0]),
            bool(terminated[0]),
            bool(truncated[0]),
            self._info(),
        )

    def render(self) -> np.ndarray | None:
        """An H x W x 3 uint8 frame of the robot and its terrain (``render_mode="rgb_array"``)."""
        if self.render_mode is None:
            gym.logger.warn(
                "render() called without a render_mode; pass render_mode='rgb_array' to gym.make"
            )
            return None
        return _render_robot(self, 0)

    def close(self) -> None:
        """Release the renderer; harmless to call more than once."""
        self._renderer = None


def action_space(grid_shape: Sequence[int]) -> spaces.Box:
    """The action space of a grid: ``Box(-1, 1, (nx * ny * nz,), float32)``."""
    return spaces.Box(-1.0, 1.0, (int(np.prod(grid_shape)),), dtype=np.float32)


def observation_space(grid_shape: Sequence[int]) -> spaces.Box:
    """The observation space of a grid (see :class:`SoftWalkerEnv`)."""
    n = int(np.prod(grid_shape))
    high = np.empty(observation_size(grid_shape), dtype=np.float32)
    cell = high[: 6 * n].reshape(n, 6)
    cell[:, 0:3] = OBS_POSITION_BOUND
    cell[:, 3:6] = OBS_VELOCITY_BOUND
    high[6 * n : 6 * n + 3] = OBS_VELOCITY_BOUND
    high[-2:] = 1.0
    return spaces.Box(-high, high, dtype=np.float32)


def _render_robot(env: Any, r: int) -> np.ndarray:
    """Frame of robot ``r`` of an env's batch (the env's renderer is made on first use)."""
    from softgym.render.frames import VoxelRenderer  # lazy: envs import without the renderer

    b = env._batch
    if env._renderer is None:
        env._renderer = VoxelRenderer(env.width, env.height, voxel_size=b.L)
    sim = b.sim
    return env._renderer.render(
        sim.positions(r),
        sim.orientations(r),
        sim.scales(r),
        b.colors(r),
        grid_index=sim.grid_index(r),
        terrain=b.terrains[r],
    )
