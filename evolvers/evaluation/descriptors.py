"""Behaviour descriptors of robot bodies for quality-diversity archives.

Each descriptor maps a material grid to one number in [0, 1]:

==============  ==========================================================================
name            value
==============  ==========================================================================
``stiff``       stiff voxels (hard tissue, ids 2 and 7) / filled voxels
``filled``      filled voxels / lattice size
``muscle``      muscle voxels (ids 3, 4, 8, 9) / filled voxels
``height``      occupied z layers / nz
``elongation``  ``1 - sqrt(l2 / l1)``: ``l1 >= l2`` the two largest eigenvalues of the
                covariance of the filled voxels' centres (0: as wide as long; ~1: a rod)
==============  ==========================================================================

:data:`MOURET_CLUNE_2015` (``stiff`` x ``filled``) is the pair Mouret and Clune
used for MAP-Elites on CPPN voxel robots (*Illuminating search spaces by mapping
elites*, 2015, 128 x 128 cells). An empty grid has every descriptor 0.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from softgym.design import MUSCLE_IDS
from softgym.exceptions import InvalidParameterError

__all__ = [
    "DESCRIPTORS",
    "MOURET_CLUNE_2015",
    "STIFF_IDS",
    "check_descriptors",
    "descriptor_values",
]

#: Hard-tissue material ids (Passive_Hard and New_Passive_Hard, E 5e8 Pa).
STIFF_IDS: tuple[int, ...] = (2, 7)
#: The default descriptor pair: Mouret and Clune (2015), 128 x 128 cells.
MOURET_CLUNE_2015: tuple[str, str] = ("stiff", "filled")


def _fraction_of_filled(ids: Sequence[int]) -> Callable[[np.ndarray], float]:
    ids = np.asarray(ids)

    def f(grid: np.ndarray) -> float:
        filled = np.count_nonzero(grid)
        return float(np.isin(grid, ids).sum() / filled) if filled else 0.0

    return f


def _filled(grid: np.ndarray) -> float:
    return float(np.count_nonzero(grid) / grid.size)


def _height(grid: np.ndarray) -> float:
    layers = np.flatnonzero(grid.reshape(-1, grid.shape[2]).any(axis=0))
    return float(len(layers) / grid.shape[2])


def _elongation(grid: np.ndarray) -> float:
    pts = np.argwhere(grid != 0).astype(np.float64)
    if len(pts) < 2:
        return 0.0
    eig = np.linalg.eigvalsh(np.cov(pts, rowvar=False))  # ascending
    l1, l2 = float(eig[-1]), max(float(eig[-2]), 0.0)
    return float(min(max(1.0 - np.sqrt(l2 / l1), 0.0), 1.0)) if l1 > 0 else 0.0


#: Descriptor functions by name: ``f(grid int8 (nx, ny, nz)) -> float in [0, 1]``.
DESCRIPTORS: dict[str, Callable[[np.ndarray], float]] = {
    "stiff": _fraction_of_filled(STIFF_IDS),
    "filled": _filled,
    "muscle": _fraction_of_filled(MUSCLE_IDS),
    "height": _height,
    "elongation": _elongation,
}


def check_descriptors(names: Sequence[str]) -> tuple[str, ...]:
    """The names as a tuple, checked.

    Raises
    ------
    InvalidParameterError
        If a name is unknown, repeated, or none is given.
    """
    names = tuple(str(n) for n in names)
    unknown = [n for n in names if n not in DESCRIPTORS]
    if unknown or not names or len(set(names)) != len(names):
        raise InvalidParameterError(
            f"descriptors must be distinct names of {sorted(DESCRIPTORS)}, got {list(names)}"
        )
    return names


def descriptor_values(grids: Sequence[np.ndarray], names: Sequence[str]) -> np.ndarray:
    """Descriptors of several bodies.

    Parameters
    ----------
    grids : sequence of ndarray of shape (nx, ny, nz), int8
        Material grids (0 = empty).
    names : sequence of str
        Names of :data:`DESCRIPTORS`.

    Returns
    -------
    ndarray of shape (len(grids), len(names)), float64
        Every value in [0, 1].
    """
    fns = [DESCRIPTORS[n] for n in check_descriptors(names)]
    out = np.zeros((len(grids), len(fns)), dtype=np.float64)
    for i, grid in enumerate(grids):
        g = np.asarray(grid)
        out[i] = [f(g) for f in fns]
    return out
