"""`RobotDesign`: a voxel grid, its palette and its controller.

A design is plain, immutable data. Its grid holds material ids: 0 is empty
and ``k >= 1`` is ``palette[k]``; ids are the seed's (see
:mod:`softgym.design.material`), so the seed's CPPN trees (ids 1-4, 6-9) and
``.vxa`` files carry over. ``grid[i, j, k]`` is the voxel at lattice index
x = i, y = j, z = k (z up).

The controller is the single source of the muscle CTE: a design's palette
entries 3 (Active_+) and 4 (Active_-) always carry ``+controller.muscle_cte``
and ``-controller.muscle_cte`` (set on construction), as in the seed's
controller evolution (the seed study).
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, fields
from functools import lru_cache
from numbers import Real
from typing import TYPE_CHECKING, Any

import numpy as np

from softgym.design.brain import Brain
from softgym.design.controller import Controller
from softgym.design.material import (
    BONE_IDS,
    MAX_MATERIAL_ID,
    MUSCLE_IDS,
    TISSUE_IDS,
    Palette,
    default_palette,
)
from softgym.exceptions import (
    CheckpointError,
    DesignFileError,
    InvalidDesignError,
    InvalidParameterError,
    SoftGymError,
)
from softgym.io import atomic_write_text, read_capped
from softgym.validate import is_int, show

if TYPE_CHECKING:  # importing softgym.engine.* runs softgym/engine/__init__ (compiled code)
    from softgym.engine.body import Body

__all__ = [
    "DESIGN_SCHEMA",
    "DESIGN_VERSION",
    "MAX_DESIGN_JSON_BYTES",
    "MAX_GRID_DIM",
    "MAX_GRID_VOXELS",
    "CompositionRules",
    "RobotDesign",
    "check_grid_shape",
    "default_walker",
    "label_components",
    "largest_component_mask",
]

#: ``"schema"`` field of a design file.
DESIGN_SCHEMA = "softgym.design"
#: Newest design-file version this softgym writes and reads.
DESIGN_VERSION = 1

#: Largest side (cells) of a design grid along any axis.
MAX_GRID_DIM = 1000
#: Largest number of cells (nx * ny * nz) of a design grid: shapes are checked against it
#: before anything is allocated (the engine holds ~1 KiB of state per voxel).
MAX_GRID_VOXELS = 1_000_000
#: Largest design JSON text (bytes) :meth:`RobotDesign.from_json` and :meth:`RobotDesign.load`
#: read: a grid of MAX_GRID_VOXELS cells in the "ints" encoding fits.
MAX_DESIGN_JSON_BYTES = 32 * 2**20

# Migrations from version v to v + 1, applied in order on load: {v: callable(dict) -> dict}.
_MIGRATIONS: dict[int, Any] = {}


# --------------------------------------------------------------------------------------------
# Grid shapes
# --------------------------------------------------------------------------------------------


def check_grid_shape(shape: Any, name: str = "grid shape") -> tuple[int, int, int]:
    """Validate a grid shape before anything of that shape is allocated.

    Parameters
    ----------
    shape : sequence of 3 ints
        (nx, ny, nz). Integers only: ``6.5``, ``True`` and ``"6"`` are refused,
        not rounded or coerced.
    name : str
        What the shape is, for the error message (``"grid_shape"``, ``"<X_Voxels>"``...).

    Returns
    -------
    tuple of 3 int

    Raises
    ------
    InvalidDesignError
        Unless every side is an integer in 1..:data:`MAX_GRID_DIM` and the
        product is at most :data:`MAX_GRID_VOXELS`.
    """
    if isinstance(shape, (str, bytes)) or not isinstance(shape, (Sequence, np.ndarray)):
        raise InvalidDesignError(f"{name} must be 3 integers (nx, ny, nz), got {show(shape)}")
    dims = list(shape)
    if len(dims) != 3 or not all(is_int(v) for v in dims):
        raise InvalidDesignError(f"{name} must be 3 integers (nx, ny, nz), got {show(shape)}")
    dims = [int(v) for v in dims]
    if not all(1 <= v <= MAX_GRID_DIM for v in dims):
        raise InvalidDesignError(
            f"{name} {show(tuple(dims))}: each side must lie in 1..{MAX_GRID_DIM} cells"
        )
    if dims[0] * dims[1] * dims[2] > MAX_GRID_VOXELS:
        raise InvalidDesignError(
            f"{name} {tuple(dims)} has {dims[0] * dims[1] * dims[2]} cells, "
            f"more than the cap of {MAX_GRID_VOXELS}"
        )
    return dims[0], dims[1], dims[2]


# --------------------------------------------------------------------------------------------
# Connectivity
# --------------------------------------------------------------------------------------------


#: Grids of at most this many cells are labelled by walking a cached neighbour table
#: (fastest for the seed's 6x6x6); larger ones by a vectorised union-find.
_SMALL_GRID = 4096


@lru_cache(maxsize=32)
def _neighbour_table(shape: tuple[int, int, int]) -> tuple[tuple[int, ...], ...]:
    """Face neighbours of each flat (C-order) index of a grid of ``shape``."""
    nx, ny, nz = shape
    idx = np.arange(nx * ny * nz).reshape(shape)
    table: list[list[int]] = [[] for _ in range(idx.size)]
    for axis in range(3):
        a = np.moveaxis(idx, axis, 0)
        lo = a[:-1].ravel()
        hi = a[1:].ravel()
        for p, q in zip(lo.tolist(), hi.tolist()):
            table[p].append(q)
            table[q].append(p)
    return tuple(tuple(sorted(t)) for t in table)


def label_components(mask: np.ndarray) -> tuple[np.ndarray, list[int]]:
    """Label the 6-connected components of a boolean voxel mask.

    Components are numbered 1, 2, ... in the order of their first voxel in
    C order (x slowest, z fastest), the order the seed scans the grid in.

    Parameters
    ----------
    mask : ndarray of shape (nx, ny, nz), bool
        Filled voxels.

    Returns
    -------
    labels : ndarray of shape (nx, ny, nz), int32
        0 for empty voxels, component number otherwise.
    sizes : list of int
        ``sizes[c - 1]`` is the number of voxels of component ``c``.
    """
    try:
        mask = np.asarray(mask, dtype=bool)
    except (TypeError, ValueError) as exc:
        raise InvalidDesignError(f"mask is not a 3-D boolean array: {exc}") from None
    if mask.ndim != 3:
        raise InvalidDesignError(f"mask must be 3-D, got shape {mask.shape}")
    if mask.size > _SMALL_GRID:
        # large grids: vectorised union-find, no per-shape table (same labels)
        check_grid_shape(mask.shape, "mask shape")
        return _label_components_union_find(mask)
    table = _neighbour_table(mask.shape)
    flat = mask.ravel().tolist()
    labels = [0] * len(flat)
    sizes: list[int] = []
    for start in np.flatnonzero(mask).tolist():
        if labels[start]:
            continue
        c = len(sizes) + 1
        labels[start] = c
        stack = [start]
        n = 0
        while stack:
            p = stack.pop()
            n += 1
            for q in table[p]:
                if flat[q] and not labels[q]:
                    labels[q] = c
                    stack.append(q)
        sizes.append(n)
    return np.asarray(labels, dtype=np.int32).reshape(mask.shape), sizes


def _label_components_union_find(mask: np.ndarray) -> tuple[np.ndarray, list[int]]:
    """:func:`label_components` by union-find over face-adjacent pairs, in numpy.

    Roots hook to the smaller flat index, so each component's root is its first
    voxel in C order and numbering roots in order gives the same labels as the
    table walk. Memory is O(n_voxels); no Python object per voxel.
    """
    shape = mask.shape
    n = mask.size
    idx = np.arange(n, dtype=np.intp).reshape(shape)
    ps, qs = [], []
    for axis in range(3):
        a = np.moveaxis(idx, axis, 0)
        m = np.moveaxis(mask, axis, 0)
        both = m[:-1] & m[1:]
        ps.append(a[:-1][both])
        qs.append(a[1:][both])
    p = np.concatenate(ps)
    q = np.concatenate(qs)
    parent = np.arange(n, dtype=np.intp)
    while True:
        rp, rq = parent[p], parent[q]
        diff = rp != rq
        if not diff.any():
            break
        np.minimum.at(parent, np.maximum(rp, rq)[diff], np.minimum(rp, rq)[diff])
        while True:  # pointer jumping until every voxel points at its root
            nxt = parent[parent]
            if np.array_equal(nxt, parent):
                break
            parent = nxt
    flat = mask.ravel()
    _, inverse, counts = np.unique(parent[flat], return_inverse=True, return_counts=True)
    labels = np.zeros(n, dtype=np.int32)
    labels[flat] = inverse.astype(np.int32) + 1
    return labels.reshape(shape), [int(c) for c in counts]


def largest_component_mask(mask: np.ndarray) -> np.ndarray:
    """Keep the largest 6-connected component of ``mask``, as the seed does.

    Ties go to the component whose first voxel comes first in C order
    (x slowest), the seed's ``make_one_shape_only`` rule.

    Parameters
    ----------
    mask : ndarray of shape (nx, ny, nz), bool

    Returns
    -------
    ndarray of shape (nx, ny, nz), bool
        All False if ``mask`` is empty.
    """
    labels, sizes = label_components(mask)
    if not sizes:
        return np.zeros(labels.shape, dtype=bool)
    best = int(np.argmax(sizes)) + 1  # argmax returns the first maximum
    return labels == best


# --------------------------------------------------------------------------------------------
# Composition rules
# --------------------------------------------------------------------------------------------


def _at_least(fraction: float, total: int) -> int:
    """Smallest integer count that is >= ``fraction * total`` (robust to float rounding)."""
    return max(0, math.ceil(fraction * total - 1e-9))


@dataclass(frozen=True)
class CompositionRules:
    """Validity rules of a design (docs/PHYSICS.md).

    A design always needs at least one voxel. The default instance checks
    only that and 6-connectivity; use :meth:`seed` or :meth:`obstacles` for
    the seed's rules. Fractions compare counts as ``count >= ceil(fraction * total)``.

    Parameters
    ----------
    min_filled_fraction : float
        Filled voxels as a fraction of the grid's volume (seed: 0.3).
    min_muscle_fraction_of_grid : float
        Muscle voxels as a fraction of the grid's volume (seed: 0.1).
    min_muscle_fraction_of_filled : float
        Muscle voxels as a fraction of the filled voxels (obstacles: 0.1).
    min_tissue_fraction_of_filled : float
        Passive tissue voxels as a fraction of the filled voxels (obstacles: 0.1).
    min_bone_voxels : int
        Minimum number of bone voxels (obstacles: 1).
    require_connected : bool
        Whether all filled voxels must form one 6-connected body.
    muscle_ids, tissue_ids, bone_ids : tuple of int
        Material ids counted as muscle, tissue and bone.
    """

    min_filled_fraction: float = 0.0
    min_muscle_fraction_of_grid: float = 0.0
    min_muscle_fraction_of_filled: float = 0.0
    min_tissue_fraction_of_filled: float = 0.0
    min_bone_voxels: int = 0
    require_connected: bool = True
    muscle_ids: tuple[int, ...] = MUSCLE_IDS
    tissue_ids: tuple[int, ...] = TISSUE_IDS
    bone_ids: tuple[int, ...] = BONE_IDS

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            if "fraction" in f.name:
                if isinstance(value, (bool, str)) or not isinstance(value, Real):
                    raise InvalidParameterError(
                        f"composition rule {f.name} must be a number in [0, 1], got {value!r}"
                    )
                if not 0.0 <= float(value) <= 1.0:
                    raise InvalidParameterError(
                        f"composition rule {f.name} must lie in [0, 1], got {value!r}"
                    )
                object.__setattr__(self, f.name, float(value))
            elif f.name == "min_bone_voxels":
                if not is_int(value) or not 0 <= value <= MAX_GRID_VOXELS:
                    raise InvalidParameterError(
                        f"composition rule min_bone_voxels must be an integer in "
                        f"0..{MAX_GRID_VOXELS}, got {value!r}"
                    )
                object.__setattr__(self, f.name, int(value))
            elif f.name == "require_connected":
                if not isinstance(value, (bool, np.bool_)):
                    raise InvalidParameterError(
                        f"composition rule require_connected must be a bool, got {value!r}"
                    )
                object.__setattr__(self, f.name, bool(value))
            else:  # muscle_ids, tissue_ids, bone_ids
                if isinstance(value, (str, bytes)) or not isinstance(value, (Sequence, np.ndarray)):
                    raise InvalidParameterError(
                        f"composition rule {f.name} must be a sequence of material ids, got {value!r}"
                    )
                ids = tuple(value)
                if not all(is_int(v) and 1 <= v <= MAX_MATERIAL_ID for v in ids):
                    raise InvalidParameterError(
                        f"composition rule {f.name} must hold material ids in 1..{MAX_MATERIAL_ID}, "
                        f"got {value!r}"
                    )
                object.__setattr__(self, f.name, tuple(int(v) for v in ids))

    @classmethod
    def seed(cls) -> CompositionRules:
        """Evosoro's default (§2.8, §3.1): >= 30 % of the grid filled, >= 10 % of the grid muscle."""
        return cls(min_filled_fraction=0.3, min_muscle_fraction_of_grid=0.1)

    @classmethod
    def obstacles(cls) -> CompositionRules:
        """The obstacle experiment's rules (§3.7).

        >= 30 % of the grid filled; tissue >= 10 % of the filled voxels;
        >= 1 bone voxel; muscle >= 10 % of the filled voxels.
        """
        return cls(
            min_filled_fraction=0.3,
            min_tissue_fraction_of_filled=0.1,
            min_bone_voxels=1,
            min_muscle_fraction_of_filled=0.1,
        )

    def violations(self, grid: np.ndarray) -> list[str]:
        """Human-readable list of the rules ``grid`` breaks (empty if valid).

        Parameters
        ----------
        grid : ndarray of shape (nx, ny, nz), integer
            Material ids, 0 = empty.
        """
        grid = np.asarray(grid)
        total = int(grid.size)
        filled = int(np.count_nonzero(grid))
        if filled == 0:
            return ["non_empty: the design has no filled voxel"]
        out = []
        if self.require_connected:
            _, sizes = label_components(grid != 0)
            if len(sizes) > 1:
                out.append(
                    f"connected: the voxels form {len(sizes)} separate 6-connected bodies "
                    f"(sizes {sorted(sizes, reverse=True)}); use largest_component()"
                )
        hist = np.bincount(grid.ravel().astype(np.intp), minlength=MAX_MATERIAL_ID + 1)
        n_muscle = int(hist[list(self.muscle_ids)].sum())
        n_tissue = int(hist[list(self.tissue_ids)].sum())
        n_bone = int(hist[list(self.bone_ids)].sum())
        checks = [
            (
                "min_filled_fraction",
                "filled voxels",
                filled,
                self.min_filled_fraction,
                total,
                "the grid",
            ),
            (
                "min_muscle_fraction_of_grid",
                "muscle voxels",
                n_muscle,
                self.min_muscle_fraction_of_grid,
                total,
                "the grid",
            ),
            (
                "min_muscle_fraction_of_filled",
                "muscle voxels",
                n_muscle,
                self.min_muscle_fraction_of_filled,
                filled,
                "the filled voxels",
            ),
            (
                "min_tissue_fraction_of_filled",
                "tissue voxels",
                n_tissue,
                self.min_tissue_fraction_of_filled,
                filled,
                "the filled voxels",
            ),
        ]
        for rule, what, count, frac, base, base_name in checks:
            need = _at_least(frac, base)
            if count < need:
                out.append(
                    f"{rule}: {count} {what} of {base} ({100.0 * count / base:.1f} %), "
                    f"needs >= {100.0 * frac:g} % of {base_name} ({need})"
                )
        if n_bone < self.min_bone_voxels:
            out.append(f"min_bone_voxels: {n_bone} bone voxels, needs >= {self.min_bone_voxels}")
        return out

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict."""
        out: dict[str, Any] = {}
        for f in fields(self):
            v = getattr(self, f.name)
            out[f.name] = list(v) if isinstance(v, tuple) else v
        return out

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> CompositionRules:
        """Inverse of :meth:`to_dict`; unknown keys raise :class:`InvalidParameterError`."""
        if not isinstance(data, Mapping):
            raise InvalidParameterError(
                f"composition rules must be an object, got {type(data).__name__}"
            )
        unknown = set(data) - {f.name for f in fields(cls)}
        if unknown:
            raise InvalidParameterError(f"unknown composition rule(s) {sorted(map(str, unknown))}")
        kw = {k: tuple(v) if isinstance(v, list) else v for k, v in data.items()}
        return cls(**kw)


# --------------------------------------------------------------------------------------------
# Grid <-> JSON
# --------------------------------------------------------------------------------------------


def _grid_to_json(grid: np.ndarray) -> dict[str, Any]:
    nx, ny, nz = grid.shape
    digits = int(grid.max(initial=0)) <= 9
    layers = []
    for z in range(nz):
        rows = []
        for y in range(ny):
            row = grid[:, y, z].tolist()
            rows.append("".join(str(v) for v in row) if digits else row)
        layers.append(rows)
    return {
        "shape": [nx, ny, nz],
        "layout": "layers[z][y][x]",
        "encoding": "digits" if digits else "ints",
        "layers": layers,
    }


def _grid_from_json(data: Any) -> np.ndarray:
    if not isinstance(data, Mapping):
        raise InvalidDesignError("design 'grid' must be an object with 'shape' and 'layers'")
    if "shape" not in data or "layers" not in data:
        raise InvalidDesignError("design 'grid' needs 'shape' [nx, ny, nz] and 'layers'")
    # the shape is checked against the caps before the grid is allocated
    nx, ny, nz = check_grid_shape(data["shape"], "design 'grid' shape")
    layers = data["layers"]
    encoding = data.get("encoding", "digits")
    if encoding not in ("digits", "ints"):
        raise InvalidDesignError(
            f"unknown grid encoding {encoding!r} (expected 'digits' or 'ints')"
        )
    if not isinstance(layers, list) or len(layers) != nz:
        raise InvalidDesignError(
            f"grid has {len(layers) if isinstance(layers, list) else 'no'} layers, shape says nz = {nz}"
        )
    grid = np.zeros((nx, ny, nz), dtype=np.int8)
    for z, layer in enumerate(layers):
        if not isinstance(layer, list) or len(layer) != ny:
            raise InvalidDesignError(f"grid layer z={z} must hold {ny} rows")
        for y, row in enumerate(layer):
            if encoding == "digits":
                if (
                    not isinstance(row, str)
                    or len(row) != nx
                    or not row.isdigit()
                    or not row.isascii()
                ):
                    raise InvalidDesignError(
                        f"grid row z={z} y={y} must be {nx} digits, got {row!r}"[:200]
                    )
                values = [int(c) for c in row]
            else:
                if not isinstance(row, list) or len(row) != nx:
                    raise InvalidDesignError(f"grid row z={z} y={y} must be a list of {nx} ints")
                # JSON ints only: 1.7, true and "1" are refused, not truncated or coerced
                for x, v in enumerate(row):
                    if type(v) is not int or not 0 <= v <= MAX_MATERIAL_ID:
                        raise InvalidDesignError(
                            f"grid cell x={x} y={y} z={z} must be an integer material id in "
                            f"0..{MAX_MATERIAL_ID}, got {v!r}"[:200]
                        )
                values = row
            grid[:, y, z] = values
    return grid


# --------------------------------------------------------------------------------------------
# RobotDesign
# --------------------------------------------------------------------------------------------


def _sync_muscles(palette: Palette, controller: Controller) -> Palette:
    plus, minus = Controller.MUSCLE_PAIR
    for mid, sign in ((plus, 1.0), (minus, -1.0)):
        if mid in palette and palette[mid].cte != sign * controller.muscle_cte:
            palette = palette.with_changes(mid, cte=sign * controller.muscle_cte)
    return palette


@dataclass(frozen=True, eq=False)
class RobotDesign:
    """A robot: voxel grid + material palette + controller.

    Parameters
    ----------
    grid : array_like of shape (nx, ny, nz), integer
        Material ids, 0 = empty, ``k`` = ``palette[k]``. Stored as a
        read-only C-contiguous int8 array.
    palette : Palette, optional
        Materials by id (default: :func:`~softgym.design.material.default_palette`).
    controller : Controller, optional
        The sinusoidal drive (default: the seed's). Its ``muscle_cte`` is
        written into palette entries 3 and 4 (``+`` and ``-``) on construction.
    brain : Brain, optional
        A closed-loop network controller (:mod:`softgym.design.brain`): when
        set, it drives the muscles from the robot's senses instead of the
        sinusoid (whose amplitude, muscle CTE and period still scale its
        outputs and set its clock). None (the default): the seed's open loop.

    Raises
    ------
    InvalidDesignError
        If the grid is not 3-D integer data with ids in 0..127, or holds an
        id the palette lacks. Composition rules are checked by :meth:`validate`.
    """

    grid: np.ndarray
    palette: Palette = field(default_factory=default_palette)
    controller: Controller = field(default_factory=Controller)
    brain: Brain | None = None

    def __post_init__(self) -> None:
        try:
            raw = np.asarray(self.grid)
        except (TypeError, ValueError, OverflowError) as exc:  # ragged nesting, odd objects
            raise InvalidDesignError(f"grid is not a 3-D array of material ids: {exc}") from None
        if raw.ndim != 3:
            raise InvalidDesignError(f"grid must be 3-D (nx, ny, nz), got shape {raw.shape}")
        if min(raw.shape) < 1:
            raise InvalidDesignError(f"grid has an empty dimension: shape {raw.shape}")
        check_grid_shape(raw.shape, "grid shape")
        if raw.dtype == bool or not np.issubdtype(raw.dtype, np.integer):
            raise InvalidDesignError(f"grid must hold integer material ids, got dtype {raw.dtype}")
        if raw.min() < 0 or raw.max() > MAX_MATERIAL_ID:
            raise InvalidDesignError(
                f"grid ids must lie in 0..{MAX_MATERIAL_ID}, got range [{raw.min()}, {raw.max()}]"
            )
        if not isinstance(self.palette, Palette):
            raise InvalidDesignError(
                f"palette must be a Palette, got {type(self.palette).__name__}"
            )
        if not isinstance(self.controller, Controller):
            raise InvalidDesignError(
                f"controller must be a Controller, got {type(self.controller).__name__}"
            )
        if self.brain is not None and not isinstance(self.brain, Brain):
            raise InvalidDesignError(f"brain must be a Brain or None, got {type(self.brain).__name__}")
        grid = np.array(raw, dtype=np.int8, order="C", copy=True)
        used = [int(v) for v in np.unique(grid) if v != 0]
        missing = [v for v in used if v not in self.palette]
        if missing:
            raise InvalidDesignError(
                f"grid uses material ids {missing} that the palette lacks (palette ids {list(self.palette)})"
            )
        grid.setflags(write=False)
        object.__setattr__(self, "grid", grid)
        object.__setattr__(self, "palette", _sync_muscles(self.palette, self.controller))

    # ---------------------------------------------------------------- basic properties

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, RobotDesign):
            return NotImplemented
        return (
            self.grid.shape == other.grid.shape
            and bool(np.array_equal(self.grid, other.grid))
            and self.palette == other.palette
            and self.controller == other.controller
            and self.brain == other.brain
        )

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        return (
            f"RobotDesign(shape={self.shape}, n_voxels={self.n_voxels}, "
            f"materials={self.material_counts()}, controller={self.controller}"
            + ("" if self.brain is None else f", brain={self.brain!r}")
            + ")"
        )

    @property
    def shape(self) -> tuple[int, int, int]:
        """Grid shape (nx, ny, nz)."""
        return tuple(int(s) for s in self.grid.shape)  # type: ignore[return-value]

    @property
    def n_voxels(self) -> int:
        """Number of filled voxels."""
        return int(np.count_nonzero(self.grid))

    def count(self, ids: int | Sequence[int]) -> int:
        """Number of voxels whose material id is in ``ids``."""
        ids = (ids,) if isinstance(ids, (int, np.integer)) else tuple(ids)
        return int(np.isin(self.grid, ids).sum())

    def material_counts(self) -> dict[int, int]:
        """Voxel count per material id in use, ``{id: count}``."""
        values, counts = np.unique(self.grid[self.grid != 0], return_counts=True)
        return {int(v): int(c) for v, c in zip(values, counts)}

    def replace(self, **changes: Any) -> RobotDesign:
        """Return a copy with ``grid``, ``palette``, ``controller`` and/or ``brain`` replaced."""
        kw = {"grid": self.grid, "palette": self.palette, "controller": self.controller,
              "brain": self.brain}  # fmt: skip
        unknown = set(changes) - set(kw)
        if unknown:
            raise InvalidDesignError(f"unknown RobotDesign field(s) {sorted(unknown)}")
        kw.update(changes)
        return RobotDesign(**kw)

    def with_controller(self, controller: Controller) -> RobotDesign:
        """Return a copy driven by ``controller`` (muscle CTEs updated)."""
        return self.replace(controller=controller)

    # ---------------------------------------------------------------- connectivity & validity

    def components(self) -> tuple[np.ndarray, list[int]]:
        """6-connected components of the filled voxels; see :func:`label_components`."""
        return label_components(self.grid != 0)

    def is_connected(self) -> bool:
        """Whether the filled voxels form exactly one 6-connected body."""
        return len(self.components()[1]) == 1

    def largest_component(self) -> RobotDesign:
        """Keep only the biggest 6-connected body, as the seed does (§2.4).

        Ties go to the body whose first voxel comes first in C order.
        """
        keep = largest_component_mask(self.grid != 0)
        return self.replace(grid=np.where(keep, self.grid, 0).astype(np.int8))

    def violations(self, rules: CompositionRules | None = None) -> list[str]:
        """Rules of ``rules`` (default :meth:`CompositionRules.seed`) this design breaks."""
        rules = CompositionRules.seed() if rules is None else rules
        return rules.violations(self.grid)

    def is_valid(self, rules: CompositionRules | None = None) -> bool:
        """Whether :meth:`validate` passes."""
        return not self.violations(rules)

    def validate(self, rules: CompositionRules | None = None) -> RobotDesign:
        """Check the design against ``rules``.

        Parameters
        ----------
        rules : CompositionRules, optional
            Default :meth:`CompositionRules.seed` (>= 30 % filled, >= 10 % muscle);
            ``CompositionRules()`` checks only non-empty and connected.

        Returns
        -------
        RobotDesign
            ``self``, for chaining.

        Raises
        ------
        InvalidDesignError
            Naming every rule that failed (``non_empty``, ``connected``,
            ``min_filled_fraction``, ``min_muscle_fraction_of_grid``, ...).
        """
        problems = self.violations(rules)
        if problems:
            raise InvalidDesignError("invalid design: " + "; ".join(problems))
        return self

    # ---------------------------------------------------------------- engine

    def material_table(self) -> dict[str, np.ndarray]:
        """Per-id property tables: row k = material k, row 0 (empty) and absent ids zero.

        Returns
        -------
        dict of str to ndarray of shape (max_id + 1,), float64
            Keys ``youngs_modulus`` (Pa), ``density`` (kg/m^3), ``poisson``,
            ``cte`` (1/°C), ``mu_static``, ``mu_kinetic``.
        """
        n = self.palette.max_id + 1
        names = ("youngs_modulus", "density", "poisson", "cte", "mu_static", "mu_kinetic")
        tables = {name: np.zeros(n) for name in names}
        for k, mat in self.palette.items():
            for name in names:
                tables[name][k] = getattr(mat, name)
        return tables

    def to_body(self, origin: Sequence[float] = (0.0, 0.0, 0.0)) -> Body:
        """The engine's view of this robot.

        Parameters
        ----------
        origin : sequence of 3 floats
            Position (m) of the grid's corner.

        Returns
        -------
        Body
            Material tables indexed by id (row 0 unused), ``temp_amplitude``
            and ``period`` from the controller, phase 0 for every material
            (counter-phase comes from the sign of the CTE).
        """
        from softgym.engine.body import (
            Body,
        )  # lazy: keeps softgym.design importable without the build

        tables = self.material_table()
        return Body(
            grid=self.grid.astype(np.int32),
            phase=np.zeros(self.palette.max_id + 1),
            temp_amplitude=self.controller.temp_amplitude,
            period=self.controller.period,
            origin=np.asarray(origin, dtype=np.float64),
            **tables,
        )

    # ---------------------------------------------------------------- JSON

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict with ``"schema"`` and ``"version"``."""
        return {
            "schema": DESIGN_SCHEMA,
            "version": DESIGN_VERSION,
            "grid": _grid_to_json(self.grid),
            "palette": self.palette.to_list(),
            "controller": self.controller.to_dict(),
            **({} if self.brain is None else {"brain": self.brain.to_dict()}),
        }

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> RobotDesign:
        """Build a design from :meth:`to_dict` output (any version up to :data:`DESIGN_VERSION`).

        Raises
        ------
        InvalidDesignError
            On a wrong schema, a version newer than this softgym reads, or malformed content.
        """
        if not isinstance(data, Mapping):
            raise InvalidDesignError(f"a design must be a JSON object, got {type(data).__name__}")
        schema = data.get("schema")
        if schema != DESIGN_SCHEMA:
            raise InvalidDesignError(
                f"not a softgym design: schema is {schema!r}, expected {DESIGN_SCHEMA!r}"
            )
        version = data.get("version")
        if isinstance(version, bool) or not isinstance(version, int) or version < 1:
            raise InvalidDesignError(f"design file has an invalid version {version!r}")
        if version > DESIGN_VERSION:
            raise InvalidDesignError(
                f"design file version {version} is newer than this softgym reads "
                f"(up to version {DESIGN_VERSION}); upgrade softgym"
            )
        data = dict(data)
        while version < DESIGN_VERSION:
            data = _MIGRATIONS[version](data)
            version += 1
        for key in ("grid", "palette", "controller"):
            if key not in data:
                raise InvalidDesignError(f"design file has no {key!r}")
        grid = _grid_from_json(data["grid"])
        palette = Palette.from_list(data["palette"])
        controller = Controller.from_dict(data["controller"])
        brain = None if data.get("brain") is None else Brain.from_dict(data["brain"])
        return cls(grid=grid, palette=palette, controller=controller, brain=brain)

    def to_json(self, indent: int | None = 1) -> str:
        """Serialise to a JSON string (floats written exactly, no pickle)."""
        return json.dumps(self.to_dict(), indent=indent)

    @classmethod
    def from_json(cls, text: str | bytes) -> RobotDesign:
        """Inverse of :meth:`to_json`.

        Raises
        ------
        InvalidDesignError
            If ``text`` is not str or bytes, longer than :data:`MAX_DESIGN_JSON_BYTES`,
            not UTF-8, not JSON, nested too deeply, or not a valid design.
        """
        if not isinstance(text, (str, bytes, bytearray)):
            raise InvalidDesignError(
                f"a design's JSON must be str or bytes, got {type(text).__name__}"
            )
        if len(text) > MAX_DESIGN_JSON_BYTES:
            raise InvalidDesignError(
                f"design JSON of {len(text)} characters is larger than the cap of "
                f"{MAX_DESIGN_JSON_BYTES} bytes"
            )
        try:
            if not isinstance(text, str):
                text = bytes(text).decode("utf-8")
            data = json.loads(text)
        except UnicodeDecodeError as exc:
            raise InvalidDesignError(f"design file is not UTF-8 text: {exc}") from None
        except json.JSONDecodeError as exc:
            raise InvalidDesignError(f"design file is not valid JSON: {exc}") from None
        except ValueError as exc:  # e.g. an integer of more than 4300 digits
            raise InvalidDesignError(f"design file holds an invalid JSON value: {exc}") from None
        except RecursionError:
            raise InvalidDesignError("design file is nested too deeply to be a design") from None
        return cls.from_dict(data)

    def save(self, path: str | os.PathLike[str]) -> None:
        """Write the design to ``path`` as JSON (via a temporary file, then rename)."""
        try:
            atomic_write_text(path, self.to_json() + "\n")
        except CheckpointError as exc:
            raise DesignFileError(f"design file {os.fspath(path)!r}: {exc}") from None

    @classmethod
    def load(cls, path: str | os.PathLike[str]) -> RobotDesign:
        """Read a design written by :meth:`save`.

        Raises
        ------
        DesignFileError
            Naming the file, if it is missing, a folder, unreadable, larger than
            :data:`MAX_DESIGN_JSON_BYTES` or not UTF-8 text (also an ``OSError``),
            or if ``path`` is not a path at all (an int...).
        InvalidDesignError
            Naming the file, if its content is not a valid design.
        """
        if not isinstance(path, (str, bytes, os.PathLike)):
            raise DesignFileError(
                f"design file must be a path (str or os.PathLike), got {type(path).__name__}"
            )
        path = os.fspath(path)
        if not isinstance(path, str):  # a bytes path
            path = os.fsdecode(path)
        data = read_capped(path, MAX_DESIGN_JSON_BYTES, "design", DesignFileError)
        try:
            text = data.decode("utf-8")
        except UnicodeDecodeError:
            raise DesignFileError(f"design file {path!r} is not UTF-8 text") from None
        try:
            return cls.from_json(text)
        except SoftGymError as exc:
            raise InvalidDesignError(f"design file {path!r}: {exc}") from exc


def default_walker() -> RobotDesign:
    """A hand-made 6x6x6 robot that walks under the seed's default sinusoid.

    A full 6x6x6 block: in the lower five layers the front two x-columns
    (x < 2) are ``Active_+`` (3) and the rear four (x >= 2) ``Active_-`` (4); the top
    layer (z = 5) is ``Passive_Soft`` (1). The two muscle groups contract in
    counter-phase; the uneven 1/3 : 2/3 split breaks the front/back symmetry
    (a symmetric half/half split only rocks in place), so the block shuffles
    steadily towards -x.

    All 216 voxels are filled, 180 are muscle: it passes
    :meth:`CompositionRules.seed`. In softgym's engine with the seed's
    settings it covers about 3 voxel lengths in the seed's fitness window
    (t = 1 to 5 s), at a steady ~0.7 voxel lengths per second.

    Returns
    -------
    RobotDesign
        Default palette and controller.
    """
    grid = np.empty((6, 6, 6), dtype=np.int8)
    grid[0:2, :, :] = 3
    grid[2:6, :, :] = 4
    grid[:, :, 5] = 1
    return RobotDesign(grid)
