"""The commands that drive a resumable run folder: ``evolve``, ``qd`` and ``poet``.

They share one skeleton: :func:`add_run_flags` (``--out``, ``--resume``,
``--dask``, ``--workers``, ``--threads``, ``--no-figures``, and the budget:
``--max-evals``, ``--max-robot-seconds``, ``--max-wall-seconds``, ``--target-score``),
:func:`build_run` (a run from the flags: the recorded config under ``--resume``, the
budget, the Dask client, the resume command) and :func:`run_command` (SIGTERM as
Ctrl-C, one interrupt message, the JSON summary with the budget that stopped the run).
"""

from __future__ import annotations

import argparse
import contextlib
import json
import logging
import shlex
import signal
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from evolvers.drivers.budget import BUDGET_FLAGS, Budget
from evolvers.drivers.registry import BACKENDS, PYMOO_ALGORITHMS
from evolvers.evaluation.experiments import CONTROLLERS, SELECTIONS, Experiment, get_experiment
from evolvers.recording.recorder import RunInterrupted, read_run_config
from softgym.exceptions import CheckpointError, InvalidParameterError, SoftGymError
from softgym.validate import threads as threads_check
from softgym_cli.flags import extra_hint, options_after, subcommands

__all__ = [
    "add_controller_flags",
    "add_evolve_parser",
    "add_poet_parser",
    "add_qd_parser",
    "add_run_flags",
    "build_run",
    "check_run_flags",
    "check_threads",
    "run_budget",
    "controller_overrides",
    "load_body",
    "quiet_dask",
    "run_command",
]

#: What builds a run: ``make(args, cfg) -> (run class, experiment, keywords)``.
Maker = Callable[[argparse.Namespace, dict[str, Any] | None], tuple[type, Experiment, dict[str, Any]]]

_DASK_HELP = ('evaluate on Dask: a LocalCluster or an existing scheduler (the distributed '
              'extra: pip install "softgym[distributed]", or pip install -e ".[distributed]" '
              'in a checkout; default: local simulations, no Dask)')  # fmt: skip


def add_run_flags(p: argparse.ArgumentParser, out: str, gif: bool = True) -> None:
    """The flags every resumable run command takes (``--quiet`` and ``-v`` are global)."""
    p.add_argument("--out", default=out, help="run folder")
    p.add_argument("--resume", action="store_true",
                   help="continue the run folder's last checkpoint with its recorded settings "
                   "(a differing flag is an error; a folder without a run is one too)")  # fmt: skip
    p.add_argument("--dask", metavar="local|tcp://ADDRESS", help=_DASK_HELP)
    p.add_argument("--workers", type=int, default=2, help="LocalCluster workers (--dask local)")
    p.add_argument("--threads", type=int,
                   help="OpenMP threads of local simulations (default: all usable CPUs)")  # fmt: skip
    p.add_argument("--no-figures", action="store_true", help="write no figures at the end")
    budget = p.add_argument_group(
        "budget", "the run stops after the generation at which the first of these (or its "
        "generations) is reached; every count goes on across --resume, where a flag not "
        "typed keeps the recorded limit and a larger one continues a stopped run")
    budget.add_argument("--max-evals", metavar="N",
                        help="simulations (phenotypes read from the run's cache are not counted; "
                        "default: no limit)")  # fmt: skip
    budget.add_argument("--max-robot-seconds", metavar="S",
                        help="simulated seconds summed over the simulated robots (default: no limit)")
    budget.add_argument("--max-wall-seconds", metavar="S",
                        help="wall-clock seconds of the run, every sitting summed (not "
                        "reproducible, unlike the others; default: no limit)")  # fmt: skip
    budget.add_argument("--target-score", metavar="X",
                        help="the best score found (the fitness; qd: the archive's best; poet: "
                        "the best pair's) reaches X (<= X for a minimised fitness; a negative X "
                        "with an exponent as --target-score=-1e3; default: none)")  # fmt: skip
    if gif:
        p.add_argument("--no-gif", action="store_true", help="no GIF of the best robot")


def add_controller_flags(p: argparse.ArgumentParser) -> None:
    """``--controller``, ``--hidden``, ``--signals``, ``--control-dt``, ``--body`` (evolve and qd)."""
    p.add_argument("--controller", metavar="{" + ",".join(CONTROLLERS) + "}",
                   help="the robots' controller: the open-loop sinusoid, or a network "
                   "(central: one per robot; distributed: one per voxel, any body) whose "
                   "weights evolve with the body (default: sinusoid)")  # fmt: skip
    p.add_argument("--hidden", type=int, help="hidden units of the network (default: 8)")
    p.add_argument("--signals", type=int,
                   help="values a distributed network's voxel sends each neighbour (default: 1)")  # fmt: skip
    p.add_argument("--control-dt", type=float, metavar="S",
                   help="seconds between the network's control steps (default: 0.05)")  # fmt: skip
    p.add_argument("--body", metavar="FILE.json|walker",
                   help="a fixed body (a design file, or walker: softgym's hand-made 6x6x6 "
                   "walker): only the controller / network evolves; --shape defaults to its grid")  # fmt: skip


def load_body(spec: str) -> tuple[dict[str, Any], tuple[int, int, int]]:
    """A ``--body`` as a design dict and its grid's shape: ``walker`` or a design file
    (JSON, .vxa), its brain dropped.

    Raises
    ------
    InvalidParameterError
        Naming the file, when it does not load as a robot design.
    """
    from softgym.design import default_walker

    if spec == "walker":
        design = default_walker()
    else:
        from softgym_cli.commands import _load_design

        try:
            design = _load_design(Path(spec))
        except (SoftGymError, OSError, KeyError, TypeError, ValueError) as exc:
            message = " ".join(str(exc).split()) or type(exc).__name__
            raise InvalidParameterError(
                f"--body {spec}: not a robot design file ({message})"
            ) from None
    return design.replace(brain=None).to_dict(), tuple(int(n) for n in design.grid.shape)


def controller_overrides(args: argparse.Namespace, exp: Experiment | None) -> dict[str, Any]:
    """The typed controller flags as :class:`Experiment` overrides (checked before any file is written).

    ``exp``: the experiment they change (its controller counts when ``--controller``
    is not typed). A fixed body sets the grid too unless ``--shape`` is typed.

    Raises
    ------
    InvalidParameterError
        An unknown controller, ``--signals`` without a distributed network, ``--hidden``
        or ``--control-dt`` without a network, a body file that does not load.
    """
    out: dict[str, Any] = {}
    if args.controller is not None:
        if args.controller not in CONTROLLERS:
            raise InvalidParameterError(
                f"--controller must be one of {', '.join(CONTROLLERS)}, got {args.controller!r}"
            )
        out["controller"] = args.controller
    controller = out.get("controller", exp.controller if exp is not None else "sinusoid")
    if args.signals is not None:
        if controller != "distributed":
            raise InvalidParameterError(
                f"--signals is for --controller distributed (a {controller} controller sends "
                "no signals)"
            )
        out["signals"] = args.signals
    for dest, flag in (("hidden", "--hidden"), ("control_dt", "--control-dt")):
        if getattr(args, dest) is not None:
            if controller == "sinusoid":
                raise InvalidParameterError(
                    f"{flag} sizes a network controller: add --controller central or distributed"
                )
            out[dest] = getattr(args, dest)
    if args.body is not None:
        out["body"], grid_shape = load_body(args.body)
        if args.shape is None:
            out["shape"] = grid_shape
    return out


def quiet_dask(verbose: int) -> None:
    """Dask's own INFO lines only with -v."""
    level = logging.INFO if verbose else logging.WARNING
    for name in ("distributed", "distributed.scheduler", "distributed.nanny",
                 "distributed.worker", "distributed.core", "distributed.http.proxy"):  # fmt: skip
        logging.getLogger(name).setLevel(level)


def recorded_config(args: argparse.Namespace) -> dict[str, Any] | None:
    """The run folder's config.json under ``--resume`` (None without it).

    Raises
    ------
    CheckpointError
        ``--resume`` on a folder that holds no run (no config.json): nothing
        to continue, and starting a new run instead would surprise.
    """
    if not args.resume:
        return None
    if not (Path(args.out) / "config.json").is_file():
        raise CheckpointError(
            f"{args.out} holds no run to resume (no config.json); drop --resume to start one"
        )
    return read_run_config(args.out)


def run_budget(args: argparse.Namespace, cfg: dict[str, Any] | None) -> Budget:
    """The run's :class:`~evolvers.drivers.budget.Budget`: each typed budget flag, else (under
    ``--resume``) the limit config.json records.

    Raises
    ------
    InvalidParameterError
        A typed limit out of its range (naming the flag and the range).
    CheckpointError
        A recorded budget that is not one (naming the file).
    """
    recorded: dict[str, Any] = {}
    if cfg is not None and cfg.get("budget"):
        try:
            recorded = Budget.from_dict(cfg["budget"]).to_dict()
        except InvalidParameterError as exc:
            raise CheckpointError(f"{Path(args.out) / 'config.json'}: 'budget' is invalid ({exc})") from None
    typed = {k: _number(getattr(args, k)) for k in BUDGET_FLAGS if getattr(args, k, None) is not None}
    return Budget.from_dict({**recorded, **typed})


def _number(text: str) -> Any:
    """A budget flag's value as a number (an int when it reads as one, ``1e4`` included);
    text that reads as none stays text, for :class:`Budget` to refuse in one line naming
    the flag.
    """
    try:
        return int(text)
    except ValueError:
        pass
    try:
        value = float(text)
    except ValueError:
        return text
    return int(value) if value.is_integer() else value


def check_threads(threads: Any) -> None:
    """``--threads``: None (all usable CPUs) or an integer in 1..MAX_THREADS
    (:func:`softgym.validate.threads`).

    Raises
    ------
    InvalidParameterError
        Naming the flag, before anything is written.
    """
    threads_check(threads, "--threads", absent="left out")


def settling_seconds(experiment: Experiment) -> float:
    """The seconds a robot of ``experiment`` settles before it is measured."""
    return float(experiment.make_task().config().init_time)


def check_run_flags(args: argparse.Namespace, experiment: Experiment) -> None:
    """What a run's flags describe, checked before anything is created: the threads, the
    robot grid, the simulated seconds (typed, they must outlast the settling time, which no
    fitness counts).

    Raises
    ------
    InvalidParameterError, InvalidDesignError
        One line naming the flag.
    """
    from softgym.design.robot import check_grid_shape

    check_threads(args.threads)
    check_grid_shape(experiment.shape, "--shape")
    settle = settling_seconds(experiment)
    if getattr(args, "seconds", None) is not None and not experiment.seconds > settle:
        raise InvalidParameterError(
            f"--seconds must be more than the {settle:g} s settling time (a robot is measured "
            f"only after it; every fitness would be ~0), got {experiment.seconds:g}"
        )


def build_run(args: argparse.Namespace, stack: contextlib.ExitStack, make: Maker) -> Any:
    """The run a command's flags describe.

    ``make(args, cfg)`` names the run class, its experiment and its own
    keywords (``cfg``: the recorded config under ``--resume``, else None);
    the rest is the same for every command: the budget (:func:`run_budget`,
    checked before anything starts), the Dask client (kept open in ``stack``) as
    a ``DaskBatchFn``, threads, figures, GIF, progress, and the shell command
    that resumes.
    """
    cfg = recorded_config(args)
    budget = run_budget(args, cfg)
    run_cls, experiment, kw = make(args, cfg)
    check_run_flags(args, experiment)  # all of it before a folder, a bar or a Dask cluster
    kw["budget"] = budget
    if args.dask:
        from evolvers.evaluation.distributed import DaskBatchFn, dask_client

        quiet_dask(args.verbose)
        client = stack.enter_context(dask_client(args.dask, n_workers=args.workers))
        quiet_dask(args.verbose)
        kw["batch_fn"] = DaskBatchFn(client)
    if hasattr(args, "no_gif"):
        kw["gif"] = not args.no_gif
    run = run_cls(experiment, args.out, n_threads=args.threads, figures=not args.no_figures,
                  progress=not args.quiet, **kw)  # fmt: skip
    run.resume_command = f"softgym {args.command} --out {shlex.quote(str(args.out))} --resume"
    return run


def _raise_keyboard_interrupt(signum, frame):  # SIGTERM: stop like Ctrl-C, checkpoint intact
    raise KeyboardInterrupt


def run_command(args: argparse.Namespace, unit: str, make: Maker,
                summary: Callable[[Any, Any], dict[str, Any]]) -> int:  # fmt: skip
    """Build the run of the flags (:func:`build_run`), run it, print its JSON summary.

    Every long command runs this way: SIGTERM acts as Ctrl-C, log lines go
    around tqdm bars, and the Dask client lives as long as the run.
    ``summary(run, result)`` gives the command's own fields (the wall time,
    run folder and figures are added). An interrupted run prints one
    message, where it is checkpointed (``unit``: "generation", "iteration")
    and the command that resumes it, and returns 130.
    """
    from tqdm.contrib.logging import logging_redirect_tqdm

    t0 = time.perf_counter()
    previous = signal.signal(signal.SIGTERM, _raise_keyboard_interrupt)
    try:
        with contextlib.ExitStack() as stack:
            stack.enter_context(logging_redirect_tqdm())
            run = build_run(args, stack, make)
            result = run.run(resume=args.resume)
    except RunInterrupted as exc:
        where = (f"{unit} {exc.generation} is checkpointed in {exc.checkpoint}"
                 if exc.checkpoint else f"no {unit} had finished")  # fmt: skip
        print(f"\nsoftgym {args.command}: interrupted; {where}\nresume with: {exc.resume}",
              file=sys.stderr)  # fmt: skip
        return 130
    except KeyboardInterrupt:
        print(f"\nsoftgym {args.command}: interrupted before the run started", file=sys.stderr)
        return 130
    finally:
        signal.signal(signal.SIGTERM, previous)
    figures = run.out / "figures"
    drawn = sorted(str(p) for p in figures.glob("*")) if figures.exists() else []
    if args.no_figures and drawn:  # an earlier sitting's figures, left as they were
        print(f"softgym {args.command}: --no-figures: {figures} holds figures of an earlier "
              "sitting, not redrawn (drop --no-figures to draw them for this one)",
              file=sys.stderr)  # fmt: skip
        drawn = []
    record = run.budget_record()
    out = {**summary(run, result), "stopped_by": run.stopped_by,
           "budget": {"limits": record["limits"], "used": record["used"]},
           "wall_seconds": round(time.perf_counter() - t0, 2),
           "out": str(run.out),
           "figures": drawn}  # fmt: skip
    print(json.dumps(out, indent=2))
    return 0


# ---------------------------------------------------------------------- evolve
#: evolve flags that define a run (what --resume reads from the run folder).
_RUN_FLAGS = {
    "experiment": "--experiment", "pop": "--pop", "seed": "--seed", "backend": "--backend",
    "algorithm": "--algorithm", "task": "--task", "seconds": "--seconds", "shape": "--shape",
    "selection": "--selection", "controller": "--controller", "hidden": "--hidden",
    "signals": "--signals", "control_dt": "--control-dt", "body": "--body",
}  # fmt: skip


def explicit_flags(parser: argparse.ArgumentParser, argv: list[str]) -> set[str]:
    """Dests of the options typed on the command line (not left at their defaults)."""
    found = set()
    for action in parser._actions:  # argparse has no public API for this
        for opt in action.option_strings:
            if any(a == opt or a.startswith(opt + "=") for a in argv):
                found.add(action.dest)
    return found


def _resumed_settings(args: argparse.Namespace, cfg: dict) -> dict:
    """The run folder's settings; a differing explicit flag is a CheckpointError naming it."""
    exp = Experiment.from_dict(cfg["experiment"])
    recorded = {
        "experiment": exp.name, "pop": exp.pop_size, "seed": cfg.get("seed"),
        "backend": cfg.get("backend"), "algorithm": cfg.get("algorithm"),
        "seconds": exp.seconds, "shape": list(exp.shape), "selection": exp.selection,
        "controller": exp.controller, "hidden": exp.hidden, "signals": exp.signals,
        "control_dt": exp.control_dt,
    }  # fmt: skip
    for dest in sorted(getattr(args, "explicit", set()) & set(_RUN_FLAGS)):
        given = getattr(args, dest)
        if dest == "task":
            same = exp.replace(task=given).to_dict()["task"] == exp.to_dict()["task"]
            shown = "its own task"
        elif dest == "body":
            same = exp.body is not None and load_body(given)[0] == exp.body
            shown = "its own body" if exp.body is not None else "no fixed body"
        elif dest == "algorithm" and recorded["backend"] != "pymoo":
            continue  # --algorithm only matters to pymoo
        else:
            want = list(given) if dest == "shape" else given
            same = want == recorded[dest] or (
                dest in ("seconds", "control_dt") and float(want) == recorded[dest]
            )
            rec = recorded[dest]
            shown = " ".join(map(str, rec)) if dest == "shape" else rec
        if not same:
            flag = _RUN_FLAGS[dest]
            given_s = " ".join(map(str, given)) if dest == "shape" else given
            raise CheckpointError(
                f"{args.out} was started with {flag} {shown}, not {given_s}; "
                f"drop {flag} to resume it, or use another --out"
            )
    return {"experiment": exp, "seed": int(cfg["seed"]), "backend": cfg["backend"],
            "algorithm": cfg.get("algorithm", args.algorithm),
            "generations": args.generations if "generations" in getattr(args, "explicit", set())
            else int(cfg.get("generations", args.generations))}  # fmt: skip


def _evolve_run(args: argparse.Namespace, cfg: dict | None) -> tuple[type, Experiment, dict]:
    if cfg is not None:
        st = _resumed_settings(args, cfg)
    else:
        overrides = {"pop_size": args.pop, "seconds": args.seconds, "selection": args.selection,
                     "task": args.task, "shape": None if args.shape is None else tuple(args.shape)}  # fmt: skip
        overrides = {k: v for k, v in overrides.items() if v is not None}
        overrides.update(controller_overrides(args, get_experiment(args.experiment)))
        st = {"experiment": get_experiment(args.experiment, **overrides), "seed": args.seed,
              "backend": args.backend, "algorithm": args.algorithm,
              "generations": args.generations}  # fmt: skip
    kw: dict[str, Any] = {"seed": st["seed"], "generations": st["generations"]}
    from evolvers.drivers.registry import driver_class

    if not BACKENDS[st["backend"]].selects and args.selection is not None:
        why = (f"pymoo's {st['algorithm']} does its own survival" if st["backend"] == "pymoo"
               else f"{BACKENDS[st['backend']].summary}")  # fmt: skip
        print(f"softgym evolve: warning: --selection {args.selection} is ignored with "
              f"--backend {st['backend']} ({why})", file=sys.stderr)  # fmt: skip
    if st["backend"] == "pymoo":
        kw["algorithm"] = st["algorithm"]
    return driver_class(st["backend"]), st["experiment"], kw


def _evolve_summary(run: Any, _: Any) -> dict[str, Any]:
    best = run.hall_of_fame[0]["individual"] if run.hall_of_fame else None
    return {
        "experiment": run.experiment.name,
        "backend": run.backend,
        "controller": run.experiment.controller,
        "fixed_body": run.experiment.body is not None,
        "generations": run.generation,
        "evaluations": run.evaluations_total,
        "best": None if best is None else best["objectives"].get(run.experiment.fitness.name),
        "best_id": None if best is None else best["id"],
    }


def cmd_evolve(args: argparse.Namespace) -> int:
    """``softgym evolve``."""
    return run_command(args, "generation", _evolve_run, _evolve_summary)


def add_evolve_parser(sub: Any) -> argparse.ArgumentParser:
    """``softgym evolve ...``; returns its parser (for :func:`explicit_flags`)."""
    p = sub.add_parser("evolve", help="evolve robots with one of the seed's experiments")
    p.add_argument("--experiment", default="controller-tournament",
                   help="experiment name (softgym experiments lists them)")  # fmt: skip
    p.add_argument("--generations", type=int, default=10, help="generations after generation 0")
    p.add_argument("--pop", type=int, default=15, help="population size")
    p.add_argument("--seed", type=int, default=0, help="seed of the run's random generator")
    add_run_flags(p, "runs/evolve")
    p.add_argument("--backend", choices=list(BACKENDS), default="native",
                   help="the search loop: " + "; ".join(f"{k}: {b.summary}"
                                                       for k, b in BACKENDS.items()))  # fmt: skip
    p.add_argument("--algorithm", choices=list(PYMOO_ALGORITHMS),
                   default="nsga2",
                   help="pymoo algorithm (--backend pymoo; ga optimises the first objective alone; "
                   "cmaes: pymoo's CMA-ES over the design vector, a fixed-topology CPPN's "
                   "weights and the controller genes, or over the network's weights on a "
                   "fixed --body)")  # fmt: skip
    p.add_argument("--task", metavar="TASK[:ARG=V,...]|FILE.json",
                   help="the world (default: the experiment's): a task name or a terrain JSON file")  # fmt: skip
    p.add_argument("--seconds", type=float,
                   help="simulated seconds per evaluation (default: the experiment's, 5)")  # fmt: skip
    p.add_argument("--shape", type=int, nargs=3, metavar=("NX", "NY", "NZ"),
                   help="robot grid (default: the experiment's, 6 6 6)")  # fmt: skip
    p.add_argument("--selection",
                   choices=list(SELECTIONS),
                   help="override the experiment's selection (native and DEAP backends; "
                   "default: the experiment's)")  # fmt: skip
    add_controller_flags(p)
    p.set_defaults(func=cmd_evolve)
    return p


# ---------------------------------------------------------------------- qd
def _typed(args: argparse.Namespace, names: tuple[str, ...]) -> dict[str, Any]:
    """The flags of ``names`` typed on the command line (lists as tuples)."""
    vals = {k: getattr(args, k) for k in names}
    return {k: tuple(v) if isinstance(v, list) else v for k, v in vals.items() if v is not None}


def _sized(exp: Experiment, args: argparse.Namespace, **more: Any) -> Experiment:
    """``exp`` under the typed ``--seconds`` and ``--shape`` (and ``more``)."""
    sizes = {"seconds": args.seconds, "shape": None if args.shape is None else tuple(args.shape),
             **more}  # fmt: skip
    return exp.replace(**{k: v for k, v in sizes.items() if v is not None})


def _seed_and_length(args: argparse.Namespace, cfg: dict | None, length: int | None,
                     default: int) -> tuple[int, int]:  # fmt: skip
    """Seed and generations (iterations): the typed flag, else the recorded value, else the default."""
    seed = args.seed if args.seed is not None else int(cfg["seed"]) if cfg else 0
    if length is None:
        length = int(cfg.get("generations", default)) if cfg else default
    return seed, length


def _qd_run(args: argparse.Namespace, cfg: dict | None) -> tuple[type, Experiment, dict]:
    """A QDRun's settings; under --resume the folder's, a mismatch with a typed flag named by QDRun.run."""
    from evolvers.drivers.qd import QDConfig, QDRun

    if cfg is not None and args.experiment is None:
        exp = Experiment.from_dict(cfg["experiment"])
    else:
        exp = get_experiment(args.experiment or "basic", pop_size=16)
    exp = _sized(exp, args, pop_size=args.batch, task=args.task)
    control = controller_overrides(args, exp)
    if control:
        exp = exp.replace(**control)
    qd = QDConfig.from_dict(cfg["qd"]) if cfg is not None and "qd" in cfg else QDConfig()
    typed = _typed(args, ("descriptors", "cells", "archive", "objective"))
    if typed:
        base = qd.to_dict()
        if "cells" not in typed and ("descriptors" in typed or "archive" in typed):
            base["cells"] = base["cells"][:1]  # one value for every descriptor
        qd = QDConfig.from_dict({**base, **typed})
    seed, gens = _seed_and_length(args, cfg, args.generations, 20)
    return QDRun, exp, {"seed": seed, "generations": gens, "config": qd}


def _qd_summary(run: Any, _: Any) -> dict[str, Any]:
    return {
        "experiment": run.experiment.name,
        "controller": run.experiment.controller,
        "archive": run.config.to_dict(),
        "generations": run.generation,
        "evaluations": run.evaluations_total,
        **run.stats(),
        "objective": run.objective,
        "export": f"softgym qd export {shlex.quote(str(run.out))}",
    }


def cmd_qd(args: argparse.Namespace) -> int:
    """``softgym qd [run]`` and ``softgym qd export``."""
    if getattr(args, "qd_command", None) == "export":
        from evolvers.drivers.qd import export_elites

        index = export_elites(args.run, args.export_out, top=args.top)
        n = len(json.loads(index.read_text())["elites"])
        print(f"wrote {n} elites (design .json and .vxa) and {index}")
        return 0
    return run_command(args, "generation", _qd_run, _qd_summary)


def add_qd_parser(sub: Any) -> None:
    """``softgym qd [run] ...`` and ``softgym qd export RUN``."""
    p = sub.add_parser(
        "qd",
        help="quality-diversity: a MAP-Elites archive of robots (pyribs); 'qd export RUN'",
        description="Fill a MAP-Elites archive (pyribs) with robots: each cell keeps the best "
        "robot of its body descriptors (default: stiff x filled fraction, 128 x 128 cells, "
        "Mouret & Clune 2015). A resumable run folder with log (QD-score, coverage, best), "
        "checkpoints, heatmap and best designs; 'softgym qd export RUN' writes the elites as "
        f"design files. Needs the qd extra: {extra_hint('qd')}.",
    )

    def options(p: argparse.ArgumentParser) -> None:
        p.add_argument("--experiment", help="experiment whose task, rules and genes are used "
                       "(default: basic, CPPN bodies; softgym experiments lists them)")  # fmt: skip
        p.add_argument("--generations", type=int, help="batches after the first (default: 20)")
        p.add_argument("--batch", type=int, help="robots per generation (default: 16)")
        p.add_argument("--seed", type=int, help="seed of the run (default: 0)")
        add_run_flags(p, "runs/qd")
        p.add_argument("--descriptors", nargs="+", metavar="NAME",
                       help="body descriptors: stiff filled muscle height elongation "
                       "(default: stiff filled)")  # fmt: skip
        p.add_argument("--cells", type=int, nargs="+",
                       help="grid: cells per descriptor (one value for all; default: 128); "
                       "cvt: the number of centroids")  # fmt: skip
        p.add_argument("--archive", choices=["grid", "cvt"],
                       help="GridArchive or CVTArchive (default: grid)")  # fmt: skip
        p.add_argument("--objective", choices=["norm_final_dist", "max_xy_dist", "score"],
                       help="maximised metric (score: the task's own measure; default: the "
                       "experiment's fitness)")  # fmt: skip
        p.add_argument("--task", metavar="TASK[:ARG=V,...]|FILE.json",
                       help="the world (default: the experiment's)")  # fmt: skip
        p.add_argument("--seconds", type=float, help="simulated seconds per evaluation (default: 5)")
        p.add_argument("--shape", type=int, nargs=3, metavar=("NX", "NY", "NZ"),
                       help="robot grid (default: 6 6 6)")  # fmt: skip
        add_controller_flags(p)

    options(p)
    ss = subcommands(p, "qd_command", default="run", default_help="run or resume (the "
                     "default; the options go before or after it)", command="qd")  # fmt: skip
    options_after(p, ss.choices["run"], options)
    r = ss.add_parser("export", help="write a QD run's elites as design files (.json, .vxa)")
    r.add_argument("run", help="a softgym qd run folder")
    r.add_argument("--out", dest="export_out", help="folder (default: RUN/elites)")
    r.add_argument("--top", type=int, help="only the best TOP elites (default: all)")
    p.set_defaults(func=cmd_qd)


# ---------------------------------------------------------------------- poet
#: poet flags that map onto PoetConfig fields (None: not typed; the config's default applies).
_POET_FLAGS = ("reproduce_every", "transfer_every", "max_children", "max_admitted", "max_active",
               "mc_low", "mc_high", "repro_threshold", "solved_threshold", "generator",
               "score_cap")  # fmt: skip


def _poet_run(args: argparse.Namespace, cfg: dict | None) -> tuple[type, Experiment, dict]:
    """A PoetRun's settings; under --resume the folder's, a mismatch with a typed flag named by PoetRun.run."""
    from evolvers.drivers.poet import PoetConfig, PoetRun, poet_experiment
    from softgym.io import read_json

    exp = Experiment.from_dict(cfg["experiment"]) if cfg is not None else poet_experiment()
    exp = _sized(exp, args, pop_size=args.pop)
    base = dict(cfg["poet"]) if cfg is not None and "poet" in cfg else PoetConfig().to_dict()
    typed = _typed(args, _POET_FLAGS)
    if args.start_terrain is not None:
        typed["start_terrain"] = read_json(args.start_terrain)
    seed, iters = _seed_and_length(args, cfg, args.iterations, 40)
    return PoetRun, exp, {"seed": seed, "iterations": iters,
                          "config": PoetConfig.from_dict({**base, **typed})}  # fmt: skip


def _poet_summary(run: Any, pairs: Any) -> dict[str, Any]:
    return {
        "iterations": run.iteration,
        "generator": run.config.generator,
        "evaluations": run.evaluations_total,
        "annecs": run.annecs,
        "annecs_archive": run.annecs_archive,
        "pairs": len(pairs),
        "active": len(run.active()),
        "solved": sum(p.solved is not None for p in pairs),
    }


def cmd_poet(args: argparse.Namespace) -> int:
    """``softgym poet [run]`` and ``softgym poet compare``."""
    if getattr(args, "poet_command", None) == "compare":
        return _cmd_poet_compare(args)
    return run_command(args, "iteration", _poet_run, _poet_summary)


def _cmd_poet_compare(args: argparse.Namespace) -> int:
    from evolvers.drivers.poet import plot_annecs
    from softgym.render.figures import figure_path, read_log
    from softgym.validate import is_int, is_real, show

    figure_path(args.compare_out)  # a format matplotlib writes, checked before the runs are read
    groups: dict[str, list] = {}
    for d in args.runs:
        cfg = read_run_config(d)
        if "poet" not in cfg:
            raise CheckpointError(f"{d}: not a POET run folder (softgym poet)")
        generator = cfg["poet"].get("generator") if isinstance(cfg["poet"], dict) else None
        if not isinstance(generator, str):
            raise CheckpointError(f"{Path(d) / 'config.json'}: 'poet' needs the string "
                                  f"'generator', got {show(generator)}")  # fmt: skip
        rows = read_log(d)
        for n, row in enumerate(rows, 1):
            if not (is_real(row.get("annecs")) and is_int(row.get("generation"))):
                raise CheckpointError(f"{Path(d) / 'log.jsonl'}: line {n} needs a number 'annecs' "
                                      f"and an integer 'generation'")  # fmt: skip
        label = "POET" if generator == "mutate" else "random terrains (control)"
        groups.setdefault(label, []).append(rows)
    path = plot_annecs(groups, args.compare_out)
    for label, runs in groups.items():
        finals = sorted(rows[-1]["annecs"] if rows else 0 for rows in runs)
        print(f"{label}: {len(runs)} run(s), final ANNECS {finals}")
    print(path)
    return 0


def add_poet_parser(sub: Any) -> None:
    """``softgym poet [run] ...`` and ``softgym poet compare RUN...``."""
    p = sub.add_parser(
        "poet",
        help="co-evolve robots and terrains (Enhanced POET); 'poet compare RUN...'",
        description="Co-evolve terrains (a 7-gene obstacle course: fence, bumps, stairs, gap) "
        "and the robots that walk them, after Enhanced POET: active (terrain, robots) pairs, "
        "minimal criterion, PATA-EC novelty, transfers, ANNECS. A resumable run folder with "
        "one log row per iteration and figures (ANNECS, transfer heatmap, hardest solved "
        "terrains); thresholds are voxel lengths of max_xy_dist (POET's 25-340 band, 200 "
        "reproduction and 230 solved map to 3.76-13.35, 9.09 and 10).",
    )

    def options(p: argparse.ArgumentParser) -> None:
        p.add_argument("--iterations", type=int, help="iterations after the first (default: 40)")
        p.add_argument("--pop", type=int, help="robots per pair (default: 8)")
        p.add_argument("--seed", type=int, help="seed of the run (default: 0)")
        add_run_flags(p, "runs/poet", gif=False)
        p.add_argument("--generator", choices=["mutate", "random"],
                       help="candidate terrains: mutants of eligible parents or uniform draws "
                       "(the random-terrain control) (default: mutate)")  # fmt: skip
        for flag, what, default, kind in (
            ("--reproduce-every", "K: iterations between reproductions", "5", int),
            ("--transfer-every", "T: iterations between transfers", "5", int),
            ("--max-children", "candidate terrains per round", "8", int),
            ("--max-admitted", "terrains admitted per round", "1", int),
            ("--max-active", "active pairs before the oldest retire", "8", int),
            ("--mc-low", "minimal criterion, low end", "3.76", float),
            ("--mc-high", "minimal criterion, high end", "13.35", float),
            ("--repro-threshold", "score to reproduce", "9.09", float),
            ("--solved-threshold", "score that solves", "10", float),
            ("--score-cap", "scores saturate here, like a finished BipedalWalker course", "none",
             float),
        ):  # fmt: skip
            p.add_argument(flag, type=kind, help=f"{what} (default: {default})")
        p.add_argument("--start-terrain", metavar="GENOME.json",
                       help="the first pair's terrain genome (default: flat)")  # fmt: skip
        p.add_argument("--seconds", type=float, help="simulated seconds per evaluation (default: 3)")
        p.add_argument("--shape", type=int, nargs=3, metavar=("NX", "NY", "NZ"),
                       help="robot grid (default: 4 4 4)")  # fmt: skip

    options(p)
    ss = subcommands(p, "poet_command", default="run", default_help="run or resume (the "
                     "default; the options go before or after it)", command="poet")  # fmt: skip
    options_after(p, ss.choices["run"], options)
    r = ss.add_parser("compare", help="ANNECS over iterations of POET runs and controls, one figure")
    r.add_argument("runs", nargs="+", metavar="RUN", help="softgym poet run folders")
    r.add_argument("--out", dest="compare_out", default="runs/poet_annecs.png", help="figure file")
    p.set_defaults(func=cmd_poet)
