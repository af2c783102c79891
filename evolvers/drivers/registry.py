"""The drivers by name: what ``softgym evolve --backend`` and ``--algorithm`` accept.

The CLI reads its choices here, and :func:`driver_class` imports the chosen driver on
demand (the DEAP and pymoo drivers need their library; nothing is imported to list
them). A new driver is one entry of :data:`BACKENDS`.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass

from softgym.exceptions import InvalidParameterError

__all__ = ["BACKENDS", "PYMOO_ALGORITHMS", "Backend", "driver_class"]


@dataclass(frozen=True)
class Backend:
    """One search loop of ``softgym evolve``.

    Attributes
    ----------
    module, cls : str
        Where its :class:`~evolvers.drivers.base.Driver` subclass is.
    summary : str
        One line for the CLI's help.
    selects : bool
        Whether ``--selection`` chooses its survival (the native and DEAP loops).
    """

    module: str
    cls: str
    summary: str
    selects: bool = False


#: The search loops by ``--backend`` name.
BACKENDS: dict[str, Backend] = {
    "native": Backend("evolvers.drivers.runner", "EvolutionRun", "softgym's own loop", True),
    "deap": Backend("evolvers.drivers.deap_runner", "DeapRun", "the same loop on a DEAP toolbox",
                    True),  # fmt: skip
    "pymoo": Backend("evolvers.drivers.pymoo_runner", "PymooRun",
                     "a pymoo algorithm (--algorithm)"),  # fmt: skip
    "random": Backend("evolvers.drivers.random_search", "RandomSearchRun",
                      "random search (fresh random genomes each generation, the best kept)"),  # fmt: skip
}

#: pymoo's algorithms by ``--algorithm`` name (``"ga"`` and ``"cmaes"`` are single-objective:
#: they optimise the experiment's fitness; ``"cmaes"`` a design vector or a brain on a fixed
#: body; :mod:`evolvers.drivers.pymoo_runner`).
PYMOO_ALGORITHMS: tuple[str, ...] = ("nsga2", "nsga3", "sms-emoa", "ga", "cmaes")


def driver_class(name: str) -> type:
    """The :class:`~evolvers.drivers.base.Driver` subclass of backend ``name`` (imported now).

    Raises
    ------
    InvalidParameterError
        For a name not in :data:`BACKENDS`.
    """
    if name not in BACKENDS:
        raise InvalidParameterError(f"backend must be one of {list(BACKENDS)}, got {name!r}")
    entry = BACKENDS[name]
    return getattr(importlib.import_module(entry.module), entry.cls)
