"""Quality-diversity over robot designs: MAP-Elites on pyribs with softgym's genomes and operators.

The pieces are pyribs' own (``pip install "softgym[qd]"``, pyribs 0.12):

* an archive of softgym genomes (:class:`~evolvers.operators.genome.Individual`; pyribs
  stores them with ``solution_dtype=object``): a
  :class:`ribs.archives.GridArchive` over body descriptors
  (:mod:`evolvers.evaluation.descriptors`; by default Mouret and Clune's 2015 pair, stiff
  fraction x filled fraction, 128 x 128 cells) or a
  :class:`ribs.archives.CVTArchive` (``archive="cvt"``);
* :class:`SoftbotEmitter`, a :class:`ribs.emitters.EmitterBase` that draws
  parents uniformly from the elites and varies them with softgym's operators
  (:func:`~evolvers.operators.variation.make_children`: CPPN mutation with validity
  retries, arithmetic crossover and bounded Gaussian mutation of the
  controller / material genes and the brain's weights when the experiment
  evolves them; on a fixed body only those vary); while the archive is empty
  it asks for random valid robots (with random brains);
* a :class:`ribs.schedulers.Scheduler` ask/tell loop, each ask evaluated by
  softgym's :class:`~evolvers.evaluation.evaluator.Evaluator` (one batched Simulation,
  phenotype-cached, or Dask through ``batch_fn``).

The objective is the experiment's fitness (``norm_final_dist`` or
``max_xy_dist``, voxel lengths, or a task's ``score``), floored at
:data:`OBJECTIVE_FLOORS`: a distance at 0, so a diverged robot scores 0, as
if it had not moved (pyribs' archives have no infeasibility; its
``threshold_min`` is for CMA-MAE only); a score, which may be negative (a turn the
wrong way, progress downhill), at -1000, with the archive's ``qd_score_offset``
there so that the QD-score counts every elite from the floor.

:class:`QDRun` writes the run folder every driver writes
(:class:`~evolvers.recording.recorder.RunRecorder`: config, log, hall of fame, atomic
pickle-free checkpoints, figures). Per generation the log gets the archive's
statistics (``qd_score``, ``coverage``, ``num_elites``, ``qd_best``,
``qd_mean``, ``norm_qd_score``, ``new_cells``, ``improved_cells``); they are
computed from the elites with an exactly rounded sum, so they equal
``archive.stats`` up to rounding and do not depend on the order in which the
elites were inserted. The checkpoint holds the archive as arrays (cell index,
objective, descriptors, threshold; CVT centroids) and its genomes as JSON; a
resumed run re-inserts them and finishes exactly like an uninterrupted one.
The figures add the archive heatmap (``figures/archive_heatmap.png``, pyribs'
``grid_archive_heatmap`` / ``cvt_archive_heatmap``) and QD-score and coverage
over evaluations (``figures/qd_progress.png``). :func:`export_elites` writes
the elites as design files (JSON and ``.vxa``).
"""

from __future__ import annotations

import logging
import math
import os
import sys
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, fields
from pathlib import Path
from typing import Any

import numpy as np

from evolvers.drivers.base import Checkpoint, Driver, IdCounter
from evolvers.evaluation.descriptors import MOURET_CLUNE_2015, check_descriptors, descriptor_values
from evolvers.evaluation.distributed import MissingExtraError
from evolvers.evaluation.evaluator import (
    EvalStats,
    pack_traces,
    unpack_traces,
)
from evolvers.evaluation.experiments import Experiment
from evolvers.operators.genome import Individual
from evolvers.operators.variation import make_children
from softgym.exceptions import CheckpointError, InvalidParameterError
from softgym.io import (
    atomic_write_json,
    atomic_write_text,
    load_latest_intact,
    read_json,
    rng_from_state,
    rng_state,
)
from softgym.render.figures import pyplot


def _numba_cache_in_user_folder() -> None:
    """Point numba's cache (pyribs compiles through numba, whose ``cache=True`` functions
    write beside their source, in site-packages) at the user's cache folder,
    ``$XDG_CACHE_HOME/softgym/numba`` (``~/.cache/softgym/numba``; Windows:
    ``%LOCALAPPDATA%/softgym/numba``), unless ``NUMBA_CACHE_DIR`` is set already.
    """
    if os.environ.get("NUMBA_CACHE_DIR"):
        return  # the user's own setting
    if sys.platform == "win32":  # pragma: no cover - Windows only
        base = os.environ.get("LOCALAPPDATA") or os.path.expanduser("~")
    else:
        base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    os.environ["NUMBA_CACHE_DIR"] = os.path.join(base, "softgym", "numba")
    config = sys.modules.get("numba.core.config")
    if config is not None:  # numba imported already: it read the variable then
        config.CACHE_DIR = os.environ["NUMBA_CACHE_DIR"]


_numba_cache_in_user_folder()  # before pyribs imports numba

try:
    from ribs.archives import CVTArchive, GridArchive, k_means_centroids
    from ribs.emitters import EmitterBase
    from ribs.schedulers import Scheduler
except ImportError as exc:  # pragma: no cover - the extra is installed in CI
    raise MissingExtraError(
        'quality-diversity runs need the "qd" extra: pip install "softgym[qd]"'
    ) from exc

__all__ = [
    "ARCHIVES",
    "OBJECTIVE_FLOORS",
    "QD_OBJECTIVES",
    "QDConfig",
    "QDRun",
    "SoftbotEmitter",
    "archive_stats",
    "export_elites",
    "make_archive",
    "plot_archive_heatmap",
    "plot_qd_progress",
    "MAX_CELLS",
]

#: Most cells an archive may have (a grid of 1,000 x 1,000): each is an array
#: slot of pyribs' archive and, once filled, an elite's design in the checkpoint.
MAX_CELLS = 1_000_000

log = logging.getLogger("evolvers")

#: Archive kinds of :class:`QDConfig`.
ARCHIVES: tuple[str, ...] = ("grid", "cvt")
#: Metrics a QD run may maximise (non-negative distances, voxel lengths; a task's score).
QD_OBJECTIVES: tuple[str, ...] = ("norm_final_dist", "max_xy_dist", "score")
#: The lowest archive objective of each metric (a lower value, e.g. a diverged robot's
#: WORST_FITNESS, counts as the floor); also the archive's ``qd_score_offset``.
OBJECTIVE_FLOORS: dict[str, float] = {"norm_final_dist": 0.0, "max_xy_dist": 0.0, "score": -1000.0}


@dataclass(frozen=True)
class QDConfig:
    """The archive of a quality-diversity run.

    Parameters
    ----------
    descriptors : tuple of str
        Names of :data:`evolvers.evaluation.descriptors.DESCRIPTORS` (default ``("stiff",
        "filled")``, Mouret and Clune 2015); each spans [0, 1].
    cells : tuple of int
        ``"grid"``: cells per descriptor (one value is used for every
        descriptor; default 128 x 128). ``"cvt"``: one value, the number of
        centroids.
    archive : {"grid", "cvt"}
        A :class:`ribs.archives.GridArchive` or a :class:`ribs.archives.CVTArchive`
        (centroids by k-means over ``cvt_samples`` uniform samples, seeded by the run).
    objective : str, optional
        The maximised metric, one of :data:`QD_OBJECTIVES` (default: the
        experiment's fitness).
    cvt_samples : int
        Samples of the CVT's k-means.
    """

    descriptors: tuple[str, ...] = MOURET_CLUNE_2015
    cells: tuple[int, ...] = (128,)
    archive: str = "grid"
    objective: str | None = None
    cvt_samples: int = 20_000

    def __post_init__(self) -> None:
        object.__setattr__(self, "descriptors", check_descriptors(self.descriptors))
        cells = (self.cells,) if isinstance(self.cells, (int, np.integer)) else self.cells
        cells = tuple(int(c) for c in cells)
        if self.archive not in ARCHIVES:
            raise InvalidParameterError(f"archive must be one of {ARCHIVES}, got {self.archive!r}")
        d = len(self.descriptors)
        if self.archive == "grid" and len(cells) == 1:
            cells = cells * d
        want = 1 if self.archive == "cvt" else d
        if len(cells) != want or min(cells) < 1:
            raise InvalidParameterError(
                f"cells must be {want} positive int(s) for a {self.archive} archive over "
                f"{d} descriptor(s), got {list(cells)}"
            )
        if int(np.prod(cells)) > MAX_CELLS:
            raise InvalidParameterError(
                f"cells {list(cells)} make {int(np.prod(cells))} archive cells, more than "
                f"{MAX_CELLS}: fewer cells per descriptor (each holds an elite and its design)"
            )
        object.__setattr__(self, "cells", cells)
        if self.objective is not None and self.objective not in QD_OBJECTIVES:
            raise InvalidParameterError(
                f"objective must be one of {QD_OBJECTIVES}, got {self.objective!r}"
            )
        if self.cvt_samples < max(cells):
            raise InvalidParameterError("cvt_samples must be at least the number of cells")

    @property
    def n_cells(self) -> int:
        """Cells of the archive."""
        return int(np.prod(self.cells))

    def objective_for(self, experiment: Experiment) -> str:
        """The maximised metric for ``experiment``."""
        name = self.objective or experiment.fitness.name
        if name not in QD_OBJECTIVES:
            raise InvalidParameterError(
                f"a QD run maximises one of {QD_OBJECTIVES}; experiment {experiment.name!r} "
                f"has fitness {name!r} (pass objective=...)"
            )
        return name

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict."""
        return {
            f.name: list(v) if isinstance(v := getattr(self, f.name), tuple) else v
            for f in fields(self)
        }

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> QDConfig:
        """Inverse of :meth:`to_dict`."""
        kw = dict(data)
        for name in ("descriptors", "cells"):
            if name in kw:
                kw[name] = tuple(kw[name])
        return cls(**kw)


def make_archive(config: QDConfig, seed: int, centroids: np.ndarray | None = None,
                 qd_score_offset: float = 0.0) -> Any:  # fmt: skip
    """An empty pyribs archive of softgym genomes (``solution_dtype=object``).

    Parameters
    ----------
    config : QDConfig
    seed : int
        Seeds the archive's generator and the CVT's k-means.
    centroids : ndarray of shape (n_cells, n_descriptors), float64, optional
        CVT centroids (a checkpoint's); computed when not given.
    qd_score_offset : float
        What the QD-score subtracts from each elite's objective (the objective's floor,
        :data:`OBJECTIVE_FLOORS`).

    Returns
    -------
    ribs.archives.GridArchive or ribs.archives.CVTArchive
    """
    ranges = [(0.0, 1.0)] * len(config.descriptors)
    common = {"solution_dim": (), "ranges": ranges, "seed": int(seed), "solution_dtype": object,
              "qd_score_offset": float(qd_score_offset)}  # fmt: skip
    if config.archive == "grid":
        return GridArchive(dims=list(config.cells), **common)
    if centroids is None:
        centroids, _ = k_means_centroids(
            centroids=config.cells[0], ranges=ranges, samples=config.cvt_samples, seed=int(seed)
        )
    return CVTArchive(centroids=np.asarray(centroids, dtype=np.float64), **common)


def _elite_data(archive: Any) -> dict[str, np.ndarray]:
    """The archive's elites, sorted by cell index (an order independent of insertion)."""
    data = archive.data()
    order = np.argsort(data["index"], kind="stable")
    return {k: np.asarray(v)[order] for k, v in data.items()}


def archive_stats(archive: Any) -> dict[str, float | int]:
    """Statistics of an archive, independent of the order its elites were inserted in.

    Returns
    -------
    dict
        ``num_elites``; ``coverage`` (elites / cells); ``qd_score`` (sum of
        ``objective - qd_score_offset`` over the elites, exactly rounded);
        ``norm_qd_score`` (``qd_score`` / cells); ``qd_best`` and ``qd_mean``
        (maximum and mean objective; NaN when empty). They equal
        ``archive.stats`` up to the rounding of its running sum.
    """
    obj = np.asarray(archive.data("objective"), dtype=np.float64)
    n = int(obj.size)
    qd = math.fsum((obj - float(archive.qd_score_offset)).tolist())
    return {
        "num_elites": n,
        "coverage": n / int(archive.cells),
        "qd_score": qd,
        "norm_qd_score": qd / int(archive.cells),
        "qd_best": float(obj.max()) if n else float("nan"),
        "qd_mean": math.fsum(obj.tolist()) / n if n else float("nan"),
    }


def _object_array(items: Sequence[Any]) -> np.ndarray:
    out = np.empty(len(items), dtype=object)
    for i, x in enumerate(items):
        out[i] = x
    return out


class SoftbotEmitter(EmitterBase):
    """A pyribs emitter of softgym genomes, varied with softgym's own operators.

    :meth:`ask` draws ``batch_size`` parents uniformly (with replacement)
    from the elites, taken in cell-index order, with the emitter's own
    generator, and returns their children from
    :func:`~evolvers.operators.variation.make_children` (CPPN mutation until the body
    changes and stays valid; arithmetic crossover and bounded Gaussian
    mutation of the controller and material genes when the experiment
    evolves them). While the archive is empty it returns ``batch_size``
    random valid robots. :meth:`tell` keeps the last batch's insertion counts.

    Parameters
    ----------
    archive : ribs.archives.ArchiveBase
        An archive with ``solution_dtype=object`` (:func:`make_archive`).
    experiment : Experiment
        Grid shape, composition rules, CPPN outputs and which genes evolve.
    batch_size : int
        Solutions per :meth:`ask`.
    rng : numpy.random.Generator or int or None
        Every random choice of the emitter.
    next_id : callable, optional
        ``next_id()`` gives a fresh individual id (default: 0, 1, 2, ...).
    """

    def __init__(
        self,
        archive: Any,
        experiment: Experiment,
        batch_size: int,
        rng: np.random.Generator | int | None = None,
        next_id: Callable[[], int] | None = None,
    ) -> None:
        super().__init__(archive, solution_dim=(), bounds=None, lower_bounds=None,
                         upper_bounds=None)  # fmt: skip
        if int(batch_size) < 1:
            raise InvalidParameterError(f"batch_size must be >= 1, got {batch_size}")
        self.experiment = experiment
        self.batch_size = int(batch_size)
        self.rng = rng if isinstance(rng, np.random.Generator) else np.random.default_rng(rng)
        self.next_id = IdCounter() if next_id is None else next_id
        #: Cells newly filled and cells improved by the last :meth:`tell`.
        self.new_cells = 0
        self.improved_cells = 0

    def ask(self) -> np.ndarray:
        """A batch of new genomes.

        Returns
        -------
        ndarray of shape (batch_size,), dtype=object
            :class:`~evolvers.operators.genome.Individual` objects, not yet evaluated.
        """
        exp = self.experiment
        if self.archive.empty:
            children = [
                exp.random_individual(self.rng, self.next_id()) for _ in range(self.batch_size)
            ]
        else:
            pool = _elite_data(self.archive)["solution"]
            picks = self.rng.integers(len(pool), size=self.batch_size)
            children = make_children(
                [pool[int(i)] for i in picks], self.rng, self.next_id, **exp.variation()
            )
        return _object_array(children)

    def tell(
        self,
        solution: Any,
        objective: Any,
        measures: Any,
        add_info: Mapping[str, np.ndarray],
        **fields: Any,
    ) -> None:
        """Count the distinct cells the batch filled (status 2) and improved (status 1)."""
        status = np.asarray(add_info["status"])
        cells = np.asarray(self.archive.index_of(np.asarray(measures)))
        self.new_cells = len(np.unique(cells[status == 2]))
        self.improved_cells = len(np.unique(cells[status == 1]))


class QDRun(Driver):
    """A resumable MAP-Elites run of an experiment's robots (see the module docstring).

    ``generations`` counts the batches after generation 0 (the first, random
    batch), as for every driver.

    Parameters
    ----------
    experiment : Experiment
        The task, robot shape, rules, and which genes evolve;
        ``experiment.pop_size`` is the batch size (robots per generation).
    out : path
        Run folder.
    seed : int
        Seeds the emitter's generator (every random choice) and the archive.
    generations : int, optional
        Default: the experiment's.
    config : QDConfig, optional
        The archive (default: Mouret and Clune's 128 x 128 grid).
    **driver
        ``batch_fn``, ``n_threads``, ``on_generation``, ``figures``, ``gif``,
        ``progress``: as for :class:`~evolvers.drivers.base.Driver` (Ctrl-C raises
        :class:`~evolvers.recording.recorder.RunInterrupted` the same way).
    """

    backend = "qd"

    def __init__(self, experiment: Experiment, out: str | Path, seed: int = 0,
                 generations: int | None = None, *, config: QDConfig | None = None,
                 **driver: Any) -> None:  # fmt: skip
        self.config = QDConfig() if config is None else config
        self.objective = self.config.objective_for(experiment)
        super().__init__(experiment, out, seed, generations,
                         extra_config={"qd": self.config.to_dict()}, **driver)  # fmt: skip

    def _fresh(self, centroids: np.ndarray | None = None) -> None:
        super()._fresh()
        self.archive = make_archive(self.config, self.seed, centroids,
                                    OBJECTIVE_FLOORS[self.objective])  # fmt: skip
        self.emitter = SoftbotEmitter(
            self.archive, self.experiment, self.experiment.pop_size,
            np.random.default_rng(self.seed), self.ids,
        )  # fmt: skip
        self.scheduler = Scheduler(self.archive, [self.emitter], add_mode="batch")

    @property
    def label(self) -> str:
        """The progress bar's description."""
        return f"{self.experiment.name} [qd {self.config.archive}]"

    def result(self) -> list[Individual]:
        """The elites, in cell-index order (what :meth:`run` returns)."""
        return self.elites()

    # ------------------------------------------------------------------ the record
    def elites(self) -> list[Individual]:
        """The archive's elites in cell-index order."""
        return list(_elite_data(self.archive)["solution"])

    def stats(self) -> dict[str, float | int]:
        """:func:`archive_stats` of the archive."""
        return archive_stats(self.archive)

    @property
    def score_maximized(self) -> bool:
        """The archive's objective is maximised."""
        return True

    def best_score(self) -> float | None:
        """The archive's best objective (``qd_best``; the ``target_score`` budget's score),
        None while the archive is empty.
        """
        best = self.stats()["qd_best"]
        return None if math.isnan(best) else float(best)

    # ------------------------------------------------------------------ the loop
    def objective_values(self, individuals: Sequence[Individual]) -> np.ndarray:
        """The archive objective of evaluated individuals: the metric, floored at
        :data:`OBJECTIVE_FLOORS` (0 for a distance).

        Returns
        -------
        ndarray of shape (n,), float64
        """
        floor = OBJECTIVE_FLOORS[self.objective]
        return np.array(
            [max(float(ind.objectives[self.objective]), floor) for ind in individuals],
            dtype=np.float64,
        )

    def descriptors(self, individuals: Sequence[Individual]) -> np.ndarray:
        """Descriptors of the individuals' bodies, ndarray of shape (n, n_descriptors), float64."""
        shape = self.experiment.shape
        return descriptor_values([ind.grid(shape) for ind in individuals], self.config.descriptors)

    def _step(self) -> EvalStats:
        """One ask / evaluate / tell round."""
        solutions = self.scheduler.ask()
        batch = list(solutions)
        stats = self.evaluator.evaluate(batch)
        self.scheduler.tell(self.objective_values(batch), self.descriptors(batch))
        self.generation += 1
        self.recorder.update_hall_of_fame(batch, self.generation)
        return stats

    def finish(self) -> None:
        """Final population (the elites), best designs, the run's figures and the archive's."""
        self.recorder.finish(self.generation, self.elites(), self.stopped_by)
        if self.figures:
            try:
                self.write_figures()
            except Exception:  # figures must never lose a finished run
                log.exception("could not write the archive figures of %s", self.out)

    def write_figures(self) -> dict[str, Path]:
        """``figures/archive_heatmap.png`` (one or two descriptors) and ``figures/qd_progress.png``."""
        fig_dir = self.out / "figures"
        out = {"qd_progress": plot_qd_progress(self.rows, fig_dir / "qd_progress.png")}
        if len(self.config.descriptors) <= 2:
            out["archive_heatmap"] = plot_archive_heatmap(
                self.archive, self.config, fig_dir / "archive_heatmap.png", self.objective,
                title=f"{self.experiment.name}: MAP-Elites archive, generation {self.generation}",
            )  # fmt: skip
        return out

    def _checkpoint_state(self) -> Checkpoint:
        data = _elite_data(self.archive)
        elites = list(data["solution"])
        traces, lengths = pack_traces([ind.trace for ind in elites])
        arrays = {
            "archive_index": data["index"].astype(np.int64),
            "archive_objective": data["objective"].astype(np.float64),
            "archive_measures": data["measures"].astype(np.float64),
            "archive_threshold": data["threshold"].astype(np.float64),
            "pop_traces": traces,
            "pop_trace_len": lengths,
        }
        if self.config.archive == "cvt":
            arrays["archive_centroids"] = np.asarray(self.archive.centroids, dtype=np.float64)
        state = {
            "rng": rng_state(self.emitter.rng),
            "next_id": self.ids.value,
        }
        columns = {
            **self.stats(),
            "new_cells": self.emitter.new_cells,
            "improved_cells": self.emitter.improved_cells,
        }
        return state, arrays, columns, elites

    def _restore(self, state: dict[str, Any], arrays: dict[str, np.ndarray]) -> None:
        self._fresh(arrays.get("archive_centroids"))
        elites = [Individual.from_dict(d) for d in state["population"]]
        for ind, tr in zip(elites, unpack_traces(arrays["pop_traces"], arrays["pop_trace_len"])):
            ind.trace = tr
        if elites:
            self.archive.add(
                _object_array(elites), arrays["archive_objective"], arrays["archive_measures"]
            )
        data = _elite_data(self.archive)
        if not (
            np.array_equal(data["index"], arrays["archive_index"])
            and np.array_equal(data["threshold"], arrays["archive_threshold"])
        ):
            raise CheckpointError(
                f"{self.checkpoint_dir}: the checkpointed elites do not rebuild the archive "
                "(another archive configuration or pyribs version?)"
            )
        self.generation = int(state["generation"])
        self.ids.value = int(state["next_id"])
        self.emitter.rng = rng_from_state(state["rng"])


# ---------------------------------------------------------------------- figures
def plot_archive_heatmap(
    archive: Any,
    config: QDConfig,
    path: str | Path,
    objective: str = "norm_final_dist",
    title: str | None = None,
) -> Path:
    """The archive's elites coloured by objective (pyribs' heatmaps), saved to ``path``.

    Parameters
    ----------
    archive : ribs.archives.GridArchive or ribs.archives.CVTArchive
        One or two descriptors.
    config : QDConfig
        Names the axes.
    path : path
        PNG file.
    objective : str
        The colour bar's label.
    title : str, optional

    Returns
    -------
    Path
    """
    plt = pyplot()
    from ribs.visualize import cvt_archive_heatmap, grid_archive_heatmap

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig, ax = plt.subplots(figsize=(6.4, 5.2))
    cbar_kwargs = {"label": f"{objective} (voxel lengths)"}
    if config.archive == "cvt":
        cvt_archive_heatmap(archive, ax=ax, cbar_kwargs=cbar_kwargs, vmin=0.0)
    else:
        grid_archive_heatmap(archive, ax=ax, cbar_kwargs=cbar_kwargs, vmin=0.0, rasterized=True)
    labels = [_axis_label(n) for n in config.descriptors]
    ax.set_xlabel(labels[0])
    if len(labels) > 1:
        ax.set_ylabel(labels[1])
    st = archive_stats(archive)
    ax.set_title(
        (title + "\n" if title else "")
        + f"{st['num_elites']} elites, coverage {st['coverage']:.3f}, "
        f"QD-score {st['qd_score']:.3g}",
        fontsize=9,
    )
    fig.savefig(path, dpi=120, bbox_inches="tight")
    plt.close(fig)
    return path


def _axis_label(name: str) -> str:
    return {
        "stiff": "stiff voxels / filled voxels",
        "filled": "filled voxels / lattice",
        "muscle": "muscle voxels / filled voxels",
        "height": "occupied layers / nz",
        "elongation": "elongation (1 - sqrt(l2/l1))",
    }.get(name, name)


def plot_qd_progress(rows: Sequence[Mapping[str, Any]], path: str | Path) -> Path:
    """QD-score and coverage against simulations, from a QD run's log rows."""
    plt = pyplot()

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    x = [r["evaluations_total"] for r in rows]
    fig, (a, b) = plt.subplots(1, 2, figsize=(9.6, 3.6))
    a.plot(x, [r["qd_score"] for r in rows], color="C0")
    a.set_xlabel("simulations")
    a.set_ylabel("QD-score (sum of elite objectives,\nvoxel lengths)")
    b.plot(x, [r["coverage"] for r in rows], color="C1")
    b.set_xlabel("simulations")
    b.set_ylabel("coverage (elites / cells)")
    fig.tight_layout()
    fig.savefig(path, dpi=120, bbox_inches="tight")
    plt.close(fig)
    return path


# ---------------------------------------------------------------------- export
def export_elites(
    run_dir: str | Path, dest: str | Path | None = None, top: int | None = None
) -> Path:
    """Write a QD run's elites (its latest intact checkpoint) as design files.

    Writes ``dest/elites.json`` (per elite: cell index, descriptors,
    objective, id, genome, and its files) and, per elite,
    ``cell-I_id-N.json`` (a :class:`~softgym.design.RobotDesign` file) and
    ``cell-I_id-N.vxa`` (VoxCAD / evosoro).

    Parameters
    ----------
    run_dir : path
        A :class:`QDRun` folder.
    dest : path, optional
        Default ``run_dir/elites``.
    top : int, optional
        Only the ``top`` best elites (by objective; ties by cell index).

    Returns
    -------
    Path
        ``dest/elites.json``.

    Raises
    ------
    CheckpointError
        If the folder is not a QD run or has no intact checkpoint.
    """
    from softgym.design import to_vxa

    run_dir = Path(run_dir)
    cfg = read_json(run_dir / "config.json")
    if not isinstance(cfg, dict) or "qd" not in cfg:
        raise CheckpointError(f"{run_dir}: not a quality-diversity run folder (softgym qd)")
    exp = Experiment.from_dict(cfg["experiment"])
    qd = QDConfig.from_dict(cfg["qd"])
    state, arrays, _, _ = load_latest_intact(run_dir / "checkpoints")
    try:
        genomes = list(state["population"])
        index = arrays["archive_index"]
        objective = arrays["archive_objective"]
        measures = arrays["archive_measures"]
    except KeyError as exc:
        raise CheckpointError(f"{run_dir}: the checkpoint holds no archive ({exc!r})") from exc
    order = sorted(range(len(genomes)), key=lambda i: (-float(objective[i]), int(index[i])))
    if top is not None:
        order = order[: max(0, int(top))]
    dest = run_dir / "elites" if dest is None else Path(dest)
    dest.mkdir(parents=True, exist_ok=True)
    entries = []
    for i in order:
        ind = Individual.from_dict(genomes[i])
        design = ind.design(exp.shape)
        stem = f"cell-{int(index[i])}_id-{ind.id}"
        atomic_write_json(dest / f"{stem}.json", design.to_dict())
        files = [f"{stem}.json"]
        try:
            atomic_write_text(dest / f"{stem}.vxa", to_vxa(design, sim_time=float(exp.seconds)))
            files.append(f"{stem}.vxa")
        except Exception as exc:  # a design VoxCAD cannot hold keeps its JSON
            log.warning("%s: no .vxa for elite %s (%s)", run_dir, ind.id, exc)
        entries.append({
            "cell": int(index[i]),
            "descriptors": dict(zip(qd.descriptors, map(float, measures[i]))),
            "objective": float(objective[i]),
            "id": ind.id,
            "files": files,
            "genome": genomes[i],
        })  # fmt: skip
    index_path = dest / "elites.json"
    atomic_write_json(
        index_path,
        {"experiment": exp.name, "objective": qd.objective_for(exp), "qd": qd.to_dict(),
         "generation": int(state["generation"]), "elites": entries},
    )  # fmt: skip
    return index_path
