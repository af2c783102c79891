"""The one run skeleton every driver shares: construction, the generation loop, progress,
Ctrl-C, checkpoints and exact resume.

A driver (:class:`~evolvers.drivers.runner.EvolutionRun`, ``DeapRun``, ``PymooRun``,
``QDRun``, ``PoetRun``) subclasses :class:`Driver` and supplies hooks:

* :meth:`Driver._fresh` - the state of a run that has not started (seeded
  generators, counters, archive, algorithm); called by the constructor and
  again when a run starts, so a run object can be started twice.
* :meth:`Driver._step` - one generation (or POET iteration): evaluate, select,
  advance :attr:`generation`; returns its :class:`~evolvers.evaluation.evaluator.EvalStats`.
* :meth:`Driver._checkpoint_state` - the driver's part of the checkpoint: a
  JSON-ready dict, plain arrays, extra log columns and the individuals the
  recorder logs; :meth:`Driver._restore` - the inverse.
* :attr:`Driver.label`, :meth:`Driver.result`, and :meth:`Driver.finish`
  where the driver writes more than the recorder; :meth:`Driver.best_score` where
  the target score is not the hall of fame's best fitness (QD, POET).

The loop stops on the run's budget (:mod:`evolvers.drivers.budget`): its generations,
or a :class:`~evolvers.drivers.budget.Budget` of simulations, robot-seconds, wall time or
a target score, whichever comes first, checked once here between generations; every
count is checkpointed and goes on across resumes (:attr:`Driver.stopped_by` names the
budget that ended the run).

Everything on disk goes through one :class:`~evolvers.recording.recorder.RunRecorder`
at ``self.recorder``; :class:`Driver` also shows its views (log rows, hall of
fame, totals). Resume is exact: a run killed at any moment and resumed ends as
an uninterrupted run with the same seed.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from evolvers.drivers.budget import Budget, BudgetUsage
from evolvers.evaluation.evaluator import BatchFn, EvalStats, Evaluator, PhenotypeCache
from evolvers.evaluation.experiments import (
    Experiment,
    check_generations,
    check_seed,
    smoke_sizes,
)
from evolvers.operators.genome import Individual
from evolvers.recording.recorder import RunRecorder
from softgym.exceptions import CheckpointError, InvalidParameterError
from softgym.io import RunLock

__all__ = ["Budget", "Checkpoint", "Driver", "IdCounter"]

log = logging.getLogger("evolvers")


class IdCounter:
    """The id source of a run's individuals (or POET's pairs): ``ids()`` gives the next id;
    :attr:`value` (the next one) is part of the checkpointed state.
    """

    def __init__(self, start: int = 0) -> None:
        self.value = int(start)

    def __call__(self) -> int:
        """The next id."""
        v = self.value
        self.value += 1
        return v


#: What :meth:`Driver._checkpoint_state` returns: ``(state, arrays, columns, individuals)``.
Checkpoint = tuple[dict[str, Any], dict[str, np.ndarray], "dict[str, Any] | None", Sequence[Individual]]


class Driver:
    """A resumable run of an experiment: the skeleton every driver fills in (module docstring).

    Parameters
    ----------
    experiment : Experiment
    out : path
        Run folder.
    seed : int
        Seed of the run's random generators.
    generations : int, optional
        Generations after generation 0 (default the experiment's).
    batch_fn : callable, optional
        Batch evaluation (default: one local Simulation; see
        :class:`evolvers.evaluation.distributed.DaskBatchFn`).
    n_threads : int, optional
        OpenMP threads of local simulations.
    on_generation : callable, optional
        ``on_generation(run, row)`` after each generation's checkpoint
        (progress bars; raising here interrupts the run like a crash).
    figures, gif : bool
        Write the run's figures (and the best robot's GIF) at the end.
    progress : bool
        A tqdm bar over the generations (each is also logged to the
        ``evolvers`` logger at INFO).
    extra_config : dict, optional
        The driver's settings in config.json (checked on resume).
    budget : Budget or dict, optional
        More limits than the generations: simulations, robot-seconds, wall time, a
        target score (:class:`~evolvers.drivers.budget.Budget`); the run stops at the
        first reached, checked between generations. Recorded in config.json; a resume
        takes the one given and counts on from the checkpoint (a larger budget continues a
        run that a smaller one stopped, ending exactly as a run given it from the start;
        not so for ``max_wall_seconds``: wall time is by nature not reproducible).

    Raises
    ------
    RunFolderLockedError
        From :meth:`run` when another process is writing the run folder.
    RunInterrupted
        From :meth:`run` on Ctrl-C (a ``KeyboardInterrupt``; the simulations
        stop within a fraction of a second): it names the last checkpoint
        and :attr:`resume_command`.
    """

    #: The driver's name in config.json (what a resume must match).
    backend: str = ""
    #: What one step is called (in messages).
    unit: str = "generation"
    #: Whether the recorder draws the run's fitness figures (POET draws its own).
    recorder_figures: bool = True

    def __init__(
        self,
        experiment: Experiment,
        out: str | Path,
        seed: int = 0,
        generations: int | None = None,
        batch_fn: BatchFn | None = None,
        n_threads: int | None = None,
        on_generation: Callable[[Any, dict[str, Any]], None] | None = None,
        figures: bool = True,
        gif: bool = True,
        progress: bool = True,
        extra_config: dict[str, Any] | None = None,
        budget: Budget | dict[str, Any] | None = None,
    ) -> None:
        if isinstance(out, str) and not out.strip():
            # Path("") is the current folder: a run written there by accident
            raise InvalidParameterError(
                f"the run folder (--out) must name a folder, got {out!r}; give one, e.g. runs/evolve"
            )
        gens = experiment.generations if generations is None else generations
        gens = check_generations(gens, f"{self.unit}s")
        self.budget = budget if isinstance(budget, Budget) else Budget.from_dict(budget)
        experiment, gens = smoke_sizes(experiment, gens)
        self.experiment = experiment
        self.out = Path(out)
        self.seed = check_seed(seed)
        self.generations = gens
        self.n_threads = n_threads
        self.on_generation = on_generation
        self.figures = figures
        self.gif = gif
        self.evaluator = self._evaluator(batch_fn, n_threads, progress)
        self.recorder = RunRecorder(
            out, experiment, self.seed, self.backend, figures and self.recorder_figures,
            gif and self.recorder_figures, extra_config=extra_config, progress=progress,
        )  # fmt: skip
        self.recorder.budget = self.budget.to_dict()
        #: The budget that ended the last :meth:`run` (a name of
        #: :data:`~evolvers.drivers.budget.STOP_ORDER`), None before one ended.
        self.stopped_by: str | None = None
        self._sitting: tuple[float, float] = (time.perf_counter(), 0.0)
        #: What :class:`RunInterrupted` tells the user to type (the CLI puts its command here).
        self.resume_command = (
            f"{type(self).__name__}(experiment, {str(self.out)!r}, seed={self.seed}).run(resume=True)"
        )
        self.generation = -1
        self.population: list[Individual] = []
        self._fresh()

    def _evaluator(self, batch_fn: BatchFn | None, n_threads: int | None,
                   progress: bool) -> Evaluator | None:  # fmt: skip
        """The run's batched, cached evaluation."""
        return Evaluator(self.experiment, batch_fn=batch_fn, n_threads=n_threads, progress=progress)

    # ------------------------------------------------------------------ hooks
    def _fresh(self) -> None:
        """The state of a run before generation 0 (seeded generators, counters...)."""
        self.ids = IdCounter()
        self.generation = -1

    def _step(self) -> EvalStats:
        """One generation: evaluate, select, advance :attr:`generation`."""
        raise NotImplementedError

    def _checkpoint_state(self) -> Checkpoint:
        """``(state, arrays, columns, individuals)`` of the generation just finished."""
        raise NotImplementedError

    def _restore(self, state: dict[str, Any], arrays: dict[str, np.ndarray]) -> None:
        """Restore what :meth:`_checkpoint_state` saved (after :meth:`_fresh`; the
        evaluator's cache and count are restored already).
        """
        raise NotImplementedError

    # ------------------------------------------------------------------ the evaluator's record
    #: The checkpoint key of the evaluator's simulation count (the driver writes it, with
    #: the cache's arrays, beside each driver's own state).
    EVALUATIONS_KEY = "evaluations_counter"

    def _evaluator_checkpoint(self) -> tuple[dict[str, Any], dict[str, np.ndarray]]:
        """The evaluator's part of a checkpoint: its simulation count and its cache."""
        return {self.EVALUATIONS_KEY: self.evaluator.n_evaluations}, self.evaluator.cache.to_arrays()

    def _restore_evaluator(self, state: dict[str, Any], arrays: dict[str, np.ndarray]) -> None:
        """Restore the evaluator's cache and simulation count (the count under the key
        POET's checkpoints used before the driver owned it, ``n_simulated``, read too).
        """
        self.evaluator.cache = PhenotypeCache.from_arrays(arrays)
        count = state.get(self.EVALUATIONS_KEY, state.get("n_simulated", 0))
        if isinstance(count, bool) or not isinstance(count, int) or count < 0:
            raise ValueError(f"{self.EVALUATIONS_KEY} must be an integer >= 0, got {count!r:.40}")
        self.evaluator.n_evaluations = count

    @property
    def label(self) -> str:
        """The progress bar's description."""
        return f"{self.experiment.name} [{self.backend}]"

    def result(self) -> Any:
        """What :meth:`run` returns (the final population by default)."""
        return self.population

    @property
    def score_maximized(self) -> bool:
        """Whether :meth:`best_score` is better larger (the target is reached at >=, else <=)."""
        return self.experiment.fitness.maximize

    def best_score(self) -> float | None:
        """The score a ``target_score`` budget compares: the best value of the run's fitness
        found so far (the hall of fame's first), None before any.
        """
        return self.best_so_far()

    def best_so_far(self) -> float | None:
        """The best value of the experiment's fitness found so far, None before any: the
        hall of fame's first (every evaluated individual is offered to it). Each log row
        records it as ``best_so_far`` (the learning curve, over ``evaluations_total``).
        """
        if not self.hall_of_fame:
            return None
        ind = self.hall_of_fame[0]["individual"]
        name = self.experiment.fitness.name
        value = ind.get("age") if name == "age" else ind.get("objectives", {}).get(name)
        return None if value is None else float(value)

    # ------------------------------------------------------------------ the budget
    def budget_used(self) -> BudgetUsage:
        """How much of each budget the run has used so far (every sitting)."""
        rec = self.recorder
        return BudgetUsage(
            generation=self.generation, evaluations=rec.evaluations_total,
            robot_seconds=rec.robot_seconds_total, wall_seconds=rec.wall_clock_total,
            best_score=self.best_score(),
        )  # fmt: skip

    def budget_reached(self) -> str | None:
        """The budget the run has reached (the first of
        :data:`~evolvers.drivers.budget.STOP_ORDER`), None while it goes on.
        """
        return self.budget.reached(self.budget_used(), self.generations, self.score_maximized)

    def budget_record(self) -> dict[str, Any]:
        """The budget as checkpoints and summaries record it: ``limits`` (the generations
        and the :class:`~evolvers.drivers.budget.Budget`'s), ``used``
        (:class:`~evolvers.drivers.budget.BudgetUsage`) and ``stopped_by`` (None while the
        run goes on).
        """
        return {
            "limits": {"generations": self.generations, **self.budget.to_dict()},
            "used": self.budget_used().to_dict(),
            "stopped_by": self.budget_reached(),
        }

    # ------------------------------------------------------------------ the loop
    def start(self) -> None:
        """Create the run folder (refusing one that holds another run's checkpoints)."""
        self.recorder.start(self.generations)
        self._fresh()

    def resume(self) -> bool:
        """Load the latest checkpoint of the run folder.

        Returns
        -------
        bool
            False if the folder has no checkpoint yet (the run starts fresh).

        Raises
        ------
        CheckpointError
            If config.json names another experiment/seed/backend/settings, or
            the latest checkpoint is corrupt (see :meth:`RunRecorder.resume`).
        """
        loaded = self.recorder.resume(self.generations)
        if loaded is None:
            return False
        try:
            self._fresh()
            self._restore_evaluator(*loaded)  # first: a driver's restore may evaluate (cached)
            self._restore(*loaded)
        except (KeyError, TypeError, ValueError, IndexError, AttributeError) as exc:
            # a re-signed checkpoint whose arrays or entries have the wrong shapes or types
            raise CheckpointError(
                f"{self.checkpoint_dir}: checkpoint content is invalid ({exc!r})"
            ) from exc
        return True

    def run(self, resume: bool = False) -> Any:
        """Run (or continue from the last checkpoint) until the budget: :attr:`generations`,
        or the first limit of :attr:`budget` reached (:attr:`stopped_by` names it).

        A resumed run counts on from its checkpoint (simulations, robot-seconds, wall
        seconds of every sitting); one whose budget is already spent only writes its
        final files.

        Returns
        -------
        :meth:`result`: the final population (QD: the elites; POET: the pairs).
        """
        # one writer per run folder: a second run into it is refused, naming the first
        with RunLock(self.out):
            self.stopped_by = None
            sitting = time.perf_counter()
            if not (resume and self.resume()):
                self.start()
            # this sitting's wall time (its resume included) adds to the sittings before it
            self._sitting = (sitting, self.recorder.wall_clock_total)
            self.recorder.open_progress(self.generation, self.generations, self.label)
            try:
                while (reason := self.budget_reached()) is None:
                    t0 = time.perf_counter()
                    stats = self._step()
                    self._end_generation(stats, time.perf_counter() - t0)
            except KeyboardInterrupt as exc:
                done = len(self.recorder.rows) - 1  # the last checkpointed generation
                raise self.recorder.interrupted(done, self.resume_command) from exc
            finally:
                self.recorder.close_progress()
            self.stopped_by = reason
            if reason != "generations":
                log.info("%s: stopped by its budget %s at %s %d (%s)", self.out, reason,
                         self.unit, self.generation, self.budget_used())  # fmt: skip
            self.finish()
        return self.result()

    def _end_generation(self, stats: EvalStats, wall: float) -> None:
        """Log row, checkpoint (with the budget), files, callback."""
        state, arrays, columns, individuals = self._checkpoint_state()
        ev_state, ev_arrays = self._evaluator_checkpoint()
        state, arrays = {**state, **ev_state}, {**arrays, **ev_arrays}
        columns = {**(columns or {}), "best_so_far": self.best_so_far()}
        start, before = self._sitting
        row = self.recorder.end_generation(
            self.generation, individuals, stats, wall, state, arrays, columns=columns,
            elapsed=before + (time.perf_counter() - start), budget=self.budget_record,
        )  # fmt: skip
        if self.on_generation is not None:
            self.on_generation(self, row)

    def finish(self) -> None:
        """Write the final population, the best designs and the figures."""
        self.recorder.finish(self.generation, self.population, self.stopped_by)

    # ------------------------------------------------------------------ the record
    @property
    def rows(self) -> list[dict[str, Any]]:
        """The log rows so far (one per generation)."""
        return self.recorder.rows

    @property
    def hall_of_fame(self) -> list[dict[str, Any]]:
        """The best individuals so far (plain data, best first)."""
        return self.recorder.hall_of_fame

    @property
    def evaluations_total(self) -> int:
        """Simulations run so far."""
        return self.recorder.evaluations_total

    @property
    def wall_total(self) -> float:
        """Wall time (s) of the generations so far."""
        return self.recorder.wall_total

    @property
    def checkpoint_dir(self) -> Path:
        """Folder of the checkpoints."""
        return self.recorder.checkpoint_dir

    def best(self) -> Individual:
        """The best individual found so far (by the first objective)."""
        return self.recorder.best()
