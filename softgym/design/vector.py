"""A fixed-length real vector encoding of designs, for any black-box optimiser.

CMA-ES, Nevergrad, evosax or scipy want a vector of floats within bounds;
:class:`DesignVector` maps one to a :class:`~softgym.design.RobotDesign` and back::

    enc = DesignVector(shape=(6, 6, 6))
    x = enc.random(rng=0)                 # ndarray (enc.size,) within [enc.lower, enc.upper]
    design = enc.decode(x)                # a RobotDesign: body + controller
    softgym.evaluate([enc.decode(x) for x in X], task="flat")

Genes, all in [0, 1] (one scale, so a single step size fits every gene):

* one per grid cell, in the grid's C order (``grid.ravel()``); the cell gets ``materials[floor(g * len(materials))]``
  (default ``(0, 1, 2, 3, 4)``: empty, soft tissue, bone, the two muscles);
* then, with ``controller=True``, ``temp_amplitude``, ``period`` and
  ``muscle_cte``, mapped linearly onto the seed's bounds
  (:data:`~softgym.design.CONTROLLER_BOUNDS`: 1-20 degC, 0.01-0.75 s, 0.001-0.04 1/degC).

Decoding keeps the largest 6-connected body (as the seed does with its CPPN
output); a vector with no filled cell decodes to one soft-tissue voxel at the
cell of its largest gene, so every vector is a valid robot. The seed's
composition rules are not imposed: check them with ``design.validate(rules)``
or score a violation in your objective.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from softgym.design.controller import CONTROLLER_BOUNDS, Controller
from softgym.design.material import default_palette
from softgym.design.robot import RobotDesign, check_grid_shape, largest_component_mask
from softgym.exceptions import InvalidParameterError
from softgym.validate import is_int, show

__all__ = ["CONTROLLER_GENES", "DesignVector"]

#: Controller genes at the end of the vector, in order.
CONTROLLER_GENES: tuple[str, ...] = ("temp_amplitude", "period", "muscle_cte")


class DesignVector:
    """Fixed-length vector <-> design (see the module docstring for the layout).

    Parameters
    ----------
    shape : tuple of 3 int
        Grid shape (nx, ny, nz).
    materials : sequence of int
        Material ids a cell can take, 0 for empty (default ``(0, 1, 2, 3, 4)``).
    controller : bool
        Append the three controller genes (else every design gets ``fixed_controller``).
    palette : Palette, optional
        Materials by id (default the seed's).
    fixed_controller : Controller, optional
        The controller when ``controller=False`` (default the seed's).

    Attributes
    ----------
    size : int
        Vector length: ``nx * ny * nz`` (+ 3 with ``controller``).
    lower, upper : ndarray of shape (size,), float64
        Bounds of every gene (0 and 1).
    names : list of str
        Gene names: ``"cell[i,j,k]"`` then the controller's.
    """

    def __init__(
        self,
        shape: Sequence[int] = (6, 6, 6),
        materials: Sequence[int] = (0, 1, 2, 3, 4),
        controller: bool = True,
        palette: Any = None,
        fixed_controller: Controller | None = None,
    ) -> None:
        if not isinstance(shape, (list, tuple, np.ndarray)):
            raise InvalidParameterError(f"shape must be 3 integers (nx, ny, nz), got {show(shape)}")
        self.shape = check_grid_shape(tuple(shape), "shape")
        if not isinstance(materials, (list, tuple, np.ndarray)) or not all(
            is_int(m) and 0 <= m <= 127 for m in materials
        ):
            raise InvalidParameterError(
                f"materials must be a list of material ids (integers in 0..127), got {show(materials)}"
            )
        self.materials = np.asarray(list(materials), dtype=np.int8)
        self.palette = default_palette() if palette is None else palette
        if not isinstance(self.palette, Mapping):
            raise InvalidParameterError(
                f"palette must map material ids to Materials (default_palette()), got {show(palette)}"
            )
        if self.materials.size < 2 or len(set(self.materials.tolist())) != self.materials.size:
            raise InvalidParameterError(
                f"materials must list at least two distinct ids, got {list(materials)}"
            )
        missing = [int(m) for m in self.materials if m != 0 and int(m) not in self.palette]
        if missing:
            raise InvalidParameterError(f"materials {missing} are not in the palette")
        if not isinstance(controller, (bool, np.bool_)):
            raise InvalidParameterError(f"controller must be True or False, got {show(controller)}")
        if fixed_controller is not None and not isinstance(fixed_controller, Controller):
            raise InvalidParameterError(
                f"fixed_controller must be a Controller or None, got {show(fixed_controller)}"
            )
        self.controller = bool(controller)
        self.fixed_controller = fixed_controller or Controller()
        self.n_cells = int(np.prod(self.shape))
        self.size = self.n_cells + (len(CONTROLLER_GENES) if self.controller else 0)
        self.lower = np.zeros(self.size)
        self.upper = np.ones(self.size)

    def __repr__(self) -> str:
        return (
            f"DesignVector(shape={self.shape}, materials={self.materials.tolist()}, "
            f"controller={self.controller}, size={self.size})"
        )

    @property
    def names(self) -> list[str]:
        """Gene names: ``cell[i,j,k]`` in the grid's C order, then the controller genes."""
        cells = [f"cell[{i},{j},{k}]" for i, j, k in np.ndindex(*self.shape)]
        return cells + (list(CONTROLLER_GENES) if self.controller else [])

    def _check(self, x: Any) -> np.ndarray:
        try:
            v = np.asarray(x, dtype=np.float64)
        except (TypeError, ValueError) as exc:
            raise InvalidParameterError(f"expected a vector of numbers, got {show(x)} ({exc!s:.80})") from None
        if v.shape != (self.size,):
            raise InvalidParameterError(f"expected a vector of shape ({self.size},), got {v.shape}")
        if not np.isfinite(v).all():
            raise InvalidParameterError("the vector holds NaN or infinite values")
        return np.clip(v, 0.0, 1.0)

    def decode(self, x: Any) -> RobotDesign:
        """The design of a vector (values outside [0, 1] are clipped).

        Parameters
        ----------
        x : array_like of shape (size,), float

        Returns
        -------
        RobotDesign
            The largest 6-connected body of the decoded grid, with the decoded
            (or the fixed) controller.
        """
        v = self._check(x)
        cells = v[: self.n_cells]
        n = self.materials.size
        idx = np.minimum((cells * n).astype(np.int64), n - 1)
        grid = self.materials[idx].reshape(self.shape)
        filled = grid != 0
        if filled.any():
            grid = np.where(largest_component_mask(filled), grid, 0).astype(np.int8)
        else:
            grid = np.zeros(self.shape, dtype=np.int8)
            grid.flat[int(np.argmax(cells))] = 1
        ctrl = self.fixed_controller
        if self.controller:
            g = v[self.n_cells :]
            lo = np.array([CONTROLLER_BOUNDS[k][0] for k in CONTROLLER_GENES])
            hi = np.array([CONTROLLER_BOUNDS[k][1] for k in CONTROLLER_GENES])
            vals = lo + g * (hi - lo)
            ctrl = Controller(**{k: float(val) for k, val in zip(CONTROLLER_GENES, vals)})
        return RobotDesign(grid, palette=self.palette, controller=ctrl)

    def encode(self, design: RobotDesign) -> np.ndarray:
        """A vector that decodes to ``design`` (cells at the middle of their material's bin).

        Raises
        ------
        InvalidParameterError
            If the design's shape differs or it uses a material not in ``materials``.
        """
        if not isinstance(design, RobotDesign):
            raise InvalidParameterError(f"expected a RobotDesign, got {show(design)}")
        grid = np.asarray(design.grid)
        if grid.shape != self.shape:
            raise InvalidParameterError(f"design shape {grid.shape} != encoding shape {self.shape}")
        lookup = {int(m): k for k, m in enumerate(self.materials)}
        unknown = sorted({int(m) for m in np.unique(grid)} - set(lookup))
        if unknown:
            raise InvalidParameterError(
                f"design uses materials {unknown} outside {self.materials.tolist()}"
            )
        n = self.materials.size
        bins = np.vectorize(lookup.__getitem__, otypes=[np.float64])(grid.ravel())
        x = np.empty(self.size)
        x[: self.n_cells] = (bins + 0.5) / n
        if self.controller:
            c = design.controller
            for k, name in enumerate(CONTROLLER_GENES):
                lo, hi, _ = CONTROLLER_BOUNDS[name]
                x[self.n_cells + k] = np.clip((getattr(c, name) - lo) / (hi - lo), 0.0, 1.0)
        return x

    def random(self, rng: np.random.Generator | int | None = None) -> np.ndarray:
        """A uniform random vector within the bounds, ndarray of shape (size,)."""
        rng = rng if isinstance(rng, np.random.Generator) else np.random.default_rng(rng)
        return rng.uniform(self.lower, self.upper)
