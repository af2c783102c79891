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
wall's side and can stand on its top.
"""

from __future__ import annotations

import json
import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from softgym.exceptions import InvalidTerrainError

__all__ = ["Box", "Terrain"]

SCHEMA = "softgym.terrain"
VERSION = 1


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
        lo = tuple(float(v) for v in self.lo)
        hi = tuple(float(v) for v in self.hi)
        if len(lo) != 3 or len(hi) != 3:
            raise InvalidTerrainError(f"a box needs 3 coordinates per corner, got {self.lo}, {self.hi}")
        if not all(math.isfinite(v) for v in lo + hi):
            raise InvalidTerrainError(f"box corners must be finite, got {lo}, {hi}")
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


@dataclass(frozen=True)
class Terrain:
    """A floor at z = 0 (optional) and a list of static boxes.

    Parameters
    ----------
    boxes : sequence of Box
        Obstacles, in voxel lengths.
    floor : bool
        Whether the floor plane z = 0 is present.
    name : str
        A label for figures and logs.
    """

    boxes: tuple[Box, ...] = ()
    floor: bool = True
    name: str = "flat"
    meta: dict[str, Any] = field(default_factory=dict, compare=False)

    def __post_init__(self) -> None:
        boxes = tuple(b if isinstance(b, Box) else Box(*b) for b in self.boxes)
        object.__setattr__(self, "boxes", boxes)

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
            if not (math.isfinite(v) and v > 0):
                raise InvalidTerrainError(f"fence {name} must be > 0, got {v}")
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
        if int(n_rings) != n_rings or n_rings < 1:
            raise InvalidTerrainError(f"n_rings must be a positive integer, got {n_rings}")
        for name, v in (("step_height", step_height), ("ring_width", ring_width), ("inner", inner)):
            if not (math.isfinite(v) and v > 0):
                raise InvalidTerrainError(f"stairs {name} must be > 0, got {v}")
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

    def as_array(self, voxel_size: float) -> np.ndarray:
        """Boxes in metres, ndarray of shape (n_boxes, 6): (x0, y0, z0, x1, y1, z1)."""
        if not self.boxes:
            return np.zeros((0, 6))
        return np.array([b.lo + b.hi for b in self.boxes], dtype=np.float64) * voxel_size

    # ----------------------------------------------------------------- JSON
    def to_dict(self) -> dict[str, Any]:
        """Plain-JSON dictionary with a schema version."""
        return {
            "schema": SCHEMA,
            "version": VERSION,
            "name": self.name,
            "floor": bool(self.floor),
            "boxes": [{"lo": list(b.lo), "hi": list(b.hi)} for b in self.boxes],
            "meta": self.meta,
        }

    def to_json(self) -> str:
        """JSON text of :meth:`to_dict`."""
        return json.dumps(self.to_dict(), indent=1)

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> Terrain:
        """Inverse of :meth:`to_dict`; malformed input raises InvalidTerrainError."""
        if not isinstance(data, dict) or data.get("schema") != SCHEMA:
            raise InvalidTerrainError(f"not a softgym terrain (schema {SCHEMA!r} expected)")
        version = data.get("version")
        if not isinstance(version, int) or version > VERSION or version < 1:
            raise InvalidTerrainError(
                f"terrain file version {version!r} is not supported (this softgym reads 1..{VERSION})"
            )
        try:
            boxes = tuple(Box(tuple(b["lo"]), tuple(b["hi"])) for b in data["boxes"])
            return cls(boxes, bool(data.get("floor", True)), str(data.get("name", "boxes")),
                       dict(data.get("meta", {})))  # fmt: skip
        except (KeyError, TypeError) as exc:
            raise InvalidTerrainError(f"malformed terrain: {exc!r}") from None

    @classmethod
    def from_json(cls, text: str) -> Terrain:
        """Parse :meth:`to_json` output."""
        try:
            data = json.loads(text)
        except json.JSONDecodeError as exc:
            raise InvalidTerrainError(f"terrain JSON is invalid: {exc}") from None
        return cls.from_dict(data)
