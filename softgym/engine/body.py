"""`Body`: the engine's plain-data view of one robot.

The engine knows nothing of palettes, genomes or controllers as objects: a
:class:`Body` is a voxel grid plus one row of physical properties per material
id, and the two numbers of the sinusoidal drive. Higher layers
(:mod:`softgym.design`) build bodies with ``RobotDesign.to_body()``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from softgym.engine.config import DENSITY_RANGE, YOUNGS_MODULUS_RANGE
from softgym.exceptions import InvalidDesignError, InvalidParameterError
from softgym.validate import number, show

__all__ = ["Body"]


def _as_table(name: str, values, n: int) -> np.ndarray:
    try:
        arr = np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError, OverflowError):
        raise InvalidParameterError(
            f"{name} must be numbers, one per material id (length {n}), got {show(values)}"
        ) from None
    if arr.ndim != 1 or arr.shape[0] != n:
        raise InvalidParameterError(
            f"{name} must be a 1-D array with one entry per material id (length {n}), "
            f"got shape {arr.shape}"
        )
    return np.ascontiguousarray(arr)


@dataclass(frozen=True, eq=False)
class Body:
    """One robot as the engine sees it.

    Parameters
    ----------
    grid : ndarray of shape (nx, ny, nz), integer dtype
        0 = empty, k >= 1 = material id k (a row of the material tables).
        Voxel (i, j, k) has its nominal centre at
        ``origin + ((i + 0.5) L, (j + 0.5) L, (k + 0.5) L)``.
    youngs_modulus : ndarray of shape (n_materials,), float64
        Young's modulus (Pa) per material id; row 0 (empty) is ignored.
    density : ndarray of shape (n_materials,), float64
        Density (kg/m^3) per material id.
    poisson : ndarray of shape (n_materials,), float64
        Poisson's ratio per material id, in [0, 0.5).
    cte : ndarray of shape (n_materials,), float64
        Coefficient of thermal expansion (1/degC) per material id.
    mu_static, mu_kinetic : ndarray of shape (n_materials,), float64
        Coulomb friction coefficients per material id (>= 0).
    phase : ndarray of shape (n_materials,), float64, optional
        Phase offset (rad) of the temperature signal per material id
        (default 0: the seed drives counter-phase muscles by the sign of CTE).
    temp_amplitude : float
        Amplitude dT (degC) of ``T(t) = dT sin(2 pi t / period + phase)``.
    period : float
        Period (s) of the temperature signal.
    fixed : ndarray of shape (nx, ny, nz), bool, optional
        Voxels whose six degrees of freedom are fixed (clamped supports).
    origin : ndarray of shape (3,), float64
        Position (m) of the grid's corner.
    """

    grid: np.ndarray
    youngs_modulus: np.ndarray
    density: np.ndarray
    poisson: np.ndarray
    cte: np.ndarray
    mu_static: np.ndarray
    mu_kinetic: np.ndarray
    phase: np.ndarray | None = None
    temp_amplitude: float = 14.0
    period: float = 0.25
    fixed: np.ndarray | None = None
    origin: np.ndarray = field(default_factory=lambda: np.zeros(3))

    def __post_init__(self) -> None:
        grid = np.asarray(self.grid)
        if grid.ndim != 3:
            raise InvalidDesignError(f"grid must be 3-D (nx, ny, nz), got shape {grid.shape}")
        if not np.issubdtype(grid.dtype, np.integer):
            raise InvalidDesignError(f"grid must have an integer dtype, got {grid.dtype}")
        if min(grid.shape) < 1:
            raise InvalidDesignError(f"grid has an empty dimension: shape {grid.shape}")
        grid = np.ascontiguousarray(grid, dtype=np.int32)
        n = len(np.asarray(self.youngs_modulus))
        if n < 2:
            raise InvalidParameterError("material tables need row 0 (empty) and at least one material")
        if grid.min() < 0 or grid.max() >= n:
            bad = sorted({int(v) for v in np.unique(grid) if v < 0 or v >= n})
            raise InvalidDesignError(
                f"grid holds unknown material ids {bad}; the tables define ids 0..{n - 1}"
            )
        if not (grid > 0).any():
            raise InvalidDesignError("empty robot: the grid has no filled voxel")
        object.__setattr__(self, "grid", grid)
        tables = {}
        for name in ("youngs_modulus", "density", "poisson", "cte", "mu_static", "mu_kinetic"):
            tables[name] = _as_table(name, getattr(self, name), n)
        phase = np.zeros(n) if self.phase is None else self.phase
        tables["phase"] = _as_table("phase", phase, n)
        used = np.unique(grid[grid > 0])
        for name, arr in tables.items():
            if not np.isfinite(arr[used]).all():
                raise InvalidParameterError(f"{name} is not finite for a material in use")
        for name, (lo, hi), unit in (("youngs_modulus", YOUNGS_MODULUS_RANGE, "Pa"),
                                     ("density", DENSITY_RANGE, "kg/m^3")):  # fmt: skip
            values = tables[name][used]
            if ((values < lo) | (values > hi)).any():
                bad = values[(values < lo) | (values > hi)][0]
                raise InvalidParameterError(
                    f"{name} must lie in [{lo:g}, {hi:g}] {unit} for every material in use, "
                    f"got {bad:g}"
                )
        nu = tables["poisson"][used]
        if ((nu < 0) | (nu >= 0.5)).any():
            raise InvalidParameterError("poisson must lie in [0, 0.5) for every material in use")
        if (tables["mu_static"][used] < 0).any() or (tables["mu_kinetic"][used] < 0).any():
            raise InvalidParameterError("friction coefficients must be >= 0")
        for name, arr in tables.items():
            object.__setattr__(self, name, arr)
        amp = float(self.temp_amplitude)
        per = float(self.period)
        if not np.isfinite(amp):
            raise InvalidParameterError(f"temp_amplitude must be finite, got {amp}")
        if not (np.isfinite(per) and per > 0):
            raise InvalidParameterError(f"period must be a finite value > 0 s, got {per}")
        object.__setattr__(self, "temp_amplitude", amp)
        object.__setattr__(self, "period", per)
        if self.fixed is not None:
            fixed = np.asarray(self.fixed, dtype=bool)
            if fixed.shape != grid.shape:
                raise InvalidDesignError(
                    f"fixed mask has shape {fixed.shape}, the grid {grid.shape}"
                )
            object.__setattr__(self, "fixed", np.ascontiguousarray(fixed))
        origin = np.asarray(self.origin, dtype=np.float64)
        if origin.shape != (3,) or not np.isfinite(origin).all():
            raise InvalidParameterError(f"origin must be 3 finite numbers, got {self.origin!r}")
        object.__setattr__(self, "origin", origin)

    @property
    def n_voxels(self) -> int:
        """Number of filled voxels."""
        return int(np.count_nonzero(self.grid))

    def replace(self, **changes) -> Body:
        """Return a copy with some fields replaced (validated again)."""
        kw = {name: getattr(self, name) for name in self.__dataclass_fields__}
        kw.update(changes)
        return Body(**kw)

    @classmethod
    def uniform(
        cls,
        grid,
        youngs_modulus: float = 5e6,
        density: float = 1e6,
        poisson: float = 0.35,
        cte: float = 0.0,
        mu_static: float = 1.0,
        mu_kinetic: float = 0.5,
        **kwargs,
    ) -> Body:
        """A body made of one material (id 1) wherever ``grid`` is non-zero."""
        g = (np.asarray(grid) != 0).astype(np.int32)

        def row(name: str, v: Any) -> np.ndarray:
            return np.array([0.0, number(name, v)])  # a number: not a bool, string or list

        return cls(
            grid=g,
            youngs_modulus=row("youngs_modulus", youngs_modulus),
            density=row("density", density),
            poisson=row("poisson", poisson),
            cte=row("cte", cte),
            mu_static=row("mu_static", mu_static),
            mu_kinetic=row("mu_kinetic", mu_kinetic),
            **kwargs,
        )
