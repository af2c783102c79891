"""A robot genome as one real vector: a fixed-topology CPPN, the controller genes, a brain.

CMA-ES and other continuous optimisers search a box of reals; the seed's CPPN genome grows
and rewires (NEAT-style mutation) and has no fixed length. :class:`CPPNVector` fixes the
topology and keeps the weights as genes, so a vector decodes through the project's own
genome (:meth:`softgym.design.CPPN.from_dict`, then :meth:`~softgym.design.CPPN.to_grid`:
the seed's material tree, largest body kept) into an
:class:`~evolvers.operators.genome.Individual` that every driver, the evaluator and the run
folder treat as any other::

    inputs x y z d b (5)  --->  hidden nodes, one per activation of ``hidden``
           |                          |
           +------------------------->+--->  outputs (the material tree's, sigmoid)

Every input links to every hidden node and every output; every hidden node links to every
output. The vector, in order (:attr:`CPPNVector.names`):

==========================  =====================================  =========================
genes                       count (defaults)                       bounds
==========================  =====================================  =========================
``w[src->dst]``             5 * 7 + 7 * 4 + 5 * 4 = 83 weights     ``[-weight_bound,
                                                                   weight_bound]`` ([-1, 1],
                                                                   the seed's weight range)
``temp_amplitude``,         3, with ``controller=True``            the seed's
``period``, ``muscle_cte``                                         :data:`~softgym.design.CONTROLLER_BOUNDS`
``brain[i]``                ``brain_spec.n_params``, with a        ``+-WEIGHT_BOUND``
                            ``brain_spec``
==========================  =====================================  =========================

Not every vector draws a valid body (the experiment's composition rules): an invalid one
decodes as usual and the evaluator scores it worst without simulating it, as it does any
other invalid robot. :meth:`CPPNVector.random_valid` draws uniform vectors until one is
valid (the seed's random individuals are valid too).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from evolvers.operators.genome import Individual
from softgym.design import (
    CONTROLLER_BOUNDS,
    CPPN,
    HIDDEN_ACTIVATIONS,
    INPUT_NAMES,
    MATERIAL_TREE_4,
    CompositionRules,
    Controller,
)
from softgym.design.brain import WEIGHT_BOUND, BrainSpec
from softgym.design.cppn import CPPN_SCHEMA, CPPN_VERSION
from softgym.exceptions import InvalidDesignError, InvalidParameterError
from softgym.validate import is_int, is_real, show

__all__ = ["CPPNVector"]


def _rng(rng: np.random.Generator | int | None) -> np.random.Generator:
    return rng if isinstance(rng, np.random.Generator) else np.random.default_rng(rng)


class CPPNVector:
    """Fixed-length vector <-> :class:`~evolvers.operators.genome.Individual` (module docstring).

    Parameters
    ----------
    outputs : sequence of str
        CPPN outputs (:data:`~softgym.design.MATERIAL_TREE_4` or ``_8``).
    hidden : sequence of str
        The activation of each hidden node (default: one node of each of the seed's
        :data:`~softgym.design.HIDDEN_ACTIVATIONS`, 7 nodes).
    controller : bool
        Whether the three controller genes are part of the vector (else every robot gets
        ``Controller()``, the seed's).
    brain_spec : BrainSpec, optional
        A network controller whose weights end the vector.
    weight_bound : float
        The CPPN weights lie in ``[-weight_bound, weight_bound]`` (> 0; default 1, the range
        the seed's weight mutation keeps).

    Attributes
    ----------
    size : int
        Length of the vector.
    lower, upper : ndarray of shape (size,), float64
        Bounds of every gene.
    names : list of str
        Gene names: ``"w[x->0]"``... then the controller's, then ``"brain[i]"``.
    n_weights : int
        CPPN weights at the start of the vector.

    Raises
    ------
    InvalidParameterError
        Naming the argument and its accepted values.
    """

    def __init__(
        self,
        outputs: Sequence[str] = MATERIAL_TREE_4,
        hidden: Sequence[str] = HIDDEN_ACTIVATIONS,
        controller: bool = True,
        brain_spec: BrainSpec | None = None,
        weight_bound: float = 1.0,
    ) -> None:
        try:
            CPPN(outputs)  # the outputs' own checks
        except InvalidParameterError as exc:
            raise InvalidParameterError(f"outputs: {exc}") from None
        self.outputs = tuple(outputs)
        if not isinstance(hidden, (list, tuple)) or not all(
            h in HIDDEN_ACTIVATIONS for h in hidden
        ):
            raise InvalidParameterError(
                f"hidden must be a list of activations of {list(HIDDEN_ACTIVATIONS)}, got {show(hidden)}"
            )
        if not isinstance(controller, (bool, np.bool_)):
            raise InvalidParameterError(f"controller must be True or False, got {show(controller)}")
        if brain_spec is not None and not isinstance(brain_spec, BrainSpec):
            raise InvalidParameterError(
                f"brain_spec must be a BrainSpec or None, got {show(brain_spec)}"
            )
        if not is_real(weight_bound) or not 0 < float(weight_bound) < np.inf:
            raise InvalidParameterError(
                f"weight_bound must be a finite number > 0, got {show(weight_bound)}"
            )
        self.hidden = tuple(hidden)
        self.controller = bool(controller)
        self.brain_spec = brain_spec
        self.weight_bound = float(weight_bound)
        h = list(range(len(self.hidden)))
        self._edges: list[tuple[Any, Any]] = (
            [(i, k) for i in INPUT_NAMES for k in h]
            + [(k, o) for k in h for o in self.outputs]
            + [(i, o) for i in INPUT_NAMES for o in self.outputs]
        )
        self.n_weights = len(self._edges)
        names = [f"w[{a}->{b}]" for a, b in self._edges]
        lower = [-self.weight_bound] * self.n_weights
        upper = [self.weight_bound] * self.n_weights
        if self.controller:
            for name, (lo, hi, _) in CONTROLLER_BOUNDS.items():
                names.append(name)
                lower.append(lo)
                upper.append(hi)
        self.n_brain = 0 if brain_spec is None else int(brain_spec.n_params)
        names += [f"brain[{i}]" for i in range(self.n_brain)]
        lower += [-WEIGHT_BOUND] * self.n_brain
        upper += [WEIGHT_BOUND] * self.n_brain
        self.names: list[str] = names
        self.size = len(names)
        self.lower = np.asarray(lower, dtype=np.float64)
        self.upper = np.asarray(upper, dtype=np.float64)
        self._nodes = [
            {"id": o, "kind": "output", "activation": "sigmoid"} for o in self.outputs
        ] + [{"id": k, "kind": "hidden", "activation": a} for k, a in zip(h, self.hidden)]

    def __repr__(self) -> str:
        return (
            f"CPPNVector(outputs={len(self.outputs)}, hidden={len(self.hidden)}, "
            f"controller={self.controller}, brain={self.n_brain}, size={self.size})"
        )

    # ------------------------------------------------------------------ decoding
    def _check(self, x: Any) -> np.ndarray:
        x = np.asarray(x, dtype=np.float64)
        if x.shape != (self.size,):
            raise InvalidParameterError(f"x must have shape ({self.size},), got {x.shape}")
        if not np.isfinite(x).all():
            raise InvalidParameterError("x must be finite")
        return np.clip(x, self.lower, self.upper)

    def cppn(self, x: np.ndarray) -> CPPN:
        """The CPPN of ``x`` (its weights clipped into their bounds).

        Parameters
        ----------
        x : ndarray of shape (size,), float64

        Returns
        -------
        CPPN
            Built by :meth:`CPPN.from_dict` (the genome's own reader).
        """
        x = self._check(x)
        return self._cppn(x)

    def _cppn(self, x: np.ndarray) -> CPPN:
        edges = [[a, b, float(w)] for (a, b), w in zip(self._edges, x[: self.n_weights])]
        return CPPN.from_dict({"schema": CPPN_SCHEMA, "version": CPPN_VERSION,
                               "outputs": list(self.outputs), "nodes": self._nodes,
                               "edges": edges})  # fmt: skip

    def individual(self, x: np.ndarray, id: int) -> Individual:
        """The individual ``x`` decodes to (genes clipped into their bounds).

        Parameters
        ----------
        x : ndarray of shape (size,), float64
        id : int
            The individual's id.

        Returns
        -------
        Individual
            With the CPPN, the controller (``Controller()`` without controller genes) and the
            brain (with a ``brain_spec``).
        """
        x = self._check(x)
        ind = Individual(cppn=self._cppn(x), id=int(id))
        k = self.n_weights
        if self.controller:
            ind.controller = Controller.clipped(*(float(v) for v in x[k : k + 3]))
            k += 3
        if self.brain_spec is not None:
            ind.brain = self.brain_spec.clipped(x[k : k + self.n_brain]).weights.copy()
            ind.brain_spec = self.brain_spec
        return ind

    # ------------------------------------------------------------------ sampling
    def random(self, rng: np.random.Generator | int | None = None) -> np.ndarray:
        """A vector drawn uniformly within the bounds, ndarray of shape (size,), float64."""
        return _rng(rng).uniform(self.lower, self.upper)

    def random_valid(
        self,
        rng: np.random.Generator | int | None = None,
        shape: Sequence[int] = (6, 6, 6),
        rules: CompositionRules | Callable[[np.ndarray], bool] | None = None,
        max_attempts: int = 10_000,
    ) -> np.ndarray:
        """Uniform vectors until one draws a valid body (``rules``, default the seed's).

        Returns
        -------
        ndarray of shape (size,), float64

        Raises
        ------
        InvalidDesignError
            If none of ``max_attempts`` vectors draws a valid body.
        InvalidParameterError
            If ``max_attempts`` is not an integer >= 1.
        """
        if not is_int(max_attempts) or max_attempts < 1:
            raise InvalidParameterError(
                f"max_attempts must be an integer >= 1, got {show(max_attempts)}"
            )
        rng = _rng(rng)
        rules = CompositionRules.seed() if rules is None else rules
        if isinstance(rules, CompositionRules):
            fixed = rules
            valid: Callable[[np.ndarray], bool] = lambda grid: not fixed.violations(grid)  # noqa: E731
        elif callable(rules):
            valid = rules
        else:
            raise InvalidParameterError(
                f"rules must be CompositionRules, a callable or None, got {show(rules)}"
            )
        shape = tuple(int(s) for s in shape)
        for _ in range(int(max_attempts)):
            x = self.random(rng)
            grid = self._cppn(x).to_grid(shape)
            if grid.any() and valid(grid):
                return x
        raise InvalidDesignError(f"no uniform vector drew a valid body in {max_attempts} attempts")
