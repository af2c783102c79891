"""The seed's experiments in DEAP's idiom: creator, Toolbox, sel*/mut*/mate, Statistics, Logbook, HallOfFame.

:func:`make_toolbox` builds a standard DEAP toolbox for an experiment::

    toolbox = make_toolbox(get_experiment("controller-pareto"), rng=0)
    pop = toolbox.population(n=15)
    fits = toolbox.map(toolbox.evaluate, pop)          # ONE batched Simulation
    for ind, fit in zip(pop, fits):
        ind.fitness.values = fit
    pop = toolbox.select(pop + offspring, 15)          # selPareto / tools.selNSGA2 / ...

Individuals are ``creator.Softbot`` (an :class:`~evolvers.operators.genome.Individual`
with a ``fitness``). ``toolbox.map`` is batched: given ``toolbox.evaluate``
it evaluates the whole list in one Simulation (or over Dask), other functions
are mapped normally. DEAP's global ``random`` is seeded from the run's numpy
Generator (it is used by ``tools.selTournament``); both states are saved in
checkpoints. :class:`DeapRun` is a resumable run of the seed's loop built on
that toolbox.
"""

from __future__ import annotations

import random
from collections.abc import Callable, Iterable
from dataclasses import fields
from functools import partial
from typing import Any

import numpy as np

from evolvers.drivers.base import IdCounter
from evolvers.drivers.runner import EvolutionRun
from evolvers.evaluation.evaluator import BatchFn, EvalStats, Evaluator
from evolvers.evaluation.experiments import Experiment
from evolvers.operators.genome import Individual
from evolvers.operators.selection import sel_fitness_tournament, sel_novelty, sel_pareto
from evolvers.operators.variation import (
    cx_arithmetic,
    mut_brain,
    mut_controller,
    mut_cppn,
    mut_materials,
)

__all__ = ["BatchedMap", "DeapRun", "as_softbot", "make_toolbox", "softbot_classes"]


def softbot_classes(experiment: Experiment) -> tuple[type, type]:
    """``(Fitness, Individual)`` classes made with ``deap.creator`` for an experiment's objectives.

    The fitness weights are +1 for maximised and -1 for minimised objectives;
    classes are created once per weight tuple (``creator`` is global).
    """
    from deap import base, creator

    weights = tuple(1.0 if o.maximize else -1.0 for o in experiment.objectives)
    tag = "".join("M" if w > 0 else "m" for w in weights)
    fit_name, ind_name = f"FitnessSoftbot_{tag}", f"Softbot_{tag}"
    if not hasattr(creator, fit_name):
        creator.create(fit_name, base.Fitness, weights=weights)
    if not hasattr(creator, ind_name):
        creator.create(ind_name, Individual, fitness=getattr(creator, fit_name))
    return getattr(creator, fit_name), getattr(creator, ind_name)


#: The genome's fields a Softbot copies (the grid cache is rebuilt).
_GENOME_FIELDS = tuple(f.name for f in fields(Individual) if not f.name.startswith("_"))


def as_softbot(Softbot: type, ind: Individual) -> Individual:
    """``ind`` as a ``Softbot`` of :func:`softbot_classes` (the same genome, results and brain)."""
    if isinstance(ind, Softbot):
        return ind
    return Softbot(**{name: getattr(ind, name) for name in _GENOME_FIELDS})


class _BatchEvaluate:
    """``toolbox.evaluate``: one individual, or a batch through :meth:`batch`."""

    def __init__(self, evaluator: Evaluator) -> None:
        self.evaluator = evaluator
        self.last_stats = EvalStats()

    def fitness_of(self, ind: Individual) -> tuple[float, ...]:
        return tuple(ind.value(o.name) for o in self.evaluator.experiment.objectives)

    def batch(self, individuals: list[Individual]) -> list[tuple[float, ...]]:
        self.last_stats = self.evaluator.evaluate(individuals)
        return [self.fitness_of(ind) for ind in individuals]

    def __call__(self, ind: Individual) -> tuple[float, ...]:
        return self.batch([ind])[0]


class BatchedMap:
    """A ``toolbox.map`` that evaluates a whole population at once.

    ``map(toolbox.evaluate, individuals)`` calls the evaluator once with the
    list (one batched Simulation, or one Dask round); any other function is
    mapped one item at a time like the builtin ``map``.
    """

    def __call__(self, func: Callable[..., Any], iterable: Iterable[Any]) -> list[Any]:
        """``map(func, iterable)`` as a list; batched when ``func`` is ``toolbox.evaluate``."""
        target = func
        while isinstance(target, partial):
            target = target.func
        items = list(iterable)
        if isinstance(target, _BatchEvaluate):
            return target.batch(items)
        return [func(x) for x in items]


def make_toolbox(
    experiment: Experiment,
    rng: np.random.Generator | int | None = None,
    batch_fn: BatchFn | None = None,
    n_threads: int | None = None,
    evaluator: Evaluator | None = None,
    next_id: Callable[[], int] | None = None,
    archive: Any = None,
    seed_python_random: bool = True,
):
    """A DEAP toolbox for an experiment.

    Registered: ``individual``, ``population`` (``tools.initRepeat``),
    ``evaluate`` (batched through ``map``), ``map`` (:class:`BatchedMap`),
    ``clone``, ``mutate`` (CPPN mutation with validity retries; none on a
    fixed body), ``mutate_genes`` (the controller / material / brain-weight
    Gaussian mutation the experiment evolves),
    ``mate`` (the seed's arithmetic crossover over a list of children and
    the parents), ``selPareto``, ``selFitnessTournament``, ``selNovelty``,
    ``selNSGA2`` (``tools.selNSGA2``), ``selTournament``
    (``tools.selTournament``, size 2) and ``select`` (the experiment's).

    Parameters
    ----------
    experiment : Experiment
    rng : numpy.random.Generator, int or None
        Randomness of our operators; Python's ``random`` is seeded from it.
    batch_fn, n_threads, evaluator
        Evaluation (see :class:`~evolvers.evaluation.evaluator.Evaluator`).
    next_id : callable, optional
        Id source (default: a counter from 0).
    archive : NoveltyArchive, optional
        For ``novelty-archive``.
    seed_python_random : bool
        Seed Python's ``random`` (DEAP's randomness) from ``rng``.

    Returns
    -------
    deap.base.Toolbox
    """
    from deap import base, tools

    rng = rng if isinstance(rng, np.random.Generator) else np.random.default_rng(rng)
    if seed_python_random:
        random.seed(int(rng.integers(2**62)))
    _, Softbot = softbot_classes(experiment)
    exp = experiment
    if next_id is None:
        next_id = IdCounter()
    evaluator = evaluator or Evaluator(exp, batch_fn=batch_fn, n_threads=n_threads)

    def individual() -> Individual:
        return as_softbot(Softbot, exp.random_individual(rng, next_id()))

    def clone(ind: Individual) -> Individual:
        return as_softbot(Softbot, ind.child(next_id()))

    def mutate(ind: Individual) -> tuple[Individual]:
        if exp.evolve_body:
            mut_cppn(ind, rng, shape=exp.shape, rules=exp.rules)
        return (ind,)

    def mutate_genes(ind: Individual) -> tuple[Individual]:
        if exp.evolve_controller:
            mut_controller(ind, rng)
        if exp.evolve_materials:
            mut_materials(ind, rng)
        if exp.evolve_brain:
            mut_brain(ind, rng)
        return (ind,)

    toolbox = base.Toolbox()
    toolbox.register("individual", individual)
    toolbox.register("population", tools.initRepeat, list, toolbox.individual)
    toolbox.register("evaluate", _BatchEvaluate(evaluator))
    toolbox.register("map", BatchedMap())
    toolbox.register("clone", clone)
    toolbox.register("mutate", mutate)
    toolbox.register("mutate_genes", mutate_genes)
    toolbox.register(
        "mate", cx_arithmetic, rng=rng, rate=exp.crossover_rate,
        controller=exp.evolve_controller, materials=exp.evolve_materials, brain=exp.evolve_brain,
    )  # fmt: skip
    toolbox.register("selPareto", sel_pareto, objectives=exp.objectives, rng=rng)
    toolbox.register(
        "selFitnessTournament", sel_fitness_tournament, objective=exp.fitness.name, rng=rng
    )
    toolbox.register("selNovelty", sel_novelty, archive=archive)
    toolbox.register("selNSGA2", tools.selNSGA2)
    toolbox.register("selTournament", tools.selTournament, tournsize=2)
    chosen = {
        "pareto": toolbox.selPareto,
        "tournament": toolbox.selFitnessTournament,
        "novelty": toolbox.selNovelty,
        "novelty-archive": toolbox.selNovelty,
        "nsga2": toolbox.selNSGA2,
    }[exp.selection]
    toolbox.register("select", chosen)
    toolbox.evaluator = evaluator
    toolbox.rng = rng
    return toolbox


def _stats(experiment: Experiment):
    from deap import tools

    stats = tools.Statistics(key=lambda ind: ind.fitness.values)
    stats.register("max", lambda v: np.asarray(v).max(axis=0).tolist())
    stats.register("median", lambda v: np.median(np.asarray(v), axis=0).tolist())
    stats.register("mean", lambda v: np.asarray(v).mean(axis=0).tolist())
    stats.register("min", lambda v: np.asarray(v).min(axis=0).tolist())
    return stats


class DeapRun(EvolutionRun):
    """The seed's loop written with a DEAP toolbox (see :func:`make_toolbox`).

    Same run folder, log, checkpoints and exact resume as
    :class:`~evolvers.drivers.runner.EvolutionRun`; variation, evaluation and
    selection go through ``toolbox.clone / mutate / mate / map / select``,
    with ``tools.Statistics``, ``tools.Logbook`` and ``tools.HallOfFame``.
    """

    backend = "deap"

    def _setup_backend(self) -> None:
        from deap import tools

        self.toolbox = make_toolbox(
            self.experiment, rng=self.rng, evaluator=self.evaluator,
            next_id=self.next_id, archive=self.archive,
        )  # fmt: skip
        self.stats = _stats(self.experiment)
        self.logbook = tools.Logbook()
        self.logbook.header = ["gen", "nevals", *self.stats.fields]
        self.hof = tools.HallOfFame(5)
        _, self.Softbot = softbot_classes(self.experiment)

    def _rebuild_toolbox(self) -> None:
        # after a restore the rng object is new: re-bind the operators to it
        self.toolbox = make_toolbox(
            self.experiment, rng=self.rng, evaluator=self.evaluator,
            next_id=self.next_id, archive=self.archive, seed_python_random=False,
        )  # fmt: skip

    def _random_individual(self) -> Individual:
        return self.toolbox.individual()

    def _as_softbot(self, ind: Individual) -> Individual:
        return as_softbot(self.Softbot, ind)

    def _from_dict(self, data: dict[str, Any]) -> Individual:
        ind = self._as_softbot(Individual.from_dict(data))
        if ind.objectives:
            ind.fitness.values = tuple(ind.value(o.name) for o in self.experiment.objectives)
        return ind

    def _evaluate(self, individuals: list[Individual]) -> EvalStats:
        fits = self.toolbox.map(self.toolbox.evaluate, individuals)
        for ind, fit in zip(individuals, fits):
            ind.fitness.values = fit
        stats = self.toolbox.evaluate.func.last_stats
        self.hof.update(individuals)
        record = self.stats.compile(individuals)
        self.logbook.record(gen=self.generation + 1, nevals=stats.n_simulated, **record)
        return stats

    def _vary(self, parents: list[Individual]) -> list[Individual]:
        order = self.rng.permutation(len(parents))
        children = []
        for i in order:
            child = self.toolbox.clone(parents[int(i)])
            (child,) = self.toolbox.mutate(child)
            children.append(child)
        exp = self.experiment
        if exp.evolve_controller or exp.evolve_materials or exp.evolve_brain:
            self.toolbox.mate(children, parents)
            for child in children:
                self.toolbox.mutate_genes(child)
        return children

    def _select(self, individuals: list[Individual], k: int) -> list[Individual]:
        return list(self.toolbox.select(individuals, k))

    def _restore_backend_state(self, state: dict[str, Any]) -> None:
        self._rebuild_toolbox()
