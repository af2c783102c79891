"""The ``softgym`` command line.

Subcommands
-----------
simulate
    Simulate the embedded default walker (or a design JSON) and write its
    centre-of-mass trajectory figure and a summary JSON.
evolve
    Run one of the seed study's experiments (native loop, DEAP or pymoo),
    on its task or another (``--task NAME``: any task of softgym.tasks, with
    arguments as ``gap:width=3``, or FILE.json), locally or on Dask, into a
    resumable run folder with log, checkpoints, best designs and figures.
replay
    Re-simulate the best robot of a run folder and render it (figures, GIF, MP4).
compare
    Best fitness per generation of several run folders in one figure (the
    report's Fig. 4); runs of one configuration (seeds) as a median with an
    interquartile band.
experiments
    List the named experiments.
view
    Write a self-contained interactive 3D viewer (HTML) of a run's best robot
    or of a design file.
convert
    Convert a design between JSON and ``.vxa`` (VoxCAD / evosoro).

``softgym evolve --resume`` reads the experiment and settings from the run
folder. Ctrl-C stops within a fraction of a second and prints the command that
resumes. ``-v`` shows log lines (and Dask's); ``--help`` shows every default.
study
    Run the seed report's scenarios over many seeds, each a resumable run
    folder (seeds in parallel on Dask); ``study report RUNS`` writes the
    claim-by-claim report and its figures.
qd
    Quality-diversity: a MAP-Elites archive (pyribs) of robots over body
    descriptors, a resumable run folder with QD-score and coverage per
    generation and a heatmap; ``qd export RUN`` writes the elites as designs.
poet
    Co-evolution of robots and terrains (Enhanced POET): a resumable run folder
    with terrains, score matrices, admissions, transfers and ANNECS per
    iteration, and figures; ``poet compare RUN...`` plots ANNECS of runs
    (POET against the random-terrain control).
"""

from __future__ import annotations

import argparse
import json
import logging
import shlex
import signal
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

__all__ = ["main"]

log = logging.getLogger("softgym")


def _cmd_simulate(args: argparse.Namespace) -> int:
    from softgym.design import RobotDesign, default_walker
    from softgym.engine import SimConfig, Simulation
    from softgym.metrics import norm_final_dist
    from softgym.render.figures import plot_trajectory

    robot = RobotDesign.load(args.design) if args.design else default_walker()
    cfg = SimConfig(actuation=args.actuation, trace_interval=0.05)
    sim = Simulation([robot], cfg)
    t0 = time.perf_counter()
    rollout = sim.run(args.seconds)
    wall = time.perf_counter() - t0
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    summary = {
        "seconds": args.seconds,
        "wall_seconds": wall,
        "steps": int(rollout.steps[0]),
        "dt": float(rollout.dt[0]),
        "n_voxels": int(rollout.voxel_offsets[1]),
        "voxel_steps_per_s": float(rollout.voxel_offsets[1] * rollout.steps[0] / wall),
        "norm_final_dist": float(norm_final_dist(rollout)[0]),
        "diverged": bool(rollout.diverged[0]),
    }
    (out / "summary.json").write_text(json.dumps(summary, indent=2))
    plot_trajectory(rollout.trace(0), out / "trajectory.png", voxel_size=rollout.voxel_size,
                    init_time=rollout.init_time)  # fmt: skip
    print(json.dumps(summary, indent=2))
    print(f"wrote {out / 'trajectory.png'} and {out / 'summary.json'}")
    return 0


#: evolve flags that define a run (what --resume reads from the run folder).
_RUN_FLAGS = {
    "experiment": "--experiment", "pop": "--pop", "seed": "--seed", "backend": "--backend",
    "algorithm": "--algorithm", "task": "--task", "seconds": "--seconds", "shape": "--shape",
    "selection": "--selection",
}  # fmt: skip


def _explicit_flags(parser: argparse.ArgumentParser, argv: list[str]) -> set[str]:
    """Dests of the options typed on the command line (not left at their defaults)."""
    found = set()
    for action in parser._actions:  # argparse has no public API for this
        for opt in action.option_strings:
            if any(a == opt or a.startswith(opt + "=") for a in argv):
                found.add(action.dest)
    return found


def _resumed_settings(args: argparse.Namespace, cfg: dict) -> dict:
    """The run folder's settings; a differing explicit flag is a CheckpointError naming it."""
    from evolvers.experiments import Experiment
    from softgym.exceptions import CheckpointError

    exp = Experiment.from_dict(cfg["experiment"])
    recorded = {
        "experiment": exp.name, "pop": exp.pop_size, "seed": cfg.get("seed"),
        "backend": cfg.get("backend"), "algorithm": cfg.get("algorithm"),
        "seconds": exp.seconds, "shape": list(exp.shape), "selection": exp.selection,
    }  # fmt: skip
    for dest in sorted(getattr(args, "explicit", set()) & set(_RUN_FLAGS)):
        given = getattr(args, dest)
        if dest == "task":
            same = exp.replace(task=given).to_dict()["task"] == exp.to_dict()["task"]
            shown = "its own task"
        elif dest == "algorithm" and recorded["backend"] != "pymoo":
            continue  # --algorithm only matters to pymoo
        else:
            want = list(given) if dest == "shape" else given
            same = want == recorded[dest] or (dest == "seconds" and float(want) == recorded[dest])
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


def _make_run(args: argparse.Namespace, batch_fn):
    from evolvers.experiments import get_experiment
    from evolvers.recorder import read_run_config

    if args.resume and (Path(args.out) / "config.json").is_file():
        st = _resumed_settings(args, read_run_config(args.out))
    else:
        overrides = {"pop_size": args.pop}
        if args.seconds is not None:
            overrides["seconds"] = args.seconds
        if args.shape is not None:
            overrides["shape"] = tuple(args.shape)
        if args.selection is not None:
            overrides["selection"] = args.selection
        if args.task is not None:
            overrides["task"] = args.task
        st = {"experiment": get_experiment(args.experiment, **overrides), "seed": args.seed,
              "backend": args.backend, "algorithm": args.algorithm,
              "generations": args.generations}  # fmt: skip
    extra = {}
    if st["backend"] == "deap":
        from evolvers.deap_runner import DeapRun as Run
    elif st["backend"] == "pymoo":
        from evolvers.pymoo_runner import PymooRun as Run

        extra["algorithm"] = st["algorithm"]
    else:
        from evolvers.runner import EvolutionRun as Run
    run = Run(
        st["experiment"], args.out, seed=st["seed"], generations=st["generations"],
        batch_fn=batch_fn, n_threads=args.threads, figures=not args.no_figures,
        gif=not args.no_gif, progress=not args.quiet, **extra,
    )  # fmt: skip
    run.resume_command = f"softgym evolve --out {shlex.quote(str(args.out))} --resume"
    return run


def _raise_keyboard_interrupt(signum, frame):  # SIGTERM: stop like Ctrl-C, checkpoint intact
    raise KeyboardInterrupt


def _dask_batch_fn(args: argparse.Namespace, stack):
    """The evaluation batch function of ``--dask`` (None without it); the client lives in ``stack``."""
    if not args.dask:
        return None
    from evolvers.distributed import DaskBatchFn, dask_client

    _quiet_dask(args.verbose)
    client = stack.enter_context(dask_client(args.dask, n_workers=args.workers))
    _quiet_dask(args.verbose)
    return DaskBatchFn(client)


def _quiet_dask(verbose: int) -> None:
    """Dask's own INFO lines only with -v."""
    level = logging.INFO if verbose else logging.WARNING
    for name in ("distributed", "distributed.scheduler", "distributed.nanny",
                 "distributed.worker", "distributed.core", "distributed.http.proxy"):  # fmt: skip
        logging.getLogger(name).setLevel(level)


def _interruptible(command: str, unit: str, start: Callable[[Any], Any]) -> tuple[int | None, Any]:
    """Run ``start(stack)`` the way every long command runs: SIGTERM acts as Ctrl-C, log
    lines go around tqdm bars, and ``stack`` (an ExitStack) holds what the run opens
    (a Dask client). Returns ``(None, start's result)``, or ``(130, None)`` after
    printing where an interrupted run is checkpointed (``unit``: "generation",
    "iteration") and the command that resumes it.
    """
    import contextlib

    from tqdm.contrib.logging import logging_redirect_tqdm

    from evolvers.recorder import RunInterrupted

    previous = signal.signal(signal.SIGTERM, _raise_keyboard_interrupt)
    try:
        with contextlib.ExitStack() as stack:
            stack.enter_context(logging_redirect_tqdm())
            return None, start(stack)
    except RunInterrupted as exc:
        where = (f"{unit} {exc.generation} is checkpointed in {exc.checkpoint}"
                 if exc.checkpoint else f"no {unit} had finished")  # fmt: skip
        print(f"\nsoftgym {command}: interrupted; {where}\nresume with: {exc.resume}", file=sys.stderr)
        return 130, None
    except KeyboardInterrupt:
        print(f"\nsoftgym {command}: interrupted before the run started", file=sys.stderr)
        return 130, None
    finally:
        signal.signal(signal.SIGTERM, previous)


def _cmd_evolve(args: argparse.Namespace) -> int:
    from softgym.exceptions import SoftGymError

    def start(stack):
        try:
            run = _make_run(args, _dask_batch_fn(args, stack))
            run.run(resume=args.resume)
            return run
        except SoftGymError as exc:
            print(f"softgym evolve: {exc}", file=sys.stderr)
            return None

    t0 = time.perf_counter()
    status, run = _interruptible("evolve", "generation", start)
    if status is not None:
        return status
    if run is None:
        return 2
    wall = time.perf_counter() - t0
    fit = run.experiment.fitness
    best = run.hall_of_fame[0]["individual"] if run.hall_of_fame else None
    summary = {
        "experiment": run.experiment.name,
        "backend": run.backend,
        "generations": run.generation,
        "evaluations": run.evaluations_total,
        "best": None if best is None else best["objectives"].get(fit.name),
        "best_id": None if best is None else best["id"],
        "wall_seconds": round(wall, 2),
        "out": str(run.out),
        "figures": sorted(str(p) for p in (run.out / "figures").glob("*"))
        if (run.out / "figures").exists()
        else [],
    }
    print(json.dumps(summary, indent=2))
    return 0


def _cmd_replay(args: argparse.Namespace) -> int:
    from evolvers.experiments import Experiment
    from softgym.design import RobotDesign
    from softgym.evaluate import evaluate
    from softgym.exceptions import SoftGymError
    from softgym.render.figures import (
        plot_robot,
        plot_trajectory,
        save_robot_gif,
        trace_interval_for,
    )

    run_dir = Path(args.run_dir)
    try:
        cfg = json.loads((run_dir / "config.json").read_text())
        design = RobotDesign.load(run_dir / "best_design.json")
        best = json.loads((run_dir / "best_designs.json").read_text())["best"][0]
        experiment = Experiment.from_dict(cfg["experiment"])
    except (OSError, ValueError, KeyError, TypeError, SoftGymError) as exc:
        print(f"softgym replay: {run_dir} is not a finished run folder ({exc})", file=sys.stderr)
        return 2
    exp = cfg["experiment"]
    seconds = float(exp["seconds"] if args.seconds is None else args.seconds)
    task = experiment.make_task().replace(seconds=seconds)
    m = evaluate([design], task=task, traces=True)
    out = Path(args.out) if args.out else run_dir / "replay"
    terrain = task.terrain_for(design.shape)
    fine = evaluate([design], task=task.replace(trace_interval=trace_interval_for(design)),
                    traces=True)  # fmt: skip
    paths = [
        plot_robot(design, out / "best_robot.png", title=f"best robot ({exp['name']})"),
        plot_trajectory(
            fine["traces"][0], out / "best_trajectory.png", init_time=1.0, terrain=terrain
        ),
    ]
    if not args.no_gif:
        paths.append(
            save_robot_gif(design, out / "best_robot.gif", terrain, seconds, config=task.config())
        )
    if args.video:
        paths.append(
            save_robot_gif(design, out / "best_robot.mp4", terrain, seconds, fps=20.0,
                           config=task.config())  # fmt: skip
        )
    metrics = {
        k: (v[0].item() if hasattr(v[0], "item") else v[0]) for k, v in m.items() if k != "traces"
    }
    summary = {"experiment": exp["name"], "seconds": seconds, "metrics": metrics,
               "recorded": best["objectives"], "files": [str(p) for p in paths]}  # fmt: skip
    print(json.dumps(summary, indent=2))
    return 0


def _config_key(cfg: dict) -> str:
    """What makes two runs the same configuration: everything but the seed."""
    from evolvers.experiments import Experiment

    exp = Experiment.from_dict(cfg["experiment"]).to_dict()
    exp.pop("generations", None)
    rest = {k: v for k, v in cfg.items() if k not in ("seed", "experiment", "generations")}
    return json.dumps({"experiment": exp, **rest}, sort_keys=True, default=str)


def _cmd_compare(args: argparse.Namespace) -> int:
    import statistics

    from evolvers.recorder import config_difference, read_run_config
    from softgym.render.figures import plot_compare, read_log

    groups: dict[str, list] = {}
    configs: dict[str, dict] = {}
    logs = {}
    for d in args.run_dirs:
        cfg = read_run_config(d)  # CheckpointError naming the folder if it is not a run
        key = _config_key(cfg)
        groups.setdefault(key, []).append(d)
        configs.setdefault(key, cfg)
        logs[d] = read_log(d)
    metric = args.metric
    if metric is None:
        first = configs[next(iter(configs))]["experiment"]["objectives"][0]["name"]
        metric = first if first != "age" else "norm_final_dist"
    column = f"{metric}_{args.stat}"
    for d, rows in logs.items():
        if not rows or column not in rows[0]:
            have = sorted({k.rsplit("_", 1)[0] for k in (rows[0] if rows else {})
                           if k.endswith("_best")})  # fmt: skip
            print(f"softgym compare: {d} did not record {metric!r} (it has: {', '.join(have) or 'no generation yet'}); "
                  f"pick a metric every run has with --metric", file=sys.stderr)  # fmt: skip
            return 2
    labelled: dict[str, list] = {}
    base = configs[next(iter(configs))]
    for key, dirs in groups.items():
        cfg = configs[key]
        label = f"{cfg['experiment']['name']} ({cfg['backend']}"
        label += f", {cfg['algorithm']})" if cfg.get("algorithm") else ")"
        if label in labelled or any(k != key and configs[k]["experiment"]["name"] == cfg["experiment"]["name"]
                                    and configs[k]["backend"] == cfg["backend"] for k in groups):  # fmt: skip
            diff = config_difference(base, cfg)
            if diff:
                label += f" [{diff.split(':')[0]}={diff.split('!=')[-1].strip()}]"
        labelled[label] = [logs[d] for d in dirs]
    path = plot_compare(labelled, metric, args.out, stat=args.stat)
    for label, runs in labelled.items():
        finals = [rows[-1][column] for rows in runs]
        print(f"{label}: {len(runs)} run(s), final {args.stat} {metric} median "
              f"{statistics.median(finals):.4g}")  # fmt: skip
    print(path)
    return 0


def _cmd_view(args: argparse.Namespace) -> int:
    from softgym.render.viewer import write_viewer

    src = Path(args.source)
    task, seconds, name = args.task or "flat", args.seconds, src.stem
    if src.is_dir():
        from evolvers.experiments import Experiment
        from evolvers.recorder import read_run_config
        from softgym.design import RobotDesign

        exp = Experiment.from_dict(read_run_config(src)["experiment"])
        design = RobotDesign.load(src / "best_design.json")
        task = args.task or exp.make_task()
        seconds = exp.seconds if seconds is None else seconds
        name = f"{src.name}: best robot ({exp.name})"
        out = Path(args.out) if args.out else src / "view.html"
    else:
        design = _load_design(src)
        out = Path(args.out) if args.out else src.with_suffix(".html")
    path = write_viewer(design, out, seconds=5.0 if seconds is None else seconds, fps=args.fps,
                        task=task, name=name)  # fmt: skip
    print(path)
    return 0


def _load_design(path: Path):
    from softgym.design import RobotDesign, load_vxa

    if path.suffix.lower() in (".vxa", ".vxd", ".xml"):
        return load_vxa(path)
    return RobotDesign.load(path)


def _cmd_convert(args: argparse.Namespace) -> int:
    from softgym.design import save_vxa

    src, dst = Path(args.source), Path(args.dest)
    design = _load_design(src)
    dst.parent.mkdir(parents=True, exist_ok=True)
    if dst.suffix.lower() == ".vxa":
        save_vxa(design, dst)
    elif dst.suffix.lower() == ".json":
        design.save(dst)
    else:
        print(f"softgym convert: {dst} must end in .json or .vxa", file=sys.stderr)
        return 2
    print(f"{src} -> {dst} ({design.n_voxels} voxels, {design.shape[0]}x{design.shape[1]}x{design.shape[2]})")
    return 0


def _cmd_experiments(args: argparse.Namespace) -> int:
    from evolvers.experiments import EXPERIMENTS

    for name, exp in EXPERIMENTS.items():
        objs = ", ".join(f"{o.name} ({'max' if o.maximize else 'min'})" for o in exp.objectives)
        print(f"{name:24s} {exp.selection:16s} {objs}\n{'':24s} {exp.description}")
    return 0


def _cmd_study(args: argparse.Namespace) -> int:
    if getattr(args, "study_command", None) == "report":
        return _cmd_study_report(args)
    from evolvers.study import (
        get_study,
        plan,
        run_order,
        run_status,
        run_study,
        settings_difference,
        time_to_go,
    )
    from softgym.exceptions import SoftGymError

    overrides = {}
    if args.pop is not None:
        overrides["pop_size"] = args.pop
    if args.seconds is not None:
        overrides["seconds"] = args.seconds
    if args.shape is not None:
        overrides["shape"] = tuple(args.shape)
    names = [n for item in (args.scenarios or []) for n in item.split(",") if n]
    try:
        study = get_study(args.study)
        specs = plan(
            args.out, study, scenarios=names or None, seeds=args.seeds,
            generations=args.generations, first_seed=args.first_seed, n_threads=args.threads,
            **overrides,
        )  # fmt: skip
    except SoftGymError as exc:
        print(f"softgym study: {exc}", file=sys.stderr)
        return 2
    if args.plan:
        ordered = run_order(specs)  # the order the runs start in
        other = {id(s): d for s in ordered if (d := settings_difference(s)) is not None}
        ok = [s for s in ordered if id(s) not in other]  # the study refuses the others
        togo = dict(zip(map(id, ok), time_to_go(ok)))
        for s in ordered:
            if id(s) in other:
                status, left_text = "other", f"run with other settings: {other[id(s)]}"
            else:
                status = run_status(s.out, s.generations)
                left, source = togo[id(s)]
                left_text = "" if status == "complete" else f"~{left / 3600:5.2f} CPU h to go ({source})"
            print(f"{s.scenario:24s} seed {s.seed:<4d} {s.generations:4d} generations  "
                  f"{status:8s} {left_text:32s}  {s.out}")  # fmt: skip
        todo = sum(left for left, _ in togo.values())
        count = {k: sum(src == k for _, src in togo.values())
                 for k in ("measured", "scenario", "estimate")}  # fmt: skip
        unfinished = sum(count.values())
        refused = f"; {len(other)} made with other settings, refused" if other else ""
        print(f"{len(specs)} runs, {unfinished} unfinished{refused}; ~{todo / 3600:.1f} CPU hours "
              f"to go ({count['measured']} timed from their own logged generations, "
              f"{count['scenario']} from their scenario's, {count['estimate']} from the "
              f"static estimate)")  # fmt: skip
        return 0

    def report(res):
        if not args.quiet:
            err = f"  {res['error']}" if res["status"] == "failed" else ""
            print(f"{res['scenario']:24s} seed {res['seed']:<4d} {res['status']:8s} "
                  f"generation {res['generation']:<4d} {res['wall']:8.1f} s{err}", flush=True)  # fmt: skip

    if args.quiet:
        logging.getLogger("evolvers").setLevel(logging.WARNING)
    if args.workers > 1 or args.dask:
        _quiet_dask(args.verbose)
    t0 = time.perf_counter()
    try:
        results = run_study(specs, workers=args.workers, scheduler=args.dask,
                            study=study.name, on_result=report)  # fmt: skip
    except SoftGymError as exc:
        print(f"softgym study: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("softgym study: interrupted; run the same command again to resume", file=sys.stderr)
        return 130
    counts: dict[str, int] = {}
    for r in results:
        counts[r["status"]] = counts.get(r["status"], 0) + 1
    summary = {
        "study": study.name,
        "out": str(args.out),
        "runs": len(results),
        "status": counts,
        "wall_seconds": round(time.perf_counter() - t0, 2),
        "report": f"softgym study report {args.out}",
    }
    print(json.dumps(summary, indent=2))
    return 1 if counts.get("failed") else 0


def _cmd_study_report(args: argparse.Namespace) -> int:
    from evolvers.study_report import claims, load_runs, write_report

    root = Path(args.runs)
    if not root.is_dir() or not load_runs(root):
        print(f"softgym study report: no run folders under {root}", file=sys.stderr)
        return 2
    readme = write_report(root, args.report_out)
    for c in claims(load_runs(root)):
        print(f"{c.id:22s} {c.verdict}")
    print(readme)
    return 0


def _add_study_parser(sub) -> None:
    """``softgym study [run] ...`` and ``softgym study report RUNS``."""
    p = sub.add_parser(
        "study",
        help="run the seed report's scenarios over many seeds (resumable); 'study report RUNS'",
        description="Run a study: every scenario x seed as a resumable run folder under --out "
        "(complete runs are skipped, interrupted ones resume; run the same command again to "
        "continue). 'softgym study report RUNS' writes the claim-by-claim report.",
    )
    p.add_argument("--study", default="seed-report", help="the named study (default seed-report)")
    p.add_argument("--scenarios", nargs="+", metavar="NAME",
                   help="scenarios to run (default: all of the study's; comma- or space-separated)")  # fmt: skip
    p.add_argument("--seeds", type=int, help="seeds per scenario (default: the scenario's)")
    p.add_argument("--first-seed", type=int, default=0, help="seeds are FIRST, FIRST+1, ...")
    p.add_argument("--generations", type=int, help="generations per run (default: the scenario's)")
    p.add_argument("--out", default="runs/study", help="the study's root folder")
    p.add_argument("--workers", type=int, default=1,
                   help="runs at a time on a Dask LocalCluster (1: one after the other, no Dask)")  # fmt: skip
    p.add_argument("--dask", metavar="tcp://ADDRESS",
                   help='run on an existing Dask scheduler\'s workers (pip install "softgym[distributed]")')  # fmt: skip
    p.add_argument("--pop", type=int, help="population size (default 15; small values for tests)")
    p.add_argument("--seconds", type=float, help="simulated seconds per evaluation (default 5)")
    p.add_argument("--shape", type=int, nargs=3, metavar=("NX", "NY", "NZ"),
                   help="robot grid (default 6 6 6)")  # fmt: skip
    p.add_argument(
        "--threads", type=int, help="OpenMP threads per run (default: 1 with --workers > 1)"
    )
    p.add_argument(
        "--plan", action="store_true", help="list the runs and their status; run nothing"
    )
    p.add_argument("--quiet", action="store_true", help="no line per finished run")
    ss = p.add_subparsers(dest="study_command", required=False)
    r = ss.add_parser("run", help="run the study (the default)")
    r.set_defaults(study_command="run")
    r = ss.add_parser("report", help="write README.md and figures from a study's run folders")
    r.add_argument("runs", help="the study's root folder (softgym study --out)")
    r.add_argument("--out", dest="report_out", default="docs/study",
                   help="where README.md and figures/ go (default docs/study)")  # fmt: skip
    p.set_defaults(func=_cmd_study)


def _make_qd_run(args: argparse.Namespace, batch_fn):
    """A QDRun from the flags; with --resume, the run folder's settings under the typed flags."""
    from evolvers.experiments import Experiment, get_experiment
    from evolvers.qd import QDConfig, QDRun
    from evolvers.recorder import read_run_config

    cfg = None
    if args.resume and (Path(args.out) / "config.json").is_file():
        cfg = read_run_config(args.out)  # a mismatch with a typed flag is named by QDRun.run
    if cfg is not None and args.experiment is None:
        exp = Experiment.from_dict(cfg["experiment"])
    else:
        exp = get_experiment(args.experiment or "basic", pop_size=16)
    overrides = {"pop_size": args.batch, "seconds": args.seconds, "task": args.task,
                 "shape": None if args.shape is None else tuple(args.shape)}  # fmt: skip
    exp = exp.replace(**{k: v for k, v in overrides.items() if v is not None})
    qd = QDConfig.from_dict(cfg["qd"]) if cfg is not None and "qd" in cfg else QDConfig()
    typed = {"descriptors": args.descriptors, "cells": args.cells, "archive": args.archive,
             "objective": args.objective}  # fmt: skip
    typed = {k: tuple(v) if isinstance(v, list) else v for k, v in typed.items() if v is not None}
    if typed:
        base = qd.to_dict()
        if "cells" not in typed and ("descriptors" in typed or "archive" in typed):
            base["cells"] = base["cells"][:1]  # one value for every descriptor
        qd = QDConfig.from_dict({**base, **typed})
    seed = args.seed if args.seed is not None else int(cfg["seed"]) if cfg else 0
    gens = args.generations
    if gens is None:
        gens = int(cfg.get("generations", 20)) if cfg else 20
    run = QDRun(
        exp, args.out, seed=seed, generations=gens, config=qd, batch_fn=batch_fn,
        n_threads=args.threads, figures=not args.no_figures, gif=not args.no_gif,
        progress=not args.quiet,
    )  # fmt: skip
    run.resume_command = f"softgym qd --out {shlex.quote(str(args.out))} --resume"
    return run


def _cmd_qd(args: argparse.Namespace) -> int:
    if getattr(args, "qd_command", None) == "export":
        return _cmd_qd_export(args)

    def start(stack):
        run = _make_qd_run(args, _dask_batch_fn(args, stack))
        run.run(resume=args.resume)
        return run

    t0 = time.perf_counter()
    status, run = _interruptible("qd", "generation", start)
    if status is not None:
        return status
    stats = run.stats()
    summary = {
        "experiment": run.experiment.name,
        "archive": run.config.to_dict(),
        "generations": run.generation,
        "evaluations": run.evaluations_total,
        **stats,
        "objective": run.objective,
        "wall_seconds": round(time.perf_counter() - t0, 2),
        "out": str(run.out),
        "figures": sorted(str(p) for p in (run.out / "figures").glob("*"))
        if (run.out / "figures").exists()
        else [],
        "export": f"softgym qd export {shlex.quote(str(run.out))}",
    }
    print(json.dumps(summary, indent=2))
    return 0


def _cmd_qd_export(args: argparse.Namespace) -> int:
    from evolvers.qd import export_elites

    index = export_elites(args.run, args.export_out, top=args.top)
    n = len(json.loads(index.read_text())["elites"])
    print(f"wrote {n} elites (design .json and .vxa) and {index}")
    return 0


def _add_qd_parser(sub) -> None:
    """``softgym qd [run] ...`` and ``softgym qd export RUN``."""
    p = sub.add_parser(
        "qd",
        help="quality-diversity: a MAP-Elites archive of robots (pyribs); 'qd export RUN'",
        description="Fill a MAP-Elites archive (pyribs) with robots: each cell keeps the best "
        "robot of its body descriptors (default: stiff x filled fraction, 128 x 128 cells, "
        "Mouret & Clune 2015). A resumable run folder with log (QD-score, coverage, best), "
        "checkpoints, heatmap and best designs; 'softgym qd export RUN' writes the elites as "
        'design files. Needs pip install "softgym[qd]".',
    )
    p.add_argument("--experiment", help="experiment whose task, rules and genes are used "
                   "(default basic: CPPN bodies; softgym experiments lists them)")  # fmt: skip
    p.add_argument("--generations", type=int, help="batches after the first (default 20)")
    p.add_argument("--batch", type=int, help="robots per generation (default 16)")
    p.add_argument("--seed", type=int, help="seed of the run (default 0)")
    p.add_argument("--out", default="runs/qd", help="run folder")
    p.add_argument("--resume", action="store_true",
                   help="continue the run folder's last checkpoint with its recorded settings")  # fmt: skip
    p.add_argument("--descriptors", nargs="+", metavar="NAME",
                   help="body descriptors: stiff filled muscle height elongation "
                   "(default stiff filled)")  # fmt: skip
    p.add_argument("--cells", type=int, nargs="+",
                   help="grid: cells per descriptor (one value for all; default 128); "
                   "cvt: the number of centroids")  # fmt: skip
    p.add_argument("--archive", choices=["grid", "cvt"], help="GridArchive (default) or CVTArchive")
    p.add_argument("--objective", choices=["norm_final_dist", "max_xy_dist"],
                   help="maximised metric (default: the experiment's fitness)")  # fmt: skip
    p.add_argument("--task", metavar="TASK[:ARG=V,...]|FILE.json",
                   help="the world (default: the experiment's)")  # fmt: skip
    p.add_argument("--seconds", type=float, help="simulated seconds per evaluation (default 5)")
    p.add_argument("--shape", type=int, nargs=3, metavar=("NX", "NY", "NZ"),
                   help="robot grid (default 6 6 6)")  # fmt: skip
    p.add_argument("--dask", metavar="local|tcp://ADDRESS",
                   help='evaluate on Dask (pip install "softgym[distributed]")')  # fmt: skip
    p.add_argument("--workers", type=int, default=2, help="LocalCluster workers (--dask local)")
    p.add_argument("--threads", type=int, help="OpenMP threads of local simulations")
    p.add_argument("--no-figures", action="store_true", help="write no figures at the end")
    p.add_argument("--no-gif", action="store_true", help="no GIF of the best robot")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    ss = p.add_subparsers(dest="qd_command", required=False)
    r = ss.add_parser("run", help="run (the default)")
    r.set_defaults(qd_command="run")
    r = ss.add_parser("export", help="write a QD run's elites as design files (.json, .vxa)")
    r.add_argument("run", help="a softgym qd run folder")
    r.add_argument("--out", dest="export_out", help="folder (default RUN/elites)")
    r.add_argument("--top", type=int, help="only the best TOP elites")
    p.set_defaults(func=_cmd_qd)


#: poet flags that map onto PoetConfig fields (None: not typed; the config's default applies).
_POET_FLAGS = ("reproduce_every", "transfer_every", "max_children", "max_admitted", "max_active",
               "mc_low", "mc_high", "repro_threshold", "solved_threshold", "generator",
               "score_cap")  # fmt: skip


def _make_poet_run(args: argparse.Namespace, jobs_fn):
    """A PoetRun from the flags; with --resume, the run folder's settings under the typed flags."""
    from evolvers.experiments import Experiment
    from evolvers.poet import PoetConfig, PoetRun, poet_experiment
    from evolvers.recorder import read_run_config
    from softgym.io import read_json

    cfg = None
    if args.resume and (Path(args.out) / "config.json").is_file():
        cfg = read_run_config(args.out)  # a mismatch with a typed flag is named by PoetRun.run
    exp = Experiment.from_dict(cfg["experiment"]) if cfg is not None else poet_experiment()
    sizes = {"pop_size": args.pop, "seconds": args.seconds,
             "shape": None if args.shape is None else tuple(args.shape)}  # fmt: skip
    exp = exp.replace(**{k: v for k, v in sizes.items() if v is not None})
    base = dict(cfg["poet"]) if cfg is not None and "poet" in cfg else PoetConfig().to_dict()
    typed = {k: getattr(args, k) for k in _POET_FLAGS if getattr(args, k) is not None}
    if args.start_terrain is not None:
        typed["start_terrain"] = read_json(args.start_terrain)
    poet = PoetConfig.from_dict({**base, **typed})
    seed = args.seed if args.seed is not None else int(cfg["seed"]) if cfg else 0
    iters = args.iterations
    if iters is None:
        iters = int(cfg.get("generations", 40)) if cfg else 40
    run = PoetRun(
        exp, args.out, seed=seed, iterations=iters, config=poet, jobs_fn=jobs_fn,
        n_threads=args.threads, figures=not args.no_figures, progress=not args.quiet,
    )  # fmt: skip
    run.resume_command = f"softgym poet --out {shlex.quote(str(args.out))} --resume"
    return run


def _cmd_poet(args: argparse.Namespace) -> int:
    if getattr(args, "poet_command", None) == "compare":
        return _cmd_poet_compare(args)

    def start(stack):
        jobs_fn = None
        if args.dask:
            from evolvers.distributed import dask_client
            from evolvers.poet import DaskJobsFn

            _quiet_dask(args.verbose)
            client = stack.enter_context(dask_client(args.dask, n_workers=args.workers))
            _quiet_dask(args.verbose)
            jobs_fn = DaskJobsFn(client)
        run = _make_poet_run(args, jobs_fn)
        return run, run.run(resume=args.resume)

    t0 = time.perf_counter()
    status, result = _interruptible("poet", "iteration", start)
    if status is not None:
        return status
    run, pairs = result
    summary = {
        "iterations": run.iteration,
        "generator": run.config.generator,
        "evaluations": run.evaluations_total,
        "annecs": run.annecs,
        "annecs_archive": run.annecs_archive,
        "pairs": len(pairs),
        "active": len(run.active()),
        "solved": sum(p.solved is not None for p in pairs),
        "wall_seconds": round(time.perf_counter() - t0, 2),
        "out": str(run.out),
        "figures": sorted(str(p) for p in (run.out / "figures").glob("*"))
        if (run.out / "figures").exists()
        else [],
    }
    print(json.dumps(summary, indent=2))
    return 0


def _cmd_poet_compare(args: argparse.Namespace) -> int:
    from evolvers.poet import plot_annecs
    from evolvers.recorder import read_run_config
    from softgym.exceptions import CheckpointError
    from softgym.render.figures import read_log

    groups: dict[str, list] = {}
    for d in args.runs:
        cfg = read_run_config(d)
        if "poet" not in cfg:
            raise CheckpointError(f"{d}: not a POET run folder (softgym poet)")
        label = "POET" if cfg["poet"]["generator"] == "mutate" else "random terrains (control)"
        groups.setdefault(label, []).append(read_log(d))
    path = plot_annecs(groups, args.compare_out)
    for label, runs in groups.items():
        finals = sorted(rows[-1]["annecs"] if rows else 0 for rows in runs)
        print(f"{label}: {len(runs)} run(s), final ANNECS {finals}")
    print(path)
    return 0


def _add_poet_parser(sub) -> None:
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
    p.add_argument("--iterations", type=int, help="iterations after the first (default 40)")
    p.add_argument("--pop", type=int, help="robots per pair (default 8)")
    p.add_argument("--seed", type=int, help="seed of the run (default 0)")
    p.add_argument("--out", default="runs/poet", help="run folder")
    p.add_argument("--resume", action="store_true",
                   help="continue the run folder's last checkpoint with its recorded settings")  # fmt: skip
    p.add_argument("--generator", choices=["mutate", "random"],
                   help="candidate terrains: mutants of eligible parents (default) or uniform "
                   "draws (the random-terrain control)")  # fmt: skip
    p.add_argument("--reproduce-every", type=int, help="K: iterations between reproductions (default 5)")
    p.add_argument("--transfer-every", type=int, help="T: iterations between transfers (default 5)")
    p.add_argument("--max-children", type=int, help="candidate terrains per round (default 8)")
    p.add_argument("--max-admitted", type=int, help="terrains admitted per round (default 1)")
    p.add_argument("--max-active", type=int, help="active pairs before the oldest retire (default 8)")
    p.add_argument("--mc-low", type=float, help="minimal criterion, low end (default 3.76)")
    p.add_argument("--mc-high", type=float, help="minimal criterion, high end (default 13.35)")
    p.add_argument("--repro-threshold", type=float, help="score to reproduce (default 9.09)")
    p.add_argument("--solved-threshold", type=float, help="score that solves (default 10)")
    p.add_argument("--score-cap", type=float,
                   help="scores saturate here, like a finished BipedalWalker course (default: none)")  # fmt: skip
    p.add_argument("--start-terrain", metavar="GENOME.json",
                   help="the first pair's terrain genome (default: flat)")  # fmt: skip
    p.add_argument("--seconds", type=float, help="simulated seconds per evaluation (default 3)")
    p.add_argument("--shape", type=int, nargs=3, metavar=("NX", "NY", "NZ"),
                   help="robot grid (default 4 4 4)")  # fmt: skip
    p.add_argument("--dask", metavar="local|tcp://ADDRESS",
                   help='evaluate the pairs in parallel on Dask (pip install "softgym[distributed]")')  # fmt: skip
    p.add_argument("--workers", type=int, default=2, help="LocalCluster workers (--dask local)")
    p.add_argument("--threads", type=int, help="OpenMP threads of local simulations")
    p.add_argument("--no-figures", action="store_true", help="write no figures at the end")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    ss = p.add_subparsers(dest="poet_command", required=False)
    r = ss.add_parser("run", help="run (the default)")
    r.set_defaults(poet_command="run")
    r = ss.add_parser("compare", help="ANNECS over iterations of POET runs and controls, one figure")
    r.add_argument("runs", nargs="+", metavar="RUN", help="softgym poet run folders")
    r.add_argument("--out", dest="compare_out", default="runs/poet_annecs.png", help="figure file")
    p.set_defaults(func=_cmd_poet)


class _HelpFormatter(argparse.ArgumentDefaultsHelpFormatter):
    """``--help`` shows every default (options without one say theirs in words)."""

    def _get_help_string(self, action: argparse.Action) -> str:
        if action.default is None or isinstance(action, argparse._StoreTrueAction):
            return action.help or ""
        return super()._get_help_string(action)


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``softgym`` command.

    A :class:`~softgym.exceptions.SoftGymError` or :class:`OSError` from a
    subcommand prints one line, ``softgym <command>: <message>``, to stderr and
    returns 2; ``softgym --debug <command> ...`` raises it instead (traceback).
    """
    parser = argparse.ArgumentParser(
        prog="softgym", description=__doc__.split("\n")[0], formatter_class=_HelpFormatter
    )
    parser.add_argument(
        "-v", "--verbose", action="count", default=0,
        help="log lines (-v: each generation and Dask's; -vv: debug)",
    )  # fmt: skip
    parser.add_argument(
        "--debug", action="store_true", help="show the traceback of an error (before the command)"
    )
    sub = parser.add_subparsers(dest="command", required=True)
    _add = sub.add_parser

    def add_parser(name, **kw):  # every subcommand shows its defaults in --help
        return _add(name, formatter_class=_HelpFormatter, allow_abbrev=False, **kw)

    sub.add_parser = add_parser
    p = sub.add_parser("simulate", help="simulate one robot and plot its trajectory")
    p.add_argument("--design", help="a RobotDesign JSON file (default: the embedded walker)")
    p.add_argument("--seconds", type=float, default=5.0, help="simulated seconds")
    p.add_argument(
        "--actuation", choices=["seed", "symmetric"], default="seed",
        help="muscle law: the seed's contraction-only, or symmetric",
    )  # fmt: skip
    p.add_argument("--out", default="runs/simulate", help="output folder")
    p.set_defaults(func=_cmd_simulate)

    p = sub.add_parser("evolve", help="evolve robots with one of the seed's experiments")
    p.add_argument(
        "--experiment",
        default="controller-tournament",
        help="experiment name (softgym experiments lists them)",
    )
    p.add_argument("--generations", type=int, default=10, help="generations after generation 0")
    p.add_argument("--pop", type=int, default=15, help="population size")
    p.add_argument("--seed", type=int, default=0, help="seed of the run's random generator")
    p.add_argument("--out", default="runs/evolve", help="run folder")
    p.add_argument(
        "--resume",
        action="store_true",
        help="continue the run folder's last checkpoint with its recorded settings "
        "(experiment, seed, backend...; a differing flag is an error)",
    )
    p.add_argument(
        "--dask",
        metavar="local|tcp://ADDRESS",
        help="evaluate on Dask: a LocalCluster or an existing scheduler "
        '(pip install "softgym[distributed]"; default: local simulations, no Dask)',
    )
    p.add_argument("--workers", type=int, default=2, help="LocalCluster workers (--dask local)")
    p.add_argument(
        "--backend", choices=["native", "deap", "pymoo"], default="native",
        help="the search loop: softgym's own, a DEAP toolbox, or a pymoo algorithm",
    )  # fmt: skip
    p.add_argument(
        "--algorithm",
        choices=["nsga2", "nsga3", "sms-emoa", "ga"],
        default="nsga2",
        help="pymoo algorithm (--backend pymoo; ga optimises the first objective alone)",
    )
    p.add_argument(
        "--task",
        metavar="TASK[:ARG=V,...]|FILE.json",
        help="the world (default: the experiment's): a task name or a terrain JSON file",
    )
    p.add_argument(
        "--seconds", type=float, help="simulated seconds per evaluation (default: the experiment's, 5)"
    )
    p.add_argument(
        "--shape", type=int, nargs=3, metavar=("NX", "NY", "NZ"),
        help="robot grid (default: the experiment's, 6 6 6)",
    )  # fmt: skip
    p.add_argument(
        "--selection",
        choices=["pareto", "tournament", "novelty", "novelty-archive", "nsga2"],
        help="override the experiment's selection (native and DEAP backends; default: the experiment's)",
    )
    p.add_argument(
        "--threads", type=int, help="OpenMP threads of local simulations (default: all usable CPUs)"
    )
    p.add_argument("--no-figures", action="store_true", help="write no figures at the end")
    p.add_argument("--no-gif", action="store_true", help="no GIF of the best robot")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=_cmd_evolve)
    evolve_parser = p

    p = sub.add_parser("replay", help="re-simulate and render the best robot of a run folder")
    p.add_argument("run_dir")
    p.add_argument("--seconds", type=float, help="simulated seconds (default: the run's)")
    p.add_argument("--out", help="output folder (default: RUN_DIR/replay)")
    p.add_argument("--no-gif", action="store_true", help="no GIF")
    p.add_argument(
        "--video", action="store_true", help='also an MP4 (pip install "softgym[video]")'
    )
    p.set_defaults(func=_cmd_replay)

    p = sub.add_parser(
        "compare",
        help="best fitness per generation of several runs; seeds of one configuration as "
        "median + interquartile band (Fig. 4)",
    )
    p.add_argument("run_dirs", nargs="+", metavar="RUN", help="run folders (any mix)")
    p.add_argument("--metric", help="metric to compare (default: the first run's fitness)")
    p.add_argument(
        "--stat", choices=["best", "median", "mean", "worst"], default="best",
        help="per-generation statistic of each run",
    )  # fmt: skip
    p.add_argument("--out", default="runs/compare.png", help="figure file")
    p.set_defaults(func=_cmd_compare)

    p = sub.add_parser(
        "view", help="write an interactive 3D viewer (self-contained HTML) of a robot's rollout"
    )
    p.add_argument("source", metavar="RUN_OR_DESIGN",
                   help="a run folder (its best robot, in its task) or a design .json / .vxa")  # fmt: skip
    p.add_argument(
        "--out", help="HTML file (default: RUN/view.html, or the design's name with .html)"
    )
    p.add_argument("--seconds", type=float, help="simulated seconds (default: the run's, or 5)")
    p.add_argument("--fps", type=float, default=10.0, help="frames per simulated second")
    p.add_argument(
        "--task", metavar="TASK[:ARG=V,...]|FILE.json",
        help="the world (default: the run's task, or flat)",
    )  # fmt: skip
    p.set_defaults(func=_cmd_view)

    p = sub.add_parser("convert", help="convert a design between JSON and .vxa (both ways)")
    p.add_argument("source", metavar="A", help="a design .json or .vxa file")
    p.add_argument("dest", metavar="B", help="the output .json or .vxa file")
    p.set_defaults(func=_cmd_convert)

    p = sub.add_parser("experiments", help="list the named experiments")
    p.set_defaults(func=_cmd_experiments)
    _add_study_parser(sub)
    _add_qd_parser(sub)
    _add_poet_parser(sub)
    argv = sys.argv[1:] if argv is None else list(argv)
    args = parser.parse_args(argv)
    if args.command == "evolve":
        args.explicit = _explicit_flags(evolve_parser, argv)
    level = (logging.WARNING, logging.INFO, logging.DEBUG)[min(args.verbose, 2)]
    logging.basicConfig(level=level, format="%(message)s")
    for name in ("softgym", "evolvers"):
        logging.getLogger(name).setLevel(level)
    from softgym.exceptions import SoftGymError

    try:
        return int(args.func(args))
    except (SoftGymError, OSError) as exc:  # bad input or a file problem: one line, exit 2
        if args.debug:
            raise
        message = " ".join(str(exc).split()) or type(exc).__name__
        print(f"softgym {args.command}: {message}", file=sys.stderr)
        return 2


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
