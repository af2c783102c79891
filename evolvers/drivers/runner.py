"""The seed's generation loop with a run folder, checkpoints and exact resume.

Generation 0: ``pop_size`` random valid individuals, evaluated. Every later
generation: every age += 1; each parent makes one mutated child (plus the
controller/material/brain GA; no CPPN mutation on a fixed body); ``n_random`` random newcomers join; the whole
population (31 for the seed) is evaluated in one batched Simulation, cached
phenotypes not re-run; selection brings it back to ``pop_size``.

The loop, progress, Ctrl-C, checkpoints and resume are the
:class:`~evolvers.drivers.base.Driver`'s, the skeleton every driver shares; this
module supplies the seed's generation. A run killed at any moment resumes from
its last checkpoint and ends with the same population as an uninterrupted run
with the same seed.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from evolvers.drivers.base import Checkpoint, Driver
from evolvers.evaluation.evaluator import (
    EvalStats,
    pack_traces,
    unpack_traces,
)
from evolvers.operators.genome import Individual
from evolvers.operators.selection import select
from evolvers.operators.variation import make_children
from evolvers.recording.recorder import RUN_SCHEMA, RunInterrupted
from evolvers.recording.rows import population_summary
from softgym.io import (
    python_random_state,
    rng_from_state,
    rng_state,
    set_python_random_state,
)
from softgym.metrics import NoveltyArchive

__all__ = ["RUN_SCHEMA", "EvolutionRun", "RunInterrupted", "population_summary"]


class EvolutionRun(Driver):
    """A resumable evolutionary run of an :class:`~evolvers.evaluation.experiments.Experiment` (native backend).

    Parameters: those of :class:`~evolvers.drivers.base.Driver` (``seed`` seeds the run's single
    ``numpy.random.Generator``: every random choice, genomes, variation, selection).
    """

    backend = "native"

    # ------------------------------------------------------------------ the record
    @property
    def config(self) -> dict[str, Any]:
        """What config.json records (and --resume checks)."""
        return dict(self.recorder.config)

    # ------------------------------------------------------------------ backend hooks
    def _fresh(self) -> None:
        super()._fresh()
        self.rng = np.random.default_rng(self.seed)
        self.population = []
        self.archive: NoveltyArchive | None = (
            NoveltyArchive(k=self.experiment.pop_size, n_add=2, variant="normalized")
            if self.experiment.selection == "novelty-archive"
            else None
        )
        self._setup_backend()

    def _setup_backend(self) -> None:
        """Backend-specific initialisation (the DEAP runner builds its toolbox here)."""

    def next_id(self) -> int:
        """A fresh individual id."""
        return self.ids()

    def _random_individual(self) -> Individual:
        return self.experiment.random_individual(self.rng, self.next_id())

    def _vary(self, parents: list[Individual]) -> list[Individual]:
        return make_children(parents, self.rng, self.next_id, **self.experiment.variation())

    def _evaluate(self, individuals: list[Individual]) -> EvalStats:
        return self.evaluator.evaluate(individuals)

    def _select(self, individuals: list[Individual], k: int) -> list[Individual]:
        exp = self.experiment
        return select(exp.selection, individuals, k, exp.objectives, self.rng, self.archive)

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

    def _step(self) -> EvalStats:
        if self.generation < 0:
            stats = self._generation_zero()
            self.recorder.update_hall_of_fame(self.population, 0)
        else:
            stats = self._next_generation()
        self.generation += 1
        return stats

    def _checkpoint_state(self) -> Checkpoint:
        data, lengths = pack_traces([ind.trace for ind in self.population])
        arrays = {"pop_traces": data, "pop_trace_len": lengths}
        state = {
            "rng": rng_state(self.rng),
            "python_random": python_random_state(),
            "next_id": self.ids.value,
            "archive": None if self.archive is None else self.archive.to_dict(),
            "backend_state": self._backend_state(),
        }
        return state, arrays, None, self.population

    def _restore(self, state: dict[str, Any], arrays: dict[str, np.ndarray]) -> None:
        self.generation = int(state["generation"])
        self.population = [self._from_dict(d) for d in state["population"]]
        traces = unpack_traces(arrays["pop_traces"], arrays["pop_trace_len"])
        for ind, tr in zip(self.population, traces):
            ind.trace = tr
        self.rng = rng_from_state(state["rng"])
        set_python_random_state(state["python_random"])
        self.ids.value = int(state["next_id"])
        if state.get("archive") is not None:
            self.archive = NoveltyArchive.from_dict(state["archive"])
        self._restore_backend_state(state.get("backend_state", {}))
