"""The seed's generation loop (SEED_REFERENCE §2.6) with a run folder, checkpoints and exact resume.

Generation 0: ``pop_size`` random valid individuals, evaluated. Every later
generation: every age += 1; each parent makes one mutated child (plus the
controller/material GA); ``n_random`` random newcomers join; the whole
population (31 for the seed) is evaluated in one batched Simulation, cached
phenotypes not re-run; selection brings it back to ``pop_size``.

The run folder::

    config.json            experiment, seed, backend (what --resume checks)
    log.csv, log.jsonl     one row per generation: best/median/mean/worst of
                           every objective, evaluations, cache hits, wall time
    checkpoints/           ckpt-NNNNNN.{json,npz}, atomic, versioned, every RNG state
    best_design.json       the best robot found (a RobotDesign file)
    best_designs.json      hall of fame: genomes, designs and objectives
    final_population.json  the last population
    figures/               fitness trend, best robot, its trajectory, its GIF

A run killed at any moment resumes from its last checkpoint and ends with the
same population as an uninterrupted run with the same seed.
"""

from __future__ import annotations

import csv
import io
import json
import logging
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from evolvers.evaluation import (
    FITNESS_METRICS,
    BatchFn,
    EvalStats,
    Evaluator,
    PhenotypeCache,
    pack_traces,
    unpack_traces,
)
from evolvers.experiments import Experiment
from evolvers.genome import Individual
from evolvers.operators import make_children
from evolvers.selection import (
    sel_fitness_tournament,
    sel_novelty,
    sel_nsga2,
    sel_pareto,
)
from softgym.exceptions import CheckpointError, InvalidParameterError
from softgym.io import (
    atomic_write_json,
    atomic_write_text,
    load_checkpoint,
    python_random_state,
    read_json,
    rng_from_state,
    rng_state,
    save_checkpoint,
    set_python_random_state,
)
from softgym.metrics import NoveltyArchive

__all__ = ["RUN_SCHEMA", "EvolutionRun", "population_summary"]

log = logging.getLogger("evolvers")

#: ``"schema"`` of a run's config.json.
RUN_SCHEMA = "softgym.run"
HALL_OF_FAME_SIZE = 5


def _direction(exp: Experiment, metric: str) -> bool:
    """True if ``metric`` is better when larger."""
    for o in exp.objectives:
        if o.name == metric:
            return o.maximize
    return metric in FITNESS_METRICS


def population_summary(individuals: Sequence[Individual]) -> list[dict[str, Any]]:
    """Comparable plain data of a population: ids, ages, genomes, objectives (no wall times)."""
    return [ind.to_dict() for ind in individuals]


class EvolutionRun:
    """A resumable evolutionary run of an :class:`~evolvers.experiments.Experiment` (native backend).

    Parameters
    ----------
    experiment : Experiment
    out : path
        Run folder.
    seed : int
        Seed of the run's single ``numpy.random.Generator`` (every random
        choice: genomes, variation, selection).
    generations : int, optional
        Generations after generation 0 (default the experiment's).
    batch_fn : callable, optional
        Batch evaluation (default: one local Simulation; see
        :class:`evolvers.distributed.DaskBatchFn`).
    n_threads : int, optional
        OpenMP threads of local simulations.
    on_generation : callable, optional
        ``on_generation(run, row)`` after each generation's checkpoint
        (progress bars; raising here interrupts the run like a crash).
    figures : bool
        Write figures (and the GIF) at the end.
    gif : bool
        Also render the best robot's GIF.
    """

    backend = "native"

    def __init__(
        self,
        experiment: Experiment,
        out: str | Path,
        seed: int = 0,
        generations: int | None = None,
        batch_fn: BatchFn | None = None,
        n_threads: int | None = None,
        on_generation: Callable[[EvolutionRun, dict[str, Any]], None] | None = None,
        figures: bool = True,
        gif: bool = True,
    ) -> None:
        self.experiment = experiment
        self.out = Path(out)
        self.seed = int(seed)
        self.generations = experiment.generations if generations is None else int(generations)
        if self.generations < 0:
            raise InvalidParameterError(f"generations must be >= 0, got {self.generations}")
        self.batch_fn = batch_fn
        self.n_threads = n_threads
        self.on_generation = on_generation
        self.figures = figures
        self.gif = gif
        self.evaluator = Evaluator(experiment, batch_fn=batch_fn, n_threads=n_threads)
        self.rng = np.random.default_rng(self.seed)
        self.generation = -1
        self.population: list[Individual] = []
        self.next_id_value = 0
        self.rows: list[dict[str, Any]] = []
        self.hall_of_fame: list[dict[str, Any]] = []
        self.archive: NoveltyArchive | None = (
            NoveltyArchive(k=experiment.pop_size, n_add=2, variant="normalized")
            if experiment.selection == "novelty-archive"
            else None
        )
        self.evaluations_total = 0
        self.wall_total = 0.0
        self._setup_backend()

    # ------------------------------------------------------------------ backend hooks
    def _setup_backend(self) -> None:
        """Backend-specific initialisation (the DEAP runner builds its toolbox here)."""

    def next_id(self) -> int:
        """A fresh individual id."""
        i = self.next_id_value
        self.next_id_value += 1
        return i

    def _random_individual(self) -> Individual:
        exp = self.experiment
        return Individual.random(self.rng, self.next_id(), exp.shape, exp.cppn_outputs, exp.rules)

    def _vary(self, parents: list[Individual]) -> list[Individual]:
        exp = self.experiment
        return make_children(
            parents,
            self.rng,
            self.next_id,
            shape=exp.shape,
            rules=exp.rules,
            evolve_controller=exp.evolve_controller,
            evolve_materials=exp.evolve_materials,
            crossover_rate=exp.crossover_rate,
        )

    def _evaluate(self, individuals: list[Individual]) -> EvalStats:
        return self.evaluator.evaluate(individuals)

    def _select(self, individuals: list[Individual], k: int) -> list[Individual]:
        exp = self.experiment
        sel = exp.selection
        if sel == "pareto":
            return sel_pareto(individuals, k, exp.objectives, self.rng)
        if sel == "tournament":
            return sel_fitness_tournament(individuals, k, exp.fitness.name, self.rng)
        if sel == "novelty":
            return sel_novelty(individuals, k)
        if sel == "novelty-archive":
            return sel_novelty(individuals, k, archive=self.archive)
        if sel == "nsga2":
            return sel_nsga2(individuals, k, exp.objectives)
        raise InvalidParameterError(f"unknown selection {sel!r}")  # pragma: no cover

    def _from_dict(self, data: dict[str, Any]) -> Individual:
        return Individual.from_dict(data)

    def _backend_state(self) -> dict[str, Any]:
        return {}

    def _restore_backend_state(self, state: dict[str, Any]) -> None:
        """Restore what :meth:`_backend_state` saved."""

    # ------------------------------------------------------------------ the loop
    @property
    def config(self) -> dict[str, Any]:
        """What config.json records (and --resume checks)."""
        return {
            "schema": RUN_SCHEMA,
            "version": 1,
            "experiment": self.experiment.to_dict(),
            "seed": self.seed,
            "backend": self.backend,
        }

    @property
    def checkpoint_dir(self) -> Path:
        """Folder of the checkpoints."""
        return self.out / "checkpoints"

    def _generation_zero(self) -> EvalStats:
        self.population = [self._random_individual() for _ in range(self.experiment.pop_size)]
        stats = self._evaluate(self.population)
        if self.experiment.selection.startswith("novelty"):
            # scores for the log only; gen 0 is not selected
            self.population = self._select(self.population, len(self.population))
        return stats

    def _next_generation(self) -> EvalStats:
        exp = self.experiment
        for ind in self.population:
            ind.age += 1
        children = self._vary(self.population)
        newcomers = [self._random_individual() for _ in range(exp.n_random)]
        everyone = self.population + children + newcomers
        stats = self._evaluate(everyone)
        self._update_hall_of_fame(everyone)
        self.population = self._select(everyone, exp.pop_size)
        return stats

    def start(self) -> None:
        """Create the run folder (refusing one that holds another run's checkpoints)."""
        self.out.mkdir(parents=True, exist_ok=True)
        cfg_path = self.out / "config.json"
        if (self.checkpoint_dir).exists() and any(self.checkpoint_dir.glob("ckpt-*.json")):
            raise CheckpointError(
                f"{self.out}: the folder already holds a run; use resume (--resume) or another --out"
            )
        atomic_write_json(cfg_path, {**self.config, "generations": self.generations})

    def resume(self) -> bool:
        """Load the latest checkpoint of the run folder.

        Returns
        -------
        bool
            False if the folder has no checkpoint yet (the run starts fresh).

        Raises
        ------
        CheckpointError
            If config.json names another experiment/seed/backend, or the
            latest checkpoint is corrupt (the message names the file; the
            previous checkpoints are still in ``checkpoints/``).
        """
        cfg_path = self.out / "config.json"
        if not cfg_path.exists():
            return False
        cfg = read_json(cfg_path)
        for key in ("experiment", "seed", "backend"):
            if cfg.get(key) != self.config[key]:
                raise CheckpointError(
                    f"{cfg_path}: the run was started with another {key} "
                    f"({cfg.get(key)!r} != {self.config[key]!r})"
                )
        if not any(self.checkpoint_dir.glob("ckpt-*.json")):
            return False
        state, arrays = load_checkpoint(self.checkpoint_dir)
        self._restore(state, arrays)
        atomic_write_json(cfg_path, {**self.config, "generations": self.generations})
        return True

    def run(self, resume: bool = False) -> list[Individual]:
        """Run (or continue) until ``generations`` generations after generation 0.

        Returns
        -------
        list of Individual
            The final population.
        """
        if not (resume and self.resume()):
            self.start()
        while self.generation < self.generations:
            t0 = time.perf_counter()
            if self.generation < 0:
                stats = self._generation_zero()
                self._update_hall_of_fame(self.population)
            else:
                stats = self._next_generation()
            self.generation += 1
            self._end_generation(stats, time.perf_counter() - t0)
        self.finish()
        return self.population

    def finish(self) -> None:
        """Write the final population, the best designs and the figures."""
        atomic_write_json(
            self.out / "final_population.json",
            {"generation": self.generation, "population": population_summary(self.population)},
        )
        self._write_best()
        if self.figures:
            try:
                from softgym.render.figures import run_figures

                run_figures(self.out, gif=self.gif)
            except Exception:  # figures must never lose a finished run
                log.exception("could not write the figures of %s", self.out)

    # ------------------------------------------------------------------ records
    def _stats_of(self, values: np.ndarray, maximize: bool) -> dict[str, float]:
        if values.size == 0:
            return {
                "best": float("nan"),
                "median": float("nan"),
                "mean": float("nan"),
                "worst": float("nan"),
            }
        return {
            "best": float(values.max() if maximize else values.min()),
            "median": float(np.median(values)),
            "mean": float(values.mean()),
            "worst": float(values.min() if maximize else values.max()),
        }

    def _end_generation(self, stats: EvalStats, wall: float) -> None:
        """Book-keeping after a generation: totals, log row, checkpoint, files, callback."""
        self.wall_total += wall
        self.evaluations_total += stats.n_simulated
        row = self._log_row(stats, wall)
        self.rows.append(row)
        self.checkpoint()
        self._write_log()
        self._write_best()
        if self.on_generation is not None:
            self.on_generation(self, row)

    def _log_row(self, stats: EvalStats, wall: float) -> dict[str, Any]:
        exp = self.experiment
        row: dict[str, Any] = {
            "generation": self.generation,
            "evaluations": stats.n_simulated,
            "evaluations_total": self.evaluations_total,
            "cache_hits": stats.n_cached,
            "invalid": stats.n_invalid,
            "diverged": stats.n_diverged,
            "bone_fraction": stats.n_bone / max(1, stats.n_individuals),
            "wall_time": wall,
            "wall_total": self.wall_total,
        }
        names = list(exp.metrics)
        if any(o.name == "age" for o in exp.objectives):
            names.append("age")
        for m in names:
            vals = np.array([ind.value(m) for ind in self.population], dtype=np.float64)
            for k, v in self._stats_of(vals, _direction(exp, m)).items():
                row[f"{m}_{k}"] = v
        if exp.selection.startswith("novelty"):
            vals = np.array(
                [ind.novelty for ind in self.population if ind.novelty is not None],
                dtype=np.float64,
            )
            for k, v in self._stats_of(vals, False).items():
                row[f"novelty_{k}"] = v
        return row

    def _update_hall_of_fame(self, individuals: Sequence[Individual]) -> None:
        exp = self.experiment
        fit = exp.fitness
        known = {h["individual"]["id"] for h in self.hall_of_fame}
        for ind in individuals:
            if ind.id in known or not ind.objectives:
                continue
            self.hall_of_fame.append(
                {"generation": self.generation + 1, "individual": ind.to_dict()}
            )
            known.add(ind.id)
        sign = -1.0 if fit.maximize else 1.0

        def key(h: dict[str, Any]) -> tuple[float, int]:
            d = h["individual"]
            v = d["age"] if fit.name == "age" else d["objectives"][fit.name]
            return (sign * float(v), int(d["id"]))

        self.hall_of_fame.sort(key=key)
        del self.hall_of_fame[HALL_OF_FAME_SIZE:]

    def best(self) -> Individual:
        """The best individual found so far (by the first objective)."""
        if not self.hall_of_fame:
            raise InvalidParameterError("the run has no evaluated individual yet")
        return Individual.from_dict(self.hall_of_fame[0]["individual"])

    def _write_best(self) -> None:
        if not self.hall_of_fame:
            return
        exp = self.experiment
        entries = []
        for h in self.hall_of_fame:
            ind = Individual.from_dict(h["individual"])
            entries.append(
                {
                    "generation": h["generation"],
                    "id": ind.id,
                    "objectives": ind.objectives,
                    "design": ind.design(exp.shape).to_dict(),
                    "genome": h["individual"],
                }
            )
        atomic_write_json(self.out / "best_designs.json", {"experiment": exp.name, "best": entries})
        atomic_write_json(self.out / "best_design.json", entries[0]["design"])

    def _write_log(self) -> None:
        if not self.rows:
            return
        keys: list[str] = []
        for r in self.rows:
            for k in r:
                if k not in keys:
                    keys.append(k)
        buf = io.StringIO()
        w = csv.DictWriter(buf, fieldnames=keys, lineterminator="\n")
        w.writeheader()
        for r in self.rows:
            w.writerow({k: (repr(v) if isinstance(v, float) else v) for k, v in r.items()})
        atomic_write_text(self.out / "log.csv", buf.getvalue())
        atomic_write_text(self.out / "log.jsonl", "".join(json.dumps(r) + "\n" for r in self.rows))

    # ------------------------------------------------------------------ checkpoints
    def checkpoint(self) -> Path:
        """Write the current generation's checkpoint (atomic; keeps the previous ones)."""
        data, lengths = pack_traces([ind.trace for ind in self.population])
        arrays = {"pop_traces": data, "pop_trace_len": lengths, **self.evaluator.cache.to_arrays()}
        state = {
            "generation": self.generation,
            "population": population_summary(self.population),
            "rng": rng_state(self.rng),
            "python_random": python_random_state(),
            "next_id": self.next_id_value,
            "rows": self.rows,
            "hall_of_fame": self.hall_of_fame,
            "archive": None if self.archive is None else self.archive.to_dict(),
            "evaluations_total": self.evaluations_total,
            "evaluations_counter": self.evaluator.n_evaluations,
            "wall_total": self.wall_total,
            "backend_state": self._backend_state(),
        }
        return save_checkpoint(self.checkpoint_dir, self.generation, state, arrays, keep=3)

    def _restore(self, state: dict[str, Any], arrays: dict[str, np.ndarray]) -> None:
        try:
            self.generation = int(state["generation"])
            self.population = [self._from_dict(d) for d in state["population"]]
            traces = unpack_traces(arrays["pop_traces"], arrays["pop_trace_len"])
            for ind, tr in zip(self.population, traces):
                ind.trace = tr
            self.rng = rng_from_state(state["rng"])
            set_python_random_state(state["python_random"])
            self.next_id_value = int(state["next_id"])
            self.rows = list(state["rows"])
            self.hall_of_fame = list(state["hall_of_fame"])
            if state.get("archive") is not None:
                self.archive = NoveltyArchive.from_dict(state["archive"])
            self.evaluations_total = int(state["evaluations_total"])
            self.evaluator.n_evaluations = int(state.get("evaluations_counter", 0))
            self.wall_total = float(state["wall_total"])
            self.evaluator.cache = PhenotypeCache.from_arrays(arrays)
            self._restore_backend_state(state.get("backend_state", {}))
        except (KeyError, TypeError, ValueError) as exc:
            raise CheckpointError(
                f"{self.checkpoint_dir}: checkpoint content is invalid ({exc!r})"
            ) from exc
