"""A study's run folders as the report reads them, and what the report compares them with
(the seed report's curves, generations and scenarios).
"""

from __future__ import annotations

import logging
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from evolvers.operators.genome import Individual
from evolvers.recording.recorder import read_best_designs, read_run_config, read_run_notes
from softgym.exceptions import CheckpointError, SoftGymError
from softgym.io import read_json
from softgym.render.figures import read_log
from softgym.validate import is_int, show

__all__ = [
    "CLAIM_SCENARIOS",
    "FAILS",
    "HOLDS",
    "OBSTACLE_SCENARIOS",
    "PARTLY",
    "REPORT_CROSSING_GENERATION",
    "REPORT_CURVES",
    "REPORT_GENERATIONS",
    "REPORT_T1_FINAL",
    "ROBOT_COM",
    "RunData",
    "UNTESTED",
    "load_runs",
]

log = logging.getLogger(__name__)

#: The report's single-run best-fitness curves (generation, NormFinalDist in voxel lengths), read
#: from its figures by eye (+-1; the seed study; the Fig. 1 step to 24 at generation 6 and
#: the intermediate Fig. 4 steps read from the PNGs in ``shared/seed``).
REPORT_CURVES: dict[str, list[tuple[int, float]]] = {
    "materials-t1": [(0, 15.0), (1, 21.5), (6, 24.0), (45, 28.5), (68, 32.3), (125, 42.7),
                     (150, 43.8), (183, 47.7), (300, 47.7)],
    "basic": [(0, 2.0), (1, 3.8), (3, 3.8), (4, 4.8), (5, 5.3), (7, 5.3), (8, 6.0), (9, 6.0),
              (10, 6.5), (40, 6.5)],
    "controller-tournament": [(0, 2.0), (1, 7.0), (2, 25.8), (5, 25.8), (6, 40.6), (17, 40.6),
                              (18, 43.5), (20, 43.5), (21, 68.6), (24, 68.6), (25, 72.5),
                              (39, 72.5), (40, 77.0)],
    "controller-pareto": [(0, 2.0), (1, 9.5), (2, 9.5), (3, 15.0), (4, 15.2), (5, 15.2),
                          (6, 16.2), (7, 18.2), (8, 18.5), (9, 40.8), (40, 40.8)],
}  # fmt: skip

#: Generations the report ran (or, for the obstacles, the generation its final setup crossed by).
REPORT_GENERATIONS: dict[str, int] = {
    "materials-t1": 300, "materials-t2": 50, "novelty": 200, "novelty-archive": 200,
    "basic-200": 200, "basic": 40, "controller-tournament": 40, "controller-pareto": 40,
    "obstacles": 80, "obstacles-robot-com": 80, "obstacles-attempt1": 80,
    "obstacles-attempt2": 80, "obstacles-attempt1-robot-com": 80, "obstacles-attempt2-robot-com": 80,
}  # fmt: skip

#: The scenarios each claim reads (a claim on shorter runs than the report's is provisional).
CLAIM_SCENARIOS: dict[str, tuple[str, ...]] = {
    "T1-improves": ("materials-t1",),
    "T1-final": ("materials-t1",),
    "T1-materials": ("materials-t1",),
    "T2-voxels": ("materials-t2",),
    "T2-muscles": ("materials-t2",),
    "novelty-fitness": (
        "novelty",
        "materials-t1",
        "materials-t2",
        "controller-tournament",
        "controller-pareto",
        "basic-200",
    ),
    "novelty-muscle": ("novelty",),
    "novelty-loop": ("novelty", "novelty-archive", "basic-200"),
    "ctrl-vs-basic": ("basic", "controller-tournament", "controller-pareto"),
    "tournament-vs-pareto": ("controller-tournament", "controller-pareto"),
    "pareto-muscles": ("controller-tournament", "controller-pareto"),
    "controller-genes": ("controller-tournament", "controller-pareto"),
    "obstacles-attempt1": ("obstacles-attempt1",),
    "obstacles-attempt2": ("obstacles-attempt2",),
    "obstacles-final": ("obstacles",),
}

#: Obstacle scenarios and the report's crossing generation of the final setup.
#: Each has a ``<name>-robot-com`` twin scored on the robot's own centre of mass, not the seed's.
OBSTACLE_SCENARIOS = ("obstacles-attempt1", "obstacles-attempt2", "obstacles")
ROBOT_COM = "-robot-com"
REPORT_CROSSING_GENERATION = 80

HOLDS, PARTLY, FAILS, UNTESTED = "holds", "partly", "does not hold", "not run"

#: The best NormFinalDist of the report's treatment-1 run (Fig. 1, voxel lengths).
REPORT_T1_FINAL = 47.7


# ---------------------------------------------------------------------------- data
@dataclass
class RunData:
    """One run folder, as the report reads it."""

    scenario: str
    path: Path
    config: dict[str, Any]
    rows: list[dict[str, Any]]
    best: dict[str, Any] | None
    complete: bool
    #: The run folder's notes (:func:`evolvers.recording.recorder.read_run_notes`).
    notes: list[dict[str, Any]] = field(default_factory=list)

    @property
    def seed(self) -> int:
        """The run's seed."""
        return int(self.config["seed"])

    @property
    def experiment(self) -> dict[str, Any]:
        """The experiment as config.json records it."""
        return self.config["experiment"]

    @property
    def target(self) -> int:
        """Generations asked for."""
        return int(self.config.get("generations", -1))

    @property
    def generation(self) -> int:
        """Last generation logged (-1 if none)."""
        return int(self.rows[-1]["generation"]) if self.rows else -1

    @property
    def fitness(self) -> str:
        """The first objective (the report's "fitness"), age excluded."""
        names = [o["name"] for o in self.experiment["objectives"] if o["name"] != "age"]
        return names[0] if names else "norm_final_dist"

    @property
    def shape(self) -> tuple[int, int, int]:
        """The robot grid."""
        s = self.experiment["shape"]
        return (int(s[0]), int(s[1]), int(s[2]))

    def series(self, key: str) -> np.ndarray:
        """``key`` per generation 0..last, NaN where missing; ndarray of shape (generation + 1,)."""
        out = np.full(self.generation + 1, np.nan)
        for r in self.rows:
            v = r.get(key)
            if v is not None:
                try:
                    out[int(r["generation"])] = float(v)
                except (TypeError, ValueError):
                    pass
        return out

    def at(self, key: str, generation: int | None = None) -> float:
        """``key`` at ``generation`` (default the last); NaN if missing."""
        s = self.series(key)
        g = len(s) - 1 if generation is None else generation
        return float(s[g]) if 0 <= g < len(s) else float("nan")

    def winner(self) -> Individual | None:
        """The best individual found (hall of fame first), or None."""
        if not self.best or "genome" not in self.best:
            return None
        return Individual.from_dict(self.best["genome"])


def load_runs(root: str | os.PathLike[str]) -> dict[str, list[RunData]]:
    """Every run folder under ``root``, by scenario, each list sorted by seed.

    The scenario is the name in ``scenario.json`` of the run folder's parent
    (written by :func:`evolvers.study.run_study`), else the experiment's name.
    """
    root = Path(root)
    runs: dict[str, list[RunData]] = {}
    for cfg_path in sorted(root.rglob("config.json")):
        run_dir = cfg_path.parent
        try:  # every file through the capped reader: a FIFO is refused, never waited on
            cfg = read_json(cfg_path)
        except CheckpointError as exc:
            log.warning("skipping a run: %s", exc)
            continue
        if not isinstance(cfg, dict) or cfg.get("schema") != "softgym.run":
            continue
        try:  # one damaged run must not stop the report: it is named and skipped
            cfg = read_run_config(run_dir)
            rows = read_log(run_dir)
            for n, row in enumerate(rows, 1):
                if not is_int(row.get("generation")):
                    raise CheckpointError(
                        f"{run_dir / 'log.jsonl'}: line {n} needs an integer 'generation', "
                        f"got {show(row.get('generation'))}"
                    )
        except CheckpointError as exc:
            log.warning("skipping a run: %s", exc)
            continue
        if not rows:  # started, no generation logged yet: nothing to report
            log.info("skipping %s: no generation logged yet", run_dir)
            continue
        scenario = cfg["experiment"]["name"]
        sc_path = run_dir.parent / "scenario.json"
        if sc_path.exists() or sc_path.is_symlink():
            try:
                name = read_json(sc_path).get("name")
                if not isinstance(name, str):
                    raise CheckpointError(f"{sc_path}: 'name' must be a string, got {show(name)}")
                scenario = name
            except (CheckpointError, AttributeError) as exc:
                log.warning("%s: grouped by its experiment's name (%s)", run_dir, exc)
        best = None
        if (run_dir / "best_designs.json").exists():
            try:
                best = read_best_designs(run_dir)[0]
                if "genome" in best:
                    Individual.from_dict(best["genome"])
            except SoftGymError as exc:
                log.warning("%s: no best robot (%s: %s)", run_dir, run_dir / "best_designs.json", exc)
                best = None
        gens = int(cfg.get("generations", -1))
        complete = (
            (run_dir / "final_population.json").exists()
            and bool(rows)
            and int(rows[-1]["generation"]) >= gens
        )
        try:
            notes = read_run_notes(run_dir)
        except CheckpointError as exc:
            log.warning("%s", exc)
            notes = [{"text": f"unreadable notes: {exc}"}]
        runs.setdefault(scenario, []).append(
            RunData(scenario, run_dir, cfg, rows, best, complete, notes)
        )
    for v in runs.values():
        v.sort(key=lambda r: r.seed)
    return runs
