"""The ``softgym`` command line.

Subcommands
-----------
simulate
    Simulate the embedded default walker (or a design JSON) and write its
    centre-of-mass trajectory figure and a summary JSON.
evolve
    Run one of the seed study's experiments (native loop, DEAP or pymoo),
    on its task or another (``--task stairs|wall|flat|FILE.json``), locally or
    on Dask, into a resumable run folder with log, checkpoints, best designs
    and figures.
replay
    Re-simulate the best robot of a run folder and render it (figures + GIF).
compare
    Best fitness per generation of several run folders in one figure (the
    report's Fig. 4).
experiments
    List the named experiments.
study
    Run the seed report's scenarios over many seeds, each a resumable run
    folder (seeds in parallel on Dask); ``study report RUNS`` writes the
    claim-by-claim report and its figures.
"""

from __future__ import annotations

import argparse
import json
import logging
import sys
import time
from pathlib import Path

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


def _make_run(args: argparse.Namespace, batch_fn):
    from evolvers.experiments import get_experiment

    overrides = {"pop_size": args.pop}
    if args.seconds is not None:
        overrides["seconds"] = args.seconds
    if args.shape is not None:
        overrides["shape"] = tuple(args.shape)
    if args.selection is not None:
        overrides["selection"] = args.selection
    if args.task is not None:
        overrides["task"] = args.task
    exp = get_experiment(args.experiment, **overrides)
    extra = {}
    if args.backend == "deap":
        from evolvers.deap_runner import DeapRun as Run
    elif args.backend == "pymoo":
        from evolvers.pymoo_runner import PymooRun as Run

        extra["algorithm"] = args.algorithm
    else:
        from evolvers.runner import EvolutionRun as Run
    return Run(
        exp, args.out, seed=args.seed, generations=args.generations, batch_fn=batch_fn,
        n_threads=args.threads, figures=not args.no_figures, gif=not args.no_gif, **extra,
    )  # fmt: skip


def _cmd_evolve(args: argparse.Namespace) -> int:
    import contextlib

    from tqdm import tqdm

    from softgym.exceptions import SoftGymError

    t0 = time.perf_counter()
    with contextlib.ExitStack() as stack:
        batch_fn = None
        try:
            if args.dask:
                from evolvers.distributed import DaskBatchFn, dask_client

                client = stack.enter_context(dask_client(args.dask, n_workers=args.workers))
                batch_fn = DaskBatchFn(client)
            run = _make_run(args, batch_fn)
        except SoftGymError as exc:
            print(f"softgym evolve: {exc}", file=sys.stderr)
            return 2
        fit = run.experiment.fitness
        bar = tqdm(total=run.generations + 1, desc=f"{run.experiment.name} [{run.backend}]",
                   unit="gen", dynamic_ncols=True, disable=args.quiet)  # fmt: skip

        def progress(r, row):
            bar.n = row["generation"] + 1
            best = row.get(f"{fit.name}_best", float("nan"))
            bar.set_postfix(best=f"{best:.3f}", evals=row["evaluations_total"], refresh=False)
            bar.refresh()

        run.on_generation = progress
        try:
            run.run(resume=args.resume)
        except SoftGymError as exc:
            bar.close()
            print(f"softgym evolve: {exc}", file=sys.stderr)
            return 2
        bar.close()
    wall = time.perf_counter() - t0
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
    from softgym.render.figures import plot_robot, plot_trajectory, save_robot_gif

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
    fine = evaluate([design], task=task.replace(trace_interval=0.05), traces=True)
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
    metrics = {
        k: (v[0].item() if hasattr(v[0], "item") else v[0]) for k, v in m.items() if k != "traces"
    }
    summary = {"experiment": exp["name"], "seconds": seconds, "metrics": metrics,
               "recorded": best["objectives"], "files": [str(p) for p in paths]}  # fmt: skip
    print(json.dumps(summary, indent=2))
    return 0


def _cmd_compare(args: argparse.Namespace) -> int:
    from softgym.exceptions import CheckpointError
    from softgym.io import read_json
    from softgym.render.figures import plot_best_fitness, read_log

    curves = {}
    metric = args.metric
    for d in args.run_dirs:
        cfg_path = Path(d) / "config.json"
        cfg = read_json(cfg_path)  # CheckpointError naming the file if missing or corrupt
        try:
            label = f"{cfg['experiment']['name']} ({cfg['backend']}, seed {cfg['seed']})"
            if metric is None:
                first = cfg["experiment"]["objectives"][0]["name"]
                metric = first if first != "age" else "norm_final_dist"
        except (KeyError, TypeError, IndexError) as exc:
            raise CheckpointError(f"{cfg_path}: not a softgym run config ({exc!r})") from None
        curves[label] = read_log(d)
    path = plot_best_fitness(curves, metric, args.out, ylabel=f"Best {metric}")
    print(path)
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
    from evolvers.study import get_study, plan, run_status, run_study
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
        for s in specs:
            print(f"{s.scenario:24s} seed {s.seed:<4d} {s.generations:4d} generations  "
                  f"{run_status(s.out, s.generations):8s} {s.out}")  # fmt: skip
        return 0

    def report(res):
        if not args.quiet:
            err = f"  {res['error']}" if res["status"] == "failed" else ""
            print(f"{res['scenario']:24s} seed {res['seed']:<4d} {res['status']:8s} "
                  f"generation {res['generation']:<4d} {res['wall']:8.1f} s{err}", flush=True)  # fmt: skip

    if args.quiet:
        logging.getLogger("evolvers").setLevel(logging.WARNING)
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
    parser = argparse.ArgumentParser(prog="softgym", description=__doc__.split("\n")[0])
    parser.add_argument(
        "--debug", action="store_true", help="show the traceback of an error (before the command)"
    )
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("simulate", help="simulate one robot and plot its trajectory")
    p.add_argument("--design", help="a RobotDesign JSON file (default: the embedded walker)")
    p.add_argument("--seconds", type=float, default=5.0)
    p.add_argument("--actuation", choices=["seed", "symmetric"], default="seed")
    p.add_argument("--out", default="runs/simulate")
    p.set_defaults(func=_cmd_simulate)

    p = sub.add_parser("evolve", help="evolve robots with one of the seed's experiments")
    p.add_argument(
        "--experiment",
        default="controller-tournament",
        help="experiment name (softgym experiments lists them)",
    )
    p.add_argument("--generations", type=int, default=10, help="generations after generation 0")
    p.add_argument("--pop", type=int, default=15, help="population size")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--out", default="runs/evolve", help="run folder")
    p.add_argument(
        "--resume", action="store_true", help="continue the run folder's last checkpoint"
    )
    p.add_argument(
        "--dask",
        metavar="local|tcp://ADDRESS",
        help='evaluate on Dask: a LocalCluster or an existing scheduler (pip install "softgym[distributed]")',
    )
    p.add_argument("--workers", type=int, default=2, help="LocalCluster workers (--dask local)")
    p.add_argument("--backend", choices=["native", "deap", "pymoo"], default="native")
    p.add_argument(
        "--algorithm",
        choices=["nsga2", "nsga3", "sms-emoa", "ga"],
        default="nsga2",
        help="pymoo algorithm (--backend pymoo; ga optimises the first objective alone)",
    )
    p.add_argument(
        "--task",
        metavar="flat|wall|stairs|FILE.json",
        help="the world (default: the experiment's): a task name or a terrain JSON file",
    )
    p.add_argument("--seconds", type=float, help="simulated seconds per evaluation (default 5)")
    p.add_argument(
        "--shape", type=int, nargs=3, metavar=("NX", "NY", "NZ"), help="robot grid (default 6 6 6)"
    )
    p.add_argument(
        "--selection",
        choices=["pareto", "tournament", "novelty", "novelty-archive", "nsga2"],
        help="override the experiment's selection (native and DEAP backends)",
    )
    p.add_argument("--threads", type=int, help="OpenMP threads of local simulations")
    p.add_argument("--no-figures", action="store_true")
    p.add_argument("--no-gif", action="store_true")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=_cmd_evolve)

    p = sub.add_parser("replay", help="re-simulate and render the best robot of a run folder")
    p.add_argument("run_dir")
    p.add_argument("--seconds", type=float, help="simulated seconds (default: the run's)")
    p.add_argument("--out", help="output folder (default RUN_DIR/replay)")
    p.add_argument("--no-gif", action="store_true")
    p.set_defaults(func=_cmd_replay)

    p = sub.add_parser("compare", help="best fitness per generation of several runs (Fig. 4)")
    p.add_argument("run_dirs", nargs="+")
    p.add_argument("--metric", help="metric to compare (default: the first run's fitness)")
    p.add_argument("--out", default="runs/compare.png")
    p.set_defaults(func=_cmd_compare)

    p = sub.add_parser("experiments", help="list the named experiments")
    p.set_defaults(func=_cmd_experiments)
    _add_study_parser(sub)
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(message)s")
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
