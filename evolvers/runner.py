"""The seed's generation loop (SEED_REFERENCE §2.6) with a run folder, checkpoints and exact resume.

Generation 0: ``pop_size`` random valid individuals, evaluated. Every later
generation: every age += 1; each parent makes one mutated child (plus the
controller/material GA); ``n_random`` random newcomers join; the whole
population (31 for the seed) is evaluated in one batched Simulation, cached
phenotypes not re-run; selection brings it back to ``pop_size``.

The run folder (config, log, checkpoints, best designs, figures) is written by
a :class:`~evolvers.recorder.RunRecorder`, the same one the DEAP and pymoo
drivers use. A run killed at any moment resumes from its last checkpoint and
ends with the same population as an uninterrupted run with the same seed.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from evolvers.evaluation import (
    BatchFn,
    EvalStats,
    Evaluator,
    PhenotypeCache,
    pack_traces,
    unpack_traces,
)
from evolvers.experiments import Experiment, smoke_sizes
from evolvers.genome import Individual
from evolvers.operators import make_children
from evolvers.recorder import (
    RUN_SCHEMA,
    RecordedRun,
    RunInterrupted,
    RunRecorder,
    population_summary,
)
from evolvers.selection import (
    sel_fitness_tournament,
    sel_novelty,
    sel_nsga2,
    sel_pareto,
)
from softgym.exceptions import CheckpointError, InvalidParameterError
from softgym.io import (
    python_random_state,
    rng_from_state,
    rng_state,
    set_python_random_state,
)
from softgym.metrics import NoveltyArchive

__all__ = ["RUN_SCHEMA", "EvolutionRun", "RunInterrupted", "population_summary"]


class EvolutionRun(RecordedRun):
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
    progress : bool
        Show a tqdm bar over the generations (each generation is also logged
        to the ``evolvers`` logger at INFO).

    Raises
    ------
    RunInterrupted
        From :meth:`run` on Ctrl-C (a ``KeyboardInterrupt``; the simulations
        stop within a fraction of a second): it names the last checkpoint
        and :attr:`resume_command`.
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
        progress: bool = True,
    ) -> None:
        experiment, gens = smoke_sizes(
            experiment, experiment.generations if generations is None else int(generations)
        )
        self.experiment = experiment
        self.out = Path(out)
        self.seed = int(seed)
        self.generations = gens
        if self.generations < 0:
            raise InvalidParameterError(f"generations must be >= 0, got {self.generations}")
        self.batch_fn = batch_fn
        self.n_threads = n_threads
        self.on_generation = on_generation
        self.figures = figures
        self.gif = gif
        self.evaluator = Evaluator(experiment, batch_fn=batch_fn, n_threads=n_threads, progress=progress)
        self.recorder = RunRecorder(
            out, experiment, self.seed, self.backend, figures, gif, progress=progress
        )
        #: What :class:`RunInterrupted` tells the user to type (the CLI puts its command here).
        self.resume_command = f"{type(self).__name__}(experiment, {str(self.out)!r}, seed={self.seed}).run(resume=True)"
        self.rng = np.random.default_rng(self.seed)
        self.generation = -1
        self.population: list[Individual] = []
        self.next_id_value = 0
        self.archive: NoveltyArchive | None = (
            NoveltyArchive(k=experiment.pop_size, n_add=2, variant="normalized")
            if experiment.selection == "novelty-archive"
            else None
        )
        self._setup_backend()

    # ------------------------------------------------------------------ the record
    @property
    def config(self) -> dict[str, Any]:
        """What config.json records (and --resume checks)."""
        return dict(self.recorder.config)

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
        self.recorder.update_hall_of_fame(everyone, self.generation + 1)
        self.population = self._select(everyone, exp.pop_size)
        return stats

    def start(self) -> None:
        """Create the run folder (refusing one that holds another run's checkpoints)."""
        self.recorder.start(self.generations)

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
            latest checkpoint is corrupt (see :meth:`RunRecorder.resume`).
        """
        loaded = self.recorder.resume(self.generations)
        if loaded is None:
            return False
        self._restore(*loaded)
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
        self.recorder.open_progress(
            self.generation, self.generations, f"{self.experiment.name} [{self.backend}]"
        )
        try:
            while self.generation < self.generations:
                t0 = time.perf_counter()
                if self.generation < 0:
                    stats = self._generation_zero()
                    self.recorder.update_hall_of_fame(self.population, 0)
                else:
                    stats = self._next_generation()
                self.generation += 1
                self._end_generation(stats, time.perf_counter() - t0)
        except KeyboardInterrupt as exc:
            raise self.recorder.interrupted(self.generation, self.resume_command) from exc
        finally:
            self.recorder.close_progress()
        self.finish()
        return self.population

    def finish(self) -> None:
        """Write the final population, the best designs and the figures."""
        self.recorder.finish(self.generation, self.population)

    def _end_generation(self, stats: EvalStats, wall: float) -> None:
        """Book-keeping after a generation: log row, checkpoint, files, callback."""
        data, lengths = pack_traces([ind.trace for ind in self.population])
        arrays = {"pop_traces": data, "pop_trace_len": lengths, **self.evaluator.cache.to_arrays()}
        state = {
            "rng": rng_state(self.rng),
            "python_random": python_random_state(),
            "next_id": self.next_id_value,
            "archive": None if self.archive is None else self.archive.to_dict(),
            "evaluations_counter": self.evaluator.n_evaluations,
            "backend_state": self._backend_state(),
        }
        row = self.recorder.end_generation(
            self.generation, self.population, stats, wall, state, arrays
        )
        if self.on_generation is not None:
            self.on_generation(self, row)

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
            if state.get("archive") is not None:
                self.archive = NoveltyArchive.from_dict(state["archive"])
            self.evaluator.n_evaluations = int(state.get("evaluations_counter", 0))
            self.evaluator.cache = PhenotypeCache.from_arrays(arrays)
            self._restore_backend_state(state.get("backend_state", {}))
        except (KeyError, TypeError, ValueError) as exc:
            raise CheckpointError(
                f"{self.checkpoint_dir}: checkpoint content is invalid ({exc!r})"
            ) from exc
