"""One row of a run's log per generation: statistics of every recorded metric, study columns.

:func:`log_row` is what :meth:`~evolvers.recording.recorder.RunRecorder.end_generation`
appends to ``log.csv`` / ``log.jsonl``; :func:`study_columns` are the columns a study
report reads (the generation's best individual, composition, repeats, obstacle
crossings); :func:`population_summary` is a population as comparable plain data.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from evolvers.evaluation.evaluator import FITNESS_METRICS, MAXIMIZED, EvalStats
from evolvers.evaluation.experiments import Experiment
from evolvers.operators.genome import Individual
from softgym.metrics import crossed_obstacles, final_xy, obstacle_footprint

__all__ = ["log_row", "population_summary", "study_columns"]


def population_summary(individuals: Sequence[Individual]) -> list[dict[str, Any]]:
    """Comparable plain data of a population: ids, ages, genomes, objectives (no wall times)."""
    return [ind.to_dict() for ind in individuals]


def _direction(exp: Experiment, metric: str) -> bool:
    """True if ``metric`` is better when larger."""
    for o in exp.objectives:
        if o.name == metric:
            return o.maximize
    return metric in MAXIMIZED


def _stats_of(values: np.ndarray, maximize: bool) -> dict[str, float]:
    if values.size == 0:
        return {k: float("nan") for k in ("best", "median", "mean", "worst")}
    return {
        "best": float(values.max() if maximize else values.min()),
        "median": float(np.median(values)),
        "mean": float(values.mean()),
        "worst": float(values.min() if maximize else values.max()),
    }


#: Composition counts of the generation's best individual copied into the log (``top_*``).
_TOP_COUNTS = ("n_voxels", "n_muscle", "n_bone", "n_tissue", "n_old_materials")


def _individual_columns(
    prefix: str, ind: Individual | None, metrics: Sequence[str]
) -> dict[str, Any]:
    nan = float("nan")
    out: dict[str, Any] = {f"{prefix}_id": -1 if ind is None else ind.id}
    for m in metrics:
        out[f"{prefix}_{m}"] = nan if ind is None else float(ind.objectives.get(m, nan))
    return out


def study_columns(
    experiment: Experiment, population: Sequence[Individual], stats: EvalStats
) -> dict[str, Any]:
    """Log columns a study report reads: the generation's best individual, composition, repeats, crossings.

    ``top_*``: the best individual of the population (by the first objective):
    its id, fitness measures, composition counts, genes
    (:meth:`Individual.genes`) and final centre of mass (``top_final_x``,
    ``top_final_y``, voxel lengths). ``muscle_fraction_median``: median share
    of muscle voxels over the population's valid bodies. ``new_individuals``
    and ``repeated_phenotypes``: individuals evaluated for the first time this
    generation, and how many of them had a phenotype already simulated in the
    run (:class:`~evolvers.evaluation.evaluator.EvalStats`). On a task with obstacles:
    ``crossed`` (individuals whose final centre of mass is outside the
    obstacles' footprint, :func:`softgym.metrics.obstacle_footprint`), ``top_crossed``, and
    ``crosser_*`` (the best of those, or id -1 and NaN).
    """
    exp = experiment
    fit = exp.fitness if exp.fitness.name != "age" else None
    name = fit.name if fit is not None else "norm_final_dist"
    maximize = True if fit is None else fit.maximize
    pop = [ind for ind in population if ind.objectives]
    row: dict[str, Any] = {
        "new_individuals": stats.n_new,
        "repeated_phenotypes": stats.n_repeated,
    }
    fractions = [
        ind.objectives["n_muscle"] / ind.objectives["n_voxels"]
        for ind in pop
        if ind.objectives.get("n_voxels", 0) > 0
    ]
    row["muscle_fraction_median"] = float(np.median(fractions)) if fractions else float("nan")
    scored = ("score",) if any(o.name == "score" for o in exp.objectives) else ()
    metrics = (*FITNESS_METRICS, *scored, *_TOP_COUNTS)
    values = np.array([ind.value(name) for ind in pop], dtype=np.float64)
    top = pop[int(np.argmax(values if maximize else -values))] if pop else None
    row.update(_individual_columns("top", top, metrics))
    if top is not None:
        row.update({f"top_{k}": v for k, v in top.genes().items()})
    task = exp.make_task()
    voxel_size = task.config().voxel_size
    xy = final_xy(None if top is None else top.trace, voxel_size)
    row["top_final_x"], row["top_final_y"] = xy
    footprint = obstacle_footprint(task.terrain_for(exp.shape))
    if footprint is not None:
        crossers = [ind for ind in pop if crossed_obstacles(final_xy(ind.trace, voxel_size), footprint)]
        row["crossed"] = len(crossers)
        row["top_crossed"] = int(top is not None and crossed_obstacles(xy, footprint))
        best = None
        if crossers:
            cv = np.array([ind.value(name) for ind in crossers], dtype=np.float64)
            best = crossers[int(np.argmax(cv if maximize else -cv))]
        row.update(_individual_columns("crosser", best, metrics))
    return row


def log_row(
    experiment: Experiment,
    generation: int,
    population: Sequence[Individual],
    stats: EvalStats,
    wall: float,
    evaluations_total: int,
    wall_total: float,
) -> dict[str, Any]:
    """One log row: counts of the generation's evaluation and statistics of every recorded metric."""
    exp = experiment
    row: dict[str, Any] = {
        "generation": generation,
        "evaluations": stats.n_simulated,
        "evaluations_total": evaluations_total,
        "cache_hits": stats.n_cached,
        "invalid": stats.n_invalid,
        "diverged": stats.n_diverged,
        "bone_fraction": stats.n_bone / max(1, stats.n_individuals),
        "wall_time": wall,
        "wall_total": wall_total,
    }
    names = list(exp.metrics)
    if any(o.name == "age" for o in exp.objectives):
        names.append("age")
    for m in names:
        vals = np.array([ind.value(m) for ind in population], dtype=np.float64)
        for k, v in _stats_of(vals, _direction(exp, m)).items():
            row[f"{m}_{k}"] = v
    if exp.selection.startswith("novelty"):
        vals = np.array(
            [ind.novelty for ind in population if ind.novelty is not None], dtype=np.float64
        )
        for k, v in _stats_of(vals, False).items():
            row[f"novelty_{k}"] = v
    row.update(study_columns(exp, population, stats))
    return row

