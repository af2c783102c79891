"""The task suite: each task's world, settings, measure and difficulty arguments, defined once.

A :class:`TaskKind` says what a named task is: a layout (the terrain built
around a robot's grid of a given shape, from the task's arguments), the engine
settings it changes (``SimConfig`` fields: friction, incline, fluid drag...),
the measure it scores (:mod:`softgym.metrics`), its arguments with their
defaults and accepted ranges, what a robot senses of it and its family
(:data:`FAMILIES`: locomotion, terrain, climbing, balancing, manipulation,
shape change). :class:`softgym.tasks.Task` reads a kind by name
(``Task("gap", options={"width": 3})``, ``get_task("gap:width=3")``), so
:func:`softgym.evaluate`, the Gymnasium ids and ``softgym evolve --task`` all
run the same definition.

Sizes are in voxel lengths; the robot's grid ``(nx, ny, nz)`` has its corner at
the origin and the centre of its footprint at ``(nx / 2, ny / 2)``.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from softgym.exceptions import InvalidParameterError
from softgym.tasks.sensing import SENSES, TaskSense
from softgym.terrain import Block, Box, Terrain

__all__ = [
    "FAMILIES",
    "KINDS",
    "Option",
    "TaskKind",
    "flat_layout",
    "stairs_layout",
    "tasks_of_family",
    "wall_layout",
]

#: The families of tasks by name, each with what its tasks ask of a robot.
FAMILIES: dict[str, str] = {
    "locomotion": "move over open ground, or through a fluid, under changed physics or towards a goal",
    "terrain": "get over, under, through or across obstacles: fences, steps, pits, roofs, bars, soft ground",
    "climbing": "raise the body up or onto terrain",
    "balancing": "stay on top of a narrow support with no floor below",
    "manipulation": "move a passive object: push, carry, throw, catch or lift it",
    "shape_change": "change the body's own shape: spread, shrink, squeeze, jump",
}


@dataclass(frozen=True)
class Option:
    """One argument of a task: its default, accepted range and meaning.

    Parameters
    ----------
    default : float or int
    lo, hi : float
        Accepted closed range.
    doc : str
        What it sets (units included).
    integer : bool
        Integers only.
    """

    default: float
    lo: float
    hi: float
    doc: str
    integer: bool = False

    def check(self, task: str, name: str, value: Any) -> float | int:
        """``value`` as this option's type, or InvalidParameterError naming the field and range."""
        what = "an integer" if self.integer else "a number"
        ok = isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(
            value, (bool, np.bool_)
        )
        if ok and self.integer and not float(value).is_integer():
            ok = False
        if ok:
            v = int(value) if self.integer else float(value)
            if math.isfinite(v) and self.lo <= v <= self.hi:
                return v
        raise InvalidParameterError(
            f"task {task!r}: {name} must be {what} in [{self.lo:g}, {self.hi:g}] "
            f"({self.doc}), got {value!r:.60}"
        )


@dataclass(frozen=True)
class TaskKind:
    """A named task of the suite.

    Parameters
    ----------
    name : str
    summary : str
        One line for tables.
    layout : callable
        ``layout(shape, **options) -> Terrain``: the world around a robot's grid.
    reward : str
        The measure the task scores (its ``score``) and an env rewards the
        progress of: a walking measure or one of
        :data:`softgym.metrics.TASK_MEASURES`.
    options : dict of str to Option
        Its difficulty arguments.
    sim : callable
        ``sim(options) -> dict`` of :class:`~softgym.engine.SimConfig` fields it sets.
    senses : tuple of TaskSense
        What a robot senses of the task beyond its own body
        (:data:`softgym.tasks.sensing.SENSES`: the object, the target, terrain
        heights ahead...): the task part of the sensing observation.
    family : str
        A key of :data:`FAMILIES` (required).
    shaping : tuple of (str, float)
        Dense guidance for reinforcement learning: measures of
        :data:`softgym.metrics.TASK_MEASURES` whose per-step progress, times its weight,
        an env adds to its reward when asked (``reward_shaping=True``); the score stays
        the task's measure. For a task whose measure only moves on success (a box that
        only moves once pushed, a pit crossed only at its far edge).

    Raises
    ------
    InvalidParameterError
        For a family that is not one of :data:`FAMILIES`.
    """

    name: str
    summary: str
    layout: Callable[..., Terrain]
    reward: str
    options: Mapping[str, Option] = field(default_factory=dict)
    sim: Callable[[Mapping[str, Any]], dict[str, Any]] = lambda o: {}
    senses: tuple[TaskSense, ...] = ()
    family: str = ""
    shaping: tuple[tuple[str, float], ...] = ()

    def __post_init__(self) -> None:
        if self.family not in FAMILIES:
            raise InvalidParameterError(
                f"task {self.name!r}: family must be one of {list(FAMILIES)}, got {self.family!r}"
            )
        from softgym.metrics.task_measures import TASK_MEASURES

        for measure, weight in self.shaping:
            if measure not in TASK_MEASURES or not (isinstance(weight, float) and weight > 0):
                raise InvalidParameterError(
                    f"task {self.name!r}: shaping needs (measure of TASK_MEASURES, weight > 0) "
                    f"pairs, got {(measure, weight)!r}"
                )

    def resolve(self, options: Mapping[str, Any] | None) -> dict[str, Any]:
        """Every argument, the given ones checked, the others at their defaults."""
        given = dict(options or {})
        unknown = sorted(set(given) - set(self.options))
        if unknown:
            raise InvalidParameterError(
                f"task {self.name!r} has no argument(s) {unknown}; its arguments are "
                f"{sorted(self.options) or 'none'}"
            )
        return {
            k: (o.check(self.name, k, given[k]) if k in given else o.default)
            for k, o in self.options.items()
        }


# --------------------------------------------------------------------- helpers
def _centre(shape: Sequence[int]) -> tuple[float, float]:
    return float(shape[0]) / 2.0, float(shape[1]) / 2.0


def _around(shape: Sequence[int], margin: float = 2.0) -> float:
    # interior side of a ring around the grid: the seed's fence has a 10-voxel interior
    # around its 6x6 workspace (a 2-voxel gap on every side)
    return max(10.0 if margin == 2.0 else 0.0, max(float(shape[0]), float(shape[1])) + 2 * margin)


def _ring(center: Sequence[float], inner: float, width: float, z0: float, z1: float) -> list[Box]:
    cx, cy = center
    a = inner / 2.0
    b = a + width
    return [
        Box((cx - b, cy - b, z0), (cx + b, cy - a, z1)),
        Box((cx - b, cy + a, z0), (cx + b, cy + b, z1)),
        Box((cx - b, cy - a, z0), (cx - a, cy + a, z1)),
        Box((cx + a, cy - a, z0), (cx + b, cy + a, z1)),
    ]


def _square(center: Sequence[float], half: float, z0: float, z1: float) -> Box:
    cx, cy = center
    return Box((cx - half, cy - half, z0), (cx + half, cy + half, z1))


# --------------------------------------------------------------------- layouts
def stairs_down_layout(shape: Sequence[int], step_height: float = 1.0, n_steps: int = 3,
                       step_width: float = 2.0) -> Terrain:  # fmt: skip
    """A stepped pyramid: the robot starts on its top and walks down ``n_steps`` rings."""
    c = _centre(shape)
    inner = _around(shape)
    bottom = -(n_steps * step_height + 2.0)
    boxes = [_square(c, inner / 2.0, bottom, 0.0)]
    for i in range(n_steps):
        # the last step is the ground, out past where the fastest robot gets in a task's run
        # (no floor below: a robot walking off its edge would score while it falls)
        width = step_width if i < n_steps - 1 else 200.0
        boxes += _ring(c, inner + 2 * i * step_width, width, bottom, -(i + 1) * step_height)
    meta = {"builder": "stairs_down", "step_height": step_height, "n_steps": n_steps,
            "step_width": step_width, "center": list(c)}  # fmt: skip
    return Terrain(tuple(boxes), False, "stairs_down", meta, box_contact="surface")


def rough_layout(shape: Sequence[int], roughness: float = 1.0, tile: float = 3.0,
                 extent: float = 12.0, seed: int = 0) -> Terrain:  # fmt: skip
    """A seeded random height field: square tiles of heights uniform in [0, roughness].

    The tiles start 1 voxel from the grid (that margin and the grid stay flat)
    and cover ``extent`` voxel lengths beyond it on every side.
    """
    nx, ny = float(shape[0]), float(shape[1])
    rng = np.random.default_rng(int(seed))
    n = int(math.ceil(extent / tile))
    mx = int(math.ceil((nx + 2.0) / tile))  # tiles over the flat start square, from x = -1
    my = int(math.ceil((ny + 2.0) / tile))
    boxes = []
    for i in range(-n, mx + n):
        for j in range(-n, my + n):
            x0, y0 = -1.0 + i * tile, -1.0 + j * tile
            h = float(rng.uniform(0.0, roughness))
            if 0 <= i < mx and 0 <= j < my:  # the start square stays flat
                continue
            if h >= 0.05:
                boxes.append(Box((x0, y0, 0.0), (x0 + tile, y0 + tile, round(h, 3))))
    meta = {"builder": "rough", "roughness": roughness, "tile": tile, "extent": extent,
            "seed": int(seed)}  # fmt: skip
    return Terrain(tuple(boxes), True, "rough", meta, box_contact="surface")


def gap_layout(shape: Sequence[int], width: float = 2.0, depth: float = 4.0) -> Terrain:
    """A start platform (the grid's footprint) in a pit ring ``width`` wide, then ground.

    No floor: the platforms are boxes with their tops at z = 0 and the pit's
    bottom is ``depth`` below them, so a robot that steps off falls in.
    """
    c = _centre(shape)
    inner = _around(shape, margin=0.0)
    outer = 20.0
    bottom = -depth
    boxes = [_square(c, inner / 2.0, bottom, 0.0)]
    boxes += _ring(c, inner + 2 * width, outer, bottom, 0.0)
    boxes.append(_square(c, inner / 2.0 + width + outer, bottom - 1.0, bottom))
    meta = {"builder": "gap", "width": width, "depth": depth, "center": list(c),
            "edge": inner / 2.0}  # fmt: skip
    return Terrain(tuple(boxes), False, "gap", meta, box_contact="surface")


def tunnel_layout(shape: Sequence[int], clearance: float = 0.75, length: float = 6.0) -> Terrain:
    """A ring-shaped low roof around the start: its underside ``clearance`` below the grid's top."""
    c = _centre(shape)
    inner = _around(shape)
    height = max(float(shape[2]) - clearance, 0.5)
    boxes = _ring(c, inner, length, height, height + 1.0)
    meta = {"builder": "tunnel", "clearance": clearance, "length": length, "height": height}
    return Terrain(tuple(boxes), True, "tunnel", meta, box_contact="surface")


def push_layout(shape: Sequence[int], size: int = 3, distance: float = 10.0,
                density: float = 5e5) -> Terrain:  # fmt: skip
    """A cube of ``size`` voxels half a voxel from the robot's -x side, a target ``distance`` further.

    (-x: where the default walker and the seed's sinusoid head.)
    """
    ny = float(shape[1])
    origin = (-0.5 - size, ny / 2.0 - size / 2.0, 0.0)
    # E in proportion to the density keeps the robot's time step (the seed's tissue: 5e6 Pa, 1e6 kg/m^3)
    block = Block.box(origin, (size, size, size), density=density, youngs_modulus=5.0 * density)
    target = [float(block.center[0] - distance), float(block.center[1])]
    meta = {"builder": "push", "size": size, "distance": distance, "target": target}
    return Terrain((), True, "push", meta, objects=(block,))


def carry_layout(shape: Sequence[int], rim: int = 4, density: float = 1e5) -> Terrain:
    """A cap on the robot: a plate over its grid with a ``rim`` hanging round its top layers.

    The cap sits at the self-contact distance (1.5 voxels between centres), so
    it rests on the robot; its rim lets a walking robot drag it along through
    the frictionless self-contact law. The rim hangs at most the grid's height
    (it never reaches into the floor). With the default rim of 4 the reference
    walker (:func:`~softgym.design.default_walker`) carries the cap about as
    far as it walks; with a rim of 1 to 3 it walks out from under it, and
    with 2 a full 6x6x6 block sheds it while settling.
    """
    nx, ny, nz = (int(s) for s in shape[:3])
    rim = min(int(rim), nz)
    # cell (i, j, k) has its centre at (i - 1, j - 1, nz + 1 - rim + k): the rim 1.5 voxels
    # from the robot's side voxels, the plate 1.5 above its top ones
    cells = np.zeros((nx + 3, ny + 3, rim + 1), dtype=bool)
    cells[:, :, rim] = True
    cells[0, :, :] = True
    cells[-1, :, :] = True
    cells[:, 0, :] = True
    cells[:, -1, :] = True
    block = Block((-1.5, -1.5, nz + 0.5 - rim), cells.shape, cells, density=density,
                  youngs_modulus=5.0 * density)
    meta = {"builder": "carry", "rim": rim, "density": density}
    return Terrain((), True, "carry", meta, objects=(block,))


# ------------------------------------------------------------ the suite's second half
def _catch_plane(c: Sequence[float], depth: float = 20.0) -> Box:
    # the ground far below a world with no floor: where a robot that falls ends up
    return _square(c, 60.0, -depth - 2.0, -depth)


def goal_layout(shape: Sequence[int], distance: float = 10.0, angle: float = 45.0) -> Terrain:
    """The floor and a goal point ``distance`` from the grid's centre.

    The goal lies ``angle`` degrees counter-clockwise (seen from above) from
    -x, the seed's heading: 0 straight ahead of the default walker, 90 on its
    left (-y), 180 behind it (+x). It is a point of the measure and the goal
    sense, not a body: nothing is built there.
    """
    cx, cy = _centre(shape)
    a = math.radians(angle)
    target = [cx - distance * math.cos(a), cy - distance * math.sin(a)]
    meta = {"builder": "goal", "distance": distance, "angle": angle, "target": target}
    return Terrain((), True, "goal", meta)


def hurdles_layout(shape: Sequence[int], height: float = 0.5, count: int = 3,
                   spacing: float = 4.0) -> Terrain:  # fmt: skip
    """``count`` rings of bars 1 voxel thick and ``height`` high, ``spacing`` apart, round the start.

    The first ring stands where the seed's fence does (a 2-voxel gap round a
    6x6 grid); each next one is ``spacing`` farther out.
    """
    c = _centre(shape)
    inner = _around(shape)
    boxes: list[Box] = []
    for i in range(int(count)):
        boxes += _ring(c, inner + 2 * i * spacing, 1.0, 0.0, height)
    meta = {"builder": "hurdles", "height": height, "count": int(count), "spacing": spacing,
            "center": list(c)}  # fmt: skip
    return Terrain(tuple(boxes), True, "hurdles", meta, box_contact="surface")


def course_layout(shape: Sequence[int], scale: float = 1.0, seed: int = 0) -> Terrain:
    """An obstacle course in rings round the start: a bar, a raised step, then rough ground.

    From the inside out: a bar 1 voxel thick and ``0.5 scale`` high where the
    seed's fence stands, 3 voxel lengths of floor, a step 4 wide and ``scale``
    high (up, then down), 3 of floor, then a band 9 wide of seeded random
    tiles (3 voxel lengths square) of heights uniform in [0, ``scale``].
    """
    c = _centre(shape)
    half = _around(shape) / 2.0
    boxes = _ring(c, 2 * half, 1.0, 0.0, 0.5 * scale)
    step = half + 1.0 + 3.0
    boxes += _ring(c, 2 * step, 4.0, 0.0, scale)
    lo = step + 4.0 + 3.0  # the rough band: lo <= max(|x - cx|, |y - cy|) <= hi
    hi = lo + 9.0
    tile = 3.0
    rng = np.random.default_rng(int(seed))
    n = int(math.ceil(hi / tile))
    for i in range(-n, n):
        for j in range(-n, n):
            u, v = i * tile, j * tile  # the tile's corner relative to the centre
            h = float(rng.uniform(0.0, scale))
            near = max(_nearest(u, u + tile), _nearest(v, v + tile))
            far = max(abs(u), abs(u + tile), abs(v), abs(v + tile))
            if near >= lo and far <= hi and h >= 0.05:
                x0, y0 = c[0] + u, c[1] + v
                boxes.append(Box((x0, y0, 0.0), (x0 + tile, y0 + tile, round(h, 3))))
    meta = {"builder": "course", "scale": scale, "seed": int(seed), "center": list(c)}
    return Terrain(tuple(boxes), True, "course", meta, box_contact="surface")


def _nearest(a: float, b: float) -> float:
    # distance from 0 to the interval [a, b]
    return 0.0 if a <= 0.0 <= b else min(abs(a), abs(b))


def mattress_layout(shape: Sequence[int], size: int = 12, thickness: int = 2,
                    stiffness: float = 1e6) -> Terrain:  # fmt: skip
    """A soft slab (a movable block) on a plinth of its own size, the robot on it; no floor.

    The slab is ``size`` x ``size`` x ``thickness`` voxels of the robot's
    density (1e6 kg/m^3) and Young's modulus ``stiffness``, centred under
    the grid, its voxels half a lattice step off the robot's (where the
    robot's feet settle) and its top half a voxel below the robot's feet
    (the self-contact distance). The plinth (a box, 10 deep) holds it; the
    ground (a box) is 20 below the grid: a robot that walks off the slab's
    edge falls there. The robot touches the slab through the frictionless
    self-contact law: it grips by pressing dents into it.
    """
    nx, ny = int(shape[0]), int(shape[1])
    size, thickness = int(size), int(thickness)
    x0, y0 = math.floor((nx - size) / 2.0) + 0.5, math.floor((ny - size) / 2.0) + 0.5
    bottom = -0.5 - thickness
    slab = Block.box(
        (x0, y0, bottom), (size, size, thickness), density=1e6, youngs_modulus=stiffness
    )
    plinth = Box((x0, y0, bottom - 10.0), (x0 + size, y0 + size, bottom))
    meta = {"builder": "mattress", "size": size, "thickness": thickness, "stiffness": stiffness}
    return Terrain((plinth, _catch_plane(_centre(shape))), False, "mattress", meta, objects=(slab,),
                   box_contact="surface")  # fmt: skip


def push_uphill_layout(shape: Sequence[int], size: int = 3, distance: float = 10.0,
                       density: float = 5e5, angle: float = 5.0) -> Terrain:  # fmt: skip
    """The push world (a box -x of the robot, a target ``distance`` beyond it) on a slope.

    The slope (``angle``, an engine setting: gravity tilted so that -x is
    uphill) leaves the world's boxes as they are; see :func:`push_layout`.
    """
    t = push_layout(shape, size=size, distance=distance, density=density)
    meta = {**t.meta, "builder": "push_uphill", "angle": angle}
    return Terrain((), True, "push_uphill", meta, objects=t.objects)


def _on_top(shape: Sequence[int], size: int, density: float, height: float = 0.0) -> Block:
    # a cube of `size` voxels centred over the grid, resting on its top (the self-contact
    # distance: 1.5 voxels between centres) or `height` above that
    nx, ny, nz = (float(s) for s in shape[:3])
    origin = (nx / 2.0 - size / 2.0, ny / 2.0 - size / 2.0, nz + 0.5 + height)
    return Block.box(origin, (size, size, size), density=density, youngs_modulus=5.0 * density)


def throw_layout(shape: Sequence[int], size: int = 2, density: float = 2e5) -> Terrain:
    """A cube of ``size`` voxels resting on the middle of the robot's top, to fling away."""
    block = _on_top(shape, int(size), density)
    meta = {"builder": "throw", "size": int(size), "density": density}
    return Terrain((), True, "throw", meta, objects=(block,))


def catch_layout(shape: Sequence[int], height: float = 12.0, offset: float = 3.0) -> Terrain:
    """A light voxel ``height`` above the robot's top, ``offset`` ahead (-x) of the grid's centre.

    The voxel (1e4 kg/m^3, a hundredth of the robot's density) drifts down
    through a thick fluid (the task's ``fluid_drag``, 2.7e5 kg/m^3) at about
    6 voxel lengths per second, where the robot's own motion hardly feels the
    drag. At the defaults it comes down over the grid's -x edge, at the
    robot's top height about 1 s after settling and on the floor 1 s later
    if nothing holds it. (A single voxel: larger light blocks in the fluid
    can make the engine diverge when a robot strikes them.)
    """
    nx, ny, nz = (float(s) for s in shape[:3])
    origin = (nx / 2.0 - offset - 0.5, ny / 2.0 - 0.5, nz + 0.5 + height)
    block = Block.box(origin, (1, 1, 1), density=1e4, youngs_modulus=5e4)
    meta = {"builder": "catch", "height": height, "offset": offset}
    return Terrain((), True, "catch", meta, objects=(block,))


def lift_layout(shape: Sequence[int], density: float = 1e6) -> Terrain:
    """A plate 1 voxel thick over the whole grid, resting on the robot's top, to raise."""
    nx, ny, nz = (int(s) for s in shape[:3])
    block = Block.box((0.0, 0.0, nz + 0.5), (nx, ny, 1), density=density,
                      youngs_modulus=5.0 * density)  # fmt: skip
    meta = {"builder": "lift", "density": density}
    return Terrain((), True, "lift", meta, objects=(block,))


def chimney_layout(shape: Sequence[int], gap: float = 0.25, height: float = 12.0) -> Terrain:
    """Two walls ``height`` high along x, ``gap`` from the grid's two y sides: climb between them.

    The walls are 2 voxel lengths thick and run 20 voxel lengths past the
    grid both ways (the chimney is open along x).
    """
    nx, ny = float(shape[0]), float(shape[1])
    walls = (Box((-20.0, -gap - 2.0, 0.0), (nx + 20.0, -gap, height)),
             Box((-20.0, ny + gap, 0.0), (nx + 20.0, ny + gap + 2.0, height)))  # fmt: skip
    meta = {"builder": "chimney", "gap": gap, "height": height}
    return Terrain(walls, True, "chimney", meta, box_contact="surface")


def ledge_layout(shape: Sequence[int], height: float = 1.0, gap: float = 1.0) -> Terrain:
    """A raised platform ``height`` high, ``gap`` from the grid's -x side (ahead of the default walker).

    It is 30 voxel lengths deep (along -x) and 20 wider than the grid on each side.
    """
    ny = float(shape[1])
    ledge = Box((-gap - 30.0, -20.0, 0.0), (-gap, ny + 20.0, height))
    meta = {"builder": "ledge", "height": height, "gap": gap}
    return Terrain((ledge,), True, "ledge", meta, box_contact="surface")


def beam_layout(shape: Sequence[int], width: float = 3.0, length: float = 40.0) -> Terrain:
    """A beam ``width`` wide along x under the grid's centre line, its top at z = 0; no floor.

    It is ``length`` long, centred on the grid, 10 voxel lengths deep; the
    ground (a box) is 20 below its top: a robot that steps off falls there.
    """
    cx, cy = _centre(shape)
    half_l, half_w = length / 2.0, width / 2.0
    beam = Box((cx - half_l, cy - half_w, -10.0), (cx + half_l, cy + half_w, 0.0))
    meta = {"builder": "beam", "width": width, "length": length, "center": [cx, cy]}
    return Terrain((beam, _catch_plane((cx, cy))), False, "beam", meta, box_contact="surface")


def balance_layout(shape: Sequence[int], width: float = 2.0) -> Terrain:
    """A square pedestal ``width`` wide under the grid's centre, its top at z = 0; no floor.

    The pedestal is 10 voxel lengths deep; the ground (a box) is 20 below its top.
    """
    c = _centre(shape)
    pedestal = _square(c, width / 2.0, -10.0, 0.0)
    meta = {"builder": "balance", "width": width, "center": list(c)}
    return Terrain((pedestal, _catch_plane(c)), False, "balance", meta, box_contact="surface")


def stones_layout(shape: Sequence[int], size: float = 2.0, gap: float = 1.0,
                  extent: float = 15.0) -> Terrain:  # fmt: skip
    """Square stepping stones ``size`` wide, ``gap`` apart, tops at z = 0; no floor.

    A stone is centred under the grid's centre and the others on a square
    lattice of pitch ``size + gap`` round it, out to ``extent`` voxel lengths
    from it; each is 10 deep and the ground (a box) is 20 below their tops.
    """
    c = _centre(shape)
    pitch = size + gap
    n = int(extent // pitch)
    boxes = [_square((c[0] + i * pitch, c[1] + j * pitch), size / 2.0, -10.0, 0.0)
             for i in range(-n, n + 1) for j in range(-n, n + 1)]  # fmt: skip
    boxes.append(_catch_plane(c))
    meta = {"builder": "stones", "size": size, "gap": gap, "extent": extent, "center": list(c)}
    return Terrain(tuple(boxes), False, "stones", meta, box_contact="surface")


def squeeze_layout(shape: Sequence[int], slit: float = 3.0, thickness: float = 2.0) -> Terrain:
    """A wall round the start, too high to climb, with a slit ``slit`` wide in the middle of each side.

    The wall stands where the seed's fence does, ``thickness`` thick and 4
    voxel lengths higher than the grid.
    """
    cx, cy = _centre(shape)
    a = _around(shape) / 2.0
    b = a + thickness
    s = slit / 2.0
    top = float(shape[2]) + 4.0
    boxes = []
    for lo, hi in (((-b, -b), (-s, -a)), ((s, -b), (b, -a)), ((-b, a), (-s, b)), ((s, a), (b, b)),
                   ((-b, -a), (-a, -s)), ((-b, s), (-a, a)), ((a, -a), (b, -s)), ((a, s), (b, a))):  # fmt: skip
        boxes.append(Box((cx + lo[0], cy + lo[1], 0.0), (cx + hi[0], cy + hi[1], top)))
    meta = {"builder": "squeeze", "slit": slit, "thickness": thickness, "center": [cx, cy]}
    return Terrain(tuple(boxes), True, "squeeze", meta, box_contact="surface")


def _flat(name: str) -> Callable[..., Terrain]:
    def layout(shape: Sequence[int], **_: Any) -> Terrain:
        return Terrain((), True, name, {"builder": name})

    layout.__name__ = f"{name}_layout"
    layout.__doc__ = f"The floor alone (the {name} task changes the engine settings or the measure)."
    return layout


def _swim(shape: Sequence[int], **_: Any) -> Terrain:
    return Terrain((), False, "swim", {"builder": "swim"})


# ----------------------------------------------------------------------- the seed's
def _seed_ring(shape: Sequence[int]) -> tuple[float, tuple[float, float]]:
    """Interior side and centre of an obstacle ring around a robot grid of ``shape`` at the origin.

    The seed's fence has a 10-voxel interior around its 6x6 workspace (a
    2-voxel gap on every side); a wider grid keeps the 2-voxel gap.
    """
    nx, ny = int(shape[0]), int(shape[1])
    return max(10.0, max(nx, ny) + 4.0), (nx / 2.0, ny / 2.0)


def flat_layout(shape: Sequence[int]) -> Terrain:
    """The floor alone (``shape`` is unused)."""
    return Terrain.flat()


def wall_layout(shape: Sequence[int]) -> Terrain:
    """The seed's fence (1 voxel high and thick) centred on a robot grid of ``shape``."""
    inner, center = _seed_ring(shape)
    return Terrain.fence(inner=inner, center=center)


def stairs_layout(shape: Sequence[int]) -> Terrain:
    """Three rings, each 2 voxels wide and 1 voxel higher than the one inside it, around the grid."""
    inner, center = _seed_ring(shape)
    return Terrain.stairs(inner=inner, center=center)


# ----------------------------------------------------------------------- suite
_SEED = Option(0, 0, 2**31 - 1, "seed of the random heights", integer=True)
# the task senses (softgym.tasks.sensing): what each kind lets a robot perceive
_TERRAIN = (SENSES["terrain"],)
_OBJECT = (SENSES["object"],)
_GRAVITY = (SENSES["gravity"],)
_SLOPE = Option(5.0, 0.0, 30.0, "slope, degrees")


def _gravity(factor: float) -> float:
    # the seed's gravity (SimConfig's default, m/s^2) times a factor
    from softgym.engine.config import SimConfig

    return float(SimConfig.gravity) * float(factor)


#: Every kind of task by name, the one registry: the seed's three (``flat``, ``wall``,
#: ``stairs``: no arguments) and the suite's, each in one of the :data:`FAMILIES`.
KINDS: dict[str, TaskKind] = {
    k.name: k
    for k in (
        TaskKind("flat", "walk on flat ground (the seed's)", flat_layout, "norm_final_dist",
                 family="locomotion"),
        TaskKind("wall", "get past a fence around the start (the seed's obstacle)", wall_layout,
                 "max_xy_dist", senses=_TERRAIN, family="terrain"),
        TaskKind("stairs", "climb three rings of steps around the start", stairs_layout,
                 "max_xy_dist", senses=_TERRAIN, family="climbing"),
        TaskKind(
            "stairs_down", "walk down a stepped pyramid from its top", stairs_down_layout,
            "max_xy_dist",
            {"step_height": Option(1.0, 0.25, 3.0, "height of each step, voxel lengths"),
             "n_steps": Option(3, 1, 10, "steps down to the ground", integer=True),
             "step_width": Option(2.0, 1.0, 10.0, "width of each step, voxel lengths")},
            senses=_TERRAIN, family="terrain",
        ),
        TaskKind(
            "rough", "walk over a seeded random height field of boxes", rough_layout,
            "max_xy_dist",
            {"roughness": Option(1.0, 0.1, 4.0, "largest tile height, voxel lengths"),
             "tile": Option(3.0, 1.0, 10.0, "side of a tile, voxel lengths"),
             "extent": Option(12.0, 4.0, 30.0, "half side of the rough area, voxel lengths"),
             "seed": _SEED},
            senses=_TERRAIN, family="terrain",
        ),
        TaskKind(
            "gap", "reach across a pit from the start platform to the ground around it", gap_layout,
            "gap_crossed",
            {"width": Option(2.0, 0.5, 10.0, "width of the pit, voxel lengths"),
             "depth": Option(4.0, 1.0, 20.0, "depth of the pit, voxel lengths")},
            senses=_TERRAIN, family="terrain", shaping=(("top_dist", 0.5),),
        ),
        TaskKind(
            "tunnel", "crawl out under a low roof", tunnel_layout, "max_xy_dist",
            {"clearance": Option(0.75, 0.0, 4.0, "how far the roof is below the grid's top, voxel lengths"),
             "length": Option(6.0, 1.0, 20.0, "length of the roofed ring, voxel lengths")},
            senses=_TERRAIN, family="terrain",
        ),
        TaskKind(
            "incline", "walk uphill (+x) on a slope made by tilting gravity", _flat("incline"),
            "x_progress", {"angle": _SLOPE},
            sim=lambda o: {"incline": float(o["angle"])}, senses=_GRAVITY, family="locomotion",
        ),
        TaskKind(
            "ice", "walk on slippery ground", _flat("ice"), "norm_final_dist",
            {"friction": Option(0.1, 0.0, 1.0, "factor on the materials' friction")},
            sim=lambda o: {"friction": float(o["friction"])}, family="locomotion",
        ),
        TaskKind(
            "mud", "walk on grippy, high-friction ground", _flat("mud"), "norm_final_dist",
            {"friction": Option(4.0, 1.0, 20.0, "factor on the materials' friction")},
            sim=lambda o: {"friction": float(o["friction"])}, family="locomotion",
        ),
        TaskKind(
            "jump", "raise the centre of mass as high as possible (muscles expand and contract)",
            _flat("jump"), "peak_height", sim=lambda o: {"actuation": "symmetric"},
            family="shape_change",
        ),
        TaskKind("turn", "turn in place about the vertical axis", _flat("turn"), "yaw",
                 senses=(SENSES["heading"],), family="locomotion"),
        TaskKind(
            "push", "push a box to a target (-x of the robot)", push_layout, "push_progress",
            {"size": Option(3, 1, 6, "side of the box, voxels", integer=True),
             "distance": Option(10.0, 1.0, 50.0, "target distance from the box, voxel lengths"),
             "density": Option(5e5, 1e4, 1e7, "the box's density, kg/m^3 (the robot's: 1e6)")},
            senses=(SENSES["object"], SENSES["target"]), family="manipulation",
            shaping=(("target_progress", 0.5),),
        ),
        TaskKind(
            "carry", "walk with a cap on top without dropping it", carry_layout, "carried_dist",
            {"rim": Option(4, 0, 4, "depth of the cap's rim round the robot's top, voxels (shallower: "
                                 "harder to keep on)", integer=True),
             "density": Option(1e5, 1e4, 1e7, "the cap's density, kg/m^3 (the robot's: 1e6)")},
            senses=_OBJECT, family="manipulation",
        ),
        TaskKind(
            "swim", "swim in a fluid (no floor, no weight, drag on exposed faces; muscles expand and contract)", _swim,
            "swim_dist",
            {"drag": Option(5e6, 1e3, 1e8, "rho C_d / 2 of the fluid, kg/m^3")},
            sim=lambda o: {"fluid_drag": float(o["drag"]), "gravity": 0.0, "floor": False,
                           "actuation": "symmetric"},
            family="locomotion",
        ),
        TaskKind(
            "grow", "spread the largest footprint (muscles expand and contract)", _flat("grow"),
            "footprint_gain", sim=lambda o: {"actuation": "symmetric"}, family="shape_change",
        ),
        # ------------------------------------------------------------- locomotion
        TaskKind(
            "downhill", "walk downhill (+x) on a slope made by tilting gravity the other way",
            _flat("downhill"), "x_progress", {"angle": _SLOPE},
            sim=lambda o: {"incline": -float(o["angle"])}, senses=_GRAVITY, family="locomotion",
        ),
        TaskKind(
            "moon", "walk on flat ground in low gravity", _flat("moon"), "norm_final_dist",
            {"gravity": Option(0.165, 0.05, 1.0, "factor on the seed's gravity (9.81 m/s^2; the Moon's: 0.165)")},
            sim=lambda o: {"gravity": _gravity(o["gravity"])}, family="locomotion",
        ),
        TaskKind(
            "goal", "walk to a goal point on flat ground", goal_layout, "target_progress",
            {"distance": Option(10.0, 2.0, 50.0, "distance of the goal from the grid's centre, voxel lengths"),
             "angle": Option(45.0, -180.0, 180.0, "direction of the goal, degrees counter-clockwise "
                                                  "from -x (the seed's heading)")},
            senses=(SENSES["goal"],), family="locomotion",
        ),
        # ---------------------------------------------------------------- terrain
        TaskKind(
            "hurdles", "get over rings of low bars around the start", hurdles_layout, "max_xy_dist",
            {"height": Option(0.5, 0.1, 3.0, "height of the bars, voxel lengths"),
             "count": Option(3, 1, 10, "rings of bars", integer=True),
             "spacing": Option(4.0, 2.0, 12.0, "distance between rings, voxel lengths")},
            senses=_TERRAIN, family="terrain",
        ),
        TaskKind(
            "course", "run an obstacle course: a bar, a raised step, then rough ground", course_layout,
            "max_xy_dist",
            {"scale": Option(1.0, 0.25, 3.0, "factor on every obstacle's height"), "seed": _SEED},
            senses=_TERRAIN, family="terrain",
        ),
        TaskKind(
            "mattress", "walk across a soft slab on a plinth (no floor) without falling off",
            mattress_layout, "top_dist",
            {"size": Option(12, 8, 32, "side of the slab, voxels", integer=True),
             "thickness": Option(2, 1, 4, "thickness of the slab, voxels", integer=True),
             "stiffness": Option(1e6, 5e5, 5e6, "the slab's Young's modulus, Pa (the robot's: 5e6)")},
            senses=_TERRAIN, family="terrain",
        ),
        # --------------------------------------------------------------- climbing
        TaskKind(
            "chimney", "climb up between two walls close to the robot's sides", chimney_layout,
            "z_progress",
            {"gap": Option(0.25, 0.0, 4.0, "gap between each wall and the grid's side, voxel lengths"),
             "height": Option(12.0, 2.0, 40.0, "height of the walls, voxel lengths")},
            senses=_TERRAIN, family="climbing",
        ),
        TaskKind(
            "ledge", "climb onto a raised platform ahead (-x) of the robot", ledge_layout,
            "z_progress",
            {"height": Option(1.0, 0.25, 6.0, "height of the platform, voxel lengths"),
             "gap": Option(1.0, 0.0, 10.0, "distance from the grid's -x side, voxel lengths")},
            senses=_TERRAIN, family="climbing",
        ),
        # -------------------------------------------------------------- balancing
        TaskKind(
            "beam", "walk along a narrow raised beam (no floor) without falling off", beam_layout,
            "top_dist",
            {"width": Option(3.0, 1.0, 12.0, "width of the beam, voxel lengths"),
             "length": Option(40.0, 10.0, 200.0, "length of the beam, voxel lengths")},
            senses=_TERRAIN, family="balancing",
        ),
        TaskKind(
            "balance", "stay on a narrow pedestal (no floor) while moving", balance_layout,
            "time_on_top",
            {"width": Option(2.0, 0.5, 6.0, "side of the pedestal's square top, voxel lengths")},
            senses=_TERRAIN, family="balancing",
        ),
        TaskKind(
            "stones", "walk over stepping stones (no floor) without falling between them",
            stones_layout, "top_dist",
            {"size": Option(2.0, 1.0, 6.0, "side of a stone, voxel lengths"),
             "gap": Option(1.0, 0.25, 4.0, "gap between stones, voxel lengths"),
             "extent": Option(15.0, 6.0, 30.0, "how far the stones reach from the start, voxel lengths")},
            senses=_TERRAIN, family="balancing",
        ),
        # ----------------------------------------------------------- manipulation
        TaskKind(
            "push_uphill", "push a box uphill to a target (-x of the robot, up the slope)",
            push_uphill_layout, "push_progress",
            {"size": Option(3, 1, 6, "side of the box, voxels", integer=True),
             "distance": Option(10.0, 1.0, 50.0, "target distance from the box, voxel lengths"),
             "density": Option(5e5, 1e4, 1e7, "the box's density, kg/m^3 (the robot's: 1e6)"),
             "angle": Option(5.0, 0.0, 20.0, "slope, degrees (-x uphill)")},
            sim=lambda o: {"incline": -float(o["angle"])},
            senses=(SENSES["object"], SENSES["target"], SENSES["gravity"]), family="manipulation",
            shaping=(("target_progress", 0.5),),
        ),
        TaskKind(
            "throw", "fling a cube resting on top as far as possible", throw_layout, "object_dist",
            {"size": Option(2, 1, 4, "side of the cube, voxels", integer=True),
             "density": Option(2e5, 1e4, 1e7, "the cube's density, kg/m^3 (the robot's: 1e6)")},
            senses=_OBJECT, family="manipulation",
        ),
        TaskKind(
            "catch", "catch a light voxel drifting down through a thick fluid and hold it up",
            catch_layout, "object_height",
            {"height": Option(12.0, 2.0, 40.0, "start height of the voxel above the grid's top, voxel lengths"),
             "offset": Option(3.0, 0.0, 12.0, "horizontal distance of the voxel ahead (-x) of the "
                                               "grid's centre, voxel lengths")},
            sim=lambda o: {"fluid_drag": 2.7e5}, senses=_OBJECT, family="manipulation",
        ),
        TaskKind(
            "lift", "raise a plate resting on top as high as possible (muscles expand and contract)",
            lift_layout, "object_rise",
            {"density": Option(1e6, 1e4, 1e7, "the plate's density, kg/m^3 (the robot's: 1e6)")},
            sim=lambda o: {"actuation": "symmetric"}, senses=_OBJECT, family="manipulation",
        ),
        # ----------------------------------------------------------- shape change
        TaskKind(
            "shrink", "shrink to the smallest footprint (muscles expand and contract)", _flat("shrink"),
            "footprint_loss",
            {"friction": Option(1.0, 0.0, 10.0, "factor on the materials' friction (grip holds the "
                                                "feet where they stand)")},
            sim=lambda o: {"actuation": "symmetric", "friction": float(o["friction"])},
            family="shape_change",
        ),
        TaskKind(
            "squeeze", "squeeze out through slits narrower than the robot in a wall around it",
            squeeze_layout, "max_xy_dist",
            {"slit": Option(3.0, 0.5, 8.0, "width of the slit in each side, voxel lengths"),
             "thickness": Option(2.0, 0.5, 10.0, "thickness of the wall, voxel lengths")},
            senses=_TERRAIN, family="shape_change",
        ),
    )
}  # fmt: skip


def tasks_of_family(family: str) -> list[str]:
    """The names of the tasks of one family (:data:`FAMILIES`), in registry order.

    Raises
    ------
    InvalidParameterError
        For a family that is not one of :data:`FAMILIES`.
    """
    if family not in FAMILIES:
        raise InvalidParameterError(f"family must be one of {list(FAMILIES)}, got {family!r:.60}")
    return [name for name, kind in KINDS.items() if kind.family == family]
