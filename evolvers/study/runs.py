"""A study: the seed report's scenarios re-run over many seeds, each an ordinary run folder.

The seed report ran every scenario once. A :class:`Study` names a set of
:class:`Scenario` s (an experiment of :mod:`evolvers.evaluation.experiments`, a number of
generations and of seeds); :func:`plan` expands it into one :class:`RunSpec`
per scenario and seed, and :func:`run_study` runs them::

    OUT/study.json                      what was asked (scenarios, seeds, overrides)
    OUT/<scenario>/scenario.json        the scenario (the report groups runs by it)
    OUT/<scenario>/seed-<k>/            an ordinary run folder (config, log, checkpoints,
                                        best designs), made by EvolutionRun

Each run is an :class:`~evolvers.drivers.runner.EvolutionRun` started with
``resume=True``: a complete run (its log reaches the asked generation and its
final population is written) is skipped, an interrupted one continues from its
last checkpoint (bit for bit as if never stopped), a missing one starts. So a
study is resumed by running the same command again, and a larger
``--generations`` extends finished runs. Runs go in parallel, one per Dask
worker (a LocalCluster of ``workers`` processes, or an existing scheduler's
workers: ``pip install "softgym[distributed]"``); a run lost with its worker is
resubmitted and resumes from its checkpoint.

The report (:mod:`evolvers.study.report`, ``softgym study report RUNS``) is
written from the run folders alone.

================================  ======================  =====  =====  ==============================
scenario                          experiment              gens   seeds  claims (report section)
================================  ======================  =====  =====  ==============================
``materials-t1``                  materials-t1            300    5      III-A, Fig. 1
``materials-t2``                  materials-t2            50     10     III-A
``novelty``                       novelty                 200    5      III-B
``novelty-archive``               novelty-archive         200    5      III-B ("patterns loop")
``basic-200``                     basic                   200    5      III-B (fitness-based reference)
``basic``                         basic                   40     10     III-C, Fig. 4
``controller-tournament``         controller-tournament   40     10     III-C, Fig. 4
``controller-pareto``             controller-pareto       40     10     III-C, Fig. 4
``obstacles-attempt1``            obstacles-attempt1      80     5      III-D attempt 1
``obstacles-attempt2``            obstacles-attempt2      80     5      III-D attempt 2
``obstacles``                     obstacles               120    10     III-D final setup
``obstacles-attempt1-robot-com``  obstacles-attempt1      80     5      (the same on the robot's
``obstacles-attempt2-robot-com``  obstacles-attempt2      80     5      own centre of mass)
``obstacles-robot-com``           obstacles               120    3
================================  ======================  =====  =====  ==============================

The three obstacle scenarios score on the seed's centre of mass, which counts the
fence's wall voxels (:data:`SEED_COM`), as the seed's runs did; the ``-robot-com``
ones are the same experiments on the robot's own centre of mass (softgym's default).
"""

from __future__ import annotations

import json
import logging
import math
import statistics
import time
import uuid
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from evolvers.evaluation.experiments import (
    MAX_SEED,
    Experiment,
    check_generations,
    check_seed,
    get_experiment,
)
from softgym.exceptions import CheckpointError, InvalidParameterError, SoftGymError
from softgym.io import atomic_write_json, read_json_lines
from softgym.validate import is_int, show, threads

__all__ = [
    "MAX_SEEDS",
    "SEED_REPORT",
    "STUDIES",
    "STUDY_SCHEMA",
    "RunSpec",
    "Scenario",
    "Study",
    "get_study",
    "plan",
    "run_one",
    "run_order",
    "run_status",
    "run_study",
    "settings_difference",
    "time_to_go",
]

log = logging.getLogger("evolvers")

#: ``"schema"`` of a study's study.json and scenario.json.
STUDY_SCHEMA = "softgym.study"

#: Most seeds per scenario a study plans (planning is linear in them: 10,000 seeds of
#: every scenario plan in seconds; each is a whole run).
MAX_SEEDS = 10_000


@dataclass(frozen=True)
class Scenario:
    """One line of a study: an experiment run for some generations over some seeds.

    Parameters
    ----------
    name : str
        The scenario's name (its folder under the study's root).
    experiment : str
        A named experiment (:data:`evolvers.evaluation.experiments.EXPERIMENTS`).
    generations : int
        Generations after generation 0.
    seeds : int
        Number of seeds (0, 1, ..., seeds - 1).
    description : str
        What the scenario tests.
    overrides : dict
        :class:`~evolvers.evaluation.experiments.Experiment` field overrides.
    cpu_per_generation : float, optional
        Measured CPU seconds of one generation at the default sizes (one
        thread): orders the runs longest first within a round of seeds and gives
        ``--plan``'s estimate.
    """

    name: str
    experiment: str
    generations: int
    seeds: int
    description: str = ""
    overrides: Mapping[str, Any] = field(default_factory=dict)
    cpu_per_generation: float | None = None

    def make_experiment(self, **overrides: Any) -> Experiment:
        """The experiment with the scenario's overrides, then ``overrides``."""
        return get_experiment(self.experiment, **{**dict(self.overrides), **overrides})

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict."""
        return {
            "name": self.name,
            "experiment": self.experiment,
            "generations": int(self.generations),
            "seeds": int(self.seeds),
            "description": self.description,
            "overrides": dict(self.overrides),
            "cpu_per_generation": self.cpu_per_generation,
        }

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> Scenario:
        """Inverse of :meth:`to_dict`."""
        return cls(
            name=str(data["name"]),
            experiment=str(data["experiment"]),
            generations=int(data["generations"]),
            seeds=int(data["seeds"]),
            description=str(data.get("description", "")),
            overrides=dict(data.get("overrides", {})),
            cpu_per_generation=data.get("cpu_per_generation"),
        )


@dataclass(frozen=True)
class Study:
    """A named set of scenarios."""

    name: str
    scenarios: tuple[Scenario, ...]

    def __getitem__(self, name: str) -> Scenario:
        for s in self.scenarios:
            if s.name == name:
                return s
        raise InvalidParameterError(
            f"study {self.name!r} has no scenario {name!r}; expected one of {self.names}"
        )

    @property
    def names(self) -> list[str]:
        """The scenario names, in order."""
        return [s.name for s in self.scenarios]


#: The seed's obstacle runs scored MaxXYDist and the L coefficient on a centre of mass that
#: counts the 44 one-kilogram wall voxels (the seed study); the study's obstacle scenarios
#: do the same (:attr:`evolvers.evaluation.experiments.Experiment.seed_centre_of_mass`).
SEED_COM: Mapping[str, Any] = {"seed_centre_of_mass": True}

#: The report's obstacle scenarios (section III-D), scored as the seed's runs were.
_OBSTACLES = (
    Scenario("obstacles-attempt1", "obstacles-attempt1", 80, 5,
             "wall, attempt 1: default controller, Pareto on MaxXYDist and muscles",
             SEED_COM, cpu_per_generation=5.8),
    Scenario("obstacles-attempt2", "obstacles-attempt2", 80, 5,
             "wall, attempt 2: controller evolution, fitness tournament on MaxXYDist",
             SEED_COM, cpu_per_generation=13.8),
    Scenario("obstacles", "obstacles", 120, 10,
             "wall, final setup: MaxXYDist, L coefficient, age, composition rules",
             SEED_COM, cpu_per_generation=52.3),
)  # fmt: skip


def _robot_com(s: Scenario, seeds: int) -> Scenario:
    """``s`` scored on the robot's own centre of mass: ``<name>-robot-com``."""
    overrides = {k: v for k, v in s.overrides.items() if k not in SEED_COM}
    return replace(s, name=s.name + "-robot-com", seeds=seeds, overrides=overrides,
                   description=f"{s.description}; scored on the robot's own centre of mass")  # fmt: skip


#: The seed report's claims (the seed study; issue 15): >= 10 seeds for the Fig. 4 trio,
#: materials T2 and the obstacle final setup, >= 5 for the long runs and the obstacle attempts.
#: ``cpu_per_generation``: CPU s of generations 1-4 of one seed (6x6x6, pop 15, 5 s, one thread,
#: the corotational default physics), measured for issue 15; the whole study is ~40 CPU hours.
SEED_REPORT = Study(
    "seed-report",
    (
        Scenario("materials-t1", "materials-t1", 300, 5,
                 "materials evolution, treatment 1 (report Fig. 1, 300 generations)", cpu_per_generation=18.1),
        Scenario("materials-t2", "materials-t2", 50, 10,
                 "materials evolution, treatment 2: also fewer voxels (50 generations)", cpu_per_generation=13.3),
        Scenario("novelty", "novelty", 200, 5,
                 "novelty search within the generation (200 generations)", cpu_per_generation=9.8),
        Scenario("novelty-archive", "novelty-archive", 200, 5,
                 "novelty search with an archive of past behaviours (the 'patterns loop')", cpu_per_generation=9.1),
        Scenario("basic-200", "basic", 200, 5,
                 "fitness-based reference for novelty: the basic Pareto run over 200 generations", cpu_per_generation=6.3),
        Scenario("basic", "basic", 40, 10, "basic evolution (report Fig. 4)", cpu_per_generation=6.0),
        Scenario("controller-tournament", "controller-tournament", 40, 10,
                 "controller evolution, fitness tournament (report Fig. 4)", cpu_per_generation=12.8),
        Scenario("controller-pareto", "controller-pareto", 40, 10,
                 "controller evolution, Pareto on distance and muscles (report Fig. 4)", cpu_per_generation=12.8),
        *_OBSTACLES,
        # the same on the robot's own centre of mass (softgym's default): does the seed's
        # wall-diluted score change what evolves?
        *(_robot_com(s, seeds) for s, seeds in zip(_OBSTACLES, (5, 5, 3))),
    ),
)  # fmt: skip

#: Named studies.
STUDIES: dict[str, Study] = {SEED_REPORT.name: SEED_REPORT}


def get_study(name: str) -> Study:
    """A named study (:data:`STUDIES`)."""
    try:
        return STUDIES[name]
    except KeyError:
        raise InvalidParameterError(
            f"unknown study {name!r}; expected one of {sorted(STUDIES)}"
        ) from None


@dataclass(frozen=True)
class RunSpec:
    """One run of a study: a scenario's experiment, a seed, generations and a folder.

    Plain data (:meth:`to_dict`), so it travels to a Dask worker as JSON-ready values.
    """

    scenario: str
    experiment: Experiment
    seed: int
    generations: int
    out: Path
    n_threads: int | None = None
    cpu_per_generation: float | None = None

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict."""
        return {
            "scenario": self.scenario,
            "experiment": self.experiment.to_dict(),
            "seed": int(self.seed),
            "generations": int(self.generations),
            "out": str(self.out),
            "n_threads": self.n_threads,
            "cpu_per_generation": self.cpu_per_generation,
        }

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> RunSpec:
        """Inverse of :meth:`to_dict`."""
        return cls(
            scenario=str(data["scenario"]),
            experiment=Experiment.from_dict(data["experiment"]),
            seed=int(data["seed"]),
            generations=int(data["generations"]),
            out=Path(data["out"]),
            n_threads=None if data.get("n_threads") is None else int(data["n_threads"]),
            cpu_per_generation=data.get("cpu_per_generation"),
        )

    @property
    def cost(self) -> float:
        """Estimated CPU seconds of the whole run (longest runs are scheduled first).

        From the scenario's measured ``cpu_per_generation``, scaled by the
        simulated robot-seconds of a generation relative to the default sizes
        (pop 15 + 1, 5 s, 6x6x6); without a measurement, 10 s per default generation.
        """
        e = self.experiment
        scale = (e.pop_size + e.n_random) * e.seconds * math.prod(e.shape) / (16 * 5.0 * 216)
        per_gen = 10.0 if self.cpu_per_generation is None else float(self.cpu_per_generation)
        return (self.generations + 1) * per_gen * scale


def plan(
    out: str | Path,
    study: str | Study = "seed-report",
    scenarios: Iterable[str] | None = None,
    seeds: int | None = None,
    generations: int | None = None,
    first_seed: int = 0,
    n_threads: int | None = None,
    **overrides: Any,
) -> list[RunSpec]:
    """The runs of a study, one per scenario and seed.

    Parameters
    ----------
    out : path
        The study's root folder.
    study : str or Study
    scenarios : iterable of str, optional
        Scenario names (default: all of the study's).
    seeds, generations : int, optional
        Override every scenario's number of seeds / generations.
    first_seed : int
        Seeds are ``first_seed, first_seed + 1, ...``.
    n_threads : int, optional
        OpenMP threads of each run's simulations.
    **overrides
        Experiment field overrides for every scenario (e.g. ``pop_size``,
        ``seconds``, ``shape`` for a small test study).

    Raises
    ------
    InvalidParameterError
        For an unknown study or scenario, seeds/generations below 1 / 0, or n_threads
        below 1 (before anything is written).
    InvalidDesignError
        For a ``shape`` override that is no robot grid.
    """
    st = get_study(study) if isinstance(study, str) else study
    chosen = [st[name] for name in scenarios] if scenarios else list(st.scenarios)
    if seeds is not None and (not is_int(seeds) or not 1 <= seeds <= MAX_SEEDS):
        raise InvalidParameterError(
            f"seeds must be an integer in [1, {MAX_SEEDS}] (per scenario), got {show(seeds)}"
        )
    if generations is not None:
        generations = check_generations(generations)
    first_seed = check_seed(first_seed, "first_seed")
    threads(n_threads, "n_threads (--threads)")
    if "shape" in overrides:
        from softgym.design.robot import check_grid_shape

        overrides["shape"] = check_grid_shape(overrides["shape"], "shape (--shape)")
    if isinstance(out, str) and not out.strip():
        raise InvalidParameterError(f"the study's root folder (--out) must name a folder, got {out!r}")
    root = Path(out)
    specs = []
    for sc in chosen:
        exp = sc.make_experiment(**overrides)
        n = sc.seeds if seeds is None else int(seeds)
        if first_seed + n - 1 > MAX_SEED:
            raise InvalidParameterError(
                f"first_seed + seeds - 1 must be at most {MAX_SEED} (the largest seed), "
                f"got {first_seed + n - 1}"
            )
        gens = sc.generations if generations is None else int(generations)
        for k in range(first_seed, first_seed + n):
            specs.append(
                RunSpec(sc.name, exp, k, gens, root / sc.name / f"seed-{k}", n_threads,
                        sc.cpu_per_generation)
            )  # fmt: skip
    return specs


def _logged_rows(run_dir: Path) -> list[dict[str, Any]]:
    """The rows of a run folder's ``log.jsonl`` through the capped reader (a FIFO or an
    oversized file is refused, never waited on); [] if it has none or it is damaged
    (a resume rewrites it from the checkpoint, or names what blocks it).
    """
    path = Path(run_dir) / "log.jsonl"
    if not (path.exists() or path.is_symlink()):
        return []
    try:
        rows = read_json_lines(path)
    except CheckpointError:
        return []
    return rows if all(is_int(r.get("generation")) for r in rows) else []


def _last_generation(run_dir: Path) -> int:
    rows = _logged_rows(run_dir)
    return int(rows[-1]["generation"]) if rows else -1


def _generation_seconds(run_dir: Path) -> tuple[int, float]:
    """(last generation logged, wall seconds its generations took); (-1, 0) without a log."""
    rows = _logged_rows(run_dir)
    total = 0.0
    for row in rows:
        try:
            total += float(row.get("wall_time") or 0.0)
        except (TypeError, ValueError):
            continue
    return (int(rows[-1]["generation"]) if rows else -1), total


def _settings_key(spec: RunSpec) -> tuple[str, str]:
    """A scenario and its settings, all but the number of generations."""
    exp = {k: v for k, v in spec.experiment.to_dict().items() if k != "generations"}
    return spec.scenario, json.dumps(exp, sort_keys=True, default=str)


def time_to_go(specs: Sequence[RunSpec]) -> list[tuple[float, str]]:
    """Seconds each run still needs, and where the figure comes from, in ``specs``' order.

    A run with logged generations is timed by its own seconds per generation
    ("measured"); a new run by the median rate of its scenario's runs in
    ``specs`` that have logged generations with the same settings ("scenario");
    otherwise by :attr:`RunSpec.cost` ("estimate"). Rates are wall seconds of
    one run on one worker, i.e. CPU seconds when each worker has a core.
    Complete runs need 0.
    """
    rate: dict[int, float] = {}  # seconds per generation of the runs with logged generations
    for s in specs:
        last, total = _generation_seconds(s.out)
        if last >= 1 and total > 0:  # a rate from a single generation 0 is mostly set-up
            rate[id(s)] = total / (last + 1)
    by_settings: dict[tuple[str, str], list[float]] = {}
    for s in specs:
        if id(s) in rate:
            by_settings.setdefault(_settings_key(s), []).append(rate[id(s)])
    out = []
    for s in specs:
        if run_status(s.out, s.generations) == "complete":
            out.append((0.0, "complete"))
            continue
        left = s.generations - _last_generation(s.out)
        if id(s) in rate:
            out.append((left * rate[id(s)], "measured"))
        elif (key := _settings_key(s)) in by_settings:
            out.append((left * statistics.median(by_settings[key]), "scenario"))
        else:
            out.append((s.cost * left / (s.generations + 1), "estimate"))
    return out


def run_status(run_dir: str | Path, generations: int) -> str:
    """``"complete"``, ``"partial"`` (a checkpoint to resume) or ``"new"``.

    Complete: ``final_population.json`` exists and the log reaches ``generations``.
    """
    run_dir = Path(run_dir)
    last = _last_generation(run_dir)
    if (run_dir / "final_population.json").exists() and last >= generations:
        return "complete"
    ckpts = run_dir / "checkpoints"
    if ckpts.exists() and any(ckpts.glob("ckpt-*.json")):
        return "partial"
    return "new"


def settings_difference(spec: RunSpec) -> str | None:
    """Where the run folder's config.json differs from ``spec`` (experiment or seed), or None.

    None also when the folder has no config.json yet (nothing ran); one that
    cannot be read (a FIFO, an oversized or malformed file, a missing key) is a
    difference naming the file. A complete run with other settings (e.g. a
    scenario whose overrides changed) must not be counted as this spec's run.
    """
    from evolvers.recording.recorder import config_difference, read_run_config

    path = Path(spec.out) / "config.json"
    if not (path.exists() or path.is_symlink()):
        return None
    try:
        cfg = read_run_config(spec.out)  # the capped reader: a FIFO is refused at once
        recorded = Experiment.from_dict(cfg["experiment"]).to_dict()
        seed = cfg.get("seed")
        if not is_int(seed):
            raise CheckpointError(f"{path}: 'seed' must be an integer, got {show(seed)}")
    except SoftGymError as exc:
        return f"its config.json cannot be read: {exc}"
    if seed != spec.seed:
        return f"seed: {seed} (recorded) != {spec.seed}"
    given = spec.experiment.to_dict()
    for d in (recorded, given):  # a run may be extended; a description is not a setting
        d.pop("generations", None)
        d.pop("description", None)
    return config_difference(recorded, given, "experiment")


def run_one(spec: Mapping[str, Any] | RunSpec) -> dict[str, Any]:
    """Run (or resume, or skip) one run of a study; the function a Dask worker calls.

    Returns
    -------
    dict
        ``scenario``, ``seed``, ``out``, ``status`` (``"skipped"``: already
        complete; ``"ran"``; ``"resumed"``; ``"failed"`` with ``error``),
        ``generation`` reached and ``wall`` seconds.
    """
    from evolvers.drivers.runner import EvolutionRun

    spec = spec if isinstance(spec, RunSpec) else RunSpec.from_dict(spec)
    out = {"scenario": spec.scenario, "seed": spec.seed, "out": str(spec.out)}
    before = run_status(spec.out, spec.generations)
    if (diff := settings_difference(spec)) is not None:  # never skip or extend another's run
        return {
            **out, "status": "failed", "generation": _last_generation(spec.out), "wall": 0.0,
            "error": f"{spec.out} was run with other settings ({diff}); move it aside or "
                     "choose another --out",
        }  # fmt: skip
    if before == "complete":
        return {**out, "status": "skipped", "generation": _last_generation(spec.out), "wall": 0.0}
    t0 = time.perf_counter()
    try:
        run = EvolutionRun(
            spec.experiment, spec.out, seed=spec.seed, generations=spec.generations,
            n_threads=spec.n_threads, figures=False, gif=False, progress=False,
        )  # fmt: skip
        run.run(resume=True)
    except SoftGymError as exc:
        return {
            **out, "status": "failed", "error": f"{type(exc).__name__}: {exc}",
            "generation": _last_generation(spec.out), "wall": time.perf_counter() - t0,
        }  # fmt: skip
    return {
        **out,
        "status": "resumed" if before == "partial" else "ran",
        "generation": run.generation,
        "wall": time.perf_counter() - t0,
    }


def _write_manifest(root: Path, study: str, specs: Sequence[RunSpec]) -> None:
    scenarios: dict[str, dict[str, Any]] = {}
    for s in specs:
        d = scenarios.setdefault(
            s.scenario,
            {
                "schema": STUDY_SCHEMA,
                "study": study,
                "name": s.scenario,
                "experiment": s.experiment.to_dict(),
                "generations": s.generations,
                "seeds": [],
            },
        )
        d["seeds"].append(s.seed)
    for name, d in scenarios.items():
        folder = root / name
        folder.mkdir(parents=True, exist_ok=True)
        atomic_write_json(folder / "scenario.json", d)
    atomic_write_json(
        root / "study.json",
        {
            "schema": STUDY_SCHEMA,
            "study": study,
            "scenarios": {n: {"generations": d["generations"], "seeds": d["seeds"]}
                          for n, d in scenarios.items()},
        },
    )  # fmt: skip


def run_order(specs: Sequence[RunSpec]) -> list[RunSpec]:
    """The order runs start in: rounds of seeds, longest run first within a round.

    Seed 0 of every scenario comes before seed 1 of any, so a study stopped
    part-way (a session ends, a cluster allocation runs out) has results for
    every scenario rather than all seeds of the longest one; within a round the
    longest runs start first so the round finishes soonest.
    """
    return sorted(specs, key=lambda s: (s.seed, -s.cost))


def run_study(
    specs: Sequence[RunSpec],
    workers: int = 1,
    scheduler: str | None = None,
    study: str = "seed-report",
    on_result: Callable[[dict[str, Any]], None] | None = None,
    on_start: Callable[[RunSpec], None] | None = None,
) -> list[dict[str, Any]]:
    """Run a study's runs: skip complete ones, resume interrupted ones, start the rest.

    Parameters
    ----------
    specs : sequence of RunSpec
        From :func:`plan` (all under one root folder).
    workers : int
        Runs at a time. 1 runs them one after the other in this process (no
        Dask needed); more starts a Dask LocalCluster of that many one-thread
        worker processes, one run per worker.
    scheduler : str, optional
        A Dask scheduler address (``tcp://host:8786``): its workers run the
        runs (``workers`` is then ignored). They write the run folders at the
        specs' paths, so the workers must see the same filesystem.
    study : str
        The study's name (recorded in study.json).
    on_result : callable, optional
        Called with each run's result (:func:`run_one`) as it finishes.
    on_start : callable, optional
        Called with each run's spec as it starts (on Dask: as it is submitted to the
        cluster, which starts it when a worker is free).

    Returns
    -------
    list of dict
        The results of :func:`run_one`, in the order of :func:`run_order`.

    Raises
    ------
    MissingExtraError
        If parallel runs are asked for without Dask installed.
    """
    if not specs:
        return []
    roots = {s.out.parent.parent for s in specs}
    for root in roots:
        _write_manifest(root, study, [s for s in specs if s.out.parent.parent == root])
    ordered = run_order(specs)
    results: list[dict[str, Any]] = []

    def done(res: dict[str, Any]) -> None:
        results.append(res)
        if res["status"] == "failed":
            log.warning("%s seed %s failed: %s", res["scenario"], res["seed"], res["error"])
        if on_result is not None:
            on_result(res)

    def failed(s: RunSpec, exc: BaseException) -> dict[str, Any]:
        log.error("%s seed %s raised", s.scenario, s.seed, exc_info=exc)
        return {
            "scenario": s.scenario, "seed": s.seed, "out": str(s.out), "status": "failed",
            "error": f"{type(exc).__name__}: {exc}", "generation": _last_generation(s.out),
            "wall": float("nan"),
        }  # fmt: skip

    if scheduler is None and workers <= 1:
        for s in ordered:
            if on_start is not None:
                on_start(s)
            try:
                res = run_one(s)
            except Exception as exc:  # a bug in one run must not stop the others
                res = failed(s, exc)
            done(res)
        return results

    from evolvers.evaluation.distributed import dask_client, require_distributed

    distributed = require_distributed()
    one_thread = [replace(s, n_threads=1) if s.n_threads is None else s for s in ordered]
    tag = uuid.uuid4().hex[:8]
    with dask_client(scheduler or "local", n_workers=workers) as client:
        # a window of as many runs as the cluster has threads, the next one submitted as one
        # ends: runs start in run_order (all seed 0 runs before any seed 1), which Dask does
        # not keep when everything is submitted at once (its workers take tasks as they are
        # placed and stolen, and a study's last seeds started before its first ones ended)
        window = max(1, sum(client.nthreads().values()))
        pending = iter(one_thread)
        futures: dict[Any, RunSpec] = {}
        ac = distributed.as_completed()

        def submit_next() -> None:
            s = next(pending, None)
            if s is None:
                return
            if on_start is not None:
                on_start(s)
            key = f"{s.scenario}-seed-{s.seed}-{tag}"
            fut = client.submit(run_one, s.to_dict(), pure=False, retries=2, key=key)
            futures[fut] = s
            ac.add(fut)

        for _ in range(window):
            submit_next()
        for fut in ac:
            try:
                res = fut.result()
            except Exception as exc:
                res = failed(futures[fut], exc)
            done(res)
            submit_next()
    return results
