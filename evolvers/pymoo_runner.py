"""The seed's experiments in pymoo's idiom: a Problem, custom operators, NSGA2 through ``minimize``.

* :class:`SoftbotProblem`: one object variable per solution (an
  :class:`~evolvers.genome.Individual`); the vectorised ``_evaluate`` scores the
  whole population in one batched Simulation and fills ``out["F"]`` (every
  objective minimised: maximised ones negated) and ``out["G"]`` (the
  experiment's composition rules as ``needed - count``, feasible when <= 0).
* :class:`SoftbotSampling` (random valid CPPN robots),
  :class:`SoftbotCrossover` (the seed's arithmetic crossover of controller /
  material genes, probability 0.4), :class:`SoftbotMutation` (CPPN mutation
  with validity retries + bounded Gaussian gene mutation) and
  :class:`SoftbotDuplicateElimination` (same phenotype hash).
* :class:`PymooRun`: ``NSGA2(...)`` run by ``pymoo.optimize.minimize`` with a
  :class:`~pymoo.core.callback.Callback` that logs and checkpoints every
  generation; resume restores the population, its rank / crowding and the
  algorithm's random state without pickle.

Differences from the seed's loop (inherent to NSGA2): survival is rank and
crowding (whatever the experiment's ``selection``), no random newcomer joins
each generation, the age objective is the age at evaluation, and novelty
experiments score against an archive of past behaviours.
"""

from __future__ import annotations

import math
import time
from typing import Any

import numpy as np
from pymoo.core.callback import Callback
from pymoo.core.crossover import Crossover
from pymoo.core.duplicate import ElementwiseDuplicateElimination
from pymoo.core.mutation import Mutation
from pymoo.core.population import Population
from pymoo.core.problem import Problem
from pymoo.core.sampling import Sampling

from evolvers.evaluation import EvalStats, Evaluator, pack_traces, unpack_traces
from evolvers.experiments import Experiment
from evolvers.genome import Individual
from evolvers.operators import _counterphase, mut_controller, mut_cppn, mut_materials
from evolvers.runner import EvolutionRun, population_summary
from evolvers.selection import minimised_matrix
from softgym.design import CompositionRules, Controller
from softgym.exceptions import CheckpointError
from softgym.io import rng_state, save_checkpoint
from softgym.metrics import NoveltyArchive

__all__ = [
    "PymooRun",
    "SoftbotCrossover",
    "SoftbotDuplicateElimination",
    "SoftbotMutation",
    "SoftbotProblem",
    "SoftbotSampling",
    "constraint_values",
    "n_constraints",
]


def _need(fraction: float, total: int) -> int:
    return max(0, math.ceil(fraction * total - 1e-9))


def n_constraints(rules: CompositionRules) -> int:
    """Number of inequality constraints :func:`constraint_values` returns for ``rules``."""
    return len(constraint_values(np.ones((1, 1, 1), dtype=np.int8), rules))


def constraint_values(grid: np.ndarray, rules: CompositionRules) -> np.ndarray:
    """Composition rules as pymoo inequality constraints (feasible when every value <= 0).

    One value per active rule, ``needed - count`` in voxels: filled
    fraction of the grid, muscle fraction of the grid, muscle and tissue
    fractions of the filled voxels, bone voxels.

    Returns
    -------
    ndarray of shape (n_constraints,), float64
    """
    grid = np.asarray(grid)
    total, filled = grid.size, int(np.count_nonzero(grid))
    n_muscle = int(np.isin(grid, rules.muscle_ids).sum())
    n_tissue = int(np.isin(grid, rules.tissue_ids).sum())
    n_bone = int(np.isin(grid, rules.bone_ids).sum())
    g = []
    if rules.min_filled_fraction > 0:
        g.append(_need(rules.min_filled_fraction, total) - filled)
    if rules.min_muscle_fraction_of_grid > 0:
        g.append(_need(rules.min_muscle_fraction_of_grid, total) - n_muscle)
    if rules.min_muscle_fraction_of_filled > 0:
        g.append(_need(rules.min_muscle_fraction_of_filled, filled) - n_muscle)
    if rules.min_tissue_fraction_of_filled > 0:
        g.append(_need(rules.min_tissue_fraction_of_filled, filled) - n_tissue)
    if rules.min_bone_voxels > 0:
        g.append(rules.min_bone_voxels - n_bone)
    g.append(0 if filled else 1)  # non-empty
    return np.asarray(g, dtype=np.float64)


class _Ids:
    """A shared id counter (part of the checkpointed state)."""

    def __init__(self, start: int = 0) -> None:
        self.value = int(start)

    def __call__(self) -> int:
        v = self.value
        self.value += 1
        return v


class SoftbotProblem(Problem):
    """A soft-robot experiment as a pymoo Problem (one object variable per solution).

    Parameters
    ----------
    experiment : Experiment
    evaluator : Evaluator
        Batched, cached evaluation (one Simulation per call, or Dask).
    archive : NoveltyArchive, optional
        For novelty experiments: ``F`` is the k-nearest-neighbour AMSS
        similarity to the batch and the archive (minimised).
    """

    def __init__(
        self, experiment: Experiment, evaluator: Evaluator, archive: NoveltyArchive | None = None
    ) -> None:
        self.experiment = experiment
        self.evaluator = evaluator
        self.archive = archive
        self.novelty = experiment.selection.startswith("novelty")
        self.last_stats = EvalStats()
        n_obj = 1 if self.novelty else len(experiment.objectives)
        super().__init__(
            n_var=1, n_obj=n_obj, n_ieq_constr=n_constraints(experiment.rules), vtype=object
        )

    def _evaluate(self, X, out, *args, **kwargs):
        inds = [x[0] for x in X]
        self.last_stats = self.evaluator.evaluate(inds)
        if self.novelty:
            trajs = [ind.trace for ind in inds]
            scores = self.archive.update(trajs) if self.archive is not None else np.zeros(len(inds))
            for ind, s in zip(inds, scores):
                ind.novelty = float(s)
            out["F"] = np.asarray(scores, dtype=np.float64).reshape(-1, 1)
        else:
            out["F"] = minimised_matrix(inds, self.experiment.objectives)
        exp = self.experiment
        out["G"] = np.array([constraint_values(ind.grid(exp.shape), exp.rules) for ind in inds])


class SoftbotSampling(Sampling):
    """Random valid individuals (the seed's generation 0)."""

    def __init__(self, experiment: Experiment, next_id: Any) -> None:
        super().__init__()
        self.experiment = experiment
        self.next_id = next_id

    def _do(self, problem, n_samples, *args, random_state=None, **kwargs):
        exp = self.experiment
        X = np.empty((n_samples, 1), dtype=object)
        for i in range(n_samples):
            X[i, 0] = Individual.random(
                random_state, self.next_id(), exp.shape, exp.cppn_outputs, exp.rules
            )
        return X


class SoftbotCrossover(Crossover):
    """The seed's arithmetic crossover: a child of parent A with the mean genes of A and B.

    Controller genes (and material genes 6-8, 9 as the counter-phase of 8)
    are averaged; the CPPN is A's. Applied with probability ``prob`` (0.4).
    """

    def __init__(self, experiment: Experiment, next_id: Any, prob: float | None = None) -> None:
        super().__init__(2, 1, prob=experiment.crossover_rate if prob is None else prob)
        self.experiment = experiment
        self.next_id = next_id

    def _do(self, problem, X, *args, random_state=None, **kwargs):
        _, n_matings, _ = X.shape
        Q = np.empty((1, n_matings, 1), dtype=object)
        for k in range(n_matings):
            a, b = X[0, k, 0], X[1, k, 0]
            child = a.child(self.next_id())
            if self.experiment.evolve_controller:
                ca, cb = a.controller, b.controller
                child.controller = Controller.clipped(
                    (ca.temp_amplitude + cb.temp_amplitude) / 2.0,
                    (ca.period + cb.period) / 2.0,
                    (ca.muscle_cte + cb.muscle_cte) / 2.0,
                )
            if self.experiment.evolve_materials:
                child.materials[:3] = (a.materials[:3] + b.materials[:3]) / 2.0
                _counterphase(child.materials)
            Q[0, k, 0] = child
        return Q


class SoftbotMutation(Mutation):
    """CPPN mutation with validity retries, then bounded Gaussian controller / material mutation.

    Evaluated individuals (parents copied through by the crossover) are
    cloned first, so parents are never modified.
    """

    def __init__(self, experiment: Experiment, next_id: Any) -> None:
        super().__init__(prob=1.0)
        self.experiment = experiment
        self.next_id = next_id

    def _do(self, problem, X, *args, random_state=None, **kwargs):
        exp = self.experiment
        Y = np.empty_like(X)
        for i in range(len(X)):
            ind = X[i, 0]
            child = ind.child(self.next_id()) if ind.objectives else ind
            child.age = ind.age + 1
            mut_cppn(child, random_state, shape=exp.shape, rules=exp.rules)
            if exp.evolve_controller:
                mut_controller(child, random_state)
            if exp.evolve_materials:
                mut_materials(child, random_state)
            Y[i, 0] = child
        return Y


class SoftbotDuplicateElimination(ElementwiseDuplicateElimination):
    """Two solutions are duplicates when their phenotypes hash equal (grid, materials, controller)."""

    def __init__(self, experiment: Experiment) -> None:
        super().__init__()
        self.shape = experiment.shape

    def is_equal(self, a, b) -> bool:
        """Whether two pymoo individuals hold the same phenotype."""
        return a.X[0].phenotype_key(self.shape) == b.X[0].phenotype_key(self.shape)


class _RunCallback(Callback):
    def __init__(self, run: PymooRun) -> None:
        super().__init__()
        self.run = run

    def notify(self, algorithm) -> None:
        self.run._after_generation(algorithm)


class PymooRun(EvolutionRun):
    """An experiment run with pymoo's NSGA2 through ``minimize`` (see the module docstring).

    Same run folder, log, figures and checkpoints as
    :class:`~evolvers.runner.EvolutionRun`. ``generations`` counts the
    generations after the initial population (pymoo's ``n_gen`` is one more).
    """

    backend = "pymoo"

    def _setup_backend(self) -> None:
        self.ids = _Ids()
        self.next_id = self.ids  # type: ignore[method-assign]
        if self.experiment.selection.startswith("novelty") and self.archive is None:
            self.archive = NoveltyArchive(k=self.experiment.pop_size, n_add=2, variant="normalized")
        self._t0 = time.perf_counter()
        self._resume_state: tuple[dict[str, Any], dict[str, np.ndarray]] | None = None

    def _algorithm(self):
        from pymoo.algorithms.moo.nsga2 import NSGA2

        exp = self.experiment
        return NSGA2(
            pop_size=exp.pop_size,
            n_offsprings=exp.pop_size,
            sampling=SoftbotSampling(exp, self.ids),
            crossover=SoftbotCrossover(exp, self.ids),
            mutation=SoftbotMutation(exp, self.ids),
            eliminate_duplicates=SoftbotDuplicateElimination(exp),
        )

    def _problem(self) -> SoftbotProblem:
        return SoftbotProblem(self.experiment, self.evaluator, self.archive)

    def run(self, resume: bool = False) -> list[Individual]:
        """Run NSGA2 through ``minimize`` (or continue it from the last checkpoint)."""
        from pymoo.optimize import minimize

        if not (resume and self.resume()):
            self.start()
        termination = ("n_gen", self.generations + 1)
        problem = self._problem()
        self._t0 = time.perf_counter()
        if self.generation < 0:
            minimize(
                problem, self._algorithm(), termination, seed=self.seed,
                callback=_RunCallback(self), verbose=False, copy_algorithm=False,
            )  # fmt: skip
        elif self.generation < self.generations:
            algorithm = self._algorithm()
            algorithm.setup(
                problem,
                termination=termination,
                seed=self.seed,
                callback=_RunCallback(self),
                verbose=False,
            )
            self._restore_algorithm(algorithm)
            algorithm.run()
        self.finish()
        return self.population

    # ------------------------------------------------------------------ callback
    def _after_generation(self, algorithm) -> None:
        self.algorithm = algorithm
        self.generation = int(algorithm.n_iter) - 1
        self.population = [x[0] for x in algorithm.pop.get("X")]
        stats = algorithm.problem.last_stats
        wall = time.perf_counter() - self._t0
        self._t0 = time.perf_counter()
        off = [
            x[0] for x in (algorithm.off if algorithm.off is not None else algorithm.pop).get("X")
        ]
        self._update_hall_of_fame(off)
        self._end_generation(stats, wall)

    # ------------------------------------------------------------------ checkpoints
    def checkpoint(self):
        """Population (genomes, F, G, CV, rank, crowding), RNG and counters; no pickle."""
        alg = self.algorithm
        pop = alg.pop
        data, lengths = pack_traces([ind.trace for ind in self.population])
        arrays = {
            "pop_traces": data, "pop_trace_len": lengths,
            "F": pop.get("F"), "G": pop.get("G"), "CV": pop.get("CV"),
            "rank": np.asarray(pop.get("rank"), dtype=np.float64),
            "crowding": np.asarray(pop.get("crowding"), dtype=np.float64),
            **self.evaluator.cache.to_arrays(),
        }  # fmt: skip
        state = {
            "generation": self.generation,
            "population": population_summary(self.population),
            "rng": rng_state(alg.random_state),
            "next_id": self.ids.value,
            "rows": self.rows,
            "hall_of_fame": self.hall_of_fame,
            "archive": None if self.archive is None else self.archive.to_dict(),
            "evaluations_total": self.evaluations_total,
            "n_eval": int(alg.evaluator.n_eval),
            "wall_total": self.wall_total,
            "python_random": None,
        }
        return save_checkpoint(self.checkpoint_dir, self.generation, state, arrays, keep=3)

    def _restore(self, state: dict[str, Any], arrays: dict[str, np.ndarray]) -> None:
        try:
            self.generation = int(state["generation"])
            self.population = [Individual.from_dict(d) for d in state["population"]]
            for ind, tr in zip(
                self.population, unpack_traces(arrays["pop_traces"], arrays["pop_trace_len"])
            ):
                ind.trace = tr
            self.ids.value = int(state["next_id"])
            self.rows = list(state["rows"])
            self.hall_of_fame = list(state["hall_of_fame"])
            if state.get("archive") is not None:
                self.archive = NoveltyArchive.from_dict(state["archive"])
            self.evaluations_total = int(state["evaluations_total"])
            self.wall_total = float(state["wall_total"])
            from evolvers.evaluation import PhenotypeCache

            self.evaluator.cache = PhenotypeCache.from_arrays(arrays)
            self._resume_state = (state, arrays)
        except (KeyError, TypeError, ValueError) as exc:
            raise CheckpointError(
                f"{self.checkpoint_dir}: checkpoint content is invalid ({exc!r})"
            ) from exc

    def _restore_algorithm(self, algorithm) -> None:
        state, arrays = self._resume_state  # type: ignore[misc]
        X = np.empty((len(self.population), 1), dtype=object)
        for i, ind in enumerate(self.population):
            X[i, 0] = ind
        pop = Population.new("X", X)
        pop.set("F", arrays["F"], "G", arrays["G"], "CV", arrays["CV"])
        pop.set("rank", arrays["rank"].astype(int), "crowding", arrays["crowding"])
        for ind in pop:
            ind.evaluated = {"F", "G", "H", "CV"}
        algorithm._initialize()
        algorithm.pop = pop
        algorithm.off = None
        algorithm.is_initialized = True
        algorithm.n_iter = self.generation + 2
        algorithm.evaluator.n_eval = int(state["n_eval"])
        algorithm.random_state.bit_generator.state = state["rng"]
        algorithm._set_optimum()
        self.algorithm = algorithm
