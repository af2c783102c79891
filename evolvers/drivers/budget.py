"""A run's budget: what stops it, whichever comes first (pymoo's ``Termination`` is the model).

A run stops after the generation (POET: iteration) at whose end any of these is reached:

========================  ==================  ==============================================
budget                    flag                what is counted
========================  ==================  ==============================================
``generations``           ``--generations``   generations after generation 0 (the driver's
                                              ``generations``; always set)
``max_evals``             ``--max-evals``     simulations run (a phenotype read from the
                                              run's cache is not simulated, not counted)
``max_robot_seconds``     ``--max-robot-      simulated seconds summed over the simulated
                          seconds``           robots (each robot its task's duration)
``max_wall_seconds``      ``--max-wall-       wall-clock seconds of the run, every sitting
                          seconds``           (resume) summed, checkpoint writes included
``target_score``          ``--target-score``  the best score found reaches it (the run's
                                              fitness: >= when maximised, <= when minimised;
                                              QD: the archive's best objective; POET: the best
                                              pair's score)
========================  ==================  ==============================================

The checks run between generations, so a generation that starts under a budget runs
whole: a run may overshoot ``max_evals`` by up to one generation's simulations, as pymoo's
do. Every count is checkpointed and goes on across resumes: a run stopped by a budget and
resumed with a larger one continues, and for the deterministic budgets (generations,
evaluations, robot-seconds, target score) it ends exactly as an uninterrupted run with the
larger budget. Wall time is by nature not reproducible: a run stopped by
``max_wall_seconds`` stops at a generation that depends on the machine and its load.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import asdict, dataclass, fields
from typing import Any

from softgym.exceptions import InvalidParameterError
from softgym.validate import is_int, is_real, show

__all__ = ["BUDGET_FLAGS", "STOP_ORDER", "Budget", "BudgetUsage"]

#: The command-line flag of each limit of a :class:`Budget` (the field's name otherwise).
BUDGET_FLAGS: dict[str, str] = {
    "max_evals": "--max-evals",
    "max_robot_seconds": "--max-robot-seconds",
    "max_wall_seconds": "--max-wall-seconds",
    "target_score": "--target-score",
}

#: What ``stopped_by`` names when several budgets are reached by the same generation: the
#: first of this order (a reached target first, the generations last).
STOP_ORDER: tuple[str, ...] = (
    "target_score", "max_evals", "max_robot_seconds", "max_wall_seconds", "generations",
)  # fmt: skip


@dataclass(frozen=True)
class BudgetUsage:
    """How much of each budget a run has used (all sittings), as checkpoints and logs record it.

    Attributes
    ----------
    generation : int
        The last finished generation (-1 before generation 0).
    evaluations : int
        Simulations run.
    robot_seconds : float
        Simulated seconds summed over the simulated robots.
    wall_seconds : float
        Wall-clock seconds of the run, every sitting summed.
    best_score : float or None
        The best score found (None before any).
    """

    generation: int = -1
    evaluations: int = 0
    robot_seconds: float = 0.0
    wall_seconds: float = 0.0
    best_score: float | None = None

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON data."""
        return asdict(self)


@dataclass(frozen=True)
class Budget:
    """Limits that stop a run, whichever comes first (the module docstring); None: no limit.

    The generations are the driver's own ``generations`` argument; a :class:`Budget`
    adds the others.

    Parameters
    ----------
    max_evals : int, optional
        Simulations, >= 1.
    max_robot_seconds : float, optional
        Simulated robot-seconds, > 0.
    max_wall_seconds : float, optional
        Wall-clock seconds over every sitting, > 0 (not reproducible: see the module docstring).
    target_score : float, optional
        Stop once the best score reaches it (any finite number).

    Raises
    ------
    InvalidParameterError
        Naming the flag (``--max-evals``...) and the accepted range.
    """

    max_evals: int | None = None
    max_robot_seconds: float | None = None
    max_wall_seconds: float | None = None
    target_score: float | None = None

    def __post_init__(self) -> None:
        v = self.max_evals
        if v is not None:
            if not is_int(v) or v < 1:
                raise InvalidParameterError(
                    f"{BUDGET_FLAGS['max_evals']} must be an integer >= 1 (simulations), got {show(v)}"
                )
            object.__setattr__(self, "max_evals", int(v))
        for name in ("max_robot_seconds", "max_wall_seconds"):
            v = getattr(self, name)
            if v is None:
                continue
            if not is_real(v) or not math.isfinite(v) or v <= 0:
                raise InvalidParameterError(
                    f"{BUDGET_FLAGS[name]} must be a finite number of seconds > 0, got {show(v)}"
                )
            object.__setattr__(self, name, float(v))
        v = self.target_score
        if v is not None:
            if not is_real(v) or not math.isfinite(v):
                raise InvalidParameterError(
                    f"{BUDGET_FLAGS['target_score']} must be a finite number, got {show(v)}"
                )
            object.__setattr__(self, "target_score", float(v))

    @property
    def limited(self) -> bool:
        """Whether any limit is set (beyond the driver's generations)."""
        return any(getattr(self, f.name) is not None for f in fields(self))

    def to_dict(self) -> dict[str, Any]:
        """The limits that are set (what config.json records as ``budget``)."""
        return {f.name: getattr(self, f.name) for f in fields(self) if getattr(self, f.name) is not None}

    @classmethod
    def from_dict(cls, data: Mapping[str, Any] | None) -> Budget:
        """Inverse of :meth:`to_dict` (None: no limit).

        Raises
        ------
        InvalidParameterError
            An unknown key, or a value out of its range (naming its flag).
        """
        if data is None:
            return cls()
        if not isinstance(data, Mapping):
            raise InvalidParameterError(f"a budget must be a mapping of limits, got {show(data)}")
        unknown = sorted(set(data) - {f.name for f in fields(cls)})
        if unknown:
            raise InvalidParameterError(
                f"unknown budget limit(s) {unknown}; expected some of {list(BUDGET_FLAGS)}"
            )
        return cls(**dict(data))

    def reached(self, used: BudgetUsage, generations: int, maximize: bool = True) -> str | None:
        """The budget that ``used`` reaches (the first of :data:`STOP_ORDER`), or None.

        Parameters
        ----------
        used : BudgetUsage
        generations : int
            The run's generations after generation 0.
        maximize : bool
            Whether the score is better larger (the target is reached at >=; else <=).
        """
        best, target = used.best_score, self.target_score
        hit = {
            "target_score": target is not None and best is not None and math.isfinite(best)
            and (best >= target if maximize else best <= target),
            "max_evals": self.max_evals is not None and used.evaluations >= self.max_evals,
            "max_robot_seconds": self.max_robot_seconds is not None
            and used.robot_seconds >= self.max_robot_seconds,
            "max_wall_seconds": self.max_wall_seconds is not None
            and used.wall_seconds >= self.max_wall_seconds,
            "generations": used.generation >= generations,
        }  # fmt: skip
        return next((name for name in STOP_ORDER if hit[name]), None)
