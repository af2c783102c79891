"""A terrain genome: a bounded, fixed-length vector that the task layer turns into boxes.

POET-style co-evolution (:mod:`evolvers.drivers.poet`) mutates terrains the way an
evolver mutates robots, so a terrain needs a genome: seven numbers, each in a
documented range, that build a :class:`~softgym.terrain.Terrain` around a
robot's grid. The obstacles are square rings centred on the robot's footprint
(a robot may walk off in any direction), outward from the start:

================  ==============  ===================================================
gene              range           what it builds (voxel lengths)
================  ==============  ===================================================
fence_height      [0, 2]          a fence ring 1 thick, its inner face 2 voxels from
                                  the footprint (the seed's wall has height 1)
rough_amplitude   [0, 1]          a 2-voxel-wide ring of bumps just outside the
                                  fence, each of height U(0, amplitude)
rough_cell        [1, 3]          the bumps' side (cells of about this size)
stair_height      [0, 1]          the rise of each step of a staircase outside the
                                  bumps (step ``i`` is ``(i + 1) stair_height`` high)
stair_count       0..3            steps of the staircase, each 1 voxel wide
gap_width         [0, 2]          a ditch down to the floor after the top step,
                                  then a 2-voxel landing at the top step's height
                                  (no stairs: no height to fall from, no ditch)
seed              0..2^31-1       draws the bump heights
================  ==============  ===================================================

A feature lower (or narrower) than :data:`MIN_FEATURE` is left out, so the
all-zero genome (:meth:`TerrainGenome.flat`) is the flat floor. Every gene out
of its range raises :class:`~softgym.exceptions.InvalidTerrainError` naming the
gene and the range.

>>> from softgym.tasks.terrain_genome import TerrainGenome
>>> g = TerrainGenome(fence_height=0.5, stair_height=0.3, stair_count=2)
>>> t = g.terrain((4, 4, 4))
>>> len(t.boxes), t.name
(12, 'poet')
"""

from __future__ import annotations

import hashlib
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from numbers import Real
from typing import Any

import numpy as np

from softgym.exceptions import InvalidTerrainError
from softgym.terrain import Box, Terrain

__all__ = [
    "MIN_FEATURE",
    "TERRAIN_BOUNDS",
    "TERRAIN_GENES",
    "TerrainGenome",
]

#: Schema tag of :meth:`TerrainGenome.to_dict`.
SCHEMA = "softgym.terrain_genome"

#: The genes, in vector order: name -> (low, high, unit). ``stair_count`` and ``seed`` are integers.
TERRAIN_BOUNDS: dict[str, tuple[float, float, str]] = {
    "fence_height": (0.0, 2.0, "voxel lengths"),
    "stair_height": (0.0, 1.0, "voxel lengths"),
    "stair_count": (0.0, 3.0, "steps"),
    "gap_width": (0.0, 2.0, "voxel lengths"),
    "rough_amplitude": (0.0, 1.0, "voxel lengths"),
    "rough_cell": (1.0, 3.0, "voxel lengths"),
    "seed": (0.0, float(2**31 - 1), ""),
}
#: Gene names in vector order.
TERRAIN_GENES: tuple[str, ...] = tuple(TERRAIN_BOUNDS)
_INTEGER = ("stair_count", "seed")

#: Heights and widths below this (voxel lengths) build nothing.
MIN_FEATURE = 0.05
#: Free floor between the robot's footprint and the fence's inner face (the seed's 2 voxels).
START_MARGIN = 2.0
#: Width of the ring of bumps (voxel lengths).
ROUGH_WIDTH = 2.0
#: Width of one step, and of the landing after the ditch (voxel lengths).
STEP_WIDTH = 1.0
LANDING_WIDTH = 2.0

_KEY_SHAPE = (4, 4, 4)

#: Default Gaussian step of :meth:`TerrainGenome.mutate`, as a fraction of each gene's range.
MUTATION_SIGMA = 0.15


def _fmt(v: float) -> str:
    return str(int(v)) if v == int(v) else f"{v:g}"


def _gene(name: str, value: Any) -> float:
    lo, hi, unit = TERRAIN_BOUNDS[name]
    shown = f"[{_fmt(lo)}, {_fmt(hi)}]" + (f" {unit}" if unit else "")
    if isinstance(value, (bool, np.bool_, str, bytes)) or not isinstance(value, Real):
        raise InvalidTerrainError(
            f"terrain genome {name} must be a number in {shown}, got {value!r:.80}"
        )
    v = float(value)
    if not math.isfinite(v) or not lo <= v <= hi:
        raise InvalidTerrainError(f"terrain genome {name} = {value!r:.40} is outside {shown}")
    if name in _INTEGER and v != int(v):
        raise InvalidTerrainError(
            f"terrain genome {name} must be an integer in {shown}, got {value!r:.40}"
        )
    return v


@dataclass(frozen=True)
class TerrainGenome:
    """Seven bounded numbers that build an obstacle course (see the module docstring).

    Parameters
    ----------
    fence_height : float
        Height of the fence ring, [0, 2] voxel lengths.
    stair_height : float
        Rise per step, [0, 1] voxel lengths.
    stair_count : int
        Steps, 0..3.
    gap_width : float
        Width of the ditch after the top step, [0, 2] voxel lengths.
    rough_amplitude : float
        Largest bump height, [0, 1] voxel lengths.
    rough_cell : float
        Bump side, [1, 3] voxel lengths.
    seed : int
        Seed of the bump heights, 0..2^31-1.

    Raises
    ------
    InvalidTerrainError
        A gene that is not a finite number in its range (or not an integer
        for ``stair_count`` and ``seed``); the message names the gene and the range.
    """

    fence_height: float = 0.0
    stair_height: float = 0.0
    stair_count: int = 0
    gap_width: float = 0.0
    rough_amplitude: float = 0.0
    rough_cell: float = 1.0
    seed: int = 0

    def __post_init__(self) -> None:
        for name in TERRAIN_GENES:
            v = _gene(name, getattr(self, name))
            object.__setattr__(self, name, int(v) if name in _INTEGER else v)

    # ------------------------------------------------------------------ vectors
    @classmethod
    def flat(cls) -> TerrainGenome:
        """The all-zero genome: the floor alone."""
        return cls()

    @classmethod
    def from_vector(cls, vector: Sequence[float] | np.ndarray) -> TerrainGenome:
        """A genome from its vector (:data:`TERRAIN_GENES` order); integer genes are rounded.

        Raises
        ------
        InvalidTerrainError
            Wrong length, or a gene out of its range.
        """
        try:
            v = np.asarray(vector, dtype=np.float64).reshape(-1)
        except (TypeError, ValueError):
            raise InvalidTerrainError(
                f"a terrain genome vector holds {len(TERRAIN_GENES)} numbers, got {vector!r:.80}"
            ) from None
        if v.size != len(TERRAIN_GENES):
            raise InvalidTerrainError(
                f"a terrain genome vector holds {len(TERRAIN_GENES)} numbers "
                f"({', '.join(TERRAIN_GENES)}), got {v.size}"
            )
        kw = {n: (float(np.rint(x)) if n in _INTEGER and math.isfinite(x) else float(x))
              for n, x in zip(TERRAIN_GENES, v.tolist())}  # fmt: skip
        return cls(**kw)

    def to_vector(self) -> np.ndarray:
        """The genes, ndarray of shape (7,), float64, in :data:`TERRAIN_GENES` order."""
        return np.array([float(getattr(self, n)) for n in TERRAIN_GENES], dtype=np.float64)

    def key(self) -> str:
        """A hash of the boxes the genome builds: genomes that differ only in genes that build
        nothing (a seed without bumps, a gap without stairs...) share it.
        """
        boxes = [b.lo + b.hi for b in self.terrain(_KEY_SHAPE).boxes]
        return hashlib.sha256(repr(boxes).encode()).hexdigest()

    # ------------------------------------------------------------------ variation
    @classmethod
    def random(cls, rng: np.random.Generator | int | None = None) -> TerrainGenome:
        """A genome drawn uniformly within the bounds (integers uniformly among their values)."""
        rng = rng if isinstance(rng, np.random.Generator) else np.random.default_rng(rng)
        kw: dict[str, float] = {}
        for name, (lo, hi, _) in TERRAIN_BOUNDS.items():
            if name in _INTEGER:
                kw[name] = int(rng.integers(int(lo), int(hi) + 1))
            else:
                kw[name] = float(rng.uniform(lo, hi))
        return cls(**kw)

    def mutate(
        self,
        rng: np.random.Generator | int | None = None,
        sigma: float = MUTATION_SIGMA,
        rate: float = 0.5,
    ) -> TerrainGenome:
        """A mutant: each gene changes with probability ``rate``, at least one always does.

        A real gene gets ``N(0, sigma * (high - low))`` added and is clipped
        into its range; ``stair_count`` moves one step up or down (reflected
        at the bounds); ``seed`` is drawn anew.

        Parameters
        ----------
        rng : numpy.random.Generator or int or None
        sigma : float
            Step as a fraction of each gene's range.
        rate : float
            Probability that a gene mutates, in (0, 1].

        Returns
        -------
        TerrainGenome
        """
        rng = rng if isinstance(rng, np.random.Generator) else np.random.default_rng(rng)
        if not (0.0 < float(rate) <= 1.0) or not (float(sigma) > 0.0):
            raise InvalidTerrainError(
                f"mutation needs rate in (0, 1] and sigma > 0, got {rate}, {sigma}"
            )
        picks = rng.random(len(TERRAIN_GENES)) < rate
        if not picks.any():
            picks[int(rng.integers(len(TERRAIN_GENES)))] = True
        kw: dict[str, float] = {}
        for pick, (name, (lo, hi, _)) in zip(picks, TERRAIN_BOUNDS.items()):
            v = getattr(self, name)
            if pick:
                if name == "seed":
                    v = int(rng.integers(0, int(hi) + 1))
                elif name == "stair_count":
                    v = v + (1 if rng.random() < 0.5 else -1)
                    v = int(lo) + 1 if v < lo else int(hi) - 1 if v > hi else v
                else:
                    v = float(np.clip(v + rng.normal(0.0, sigma * (hi - lo)), lo, hi))
            kw[name] = v
        return TerrainGenome(**kw)

    # ------------------------------------------------------------------ boxes
    def terrain(self, shape: Sequence[int]) -> Terrain:
        """The obstacle course around a robot grid of ``shape`` (its corner at the origin).

        Parameters
        ----------
        shape : (nx, ny, nz)
            The robot grid; the rings are centred on its footprint.

        Returns
        -------
        Terrain
            Named ``"poet"``; ``meta`` holds the genome (``meta["genome"]``).
        """
        nx, ny = int(shape[0]), int(shape[1])
        c = (nx / 2.0, ny / 2.0)
        h = max(nx, ny) / 2.0
        boxes: list[Box] = []
        r = h + START_MARGIN  # half side of the next ring's inner face
        if self.fence_height >= MIN_FEATURE:
            boxes += _ring(c, r, 1.0, self.fence_height)
        r += 1.0
        if self.rough_amplitude >= MIN_FEATURE:
            boxes += _bumps(c, r, ROUGH_WIDTH, self.rough_cell, self.rough_amplitude, self.seed)
        r += ROUGH_WIDTH
        if self.stair_height >= MIN_FEATURE and self.stair_count > 0:
            for i in range(self.stair_count):
                boxes += _ring(c, r, STEP_WIDTH, (i + 1) * self.stair_height)
                r += STEP_WIDTH
            if self.gap_width >= MIN_FEATURE:
                r += self.gap_width
                boxes += _ring(c, r, LANDING_WIDTH, self.stair_count * self.stair_height)
        return Terrain(
            tuple(boxes), True, "poet", {"builder": "terrain_genome", "genome": self.to_dict()}
        )

    # ------------------------------------------------------------------ JSON
    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict (with a schema tag)."""
        return {"schema": SCHEMA, **{n: getattr(self, n) for n in TERRAIN_GENES}}

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> TerrainGenome:
        """Inverse of :meth:`to_dict` (the schema tag is optional; unknown keys are refused)."""
        if not isinstance(data, Mapping):
            raise InvalidTerrainError(
                f"a terrain genome is a JSON object, got {type(data).__name__}"
            )
        kw = {k: v for k, v in data.items() if k != "schema"}
        unknown = sorted(set(map(str, kw)) - set(TERRAIN_GENES))
        if unknown:
            raise InvalidTerrainError(
                f"unknown terrain genome field(s) {unknown}; expected {list(TERRAIN_GENES)}"
            )
        return cls(**kw)

    def describe(self) -> str:
        """A short label for figures, e.g. ``"fence 0.5, 2 steps x 0.3, gap 1.0"``."""
        parts = []
        if self.fence_height >= MIN_FEATURE:
            parts.append(f"fence {self.fence_height:.2f}")
        if self.rough_amplitude >= MIN_FEATURE:
            parts.append(f"bumps {self.rough_amplitude:.2f}/{self.rough_cell:.1f}")
        if self.stair_height >= MIN_FEATURE and self.stair_count > 0:
            parts.append(f"{self.stair_count} steps x {self.stair_height:.2f}")
            if self.gap_width >= MIN_FEATURE:
                parts.append(f"gap {self.gap_width:.2f}")
        return ", ".join(parts) or "flat"


def _ring(center: tuple[float, float], a: float, width: float, height: float) -> list[Box]:
    """A square ring of four non-overlapping boxes: inner half side ``a``, ``width`` wide."""
    cx, cy = center
    b = a + width
    return [
        Box((cx - b, cy - b, 0.0), (cx + b, cy - a, height)),  # south, full width
        Box((cx - b, cy + a, 0.0), (cx + b, cy + b, height)),  # north, full width
        Box((cx - b, cy - a, 0.0), (cx - a, cy + a, height)),  # west
        Box((cx + a, cy - a, 0.0), (cx + b, cy + a, height)),  # east
    ]


def _bumps(
    center: tuple[float, float], a: float, width: float, cell: float, amplitude: float, seed: int
) -> list[Box]:
    """The ring of :func:`_ring` tiled into cells of about ``cell`` a side, heights U(0, amplitude)."""
    rng = np.random.default_rng(int(seed))
    out: list[Box] = []
    for strip in _ring(center, a, width, 1.0):
        (x0, y0, _), (x1, y1, _) = strip.lo, strip.hi
        nx = max(1, round((x1 - x0) / cell))
        ny = max(1, round((y1 - y0) / cell))
        xs = np.linspace(x0, x1, nx + 1)
        ys = np.linspace(y0, y1, ny + 1)
        heights = amplitude * rng.random((nx, ny))
        for i in range(nx):
            for j in range(ny):
                if heights[i, j] >= MIN_FEATURE:
                    out.append(
                        Box((xs[i], ys[j], 0.0), (xs[i + 1], ys[j + 1], float(heights[i, j])))
                    )
    return out
