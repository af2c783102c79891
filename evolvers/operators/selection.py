"""Selection schemes: the seed's Pareto (with optional age), NSGA-II, fitness tournament, AMSS novelty.

Each ``sel_*`` function has DEAP's shape, ``sel(individuals, k, ...) -> list``,
so it registers as ``toolbox.register("select", sel_pareto, objectives=...)``.
Objectives are :class:`Objective` (a metric name and a direction); the name
``"age"`` reads :attr:`Individual.age`.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from evolvers.operators.genome import Individual
from softgym.exceptions import InvalidParameterError
from softgym.metrics import WORST_FITNESS, NoveltyArchive, novelty_scores

__all__ = [
    "SELECTORS",
    "Objective",
    "minimised_matrix",
    "pareto_levels",
    "select",
    "sel_fitness_tournament",
    "sel_nsga2",
    "sel_novelty",
    "sel_pareto",
    "sort_by_objectives",
]


@dataclass(frozen=True)
class Objective:
    """One objective: a metric name (``Individual.objectives`` key or ``"age"``) and a direction."""

    name: str
    maximize: bool = True

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict."""
        return {"name": self.name, "maximize": self.maximize}


def _rng(rng: np.random.Generator | int | None) -> np.random.Generator:
    return rng if isinstance(rng, np.random.Generator) else np.random.default_rng(rng)


def minimised_matrix(
    individuals: Sequence[Individual], objectives: Sequence[Objective]
) -> np.ndarray:
    """Objective values to minimise, ndarray of shape (n, n_objectives): maximised ones negated."""
    F = np.array([[ind.value(o.name) for o in objectives] for ind in individuals], dtype=np.float64)
    F = F.reshape(len(individuals), len(objectives))
    for j, o in enumerate(objectives):
        if o.maximize:
            F[:, j] = -F[:, j]
    return F


def pareto_levels(individuals: Sequence[Individual], objectives: Sequence[Objective]) -> np.ndarray:
    """The seed's Pareto level of each individual (§2.7): its number of dominators.

    Individuals are visited by increasing id; ``a`` is dominated by ``b`` when
    ``a`` is strictly better than ``b`` in no objective and ``a.id`` is not
    already among ``b``'s dominators (so between exact ties the newer id
    wins). An individual whose first objective has the worst value (-1e7,
    invalid or diverged) gets ``2 * len(individuals)`` extra dominators.

    Returns
    -------
    ndarray of shape (len(individuals),), int64
        Levels in the order of ``individuals``.
    """
    n = len(individuals)
    F = minimised_matrix(individuals, objectives)
    order = sorted(range(n), key=lambda i: individuals[i].id)
    dominated_by: dict[int, set[int]] = {i: set() for i in range(n)}
    for i in order:
        for j in order:
            if i == j:
                continue
            if not np.any(F[i] < F[j]) and i not in dominated_by[j]:
                dominated_by[i].add(j)
    levels = np.array([len(dominated_by[i]) for i in range(n)], dtype=np.int64)
    first = objectives[0]
    for i, ind in enumerate(individuals):
        if first.name != "age" and ind.value(first.name) == (
            WORST_FITNESS if first.maximize else -WORST_FITNESS
        ):
            levels[i] += 2 * n
    return levels


def sort_by_objectives(
    individuals: Sequence[Individual], objectives: Sequence[Objective], levels: np.ndarray
) -> list[int]:
    """The seed's ordering (§2.7): level, then objectives by importance, then age, then newest id.

    Returns
    -------
    list of int
        Indices into ``individuals``, best first.
    """
    idx = list(range(len(individuals)))
    idx.sort(key=lambda i: individuals[i].id, reverse=True)
    idx.sort(key=lambda i: individuals[i].age)
    for o in reversed(objectives):
        idx.sort(key=lambda i, o=o: individuals[i].value(o.name), reverse=o.maximize)
    idx.sort(key=lambda i: levels[i])
    return idx


def sel_pareto(
    individuals: Sequence[Individual],
    k: int,
    objectives: Sequence[Objective],
    rng: np.random.Generator | int | None = None,
) -> list[Individual]:
    """The seed's Pareto selection (evosoro ``pareto_selection``, §2.7).

    Levels are filled in order; when a level does not fit, its best-sorted
    member is taken, then members ``i >= 1`` are drawn with ``r ~ U(0, 1)``
    and ``log(i) / log(n) <= r < log(i + 1) / log(n)`` (biased towards the
    front of the level) until the population is full. Add ``Objective("age",
    maximize=False)`` for age-fitness Pareto.

    Returns
    -------
    list of Individual
        ``k`` individuals.
    """
    rng = _rng(rng)
    k = min(int(k), len(individuals))
    levels = pareto_levels(individuals, objectives)
    ordered = sort_by_objectives(individuals, objectives, levels)
    chosen: list[int] = []
    for level in sorted(set(levels.tolist())):
        this = [i for i in ordered if levels[i] == level]
        if len(chosen) + len(this) <= k:
            chosen += this
        else:
            chosen.append(this[0])
            n = len(this)
            log_n = math.log(n)
            while len(chosen) < k:
                r = float(rng.random())
                for i in range(1, n):
                    if math.log(i) / log_n <= r < math.log(i + 1) / log_n and this[i] not in chosen:
                        chosen.append(this[i])
                        break
        if len(chosen) >= k:
            break
    return [individuals[i] for i in chosen[:k]]


def sel_fitness_tournament(
    individuals: Sequence[Individual],
    k: int,
    objective: str = "norm_final_dist",
    rng: np.random.Generator | int | None = None,
    tournsize: int = 2,
) -> list[Individual]:
    """The seed's fitness tournament (§3.3): remove tournament losers until ``k`` remain.

    While more than ``k`` individuals remain, ``tournsize`` distinct random
    ones are drawn and the one with the lowest ``objective`` (maximised) is
    removed (the first drawn on ties).
    """
    rng = _rng(rng)
    pop = list(individuals)
    while len(pop) > k:
        picks = rng.choice(len(pop), size=min(tournsize, len(pop)), replace=False)
        worst = int(picks[0])
        for p in picks[1:]:
            if pop[int(p)].value(objective) < pop[worst].value(objective):
                worst = int(p)
        del pop[worst]
    return pop


def sel_novelty(
    individuals: Sequence[Individual],
    k: int,
    archive: NoveltyArchive | None = None,
    time_scale: float | None = None,
) -> list[Individual]:
    """AMSS novelty selection (§3.4): keep the ``k`` lowest similarity scores.

    ``archive=None`` is the seed's variant: ``S_i = sum_j AMSS(T_i, T_j)``
    over the current individuals, kept with ``argpartition`` (no memory).
    With a :class:`~softgym.metrics.NoveltyArchive`, scores are k-nearest
    neighbours over the population and the archive, and the archive is
    updated with the most novel trajectories. Sets ``ind.novelty``.
    """
    trajs = [ind.trace for ind in individuals]
    if archive is None:
        scores = novelty_scores(trajs, "seed", time_scale=time_scale)
    else:
        scores = archive.score(trajs)
    for ind, s in zip(individuals, scores):
        ind.novelty = float(s)
    k = min(int(k), len(individuals))
    if k == len(individuals):
        keep = np.arange(k)
    else:
        keep = np.sort(np.argpartition(scores, k - 1, kind="introselect")[:k])
    chosen = [individuals[int(i)] for i in keep]
    if archive is not None:
        archive.update(
            [ind.trace for ind in chosen], scores=np.array([ind.novelty for ind in chosen])
        )
    return chosen


def sel_nsga2(
    individuals: Sequence[Individual], k: int, objectives: Sequence[Objective]
) -> list[Individual]:
    """NSGA-II survival (non-dominated sorting + crowding distance) through DEAP's ``selNSGA2``."""
    from deap import base, tools

    weights = tuple(1.0 if o.maximize else -1.0 for o in objectives)
    fitness_cls = type("_Fitness", (base.Fitness,), {"weights": weights})

    class _Wrap:
        __slots__ = ("fitness", "ind")

        def __init__(self, ind: Individual) -> None:
            self.ind = ind
            self.fitness = fitness_cls(tuple(ind.value(o.name) for o in objectives))

    wrapped = [_Wrap(ind) for ind in individuals]
    return [w.ind for w in tools.selNSGA2(wrapped, min(int(k), len(wrapped)))]


def _by_name() -> dict[str, Callable[..., list[Individual]]]:
    def pareto(inds, k, objectives, rng, archive):
        return sel_pareto(inds, k, objectives, rng)

    def tournament(inds, k, objectives, rng, archive):
        return sel_fitness_tournament(inds, k, objectives[0].name, rng)

    def novelty(inds, k, objectives, rng, archive):
        return sel_novelty(inds, k)

    def novelty_archive(inds, k, objectives, rng, archive):
        return sel_novelty(inds, k, archive=archive)

    def nsga2(inds, k, objectives, rng, archive):
        return sel_nsga2(inds, k, objectives)

    return {"pareto": pareto, "tournament": tournament, "novelty": novelty,
            "novelty-archive": novelty_archive, "nsga2": nsga2}  # fmt: skip


#: The selections an experiment names (``Experiment.selection``), each as
#: ``sel(individuals, k, objectives, rng, archive)`` (the tournament reads the first
#: objective; ``novelty-archive`` scores against ``archive``). One registry: the
#: native driver selects through it and experiments validate against it.
SELECTORS: dict[str, Callable[..., list[Individual]]] = _by_name()


def select(
    name: str,
    individuals: list[Individual],
    k: int,
    objectives: Sequence[Objective],
    rng: np.random.Generator | int | None = None,
    archive: NoveltyArchive | None = None,
) -> list[Individual]:
    """Select ``k`` of ``individuals`` with the selection called ``name`` (:data:`SELECTORS`).

    Raises
    ------
    InvalidParameterError
        If ``name`` is not a selection.
    """
    if name not in SELECTORS:
        raise InvalidParameterError(f"unknown selection {name!r}; expected one of {tuple(SELECTORS)}")
    return SELECTORS[name](individuals, k, objectives, rng, archive)
