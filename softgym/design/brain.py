"""Closed-loop controllers: neural networks that map a robot's senses to its muscles.

Next to the seed's open-loop :class:`~softgym.design.Controller` (one global
sinusoid), a design may carry a :class:`Brain`: a small network with one
hidden ``tanh`` layer whose weights are a flat vector in
``[-WEIGHT_BOUND, WEIGHT_BOUND]``, so any optimiser (CMA-ES, a GA, random
search) can search it and any body can carry it. Two kinds:

``central``
    One network per robot: every sensor of its grid in (the task
    observation of :mod:`softgym.tasks.sensing`), one output per grid cell
    (every muscle) out. Its sizes are fixed by the grid and the task.
``distributed``
    One small network per voxel with the same weights in every voxel (after
    Medvet et al., GECCO 2020): the voxel's own sensors, the robot's shared
    ones (clock, orientation, the task's senses) and the ``signals`` values
    its six lattice neighbours sent at the previous control step in; its own
    actuation and ``signals`` values for its neighbours out. Its sizes do not
    depend on the body, so one brain drives bodies of any shape.

Each output ``o`` in ``[-1, 1]`` sets its muscle as an env action does
(:class:`softgym.tasks.ActionMap`: under the seed's contraction-only law
``o = -1`` fully contracts the positive-CTE muscles and rests the negative
ones), scaled by the design's controller amplitude and muscle CTE; the
controller's ``period`` is the brain's clock. A :class:`BrainSpec` (kind and
sizes) and a weight vector make a brain; :meth:`BrainSpec.random` draws one.
Plain data with a JSON round trip; the batched control step is
:func:`forward` (every robot of a batch in one call, no loop per robot).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from softgym.exceptions import InvalidDesignError
from softgym.validate import show

__all__ = [
    "BRAIN_KINDS",
    "CONTROL_DT_RANGE",
    "MAX_BRAIN_PARAMS",
    "MAX_HIDDEN",
    "MAX_SIGNALS",
    "WEIGHT_BOUND",
    "Brain",
    "BrainSpec",
    "forward",
]

#: The network kinds.
BRAIN_KINDS: tuple[str, ...] = ("central", "distributed")
#: Every weight and bias lies in [-WEIGHT_BOUND, WEIGHT_BOUND].
WEIGHT_BOUND = 3.0
#: Most hidden units.
MAX_HIDDEN = 256
#: Most signals a distributed brain's voxel sends each neighbour.
MAX_SIGNALS = 8
#: Most weights a brain may have (checked before anything is allocated).
MAX_BRAIN_PARAMS = 2_000_000
#: Accepted control step (s): the brain reads its senses and sets its muscles this often.
CONTROL_DT_RANGE: tuple[float, float] = (0.005, 1.0)
#: Most inputs or outputs of one network.
MAX_PORTS = 10_000_000


def _int_in(name: str, value: Any, lo: int, hi: int) -> int:
    ok = isinstance(value, (int, np.integer)) and not isinstance(value, (bool, np.bool_))
    if not ok or not lo <= int(value) <= hi:
        raise InvalidDesignError(f"brain {name} must be an integer in [{lo}, {hi}], got {show(value)}")
    return int(value)


@dataclass(frozen=True)
class BrainSpec:
    """A network's kind and sizes: what a weight vector is read as.

    Parameters
    ----------
    kind : {"central", "distributed"}
    n_inputs : int
        Inputs of the network: for a central brain the task observation's
        length, for a distributed one a voxel's sensor inputs plus ``6 *
        signals`` from its neighbours.
    n_outputs : int
        Outputs: a central brain's grid cells; ``1 + signals`` for a
        distributed one.
    hidden : int
        Hidden ``tanh`` units, in [0, MAX_HIDDEN]; 0 is a single layer.
    signals : int
        Values a distributed brain's voxel sends each neighbour, in
        [0, MAX_SIGNALS] (0 for a central brain).
    control_dt : float
        Seconds between two control steps, in :data:`CONTROL_DT_RANGE`.
    """

    kind: str
    n_inputs: int
    n_outputs: int
    hidden: int = 8
    signals: int = 0
    control_dt: float = 0.05

    def __post_init__(self) -> None:
        if not isinstance(self.kind, str) or self.kind not in BRAIN_KINDS:
            raise InvalidDesignError(f"brain kind must be one of {list(BRAIN_KINDS)}, got {show(self.kind)}")
        object.__setattr__(self, "n_inputs", _int_in("n_inputs", self.n_inputs, 1, MAX_PORTS))
        object.__setattr__(self, "n_outputs", _int_in("n_outputs", self.n_outputs, 1, MAX_PORTS))
        object.__setattr__(self, "hidden", _int_in("hidden", self.hidden, 0, MAX_HIDDEN))
        object.__setattr__(self, "signals", _int_in("signals", self.signals, 0, MAX_SIGNALS))
        lo, hi = CONTROL_DT_RANGE
        dt = self.control_dt
        if (isinstance(dt, (bool, np.bool_)) or not isinstance(dt, (int, float, np.integer, np.floating))
                or not math.isfinite(float(dt)) or not lo <= float(dt) <= hi):  # fmt: skip
            raise InvalidDesignError(f"brain control_dt must be a number in [{lo}, {hi}] s, got {show(dt)}")
        object.__setattr__(self, "control_dt", float(dt))
        if self.kind == "central" and self.signals:
            raise InvalidDesignError(f"a central brain sends no signals, got signals={self.signals}")
        if self.kind == "distributed":
            if self.n_outputs != 1 + self.signals:
                raise InvalidDesignError(
                    f"a distributed brain has n_outputs = 1 + signals = {1 + self.signals}, "
                    f"got {self.n_outputs}"
                )
            if self.n_inputs < 6 * self.signals:
                raise InvalidDesignError(
                    f"a distributed brain's n_inputs ({self.n_inputs}) must hold the 6 * "
                    f"signals = {6 * self.signals} neighbour signals"
                )
        if self.n_params > MAX_BRAIN_PARAMS:
            raise InvalidDesignError(
                f"a brain of {self.n_inputs} inputs, {self.hidden} hidden units and "
                f"{self.n_outputs} outputs has {self.n_params} weights, over MAX_BRAIN_PARAMS = "
                f"{MAX_BRAIN_PARAMS}; use fewer hidden units or the distributed kind"
            )

    @property
    def n_params(self) -> int:
        """Length of the weight vector."""
        if self.hidden == 0:
            return self.n_outputs * (self.n_inputs + 1)
        return self.hidden * (self.n_inputs + 1) + self.n_outputs * (self.hidden + 1)

    @property
    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """Lower and upper bound of every weight (for an optimiser's box)."""
        n = self.n_params
        return np.full(n, -WEIGHT_BOUND), np.full(n, WEIGHT_BOUND)

    def brain(self, weights: Any) -> Brain:
        """The brain of this spec with ``weights`` (checked: length, finite, in bounds)."""
        return Brain(self, weights)

    def clipped(self, weights: Any) -> Brain:
        """The brain with ``weights`` clipped into the bounds (non-finite values still refused)."""
        w = _as_vector(weights, self.n_params)
        return Brain(self, np.clip(w, -WEIGHT_BOUND, WEIGHT_BOUND))

    def random(self, rng: np.random.Generator | int | None = None, scale: float = 1.0) -> Brain:
        """A brain with weights drawn from ``N(0, scale / sqrt(fan_in))``, clipped into the bounds."""
        rng = rng if isinstance(rng, np.random.Generator) else np.random.default_rng(rng)
        parts = []
        for rows, cols in self.layer_shapes():
            parts.append(rng.normal(0.0, scale / math.sqrt(cols), size=rows * cols))
        return self.clipped(np.concatenate(parts))

    def layer_shapes(self) -> list[tuple[int, int]]:
        """The layers' (outputs, inputs + 1) in the order of the weight vector (bias last in a row)."""
        if self.hidden == 0:
            return [(self.n_outputs, self.n_inputs + 1)]
        return [(self.hidden, self.n_inputs + 1), (self.n_outputs, self.hidden + 1)]

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict."""
        return {"kind": self.kind, "n_inputs": self.n_inputs, "n_outputs": self.n_outputs,
                "hidden": self.hidden, "signals": self.signals, "control_dt": self.control_dt}  # fmt: skip

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> BrainSpec:
        """Inverse of :meth:`to_dict`."""
        if not isinstance(data, Mapping):
            raise InvalidDesignError(f"a brain spec must be an object, got {type(data).__name__}")
        unknown = sorted(set(map(str, data)) - {"kind", "n_inputs", "n_outputs", "hidden", "signals", "control_dt"})
        if unknown:
            raise InvalidDesignError(f"unknown brain field(s) {unknown}")
        return cls(**dict(data))


def _as_vector(weights: Any, n: int) -> np.ndarray:
    try:
        w = np.asarray(weights)
    except (TypeError, ValueError, OverflowError) as exc:
        raise InvalidDesignError(f"brain weights must be a vector of {n} numbers: {exc!s:.120}") from None
    if w.dtype.kind not in "iuf":
        raise InvalidDesignError(f"brain weights must be real numbers, got dtype {w.dtype}")
    if w.shape != (n,):
        raise InvalidDesignError(f"brain weights must have shape ({n},), got {w.shape}")
    w = w.astype(np.float64)
    if not np.isfinite(w).all():
        raise InvalidDesignError("brain weights hold NaN or infinite values")
    return w


class Brain:
    """A network controller: a :class:`BrainSpec` and its weight vector.

    Parameters
    ----------
    spec : BrainSpec
    weights : array_like of shape (spec.n_params,)
        Finite, each in ``[-WEIGHT_BOUND, WEIGHT_BOUND]`` (stored read-only).

    Raises
    ------
    InvalidDesignError
        For a wrong length, a non-finite or out-of-bounds weight.
    """

    __slots__ = ("spec", "weights")

    def __init__(self, spec: BrainSpec, weights: Any) -> None:
        if not isinstance(spec, BrainSpec):
            raise InvalidDesignError(f"spec must be a BrainSpec, got {type(spec).__name__}")
        w = _as_vector(weights, spec.n_params)
        bad = np.flatnonzero(np.abs(w) > WEIGHT_BOUND)
        if bad.size:
            raise InvalidDesignError(
                f"brain weight {int(bad[0])} = {w[bad[0]]!r} is outside [-{WEIGHT_BOUND}, {WEIGHT_BOUND}]"
            )
        w = w.copy()
        w.setflags(write=False)
        self.spec = spec
        self.weights = w

    @property
    def kind(self) -> str:
        """``"central"`` or ``"distributed"``."""
        return self.spec.kind

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Brain):
            return NotImplemented
        return self.spec == other.spec and bool(np.array_equal(self.weights, other.weights))

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        s = self.spec
        return (f"Brain({s.kind}, {s.n_inputs} in, {s.hidden} hidden, {s.n_outputs} out, "
                f"{s.n_params} weights)")  # fmt: skip

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict: the spec's fields and ``weights`` (floats written exactly)."""
        return {**self.spec.to_dict(), "weights": [float(v) for v in self.weights]}

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> Brain:
        """Inverse of :meth:`to_dict`."""
        if not isinstance(data, Mapping) or "weights" not in data:
            raise InvalidDesignError("a brain must be an object with 'weights'")
        rest = {k: v for k, v in data.items() if k != "weights"}
        return cls(BrainSpec.from_dict(rest), data["weights"])


def forward(spec: BrainSpec, weights: np.ndarray, x: np.ndarray | list[np.ndarray]) -> np.ndarray:
    """The networks of many robots at once: ``tanh`` hidden layer, ``tanh`` outputs in [-1, 1].

    Parameters
    ----------
    spec : BrainSpec
        Every robot's network has these sizes.
    weights : ndarray of shape (n_robots, spec.n_params)
    x : ndarray of shape (n_robots, m, spec.n_inputs), or a list of parts
        The inputs of ``m`` networks per robot (a distributed brain's cells;
        1 for a central brain). As a list, the parts' last axes are the
        inputs in order, each part of shape (n_robots, m, k) or (n_robots, 1,
        k): a part shared by a robot's networks (its clock, its task senses)
        is multiplied once per robot, not once per cell.

    Returns
    -------
    ndarray of shape (n_robots, m, spec.n_outputs), float64
    """
    parts = [x] if isinstance(x, np.ndarray) else list(x)
    n = weights.shape[0]
    start = 0
    h = None
    for layer, (rows, cols) in enumerate(spec.layer_shapes()):
        w = weights[:, start:start + rows * cols].reshape(n, rows, cols)
        start += rows * cols
        if layer == 0:
            at = 0
            for part in parts:
                k = part.shape[-1]
                term = np.matmul(part, w[:, :, at:at + k].transpose(0, 2, 1))
                h = term if h is None else h + term
                at += k
        else:
            h = np.matmul(h, w[:, :, :-1].transpose(0, 2, 1))
        h = np.tanh(h + w[:, None, :, -1])
    return h
