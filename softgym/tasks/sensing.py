"""What a robot senses: per-voxel, per-robot and per-task sensors, read for a whole batch at once.

The sensing observation of a robot on a grid of ``n`` cells is, in this order:

* **per cell** (:data:`CELL_SENSORS`, 8 values, C order of the grid; empty
  cells are zeros): the voxel centre minus the centre of mass (voxel
  lengths), its velocity minus the centre-of-mass velocity (voxel lengths /
  s), ``touch`` (1 in contact with the floor, a box, an obstacle voxel, a
  movable object or its own robot's voxels more than 3 lattice steps away,
  falling linearly to 0 at a gap of :data:`TOUCH_REACH` voxel lengths:
  :meth:`softgym.engine.Simulation.contact_gaps`) and ``strain`` (the mean
  relative stretch of its bonds to its lattice neighbours: ``|p_i - p_j| /
  L - 1``, actuation included);
* **per robot** (:data:`ROBOT_SENSORS`, 11 values): the centre-of-mass
  velocity, the body's ``up`` and ``forward`` axes in the world (the best-fit
  rotation of its voxel centres from their lattice positions: its +z and +x
  axes) and the clock phase ``sin, cos(2 pi t / period)``;
* **per task**: the task's own senses (:class:`TaskSense`), declared by its
  kind next to its layout and measure (:mod:`softgym.tasks.suite`): an
  object's position and velocity relative to the robot, a target relative
  to the object or a goal relative to the robot, the heading turned so far,
  terrain heights ahead, the slope.

:func:`sensing_layout` gives the labels, bounds and input scales of a task on
a grid (the env's observation space and the task pages' tables);
:class:`Sensing` reads them for every robot of an
:class:`~softgym.tasks.EpisodeBatch` after each engine call, with no loop over
robots (the contact gaps come from the engine's compiled sensor).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from softgym.tasks.episode import EpisodeBatch
    from softgym.terrain import Terrain

__all__ = [
    "CELL_SENSORS",
    "HEIGHT_BOUND",
    "ROBOT_SENSORS",
    "SENSES",
    "TERRAIN_DIRECTIONS",
    "TERRAIN_DISTANCES",
    "TOUCH_REACH",
    "SenseContext",
    "SenseLayout",
    "Sensing",
    "TaskSense",
    "sensing_layout",
]

#: Gap (voxel lengths) at which ``touch`` falls to 0 (1 at contact).
TOUCH_REACH = 0.1
#: Terrain heights are clipped to +-this (voxel lengths).
HEIGHT_BOUND = 10.0
#: Directions of the terrain samples, degrees from the body's forward axis (counter-clockwise).
TERRAIN_DIRECTIONS: tuple[float, ...] = (0.0, 45.0, 90.0, 135.0, 180.0, 225.0, 270.0, 315.0)
#: Distances of the terrain samples from the centre of mass (voxel lengths).
TERRAIN_DISTANCES: tuple[float, ...] = (4.0, 7.0)

#: The per-cell sensors, in order: (label, bound, input scale of a brain).
CELL_SENSORS: tuple[tuple[str, float, float], ...] = (
    ("dx", 50.0, 3.0), ("dy", 50.0, 3.0), ("dz", 50.0, 3.0),
    ("vx", 500.0, 10.0), ("vy", 500.0, 10.0), ("vz", 500.0, 10.0),
    ("touch", 1.0, 1.0), ("strain", 1.0, 0.25),
)  # fmt: skip
#: The per-robot sensors, in order: (label, bound, input scale of a brain).
ROBOT_SENSORS: tuple[tuple[str, float, float], ...] = (
    ("cm_vx", 500.0, 5.0), ("cm_vy", 500.0, 5.0), ("cm_vz", 500.0, 5.0),
    ("up_x", 1.0, 1.0), ("up_y", 1.0, 1.0), ("up_z", 1.0, 1.0),
    ("forward_x", 1.0, 1.0), ("forward_y", 1.0, 1.0), ("forward_z", 1.0, 1.0),
    ("clock_sin", 1.0, 1.0), ("clock_cos", 1.0, 1.0),
)  # fmt: skip


@dataclass(frozen=True)
class SenseContext:
    """What a task sense reads, for every robot of a batch (SI units unless said).

    Attributes
    ----------
    cm, cm_vel : ndarray (n, 3)
        Centre of mass (m) and its velocity (m/s).
    rot : ndarray (n, 3, 3)
        The body's rotation (columns: its x, y, z axes in the world).
    object_cm, object_vel : ndarray (n, 3)
        The movable objects' centre of mass and velocity (0 without objects).
    aux, aux0 : ndarray (n, n_aux)
        The kernel's auxiliary measures now and at the episode start
        (:data:`softgym.engine.AUX_NAMES`).
    params : dict
        The task measures' per-robot parameters (:func:`softgym.tasks.task.measure_params`).
    heights : callable
        ``heights(xy)`` with ``xy`` of shape (n, k, 2) in voxel lengths:
        each robot's terrain height there (voxel lengths; ``-HEIGHT_BOUND``
        over a pit with no floor).
    gravity : ndarray (3,)
        Unit vector of gravity in the world (the incline tilts it).
    voxel_size : float
    """

    cm: np.ndarray
    cm_vel: np.ndarray
    rot: np.ndarray
    object_cm: np.ndarray
    object_vel: np.ndarray
    aux: np.ndarray
    aux0: np.ndarray
    params: dict[str, np.ndarray]
    heights: Callable[[np.ndarray], np.ndarray]
    gravity: np.ndarray
    voxel_size: float


@dataclass(frozen=True)
class TaskSense:
    """A task's sense: named values of every robot, read from a :class:`SenseContext`.

    Parameters
    ----------
    name : str
    labels : tuple of str
        One per value.
    bound : float
        Values are clipped to +-bound (the observation space's box).
    scale : float
        A brain divides the values by this before its network.
    read : callable
        ``read(ctx) -> ndarray (n_robots, len(labels))``.
    doc : str
        What the values are (units), for the task pages.
    """

    name: str
    labels: tuple[str, ...]
    bound: float
    scale: float
    read: Callable[[SenseContext], np.ndarray]
    doc: str


def _object(ctx: SenseContext) -> np.ndarray:
    L = ctx.voxel_size
    return np.column_stack([(ctx.object_cm - ctx.cm) / L, (ctx.object_vel - ctx.cm_vel) / L])


def _target(ctx: SenseContext) -> np.ndarray:
    return ctx.params["target"] - ctx.object_cm[:, :2] / ctx.voxel_size


def _goal(ctx: SenseContext) -> np.ndarray:
    return ctx.params["target"] - ctx.cm[:, :2] / ctx.voxel_size


def _heading(ctx: SenseContext) -> np.ndarray:
    now = np.arctan2(ctx.aux[:, 4], ctx.aux[:, 3])
    start = np.arctan2(ctx.aux0[:, 4], ctx.aux0[:, 3])
    d = now - start
    return np.column_stack([np.sin(d), np.cos(d)])


def _terrain(ctx: SenseContext) -> np.ndarray:
    fwd = ctx.rot[:, :2, 0]
    yaw = np.arctan2(fwd[:, 1], fwd[:, 0])
    ang = yaw[:, None] + np.radians(np.asarray(TERRAIN_DIRECTIONS))[None, :]  # (n, n_dir)
    cm = ctx.cm[:, :2] / ctx.voxel_size
    pts = [cm[:, None, :]]
    for d in TERRAIN_DISTANCES:
        pts.append(cm[:, None, :] + d * np.stack([np.cos(ang), np.sin(ang)], axis=-1))
    h = ctx.heights(np.concatenate(pts, axis=1))
    return h[:, 1:] - h[:, :1]


def _gravity(ctx: SenseContext) -> np.ndarray:
    return np.einsum("rij,i->rj", ctx.rot, ctx.gravity)


def _terrain_labels() -> tuple[str, ...]:
    return tuple(f"height_{d:g}_at_{a:g}" for d in TERRAIN_DISTANCES for a in TERRAIN_DIRECTIONS)


#: The task senses by name.
SENSES: dict[str, TaskSense] = {
    s.name: s
    for s in (
        TaskSense("object", ("object_dx", "object_dy", "object_dz", "object_vx", "object_vy",
                             "object_vz"), 500.0, 5.0, _object,
                  "the movable objects' centre of mass minus the robot's (voxel lengths) and "
                  "their velocity minus the robot's (voxel lengths / s), world frame"),
        TaskSense("target", ("target_dx", "target_dy"), 1000.0, 10.0, _target,
                  "the push target minus the object's centre (x, y; voxel lengths)"),
        TaskSense("goal", ("goal_dx", "goal_dy"), 1000.0, 10.0, _goal,
                  "the goal minus the robot's centre of mass (x, y; voxel lengths)"),
        TaskSense("heading", ("turned_sin", "turned_cos"), 1.0, 1.0, _heading,
                  "sine and cosine of the heading turned since the episode start"),
        TaskSense("terrain", _terrain_labels(), HEIGHT_BOUND, 3.0, _terrain,
                  "terrain height (top of the highest box, the floor, or -10 over a pit) at "
                  f"{', '.join(f'{d:g}' for d in TERRAIN_DISTANCES)} voxel lengths from the "
                  f"centre of mass in {len(TERRAIN_DIRECTIONS)} directions from the body's "
                  "forward axis, minus the height under the centre of mass (voxel lengths)"),
        TaskSense("gravity", ("gravity_x", "gravity_y", "gravity_z"), 1.0, 1.0, _gravity,
                  "gravity's direction in the body frame (the slope, for a robot that "
                  "cannot see it)"),
    )
}  # fmt: skip


@dataclass(frozen=True)
class SenseLayout:
    """The sensing observation of a task on a grid: labels, bounds and a brain's input scales.

    Attributes
    ----------
    grid_shape : tuple of 3 int
    task_senses : tuple of TaskSense
    """

    grid_shape: tuple[int, int, int]
    task_senses: tuple[TaskSense, ...]

    @property
    def n_cells(self) -> int:
        """Cells of the grid."""
        return int(np.prod(self.grid_shape))

    @property
    def n_task(self) -> int:
        """Values of the task's senses."""
        return sum(len(s.labels) for s in self.task_senses)

    @property
    def size(self) -> int:
        """Length of the observation vector: 8 per cell, 11 per robot, the task's."""
        return len(CELL_SENSORS) * self.n_cells + len(ROBOT_SENSORS) + self.n_task

    @property
    def local_size(self) -> int:
        """A distributed brain's sensor inputs per voxel: its cell's, the robot's, the task's."""
        return len(CELL_SENSORS) + len(ROBOT_SENSORS) + self.n_task

    def labels(self) -> list[str]:
        """Every value's label, in the observation's order (``c12_touch``, ``clock_sin``, ...)."""
        out = [f"c{c}_{name}" for c in range(self.n_cells) for name, _, _ in CELL_SENSORS]
        out += [name for name, _, _ in ROBOT_SENSORS]
        for s in self.task_senses:
            out += list(s.labels)
        return out

    def _column(self, which: int) -> np.ndarray:
        cell = np.array([row[which] for row in CELL_SENSORS])
        rob = np.array([row[which] for row in ROBOT_SENSORS])
        task = [np.full(len(s.labels), s.bound if which == 1 else s.scale) for s in self.task_senses]
        return np.concatenate([np.tile(cell, self.n_cells), rob, *task])

    def bounds(self) -> np.ndarray:
        """Each value's bound (the observation box is +-bound), shape (size,)."""
        return self._column(1)

    def scales(self) -> np.ndarray:
        """Each value's input scale for a brain, shape (size,)."""
        return self._column(2)

    def local_scales(self) -> np.ndarray:
        """A distributed brain's input scales for one voxel's sensors, shape (local_size,)."""
        cell = np.array([row[2] for row in CELL_SENSORS])
        rob = np.array([row[2] for row in ROBOT_SENSORS])
        task = [np.full(len(s.labels), s.scale) for s in self.task_senses]
        return np.concatenate([cell, rob, *task])

    def table(self) -> list[tuple[str, str, str]]:
        """Rows (index, what, bound) for a task page: ``c`` a cell's C-order index, ``n`` the cells."""
        k = len(CELL_SENSORS)
        rows = [(f"{k} c + {i}", f"cell c: {name}", f"+-{b:g}") for i, (name, b, _) in enumerate(CELL_SENSORS)]
        rows += [(f"{k} n + {i}", name, f"+-{b:g}") for i, (name, b, _) in enumerate(ROBOT_SENSORS)]
        at = len(ROBOT_SENSORS)
        for s in self.task_senses:
            end = at + len(s.labels) - 1
            idx = f"{k} n + {at}" + (f" .. {k} n + {end}" if end > at else "")
            rows.append((idx, f"{s.name}: {s.doc}", f"+-{s.bound:g}"))
            at = end + 1
        return rows


def sensing_layout(task: Any, grid_shape: Sequence[int]) -> SenseLayout:
    """The sensing observation's layout of ``task`` (a :class:`~softgym.tasks.Task`) on a grid.

    Raises
    ------
    InvalidParameterError
        For a grid that is not 3 integers within the design caps
        (:func:`softgym.design.check_grid_shape`) or a task that is not a Task.
    """
    from softgym.design import check_grid_shape
    from softgym.exceptions import InvalidDesignError, InvalidParameterError
    from softgym.tasks.task import Task

    if not isinstance(task, Task):
        raise InvalidParameterError(f"task must be a softgym Task, got {type(task).__name__}")
    try:
        shape = check_grid_shape(grid_shape, "grid_shape")
    except InvalidDesignError as exc:
        raise InvalidParameterError(str(exc)) from None
    return SenseLayout(shape, tuple(task.senses))


class _Heights:
    """Terrain heights of every robot's world at many points at once (voxel lengths)."""

    def __init__(self, terrains: Sequence[Terrain], floors: np.ndarray) -> None:
        n = len(terrains)
        m = max([len(t.boxes) for t in terrains] + [1])
        self.boxes = np.zeros((n, m, 6))
        self.valid = np.zeros((n, m), dtype=bool)
        for r, t in enumerate(terrains):
            for j, b in enumerate(t.boxes):
                self.boxes[r, j] = (*b.lo, *b.hi)
                self.valid[r, j] = True
        self.floor = np.where(floors, 0.0, -HEIGHT_BOUND)

    def __call__(self, xy: np.ndarray) -> np.ndarray:
        b = self.boxes[:, None, :, :]
        x = xy[:, :, None, 0]
        y = xy[:, :, None, 1]
        inside = (self.valid[:, None, :] & (x >= b[..., 0]) & (x <= b[..., 3])
                  & (y >= b[..., 1]) & (y <= b[..., 4]))  # fmt: skip
        top = np.where(inside, b[..., 5], -np.inf).max(axis=2)
        return np.clip(np.maximum(top, self.floor[:, None]), -HEIGHT_BOUND, HEIGHT_BOUND)


class Sensing:
    """The sensors of every robot of an :class:`~softgym.tasks.EpisodeBatch`, read at once.

    Parameters
    ----------
    batch : EpisodeBatch
        Its simulation, robots, grid, terrains and task.
    """

    def __init__(self, batch: EpisodeBatch) -> None:
        self.batch = batch
        self.layout = sensing_layout(batch.task, batch.grid_shape)
        n, nc = batch.n_robots, batch.n_cells
        self.L = float(batch.L)
        # the lattice positions of every cell (voxel lengths) and each robot's filled cells
        idx = np.stack(np.unravel_index(np.arange(nc), batch.grid_shape), axis=1).astype(np.float64)
        w = batch.filled_mask.reshape(n, nc).astype(np.float64)
        count = np.maximum(w.sum(axis=1), 1.0)
        rest = np.broadcast_to(idx, (n, nc, 3))
        rest_c = rest - (w[:, :, None] * rest).sum(axis=1, keepdims=True) / count[:, None, None]
        self.rest_w = np.ascontiguousarray(rest_c * w[:, :, None])  # centred, empty cells zero
        # the compiled pass's maps: each voxel's cell, each cell's voxel (-1: empty)
        self.cell_of = (batch.flat_cells % nc).astype(np.intp)
        self.voxel_of = np.full((n, nc), -1, dtype=np.intp)
        self.voxel_of.reshape(-1)[batch.flat_cells] = np.arange(batch.flat_cells.size)
        self.cells = np.zeros((n, nc, 8))
        self.cov = np.zeros((n, 3, 3))
        terrains = batch.terrains
        floors = np.array([bool(t.floor) and bool(batch.config.floor) for t in terrains])
        self.heights = _Heights(terrains, floors)
        inc = math.radians(float(batch.config.incline))
        self.gravity = np.array([-math.sin(inc), 0.0, -math.cos(inc)]) if batch.config.gravity else np.zeros(3)
        self._cell_bound = np.array([b for _, b, _ in CELL_SENSORS])
        self._robot_bound = np.array([b for _, b, _ in ROBOT_SENSORS])
        self.rot = np.broadcast_to(np.eye(3), (n, 3, 3)).copy()

    # ------------------------------------------------------------------ read
    def read(self, clock: np.ndarray, period: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Every robot's sensors now.

        Parameters
        ----------
        clock : ndarray (n_robots,)
            Each robot's time since it was placed (s).
        period : ndarray (n_robots,)
            Each robot's clock period (s).

        Returns
        -------
        cells : ndarray (n_robots, n_cells, 8)
        robot : ndarray (n_robots, 11)
        task : ndarray (n_robots, n_task)
            Clipped to their bounds.
        """
        b = self.batch
        sim = b.sim
        n = b.n_robots
        L = self.L
        cells = self.cells  # empty cells' rows stay zero
        cm, cm_vel = sim.cell_sensors(
            b.grid_shape, self.cell_of, self.voxel_of, self.rest_w, cells, self.cov, TOUCH_REACH,
            (self._cell_bound[0], self._cell_bound[3]),
        )  # fmt: skip
        # the body's rotation: the best fit of its centred voxel centres to their lattice ones
        u, _, vt = np.linalg.svd(self.cov)
        d = np.sign(np.linalg.det(np.einsum("rij,rjk->rik", u, vt)))
        d[d == 0] = 1.0
        vt[:, 2, :] *= d[:, None]
        rot = np.einsum("rji,rkj->rik", vt, u)  # V U^T: lattice -> world
        ok = np.isfinite(rot).all(axis=(1, 2))
        self.rot[ok] = rot[ok]
        theta = 2.0 * np.pi * clock / period
        robot = np.column_stack([cm_vel / L, self.rot[:, :, 2], self.rot[:, :, 0],
                                 np.sin(theta), np.cos(theta)])  # fmt: skip
        np.clip(robot, -self._robot_bound, self._robot_bound, out=robot)
        if not self.layout.task_senses:
            return cells, robot, np.zeros((n, 0))
        ctx = SenseContext(
            cm=cm, cm_vel=cm_vel, rot=self.rot, object_cm=sim.object_center_of_mass(),
            object_vel=sim.object_velocity(), aux=sim.aux(), aux0=b.aux0, params=b.measure_params,
            heights=self.heights, gravity=self.gravity, voxel_size=L,
        )  # fmt: skip
        task = np.concatenate(
            [np.clip(s.read(ctx), -s.bound, s.bound) for s in self.layout.task_senses], axis=1
        )
        return cells, robot, task

    def observation(self, clock: np.ndarray, period: np.ndarray) -> np.ndarray:
        """The sensing observation of every robot, shape (n_robots, layout.size), float64."""
        cells, robot, task = self.read(clock, period)
        return np.concatenate([cells.reshape(cells.shape[0], -1), robot, task], axis=1)
