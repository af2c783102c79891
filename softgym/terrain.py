"""Terrains: the floor plus static axis-aligned boxes (fences, stairs, your own).

Sizes and positions are in **voxel lengths** (multiples of
``SimConfig.voxel_size``), the unit of the seed study, so one terrain fits any
lattice dimension. Boxes are obstacles, not robot mass: the centre of mass and
every metric use the robot's voxels only. (The seed's engine modelled its fence
as 44 fixed 1 kg voxels and counted them in the centre of mass, which diluted
its reported distances by ``M_robot / (M_robot + 44 kg)``; softgym does not.)

Contact between a voxel and a box uses the floor's laws: penalty normal force
``2 E L p`` on the voxel's penetration ``p`` of the box (treating the voxel as a
sphere of its half actuated size), collision damping, and static/kinetic
Coulomb friction with the voxel's coefficients, so a robot is stopped by a
wall's side and can stand on its top. In the engine's ``"seed"`` model, boxes
with integer corners become the seed's fixed wall voxels instead (its fence),
unless the terrain says ``box_contact="surface"``.

A terrain may also hold movable :class:`Block` objects: passive voxel bodies
(a box to push, a cap to carry) simulated with each robot as a second
component of its simulation entry. They touch the robot through the
self-collision law, rest on the floor and boxes like voxels do, and are left
out of the robot's centre of mass, actuation and metrics (except the task
measures that read them).
"""

from __future__ import annotations

import json
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from functools import partial
from typing import Any

import numpy as np

from softgym.exceptions import InvalidTerrainError
from softgym.validate import number, positive

__all__ = [
    "BOX_CONTACTS",
    "MAX_BLOCK_DIM",
    "MAX_BOXES",
    "MAX_COORDINATE",
    "MAX_OBJECTS",
    "MAX_TERRAIN_JSON_BYTES",
    "Block",
    "Box",
    "Terrain",
]

SCHEMA = "softgym.terrain"
VERSION = 1

#: Most boxes a terrain may hold (contact is checked for every voxel against every box).
MAX_BOXES = 1000
#: Largest ``|coordinate|`` of a box corner, in voxel lengths.
MAX_COORDINATE = 1e6
#: Largest terrain JSON text (bytes) :meth:`Terrain.from_json` reads.
MAX_TERRAIN_JSON_BYTES = 4 * 2**20
#: Most movable blocks a terrain may hold.
MAX_OBJECTS = 16
#: Largest side of a block's grid (voxels).
MAX_BLOCK_DIM = 32
#: How boxes touch voxels: ``"auto"`` (the engine's ``"seed"`` model turns boxes with integer
#: corners into the seed's fixed wall voxels, frictionless; otherwise penalty contact with
#: friction) or ``"surface"`` (always the penalty contact with friction: ground to walk on).
BOX_CONTACTS: tuple[str, ...] = ("auto", "surface")


_number = partial(number, error=InvalidTerrainError)
_positive = partial(positive, error=InvalidTerrainError)


def _point(name: str, value: Any, n: int = 3) -> tuple[float, ...]:
    """``n`` finite coordinates within +-MAX_COORDINATE voxel lengths."""
    if isinstance(value, (str, bytes)) or not isinstance(value, (Sequence, np.ndarray)):
        raise InvalidTerrainError(f"{name} must be a sequence of {n} numbers, got {value!r:.80}")
    if len(value) != n:
        raise InvalidTerrainError(f"{name} needs {n} coordinates, got {len(value)}: {value!r:.80}")
    out = tuple(_number(f"{name}[{k}]", v) for k, v in enumerate(value))
    if any(abs(v) > MAX_COORDINATE for v in out):
        raise InvalidTerrainError(
            f"{name} = {out}: coordinates must lie in [-{MAX_COORDINATE:g}, {MAX_COORDINATE:g}] "
            "voxel lengths"
        )
    return out


@dataclass(frozen=True)
class Box:
    """A static axis-aligned box.

    Parameters
    ----------
    lo : sequence of 3 floats
        Minimum corner (x, y, z) in voxel lengths.
    hi : sequence of 3 floats
        Maximum corner (x, y, z) in voxel lengths; every side must be > 0.
    """

    lo: tuple[float, float, float]
    hi: tuple[float, float, float]

    def __post_init__(self) -> None:
        lo = _point("box corner lo", self.lo)
        hi = _point("box corner hi", self.hi)
        if any(h - low <= 0 for low, h in zip(lo, hi)):
            raise InvalidTerrainError(f"box sizes must be > 0, got lo={lo} hi={hi}")
        object.__setattr__(self, "lo", lo)
        object.__setattr__(self, "hi", hi)

    @property
    def size(self) -> tuple[float, float, float]:
        """Side lengths (voxel lengths)."""
        return tuple(h - low for low, h in zip(self.lo, self.hi))

    def overlaps(self, lo: Sequence[float], hi: Sequence[float]) -> bool:
        """True when the open interiors of this box and the box [lo, hi] intersect."""
        return all(self.lo[k] < hi[k] and lo[k] < self.hi[k] for k in range(3))


@dataclass(frozen=True, eq=False)
class Block:
    """A passive, movable voxel body of one material (a box to push, a cap to carry).

    Parameters
    ----------
    origin : sequence of 3 floats
        Corner of the block's grid (voxel lengths): cell (i, j, k) has its
        centre at ``origin + (i + 0.5, j + 0.5, k + 0.5)``. It may be off the
        lattice (e.g. half a voxel from the robot, the self-contact envelope).
    shape : sequence of 3 ints
        Grid size (voxels), each in 1..:data:`MAX_BLOCK_DIM`.
    cells : array_like of bool of shape ``shape``, optional
        Filled cells (default all): any 6-connected shape.
    youngs_modulus, density : float
        Pa and kg/m^3 (> 0); the seed's tissue is 5e6 Pa and 1e6 kg/m^3. A
        stiffer or lighter block than the robot shortens the time step.
    poisson : float
        Poisson's ratio in [0, 0.5).
    mu_static, mu_kinetic : float
        Friction coefficients against the floor and boxes (>= 0).
    """

    origin: tuple[float, float, float]
    shape: tuple[int, int, int] = (1, 1, 1)
    cells: Any = None
    youngs_modulus: float = 5e6
    density: float = 1e6
    poisson: float = 0.35
    mu_static: float = 1.0
    mu_kinetic: float = 0.5

    def __post_init__(self) -> None:
        object.__setattr__(self, "origin", _point("block origin", self.origin))
        shape = self.shape
        if (
            isinstance(shape, (str, bytes))
            or not isinstance(shape, (Sequence, np.ndarray))
            or len(shape) != 3
            or any(
                isinstance(v, (bool, np.bool_))
                or not isinstance(v, (int, np.integer))
                or not 1 <= v <= MAX_BLOCK_DIM
                for v in shape
            )
        ):
            raise InvalidTerrainError(
                f"block shape must be 3 integers, each in 1..{MAX_BLOCK_DIM}, got {shape!r:.80}"
            )
        shape = tuple(int(v) for v in shape)
        object.__setattr__(self, "shape", shape)
        if self.cells is None:
            cells = np.ones(shape, dtype=bool)
        else:
            try:
                cells = np.asarray(self.cells)
            except (TypeError, ValueError):
                raise InvalidTerrainError("block cells must be an array of bools") from None
            if cells.shape != shape or cells.dtype.kind not in "biu":
                raise InvalidTerrainError(
                    f"block cells must be bools of shape {shape}, got {cells.dtype} {cells.shape}"
                )
            cells = cells.astype(bool)
        if not cells.any():
            raise InvalidTerrainError("a block needs at least one filled cell")
        cells.setflags(write=False)
        object.__setattr__(self, "cells", cells)
        for name in ("youngs_modulus", "density"):
            object.__setattr__(self, name, _positive(f"block {name}", getattr(self, name)))
        nu = _number("block poisson", self.poisson)
        if not 0.0 <= nu < 0.5:
            raise InvalidTerrainError(f"block poisson must be in [0, 0.5), got {nu}")
        object.__setattr__(self, "poisson", nu)
        for name in ("mu_static", "mu_kinetic"):
            v = _number(f"block {name}", getattr(self, name))
            if v < 0:
                raise InvalidTerrainError(f"block {name} must be >= 0, got {v}")
            object.__setattr__(self, name, v)

    @classmethod
    def box(cls, lo: Sequence[float], size: Sequence[int], **material: Any) -> Block:
        """A full box of ``size`` voxels with its corner at ``lo`` (voxel lengths)."""
        return cls(tuple(lo), tuple(size), None, **material)

    @property
    def n_voxels(self) -> int:
        """Filled cells."""
        return int(np.count_nonzero(self.cells))

    @property
    def lo(self) -> tuple[float, float, float]:
        """Minimum corner of its grid (voxel lengths)."""
        return self.origin

    @property
    def hi(self) -> tuple[float, float, float]:
        """Maximum corner of its grid (voxel lengths)."""
        return tuple(o + s for o, s in zip(self.origin, self.shape))

    @property
    def center(self) -> np.ndarray:
        """Centre of its filled cells (voxel lengths), shape (3,): its centre of mass at rest."""
        return np.asarray(self.origin) + np.argwhere(self.cells).mean(axis=0) + 0.5

    def to_dict(self) -> dict[str, Any]:
        """Plain-JSON dict."""
        out: dict[str, Any] = {"origin": list(self.origin), "shape": list(self.shape)}
        if not self.cells.all():
            out["cells"] = self.cells.astype(int).tolist()
        for name in ("youngs_modulus", "density", "poisson", "mu_static", "mu_kinetic"):
            out[name] = getattr(self, name)
        return out

    @classmethod
    def from_dict(cls, data: Any) -> Block:
        """Inverse of :meth:`to_dict`."""
        known = {"origin", "shape", "cells", "youngs_modulus", "density", "poisson",
                 "mu_static", "mu_kinetic"}  # fmt: skip
        if not isinstance(data, dict) or "origin" not in data or set(data) - known:
            raise InvalidTerrainError(
                f"a block is an object with 'origin' and optional {sorted(known - {'origin'})}, "
                f"got {data!r:.80}"
            )
        return cls(**data)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Block):
            return NotImplemented
        return self.to_dict() == other.to_dict()

    __hash__ = None  # type: ignore[assignment]


@dataclass(frozen=True)
class Terrain:
    """A floor at z = 0 (optional) and a list of static boxes.

    Parameters
    ----------
    boxes : sequence of Box
        Obstacles, in voxel lengths.
    floor : bool
        Whether the floor plane z = 0 is present (without it, boxes are the
        only ground: platforms over a pit, a world under water).
    name : str
        A label for figures and logs.
    meta : dict
        What built it (builder name and arguments), for logs; not compared.
    objects : sequence of Block
        Movable passive bodies (at most :data:`MAX_OBJECTS`).
    box_contact : {"auto", "surface"}
        How boxes touch voxels (:data:`BOX_CONTACTS`): ``"surface"`` keeps
        the penalty contact with friction in every engine model (ground to
        walk on); ``"auto"`` lets the ``"seed"`` model make lattice boxes
        the seed's frictionless wall voxels.
    """

    boxes: tuple[Box, ...] = ()
    floor: bool = True
    name: str = "flat"
    meta: dict[str, Any] = field(default_factory=dict, compare=False)
    objects: tuple[Block, ...] = ()
    box_contact: str = "auto"

    def __post_init__(self) -> None:
        if isinstance(self.boxes, (str, bytes)) or not isinstance(self.boxes, (Sequence, np.ndarray)):
            raise InvalidTerrainError(f"terrain boxes must be a sequence, got {self.boxes!r:.80}")
        if len(self.boxes) > MAX_BOXES:
            raise InvalidTerrainError(
                f"a terrain holds at most {MAX_BOXES} boxes, got {len(self.boxes)}"
            )
        boxes = []
        for k, b in enumerate(self.boxes):
            if isinstance(b, Box):
                boxes.append(b)
            elif isinstance(b, (tuple, list)) and len(b) == 2:
                boxes.append(Box(*b))
            else:
                raise InvalidTerrainError(f"box {k} must be a Box or a (lo, hi) pair, got {b!r:.80}")
        if not isinstance(self.floor, (bool, np.bool_)):
            raise InvalidTerrainError(f"terrain floor must be a bool, got {self.floor!r:.80}")
        if not isinstance(self.name, str):
            raise InvalidTerrainError(f"terrain name must be a str, got {self.name!r:.80}")
        if not isinstance(self.meta, dict):
            raise InvalidTerrainError(f"terrain meta must be a dict, got {self.meta!r:.80}")
        object.__setattr__(self, "boxes", tuple(boxes))
        object.__setattr__(self, "floor", bool(self.floor))
        if isinstance(self.objects, (str, bytes)) or not isinstance(self.objects, (Sequence, np.ndarray)):
            raise InvalidTerrainError(f"terrain objects must be a sequence, got {self.objects!r:.80}")
        if len(self.objects) > MAX_OBJECTS:
            raise InvalidTerrainError(
                f"a terrain holds at most {MAX_OBJECTS} objects, got {len(self.objects)}"
            )
        objects = []
        for k, o in enumerate(self.objects):
            if isinstance(o, Block):
                objects.append(o)
            elif isinstance(o, dict):
                objects.append(Block.from_dict(o))
            else:
                raise InvalidTerrainError(f"object {k} must be a Block, got {o!r:.80}")
        object.__setattr__(self, "objects", tuple(objects))
        if not isinstance(self.box_contact, str) or self.box_contact not in BOX_CONTACTS:
            raise InvalidTerrainError(
                f"terrain box_contact must be one of {BOX_CONTACTS}, got {self.box_contact!r:.80}"
            )

    # ------------------------------------------------------------- builders
    @classmethod
    def flat(cls) -> Terrain:
        """The floor alone."""
        return cls((), True, "flat")

    @classmethod
    def from_boxes(cls, boxes: Iterable[Any], name: str = "boxes", floor: bool = True) -> Terrain:
        """A terrain of the user's boxes: ``Box`` objects or ``(lo, hi)`` pairs."""
        return cls(tuple(boxes), floor, name)

    @staticmethod
    def _ring(center: Sequence[float], inner: float, thickness: float, z0: float, z1: float) -> list[Box]:
        # a square ring of four boxes around `center`, inner side `inner`, no overlaps
        cx, cy = float(center[0]), float(center[1])
        a = inner / 2.0
        b = a + thickness
        return [
            Box((cx - b, cy - b, z0), (cx + b, cy - a, z1)),  # south, full width
            Box((cx - b, cy + a, z0), (cx + b, cy + b, z1)),  # north, full width
            Box((cx - b, cy - a, z0), (cx - a, cy + a, z1)),  # west
            Box((cx + a, cy - a, z0), (cx + b, cy + a, z1)),  # east
        ]

    @classmethod
    def fence(
        cls,
        inner: float = 10,
        height: float = 1,
        thickness: float = 1,
        center: Sequence[float] = (3.0, 3.0),
    ) -> Terrain:
        """The seed's walled square fence around the robot's start.

        Parameters
        ----------
        inner : float
            Inner side of the fence (voxel lengths). The seed's first fence
            (side 12 with 1-voxel walls) has a 10-voxel interior, so a 6-wide
            robot has a 2-voxel gap on every side.
        height, thickness : float
            Wall height and thickness (voxel lengths), 1 and 1 in the seed.
        center : sequence of 2 floats
            Centre of the fence in the xy plane (voxel lengths): the centre of
            the robot's footprint, (3, 3) for a 6x6 robot at the origin.
        """
        for name, v in (("inner", inner), ("height", height), ("thickness", thickness)):
            if not _number(f"fence {name}", v) > 0:
                raise InvalidTerrainError(f"fence {name} must be > 0, got {v}")
        center = _point("fence center", center, 2)
        boxes = cls._ring(center, inner, thickness, 0.0, height)
        meta = {"builder": "fence", "inner": inner, "height": height, "thickness": thickness,
                "center": list(map(float, center))}  # fmt: skip
        return cls(tuple(boxes), True, "fence", meta)

    @classmethod
    def stairs(
        cls,
        n_rings: int = 3,
        step_height: float = 1,
        ring_width: float = 2,
        inner: float = 10,
        center: Sequence[float] = (3.0, 3.0),
        equal_heights: bool = False,
    ) -> Terrain:
        """Concentric square rings, each one step higher than the one inside it.

        Ring ``i`` (0 = innermost) spans ``inner/2 + i ring_width`` to
        ``inner/2 + (i + 1) ring_width`` from the centre and is
        ``(i + 1) step_height`` high: a real staircase leading out of the start
        area. ``equal_heights=True`` gives the seed's "stairs": rings all of
        height ``step_height``, separated by gaps of ``ring_width`` (the seed's
        concentric fences of sides 12, 20, 26...).
        """
        if (
            isinstance(n_rings, (bool, np.bool_))
            or not isinstance(n_rings, (int, np.integer))
            or not 1 <= n_rings <= MAX_BOXES // 4
        ):
            raise InvalidTerrainError(
                f"n_rings must be an integer in 1..{MAX_BOXES // 4} (4 boxes per ring, "
                f"at most {MAX_BOXES} boxes), got {n_rings!r:.80}"
            )
        for name, v in (("step_height", step_height), ("ring_width", ring_width), ("inner", inner)):
            if not _number(f"stairs {name}", v) > 0:
                raise InvalidTerrainError(f"stairs {name} must be > 0, got {v}")
        if not isinstance(equal_heights, (bool, np.bool_)):
            raise InvalidTerrainError(f"stairs equal_heights must be a bool, got {equal_heights!r:.80}")
        center = _point("stairs center", center, 2)
        boxes: list[Box] = []
        for i in range(int(n_rings)):
            if equal_heights:
                side = inner + 2 * i * (ring_width + 1)
                boxes += cls._ring(center, side, 1.0, 0.0, step_height)
            else:
                side = inner + 2 * i * ring_width
                boxes += cls._ring(center, side, ring_width, 0.0, (i + 1) * step_height)
        meta = {"builder": "stairs", "n_rings": int(n_rings), "step_height": step_height,
                "ring_width": ring_width, "inner": inner, "center": list(map(float, center)),
                "equal_heights": bool(equal_heights)}  # fmt: skip
        return cls(tuple(boxes), True, "stairs", meta)

    # ------------------------------------------------------------ validation
    def validate(self, robot_lo: Sequence[float], robot_hi: Sequence[float]) -> None:
        """Raise InvalidTerrainError if a box overlaps the robot's start box (voxel lengths)."""
        for k, box in enumerate(self.boxes):
            if box.overlaps(robot_lo, robot_hi):
                raise InvalidTerrainError(
                    f"box {k} {box.lo}-{box.hi} overlaps the robot's start region "
                    f"{tuple(robot_lo)}-{tuple(robot_hi)}"
                )
        for k, obj in enumerate(self.objects):
            if all(obj.lo[a] < robot_hi[a] and robot_lo[a] < obj.hi[a] for a in range(3)):
                cells = np.argwhere(obj.cells) + np.asarray(obj.origin)
                inside = np.all((cells + 1 > np.asarray(robot_lo)) & (cells < np.asarray(robot_hi)), axis=1)
                if inside.any():
                    raise InvalidTerrainError(
                        f"object {k} at {obj.origin} overlaps the robot's start region "
                        f"{tuple(robot_lo)}-{tuple(robot_hi)}"
                    )

    def as_array(self, voxel_size: float) -> np.ndarray:
        """Boxes in metres, ndarray of shape (n_boxes, 6): (x0, y0, z0, x1, y1, z1)."""
        if not self.boxes:
            return np.zeros((0, 6))
        return np.array([b.lo + b.hi for b in self.boxes], dtype=np.float64) * voxel_size

    # ----------------------------------------------------------------- JSON
    def to_dict(self) -> dict[str, Any]:
        """Plain-JSON dictionary with a schema version (``objects`` and ``box_contact`` when set)."""
        out = {
            "schema": SCHEMA,
            "version": VERSION,
            "name": self.name,
            "floor": bool(self.floor),
            "boxes": [{"lo": list(b.lo), "hi": list(b.hi)} for b in self.boxes],
            "meta": self.meta,
        }
        if self.objects:
            out["objects"] = [o.to_dict() for o in self.objects]
        if self.box_contact != "auto":
            out["box_contact"] = self.box_contact
        return out

    def to_json(self) -> str:
        """JSON text of :meth:`to_dict`."""
        return json.dumps(self.to_dict(), indent=1)

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> Terrain:
        """Inverse of :meth:`to_dict`; malformed input raises InvalidTerrainError."""
        if not isinstance(data, dict) or data.get("schema") != SCHEMA:
            raise InvalidTerrainError(f"not a softgym terrain (schema {SCHEMA!r} expected)")
        version = data.get("version")
        if isinstance(version, bool) or not isinstance(version, int) or not 1 <= version <= VERSION:
            raise InvalidTerrainError(
                f"terrain file version {version!r:.40} is not supported (this softgym reads 1..{VERSION})"
            )
        unknown = set(data) - {"schema", "version", "name", "floor", "boxes", "meta", "objects",
                               "box_contact"}
        if unknown:
            raise InvalidTerrainError(f"unknown terrain field(s) {sorted(map(str, unknown))}")
        raw_boxes = data.get("boxes")
        if not isinstance(raw_boxes, list):
            raise InvalidTerrainError(f"terrain 'boxes' must be a list, got {raw_boxes!r:.80}")
        if len(raw_boxes) > MAX_BOXES:
            raise InvalidTerrainError(
                f"a terrain holds at most {MAX_BOXES} boxes, got {len(raw_boxes)}"
            )
        boxes = []
        for k, b in enumerate(raw_boxes):
            if not isinstance(b, dict) or set(b) != {"lo", "hi"}:
                raise InvalidTerrainError(
                    f"terrain box {k} must be an object with exactly 'lo' and 'hi', got {b!r:.80}"
                )
            try:
                boxes.append(Box(b["lo"], b["hi"]))
            except InvalidTerrainError as exc:
                raise InvalidTerrainError(f"terrain box {k}: {exc}") from None
        objects = data.get("objects", [])
        if not isinstance(objects, list):
            raise InvalidTerrainError(f"terrain 'objects' must be a list, got {objects!r:.80}")
        return cls(tuple(boxes), data.get("floor", True), data.get("name", "boxes"),
                   data.get("meta", {}), tuple(Block.from_dict(o) for o in objects),
                   data.get("box_contact", "auto"))  # fmt: skip

    @classmethod
    def from_json(cls, text: str | bytes) -> Terrain:
        """Parse :meth:`to_json` output.

        Raises
        ------
        InvalidTerrainError
            If ``text`` is not str or bytes, larger than :data:`MAX_TERRAIN_JSON_BYTES`,
            not UTF-8 JSON, nested too deeply, or not a valid terrain.
        """
        if not isinstance(text, (str, bytes, bytearray)):
            raise InvalidTerrainError(f"terrain JSON must be str or bytes, got {type(text).__name__}")
        if len(text) > MAX_TERRAIN_JSON_BYTES:
            raise InvalidTerrainError(
                f"terrain JSON of {len(text)} characters is larger than the cap of "
                f"{MAX_TERRAIN_JSON_BYTES} bytes"
            )
        try:
            data = json.loads(text)
        except (ValueError, RecursionError) as exc:  # JSONDecodeError, UnicodeDecodeError...
            raise InvalidTerrainError(f"terrain JSON is invalid: {exc!s:.200}") from None
        return cls.from_dict(data)
