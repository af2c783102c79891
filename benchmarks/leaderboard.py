"""The co-design leaderboard: every task x optimiser x seed at one budget of simulations.

For every registered task (``softgym.tasks.task_names()``, read again at each launch, so a
task registered since is planned by the next one), every optimiser and every seed, one run
(a *cell*) of body and controller co-design:

* **search space**: 6x6x6 robots drawn by a CPPN (the seed's 4-output material tree; at
  least 30 % of the grid filled and 10 % muscle) with the seed's open-loop sinusoid, whose
  three genes (amplitude, period, muscle CTE) evolve too, scored on the task's own measure
  (its ``score``): the ``codesign`` experiments of :mod:`evolvers.evaluation.experiments`;
* **budget**: ``--evals`` simulations per run, ``--seconds`` simulated each (the first second
  settles), ``--pop`` robots a generation, one thread. A run stops after the generation that
  reaches the budget (up to one generation more); a phenotype read from the run's cache and
  an invalid body are not simulated and not counted;
* **optimisers** (:data:`REFERENCES`): each is a ``softgym`` command, run in this process
  through the project's own drivers, so its cell is an ordinary, resumable run folder.

Runs go to ``OUT/runs/<task>/<optimiser>/seed-<k>/`` (run folders with checkpoints; git
ignores ``runs/``); a finished run leaves a lean record in
``OUT/cells/<task>/<optimiser>/seed-<k>.json`` (the command, the best-so-far curve over
simulations, the best score and design, CPU seconds). A relaunch skips finished cells and
resumes interrupted ones from their last checkpoint; seeds are the outer loop, so a partial
leaderboard has every task at its first seeds. ``OUT/plan.json`` records the budget and the
commands: a relaunch with another budget is refused.

A user adds an optimiser with ``--optimizer NAME=COMMAND`` (repeatable): a command line with
placeholders (:data:`PLACEHOLDERS`; ``{run_flags}`` holds the task, seed, budget, threads,
run folder and ``--resume`` when the folder holds a run), or ``py:MODULE:FACTORY``, a
callable with a :class:`~evolvers.drivers.base.Driver`'s signature (any Driver subclass)
given the ``codesign`` experiment of the task. With ``--reference DIR`` the budget, seeds and
tasks come from that leaderboard and the printed tables put the new rows beside its own.
The command must leave a softgym run folder whose experiment maximises the task's score
with the plan's task, seconds and ``--max-evals``: each is checked when the cell is read.

    python benchmarks/leaderboard.py --plan              # the plan and its estimated CPU cost
    nohup nice -n 10 python benchmarks/leaderboard.py --out benchmarks/data/leaderboard \\
        > /tmp/leaderboard.log 2>&1 &                    # run (the same command resumes)
    python benchmarks/leaderboard.py --out benchmarks/data/leaderboard --report \\
        --doc docs/leaderboard.md --figures docs/figures # the tables, curves and gallery
    python benchmarks/leaderboard.py --reference benchmarks/data/leaderboard --out runs/mine \\
        --optimizer "novelty=softgym evolve --experiment codesign --selection novelty \\
        --pop {pop} {run_flags}"                         # a new row beside the references
"""

from __future__ import annotations

import argparse
import contextlib
import datetime as _dt
import importlib
import io
import math
import re
import resource
import shlex
import signal
import subprocess
import sys
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from evolvers.evaluation.experiments import Experiment, get_experiment
from evolvers.recording.recorder import read_run_config
from softgym.exceptions import CheckpointError, InvalidParameterError, SoftGymError
from softgym.io import RunLock, atomic_write_json, atomic_write_text, read_json, read_json_lines
from softgym.tasks import get_task, task_names

ROOT = Path(__file__).resolve().parents[1]
SCHEMA = "softgym.leaderboard"
#: The plan of a leaderboard folder unless typed or recorded.
DEFAULTS = {"evals": 256, "pop": 16, "seconds": 3.0, "seeds": 5}
#: Generations of every run: more than any budget of simulations needs (the budget stops it).
GENERATIONS = 100_000
#: Threads of every run (the CPU seconds are one core's).
THREADS = 1
#: What ``{run_flags}`` stands for in an optimiser's command.
RUN_FLAGS = ("--task {task} --seed {seed} --seconds {seconds} --max-evals {evals} "
             "--generations {generations} --threads {threads} --out {out} --no-figures "
             "--no-gif -q {resume}")  # fmt: skip
#: The placeholders of an optimiser's command.
PLACEHOLDERS = ("task", "seed", "out", "evals", "pop", "seconds", "threads", "generations",
                "resume", "run_flags")  # fmt: skip
#: The reference optimisers: name -> (command, the search in words).
REFERENCES: dict[str, tuple[str, str]] = {
    "random": (
        "softgym evolve --experiment codesign --backend random --pop {pop} {run_flags}",
        "random search: {pop} fresh random valid genomes a generation (a random CPPN, "
        "controller genes uniform in their bounds), the best {pop} kept",
    ),
    "tournament": (
        "softgym evolve --experiment codesign --pop {pop} {run_flags}",
        "the seed's GA: each parent makes one child (CPPN mutation with validity retries, "
        "arithmetic crossover and Gaussian mutation of the controller genes), one random "
        "newcomer a generation, fitness tournament of 2",
    ),
    "afpo": (
        "softgym evolve --experiment codesign-afpo --pop {pop} {run_flags}",
        "age-fitness Pareto (the seed's loop and variation; Pareto levels on score and age, "
        "the random newcomer at age 0)",
    ),
    "nsga2": (
        "softgym evolve --experiment codesign-afpo --backend pymoo --algorithm nsga2 "
        "--pop {pop} {run_flags}",
        "pymoo's NSGA-II on score and age (the softbot operators: arithmetic crossover, "
        "CPPN mutation; duplicates eliminated; no newcomers)",
    ),
    "cmaes": (
        "softgym evolve --experiment codesign --backend pymoo --algorithm cmaes "
        "--pop {pop} {run_flags}",
        "pymoo's CMA-ES over an 86-gene design vector: the 83 weights of a fixed-topology "
        "CPPN (5 inputs, 7 hidden nodes, one per activation, 4 outputs) and the 3 controller "
        "genes; x0 the best of {pop} random valid vectors, sigma 0.1 of the box",
    ),
    "map-elites": (
        "softgym qd --experiment codesign --batch {pop} --cells 10 {run_flags}",
        "MAP-Elites on pyribs: a 10 x 10 grid over stiff and filled fractions, parents drawn "
        "uniformly from the elites, the seed's variation",
    ),
}
_NAME = re.compile(r"[a-z0-9][a-z0-9._-]{0,39}")
_DOC_START, _DOC_END = "<!-- leaderboard:start -->", "<!-- leaderboard:end -->"


# ---------------------------------------------------------------------- the plan
def parse_optimizer(text: str) -> tuple[str, str]:
    """``NAME=COMMAND`` as ``(name, command)``, the command's placeholders checked.

    Raises
    ------
    InvalidParameterError
        Naming ``--optimizer`` and what is wrong.
    """
    name, sep, command = text.partition("=")
    name, command = name.strip(), command.strip()
    if not sep or not _NAME.fullmatch(name) or not command:
        raise InvalidParameterError(
            f"--optimizer must be NAME=COMMAND with NAME of lower-case letters, digits, '.', "
            f"'_' or '-' (at most 40), got {text!r}"
        )
    if command.startswith("py:"):
        if command.count(":") != 2 or not all(command.split(":")[1:]):
            raise InvalidParameterError(f"--optimizer {name}: py: entries are py:MODULE:FACTORY, "
                                        f"got {command!r}")  # fmt: skip
    else:
        _argv(command, {p: "x" for p in PLACEHOLDERS}, name)
    return name, command


def _argv(command: str, values: dict[str, Any], name: str) -> list[str]:
    """The argument list of an optimiser's command with its placeholders filled."""
    try:
        tokens = shlex.split(command.replace("{run_flags}", RUN_FLAGS))
        argv = [t.format(**values) for t in tokens]
    except KeyError as exc:
        raise InvalidParameterError(f"--optimizer {name}: unknown placeholder {{{exc.args[0]}}}; "
                                    f"the placeholders are {list(PLACEHOLDERS)}") from None  # fmt: skip
    except (ValueError, IndexError) as exc:
        raise InvalidParameterError(
            f"--optimizer {name}: the command does not parse ({exc})"
        ) from None
    return [a for a in argv if a]


def read_plan(folder: Path) -> dict[str, Any] | None:
    """A leaderboard folder's plan.json (None when it has none)."""
    path = folder / "plan.json"
    if not path.exists():
        return None
    plan = read_json(path)
    if not isinstance(plan, dict) or plan.get("schema") != SCHEMA:
        raise CheckpointError(f"{path}: not a leaderboard plan (schema {SCHEMA!r})")
    return plan


def resolve_plan(args: argparse.Namespace) -> tuple[dict[str, Any], list[str], dict[str, str]]:
    """The folder's plan after this launch, the tasks and the optimisers this launch runs.

    The budget (evals, pop, seconds, seeds): typed, else the folder's, else the
    reference's, else :data:`DEFAULTS`; a typed value that differs from the folder's or the
    reference's is refused. Tasks: typed, else the reference's, else the registry's (read
    now). Optimisers: the ``--optimizer`` ones, else the ``--optimizers`` subset of
    :data:`REFERENCES`.

    Raises
    ------
    InvalidParameterError
        Naming the flag.
    """
    recorded = read_plan(args.out)
    reference = read_plan(args.reference) if args.reference else None
    if args.reference and reference is None:
        raise InvalidParameterError(
            f"--reference {args.reference}: no leaderboard there (no plan.json)"
        )
    budget = {}
    for key, default in DEFAULTS.items():
        typed = getattr(args, key)
        value = typed
        for source, where in ((recorded, args.out), (reference, args.reference)):
            if source is None:
                continue
            have = len(source["seeds"]) if key == "seeds" else source[key]
            if value is None:
                value = have
            elif value != have:
                raise InvalidParameterError(
                    f"--{key} {value}: {where} was planned with --{key} {have} (the same budget "
                    "for every row); drop the flag or use another --out"
                )
        value = default if value is None else value
        if not (isinstance(value, (int, float)) and value > 0) or (
            key != "seconds" and value != int(value)
        ):
            raise InvalidParameterError(
                f"--{key} must be a number > 0 (an integer but --seconds), got {value}"
            )
        budget[key] = int(value) if key != "seconds" else float(value)
    if budget["seconds"] <= 1.0:
        raise InvalidParameterError(
            f"--seconds must be more than the 1 s settling time, got {budget['seconds']}"
        )
    registry = task_names()
    if args.tasks:
        unknown = [t for t in args.tasks if t not in registry]
        if unknown:
            raise InvalidParameterError(
                f"--tasks: unknown task(s) {unknown}; the tasks are {registry}"
            )
        tasks = list(args.tasks)
    else:
        tasks = list(reference["tasks"]) if reference else registry
    if args.optimizer:
        runs = dict(parse_optimizer(t) for t in args.optimizer)
    else:
        names = args.optimizers or list(REFERENCES)
        unknown = [n for n in names if n not in REFERENCES]
        if unknown:
            raise InvalidParameterError(f"--optimizers: unknown {unknown}; the references are "
                                        f"{list(REFERENCES)} (add others with --optimizer)")  # fmt: skip
        runs = {n: REFERENCES[n][0] for n in names}
    known = {**(reference or {}).get("optimizers", {}), **(recorded or {}).get("optimizers", {})}
    for name, command in runs.items():
        if name in known and known[name]["command"] != command:
            raise InvalidParameterError(
                f"--optimizer {name}: that name runs {known[name]['command']!r} here (or in the "
                "reference); give this command another name"
            )
    optimizers = {**(recorded or {}).get("optimizers", {})}
    for name, command in runs.items():
        space = REFERENCES[name][1] if name in REFERENCES and REFERENCES[name][0] == command else ""
        optimizers[name] = {"command": command, "search": space}
    plan_tasks = list((recorded or {}).get("tasks", []))
    plan_tasks += [t for t in tasks if t not in plan_tasks]
    plan = {"schema": SCHEMA, "version": 1, **{k: budget[k] for k in ("evals", "pop", "seconds")},
            "seeds": list(range(1, budget["seeds"] + 1)), "tasks": plan_tasks,
            "optimizers": optimizers, "threads": THREADS, "shape": [6, 6, 6]}  # fmt: skip
    return plan, tasks, runs


# ---------------------------------------------------------------------- the cells
def cell_paths(out: Path, task: str, name: str, seed: int) -> tuple[Path, Path, Path]:
    """``(run folder, lean record, sittings file)`` of a cell."""
    run = out / "runs" / task / name / f"seed-{seed}"
    return (
        run,
        out / "cells" / task / name / f"seed-{seed}.json",
        run.with_name(f"seed-{seed}.sittings.json"),
    )


def _git_commit() -> str | None:
    try:
        res = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True,
                             text=True, timeout=10)  # fmt: skip
    except OSError:
        return None
    return res.stdout.strip() or None


def _raise_interrupt(signum, frame):  # SIGTERM: stop like Ctrl-C (the cell's checkpoint stays)
    raise KeyboardInterrupt


def _run_softgym(argv: list[str]) -> int:
    """A ``softgym`` command in this process (its JSON summary not printed)."""
    from softgym_cli import main

    with contextlib.redirect_stdout(io.StringIO()):
        return int(main(argv[1:]))


def _run_python(entry: str, plan: dict[str, Any], task: str, seed: int, run_dir: Path) -> int:
    """A ``py:MODULE:FACTORY`` optimiser: the factory's Driver on the task's codesign experiment."""
    _, module, attr = entry.split(":")
    factory = getattr(importlib.import_module(module), attr)
    exp = get_experiment("codesign", task=task, pop_size=plan["pop"], seconds=plan["seconds"])
    run = factory(exp, run_dir, seed=seed, generations=GENERATIONS, budget={"max_evals": plan["evals"]},
                  n_threads=THREADS, progress=False, figures=False, gif=False)  # fmt: skip
    run.run(resume=True)
    return 0


def _run_child(argv: list[str]) -> int:
    """Any other command, as a child process (SIGTERM passed on, its checkpoint kept)."""
    proc = subprocess.Popen(argv)
    try:
        return proc.wait()
    except KeyboardInterrupt:
        proc.send_signal(signal.SIGTERM)
        proc.wait(timeout=120)
        raise


def run_cell(
    plan: dict[str, Any], out: Path, task: str, name: str, seed: int, commit: str | None
) -> int:
    """Run (or resume) one cell; write its lean record when it finishes. Returns the exit code."""
    run_dir, record_path, sittings_path = cell_paths(out, task, name, seed)
    command = plan["optimizers"][name]["command"]
    values = {"task": task, "seed": seed, "out": str(run_dir), "evals": plan["evals"],
              "pop": plan["pop"], "seconds": plan["seconds"], "threads": THREADS,
              "generations": GENERATIONS,
              "resume": "--resume" if (run_dir / "config.json").exists() else ""}  # fmt: skip
    argv = [command] if command.startswith("py:") else _argv(command, values, name)
    sittings = read_json(sittings_path) if sittings_path.exists() else []
    cpu0, child0, wall0 = (
        time.process_time(),
        resource.getrusage(resource.RUSAGE_CHILDREN),
        time.perf_counter(),
    )
    rc = 1
    try:
        run_dir.parent.mkdir(parents=True, exist_ok=True)
        if argv[0].startswith("py:"):
            rc = _run_python(argv[0], plan, task, seed, run_dir)
        elif argv[0] == "softgym":
            rc = _run_softgym(argv)
        else:
            rc = _run_child(argv)
    except KeyboardInterrupt:
        rc = 130
        raise
    except Exception as exc:  # a failing optimiser must not stop the others' cells
        print(
            f"leaderboard: {task} {name} seed {seed}: {type(exc).__name__}: {exc}", file=sys.stderr
        )
        rc = 1
    finally:
        child1 = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpu = (
            (time.process_time() - cpu0)
            + (child1.ru_utime - child0.ru_utime)
            + (child1.ru_stime - child0.ru_stime)
        )
        sittings.append({"cpu_seconds": round(cpu, 3), "wall_seconds": round(time.perf_counter() - wall0, 3),
                         "exit": rc, "ended": _now()})  # fmt: skip
        sittings_path.parent.mkdir(parents=True, exist_ok=True)
        atomic_write_json(sittings_path, sittings)
    if rc == 0:
        record = lean_record(plan, run_dir, task, name, seed, argv, sittings, commit)
        atomic_write_json(record_path, record, indent=None)
    return rc


def _now() -> str:
    return _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")


def lean_record(plan: dict[str, Any], run_dir: Path, task: str, name: str, seed: int,
                argv: Sequence[str], sittings: list[dict[str, Any]], commit: str | None) -> dict[str, Any]:  # fmt: skip
    """What the leaderboard keeps of a finished run (a cell's JSON record).

    Raises
    ------
    CheckpointError
        When the run folder is not a run of this cell: another task, seconds or budget, a
        fitness that is not the task's score, a run that ended short of the budget.
    """
    cfg = read_run_config(run_dir)
    exp = Experiment.from_dict(cfg["experiment"])
    where = f"{run_dir}: {name}'s run"
    want = get_experiment("codesign", task=task).to_dict()["task"]
    if exp.to_dict()["task"] != want:
        raise CheckpointError(
            f"{where} is on task {exp.to_dict()['task']!r}, not {task!r} ({{task}})"
        )
    if exp.fitness.name != "score" or not exp.fitness.maximize:
        raise CheckpointError(f"{where} selects on {exp.fitness.name!r}; the leaderboard ranks the task's "
                              "score (use --experiment codesign or codesign-afpo)")  # fmt: skip
    if exp.seconds != plan["seconds"]:
        raise CheckpointError(
            f"{where} simulates {exp.seconds} s, not {plan['seconds']} ({{seconds}})"
        )
    if cfg.get("budget", {}).get("max_evals") != plan["evals"]:
        raise CheckpointError(
            f"{where} has budget {cfg.get('budget')}, not --max-evals {plan['evals']} ({{evals}})"
        )
    rows = [r for r in read_json_lines(run_dir / "log.jsonl") if r.get("best_so_far") is not None]
    curve = [[int(r["evaluations_total"]), float(r["best_so_far"])] for r in rows]
    if not curve or curve[-1][0] < plan["evals"]:
        raise CheckpointError(f"{where} ended after {curve[-1][0] if curve else 0} simulations, short of "
                              f"its budget of {plan['evals']} (its generations?)")  # fmt: skip
    # the score at the budget: the last generation within it (a run's last generation may
    # go past it, by up to one generation's simulations; it counts for no one)
    within = [r for r in rows if r["evaluations_total"] <= plan["evals"]] or rows[:1]
    at = within[-1]
    entries = read_json(run_dir / "best_designs.json")["best"]
    found = [e for e in entries if e["generation"] <= at["generation"]]
    return {
        "schema": SCHEMA, "task": task, "optimizer": name, "seed": seed,
        "command": shlex.join(argv), "backend": cfg.get("backend"), "algorithm": cfg.get("algorithm"),
        "evals": int(at["evaluations_total"]), "evals_run": curve[-1][0], "budget_evals": plan["evals"],
        "seconds": plan["seconds"], "pop": exp.pop_size, "best_score": float(at["best_so_far"]),
        "final_score": curve[-1][1], "curve": curve,
        "cpu_seconds": round(sum(s["cpu_seconds"] for s in sittings), 3),
        "wall_seconds": round(sum(s["wall_seconds"] for s in sittings), 3),
        "sittings": len(sittings), "commit": commit, "finished": _now(),
        # the best design within the budget (the hall of fame keeps the best five found)
        "design": found[0]["design"] if found else None,
    }  # fmt: skip


def run(args: argparse.Namespace) -> int:
    """Run (or resume) the cells of this launch; then print the tables."""
    plan, tasks, runs = resolve_plan(args)
    cells = [(t, n, s) for s in plan["seeds"] for t in tasks for n in runs]
    todo = [c for c in cells if not cell_paths(args.out, *c)[1].exists()]
    print(plan_text(plan, tasks, runs, todo, args), flush=True)
    if args.plan:
        return 0
    commit = _git_commit()
    failed = 0
    previous = signal.signal(signal.SIGTERM, _raise_interrupt)
    try:
        with RunLock(args.out):
            atomic_write_json(args.out / "plan.json", plan)
            for k, (task, name, seed) in enumerate(todo, 1):
                t0 = time.perf_counter()
                rc = run_cell(plan, args.out, task, name, seed, commit)
                if rc == 130:
                    raise KeyboardInterrupt
                record = cell_paths(args.out, task, name, seed)[1]
                if rc == 0 and record.exists():
                    r = read_json(record)
                    print(f"[{k}/{len(todo)}] {task} {name} seed {seed}: best {r['best_score']:.4g} "
                          f"({r['evals']} simulations, {r['cpu_seconds']:.0f} CPU-s, "
                          f"{time.perf_counter() - t0:.0f} s)", flush=True)  # fmt: skip
                else:
                    failed += 1
                    print(
                        f"[{k}/{len(todo)}] {task} {name} seed {seed}: failed (exit {rc})",
                        flush=True,
                    )
    except KeyboardInterrupt:
        print(f"\nleaderboard: interrupted; the cell's last checkpoint is kept. Resume with: "
              f"{shlex.join(['python', 'benchmarks/leaderboard.py', *sys.argv[1:]])}", file=sys.stderr)  # fmt: skip
        return 130
    finally:
        signal.signal(signal.SIGTERM, previous)
    print(report(args.out, args.reference, figures=None))
    return 1 if failed else 0


# ---------------------------------------------------------------------- the estimate
def calibrate(task: str, seconds: float, n: int = 4) -> float:
    """CPU seconds of one simulation of a random codesign robot on ``task`` (one thread)."""
    import softgym

    exp = get_experiment("codesign", task=task)
    rng = np.random.default_rng(0)
    designs = [exp.random_individual(rng, i).design(exp.shape) for i in range(n)]
    t0 = time.process_time()
    softgym.evaluate(designs, task=get_task(task).replace(seconds=seconds), n_threads=THREADS)
    return (time.process_time() - t0) / n


#: A run's CPU over its simulations' alone (variation, validity retries, CMA-ES's decoding,
#: logs, checkpoints): 1.7 measured on flat's first six cells (81 ms a simulation, 47 alone).
OVERHEAD = 1.7


def plan_text(plan: dict[str, Any], tasks: list[str], runs: dict[str, str], todo: list[tuple[str, str, int]],
              args: argparse.Namespace) -> str:  # fmt: skip
    """The plan of this launch and the estimated CPU time of the cells it runs."""
    n = len(plan["seeds"]) * len(tasks) * len(runs)
    lines = [f"leaderboard {args.out}: {len(tasks)} tasks x {len(runs)} optimisers ({', '.join(runs)}) "
             f"x {len(plan['seeds'])} seeds = {n} cells, {n - len(todo)} finished, {len(todo)} to run; "
             f"{plan['evals']} simulations of {plan['seconds']:g} s a run, population {plan['pop']}, "
             f"{THREADS} thread"]  # fmt: skip
    if not todo:
        return lines[0]
    done = load_cells([args.out, *([args.reference] if args.reference else [])])
    per_task: dict[str, float] = {}
    for task in dict.fromkeys(t for t, _, _ in todo):
        mine = [c for c in done if c["task"] == task]
        if mine:  # the measured CPU of the task's finished cells
            per_task[task] = sum(c["cpu_seconds"] for c in mine) / sum(c["evals_run"] for c in mine)
        else:  # a short calibration
            per_task[task] = calibrate(task, plan["seconds"]) * OVERHEAD
    total = sum(per_task[t] * plan["evals"] for t, _, _ in todo)
    lines.append(f"estimated CPU time of the cells to run: {total / 3600:.2f} h (per simulation: "
                 + ", ".join(f"{t} {1000 * v:.0f} ms" for t, v in per_task.items()) + ")")  # fmt: skip
    return "\n".join(lines)


# ---------------------------------------------------------------------- the report
def load_cells(folders: Sequence[Path]) -> list[dict[str, Any]]:
    """The lean records under ``folders`` (the first folder's record of a cell wins)."""
    seen: dict[tuple[str, str, int], dict[str, Any]] = {}
    for folder in folders:
        for path in sorted(Path(folder).glob("cells/*/*/seed-*.json")):
            r = read_json(path)
            key = (r["task"], r["optimizer"], int(r["seed"]))
            seen.setdefault(key, r)
    return list(seen.values())


def _fmt(v: float) -> str:
    if not math.isfinite(v):
        return "-"
    return f"{v:.3g}" if abs(v) >= 0.01 or v == 0 else f"{v:.2e}"


def summarise(plans: list[dict[str, Any]], cells: list[dict[str, Any]]) -> dict[str, Any]:
    """Medians, quartiles, winners, normalised scores and costs of the cells."""
    tasks = list(dict.fromkeys(t for p in plans for t in p["tasks"]))
    optimizers: dict[str, dict[str, Any]] = {}
    for p in plans:
        for name, o in p["optimizers"].items():
            optimizers.setdefault(name, o)
    scores: dict[tuple[str, str], list[float]] = {}
    for c in cells:
        scores.setdefault((c["task"], c["optimizer"]), []).append(float(c["best_score"]))
    stats = {k: (float(np.median(v)), float(np.percentile(v, 25)), float(np.percentile(v, 75)), len(v))
             for k, v in scores.items()}  # fmt: skip
    best_known = {
        t: max((c["best_score"] for c in cells if c["task"] == t), default=math.nan) for t in tasks
    }
    norm: dict[tuple[str, str], float] = {}
    winners: dict[str, list[str]] = {}
    for t in tasks:
        meds = {o: stats[(t, o)][0] for o in optimizers if (t, o) in stats}
        if meds:
            top = max(meds.values())
            winners[t] = [o for o, m in meds.items() if m == top]
        base = stats.get((t, "random"), (math.nan,))[0]
        span = best_known[t] - base
        for o, m in meds.items():
            norm[(t, o)] = (m - base) / span if span > 0 else math.nan
    cost = {}
    for t in tasks:
        mine = [c for c in cells if c["task"] == t]
        cpu = sum(c["cpu_seconds"] for c in mine)
        cost[t] = sum(c["evals_run"] for c in mine) / cpu if cpu > 0 else math.nan
    return {"tasks": tasks, "optimizers": optimizers, "stats": stats, "norm": norm, "winners": winners,
            "best_known": best_known, "evals_per_cpu_s": cost,
            "cpu_seconds": sum(c["cpu_seconds"] for c in cells)}  # fmt: skip


def report(out: Path, reference: Path | None = None, figures: Path | None = None) -> str:
    """The leaderboard's markdown: the plan, the per-task table, the per-optimiser table."""
    folders = [out, *([reference] if reference else [])]
    plans = [p for p in (read_plan(Path(f)) for f in folders) if p is not None]
    if not plans:
        raise InvalidParameterError(f"{out}: no leaderboard there (no plan.json)")
    plan = plans[0]
    cells = load_cells(folders)
    s = summarise(plans[::-1], cells)  # the reference's optimisers first, then this folder's
    tasks, opts, stats = s["tasks"], list(s["optimizers"]), s["stats"]
    seeds = len(plan["seeds"])
    n_all = len(tasks) * len(opts) * seeds
    lines = [
        f"{len(cells)} of {n_all} runs finished ({len(tasks)} tasks x {len(opts)} optimisers x "
        f"{seeds} seeds); each run: {plan['evals']} simulations of {plan['seconds']:g} s, "
        f"population {plan['pop']}, one thread; total CPU time {s['cpu_seconds'] / 3600:.2f} h.",
        "",
        "Best score a run found within its budget (the task's measure; a run's last generation may "
        "pass the budget by up to one generation, which counts for no one): median [25th, 75th "
        "percentile] over the seeds, (n) where fewer seeds have finished; **bold**: the task's "
        "winner (highest median). "
        "evals/CPU-s: simulations per CPU-second of the task's runs, everything counted "
        "(simulation, variation, logs, checkpoints).",
        "",
        "| task | " + " | ".join(opts) + " | winner | evals/CPU-s |",
        "|---|" + "---|" * len(opts) + "---|---:|",
    ]
    for t in tasks:
        row = []
        for o in opts:
            if (t, o) not in stats:
                row.append("-")
                continue
            med, q1, q3, n = stats[(t, o)]
            text = f"{_fmt(med)} [{_fmt(q1)}, {_fmt(q3)}]" + (f" ({n})" if n < seeds else "")
            row.append(f"**{text}**" if o in s["winners"].get(t, []) else text)
        win = " = ".join(s["winners"].get(t, [])) or "-"
        lines.append(
            f"| {t} | " + " | ".join(row) + f" | {win} | {_fmt(s['evals_per_cpu_s'][t])} |"
        )
    lines += [
        "",
        "Normalised score of an optimiser on a task: (its median - random search's median) / "
        "(the best score any run found - random search's median): 0 is random search, 1 the best "
        "known; averaged over the tasks where it is defined.",
        "",
        "| optimiser | mean normalised | median normalised | tasks won | runs | CPU h |",
        "|---|---:|---:|---:|---:|---:|",
    ]
    for o in opts:
        v = np.array([s["norm"][(t, o)] for t in tasks if (t, o) in s["norm"]], dtype=float)
        v = v[np.isfinite(v)]
        won = sum(o in w for w in s["winners"].values())
        mine = [c for c in cells if c["optimizer"] == o]
        cpu = sum(c["cpu_seconds"] for c in mine) / 3600
        mean = _fmt(float(v.mean())) if v.size else "-"
        median = _fmt(float(np.median(v))) if v.size else "-"
        lines.append(f"| {o} | {mean} | {median} | {won} | {len(mine)} | {cpu:.2f} |")
    if figures is not None:
        figures.mkdir(parents=True, exist_ok=True)
        draw_curves(s, cells, plan, figures / "leaderboard_curves.png")
        draw_gallery(s, cells, plan, figures / "leaderboard_gallery.png")
    return "\n".join(lines)


def commands_table(out: Path, reference: Path | None = None) -> str:
    """The optimisers of a leaderboard: name, search, command (for the documentation)."""
    plans = [
        p for p in (read_plan(Path(f)) for f in [*([reference] if reference else []), out]) if p
    ]
    lines = ["| optimiser | search | command |", "|---|---|---|"]
    seen = set()
    for p in plans:
        for name, o in p["optimizers"].items():
            if name in seen:
                continue
            seen.add(name)
            search = o["search"].format(pop=p["pop"]) if o["search"] else "(user's)"
            lines.append(f"| {name} | {search} | `{o['command']}` |")
    return "\n".join(lines)


def _curve_on(grid: np.ndarray, curve: list[list[float]]) -> np.ndarray:
    """A run's best so far at each number of simulations of ``grid`` (NaN before its first row)."""
    evals = np.array([p[0] for p in curve], dtype=float)
    best = np.array([p[1] for p in curve], dtype=float)
    idx = np.searchsorted(evals, grid, side="right") - 1
    return np.where(idx >= 0, best[np.clip(idx, 0, None)], np.nan)


def draw_curves(
    s: dict[str, Any], cells: list[dict[str, Any]], plan: dict[str, Any], path: Path
) -> None:
    """Median best-so-far over simulations, one panel per task, and the mean normalised curve first."""
    from softgym.render.figures import pyplot

    plt = pyplot()
    grid = np.linspace(0, plan["evals"], 65)
    tasks, opts = s["tasks"], list(s["optimizers"])
    cols = 6
    rows = -(-(len(tasks) + 1) // cols)
    fig, axes = plt.subplots(rows, cols, figsize=(2.6 * cols, 2.1 * rows), squeeze=False)
    colors = plt.get_cmap("tab10")
    flat = list(axes.ravel())
    for ax in flat:
        ax.axis("off")
    normalised: dict[str, list[np.ndarray]] = {o: [] for o in opts}
    handles: dict[str, Any] = {}
    for ax, t in zip(flat[1:], tasks):
        ax.axis("on")
        base = s["stats"].get((t, "random"), (math.nan,))[0]
        span = s["best_known"][t] - base
        for k, o in enumerate(opts):
            runs = [
                _curve_on(grid, c["curve"]) for c in cells if c["task"] == t and c["optimizer"] == o
            ]
            if not runs:
                continue
            with np.errstate(all="ignore"), _quiet():
                med = np.nanmedian(np.array(runs), axis=0)
            handles[o] = ax.plot(grid, med, color=colors(k % 10), lw=1.2)[0]
            if span > 0:
                normalised[o].append((med - base) / span)
        ax.set_title(t, fontsize=8)
        ax.tick_params(labelsize=6)
    ax = flat[0]
    ax.axis("on")
    for k, o in enumerate(opts):
        if normalised[o]:
            with np.errstate(all="ignore"), _quiet():
                ax.plot(
                    grid,
                    np.nanmean(np.array(normalised[o]), axis=0),
                    color=colors(k % 10),
                    lw=1.5,
                    label=o,
                )
    ax.set_title("all tasks: mean normalised", fontsize=8)
    ax.set_xlabel("simulations", fontsize=7)
    ax.tick_params(labelsize=6)
    ax.legend(list(handles.values()), list(handles), fontsize=6, loc="lower right")
    fig.suptitle(f"best score so far (median over seeds) against simulations; {plan['seconds']:g} s each",
                 fontsize=9)  # fmt: skip
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


@contextlib.contextmanager
def _quiet():
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        yield


def _frame(design: Any, task: str, seconds: float, renderer: Any) -> np.ndarray:
    """``design`` in ``task``'s world after ``seconds`` (scripts/task_gallery.py's view)."""
    from softgym.engine import Simulation
    from softgym.render import render_in_world

    world = get_task(task)
    terrain = world.terrain_for(design.shape)
    sim = Simulation([design], config=world.config(), terrain=terrain, n_threads=THREADS)
    sim.advance(seconds)
    return render_in_world(sim, design, terrain, renderer)


def draw_gallery(
    s: dict[str, Any], cells: list[dict[str, Any]], plan: dict[str, Any], path: Path
) -> None:
    """Each task's best robot found, at the end of its episode in the task's world."""
    from softgym.design import RobotDesign
    from softgym.render import VoxelRenderer
    from softgym.render.figures import pyplot

    plt = pyplot()
    best = {}
    for c in cells:
        if c["design"] is not None and (
            c["task"] not in best or c["best_score"] > best[c["task"]]["best_score"]
        ):
            best[c["task"]] = c
    tasks = [t for t in s["tasks"] if t in best]
    if not tasks:
        return
    cols = min(6, len(tasks))
    rows = -(-len(tasks) // cols)
    renderer = VoxelRenderer(320, 240, pixels_per_voxel=9.0)
    fig, axes = plt.subplots(rows, cols, figsize=(2.7 * cols, 2.3 * rows), squeeze=False)
    for ax in axes.ravel():
        ax.axis("off")
    for ax, t in zip(axes.ravel(), tasks):
        c = best[t]
        ax.imshow(_frame(RobotDesign.from_dict(c["design"]), t, plan["seconds"], renderer))
        ax.set_title(
            f"{t}: {_fmt(c['best_score'])}\n{c['optimizer']}, seed {c['seed']}", fontsize=7
        )
    fig.tight_layout()
    fig.savefig(path, dpi=100, bbox_inches="tight")
    plt.close(fig)


def write_doc(doc: Path, text: str) -> None:
    """Replace the block between the leaderboard markers of ``doc`` with ``text``."""
    page = doc.read_text()
    if _DOC_START not in page or _DOC_END not in page:
        raise InvalidParameterError(f"--doc {doc}: no {_DOC_START} ... {_DOC_END} block to replace")
    head, rest = page.split(_DOC_START, 1)
    _, tail = rest.split(_DOC_END, 1)
    atomic_write_text(doc, f"{head}{_DOC_START}\n{text}\n{_DOC_END}{tail}")


# ---------------------------------------------------------------------- the command line
def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "data" / "leaderboard",
                    help="the leaderboard folder: plan.json, runs/ (run folders), cells/ (records)")  # fmt: skip
    ap.add_argument("--tasks", nargs="+", metavar="TASK",
                    help="tasks of this launch (default: every registered task, read now; with "
                    "--reference, its tasks)")  # fmt: skip
    ap.add_argument(
        "--optimizers",
        nargs="+",
        metavar="NAME",
        help=f"reference optimisers of this launch (default: all, {', '.join(REFERENCES)})",
    )
    ap.add_argument("--optimizer", action="append", metavar="NAME=COMMAND",
                    help="run your own optimiser instead of the references: a command line with "
                    f"placeholders {{{'}, {'.join(PLACEHOLDERS)}}} or py:MODULE:FACTORY (repeatable)")  # fmt: skip
    ap.add_argument("--reference", type=Path, metavar="DIR",
                    help="a leaderboard whose budget, seeds and tasks this launch takes and whose "
                    "rows the tables show beside")  # fmt: skip
    ap.add_argument("--evals", type=int, help=f"simulations per run (default {DEFAULTS['evals']})")
    ap.add_argument("--pop", type=int, help=f"robots a generation (default {DEFAULTS['pop']})")
    ap.add_argument(
        "--seconds", type=float, help=f"simulated seconds a robot (default {DEFAULTS['seconds']})"
    )
    ap.add_argument("--seeds", type=int, help=f"seeds 1..N (default {DEFAULTS['seeds']})")
    ap.add_argument(
        "--plan", action="store_true", help="print the plan and its CPU estimate, run nothing"
    )
    ap.add_argument(
        "--report", action="store_true", help="print the tables of the finished runs, run nothing"
    )
    ap.add_argument(
        "--doc", type=Path, help="with --report: rewrite the leaderboard block of this page"
    )
    ap.add_argument("--figures", type=Path, help="with --report: write the curves and gallery here")
    args = ap.parse_args(argv)
    try:
        if args.report:
            text = report(args.out, args.reference, args.figures)
            if args.doc is not None:
                write_doc(args.doc, commands_table(args.out, args.reference) + "\n\n" + text)
            print(text)
            return 0
        return run(args)
    except (SoftGymError, OSError) as exc:
        print(f"leaderboard: {' '.join(str(exc).split())}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
