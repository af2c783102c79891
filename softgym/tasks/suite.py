"""The task suite: each task's world, settings, measure and difficulty arguments, defined once.

A :class:`TaskKind` says what a named task is: a layout (the terrain built
around a robot's grid of a given shape, from the task's arguments), the engine
settings it changes (``SimConfig`` fields: friction, incline, fluid drag...),
the measure it scores (:mod:`softgym.metrics`) and its arguments with their
defaults and accepted ranges. :class:`softgym.tasks.Task` reads a kind by name
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

__all__ = ["KINDS", "Option", "TaskKind", "flat_layout", "stairs_layout", "wall_layout"]


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
    """

    name: str
    summary: str
    layout: Callable[..., Terrain]
    reward: str
    options: Mapping[str, Option] = field(default_factory=dict)
    sim: Callable[[Mapping[str, Any]], dict[str, Any]] = lambda o: {}
    senses: tuple[TaskSense, ...] = ()

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
        width = step_width if i < n_steps - 1 else 30.0  # the last step is the ground
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


def carry_layout(shape: Sequence[int], rim: int = 2, density: float = 1e5) -> Terrain:
    """A cap on the robot: a plate over its grid with a ``rim`` hanging round its top layers.

    The cap sits at the self-contact distance (1.5 voxels between centres), so
    it rests on the robot; its rim lets a walking robot drag it along through
    the frictionless self-contact law.
    """
    nx, ny, nz = (int(s) for s in shape[:3])
    rim = int(rim)
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

#: Every kind of task by name, the one registry: the seed's three (``flat``, ``wall``,
#: ``stairs``: no arguments) and the suite's.
KINDS: dict[str, TaskKind] = {
    k.name: k
    for k in (
        TaskKind("flat", "walk on flat ground (the seed's)", flat_layout, "norm_final_dist"),
        TaskKind("wall", "get past a fence around the start (the seed's obstacle)", wall_layout,
                 "max_xy_dist", senses=_TERRAIN),  # fmt: skip
        TaskKind("stairs", "climb three rings of steps around the start", stairs_layout,
                 "max_xy_dist", senses=_TERRAIN),  # fmt: skip
        TaskKind(
            "stairs_down", "walk down a stepped pyramid from its top", stairs_down_layout,
            "max_xy_dist",
            {"step_height": Option(1.0, 0.25, 3.0, "height of each step, voxel lengths"),
             "n_steps": Option(3, 1, 10, "steps down to the ground", integer=True),
             "step_width": Option(2.0, 1.0, 10.0, "width of each step, voxel lengths")},
            senses=_TERRAIN,
        ),
        TaskKind(
            "rough", "walk over a seeded random height field of boxes", rough_layout,
            "max_xy_dist",
            {"roughness": Option(1.0, 0.1, 4.0, "largest tile height, voxel lengths"),
             "tile": Option(3.0, 1.0, 10.0, "side of a tile, voxel lengths"),
             "extent": Option(12.0, 4.0, 30.0, "half side of the rough area, voxel lengths"),
             "seed": _SEED},
            senses=_TERRAIN,
        ),
        TaskKind(
            "gap", "reach across a pit from the start platform to the ground around it", gap_layout,
            "gap_crossed",
            {"width": Option(2.0, 0.5, 10.0, "width of the pit, voxel lengths"),
             "depth": Option(4.0, 1.0, 20.0, "depth of the pit, voxel lengths")},
            senses=_TERRAIN,
        ),
        TaskKind(
            "tunnel", "crawl out under a low roof", tunnel_layout, "max_xy_dist",
            {"clearance": Option(0.75, 0.0, 4.0, "how far the roof is below the grid's top, voxel lengths"),
             "length": Option(6.0, 1.0, 20.0, "length of the roofed ring, voxel lengths")},
            senses=_TERRAIN,
        ),
        TaskKind(
            "incline", "walk uphill (+x) on a slope made by tilting gravity", _flat("incline"),
            "x_progress", {"angle": Option(5.0, 0.0, 30.0, "slope, degrees")},
            sim=lambda o: {"incline": float(o["angle"])}, senses=(SENSES["gravity"],),
        ),
        TaskKind(
            "ice", "walk on slippery ground", _flat("ice"), "norm_final_dist",
            {"friction": Option(0.1, 0.0, 1.0, "factor on the materials' friction")},
            sim=lambda o: {"friction": float(o["friction"])},
        ),
        TaskKind(
            "mud", "walk on grippy, high-friction ground", _flat("mud"), "norm_final_dist",
            {"friction": Option(4.0, 1.0, 20.0, "factor on the materials' friction")},
            sim=lambda o: {"friction": float(o["friction"])},
        ),
        TaskKind(
            "jump", "raise the centre of mass as high as possible (muscles expand and contract)",
            _flat("jump"), "peak_height", sim=lambda o: {"actuation": "symmetric"},
        ),
        TaskKind("turn", "turn in place about the vertical axis", _flat("turn"), "yaw",
                 senses=(SENSES["heading"],)),  # fmt: skip
        TaskKind(
            "push", "push a box to a target (-x of the robot)", push_layout, "push_progress",
            {"size": Option(3, 1, 6, "side of the box, voxels", integer=True),
             "distance": Option(10.0, 1.0, 50.0, "target distance from the box, voxel lengths"),
             "density": Option(5e5, 1e4, 1e7, "the box's density, kg/m^3 (the robot's: 1e6)")},
            senses=(SENSES["object"], SENSES["target"]),
        ),
        TaskKind(
            "carry", "walk with a cap on top without dropping it", carry_layout, "carried_dist",
            {"rim": Option(2, 0, 4, "depth of the cap's rim round the robot's top, voxels", integer=True),
             "density": Option(1e5, 1e4, 1e7, "the cap's density, kg/m^3 (the robot's: 1e6)")},
            senses=_OBJECT,
        ),
        TaskKind(
            "swim", "swim in a fluid (no floor, no weight, drag on exposed faces; muscles expand and contract)", _swim,
            "swim_dist",
            {"drag": Option(5e6, 1e3, 1e8, "rho C_d / 2 of the fluid, kg/m^3")},
            sim=lambda o: {"fluid_drag": float(o["drag"]), "gravity": 0.0, "floor": False,
                           "actuation": "symmetric"},
        ),
        TaskKind(
            "grow", "spread the largest footprint (muscles expand and contract)", _flat("grow"),
            "footprint_gain", sim=lambda o: {"actuation": "symmetric"},
        ),
    )
}  # fmt: skip
