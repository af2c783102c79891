"""Co-evolution of robots and terrains after Enhanced POET (Wang et al. 2019, 2020).

POET keeps a set of active *pairs*, each a terrain
(:class:`~softgym.tasks.terrain_genome.TerrainGenome`, a bounded vector that
the task layer turns into boxes) and a population of robots
(:class:`~evolvers.operators.genome.Individual`) that softgym's operators improve on it.
One :class:`PoetRun` iteration:

1. **Reproduction** (every ``reproduce_every`` iterations, K): pairs whose best
   robot scores at least ``repro_threshold`` on their own terrain are
   eligible parents. ``max_children`` (8) times, an eligible parent is drawn and
   its terrain mutated (``generator="random"``: a terrain drawn uniformly, the
   random-terrain control). A candidate already known is rejected
   (``duplicate``); the parent's best robot is scored on it and the candidate
   passes the *minimal criterion* only if that score lies in
   ``[mc_low, mc_high]`` (rejected as ``trivial`` above, ``impossible`` below).
   The passing candidates are ranked by PATA-EC novelty (:func:`pata_ec`,
   :func:`novelty`): the scores of every robot kept (the best robot of each
   active and archived pair) on the candidate, clipped to the band and
   rank-normalised, against the same vector of every active and archived
   terrain; novelty is the mean distance to the ``novelty_k`` (5) nearest. In
   that order a candidate is admitted if the best *active* robot on it also
   lies in the band (Enhanced POET's targeted transfer: the new pair starts
   from the population of the pair whose robot that is), at most
   ``max_admitted`` (1) per round. Past ``max_active`` pairs, the oldest retire
   to the archive (keeping their best robot).
2. **Optimisation**: every active pair runs one generation of the seed's loop
   on its own terrain (each parent makes one mutated child, the controller GA
   varies them, ``n_random`` random newcomers join; elitist fitness
   tournament back to ``pop_size``). The new robots of all pairs are
   evaluated together: one batched Simulation per terrain, or all terrains at
   once on Dask (:meth:`evolvers.evaluation.distributed.DaskBatchFn.jobs`).
3. **Transfers** (every ``transfer_every`` iterations, T): the best robot of
   every active pair is scored on every active terrain; a pair adopts another
   pair's robot that beats its own best there (replacing its worst robot).
4. **Bookkeeping**: a pair is *solved* once its best robot reaches
   ``solved_threshold``. ANNECS (the accumulated number of novel
   environments created and solved) counts the admitted terrains that passed
   the minimal criterion against *every* robot kept at their admission (the
   best of all of them in the band: neither trivial for any nor impossible
   for all) and were later solved, the Enhanced POET paper's definition; it
   never decreases. ``annecs_archive`` is the reference code's counter
   (admitted terrains on which the best *archived* robot lies in the band;
   0 while the archive is empty).

Scores and thresholds
---------------------
The score of a robot on a terrain is ``max_xy_dist`` (voxel lengths: how far
its centre of mass got from the start; a diverged robot scores 0). POET's
numbers are BipedalWalker rewards: minimal-criterion band 25-340,
reproduction threshold 200, "solved" 230. softgym maps a reward ``r`` to
``trapped + (solved - trapped) r / 230`` voxel lengths (:func:`poet_thresholds`),
where ``trapped`` (3) is about what a robot that never leaves the fenced start
area scores (the fence's inner face is 2 voxels from the footprint) and
``solved`` (10) is a distance that clears the fence and the ring of bumps of
the default 4x4x4 course: band [3.76, 13.35], reproduction 9.09, solved 10.
A BipedalWalker reward also saturates once the course is finished (about 300);
``max_xy_dist`` does not, so a fast robot keeps its terrain's mutants above
the band. ``PoetConfig(score_cap=12.13)`` (reward 300 through the same map)
makes scores saturate too; it is off by default (``benchmarks/RESULTS.md``
compares both).

The run folder is the one every driver writes (:class:`~evolvers.recording.recorder.RunRecorder`):
config.json, log.jsonl / log.csv with one row per iteration (the standard
columns over the active pairs' best robots, plus ``annecs``,
``annecs_archive``, ``n_active``, ``n_archived``, ``n_solved``, the
``terrains`` with their scores, ``admitted``, ``rejected`` with reasons,
``transfers`` and the ``score_matrix`` when one was computed), atomic
pickle-free checkpoints (every pair, the random state, the score cache) from
which a run resumes exactly, also after kill -9, and figures: ANNECS over
iterations, the transfer heatmap and a gallery of the hardest solved terrains
with their robots (:meth:`PoetRun.write_figures`, :func:`plot_annecs`).
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any

import numpy as np

from evolvers.drivers.base import Checkpoint, Driver, IdCounter
from evolvers.drivers.budget import Budget
from evolvers.evaluation.evaluator import BatchFn, EvalStats, Evaluator, JobsFn, PhenotypeCache
from evolvers.evaluation.experiments import Experiment, get_experiment
from evolvers.operators.genome import Individual
from evolvers.operators.selection import sel_fitness_tournament
from evolvers.operators.variation import make_children
from softgym.design import CONTROLLER_BOUNDS, Controller
from softgym.exceptions import CheckpointError, InvalidParameterError
from softgym.io import read_json_records, rng_from_state, rng_state
from softgym.render.figures import pyplot
from softgym.tasks import Task
from softgym.tasks.terrain_genome import TerrainGenome
from softgym.validate import is_int, is_real, show

__all__ = [
    "GENERATORS",
    "POET_REWARDS",
    "JobsFn",
    "Pair",
    "PoetConfig",
    "PoetRun",
    "centered_ranks",
    "novelty",
    "pata_ec",
    "plot_annecs",
    "poet_experiment",
    "poet_thresholds",
    "read_pairs",
]

log = logging.getLogger("evolvers")

#: The keys of a pair in ``pairs.json`` that its readers use, and what each must be.
_PAIR_KEYS = {"id": (is_int, "an integer"), "score": (is_real, "a number"),
              "design": (lambda v: isinstance(v, dict), "an object"),
              "terrain": (lambda v: isinstance(v, dict), "an object"),
              "describe": (lambda v: isinstance(v, str), "a string")}  # fmt: skip


def read_pairs(run_dir: str | Path) -> list[dict[str, Any]]:
    """The pairs of a POET run folder's ``pairs.json`` (through the capped reader).

    Raises
    ------
    CheckpointError
        Naming the file and the key, if it is missing, not a regular file,
        oversized, malformed, or holds no pair.
    """
    path = Path(run_dir) / "pairs.json"
    pairs = read_json_records(path, "pairs", "pairs")
    for i, pair in enumerate(pairs):
        for key, (check, what) in _PAIR_KEYS.items():
            if not check(pair.get(key)):
                raise CheckpointError(
                    f"{path}: 'pairs'[{i}][{key!r}] must be {what}, got {show(pair.get(key))}"
                )
    return pairs

#: Enhanced POET's BipedalWalker rewards: minimal-criterion band, reproduction threshold, solved.
POET_REWARDS: dict[str, float] = {
    "mc_low": 25.0,
    "mc_high": 340.0,
    "repro_threshold": 200.0,
    "solved_threshold": 230.0,
}
#: Terrain generators: mutants of eligible parents (POET), or uniform draws (the control).
GENERATORS: tuple[str, ...] = ("mutate", "random")

#: Draws of a candidate terrain before it counts as a duplicate of a known one.
_MUTATION_TRIES = 10



def poet_thresholds(trapped: float = 3.0, solved: float = 10.0) -> dict[str, float]:
    """POET's reward thresholds in softgym's units (voxel lengths of ``max_xy_dist``).

    A BipedalWalker reward ``r`` maps to ``trapped + (solved - trapped) r / 230``:
    reward 0 is a robot that stays in the start area, 230 (POET's "solved") a
    robot that clears the course.

    Parameters
    ----------
    trapped : float
        Score (voxel lengths) of a robot that never leaves the start area.
    solved : float
        Score (voxel lengths) that counts as solving a terrain; > ``trapped``.

    Returns
    -------
    dict
        ``mc_low``, ``mc_high``, ``repro_threshold``, ``solved_threshold``.
    """
    if not (math.isfinite(trapped) and math.isfinite(solved) and solved > trapped >= 0):
        raise InvalidParameterError(f"need 0 <= trapped < solved, got {trapped}, {solved}")
    scale = (solved - trapped) / POET_REWARDS["solved_threshold"]
    return {k: trapped + scale * r for k, r in POET_REWARDS.items()}


_DEFAULT_THRESHOLDS = poet_thresholds()


def poet_experiment(**overrides: Any) -> Experiment:
    """The robots of a POET run: ``obstacles-attempt2`` (CPPN + controller GA, tournament on
    ``max_xy_dist``), 4x4x4, 3 s simulated, 8 robots per pair; fields overridable.
    """
    kw: dict[str, Any] = {"pop_size": 8, "seconds": 3.0, "shape": (4, 4, 4), "task": "flat"}
    kw.update(overrides)
    return get_experiment("obstacles-attempt2", **kw)


@dataclass(frozen=True)
class PoetConfig:
    """The co-evolution's settings (see the module docstring for what each does).

    Parameters
    ----------
    reproduce_every : int
        K: iterations between reproduction rounds (0: never; direct evolution).
    transfer_every : int
        T: iterations between transfer rounds (0: never).
    max_children : int
        Candidate terrains per reproduction round (8, as POET).
    max_admitted : int
        Most terrains admitted per round (1, as POET).
    max_active : int
        Most active pairs (POET: 40 on a cluster; 8 here for 2 cores).
    mc_low, mc_high : float
        Minimal-criterion band (voxel lengths of ``max_xy_dist``).
    repro_threshold : float
        Score a pair's best robot needs for its terrain to reproduce.
    solved_threshold : float
        Score that solves a terrain.
    novelty_k : int
        Nearest neighbours of the PATA-EC novelty (5).
    generator : {"mutate", "random"}
        Candidate terrains: mutants of eligible parents, or uniform draws (the control).
    mutation_sigma : float
        Gaussian step of a terrain gene, as a fraction of its range.
    start_terrain : dict, optional
        The first pair's terrain (a :class:`TerrainGenome` dict; default flat).
    score_cap : float, optional
        Scores saturate here, as a BipedalWalker reward does once the course is
        finished (about 300: ``poet_thresholds``' map gives 12.13); default
        none: ``max_xy_dist`` grows with speed, so a mastered terrain's mutants
        stay above ``mc_high`` (trivial) until they are much harder.
    """

    reproduce_every: int = 5
    transfer_every: int = 5
    max_children: int = 8
    max_admitted: int = 1
    max_active: int = 8
    mc_low: float = _DEFAULT_THRESHOLDS["mc_low"]
    mc_high: float = _DEFAULT_THRESHOLDS["mc_high"]
    repro_threshold: float = _DEFAULT_THRESHOLDS["repro_threshold"]
    solved_threshold: float = _DEFAULT_THRESHOLDS["solved_threshold"]
    novelty_k: int = 5
    generator: str = "mutate"
    mutation_sigma: float = 0.15
    start_terrain: dict[str, Any] | None = None
    score_cap: float | None = None

    def __post_init__(self) -> None:
        for name in ("reproduce_every", "transfer_every"):
            _int_at_least(name, getattr(self, name), 0)
        for name in ("max_children", "max_admitted", "max_active", "novelty_k"):
            _int_at_least(name, getattr(self, name), 1)
        for name in ("mc_low", "mc_high", "repro_threshold", "solved_threshold", "mutation_sigma"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
                raise InvalidParameterError(f"{name} must be a finite number, got {v!r}")
            object.__setattr__(self, name, float(v))
        if not 0 <= self.mc_low < self.mc_high:
            raise InvalidParameterError(
                f"the minimal-criterion band needs 0 <= mc_low < mc_high, got [{self.mc_low}, {self.mc_high}]"
            )
        if self.score_cap is not None:
            cap = self.score_cap
            if isinstance(cap, bool) or not isinstance(cap, (int, float)) or not cap > self.mc_low:
                raise InvalidParameterError(f"score_cap must be a number > mc_low, got {cap!r}")
            object.__setattr__(self, "score_cap", float(cap))
        if self.mutation_sigma <= 0:
            raise InvalidParameterError(f"mutation_sigma must be > 0, got {self.mutation_sigma}")
        if self.generator not in GENERATORS:
            raise InvalidParameterError(
                f"generator must be one of {GENERATORS}, got {self.generator!r}"
            )
        if self.start_terrain is not None:
            object.__setattr__(
                self, "start_terrain", TerrainGenome.from_dict(self.start_terrain).to_dict()
            )

    @property
    def start(self) -> TerrainGenome:
        """The first pair's terrain."""
        return (
            TerrainGenome.flat()
            if self.start_terrain is None
            else TerrainGenome.from_dict(self.start_terrain)
        )

    def passes(self, score: float) -> bool:
        """The minimal criterion: ``mc_low <= score <= mc_high``."""
        return bool(self.mc_low <= score <= self.mc_high)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict."""
        return {f.name: getattr(self, f.name) for f in fields(self)}

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> PoetConfig:
        """Inverse of :meth:`to_dict`."""
        unknown = sorted(set(data) - {f.name for f in fields(cls)})
        if unknown:
            raise InvalidParameterError(f"unknown POET settings {unknown}")
        return cls(**dict(data))


def _int_at_least(name: str, v: Any, low: int) -> None:
    if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < low:
        raise InvalidParameterError(f"{name} must be an integer >= {low}, got {v!r}")


# ---------------------------------------------------------------------- PATA-EC
def centered_ranks(x: np.ndarray) -> np.ndarray:
    """Ranks of ``x`` scaled to [-0.5, 0.5] (ties share their mean rank; one value gives 0).

    Parameters
    ----------
    x : ndarray of shape (n,)

    Returns
    -------
    ndarray of shape (n,), float64
    """
    x = np.asarray(x, dtype=np.float64).reshape(-1)
    n = x.size
    if n <= 1:
        return np.zeros(n)
    order = np.argsort(x, kind="stable")
    ranks = np.empty(n)
    sx = x[order]
    i = 0
    while i < n:
        j = i
        while j + 1 < n and sx[j + 1] == sx[i]:
            j += 1
        ranks[order[i : j + 1]] = 0.5 * (i + j)
        i = j + 1
    return ranks / (n - 1) - 0.5


def pata_ec(scores: np.ndarray, low: float, high: float) -> np.ndarray:
    """The PATA-EC vector of a terrain: robots' scores clipped to the band, then rank-normalised.

    Parameters
    ----------
    scores : ndarray of shape (n_robots,)
        Scores of the same robots, in the same order, on one terrain.
    low, high : float
        The minimal-criterion band.

    Returns
    -------
    ndarray of shape (n_robots,), float64
        Centred ranks in [-0.5, 0.5]. A strictly increasing transform of the
        scores (and of the band) leaves it unchanged.
    """
    return centered_ranks(np.clip(np.asarray(scores, dtype=np.float64), low, high))


def novelty(vector: np.ndarray, others: np.ndarray, k: int = 5) -> float:
    """Mean Euclidean distance from ``vector`` to its ``k`` nearest rows of ``others``.

    Parameters
    ----------
    vector : ndarray of shape (n_robots,)
    others : ndarray of shape (n_terrains, n_robots)
    k : int

    Returns
    -------
    float
        ``inf`` when ``others`` is empty.
    """
    others = np.asarray(others, dtype=np.float64).reshape(-1, np.asarray(vector).size)
    if len(others) == 0:
        return float("inf")
    d = np.sort(np.linalg.norm(others - np.asarray(vector, dtype=np.float64)[None, :], axis=1))
    return float(d[: max(1, int(k))].mean())


# ---------------------------------------------------------------------- pairs
@dataclass
class Pair:
    """A terrain and the robots evolving on it.

    Attributes
    ----------
    id : int
        Unique in the run, in order of creation (0: the first pair).
    terrain : TerrainGenome
    population : list of Individual
        Robots with their results on this terrain (an archived pair keeps its best robot).
    parent : int or None
        The pair whose terrain was mutated into this one.
    created : int
        Iteration of admission.
    retired : int or None
        Iteration it moved to the archive.
    solved : int or None
        First iteration its best robot reached the solved threshold.
    novel : bool
        It passed the minimal criterion against every robot kept at its admission.
    counted : bool
        Counted in ANNECS (novel, then solved).
    """

    id: int
    terrain: TerrainGenome
    population: list[Individual]
    parent: int | None = None
    created: int = 0
    retired: int | None = None
    solved: int | None = None
    novel: bool = False
    counted: bool = False
    metric: str = field(default="max_xy_dist", repr=False)
    cap: float | None = field(default=None, repr=False)

    @property
    def active(self) -> bool:
        """Not archived."""
        return self.retired is None

    def score_of(self, ind: Individual) -> float:
        """A robot's score here (its metric clipped at 0; 0 before evaluation)."""
        return _score(ind.objectives, self.metric, self.cap)

    @property
    def best(self) -> Individual:
        """The best robot (highest score, then lowest id)."""
        return min(self.population, key=lambda ind: (-self.score_of(ind), ind.id))

    @property
    def best_score(self) -> float:
        """The best robot's score."""
        return self.score_of(self.best)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict (robots with their results)."""
        return {
            "id": self.id,
            "terrain": self.terrain.to_dict(),
            "population": [ind.to_dict() for ind in self.population],
            "parent": self.parent,
            "created": self.created,
            "retired": self.retired,
            "solved": self.solved,
            "novel": self.novel,
            "counted": self.counted,
        }

    @classmethod
    def from_dict(
        cls, data: Mapping[str, Any], metric: str = "max_xy_dist", cap: float | None = None
    ) -> Pair:
        """Inverse of :meth:`to_dict`."""
        return cls(
            id=int(data["id"]),
            terrain=TerrainGenome.from_dict(data["terrain"]),
            population=[Individual.from_dict(d) for d in data["population"]],
            parent=None if data["parent"] is None else int(data["parent"]),
            created=int(data["created"]),
            retired=None if data["retired"] is None else int(data["retired"]),
            solved=None if data["solved"] is None else int(data["solved"]),
            novel=bool(data["novel"]),
            counted=bool(data["counted"]),
            metric=metric,
            cap=cap,
        )


def _score(objectives: Mapping[str, float], metric: str, cap: float | None = None) -> float:
    v = float(objectives.get(metric, 0.0))
    v = v if math.isfinite(v) and v > 0 else 0.0
    return v if cap is None else min(v, cap)


# ---------------------------------------------------------------------- the run
class PoetRun(Driver):
    """A resumable POET run (see the module docstring).

    ``iterations`` counts the iterations after iteration 0 (the first pair's
    random population), as ``generations`` does for the other drivers.

    Parameters
    ----------
    experiment : Experiment, optional
        The robots: grid shape, composition rules, genes, ``pop_size`` robots
        per pair, ``n_random`` newcomers, simulated seconds (default
        :func:`poet_experiment`). Its task is not used: each pair has its terrain.
    out : path
        Run folder.
    seed : int
        Seeds the run's one ``numpy.random.Generator`` (every random choice).
    iterations : int
    config : PoetConfig, optional
    batch_fn : callable, optional
        ``(design dicts, task) -> metrics`` of one terrain (default: one local
        Simulation); tests pass a fake. A :class:`~evolvers.evaluation.distributed.DaskBatchFn`
        evaluates all terrains at once (its ``jobs``).
    jobs_fn : callable, optional
        Several terrains' batches at once (:data:`~evolvers.evaluation.evaluator.JobsFn`);
        overrides ``batch_fn``.
    n_threads : int, optional
        OpenMP threads of local simulations.
    on_iteration : callable, optional
        ``on_iteration(run, row)`` after each iteration's checkpoint (raising
        here interrupts the run like a crash).
    figures : bool
        Write the figures when the run finishes.
    progress : bool
        A tqdm bar over the iterations (each iteration is also logged at INFO).
    budget : Budget or dict, optional
        Limits besides the iterations (:class:`~evolvers.drivers.budget.Budget`); its
        ``target_score`` is reached when a pair's best robot scores it on its terrain
        (:meth:`best_score`).
    """

    backend = "poet"
    unit = "iteration"
    recorder_figures = False  # POET draws its own (write_figures)

    def __init__(
        self,
        experiment: Experiment | None = None,
        out: str | Path = "runs/poet",
        seed: int = 0,
        iterations: int = 40,
        config: PoetConfig | None = None,
        batch_fn: BatchFn | None = None,
        jobs_fn: JobsFn | None = None,
        n_threads: int | None = None,
        on_iteration: Callable[[PoetRun, dict[str, Any]], None] | None = None,
        figures: bool = True,
        progress: bool = True,
        budget: Budget | dict[str, Any] | None = None,
    ) -> None:
        if experiment is not None and (experiment.evolve_brain or not experiment.evolve_body):
            raise InvalidParameterError(
                "POET evolves CPPN bodies with the sinusoid controller: network controllers "
                "(controller != 'sinusoid') and fixed bodies are for evolve and qd runs"
            )
        self.config = PoetConfig() if config is None else config
        self.metric = "max_xy_dist"
        self._jobs_fn = jobs_fn or getattr(batch_fn, "jobs", None)
        super().__init__(
            poet_experiment() if experiment is None else experiment, out, seed, int(iterations),
            batch_fn, n_threads, on_iteration, figures, False, progress,
            extra_config={"poet": self.config.to_dict()}, budget=budget,
        )  # fmt: skip

    def _evaluator(self, batch_fn: BatchFn | None, n_threads: int | None, progress: bool) -> Evaluator:
        """The drivers' evaluator, keyed by (terrain, phenotype) (:meth:`evaluate`); no traces kept."""
        return Evaluator(self.experiment, batch_fn, n_threads, progress=progress,
                         jobs_fn=self._jobs_fn, traces=False)  # fmt: skip

    def _fresh(self) -> None:
        super()._fresh()
        self.rng = np.random.default_rng(self.seed)
        self.pair_ids = IdCounter()
        self.pairs: list[Pair] = []
        self.evaluator.cache = PhenotypeCache()
        self.evaluator.n_evaluations = 0
        self.annecs = 0
        self.annecs_archive = 0

    # ------------------------------------------------------------------ views
    @property
    def n_simulated(self) -> int:
        """Simulations run so far (the evaluator's count)."""
        return self.evaluator.n_evaluations

    @property
    def iteration(self) -> int:
        """The last finished iteration (the driver's :attr:`generation`), -1 before the first."""
        return self.generation

    @iteration.setter
    def iteration(self, value: int) -> None:
        self.generation = value

    @property
    def iterations(self) -> int:
        """Iterations after iteration 0 (the driver's :attr:`generations`)."""
        return self.generations

    @property
    def label(self) -> str:
        """The progress bar's description."""
        return f"poet [{self.config.generator}]"

    def result(self) -> list[Pair]:
        """Every pair, active and archived, in order of creation (what :meth:`run` returns)."""
        return list(self.pairs)

    @property
    def score_maximized(self) -> bool:
        """POET's scores are distances: better larger."""
        return True

    def best_score(self) -> float | None:
        """The best score of any pair's best robot on its own terrain (active or archived):
        the ``target_score`` budget's score; None before the first iteration.
        """
        return max((p.best_score for p in self.pairs), default=None)

    def active(self) -> list[Pair]:
        """Active pairs, oldest first."""
        return [p for p in self.pairs if p.active]

    def archived(self) -> list[Pair]:
        """Archived pairs, oldest first."""
        return [p for p in self.pairs if not p.active]

    def pair(self, pair_id: int) -> Pair:
        """The pair of an id."""
        for p in self.pairs:
            if p.id == pair_id:
                return p
        raise InvalidParameterError(f"no pair {pair_id}")

    # ------------------------------------------------------------------ evaluation
    def task_for(self, terrain: TerrainGenome) -> Task:
        """The task a robot runs on ``terrain``: the experiment's duration and sampling."""
        return self.evaluator.task.replace(terrain=terrain.terrain(self.experiment.shape))

    def evaluate(
        self, jobs: Sequence[tuple[TerrainGenome, Sequence[Individual]]], assign: bool = False
    ) -> tuple[list[np.ndarray], EvalStats]:
        """Score robots on terrains: every uncached (terrain, phenotype) simulated once, batched
        (:meth:`Evaluator.evaluate_jobs`, the task keyed by :meth:`TerrainGenome.key`).

        Parameters
        ----------
        jobs : sequence of (TerrainGenome, sequence of Individual)
        assign : bool
            Also store each robot's results on it (``objectives``), for robots
            that belong to that terrain's pair.

        Returns
        -------
        scores : list of ndarray of shape (n_robots of the job,), float64
        stats : EvalStats
        """
        results, stats = self.evaluator.evaluate_jobs(
            [(terrain.key(), self.task_for(terrain), inds) for terrain, inds in jobs], assign=assign
        )
        cap = self.config.score_cap
        scores = [np.array([_score(obj, self.metric, cap) for obj in row], dtype=np.float64)
                  for row in results]  # fmt: skip
        return scores, stats

    def score_matrix(
        self, robots: Sequence[Pair], terrains: Sequence[Pair]
    ) -> tuple[np.ndarray, EvalStats]:
        """Scores of the best robot of each pair of ``robots`` on each terrain of ``terrains``.

        Returns
        -------
        ndarray of shape (len(robots), len(terrains)), float64
        EvalStats
        """
        best = [p.best for p in robots]
        cols, stats = self.evaluate([(p.terrain, best) for p in terrains])
        m = np.column_stack(cols) if cols else np.zeros((len(best), 0))
        return m.reshape(len(best), len(terrains)), stats

    # ------------------------------------------------------------------ robots
    def _random_individual(self) -> Individual:
        exp = self.experiment
        ind = Individual.random(self.rng, self.ids(), exp.shape, exp.cppn_outputs, exp.rules)
        if exp.evolve_controller:  # newcomers start anywhere in the controller's bounds
            ind.controller = Controller(**{
                name: float(self.rng.uniform(lo, hi)) for name, (lo, hi, _) in CONTROLLER_BOUNDS.items()
            })  # fmt: skip
        return ind

    def _select(self, pair: Pair, everyone: list[Individual]) -> list[Individual]:
        """Elitist: the best robot stays, a fitness tournament picks the rest."""
        k = self.experiment.pop_size
        best = min(everyone, key=lambda ind: (-pair.score_of(ind), ind.id))
        rest = [ind for ind in everyone if ind is not best]
        for ind in rest:  # the tournament reads the clipped score
            ind.objectives.setdefault(self.metric, 0.0)
        kept = sel_fitness_tournament(rest, k - 1, self.metric, self.rng)
        return [best, *kept]

    # ------------------------------------------------------------------ one iteration
    def _stats_sum(self, total: EvalStats, part: EvalStats) -> None:
        for f in fields(EvalStats):
            setattr(total, f.name, getattr(total, f.name) + getattr(part, f.name))

    def _first(self, events: dict[str, Any], total: EvalStats) -> None:
        exp = self.experiment
        pop = [self._random_individual() for _ in range(exp.pop_size)]
        root = Pair(self.pair_ids(), self.config.start, pop, None, 0, metric=self.metric,
                    cap=self.config.score_cap)  # fmt: skip
        self.pairs.append(root)
        _, st = self.evaluate([(root.terrain, pop)], assign=True)
        self._stats_sum(total, st)
        events["admitted"].append({"pair": root.id, "parent": None, "genome": root.terrain.to_dict(),
                                   "score": root.best_score, "reason": "the start terrain"})  # fmt: skip

    def _optimise(self, total: EvalStats) -> None:
        exp = self.experiment
        jobs = []
        for pair in self.active():
            for ind in pair.population:
                ind.age += 1
            children = make_children(
                pair.population, self.rng, self.ids, shape=exp.shape, rules=exp.rules,
                evolve_controller=exp.evolve_controller, evolve_materials=exp.evolve_materials,
                crossover_rate=exp.crossover_rate,
            )  # fmt: skip
            children += [self._random_individual() for _ in range(exp.n_random)]
            jobs.append((pair, children))
        _, st = self.evaluate([(p.terrain, c) for p, c in jobs], assign=True)
        self._stats_sum(total, st)
        for pair, children in jobs:
            pair.population = self._select(pair, pair.population + children)

    def _reproduce(self, events: dict[str, Any], total: EvalStats) -> None:
        cfg = self.config
        active = self.active()
        eligible = [p for p in active if p.best_score >= cfg.repro_threshold]
        events["eligible"] = [p.id for p in eligible]
        if not eligible:
            return
        known = {p.terrain.key() for p in self.pairs}
        candidates = []
        for _ in range(cfg.max_children):
            parent = eligible[int(self.rng.integers(len(eligible)))]
            for _ in range(_MUTATION_TRIES):  # a mutant of genes that build nothing is retried
                if cfg.generator == "random":
                    child = TerrainGenome.random(self.rng)
                else:
                    child = parent.terrain.mutate(self.rng, cfg.mutation_sigma)
                if child.key() not in known:
                    break
            cand = {"parent": parent.id, "genome": child.to_dict()}
            if child.key() in known:
                events["rejected"].append({**cand, "reason": "duplicate"})
                continue
            known.add(child.key())
            candidates.append((parent, child, cand))
        if not candidates:
            return
        # the minimal criterion on the parent's best robot
        scores, st = self.evaluate([(child, [parent.best]) for parent, child, _ in candidates])
        self._stats_sum(total, st)
        passing = []
        for (parent, child, cand), s in zip(candidates, scores):
            s = float(s[0])
            cand["parent_score"] = s
            if s > cfg.mc_high:
                events["rejected"].append(
                    {
                        **cand,
                        "reason": f"trivial: parent's robot scores {s:.3g} > {cfg.mc_high:.3g}",
                    }
                )
            elif s < cfg.mc_low:
                events["rejected"].append(
                    {
                        **cand,
                        "reason": f"impossible: parent's robot scores {s:.3g} < {cfg.mc_low:.3g}",
                    }
                )
            else:
                passing.append((parent, child, cand))
        if not passing:
            return
        # PATA-EC: every kept robot on every kept terrain and on each passing candidate
        kept = list(self.pairs)
        matrix, st = self.score_matrix(kept, kept)
        self._stats_sum(total, st)
        events["score_matrix"] = _matrix_log(kept, kept, matrix)
        cand_scores, st = self.evaluate(
            [(child, [p.best for p in kept]) for _, child, _ in passing]
        )
        self._stats_sum(total, st)
        archive_vecs = np.array(
            [pata_ec(matrix[:, j], cfg.mc_low, cfg.mc_high) for j in range(len(kept))]
        )
        ranked = []
        for (parent, child, cand), s in zip(passing, cand_scores):
            cand["novelty"] = novelty(
                pata_ec(s, cfg.mc_low, cfg.mc_high), archive_vecs, cfg.novelty_k
            )
            ranked.append((parent, child, cand, s))
        ranked.sort(key=lambda r: -r[2]["novelty"])  # stable: ties keep the draw order
        admitted = 0
        is_active = np.array([p.active for p in kept])
        for parent, child, cand, s in ranked:
            if admitted >= cfg.max_admitted:
                events["rejected"].append(
                    {**cand, "reason": f"less novel: at most {cfg.max_admitted} admitted per round"}
                )
                continue
            i_best = int(np.flatnonzero(is_active)[np.argmax(s[is_active])])
            best_active = float(s[i_best])
            if not cfg.passes(best_active):
                why = "trivial" if best_active > cfg.mc_high else "impossible"
                events["rejected"].append(
                    {
                        **cand,
                        "reason": f"{why} for the best active robot (pair {kept[i_best].id}, {best_active:.3g})",
                    }
                )
                continue
            source = kept[i_best]
            pop = [ind.child(self.ids()) for ind in source.population]
            pair = Pair(
                self.pair_ids(),
                child,
                pop,
                parent.id,
                self.iteration + 1,
                metric=self.metric,
                cap=cfg.score_cap,
            )
            _, st = self.evaluate([(child, pop)], assign=True)
            self._stats_sum(total, st)
            pair.novel = cfg.passes(float(s.max()))
            archived = s[~is_active]
            if archived.size and cfg.passes(float(archived.max())):
                self.annecs_archive += 1
            self.pairs.append(pair)
            admitted += 1
            events["admitted"].append({**cand, "pair": pair.id, "seeded_from": source.id,
                                       "best_active_score": best_active, "novel": pair.novel})  # fmt: skip
        while len(self.active()) > cfg.max_active:
            oldest = self.active()[0]
            oldest.population = [oldest.best]
            oldest.retired = self.iteration + 1
            events["retired"].append(oldest.id)

    def _transfer(self, events: dict[str, Any], total: EvalStats) -> None:
        active = self.active()
        if len(active) < 2:
            return
        matrix, st = self.score_matrix(active, active)
        self._stats_sum(total, st)
        events["score_matrix"] = _matrix_log(active, active, matrix)
        robots = [p.best for p in active]
        for j, target in enumerate(active):
            others = [i for i in range(len(active)) if i != j]
            i = max(others, key=lambda i: (matrix[i, j], -i))
            if matrix[i, j] > matrix[j, j]:
                incoming = robots[i].child(self.ids())
                self.evaluate([(target.terrain, [incoming])], assign=True)  # cached: no simulation
                worst = min(target.population, key=lambda ind: (target.score_of(ind), -ind.id))
                target.population = [incoming if ind is worst else ind for ind in target.population]
                events["transfers"].append({"from": active[i].id, "to": target.id,
                                            "score": float(matrix[i, j]), "previous": float(matrix[j, j])})  # fmt: skip

    def _bookkeeping(self) -> None:
        for p in self.active():
            if p.solved is None and p.best_score >= self.config.solved_threshold:
                p.solved = self.iteration
        for p in self.pairs:
            if p.novel and p.solved is not None and not p.counted:
                p.counted = True
                self.annecs += 1

    def _iterate(self) -> tuple[EvalStats, dict[str, Any]]:
        cfg = self.config
        events: dict[str, Any] = {"eligible": [], "admitted": [], "rejected": [], "retired": [],
                                  "transfers": [], "score_matrix": None}  # fmt: skip
        total = EvalStats()
        it = self.iteration + 1
        if it == 0:
            self._first(events, total)
        else:
            if cfg.reproduce_every and it % cfg.reproduce_every == 0:
                self._reproduce(events, total)
            self._optimise(total)
            if cfg.transfer_every and it % cfg.transfer_every == 0:
                self._transfer(events, total)
        self.iteration = it
        self._bookkeeping()
        return total, events

    # ------------------------------------------------------------------ the loop
    def _step(self) -> EvalStats:
        stats, self._events = self._iterate()
        return stats

    def _checkpoint_state(self) -> Checkpoint:
        active = self.active()
        columns = {
            "iteration": self.iteration,
            "annecs": self.annecs,
            "annecs_archive": self.annecs_archive,
            "n_active": len(active),
            "n_archived": len(self.pairs) - len(active),
            "n_solved": sum(p.solved is not None for p in self.pairs),
            "terrains": [
                {
                    "pair": p.id,
                    "genome": p.terrain.to_vector().tolist(),
                    "active": p.active,
                    "score": p.best_score,
                    "solved": p.solved is not None,
                }  # fmt: skip
                for p in self.pairs
            ],
            **self._events,
        }
        state = {
            "rng": rng_state(self.rng),
            "next_id": self.ids.value,
            "next_pair": self.pair_ids.value,
            "annecs": self.annecs,
            "annecs_archive": self.annecs_archive,
            "pairs": [p.to_dict() for p in self.pairs],
        }
        return state, {}, columns, [p.best for p in active]

    def _restore(self, state: dict[str, Any], arrays: dict[str, np.ndarray]) -> None:
        self.rng = rng_from_state(state["rng"])
        self.ids.value = int(state["next_id"])
        self.pair_ids.value = int(state["next_pair"])
        self.annecs = int(state["annecs"])
        self.annecs_archive = int(state["annecs_archive"])
        self.pairs = [
            Pair.from_dict(d, self.metric, self.config.score_cap) for d in state["pairs"]
        ]
        self.iteration = int(state["generation"])

    # ------------------------------------------------------------------ outputs
    def finish(self) -> None:
        """Final pairs (``pairs.json``: terrains, robots' designs, scores) and the figures."""
        from softgym.io import atomic_write_json

        exp = self.experiment
        atomic_write_json(self.out / "pairs.json", {
            "iteration": self.iteration,
            "annecs": self.annecs,
            "pairs": [{
                "id": p.id, "parent": p.parent, "created": p.created, "retired": p.retired,
                "solved": p.solved, "novel": p.novel, "score": p.best_score,
                "terrain": p.terrain.to_dict(), "describe": p.terrain.describe(),
                "robot": p.best.to_dict(), "design": p.best.design(exp.shape).to_dict(),
            } for p in self.pairs],
        })  # fmt: skip
        self.recorder.finish(self.iteration, [p.best for p in self.active()], self.stopped_by)
        if self.figures:
            try:
                self.write_figures()
            except Exception:  # figures must never lose a finished run
                log.exception("could not write the POET figures of %s", self.out)

    def hardest_solved(self, n: int = 4) -> list[tuple[Pair, float]]:
        """The solved terrains the kept robots find hardest: fewest robots at the solved threshold,
        then the lowest mean score (simulations here are not counted in the log).

        Returns
        -------
        list of (Pair, float)
            Each pair with the mean score of every kept robot on its terrain.
        """
        solved = [p for p in self.pairs if p.solved is not None]
        if not solved:
            return []
        matrix, _ = self.score_matrix(self.pairs, solved)
        thr = self.config.solved_threshold
        order = sorted(range(len(solved)),
                       key=lambda j: ((matrix[:, j] >= thr).sum(), matrix[:, j].mean(), solved[j].id))  # fmt: skip
        return [(solved[j], float(matrix[:, j].mean())) for j in order[:n]]

    def write_figures(self) -> dict[str, Path]:
        """``figures/annecs.png``, ``figures/transfers.png`` and ``figures/gallery.png``."""
        fig_dir = self.out / "figures"
        out = {
            "annecs": plot_annecs({"poet": [self.rows]}, fig_dir / "annecs.png"),
            "transfers": plot_transfers(self.rows, fig_dir / "transfers.png"),
        }
        hardest = self.hardest_solved()
        if hardest:
            out["gallery"] = plot_gallery(self, hardest, fig_dir / "gallery.png")
        return out


def _matrix_log(robots: Sequence[Pair], terrains: Sequence[Pair], m: np.ndarray) -> dict[str, Any]:
    return {"robots": [p.id for p in robots], "terrains": [p.id for p in terrains],
            "scores": np.round(m, 6).tolist()}  # fmt: skip


# ---------------------------------------------------------------------- figures
def plot_annecs(
    groups: Mapping[str, Sequence[Sequence[Mapping[str, Any]]]], path: str | Path
) -> Path:
    """ANNECS over iterations: per label, one line per run, or the median and range of several.

    Parameters
    ----------
    groups : dict of str to list of log rows lists
        e.g. ``{"POET": [rows_seed0, rows_seed1], "random terrains": [...]}``.
    path : path
        PNG file.
    """
    plt = pyplot()
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig, ax = plt.subplots(figsize=(6.4, 3.8))
    for k, (label, runs) in enumerate(groups.items()):
        runs = [r for r in runs if r]
        if not runs:
            continue
        n = min(len(r) for r in runs)
        x = [r["generation"] for r in runs[0][:n]]
        y = np.array([[row["annecs"] for row in r[:n]] for r in runs], dtype=np.float64)
        color = f"C{k}"
        if len(runs) == 1:
            ax.step(x, y[0], where="post", color=color, label=label)
        else:
            ax.step(x, np.median(y, axis=0), where="post", color=color,
                    label=f"{label} (median of {len(runs)})")  # fmt: skip
            ax.fill_between(x, y.min(axis=0), y.max(axis=0), step="post", color=color, alpha=0.2)
    ax.set_xlabel("iteration")
    ax.set_ylabel("ANNECS")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def transfer_counts(rows: Sequence[Mapping[str, Any]]) -> tuple[list[int], np.ndarray]:
    """Transfers between pairs over a run's log: (pair ids, counts[source, target])."""
    ids = sorted({t["pair"] for r in rows for t in r.get("terrains", [])})
    index = {p: i for i, p in enumerate(ids)}
    counts = np.zeros((len(ids), len(ids)), dtype=np.int64)
    for r in rows:
        for t in r.get("transfers", []) or []:
            counts[index[t["from"]], index[t["to"]]] += 1
    return ids, counts


def plot_transfers(rows: Sequence[Mapping[str, Any]], path: str | Path) -> Path:
    """Heatmap of the transfers of a run (rows: the robot's pair, columns: the adopting pair)."""
    plt = pyplot()
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    ids, counts = transfer_counts(rows)
    fig, ax = plt.subplots(figsize=(0.35 * len(ids) + 3.0, 0.35 * len(ids) + 2.4))
    im = ax.imshow(counts, cmap="viridis", origin="upper")
    ax.set_xticks(range(len(ids)), [str(i) for i in ids], fontsize=7)
    ax.set_yticks(range(len(ids)), [str(i) for i in ids], fontsize=7)
    ax.set_xlabel("adopting pair")
    ax.set_ylabel("pair the robot came from")
    ax.set_title(f"{int(counts.sum())} transfers", fontsize=9)
    fig.colorbar(im, ax=ax, label="transfers")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def plot_gallery(run: PoetRun, hardest: Sequence[tuple[Pair, float]], path: str | Path) -> Path:
    """The hardest solved terrains, each with its robot's final pose after a run on it."""
    from softgym.engine import Simulation
    from softgym.render.frames import VoxelRenderer, render_rollout

    plt = pyplot()
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    n = len(hardest)
    fig, axes = plt.subplots(1, n, figsize=(3.6 * n, 3.4), squeeze=False)
    shape = run.experiment.shape
    for ax, (pair, mean) in zip(axes[0], hardest):
        task = run.task_for(pair.terrain)
        terrain = task.terrain_for(shape)
        cfg = task.config()
        sim = Simulation([pair.best.design(shape)], config=cfg, terrain=terrain)
        sim.advance_to(task.seconds)
        renderer = VoxelRenderer(
            width=360, height=300, voxel_size=cfg.voxel_size, pixels_per_voxel=9.0
        )
        ax.imshow(render_rollout(sim.rollout(), 0, renderer, terrain=terrain))
        ax.set_axis_off()
        ax.set_title(f"pair {pair.id}: {pair.terrain.describe()}\nrobot {pair.best_score:.1f} "
                     f"(all robots' mean {mean:.1f})", fontsize=8)  # fmt: skip
    fig.tight_layout(pad=1.2)
    fig.savefig(path, dpi=110, bbox_inches="tight")
    plt.close(fig)
    return path
