"""Evolve soft robots as the seed study did, in one folder per job (each imports only those above it).

* :mod:`evolvers.operators` - the genome and what a search does to it:
  :class:`Individual` (:mod:`~evolvers.operators.genome`: CPPN + material genes +
  controller genes + age + lineage), crossover and mutations
  (:mod:`~evolvers.operators.variation`), the seed's Pareto (with age), NSGA-II, fitness
  tournament and AMSS novelty (:mod:`~evolvers.operators.selection`).
* :mod:`evolvers.evaluation` - what a robot is scored on and how: :data:`EXPERIMENTS`
  (:mod:`~evolvers.evaluation.experiments`: the seed's scenarios by name),
  :class:`Evaluator` (:mod:`~evolvers.evaluation.evaluator`: batched, phenotype-cached
  evaluation), Dask evaluation (:mod:`~evolvers.evaluation.distributed`,
  ``pip install "softgym[distributed]"``) and body descriptors
  (:mod:`~evolvers.evaluation.descriptors`).
* :mod:`evolvers.recording` - the run folder: one :class:`RunRecorder` (config, log, hall
  of fame, atomic checkpoints, figures) for every driver.
* :mod:`evolvers.drivers` - drivers with exact resume, each a
  :class:`~evolvers.drivers.base.Driver` (the one run skeleton: construction, generation
  loop, progress, Ctrl-C, checkpoint, resume; a :class:`Budget` of simulations,
  robot-seconds, wall time or a target score besides the generations):
  :class:`EvolutionRun` (the seed's loop),
  :class:`~evolvers.drivers.deap_runner.DeapRun` (the same loop on a DEAP toolbox),
  :class:`~evolvers.drivers.pymoo_runner.PymooRun` (any pymoo algorithm through ask and
  tell: NSGA-II, NSGA-III, SMS-EMOA, GA, CMA-ES...),
  :class:`~evolvers.drivers.random_search.RandomSearchRun` (random search); open-ended search:
  :mod:`~evolvers.drivers.qd` (MAP-Elites on pyribs) and :mod:`~evolvers.drivers.poet`
  (co-evolution of robots and terrains after Enhanced POET).
* :mod:`evolvers.study` - the seed study over many seeds and its report (nothing else
  imports it).

The DEAP, pymoo and Dask modules are imported on demand (``from evolvers.drivers.deap_runner import DeapRun``).
"""

from evolvers.drivers.base import Driver, IdCounter
from evolvers.drivers.budget import Budget
from evolvers.drivers.runner import EvolutionRun
from evolvers.evaluation.evaluator import Evaluator, PhenotypeCache
from evolvers.evaluation.experiments import (
    EXPERIMENTS,
    Experiment,
    get_experiment,
    list_experiments,
)
from evolvers.operators.genome import Individual
from evolvers.operators.selection import (
    Objective,
    sel_fitness_tournament,
    sel_novelty,
    sel_nsga2,
    sel_pareto,
)
from evolvers.operators.variation import (
    cx_arithmetic,
    make_children,
    mut_controller,
    mut_cppn,
    mut_materials,
)
from evolvers.recording.recorder import RunRecorder

__all__ = [
    "EXPERIMENTS",
    "Budget",
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
