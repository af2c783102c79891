"""Batched population evaluation with a (task, phenotype) cache: the one evaluator of every driver.

An :class:`Evaluator` turns individuals into designs, skips those whose
phenotype (grid + used materials + controller, :meth:`Individual.phenotype_key`)
was already simulated on the same task, and simulates all the others **in one
batched Simulation per task** (locally) or in a few batches spread over Dask
workers (:mod:`evolvers.evaluation.distributed`). The ordinary drivers evaluate on their
experiment's task (:meth:`Evaluator.evaluate`); POET scores robots on many
terrains at once (:meth:`Evaluator.evaluate_jobs`, the cache keyed by terrain
and phenotype, :meth:`PhenotypeCache.key`). A robot's result does not depend on
its batch, so local and distributed runs, cached and fresh evaluations, agree
bit for bit.
"""

from __future__ import annotations

import hashlib
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import partial
from typing import Any

import numpy as np

from evolvers.evaluation.experiments import Experiment
from evolvers.operators.genome import Individual
from softgym.design import RobotDesign
from softgym.evaluate import METRIC_KEYS, evaluate
from softgym.exceptions import CheckpointError
from softgym.metrics import WORST_FITNESS, WORST_MINIMIZED
from softgym.tasks import Task

__all__ = [
    "FITNESS_METRICS",
    "MAXIMIZED",
    "BatchFn",
    "EvalStats",
    "Evaluator",
    "Job",
    "JobsFn",
    "PhenotypeCache",
    "STORED_METRICS",
    "local_batch_fn",
    "pack_traces",
    "unpack_traces",
    "worst_objectives",
]

#: Maximised metrics (the rest are counts, minimised when they are objectives).
FITNESS_METRICS: tuple[str, ...] = ("norm_final_dist", "max_xy_dist", "l_coefficient")
#: Every maximised metric: the fitness measures and a task's ``score`` (its own measure).
MAXIMIZED: tuple[str, ...] = (*FITNESS_METRICS, "score")

#: ``(designs, task) -> softgym.evaluate output with traces``. The designs are
#: :class:`~softgym.design.RobotDesign` objects (plain dicts only across Dask, where
#: :class:`evolvers.evaluation.distributed.DaskBatchFn` turns them into ``to_dict()``).
BatchFn = Callable[[list[RobotDesign], Task], dict[str, Any]]
#: ``[(designs, task), ...] -> [softgym.evaluate output, ...]``: several tasks' batches at once.
JobsFn = Callable[[list[tuple[list[RobotDesign], Task]]], list[dict[str, Any]]]
#: Robots to score on one task, :meth:`Evaluator.evaluate_jobs`: ``(task key, task, individuals)``.
Job = tuple[str | None, Task, Sequence[Individual]]

#: The metrics kept per evaluated phenotype (on individuals and in the cache).
STORED_METRICS: tuple[str, ...] = tuple(k for k in METRIC_KEYS if k != "time_max_xy_dist")

#: The cache's columns in checkpoints written before they carried their names
#: (``cache_metrics``): :data:`STORED_METRICS` before the task suite added ``score``.
_UNNAMED_CACHE_COLUMNS: tuple[str, ...] = (
    "norm_final_dist", "max_xy_dist", "l_coefficient", "diverged",
    "n_voxels", "n_muscle", "n_old_materials", "n_bone", "n_tissue",
)  # fmt: skip


def local_batch_fn(
    designs: list[RobotDesign] | list[dict[str, Any]], task: Task, progress: bool | None = None
) -> dict[str, Any]:
    """Evaluate every design in one local Simulation (:func:`softgym.evaluate`;
    ``progress`` as there: None shows a bar for a batch that takes long).
    """
    return evaluate(designs, task=task, traces=True, progress=progress)


def pack_traces(traces: Sequence[np.ndarray | None]) -> tuple[np.ndarray, np.ndarray]:
    """Pad traces into one array.

    Returns
    -------
    data : ndarray of shape (n, max_points, 4), float64
    lengths : ndarray of shape (n,), int64
        Points of each trace; -1 for None.
    """
    n = len(traces)
    lengths = np.array([-1 if t is None else len(t) for t in traces], dtype=np.int64)
    m = max([0, *lengths.tolist()])
    data = np.zeros((n, m, 4))
    for i, t in enumerate(traces):
        if t is not None and len(t):
            data[i, : len(t)] = t
    return data, lengths


def unpack_traces(data: np.ndarray, lengths: np.ndarray) -> list[np.ndarray | None]:
    """Inverse of :func:`pack_traces`."""
    return [None if n < 0 else np.array(data[i, :n]) for i, n in enumerate(lengths.tolist())]


class PhenotypeCache:
    """Results by (task, phenotype) key (:meth:`key`): metric values and the centre-of-mass trace."""

    def __init__(self) -> None:
        self._data: dict[str, tuple[dict[str, float], np.ndarray | None]] = {}

    def __len__(self) -> int:
        return len(self._data)

    def __contains__(self, key: str) -> bool:
        return key in self._data

    @staticmethod
    def key(phenotype: str, task: str | None = None) -> str:
        """The cache key of a phenotype (:meth:`Individual.phenotype_key`) on a task.

        ``task`` None (a run's own task): the phenotype key itself; else the
        SHA-256 (hex) of the task's key and the phenotype key, e.g. POET's
        ``TerrainGenome.key()``. Both keys are what checkpoints have always stored.
        """
        if task is None:
            return phenotype
        return hashlib.sha256((task + phenotype).encode()).hexdigest()

    def get(self, key: str) -> tuple[dict[str, float], np.ndarray | None]:
        """The stored ``(objectives, trace)`` of ``key``."""
        return self._data[key]

    def put(self, key: str, objectives: dict[str, float], trace: np.ndarray | None) -> None:
        """Store a result."""
        self._data[key] = (dict(objectives), trace)

    def to_arrays(self) -> dict[str, np.ndarray]:
        """Checkpoint arrays (plain dtypes, no pickle)."""
        keys = list(self._data)
        values = np.array(
            [[self._data[k][0].get(m, np.nan) for m in STORED_METRICS] for k in keys],
            dtype=np.float64,
        ).reshape(len(keys), len(STORED_METRICS))
        data, lengths = pack_traces([self._data[k][1] for k in keys])
        return {
            "cache_keys": np.array(keys, dtype="<U64"),
            "cache_metrics": np.array(STORED_METRICS, dtype="<U32"),
            "cache_values": values,
            "cache_traces": data,
            "cache_trace_len": lengths,
        }

    @classmethod
    def from_arrays(cls, arrays: dict[str, np.ndarray]) -> PhenotypeCache:
        """Inverse of :meth:`to_arrays` (an empty cache if the arrays are absent).

        Columns are matched by the names stored with them (``cache_metrics``),
        so a checkpoint reads back right after the stored metrics change;
        older checkpoints without names have :data:`_UNNAMED_CACHE_COLUMNS`.
        A value stored as NaN (a metric the entry did not have) stays absent.

        Raises
        ------
        CheckpointError
            If the number of columns does not match their names.
        """
        cache = cls()
        if "cache_keys" not in arrays:
            return cache
        for name in ("cache_keys", "cache_metrics"):
            if name in arrays and (arrays[name].ndim != 1 or arrays[name].dtype.kind != "U"):
                raise CheckpointError(
                    f"{name}: expected a 1-D array of names, got {arrays[name].dtype} of shape "
                    f"{arrays[name].shape}; the checkpoint is damaged"
                )
        if "cache_metrics" in arrays:
            names = tuple(str(m) for m in arrays["cache_metrics"].tolist())
        else:
            names = _UNNAMED_CACHE_COLUMNS
        values = np.asarray(arrays["cache_values"], dtype=np.float64)
        if values.ndim == 2 and values.shape[0] != len(arrays["cache_keys"]):
            raise CheckpointError(
                f"cache_values: {values.shape[0]} rows for {len(arrays['cache_keys'])} cached "
                "results; the checkpoint is damaged"
            )
        if values.ndim != 2 or values.shape[1] != len(names):
            raise CheckpointError(
                f"cache_values: {values.shape[-1] if values.ndim else 0} columns for "
                f"{len(names)} metric names {names}; the checkpoint is damaged (one resumed "
                "across the addition of 'score' is repaired by scripts/repair_cache_columns.py)"
            )
        traces = unpack_traces(arrays["cache_traces"], arrays["cache_trace_len"])
        for key, row, tr in zip(arrays["cache_keys"].tolist(), values, traces):
            obj = {m: float(v) for m, v in zip(names, row) if not np.isnan(v)}
            cache._data[str(key)] = (obj, tr)
        return cache


@dataclass
class EvalStats:
    """What one :meth:`Evaluator.evaluate` call did."""

    n_individuals: int = 0
    n_simulated: int = 0
    n_cached: int = 0
    n_invalid: int = 0
    n_diverged: int = 0
    n_bone: int = 0
    #: Individuals not evaluated before this call (children, newcomers; parents are not).
    n_new: int = 0
    #: New, valid individuals whose phenotype was already simulated earlier in the run
    #: (or twice in this call): the seed's "patterns loop".
    n_repeated: int = 0
    #: Simulated seconds summed over the simulated robots (each its task's ``seconds``;
    #: cached results count none): what a run's ``max_robot_seconds`` budget counts.
    robot_seconds: float = 0.0


def worst_objectives() -> dict[str, float]:
    """The objectives of an invalid or diverged robot: the worst value of every
    stored metric (maximised ones :data:`~softgym.metrics.WORST_FITNESS`, counts
    :data:`~softgym.metrics.WORST_MINIMIZED`), ``diverged`` 0.
    """
    out = {m: (WORST_FITNESS if m in MAXIMIZED else WORST_MINIMIZED) for m in STORED_METRICS}
    out["diverged"] = 0.0
    return out


class Evaluator:
    """Evaluate individuals of an experiment, batched and cached by (task, phenotype).

    Every driver evaluates through one: the ordinary runs on the experiment's
    task (:meth:`evaluate`), POET on each pair's terrain (:meth:`evaluate_jobs`,
    several tasks' batches at once).

    Parameters
    ----------
    experiment : Experiment
        Gives the task (:meth:`Experiment.make_task`), the grid shape and the rules.
    batch_fn : callable, optional
        ``(designs, task) -> metrics`` (default :func:`local_batch_fn`:
        one local Simulation). :class:`evolvers.evaluation.distributed.DaskBatchFn` spreads
        the batch over Dask workers.
    n_threads : int, optional
        OpenMP threads of local simulations.
    cache : PhenotypeCache, optional
        Shared results (a fresh cache by default).
    progress : bool
        False keeps the default batch function's progress bar off (a run
        that shows none of its own, e.g. inside a study).
    jobs_fn : callable, optional
        Several tasks' batches at once (:data:`JobsFn`, e.g.
        :meth:`evolvers.evaluation.distributed.DaskBatchFn.jobs`); default ``batch_fn``
        on each batch in turn.
    traces : bool
        Keep each robot's centre-of-mass trace (in the cache and on the
        individuals); False stores None (POET, which scores distances only).
    """

    def __init__(
        self,
        experiment: Experiment,
        batch_fn: BatchFn | None = None,
        n_threads: int | None = None,
        cache: PhenotypeCache | None = None,
        progress: bool = True,
        jobs_fn: JobsFn | None = None,
        traces: bool = True,
    ) -> None:
        self.experiment = experiment
        self.task = experiment.make_task(n_threads)
        # the default batch function shows a bar on long batches unless asked not to
        self.batch_fn = batch_fn or (
            local_batch_fn if progress else partial(local_batch_fn, progress=False)
        )
        self.jobs_fn: JobsFn = jobs_fn or self._each_batch
        self.traces = bool(traces)
        self.cache = PhenotypeCache() if cache is None else cache
        self.n_evaluations = 0

    def _each_batch(self, jobs: list[tuple[list[RobotDesign], Task]]) -> list[dict[str, Any]]:
        return [self.batch_fn(designs, task) for designs, task in jobs]

    def evaluate(self, individuals: Sequence[Individual]) -> EvalStats:
        """Fill ``objectives`` and ``trace`` of every individual (in place), on the experiment's task.

        All metrics of :func:`softgym.evaluate` are stored (``diverged`` as
        0/1). Invalid bodies (breaking the experiment's rules) are not
        simulated and get the worst values; identical phenotypes are
        simulated once.
        """
        return self.evaluate_jobs([(None, self.task, individuals)])[1]

    def evaluate_jobs(
        self, jobs: Sequence[Job], assign: bool = True
    ) -> tuple[list[list[dict[str, float]]], EvalStats]:
        """Results of robots on tasks: every uncached (task, phenotype) simulated once, batched.

        Parameters
        ----------
        jobs : sequence of (task key, Task, sequence of Individual)
            The key names the task in the cache (:meth:`PhenotypeCache.key`;
            None: the experiment's own task). The uncached robots of one key
            are one batch (the task of its first job), all batches one
            :attr:`jobs_fn` call.
        assign : bool
            Store each robot's results on it (``objectives``, ``trace``); False
            only reads them (robots scored on another pair's terrain).

        Returns
        -------
        results : list of list of dict
            The objectives of each robot of each job (read only).
        stats : EvalStats
        """
        exp = self.experiment
        stats = EvalStats()
        # cache key -> the robot simulated for it; task key -> (task, its keys to simulate)
        pending: dict[str, Individual] = {}
        batches: dict[str | None, tuple[Task, list[str]]] = {}
        rows: list[list[dict[str, float] | str]] = []
        for task_key, task, inds in jobs:
            row: list[dict[str, float] | str] = []
            for ind in inds:
                stats.n_individuals += 1
                new = not ind.objectives  # parents carry their results; children and newcomers do not
                stats.n_new += int(new)
                grid = ind.grid(exp.shape)
                if exp.rules.violations(grid):
                    row.append(worst_objectives())
                    if assign:
                        ind.objectives = worst_objectives()
                        ind.trace = None
                    stats.n_invalid += 1
                    continue
                if (grid == 2).any():
                    stats.n_bone += 1
                key = PhenotypeCache.key(ind.phenotype_key(exp.shape), task_key)
                seen = key in self.cache or key in pending
                stats.n_repeated += int(new and seen)
                stats.n_cached += int(seen)
                row.append(key)
                if key in self.cache:
                    if assign:
                        obj, tr = self.cache.get(key)
                        ind.objectives = dict(obj)
                        ind.trace = tr
                elif key not in pending:
                    pending[key] = ind
                    batches.setdefault(task_key, (task, []))[1].append(key)
            rows.append(row)
        if pending:
            groups = list(batches.values())
            # the designs as objects: dicts only where they cross to Dask workers
            outs = self.jobs_fn(
                [([pending[k].design(exp.shape) for k in keys], task) for task, keys in groups]
            )
            for (task, keys), res in zip(groups, outs):
                stats.robot_seconds += len(keys) * float(task.seconds)
                for i, key in enumerate(keys):
                    # (a batch function of an older softgym, or a fake, may not report "score")
                    obj = {m: float(res[m][i]) for m in STORED_METRICS if m in res}
                    tr = res["traces"][i] if self.traces else None
                    tr = None if tr is None else np.asarray(tr, dtype=np.float64)
                    self.cache.put(key, obj, tr)
                    stats.n_diverged += int(obj["diverged"])
            stats.n_simulated = len(pending)
        self.n_evaluations += stats.n_simulated
        results = []
        for (_, _, inds), row in zip(jobs, rows):
            out = []
            for ind, entry in zip(inds, row):
                if isinstance(entry, dict):
                    out.append(entry)
                    continue
                obj, tr = self.cache.get(entry)
                out.append(obj)
                if assign and entry in pending:
                    ind.objectives = dict(obj)
                    ind.trace = tr
            results.append(out)
        return results, stats
