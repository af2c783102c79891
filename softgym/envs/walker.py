"""`SoftWalkerEnv`: a Gymnasium environment of one voxel soft robot walking.

The physics is :class:`~softgym.engine.Simulation` (the batched engine), the
task (terrain, duration, reward, metrics) is a :class:`softgym.tasks.Task`, and
:class:`softgym.tasks.EpisodeBatch` runs it as control episodes (dm_control's
Physics / Task / Environment split). This module only adapts a batch of one
robot to Gymnasium's API (spaces, ``reset``/``step``/``render``);
:class:`softgym.envs.vector.SoftWalkerVectorEnv` adapts a batch of N, so both
compute exactly the same numbers for a robot.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import logger, spaces

from softgym.design.robot import RobotDesign, default_walker
from softgym.engine import SimConfig, Simulation
from softgym.exceptions import InvalidActionError, InvalidDesignError, InvalidParameterError
from softgym.tasks import (
    OBS_POSITION_BOUND,
    OBS_VELOCITY_BOUND,
    TASKS,
    EpisodeBatch,
    Task,
    TaskLike,
    get_task,
    observation_size,
)
from softgym.tasks.actions import ACTION_MODES, ActionMap  # noqa: F401 (re-exported)
from softgym.tasks.episode import MAX_STEPS_PER_EPISODE
from softgym.terrain import Terrain
from softgym.validate import threads

__all__ = [
    "ACTION_MODES",
    "OBS_POSITION_BOUND",
    "OBS_VELOCITY_BOUND",
    "TASKS",
    "ActionMap",
    "SoftWalkerEnv",
    "MAX_FRAME_SIDE",
    "action_space",
    "check_render_options",
    "check_temperatures",
    "load_design",
    "make_config",
    "make_batch",
    "observation_size",
    "observation_space",
    "warn_if_cut_short",
]

# the engine's own centre-of-mass trace is not used (the episode samples once per control
# step); a huge sampling interval keeps its buffers at constant size however long the env runs
_NO_ENGINE_TRACE = 1.0e9

#: Largest rendered frame side (pixels): a frame is width x height x 3 bytes.
MAX_FRAME_SIDE = 4096
RENDER_MODES: tuple[str, ...] = ("rgb_array",)
# engine threads an env may ask for (the engine uses at most one per robot anyway)


def _show(value: Any) -> str:
    # repr for an error message: short, and safe for ints beyond repr's 4300 digits
    try:
        text = repr(value)
    except ValueError:
        text = f"<{type(value).__name__} too large to print>"
    return text if len(text) <= 80 else text[:77] + "..."


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


def _is_int(value: Any) -> bool:
    return isinstance(value, (int, np.integer)) and not isinstance(value, (bool, np.bool_))


def check_render_options(render_mode: Any, width: Any, height: Any) -> tuple[int, int]:
    """Check an env's ``render_mode`` (None or ``"rgb_array"``) and frame size; return (width, height).

    Raises
    ------
    InvalidParameterError
        Unless ``render_mode`` is None or one of ``RENDER_MODES`` and
        ``width``, ``height`` are ints (not bools) in 1..:data:`MAX_FRAME_SIDE` pixels.
    """
    if render_mode is not None and not (
        isinstance(render_mode, str) and render_mode in RENDER_MODES
    ):
        raise InvalidParameterError(
            f"render_mode must be None or one of {list(RENDER_MODES)}, got {_show(render_mode)}"
        )
    for name, value in (("width", width), ("height", height)):
        if not _is_int(value) or not 1 <= value <= MAX_FRAME_SIDE:
            raise InvalidParameterError(
                f"{name} must be an integer in 1..{MAX_FRAME_SIDE} pixels, got {_show(value)}"
            )
    return int(width), int(height)


def warn_if_cut_short(limit: int | None, control_dt: float, episode_seconds: float) -> None:
    """Warn when a step limit ends episodes before ``episode_seconds``.

    The ids register ``max_episode_steps=80`` (4 s at the default 0.05 s per
    step); with a finer ``control_dt`` that limit shortens the episode
    unless ``max_episode_steps`` is passed too. ``make_vec`` hands the limit
    to the vector env, which warns; ``gym.make`` applies it in a
    ``TimeLimit`` wrapper the env cannot see (its docstring says so).
    """
    # (an episode has at most MAX_STEPS_PER_EPISODE steps; the ratio may be huge, even inf)
    full = max(1, round(min(episode_seconds / control_dt, MAX_STEPS_PER_EPISODE)))
    if limit is not None and int(limit) < full:
        logger.warn(
            f"max_episode_steps={int(limit)} ends episodes after {int(limit) * control_dt:.4g} s "
            f"of the {episode_seconds:.4g} s episode (control_dt={control_dt:.4g} s); pass "
            f"max_episode_steps={full} for full episodes"
        )


def make_config(
    sim_config: SimConfig | None,
    actuation: str | None,
    self_collision: bool | None,
    task: Task | None = None,
) -> SimConfig:
    """The env's engine settings: ``sim_config`` (the seed's by default), the task's ``sim``, overrides.

    The arguments are checked here and assembled by :meth:`Task.config
    <softgym.tasks.Task.config>` (no task: ``sim_config`` and the overrides
    alone); the engine's own trace is off (the episode samples the robots).
    ``self_collision`` must be None or a bool (``"yes"`` or ``1`` is refused with
    :class:`~softgym.exceptions.InvalidParameterError`, not read as true).
    """
    if actuation is not None and not isinstance(actuation, str):  # the engine checks the name
        raise InvalidParameterError(
            f'actuation must be None, "seed" or "symmetric", got {_show(actuation)}'
        )
    if self_collision is not None and not isinstance(self_collision, (bool, np.bool_)):
        raise InvalidParameterError(
            f"self_collision must be None, True or False, got {_show(self_collision)}"
        )
    if sim_config is not None and not isinstance(sim_config, SimConfig):
        raise InvalidParameterError(
            f"sim_config must be a SimConfig, got {type(sim_config).__name__}"
        )
    return (Task() if task is None else task).config(
        sim_config, settings=task is not None,
        trace_interval=_NO_ENGINE_TRACE, actuation=actuation,
        self_collision=None if self_collision is None else bool(self_collision),
    )  # fmt: skip


def make_batch(
    designs: list[RobotDesign],
    task: TaskLike,
    *,
    terrain: Terrain | None,
    episode_seconds: float | None,
    control_dt: float,
    actuation: str | None,
    self_collision: bool | None,
    grid_shape: Sequence[int],
    sim_config: SimConfig | None,
    n_threads: int | None,
    max_episode_steps: int | None,
    drive: str,
    observe: str = "blind",
    reward_shaping: bool = False,
) -> EpisodeBatch:
    """The :class:`~softgym.tasks.EpisodeBatch` behind a SoftWalker env (the single and vector envs' shared set-up).

    ``task`` is anything :func:`softgym.tasks.get_task` reads; ``terrain``
    replaces its world for every robot; ``episode_seconds`` defaults to the
    task's ``seconds`` minus the settling time (4 s for the seed's 5 s runs).
    A ``max_episode_steps`` that cuts episodes short warns.
    """
    n_threads = threads(n_threads)
    t = get_task(task)
    if terrain is not None:
        if not isinstance(terrain, Terrain):
            raise InvalidParameterError(f"terrain must be a Terrain, got {type(terrain).__name__}")
        t = t.replace(terrain=terrain)
    config = make_config(sim_config, actuation, self_collision, t)
    if episode_seconds is None:
        episode_seconds = t.seconds - float(config.init_time)
        if episode_seconds <= 0:
            raise InvalidParameterError(
                f"the task's {t.seconds} s do not outlast the settling time "
                f"{config.init_time} s; pass episode_seconds"
            )
    batch = EpisodeBatch(
        designs, t, grid_shape, control_dt, episode_seconds, max_episode_steps, config,
        n_threads=n_threads, drive=drive, observe=observe, reward_shaping=reward_shaping,
    )  # fmt: skip
    if max_episode_steps is not None:
        warn_if_cut_short(max_episode_steps, batch.control_dt, batch.episode_seconds)
    return batch


def check_temperatures(fraction: Any, shape: tuple[int, ...]) -> np.ndarray:
    """``fraction`` as float64 of ``shape``, each value in [-1, 1] (the argument of
    :meth:`SoftWalkerEnv.action_from_temperatures` and its vector env's).

    Raises
    ------
    InvalidActionError
        Naming the shape expected and given, or a value that is not a number in [-1, 1].
    """
    try:
        f = np.asarray(fraction, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InvalidActionError(f"temperature fractions must be numbers, got {_show(fraction)} "
                                 f"({exc!s:.80})") from None  # fmt: skip
    if f.shape != tuple(shape):
        raise InvalidActionError(
            f"temperature fractions must have shape {tuple(shape)} (one per cell), got {f.shape}"
        )
    if not (np.isfinite(f).all() and np.abs(f).max(initial=0.0) <= 1.0):
        raise InvalidActionError("temperature fractions must be finite numbers in [-1, 1]")
    return f


class SoftWalkerEnv(gym.Env):
    """A 3-D voxel soft robot that must walk, on flat ground, out of a fence or up stairs.

    Description
    -----------
    One robot (by default the embedded 6x6x6 walker, :func:`~softgym.design.default_walker`)
    is simulated by softgym's lattice engine with the seed study's settings
    (evosoro / Ev-SoftBots: 1 cm voxels, thermal muscles, floor friction,
    self-collision). Instead of the seed's global sinusoid, the agent sets
    every muscle voxel's contraction at each control step. The ids:

    * ``SoftWalker-Flat-v0``: flat floor; reward on the seed's ``NormFinalDist``.
    * ``SoftWalker-Wall-v0``: the seed's fence (a square wall 1 voxel high and
      thick, 2 voxels from the robot); reward on Ev-SoftBots' ``MaxXYDist``.
    * ``SoftWalker-Stairs-v0``: three concentric rings, each one voxel higher
      than the one inside it; reward on ``MaxXYDist``.

    and the rest of the task suite (:mod:`softgym.tasks.suite`), each rewarded
    on the progress of its own measure (:mod:`softgym.metrics.task_measures`):

    ==============================  ==============================================  ===================
    id                              world and goal                                  measure
    ==============================  ==============================================  ===================
    ``SoftWalker-StairsDown-v0``    walk down a stepped pyramid from its top        ``max_xy_dist``
    ``SoftWalker-Rough-v0``         a seeded random height field of boxes           ``max_xy_dist``
    ``SoftWalker-Gap-v0``           no floor: cross the pit around the start        ``gap_crossed``
    ``SoftWalker-Tunnel-v0``        crawl out under a low ring-shaped roof          ``max_xy_dist``
    ``SoftWalker-Incline-v0``       walk uphill (+x): gravity tilted                ``x_progress``
    ``SoftWalker-Ice-v0``           ground friction x 0.1                           ``norm_final_dist``
    ``SoftWalker-Mud-v0``           ground friction x 4                             ``norm_final_dist``
    ``SoftWalker-Jump-v0``          raise the centre of mass                        ``peak_height``
    ``SoftWalker-Turn-v0``          turn in place about z                           ``yaw`` (rad)
    ``SoftWalker-Push-v0``          push a box to a target                          ``push_progress``
    ``SoftWalker-Carry-v0``         walk with a cap on top, not dropping it         ``carried_dist``
    ``SoftWalker-Swim-v0``          no floor, no weight, drag on exposed faces      ``swim_dist``
    ``SoftWalker-Grow-v0``          spread the largest footprint                    ``footprint_gain``
    ==============================  ==============================================  ===================

    A task's difficulty arguments go through ``task=``:
    ``gym.make("SoftWalker-Gap-v0", task="gap:width=4")`` or
    ``task=softgym.tasks.Task("gap", options={"width": 4})``; out-of-range
    values raise :class:`~softgym.exceptions.InvalidParameterError`. Movable
    objects (push, carry) are not part of the observation (the robot feels
    them through contact).

    The spaces depend on ``grid_shape`` only, never on the body, so any two
    bodies of one grid share them (and one vector env can hold both).

    Action Space
    ------------
    ``Box(-1, 1, (nx * ny * nz,), float32)``: one entry per grid cell, in
    C order (x slowest, z fastest: ``action.reshape(grid_shape)[i, j, k]``
    drives voxel ``(i, j, k)``). Entries of empty and passive cells are
    ignored (``env.muscle_mask`` and ``info["muscle_mask"]`` of :meth:`reset`
    tell which count). Each action is held for ``control_dt`` seconds. What
    an entry means is ``action_mode`` (:class:`ActionMap`):

    * ``"contraction"`` (the default under the seed's actuation law): the
      temperature ``T = (a - s) dT / 2``, ``s = sign(CTE)`` of the cell's
      muscle, ``dT`` the design's controller amplitude (14 degC by default):
      the seed's signal halved and shifted into the muscles' contracting
      range, so the muscle contracts by ``(1 - s a) / 2`` of its full range
      (size ``L (1 - |CTE| dT (1 - s a) / 2)``). ``a = -1`` fully contracts
      the positive-CTE muscles and rests the negative ones, ``+1`` the
      reverse, ``0`` half contracts both. Every action sets the size; none
      holds it. One value on every cell drives the two muscle kinds in
      counter-phase, as the seed's drive does (``sin(2 pi t / period)`` on
      every cell walks 2.68 voxel lengths in 4 s at 0.05 s steps).
    * ``"temperature"`` (the default with ``actuation="symmetric"``): the
      temperature ``T = a dT``, the seed's signal; the size follows
      ``L (1 + CTE T)`` under the actuation law. Under the seed's law
      (muscles only contract) a command that would expand a muscle keeps its
      last size, so half of each entry's range means "hold" and only commands
      back towards 0 relax a contracted muscle.

    Why contraction is the default: under the seed's law with temperature
    actions PPO (SB3, 600k steps) walked 0.135 voxel lengths in 4 s on
    ``SoftWalker-Flat-v0``, below the seed's sinusoid (0.67): a policy that
    overshoots holds its muscles contracted, and the hold changes the seed's
    own gait when sampled every 0.05 s (0.67 against the engine's 4.38).
    Through contraction actions (:meth:`action_from_temperatures`) the
    seed's sinusoid walks 2.91 at 0.05 s (``benchmarks/RESULTS.md``). The
    physics is the seed's either way; ``action_mode="temperature"`` gives
    the seed's signal back.

    :class:`softgym.policies.Sinusoid` returns the seed's temperature signal
    ``sin(2 pi t / period)`` on every cell; :meth:`action_from_temperatures`
    turns it into this env's action (identity in ``"temperature"`` mode).
    Sampled every ``control_dt <= 0.005`` s in ``"temperature"`` mode it walks
    the engine's built-in sinusoid's distance to within 1 %, while 0.05 s
    (5 samples per 0.25 s period) changes the seed's gait.

    An action must be an array (or nested list) of real numbers of shape
    exactly ``(nx * ny * nz,)``: another shape of the same size (e.g. the grid
    shape) is refused, not reshaped, and so are complex, bool, object and
    string dtypes; ints and floats of any precision are read as float64.
    Finite values outside [-1, 1] are clipped to it (documented, not an
    error). A refused action, or one holding NaN or infinity, raises
    :class:`~softgym.exceptions.InvalidActionError` before the state is touched.

    Observation Space
    -----------------
    ``Box(low, high, (6 * nx * ny * nz + 5,), float32)`` (1301 for 6x6x6):

    ======================  =======================================================  =================  =====
    index                   observation                                              unit               bound
    ======================  =======================================================  =================  =====
    ``6 c + 0 .. 6 c + 2``  cell ``c``'s voxel centre minus the centre of mass       voxel lengths      +-50
                            (x, y, z)
    ``6 c + 3 .. 6 c + 5``  cell ``c``'s voxel velocity minus the CM velocity        voxel lengths / s  +-500
    ``6 n .. 6 n + 2``      centre-of-mass velocity (x, y, z)                        voxel lengths / s  +-500
    ``6 n + 3``             ``sin(2 pi t / period)``                                                    +-1
    ``6 n + 4``             ``cos(2 pi t / period)``                                                    +-1
    ======================  =======================================================  =================  =====

    ``c`` is the cell's C-order index, ``n = nx * ny * nz`` (so
    ``obs[:6 * n].reshape(nx, ny, nz, 6)`` is a grid of features); empty cells
    are zeros. Vectors are in the world frame (z up). ``t`` is the robot's
    time since it was placed (settling included), ``period`` its controller's.
    Values beyond the bounds are clipped (only a diverging robot reaches them).

    With ``observe="sensing"`` (the ``SoftWalker-<Task>-Sensing-v0`` ids) the
    robot observes every sensor instead (:mod:`softgym.tasks.sensing`): 8
    values per cell (position and velocity relative to the centre of mass,
    touch, bond strain), 11 of the robot (centre-of-mass velocity, its up and
    forward axes, the clock's sin and cos) and the task's own senses (the
    object and the target of ``push``, terrain heights ahead on the obstacle
    tasks, ...): ``Box(-bounds, bounds)`` of
    :func:`~softgym.tasks.sensing.sensing_layout` ``(task, grid_shape).size``
    values (1747 for push on 6x6x6); each task's page lists them.

    Rewards
    -------
    The per-step progress of the task metric, in voxel lengths: on Flat the
    increase of ``NormFinalDist = |CM_xy(t) - CM_xy(t0)| / L``; on Wall and
    Stairs the increase of ``MaxXYDist = max(|dx|, |dy|) / L`` (the seed's
    obstacle fitness); on the suite's other tasks the increase of their
    measure; ``t0`` is the episode start (after settling). The
    return of an episode is therefore the metric at its end (``info["score"]``): with the default
    4 s episode, the seed's fitness over its window t in (1, 5] s. A diverged
    episode forfeits its progress: the diverging step's reward makes its
    return 0.

    Starting State
    --------------
    The robot is placed with its grid's corner at the origin, at rest on the
    floor, and settles for ``SimConfig.init_time`` (1 s, the seed's
    ``InitCmTime``) with its muscles idle inside :meth:`reset` (the settled
    state is computed once and reused). The start is deterministic: the
    engine has no noise, and ``seed`` only seeds ``np_random``.

    Episode End
    -----------
    * Termination: the robot diverged (non-finite state or runaway strain);
      ``info["diverged"]`` is True. Its state stays frozen. A robot that
      diverges while settling (an unstable design or ``sim_config``) starts
      with ``info["diverged"]`` True and terminates at its first step.
    * Truncation: after ``episode_seconds`` (``round(episode_seconds /
      control_dt)`` steps, 80 by default). The ids register no step limit,
      so the episode lasts its seconds whatever ``control_dt``
      (``control_dt=0.005`` gives 800 steps of 4 s).

    Info
    ----
    The task's metrics (:meth:`softgym.tasks.EpisodeBatch.metrics`, computed by
    :func:`softgym.metrics.walk_metrics_from_arrays` like :func:`softgym.evaluate`'s):
    ``norm_final_dist``, ``max_xy_dist`` (voxel lengths, since the episode
    start), ``l_coefficient`` (the seed's ``MaxXYDist^2 / t_max``, from one
    centre-of-mass sample per control step, ``t_max`` the engine time of the
    first sample within 0.1 voxel of ``MaxXYDist``), ``diverged`` (bool) and
    ``time`` (s since the robot was placed), ``score`` (the task's reward
    metric) and, on a suite task, its measure by name. Diverged episodes report
    :data:`softgym.metrics.WORST_FITNESS` for the metrics, as the seed does.
    :meth:`reset`'s info also holds ``muscle_mask`` (bool, one per cell).

    Parameters
    ----------
    design : RobotDesign, str, os.PathLike or None, default None
        A :class:`~softgym.design.RobotDesign` or the path of its JSON file; None: the
        default walker.
    task : str, Task, Terrain or path, default "flat"
        A task name (``"flat"``, ``"wall"``, ``"stairs"``...: set by the id), a
        :class:`softgym.tasks.Task`, a :class:`~softgym.terrain.Terrain` or a terrain
        JSON file (anything :func:`softgym.tasks.get_task` reads).
    episode_seconds : float or None, default None
        Controlled time per episode (s); None: the task's ``seconds`` minus the
        settling time (4 s: the seed's fitness window).
    control_dt : float, default 0.05
        Seconds each action is held (about 78 engine steps of the default walker), a
        finite number in (0, 10] s.
    actuation : {"seed", "symmetric"} or None, default None
        ``"seed"``: muscles only contract; ``"symmetric"``: they also expand. None
        keeps ``sim_config``'s (the seed's).
    self_collision : bool or None, default None
        Voxel-voxel contact within the robot; None keeps ``sim_config``'s (on).
    grid_shape : sequence of 3 ints, default (6, 6, 6)
        The lattice the spaces are built on (each 1 to 1000, at most 10^6 cells;
        floats such as 6.5 are refused); the design must fit in it (placed at its
        corner).
    sim_config : SimConfig or None, default None
        The engine's settings (default the seed's). Its ``trace_interval`` is
        ignored: the env keeps its own centre-of-mass samples.
    terrain : Terrain or None, default None
        A world replacing the task's.
    render_mode : {"rgb_array"} or None, default None
        ``"rgb_array"``: :meth:`render` returns an H x W x 3 uint8 frame (see
        :class:`softgym.render.VoxelRenderer`).
    width : int, default 320
        Frame width in pixels, from 1 to 4096.
    height : int, default 240
        Frame height in pixels, from 1 to 4096.
    n_threads : int or None, default 1
        Engine threads, None or an int from 1 to 1024 (a single robot cannot use
        more than 1).
    max_episode_steps : int or None, default None
        An extra cap on the steps per episode: None or an int from 1 to
        :data:`softgym.tasks.episode.MAX_STEPS_PER_EPISODE` (not a bool or a float),
        checked by the env. ``gym.make(id, max_episode_steps=...)`` is different:
        Gymnasium consumes it for a ``TimeLimit`` wrapper (the ids register none;
        ``-1`` means none; Gymnasium raises its own TypeError or ValueError for bad
        values) and the env never receives it; the env's own cap goes through
        ``SoftWalkerEnv(max_episode_steps=k)`` or ``make_vec``.
    drive : {"action", "controller"}, default "action"
        ``"controller"``: the design's own sinusoidal controller drives the muscles
        as in :func:`softgym.evaluate` and the seed, and actions are ignored (the
        open-loop baseline; with ``control_dt`` equal to the task's
        ``trace_interval`` an episode reports exactly ``softgym.evaluate``'s
        metrics).
    action_mode : {"contraction", "temperature"} or None, default None
        See Action Space; None: contraction under the seed's actuation law,
        temperature under ``"symmetric"``.
    observe : {"blind", "sensing"}, default "blind"
        ``"blind"``: the table of Observation Space; ``"sensing"``: every sensor and
        the task's senses (the ``-Sensing-v0`` ids set it).
    reward_shaping : bool, default False
        Add the task's dense guidance to the reward (``push``, ``push_uphill``: the
        robot's progress toward the box's target; ``gap``: its farthest reach while on
        top; :attr:`TaskKind.shaping <softgym.tasks.suite.TaskKind.shaping>`), each
        term's per-step progress times its weight; ``info["score"]`` stays the task's
        measure. For reinforcement learning on tasks whose measure only moves on success.

    Examples
    --------
    >>> import gymnasium as gym
    >>> import softgym  # registers the ids
    >>> env = gym.make("SoftWalker-Wall-v0", control_dt=0.05, action_mode="contraction")
    >>> obs, info = env.reset(seed=0)
    >>> obs.shape
    (1301,)

    Version History
    ---------------
    * ``-Sensing-v0`` (new ids beside the ``-v0`` ones, which are unchanged): the
      sensing observation (``observe="sensing"``).

    * v0: initial version. Since issue 33: ``action_mode`` (contractions by default
      under the seed's law; ``action_mode="temperature"`` is the former action), and the ids
      register no ``max_episode_steps`` (the episode lasts ``episode_seconds`` at any
      ``control_dt``; it was 80 steps whatever the step). Since the task suite (issue 14): ``info["score"]``, 13 more ids,
      task arguments in ``task=``. Since the task layer (issue 11): ``task`` also takes a Task,
      Terrain or JSON file, ``episode_seconds`` defaults to the task's, the wall is centred on
      the design's grid (as in ``softgym.evaluate``; the default walker fills its grid, so
      its world is unchanged), ``l_coefficient`` uses the engine's sample times, and
      ``drive="controller"`` was added.
    """

    metadata: dict[str, Any] = {"render_modes": ["rgb_array"], "render_fps": 20}

    def __init__(
        self,
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
        n_threads: int | None = 1,
        max_episode_steps: int | None = None,
        drive: str = "action",
        action_mode: str | None = None,
        observe: str = "blind",
        reward_shaping: bool = False,
    ) -> None:
        super().__init__()
        size = check_render_options(render_mode, width, height)
        self.design = load_design(design)
        self._batch = make_batch(
            [self.design], task, terrain=terrain, episode_seconds=episode_seconds,
            control_dt=control_dt, actuation=actuation, self_collision=self_collision,
            grid_shape=grid_shape, sim_config=sim_config, n_threads=n_threads,
            max_episode_steps=max_episode_steps, drive=drive, observe=observe,
            reward_shaping=reward_shaping,
        )  # fmt: skip
        b = self._batch
        self.observe = b.observe
        self._action_map = ActionMap(b, action_mode)
        self.action_mode = self._action_map.mode
        self.task = b.task
        self.grid_shape = b.grid_shape
        self.control_dt = b.control_dt
        self.episode_seconds = b.episode_seconds
        self.max_steps = b.max_steps
        self.metadata = {**type(self).metadata, "render_fps": max(1, round(1.0 / b.control_dt))}
        self.render_mode = render_mode
        self.width, self.height = size
        self._renderer: Any = None
        self.action_space = action_space(b.grid_shape)
        self.observation_space = observation_space(b.grid_shape, b.task, b.observe)
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

    def action_from_temperatures(self, fraction: Any) -> np.ndarray:
        """The action giving each muscle the size the temperature ``fraction * dT`` gives it.

        ``fraction`` has shape (n_cells,), values in [-1, 1] (a temperature
        signal such as :class:`softgym.policies.Sinusoid`'s, the seed's
        drive). In ``action_mode="temperature"`` it is the action itself; in
        ``"contraction"`` a command that would expand a muscle leaves it at
        rest (the seed's law without its hold). Returns float32 of shape (n_cells,).
        """
        f = check_temperatures(fraction, self.action_space.shape)
        return self._action_map.from_temperatures(f.reshape(1, -1))[0]

    @property
    def time(self) -> float:
        """Seconds since the robot was placed (settling included)."""
        return float(self._batch.clock()[0])

    # ------------------------------------------------------------------- API
    def _info(self, with_mask: bool = False) -> dict[str, Any]:
        raw = self._batch.infos()
        info: dict[str, Any] = {
            key: (bool(v[0]) if key == "diverged" else float(v[0])) for key, v in raw.items()
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
        action : array_like of shape (n_cells,), int or float
            In [-1, 1] (finite values outside are clipped); exactly this
            shape, a real dtype (see the class docstring).

        Returns
        -------
        observation, reward, terminated, truncated, info

        Raises
        ------
        InvalidActionError
            If the action has the wrong shape or dtype or holds NaN or
            infinity (the state is unchanged).
        """
        b = self._batch
        a = b.validate_actions(action, single=True)
        if self._needs_reset:
            raise gym.error.ResetNeeded(
                "call reset() before step(): the episode has not started or has ended "
                "(terminated or truncated)"
            )
        b.apply(self._action_map(a))
        b.advance()
        reward, terminated, truncated, _ = b.update(np.ones(1, dtype=bool))
        # Gymnasium's convention: an episode that ended needs reset() (issue 31: the env
        # went on stepping after truncation)
        self._needs_reset = bool(terminated[0] or truncated[0])
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
        return self._batch.render_frame(self._get_renderer(), 0)

    def _get_renderer(self) -> Any:
        if self._renderer is None:
            from softgym.render import VoxelRenderer  # lazy: envs import without the renderer

            self._renderer = VoxelRenderer(self.width, self.height, voxel_size=self._batch.L)
        return self._renderer

    def close(self) -> None:
        """Release the renderer; harmless to call more than once."""
        self._renderer = None


def action_space(grid_shape: Sequence[int]) -> spaces.Box:
    """The action space of a grid: ``Box(-1, 1, (nx * ny * nz,), float32)``."""
    return spaces.Box(-1.0, 1.0, (int(np.prod(grid_shape)),), dtype=np.float32)


def observation_space(grid_shape: Sequence[int], task: Task | None = None,
                      observe: str = "blind") -> spaces.Box:  # fmt: skip
    """The observation space of a grid (see :class:`SoftWalkerEnv`): blind, or a task's sensing one."""
    if observe == "sensing":
        from softgym.tasks.sensing import sensing_layout

        high = sensing_layout(Task() if task is None else task, grid_shape).bounds().astype(np.float32)
        return spaces.Box(-high, high, dtype=np.float32)
    n = int(np.prod(grid_shape))
    high = np.empty(observation_size(grid_shape), dtype=np.float32)
    cell = high[: 6 * n].reshape(n, 6)
    cell[:, 0:3] = OBS_POSITION_BOUND
    cell[:, 3:6] = OBS_VELOCITY_BOUND
    high[6 * n : 6 * n + 3] = OBS_VELOCITY_BOUND
    high[-2:] = 1.0
    return spaces.Box(-high, high, dtype=np.float32)
