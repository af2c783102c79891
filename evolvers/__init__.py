"""Evolve soft robots as the seed study did: genomes, operators, selections, runners.

* :class:`Individual` (:mod:`evolvers.genome`): CPPN + material genes + controller genes + age + lineage.
* :mod:`evolvers.operators`: arithmetic crossover, bounded Gaussian mutation, CPPN mutation.
* :mod:`evolvers.selection`: the seed's Pareto (with age), NSGA-II, fitness tournament, AMSS novelty.
* :class:`Evaluator` (:mod:`evolvers.evaluation`): batched, phenotype-cached evaluation.
* :data:`EXPERIMENTS` (:mod:`evolvers.experiments`): the seed's scenarios by name.
* Drivers with exact resume, each a :class:`~evolvers.driver.Driver` (the one run
  skeleton: construction, generation loop, progress, Ctrl-C, checkpoint, resume) writing
  its run folder through one :class:`RunRecorder` (config, log, hall of fame, atomic
  checkpoints, figures): :class:`EvolutionRun` (the seed's loop), :class:`~evolvers.deap_runner.DeapRun`
  (the same loop on a DEAP toolbox), :class:`~evolvers.pymoo_runner.PymooRun`
  (any pymoo algorithm through ask and tell: NSGA-II, NSGA-III, SMS-EMOA, GA...);
  Dask evaluation in :mod:`evolvers.distributed` (``pip install "softgym[distributed]"``).
* Open-ended search: :mod:`evolvers.qd` (MAP-Elites on pyribs) and :mod:`evolvers.poet`
  (co-evolution of robots and terrains after Enhanced POET).

The DEAP, pymoo and Dask modules are imported on demand (``from evolvers.deap_runner import DeapRun``).
"""

from evolvers.driver import Driver, IdCounter
from evolvers.evaluation import Evaluator, PhenotypeCache
from evolvers.experiments import EXPERIMENTS, Experiment, get_experiment, list_experiments
from evolvers.genome import Individual
from evolvers.operators import cx_arithmetic, make_children, mut_controller, mut_cppn, mut_materials
from evolvers.recorder import RunRecorder
from evolvers.runner import EvolutionRun
from evolvers.selection import (
    Objective,
    sel_fitness_tournament,
    sel_novelty,
    sel_nsga2,
    sel_pareto,
)

__all__ = [
    "EXPERIMENTS",
    "Driver",
    "EvolutionRun",
    "Evaluator",
    "Experiment",
    "IdCounter",
    "Individual",
    "Objective",
    "PhenotypeCache",
    "RunRecorder",
    "cx_arithmetic",
    "get_experiment",
    "list_experiments",
    "make_children",
    "mut_controller",
    "mut_cppn",
    "mut_materials",
    "sel_fitness_tournament",
    "sel_novelty",
    "sel_nsga2",
    "sel_pareto",
]
