"""The seed's experiments in pymoo's idiom: a Problem, custom operators, any pymoo algorithm.

* :class:`SoftbotProblem`: one object variable per solution (an
  :class:`~evolvers.operators.genome.Individual`); the vectorised ``_evaluate`` scores the
  whole population in one batched Simulation and fills ``out["F"]`` (every
  objective minimised: maximised ones negated) and ``out["G"]`` (the
  experiment's composition rules as ``needed - count``, feasible when <= 0).
* :class:`SoftbotSampling` (random valid CPPN robots),
  :class:`SoftbotCrossover` (the seed's arithmetic crossover of controller /
  material genes, probability 0.4), :class:`SoftbotMutation` (CPPN mutation
  with validity retries + bounded Gaussian gene mutation) and
  :class:`SoftbotDuplicateElimination` (same phenotype hash).
* ``algorithm="cmaes"``: pymoo's own CMA-ES
  (:class:`pymoo.algorithms.soo.nonconvex.cmaes.CMAES`, which wraps the
  ``cma`` package) over a real vector, on the experiment's fitness:

  - on a CPPN body, :class:`DesignProblem`: the whole robot as one
    :class:`~evolvers.operators.encoding.CPPNVector` (the weights of a
    fixed-topology CPPN, 83 for the 4-output tree; the three controller genes when
    the experiment evolves them; a network's weights when it has one), decoded
    through the CPPN genome; generation 0 is ``pop_size`` uniform vectors that draw
    valid bodies (:class:`DesignSampling`);
  - on a fixed body with a network controller, :class:`BrainProblem`: the brain's
    weights (bounds ``+-WEIGHT_BOUND``), each ``x`` evaluated as the body with
    ``spec.clipped(x)``; generation 0 is ``pop_size`` random brains
    (``BrainSpec.random``).

  The best of generation 0 is CMA-ES's ``x0``. Not for an experiment that evolves
  material genes, nor a fixed body with the sinusoid alone.
* :class:`PymooRun`: a pymoo algorithm (``algorithm=``: NSGA-II by default,
  ``"nsga3"``, ``"sms-emoa"``, ``"ga"``, ``"cmaes"``, or any pymoo algorithm class)
  driven through pymoo's public ask-and-tell interface
  (``algorithm.setup``, ``ask``, ``evaluator.eval``, ``tell``), with the same
  run folder as every driver (:class:`~evolvers.recording.recorder.RunRecorder`).
  Resume is exact: the checkpoint holds every simulated result (the phenotype
  cache), and the run replays its generations from the seed without
  simulating (the algorithm's state is never reached into), then checks that
  it reached the checkpointed population before it goes on.

Differences from the seed's loop (inherent to pymoo's algorithms): survival is
the algorithm's (rank and crowding for NSGA-II, whatever the experiment's
``selection``), no random newcomer joins each generation, the age objective is
the age at evaluation, and novelty experiments score against an archive of
past behaviours.
"""

from __future__ import annotations

import contextlib
import math
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np
from pymoo.core.algorithm import Algorithm
from pymoo.core.crossover import Crossover
from pymoo.core.duplicate import ElementwiseDuplicateElimination
from pymoo.core.mutation import Mutation
from pymoo.core.problem import Problem
from pymoo.core.sampling import Sampling

from evolvers.drivers.base import Checkpoint, Driver, IdCounter
from evolvers.drivers.registry import PYMOO_ALGORITHMS
from evolvers.evaluation.evaluator import EvalStats, Evaluator, pack_traces
from evolvers.evaluation.experiments import Experiment
from evolvers.operators.encoding import CPPNVector
from evolvers.operators.genome import Individual
from evolvers.operators.selection import Objective, minimised_matrix
from evolvers.operators.variation import (
    mut_brain,
    mut_controller,
    mut_cppn,
    mut_materials,
    set_counterphase,
)
from evolvers.recording.rows import population_summary
from softgym.design import CompositionRules, Controller
from softgym.design.brain import WEIGHT_BOUND
from softgym.exceptions import CheckpointError, InvalidParameterError
from softgym.io import rng_state
from softgym.metrics import NoveltyArchive

__all__ = [
    "ALGORITHMS",
    "BrainProblem",
    "BrainSampling",
    "DesignProblem",
    "DesignSampling",
    "MULTI_OBJECTIVE",
    "PymooRun",
    "SoftbotCrossover",
    "SoftbotDuplicateElimination",
    "SoftbotMutation",
    "SoftbotProblem",
    "SoftbotSampling",
    "VectorProblem",
    "constraint_values",
    "design_encoding",
    "make_algorithm",
    "n_constraints",
    "problem_objectives",
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
    objectives : tuple of Objective, optional
        The objectives in ``F`` (default the experiment's; its first alone
        for a single-objective algorithm).
    """

    def __init__(
        self,
        experiment: Experiment,
        evaluator: Evaluator,
        archive: NoveltyArchive | None = None,
        objectives: tuple[Objective, ...] | None = None,
    ) -> None:
        self.experiment = experiment
        self.evaluator = evaluator
        self.archive = archive
        self.objectives = tuple(experiment.objectives if objectives is None else objectives)
        self.novelty = experiment.selection.startswith("novelty")
        self.last_stats = EvalStats()
        n_obj = 1 if self.novelty else len(self.objectives)
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
            out["F"] = minimised_matrix(inds, self.objectives)
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
            X[i, 0] = exp.random_individual(random_state, self.next_id())
        return X


class SoftbotCrossover(Crossover):
    """The seed's arithmetic crossover: a child of parent A with the mean genes of A and B.

    Controller genes (and material genes 6-8, 9 as the counter-phase of 8,
    and brain weights) are averaged; the CPPN is A's. Applied with probability
    ``prob`` (0.4).
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
                set_counterphase(child.materials)
            if self.experiment.evolve_brain and a.brain is not None and b.brain is not None:
                child.brain = np.clip((a.brain + b.brain) / 2.0, -WEIGHT_BOUND, WEIGHT_BOUND)
            Q[0, k, 0] = child
        return Q


class SoftbotMutation(Mutation):
    """CPPN mutation with validity retries (none on a fixed body), then bounded Gaussian
    controller / material / brain-weight mutation.

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
            if exp.evolve_body:
                mut_cppn(child, random_state, shape=exp.shape, rules=exp.rules)
            if exp.evolve_controller:
                mut_controller(child, random_state)
            if exp.evolve_materials:
                mut_materials(child, random_state)
            if exp.evolve_brain:
                mut_brain(child, random_state)
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


class VectorProblem(Problem):
    """A real-valued pymoo Problem whose vectors decode to individuals (CMA-ES's problems).

    ``F`` is the experiment's fitness, minimised (a maximised one negated); each batch is
    one batched Simulation (phenotype-cached). :meth:`individuals` gives the
    :class:`~evolvers.operators.genome.Individual` each evaluated ``x`` became. Subclasses
    set the bounds and :meth:`make`.

    Parameters
    ----------
    experiment : Experiment
    evaluator : Evaluator
    next_id : callable
        Ids of the individuals made.
    xl, xu : ndarray of shape (n_var,), float64
        Bounds of the variables.
    """

    def __init__(self, experiment: Experiment, evaluator: Evaluator, next_id: Any,
                 xl: np.ndarray, xu: np.ndarray) -> None:  # fmt: skip
        self.experiment = experiment
        self.evaluator = evaluator
        self.next_id = next_id
        self.objectives = experiment.objectives[:1]
        self.last_stats = EvalStats()
        self._made: dict[bytes, Individual] = {}
        super().__init__(n_var=len(xl), n_obj=1, xl=xl, xu=xu, vtype=float)

    def make(self, x: np.ndarray) -> Individual:
        """The individual ``x`` decodes to (a fresh id)."""
        raise NotImplementedError

    def _evaluate(self, X, out, *args, **kwargs):
        inds = [self.make(x) for x in np.atleast_2d(np.asarray(X, dtype=np.float64))]
        self.last_stats = self.evaluator.evaluate(inds)
        self._made = {np.asarray(x, dtype=np.float64).tobytes(): ind for x, ind in zip(X, inds)}
        out["F"] = minimised_matrix(inds, self.objectives)

    def individuals(self, X: np.ndarray) -> list[Individual]:
        """The individuals the rows of ``X`` (the last evaluated batch's) became."""
        try:
            return [self._made[np.asarray(x, dtype=np.float64).tobytes()] for x in X]
        except KeyError:
            raise CheckpointError("a CMA-ES solution was not evaluated in the last batch") from None


class BrainProblem(VectorProblem):
    """A brain's weights on an experiment's fixed body, as a real-valued pymoo Problem.

    ``n_var`` is the brain's ``n_params``, every variable in ``[-WEIGHT_BOUND,
    WEIGHT_BOUND]``; ``x`` is evaluated as the fixed body carrying
    ``spec.clipped(x)`` (one batched Simulation per call, phenotype-cached);
    ``F`` is the experiment's fitness, minimised (a maximised one negated).
    :meth:`individuals` gives the :class:`~evolvers.operators.genome.Individual`
    each evaluated ``x`` became.

    Parameters
    ----------
    experiment : Experiment
        With a fixed ``body`` and a network ``controller``.
    evaluator : Evaluator
    next_id : callable
        Ids of the individuals made.
    """

    def __init__(self, experiment: Experiment, evaluator: Evaluator, next_id: Any) -> None:
        spec, body = experiment.brain_spec(), experiment.fixed_body()
        if spec is None or body is None:
            raise InvalidParameterError(
                "CMA-ES searches a brain's weights on a fixed body: the experiment needs "
                "controller='central' or 'distributed' and a body"
            )
        self.spec, self.body = spec, body
        n = spec.n_params
        super().__init__(experiment, evaluator, next_id, np.full(n, -WEIGHT_BOUND),
                         np.full(n, WEIGHT_BOUND))  # fmt: skip

    def make(self, x: np.ndarray) -> Individual:
        """The fixed body carrying the brain ``spec.clipped(x)``."""
        return Individual(
            cppn=None, controller=self.body.controller, id=self.next_id(), body=self.body,
            brain=self.spec.clipped(x).weights, brain_spec=self.spec,
        )  # fmt: skip


class DesignProblem(VectorProblem):
    """A whole robot (body, controller genes, brain) as one real vector: a
    :class:`~evolvers.operators.encoding.CPPNVector` (a fixed-topology CPPN's weights, then
    the controller genes when the experiment evolves them, then the brain's weights when it
    has a network controller), decoded through the CPPN genome.

    A vector whose body breaks the experiment's rules is scored worst, unsimulated (the
    evaluator's rule for every invalid robot), so it costs no simulation.

    Parameters
    ----------
    experiment : Experiment
        With a CPPN body (no fixed ``body``) and no material genes.
    evaluator : Evaluator
    next_id : callable
        Ids of the individuals made.
    """

    def __init__(self, experiment: Experiment, evaluator: Evaluator, next_id: Any) -> None:
        self.encoding = design_encoding(experiment)
        enc = self.encoding
        super().__init__(experiment, evaluator, next_id, enc.lower.copy(), enc.upper.copy())

    def make(self, x: np.ndarray) -> Individual:
        """The robot ``x`` decodes to (:meth:`CPPNVector.individual`)."""
        return self.encoding.individual(x, self.next_id())


def design_encoding(experiment: Experiment) -> CPPNVector:
    """The :class:`~evolvers.operators.encoding.CPPNVector` CMA-ES searches for ``experiment``:
    its CPPN outputs, the controller genes when they evolve, its brain when it has one.

    Raises
    ------
    InvalidParameterError
        For a fixed body (CMA-ES searches its brain instead, :class:`BrainProblem`) or an
        experiment that evolves material genes.
    """
    if experiment.body is not None:
        raise InvalidParameterError(
            "a design vector draws its own body: the experiment has a fixed body "
            "(CMA-ES searches its brain's weights, BrainProblem)"
        )
    if experiment.evolve_materials:
        raise InvalidParameterError(
            f"algorithm 'cmaes' has no vector genes for the material genes that experiment "
            f"{experiment.name!r} evolves; choose an experiment without materials evolution"
        )
    return CPPNVector(experiment.cppn_outputs, controller=experiment.evolve_controller,
                      brain_spec=experiment.brain_spec())  # fmt: skip


class BrainSampling(Sampling):
    """Random brains (:meth:`BrainSpec.random`) as real vectors: CMA-ES's first population."""

    def __init__(self, experiment: Experiment) -> None:
        super().__init__()
        self.spec = experiment.brain_spec()

    def _do(self, problem, n_samples, *args, random_state=None, **kwargs):
        return np.stack([self.spec.random(random_state).weights for _ in range(n_samples)])


class DesignSampling(Sampling):
    """Uniform design vectors that draw valid bodies (:meth:`CPPNVector.random_valid`):
    CMA-ES's first population on a CPPN body.
    """

    def __init__(self, experiment: Experiment) -> None:
        super().__init__()
        self.encoding = design_encoding(experiment)
        self.shape, self.rules = experiment.shape, experiment.rules

    def _do(self, problem, n_samples, *args, random_state=None, **kwargs):
        enc = self.encoding
        return np.stack([enc.random_valid(random_state, self.shape, self.rules)
                         for _ in range(n_samples)])  # fmt: skip


def make_cmaes(experiment: Experiment, sigma: float = 0.1, **kwargs: Any) -> Algorithm:
    """Pymoo's CMA-ES over a design vector (:class:`DesignProblem`, a CPPN body) or a
    brain's weights (:class:`BrainProblem`, a fixed body).

    ``experiment.pop_size`` random vectors (:class:`DesignSampling`, valid bodies;
    :class:`BrainSampling`) are the first generation; the best is ``x0``; CMA-ES then asks
    ``pop_size`` solutions a generation. ``sigma`` is the initial step in the
    [0, 1]-normalised box (0.1: 0.6 brain-weight units, 0.2 CPPN-weight units). cma's
    stopping tests are off (the run ends at its budget); ``kwargs`` go to
    :class:`~pymoo.algorithms.soo.nonconvex.cmaes.CMAES`.
    """
    from pymoo.algorithms.soo.nonconvex.cmaes import CMAES
    from pymoo.core.initialization import Initialization

    opts: dict[str, Any] = {
        "tolfun": 0, "tolx": 0, "tolflatfitness": 10**9, "tolstagnation": 10**9,
        "tolfunhist": 0, "tolupsigma": 1e300, "tolconditioncov": 1e300,
    }  # fmt: skip
    opts.update(kwargs)
    algorithm = CMAES(sigma=sigma, pop_size=experiment.pop_size, **opts)
    sampling = (
        BrainSampling(experiment) if experiment.body is not None else DesignSampling(experiment)
    )
    algorithm.initialization = Initialization(sampling)
    algorithm.n_sample_points = experiment.pop_size
    return algorithm


def _nsga3(pop_size: int, n_obj: int, **operators: Any) -> Algorithm:
    from pymoo.algorithms.moo.nsga3 import NSGA3
    from pymoo.util.ref_dirs import get_reference_directions

    if n_obj < 2:  # one objective has one reference direction whatever p: the loop would not end
        raise InvalidParameterError(
            f"algorithm 'nsga3' needs at least 2 objectives, got {n_obj}; use 'nsga2' or 'ga'"
        )
    # about one reference direction per individual ("das-dennis" on the objective simplex)
    p = 1
    while math.comb(p + 1 + n_obj - 1, n_obj - 1) <= pop_size:
        p += 1
    ref_dirs = get_reference_directions("das-dennis", n_obj, n_partitions=p)
    return NSGA3(ref_dirs=ref_dirs, pop_size=pop_size, **operators)


def _named(name: str) -> Callable[..., Algorithm]:
    if name == "nsga2":
        from pymoo.algorithms.moo.nsga2 import NSGA2

        return NSGA2
    if name == "sms-emoa":
        from pymoo.algorithms.moo.sms import SMSEMOA

        return SMSEMOA
    if name == "ga":
        from pymoo.algorithms.soo.nonconvex.ga import GA

        return GA
    raise InvalidParameterError(f"unknown algorithm {name!r}; expected one of {ALGORITHMS}")


#: Algorithms by name that need two objectives or more (NSGA-III's reference directions,
#: SMS-EMOA's hypervolume contributions): refused on a single-objective problem.
MULTI_OBJECTIVE: tuple[str, ...] = ("nsga3", "sms-emoa")


def problem_objectives(experiment: Experiment, single_objective: bool = False) -> int:
    """Objectives of the pymoo problem of ``experiment``: 1 for a novelty search (its
    novelty alone) or a single-objective algorithm, else the experiment's objectives.
    """
    if single_objective or experiment.selection.startswith("novelty"):
        return 1
    return len(experiment.objectives)


#: Algorithms known by name (``"ga"`` and ``"cmaes"`` are single-objective: they optimise the
#: experiment's fitness; ``"cmaes"`` a design vector or a brain on a fixed body, :func:`make_cmaes`);
#: the drivers' registry holds them (:data:`evolvers.drivers.registry.PYMOO_ALGORITHMS`).
ALGORITHMS: tuple[str, ...] = PYMOO_ALGORITHMS


def make_algorithm(
    algorithm: str | Callable[..., Algorithm],
    experiment: Experiment,
    ids: IdCounter,
    n_obj: int,
    **kwargs: Any,
) -> Algorithm:
    """A pymoo algorithm with the softbot operators, for ``experiment``.

    Parameters
    ----------
    algorithm : str or callable
        A name of :data:`ALGORITHMS`, or a pymoo algorithm class (or any
        callable) that takes ``pop_size``, ``sampling``, ``crossover``,
        ``mutation``, ``eliminate_duplicates`` and ``n_offsprings`` keywords
        (NSGA2, NSGA3 with ``ref_dirs=`` in ``kwargs``, SMSEMOA, GA, ...).
    experiment : Experiment
    ids : IdCounter
        The id source of new individuals.
    n_obj : int
        Objectives of the problem (NSGA-III's reference directions).
    **kwargs
        More keywords for the algorithm.

    Returns
    -------
    pymoo.core.algorithm.Algorithm
    """
    exp = experiment
    operators: dict[str, Any] = {
        "sampling": SoftbotSampling(exp, ids),
        "crossover": SoftbotCrossover(exp, ids),
        "mutation": SoftbotMutation(exp, ids),
        "eliminate_duplicates": SoftbotDuplicateElimination(exp),
        "n_offsprings": exp.pop_size,
        **kwargs,
    }
    if algorithm == "nsga3" and "ref_dirs" not in kwargs:
        return _nsga3(exp.pop_size, n_obj, **operators)
    if algorithm == "cmaes":
        return make_cmaes(exp, **kwargs)
    factory = _named(algorithm) if isinstance(algorithm, str) else algorithm
    if not callable(factory):
        raise InvalidParameterError(
            f"algorithm must be a name of {ALGORITHMS} or a pymoo algorithm class, got {algorithm!r}"
        )
    return factory(pop_size=exp.pop_size, **operators)


def _algorithm_label(algorithm: Any) -> str:
    if isinstance(algorithm, str):
        return algorithm
    return getattr(algorithm, "__name__", type(algorithm).__name__)


class PymooRun(Driver):
    """An experiment run with a pymoo algorithm through ask and tell (see the module docstring).

    Same run folder, log, figures and checkpoints as every driver
    (:class:`~evolvers.recording.recorder.RunRecorder`). ``generations`` counts the
    generations after the initial population (pymoo's ``n_gen`` is one more).

    Parameters
    ----------
    experiment, out, seed, generations, **driver
        As for :class:`~evolvers.drivers.base.Driver` (``batch_fn``, ``n_threads``,
        ``on_generation``, ``figures``, ``gif``, ``progress``; Ctrl-C raises
        :class:`~evolvers.recording.recorder.RunInterrupted` the same way).
    algorithm : str or callable
        ``"nsga2"`` (default), ``"nsga3"``, ``"sms-emoa"``, ``"ga"``
        (single-objective, on the experiment's fitness), ``"cmaes"`` (pymoo's
        CMA-ES on the fitness: over a design vector on a CPPN body,
        :class:`DesignProblem`; over the brain's weights on a fixed ``body`` with a
        network ``controller``, whose controller genes stay the body's), or a pymoo
        algorithm class or factory
        (:func:`make_algorithm`); a fresh algorithm is built for every :meth:`run`.
    algorithm_kwargs : dict, optional
        More keywords for the algorithm (e.g. NSGA-III's ``ref_dirs``).
    single_objective : bool, optional
        Optimise the fitness alone (default: True for ``"ga"``).
    """

    backend = "pymoo"

    def __init__(self, experiment: Experiment, out: str | Path, seed: int = 0,
                 generations: int | None = None, *,
                 algorithm: str | Callable[..., Algorithm] = "nsga2",
                 algorithm_kwargs: dict[str, Any] | None = None,
                 single_objective: bool | None = None, **driver: Any) -> None:  # fmt: skip
        if isinstance(algorithm, str) and algorithm not in ALGORITHMS:
            raise InvalidParameterError(
                f"unknown algorithm {algorithm!r}; expected one of {ALGORITHMS}"
            )
        self.cmaes = algorithm == "cmaes"
        if self.cmaes and experiment.body is not None and not experiment.evolve_brain:
            raise InvalidParameterError(
                "algorithm 'cmaes' on a fixed body searches a brain's weights: it needs a network "
                "controller ('central' or 'distributed'); or drop the fixed body (--body) for "
                "CMA-ES over the whole design vector"
            )
        if self.cmaes and experiment.body is None:
            design_encoding(experiment)  # refuses material genes, before anything is written
        self.algorithm_spec = algorithm
        self.algorithm_kwargs = dict(algorithm_kwargs or {})
        self.single_objective = (
            (algorithm in ("ga", "cmaes")) if single_objective is None else single_objective
        )
        n_obj = problem_objectives(experiment, self.single_objective or self.cmaes)
        if algorithm in MULTI_OBJECTIVE and n_obj < 2:
            raise InvalidParameterError(
                f"algorithm {algorithm!r} needs at least 2 objectives; experiment "
                f"{experiment.name!r} optimises {n_obj} ({experiment.objectives[0].name}"
                f"{', novelty' if experiment.selection.startswith('novelty') else ''}): "
                f"use algorithm 'nsga2' or 'ga' (--algorithm), or a multi-objective experiment"
            )
        super().__init__(experiment, out, seed, generations,
                         extra_config={"algorithm": _algorithm_label(algorithm)}, **driver)  # fmt: skip

    # ------------------------------------------------------------------ the loop
    def _fresh(self) -> None:
        super()._fresh()
        exp = self.experiment
        novelty = exp.selection.startswith("novelty")
        self.archive: NoveltyArchive | None = (
            NoveltyArchive(k=exp.pop_size, n_add=2, variant="normalized") if novelty else None
        )
        objectives = exp.objectives[:1] if self.single_objective else exp.objectives
        self.problem: Problem
        if self.cmaes and exp.body is not None:
            self.problem = BrainProblem(exp, self.evaluator, self.ids)
        elif self.cmaes:
            self.problem = DesignProblem(exp, self.evaluator, self.ids)
        else:
            self.problem = SoftbotProblem(exp, self.evaluator, self.archive, objectives)
        self.algorithm: Algorithm = make_algorithm(
            self.algorithm_spec, exp, self.ids, self.problem.n_obj, **self.algorithm_kwargs
        )
        # CMA-ES draws depend on its maxiter (pymoo passes n_gen): one fixed value, so that a
        # run resumed with more generations replays the same draws; the run counts its own
        n_gen = 10**6 if self.cmaes else self.generations + 1
        self.algorithm.setup(
            self.problem, termination=("n_gen", n_gen), seed=self.seed, verbose=False,
        )  # fmt: skip
        #: numpy's global generator as cma left it (cma draws from numpy.random; see _cma_random)
        self._cma_state: Any = None
        if self.cmaes:  # cma reads seed 0 as "from the clock": a fixed non-zero seed of the run's
            self.algorithm.options["seed"] = self.seed % (2**31 - 1) + 1

    @property
    def label(self) -> str:
        """The progress bar's description."""
        return f"{self.experiment.name} [pymoo {_algorithm_label(self.algorithm_spec)}]"

    def _individuals(self, problem: Problem, pop: Any) -> list[Individual]:
        """The individuals of a pymoo population (object variables, or CMA-ES's vectors)."""
        if isinstance(problem, VectorProblem):
            return problem.individuals(pop.get("X"))
        return [x[0] for x in pop.get("X")]

    @contextlib.contextmanager
    def _cma_random(self) -> Iterator[None]:
        """Cma samples from ``numpy.random``'s global generator (seeded once by it): give it
        its own state, kept apart from any other user of the global generator, so a run
        replayed without simulating draws exactly what the uninterrupted run drew.
        """
        if not self.cmaes:
            yield
            return
        outer = np.random.get_state()  # noqa: NPY002 - cma's own generator
        if self._cma_state is not None:
            np.random.set_state(self._cma_state)  # noqa: NPY002 - cma's own generator
        try:
            yield
        finally:
            self._cma_state = np.random.get_state()  # noqa: NPY002 - cma's own generator
            np.random.set_state(outer)  # noqa: NPY002 - cma's own generator

    def _generation(self, problem: Problem, algorithm: Algorithm) -> list[Individual]:
        """One ask / evaluate / tell round; returns the evaluated infills."""
        with self._cma_random():
            infills = algorithm.ask()
        if infills is None or len(infills) == 0:
            raise RuntimeError(
                f"{self.label}: the algorithm stopped asking at generation {self.generation}"
            )
        algorithm.evaluator.eval(problem, infills)
        with self._cma_random():
            algorithm.tell(infills=infills)
        self.generation += 1
        self.population = self._individuals(problem, algorithm.pop)
        return self._individuals(problem, infills)

    def _replay(self, problem: Problem, algorithm: Algorithm, state: dict[str, Any]) -> None:
        """Re-run the checkpointed generations from the seed; every result comes from the cache."""
        target = int(state["generation"])
        counter = self.evaluator.n_evaluations
        while self.generation < target:
            self._generation(problem, algorithm)
        self.evaluator.n_evaluations = counter
        if population_summary(self.population) != state["population"] or self.ids.value != int(
            state["next_id"]
        ):
            raise CheckpointError(
                f"{self.recorder.checkpoint_dir}: replaying generations 0-{target} did not "
                "reach the checkpointed population (another softgym, pymoo or algorithm?)"
            )

    def _step(self) -> EvalStats:
        infills = self._generation(self.problem, self.algorithm)
        self.recorder.update_hall_of_fame(infills, self.generation)
        return self.problem.last_stats

    def _restore(self, state: dict[str, Any], arrays: dict[str, np.ndarray]) -> None:
        self._replay(self.problem, self.algorithm, state)

    def _checkpoint_state(self) -> Checkpoint:
        algorithm = self.algorithm
        pop = algorithm.pop
        data, lengths = pack_traces([ind.trace for ind in self.population])
        arrays = {
            "pop_traces": data, "pop_trace_len": lengths,
            "F": pop.get("F"), "G": pop.get("G"), "CV": pop.get("CV"),
        }  # fmt: skip
        state = {
            "rng": rng_state(algorithm.random_state),
            "next_id": self.ids.value,
            "archive": None if self.archive is None else self.archive.to_dict(),
            "n_eval": int(algorithm.evaluator.n_eval),
        }
        return state, arrays, None, self.population
