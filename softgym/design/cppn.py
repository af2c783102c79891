"""CPPN genomes: compositional pattern-producing networks that draw robots.

A :class:`CPPN` is a small acyclic graph evaluated once per voxel of a grid
(docs/PHYSICS.md):

* **Inputs** ``x, y, z, d, b``: the voxel indices, each linearly mapped to
  [-1, 1] over the grid (an axis of size 1 maps to -1, as the seed's
  ``normalize`` does), ``d = sqrt(x^2 + y^2 + z^2)`` of those normalised
  values, itself mapped to [-1, 1], and the bias ``b = 1``.
* **Hidden nodes** use one of the seed's activations ``sin, abs, neg_abs,
  square, neg_square, sqrt_abs, neg_sqrt_abs``; output nodes start with the
  seed's ``sigmoid(x) = 2 / (1 + exp(-x)) - 1`` and may later mutate to the
  others. A node's value is ``activation(sum of weight * source value)``.
* **Outputs** feed a material tree, each output thresholded at ``> 0``:
  :data:`MATERIAL_TREE_4` (evosoro's ``shape, muscleOrTissue, muscleType,
  tissueType`` -> ids 1-4) or :data:`MATERIAL_TREE_8` (Ev-SoftBots' materials
  evolution -> ids 1-4 and 6-9). Only the largest 6-connected body is kept.

Difference from the seed, on purpose: evosoro's ``calc_node_state`` caches a
hidden node's *pre-activation* sum and returns it un-activated to every
consumer after the first (a node with fan-out > 1 feeds ``f(s)`` to one
consumer and ``s`` to the others). Here every consumer sees ``f(s)``. Seed
genomes therefore map to slightly different shapes when a hidden node has
several outgoing links.

Mutation (:meth:`CPPN.mutate`) follows §2.5: one of six operators, chosen
uniformly, applied to a copy of the parent and retried from the parent until
the phenotype changes and is valid, up to ``max_attempts`` (1500 in the seed).
Every random choice uses a ``numpy.random.Generator``, so a genome and a seed
give the same child. Genomes serialise to JSON.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np

from softgym.design.controller import Controller
from softgym.design.material import Palette
from softgym.design.robot import (
    CompositionRules,
    RobotDesign,
    check_grid_shape,
    largest_component_mask,
)
from softgym.exceptions import InvalidDesignError, InvalidParameterError

__all__ = [
    "ACTIVATIONS",
    "CPPN",
    "CPPN_SCHEMA",
    "CPPN_VERSION",
    "HIDDEN_ACTIVATIONS",
    "INPUT_NAMES",
    "MATERIAL_TREE_4",
    "MATERIAL_TREE_8",
    "MUTATIONS",
    "MutationResult",
    "cppn_inputs",
    "material_tree",
]

NodeId = str | int

CPPN_SCHEMA = "softgym.cppn"
CPPN_VERSION = 1

#: Input node names, in order.
INPUT_NAMES: tuple[str, ...] = ("x", "y", "z", "d", "b")
#: evosoro's 4-output material tree.
MATERIAL_TREE_4: tuple[str, ...] = ("shape", "muscleOrTissue", "muscleType", "tissueType")
#: Ev-SoftBots' 8-output tree of materials evolution (§3.1).
MATERIAL_TREE_8: tuple[str, ...] = (
    "shape",
    "newOrOld",
    "newMuscleOrTissue",
    "oldMuscleOrTissue",
    "newMuscleType",
    "newTissueType",
    "muscleType",
    "tissueType",
)
#: The six mutation operators of §2.5.
MUTATIONS: tuple[str, ...] = (
    "add_node",
    "remove_node",
    "add_link",
    "remove_link",
    "mutate_function",
    "mutate_weight",
)


def _sigmoid(x: np.ndarray) -> np.ndarray:
    return 2.0 / (1.0 + np.exp(-x)) - 1.0


def _sqrt_abs(x: np.ndarray) -> np.ndarray:
    return np.sqrt(np.abs(x))


#: Activation functions by name (the seed's hidden set plus the output ``sigmoid``).
ACTIVATIONS: dict[str, Callable[[np.ndarray], np.ndarray]] = {
    "sin": np.sin,
    "abs": np.abs,
    "neg_abs": lambda x: -np.abs(x),
    "square": np.square,
    "neg_square": lambda x: -np.square(x),
    "sqrt_abs": _sqrt_abs,
    "neg_sqrt_abs": lambda x: -_sqrt_abs(x),
    "sigmoid": _sigmoid,
}
#: Activations drawn by ``add_node`` and ``mutate_function`` (the seed's list, no sigmoid).
HIDDEN_ACTIVATIONS: tuple[str, ...] = (
    "sin",
    "abs",
    "neg_abs",
    "square",
    "neg_square",
    "sqrt_abs",
    "neg_sqrt_abs",
)


def _normalize(v: np.ndarray) -> np.ndarray:
    """The seed's ``normalize``: map min..max to -1..1; a constant array maps to -1."""
    v = v - v.min()
    top = v.max()
    v = v / top if top > 0 else np.zeros_like(v)
    return v * 2.0 - 1.0


@lru_cache(maxsize=16)
def _inputs_cached(shape: tuple[int, int, int]) -> tuple[np.ndarray, ...]:
    ix, iy, iz = np.meshgrid(*(np.arange(n, dtype=np.float64) for n in shape), indexing="ij")
    x, y, z = _normalize(ix), _normalize(iy), _normalize(iz)
    d = _normalize(np.sqrt(x * x + y * y + z * z))
    b = np.ones(shape)
    out = []
    for a in (x, y, z, d, b):
        a = np.ascontiguousarray(a).ravel()
        a.setflags(write=False)
        out.append(a)
    return tuple(out)


def _check_shape(shape: Sequence[int]) -> tuple[int, int, int]:
    # integers only, within the design grid caps (checked before any array is made)
    try:
        return check_grid_shape(shape, "CPPN shape")
    except InvalidDesignError as exc:
        raise InvalidParameterError(str(exc)) from None


def cppn_inputs(shape: Sequence[int] = (6, 6, 6)) -> dict[str, np.ndarray]:
    """The CPPN input values of every voxel.

    Parameters
    ----------
    shape : (nx, ny, nz)

    Returns
    -------
    dict of str to ndarray of shape (nx, ny, nz), float64
        Keys ``x, y, z, d, b`` (see the module docstring).
    """
    s = _check_shape(shape)
    return {name: a.reshape(s).copy() for name, a in zip(INPUT_NAMES, _inputs_cached(s))}


def _tree_4(o: Mapping[str, np.ndarray]) -> np.ndarray:
    shape = o["shape"] > 0
    muscle = o["muscleOrTissue"] > 0
    mat = np.where(
        muscle,
        np.where(o["muscleType"] > 0, 3, 4),
        np.where(o["tissueType"] > 0, 1, 2),
    )
    return np.where(shape, mat, 0).astype(np.int8)


def _tree_8(o: Mapping[str, np.ndarray]) -> np.ndarray:
    shape = o["shape"] > 0
    new = np.where(
        o["newMuscleOrTissue"] > 0,
        np.where(o["newMuscleType"] > 0, 8, 9),
        np.where(o["newTissueType"] > 0, 6, 7),
    )
    old = np.where(
        o["oldMuscleOrTissue"] > 0,
        np.where(o["muscleType"] > 0, 3, 4),
        np.where(o["tissueType"] > 0, 1, 2),
    )
    return np.where(shape, np.where(o["newOrOld"] > 0, new, old), 0).astype(np.int8)


_TREES: dict[tuple[str, ...], Callable[[Mapping[str, np.ndarray]], np.ndarray]] = {
    MATERIAL_TREE_4: _tree_4,
    MATERIAL_TREE_8: _tree_8,
}


def material_tree(outputs: Mapping[str, np.ndarray], keep_largest: bool = True) -> np.ndarray:
    """Map CPPN outputs to material ids with the seed's decision tree.

    Parameters
    ----------
    outputs : mapping of str to ndarray of shape (nx, ny, nz)
        Either the names of :data:`MATERIAL_TREE_4` or of :data:`MATERIAL_TREE_8`.
    keep_largest : bool
        Keep only the largest 6-connected body (the seed does).

    Returns
    -------
    ndarray of shape (nx, ny, nz), int8
        0 = empty; ids 1-4 (4-output tree) or 1-4 and 6-9 (8-output tree).
    """
    names = set(outputs)
    for tree_names, fn in _TREES.items():
        if names == set(tree_names):
            grid = fn(outputs)
            break
    else:
        raise InvalidDesignError(
            f"outputs {sorted(names)} match no material tree; expected {list(MATERIAL_TREE_4)} "
            f"or {list(MATERIAL_TREE_8)}"
        )
    if keep_largest:
        grid = np.where(largest_component_mask(grid != 0), grid, 0).astype(np.int8)
    return grid


@dataclass(frozen=True)
class MutationResult:
    """Outcome of :meth:`CPPN.mutate`.

    Attributes
    ----------
    genome : CPPN
        The child; a copy of the parent when ``success`` is False.
    operator : str or None
        The operator of the accepted mutation (one of :data:`MUTATIONS`).
    attempts : int
        Attempts made (1 = the first try was accepted).
    success : bool
        False when no valid, phenotype-changing mutation was found in
        ``max_attempts`` (the seed then keeps the un-mutated clone).
    """

    genome: CPPN
    operator: str | None
    attempts: int
    success: bool


Validity = CompositionRules | Callable[[np.ndarray], bool] | None


def _validity_fn(is_valid: Validity) -> Callable[[np.ndarray], bool]:
    if is_valid is None:
        is_valid = CompositionRules.seed()
    if isinstance(is_valid, CompositionRules):
        rules = is_valid
        return lambda grid: not rules.violations(grid)
    if callable(is_valid):
        return is_valid
    raise InvalidParameterError(
        f"is_valid must be CompositionRules, a callable or None, got {is_valid!r}"
    )


class CPPN:
    """A CPPN genome (see the module docstring).

    Parameters
    ----------
    outputs : sequence of str
        Output node names, e.g. :data:`MATERIAL_TREE_4` (default) or :data:`MATERIAL_TREE_8`.

    Notes
    -----
    A new ``CPPN(outputs)`` is the seed's minimal graph: every input linked
    to every output with weight 0, outputs with ``sigmoid``. Use
    :meth:`random` for the seed's random initial genome. Node ids are the
    input and output names (str) and integers for hidden nodes.
    """

    def __init__(self, outputs: Sequence[str] = MATERIAL_TREE_4) -> None:
        outputs = tuple(outputs)
        if not outputs or len(set(outputs)) != len(outputs):
            raise InvalidParameterError(f"outputs must be distinct names, got {outputs!r}")
        if any(not isinstance(o, str) or o in INPUT_NAMES for o in outputs):
            raise InvalidParameterError(
                f"output names must be strings other than the inputs {INPUT_NAMES}"
            )
        self.outputs: tuple[str, ...] = outputs
        self._act: dict[NodeId, str | None] = {name: None for name in INPUT_NAMES}
        for o in outputs:
            self._act[o] = "sigmoid"
        self._edges: dict[tuple[NodeId, NodeId], float] = {
            (i, o): 0.0 for i in INPUT_NAMES for o in outputs
        }
        self._order: list[NodeId] | None = None

    # ------------------------------------------------------------------ structure

    @property
    def nodes(self) -> list[NodeId]:
        """Node ids: inputs, outputs, then hidden nodes in creation order."""
        return list(self._act)

    @property
    def hidden(self) -> list[int]:
        """Hidden node ids."""
        return [n for n in self._act if isinstance(n, int)]

    @property
    def edges(self) -> dict[tuple[NodeId, NodeId], float]:
        """Links ``{(source, target): weight}`` (a copy)."""
        return dict(self._edges)

    def activation(self, node: NodeId) -> str | None:
        """Activation name of ``node`` (None for inputs)."""
        return self._act[node]

    def _kind(self, node: NodeId) -> str:
        if isinstance(node, int):
            return "hidden"
        return "input" if node in INPUT_NAMES else "output"

    def copy(self) -> CPPN:
        """An independent copy."""
        new = CPPN.__new__(CPPN)
        new.outputs = self.outputs
        new._act = dict(self._act)
        new._edges = dict(self._edges)
        new._order = self._order
        return new

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, CPPN):
            return NotImplemented
        return (
            self.outputs == other.outputs
            and list(self._act.items()) == list(other._act.items())
            and list(self._edges.items()) == list(other._edges.items())
        )

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        return f"CPPN(outputs={len(self.outputs)}, hidden={len(self.hidden)}, edges={len(self._edges)})"

    def _touch(self) -> None:
        self._order = None

    def _topological_order(self) -> list[NodeId]:
        if self._order is None:
            indeg = dict.fromkeys(self._act, 0)
            succ: dict[NodeId, list[NodeId]] = {n: [] for n in self._act}
            for a, b in self._edges:
                indeg[b] += 1
                succ[a].append(b)
            ready = [n for n in self._act if indeg[n] == 0]
            order: list[NodeId] = []
            while ready:
                n = ready.pop(0)
                order.append(n)
                for m in succ[n]:
                    indeg[m] -= 1
                    if indeg[m] == 0:
                        ready.append(m)
            if len(order) != len(self._act):
                raise InvalidDesignError("CPPN graph has a cycle")
            self._order = order
        return self._order

    # ------------------------------------------------------------------ expression

    def evaluate(self, shape: Sequence[int] = (6, 6, 6)) -> dict[str, np.ndarray]:
        """Output values of every voxel.

        Parameters
        ----------
        shape : (nx, ny, nz)
            Grid to draw in.

        Returns
        -------
        dict of str to ndarray of shape (nx, ny, nz), float64
            One array per output node, after its activation.
        """
        s = _check_shape(shape)
        values: dict[NodeId, np.ndarray] = dict(zip(INPUT_NAMES, _inputs_cached(s)))
        incoming: dict[NodeId, list[tuple[NodeId, float]]] = {}
        for (a, b), w in self._edges.items():
            incoming.setdefault(b, []).append((a, w))
        n = s[0] * s[1] * s[2]
        with np.errstate(over="ignore", invalid="ignore"):
            for node in self._topological_order():
                act = self._act[node]
                if act is None:
                    continue
                total = np.zeros(n)
                for src, w in incoming.get(node, ()):
                    if w != 0.0:
                        total += w * values[src]
                values[node] = ACTIVATIONS[act](total)
        return {o: values[o].reshape(s) for o in self.outputs}

    def to_grid(self, shape: Sequence[int] = (6, 6, 6)) -> np.ndarray:
        """The material grid this genome draws (tree + largest body).

        Returns
        -------
        ndarray of shape (nx, ny, nz), int8
            All zeros if an output is not finite or nothing is drawn.
        """
        out = self.evaluate(shape)
        if not all(np.isfinite(v).all() for v in out.values()):
            return np.zeros(_check_shape(shape), dtype=np.int8)
        return material_tree(out)

    def to_design(
        self,
        shape: Sequence[int] = (6, 6, 6),
        palette: Palette | None = None,
        controller: Controller | None = None,
    ) -> RobotDesign:
        """The :class:`~softgym.design.robot.RobotDesign` of this genome.

        The design is not validated; call ``design.validate(rules)``.
        """
        kw: dict[str, Any] = {}
        if palette is not None:
            kw["palette"] = palette
        if controller is not None:
            kw["controller"] = controller
        return RobotDesign(self.to_grid(shape), **kw)

    # ------------------------------------------------------------------ mutation operators

    def _reachable_from(self, start: NodeId) -> set[NodeId]:
        succ: dict[NodeId, list[NodeId]] = {}
        for a, b in self._edges:
            succ.setdefault(a, []).append(b)
        seen = {start}
        stack = [start]
        while stack:
            for m in succ.get(stack.pop(), ()):
                if m not in seen:
                    seen.add(m)
                    stack.append(m)
        return seen

    def _add_node(self, rng: np.random.Generator) -> bool:
        if not self._edges:
            return False
        edges = list(self._edges)
        n1, n2 = edges[int(rng.integers(len(edges)))]
        hidden = self.hidden
        new = max(hidden) + 1 if hidden else 0
        self._act[new] = HIDDEN_ACTIVATIONS[int(rng.integers(len(HIDDEN_ACTIVATIONS)))]
        w = self._edges.pop((n1, n2))
        self._edges[(new, n2)] = 1.0
        self._edges[(n1, new)] = w
        return True

    def _remove_node(self, rng: np.random.Generator) -> bool:
        hidden = self.hidden
        if not hidden:
            return False
        h = hidden[int(rng.integers(len(hidden)))]
        ins = [(a, w) for (a, b), w in self._edges.items() if b == h]
        outs = [(b, w) for (a, b), w in self._edges.items() if a == h]
        for a, wa in ins:
            for b, wb in outs:
                self._edges[(a, b)] = wa * wb
        self._drop_node(h)
        return True

    def _drop_node(self, node: NodeId) -> None:
        del self._act[node]
        self._edges = {e: w for e, w in self._edges.items() if node not in e}

    def _add_link(self, rng: np.random.Generator) -> bool:
        nodes = self.nodes
        candidates = []
        for b in nodes:
            if self._kind(b) == "input":
                continue
            downstream = self._reachable_from(b)  # a -> b closes a cycle iff a is downstream of b
            for a in nodes:
                if (
                    a == b
                    or self._kind(a) == "output"
                    or (a, b) in self._edges
                    or (b, a) in self._edges
                    or a in downstream
                ):
                    continue
                candidates.append((a, b))
        if not candidates:
            return False
        a, b = candidates[int(rng.integers(len(candidates)))]
        self._edges[(a, b)] = 0.1 if rng.random() > 0.5 else -0.1
        return True

    def _remove_link(self, rng: np.random.Generator) -> bool:
        if not self._edges:
            return False
        edges = list(self._edges)
        del self._edges[edges[int(rng.integers(len(edges)))]]
        return True

    def _mutate_function(self, rng: np.random.Generator) -> bool:
        nodes = [n for n in self._act if self._act[n] is not None]
        node = nodes[int(rng.integers(len(nodes)))]
        old = self._act[node]
        choices = [f for f in HIDDEN_ACTIVATIONS if f != old]
        self._act[node] = choices[int(rng.integers(len(choices)))]
        return True

    def _mutate_weight(self, rng: np.random.Generator, std: float = 0.5) -> bool:
        if not self._edges:
            return False
        edges = list(self._edges)
        e = edges[int(rng.integers(len(edges)))]
        old = self._edges[e]
        new = old
        while new == old:
            new = min(1.0, max(-1.0, float(rng.normal(old, std))))
        self._edges[e] = new
        return True

    def _prune(self) -> None:
        """Remove hidden nodes with no incoming or no outgoing link, until none is left."""
        changed = True
        while changed:
            changed = False
            has_in = {b for _, b in self._edges}
            has_out = {a for a, _ in self._edges}
            for h in self.hidden:
                if h not in has_in or h not in has_out:
                    self._drop_node(h)
                    changed = True

    def _apply(self, operator: str, rng: np.random.Generator) -> bool:
        self._touch()
        done = getattr(self, "_" + operator)(rng)
        self._prune()
        self._touch()
        return done

    # ------------------------------------------------------------------ public mutation API

    def mutate(
        self,
        rng: np.random.Generator | int | None = None,
        shape: Sequence[int] = (6, 6, 6),
        is_valid: Validity = None,
        max_attempts: int = 1500,
    ) -> MutationResult:
        """One NEAT-style mutation with validity retries (docs/PHYSICS.md).

        Each attempt copies this genome, applies one operator drawn uniformly
        from :data:`MUTATIONS`, prunes dangling hidden nodes and expresses the
        result; it is accepted when the material grid differs from the
        parent's, every output is finite, and ``is_valid`` holds.

        Parameters
        ----------
        rng : numpy.random.Generator, int or None
            Source of randomness (``numpy.random.default_rng(rng)``).
        shape : (nx, ny, nz)
            Grid the phenotype is drawn in.
        is_valid : CompositionRules, callable or None
            Validity of a child's grid (int8 array of ``shape``): rules or a
            predicate. None means :meth:`CompositionRules.seed` (the seed's
            >= 30 % filled, >= 10 % muscle); ``CompositionRules()`` accepts
            any non-empty body.
        max_attempts : int
            Attempts before giving up (1500 in the seed).

        Returns
        -------
        MutationResult
            The child and how it was found. This genome is not modified.
        """
        rng = np.random.default_rng(rng)
        if max_attempts < 1:
            raise InvalidParameterError(f"max_attempts must be >= 1, got {max_attempts}")
        valid = _validity_fn(is_valid)
        parent_grid = self.to_grid(shape)
        for attempt in range(1, max_attempts + 1):
            op = MUTATIONS[int(rng.integers(len(MUTATIONS)))]
            child = self.copy()
            if not child._apply(op, rng):
                continue
            out = child.evaluate(shape)
            if not all(np.isfinite(v).all() for v in out.values()):
                continue
            grid = material_tree(out)
            if np.array_equal(grid, parent_grid) or not valid(grid):
                continue
            return MutationResult(child, op, attempt, True)
        return MutationResult(self.copy(), None, max_attempts, False)

    def apply_mutation(self, operator: str, rng: np.random.Generator | int | None = None) -> CPPN:
        """Apply one named operator once (no validity check) and prune; return the new genome.

        Raises
        ------
        InvalidParameterError
            If ``operator`` is not one of :data:`MUTATIONS`.
        """
        if operator not in MUTATIONS:
            raise InvalidParameterError(
                f"unknown mutation {operator!r}; expected one of {MUTATIONS}"
            )
        child = self.copy()
        child._apply(operator, np.random.default_rng(rng))
        return child

    @classmethod
    def random(
        cls,
        outputs: Sequence[str] = MATERIAL_TREE_4,
        rng: np.random.Generator | int | None = None,
        n_add_node: int = 5,
        n_remove_node: int = 0,
        n_add_link: int = 10,
        n_remove_link: int = 5,
        n_mutate_function: int = 100,
        n_mutate_weight: int = 100,
    ) -> CPPN:
        """The seed's random initial genome (§2.4).

        The minimal graph, then ``n_add_node`` add-node, ``n_remove_node``
        remove-node, ``n_add_link`` add-link, ``n_remove_link`` remove-link,
        ``n_mutate_function`` function and ``n_mutate_weight`` weight
        mutations in that order, then pruning. Not checked for validity; see
        :meth:`random_valid`.
        """
        rng = np.random.default_rng(rng)
        g = cls(outputs)
        plan = (
            ("add_node", n_add_node),
            ("remove_node", n_remove_node),
            ("add_link", n_add_link),
            ("remove_link", n_remove_link),
            ("mutate_function", n_mutate_function),
            ("mutate_weight", n_mutate_weight),
        )
        for op, count in plan:
            for _ in range(int(count)):
                getattr(g, "_" + op)(rng)
        g._prune()
        g._touch()
        return g

    @classmethod
    def random_valid(
        cls,
        outputs: Sequence[str] = MATERIAL_TREE_4,
        rng: np.random.Generator | int | None = None,
        shape: Sequence[int] = (6, 6, 6),
        is_valid: Validity = None,
        max_attempts: int = 10000,
    ) -> CPPN:
        """Draw :meth:`random` genomes until one draws a valid robot (the seed's new individuals).

        ``is_valid`` is as in :meth:`mutate` (None: :meth:`CompositionRules.seed`).

        Raises
        ------
        InvalidDesignError
            If none of ``max_attempts`` genomes is valid.
        """
        rng = np.random.default_rng(rng)
        valid = _validity_fn(is_valid)
        for _ in range(max_attempts):
            g = cls.random(outputs, rng)
            out = g.evaluate(shape)
            if not all(np.isfinite(v).all() for v in out.values()):
                continue
            if valid(material_tree(out)):
                return g
        raise InvalidDesignError(f"no valid random CPPN found in {max_attempts} attempts")

    # ------------------------------------------------------------------ JSON

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict (nodes and links in order, so mutation stays deterministic after a round-trip)."""
        return {
            "schema": CPPN_SCHEMA,
            "version": CPPN_VERSION,
            "outputs": list(self.outputs),
            "nodes": [
                {"id": n, "kind": self._kind(n), "activation": a}
                for n, a in self._act.items()
                if a is not None
            ],
            "edges": [[a, b, w] for (a, b), w in self._edges.items()],
        }

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> CPPN:
        """Inverse of :meth:`to_dict`.

        Raises
        ------
        InvalidDesignError
            On a wrong schema or version, unknown nodes or activations,
            links into inputs or out of outputs, or a cycle.
        """
        if not isinstance(data, Mapping) or data.get("schema") != CPPN_SCHEMA:
            raise InvalidDesignError(f"not a softgym CPPN: schema must be {CPPN_SCHEMA!r}")
        version = data.get("version")
        if not isinstance(version, int) or isinstance(version, bool) or version < 1:
            raise InvalidDesignError(f"CPPN has an invalid version {version!r}")
        if version > CPPN_VERSION:
            raise InvalidDesignError(
                f"CPPN version {version} is newer than this softgym reads (up to {CPPN_VERSION}); upgrade softgym"
            )
        outputs = data.get("outputs")
        if not isinstance(outputs, list) or not all(isinstance(o, str) for o in outputs):
            raise InvalidDesignError(f"CPPN outputs must be a list of names, got {outputs!r}")
        try:
            g = cls(outputs)
        except InvalidParameterError as exc:
            raise InvalidDesignError(f"CPPN outputs are invalid: {exc}") from exc
        nodes, edges = data.get("nodes", []), data.get("edges", [])
        if not isinstance(nodes, list) or not isinstance(edges, list):
            raise InvalidDesignError("CPPN 'nodes' and 'edges' must be lists")
        g._edges = {}
        for item in nodes:
            if not isinstance(item, Mapping):
                raise InvalidDesignError(f"CPPN node {item!r} is not an object")
            node, kind, act = item.get("id"), item.get("kind"), item.get("activation")
            if not isinstance(node, (str, int)) or not isinstance(act, str):
                raise InvalidDesignError(
                    f"CPPN node {node!r} needs an int or str 'id' and a str 'activation'"
                )
            if act not in ACTIVATIONS:
                raise InvalidDesignError(f"CPPN node {node!r} has unknown activation {act!r}")
            if kind == "output" and node in g.outputs:
                g._act[node] = act
            elif kind == "hidden" and isinstance(node, int) and not isinstance(node, bool):
                if node in g._act:
                    raise InvalidDesignError(f"CPPN node {node!r} is listed twice")
                g._act[node] = act
            else:
                raise InvalidDesignError(f"CPPN node {node!r} of kind {kind!r} is not valid")
        for item in edges:
            if (
                not isinstance(item, list)
                or len(item) != 3
                or not all(isinstance(v, (str, int)) for v in item[:2])
                or isinstance(item[2], bool)
                or not isinstance(item[2], (int, float))
            ):
                raise InvalidDesignError(f"CPPN link {item!r} is not [source, target, weight]")
            a, b, w = item[0], item[1], float(item[2])
            if a not in g._act or b not in g._act:
                raise InvalidDesignError(f"CPPN link {a!r} -> {b!r} names an unknown node")
            if g._kind(b) == "input" or g._kind(a) == "output":
                raise InvalidDesignError(
                    f"CPPN link {a!r} -> {b!r} goes into an input or out of an output"
                )
            if not np.isfinite(w):
                raise InvalidDesignError(f"CPPN link {a!r} -> {b!r} has a non-finite weight")
            g._edges[(a, b)] = w
        g._touch()
        g._topological_order()  # raises on a cycle
        return g

    def to_json(self, indent: int | None = None) -> str:
        """Serialise to a JSON string."""
        return json.dumps(self.to_dict(), indent=indent)

    @classmethod
    def from_json(cls, text: str | bytes) -> CPPN:
        """Inverse of :meth:`to_json`; any malformed text raises :class:`InvalidDesignError`."""
        if not isinstance(text, (str, bytes, bytearray)):
            raise InvalidDesignError(
                f"a CPPN's JSON must be str or bytes, got {type(text).__name__}"
            )
        try:
            data = json.loads(text)
        except (ValueError, RecursionError) as exc:  # JSONDecodeError, UnicodeDecodeError...
            raise InvalidDesignError(f"CPPN is not valid JSON: {exc!s:.200}") from None
        return cls.from_dict(data)
