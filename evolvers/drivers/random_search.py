"""Random search: fresh random genomes every generation, the best kept (the baseline of any search).

Generation 0 and every later generation draw ``pop_size`` fresh random valid genomes of the
experiment's search space (:func:`random_genome`): a random valid CPPN body (the seed's
random individuals; a fixed body stays fixed), and, where the experiment evolves them,
controller genes and material genes uniform within their bounds and a random brain. They
are evaluated in one batched Simulation (phenotype-cached); the population is the
``pop_size`` best found so far by the experiment's fitness (its first objective), so the
log's best column is the best-so-far curve. Nothing is varied and nothing is selected on
but the fitness: whatever a search gains over this run at the same budget of simulations
is what its variation and selection bring.

The loop, checkpoints and exact resume are :class:`~evolvers.drivers.runner.EvolutionRun`'s
(the run's single seeded ``numpy.random.Generator`` draws every genome); ``softgym evolve
--backend random`` runs it.
"""

from __future__ import annotations

import numpy as np

from evolvers.drivers.runner import EvolutionRun
from evolvers.evaluation.evaluator import EvalStats
from evolvers.evaluation.experiments import Experiment
from evolvers.operators.genome import Individual
from evolvers.operators.selection import Objective
from evolvers.operators.variation import MATERIAL_MUTATION, set_counterphase
from softgym.design import CONTROLLER_BOUNDS, Controller

__all__ = ["RandomSearchRun", "keep_best", "random_genome"]


def random_genome(experiment: Experiment, rng: np.random.Generator, id: int) -> Individual:
    """A random individual of ``experiment``'s whole search space.

    :meth:`Experiment.random_individual` (a random valid CPPN, or the fixed body; a random
    brain with a network controller), then, when the experiment evolves them, the
    controller genes uniform within :data:`~softgym.design.CONTROLLER_BOUNDS` (amplitude,
    period, muscle CTE, in that order) and the material genes uniform within the bounds of
    their mutation (:data:`~evolvers.operators.variation.MATERIAL_MUTATION`, in its order;
    material 9 the counter-phase of 8).

    Parameters
    ----------
    experiment : Experiment
    rng : numpy.random.Generator
    id : int
        The individual's id.

    Returns
    -------
    Individual
    """
    ind = experiment.random_individual(rng, id)
    if experiment.evolve_controller:
        values = {
            name: float(rng.uniform(lo, hi)) for name, (lo, hi, _) in CONTROLLER_BOUNDS.items()
        }
        ind.controller = Controller.clipped(**values)
    if experiment.evolve_materials:
        for row, col, _, lo, hi in MATERIAL_MUTATION:
            ind.materials[row, col] = float(rng.uniform(lo, hi))
        set_counterphase(ind.materials)
    return ind


def keep_best(individuals: list[Individual], k: int, fitness: Objective) -> list[Individual]:
    """The ``k`` best of ``individuals`` by ``fitness``, best first (ties: the older id first).

    Parameters
    ----------
    individuals : list of Individual
        Evaluated (``fitness.name`` in their objectives, or ``"age"``).
    k : int
    fitness : Objective

    Returns
    -------
    list of Individual
    """
    sign = -1.0 if fitness.maximize else 1.0
    ranked = sorted(individuals, key=lambda ind: (sign * ind.value(fitness.name), ind.id))
    return ranked[:k]


class RandomSearchRun(EvolutionRun):
    """A resumable random search of an :class:`~evolvers.evaluation.experiments.Experiment`
    (module docstring): ``pop_size`` fresh random genomes a generation, the best kept.

    Parameters: those of :class:`~evolvers.drivers.base.Driver`. The experiment's
    ``selection``, ``n_random`` and ``crossover_rate`` are not used.
    """

    backend = "random"

    def _random_individual(self) -> Individual:
        return random_genome(self.experiment, self.rng, self.next_id())

    def _select(self, individuals: list[Individual], k: int) -> list[Individual]:
        return keep_best(individuals, k, self.experiment.fitness)

    def _generation_zero(self) -> EvalStats:
        self.population = [self._random_individual() for _ in range(self.experiment.pop_size)]
        stats = self._evaluate(self.population)
        self.population = self._select(self.population, len(self.population))
        return stats

    def _next_generation(self) -> EvalStats:
        exp = self.experiment
        for ind in self.population:
            ind.age += 1
        fresh = [self._random_individual() for _ in range(exp.pop_size)]
        stats = self._evaluate(fresh)
        self.recorder.update_hall_of_fame(fresh, self.generation + 1)
        self.population = self._select(self.population + fresh, exp.pop_size)
        return stats
