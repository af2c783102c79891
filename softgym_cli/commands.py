"""The commands that read or render what exists: ``simulate``, ``replay``, ``compare``,
``view``, ``convert``, ``experiments`` and ``info``.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path
from typing import Any

__all__ = ["add_tool_parsers", "describe_folder", "kernel_info", "kernel_line"]


def kernel_info() -> dict[str, Any]:
    """The compiled engine in use: its kernel build, the builds installed and OpenMP."""
    import os

    from softgym.engine import omp_max_threads, openmp_enabled
    from softgym.engine._cpu import cpu_level
    from softgym.engine._dispatch import available_kernels, installed_kernels, kernel_build

    return {
        "kernel": kernel_build(),
        "forced_by": "SOFTGYM_KERNEL" if os.environ.get("SOFTGYM_KERNEL") else None,
        "installed": installed_kernels(),
        "this_cpu_runs": available_kernels(),
        # 4, 3, or 1 (below v3); 0: not x86-64
        "cpu_level": f"x86-64-v{cpu_level()}" if cpu_level() else "not x86-64",
        "openmp": bool(openmp_enabled()),
        "threads": int(omp_max_threads()) if openmp_enabled() else 1,
    }


def kernel_line() -> str:
    """One line: the kernel build in use, the builds installed, OpenMP on or off."""
    k = kernel_info()
    forced = " (SOFTGYM_KERNEL)" if k["forced_by"] else ""
    omp = f"OpenMP on ({k['threads']} threads)" if k["openmp"] else "OpenMP off (built serially)"
    return (f"kernel {k['kernel']}{forced}; installed: {', '.join(k['installed'])}; {omp}")


def describe_folder(path: str | Path) -> tuple[str, str] | None:
    """What a folder is, as (kind, the commands that read it), or None for no softgym folder.

    Kinds: ``study`` (a study's root: study.json), ``poet``, ``qd`` and ``evolve`` (a run
    folder, told apart by its config.json's sections). Reads config.json through the capped
    reader; a folder whose config.json does not read is None.
    """
    from evolvers.recording.recorder import read_run_config
    from softgym.exceptions import SoftGymError

    folder = Path(path)
    if (folder / "study.json").is_file() or (folder / "scenario.json").is_file():
        root = folder if (folder / "study.json").is_file() else folder.parent
        return ("a study's folder (softgym study)",
                f"softgym study report {root}; replay or view one of its runs, e.g. "
                f"{root}/SCENARIO/seed-0")  # fmt: skip
    if not (folder / "config.json").is_file():
        return None
    try:
        cfg = read_run_config(folder)
    except (SoftGymError, OSError):
        return None
    if "poet" in cfg:
        return ("a POET run folder (softgym poet)",
                f"softgym view {folder} (its best pair), softgym poet compare {folder}")  # fmt: skip
    if "qd" in cfg:
        return ("a QD run folder (softgym qd)",
                f"softgym replay/view/compare {folder}, softgym qd export {folder}")  # fmt: skip
    return ("an evolve run folder (softgym evolve)",
            f"softgym replay/view/compare {folder}")  # fmt: skip


def _cmd_info(args: argparse.Namespace) -> int:
    import platform

    from softgym_cli.flags import installed_version

    k = kernel_info()
    forced = " (forced by SOFTGYM_KERNEL)" if k["forced_by"] else " (the newest this CPU runs)"
    lines = [
        ("softgym", installed_version()),
        ("python", f"{platform.python_version()} ({platform.machine()})"),
        ("kernel in use", k["kernel"] + forced),
        ("kernels installed", ", ".join(k["installed"])),
        ("this CPU runs", f"{', '.join(k['this_cpu_runs'])} (CPU level: {k['cpu_level']})"),
        ("OpenMP", f"on, {k['threads']} threads" if k["openmp"] else "off (built serially)"),
    ]
    missing = [f"x86-64-v{n}" for n in (3, 4) if f"x86-64-v{n}" not in k["installed"]]
    if missing and k["cpu_level"] != "not x86-64":
        lines.append(("not built", f"{', '.join(missing)} (the compiler lacked "
                      "-march=x86-64-vN, or SOFTGYM_PORTABLE / SOFTGYM_NATIVE was set)"))  # fmt: skip
    if args.json:
        print(json.dumps({"softgym": installed_version(), **k}, indent=2))
    else:
        for name, value in lines:
            print(f"{name + ':':18s} {value}")
    return 0


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

def _cmd_replay(args: argparse.Namespace) -> int:
    from evolvers.evaluation.experiments import Experiment
    from evolvers.recording.recorder import read_best_designs, read_run_config
    from softgym.design import RobotDesign
    from softgym.evaluate import evaluate
    from softgym.exceptions import InvalidParameterError, SoftGymError
    from softgym.render.figures import (
        plot_robot,
        plot_trajectory,
        save_robot_gif,
        trace_interval_for,
    )

    run_dir = Path(args.run_dir)
    if args.video:  # the extra before any simulation, not after
        _require_video()
    kind = describe_folder(run_dir) if run_dir.is_dir() else None
    if kind is not None and not kind[0].startswith(("an evolve", "a QD")):
        print(f"softgym replay: {run_dir} is {kind[0]}, which replay does not read; "
              f"try {kind[1]}", file=sys.stderr)  # fmt: skip
        return 2
    try:  # every file through the capped reader: a FIFO is refused, never waited on
        cfg = read_run_config(run_dir)
        design = RobotDesign.load(run_dir / "best_design.json")
        best = read_best_designs(run_dir)[0]
        experiment = Experiment.from_dict(cfg["experiment"])
    except SoftGymError as exc:
        print(f"softgym replay: {run_dir} is not a finished run folder of softgym evolve or "
              f"qd ({exc})", file=sys.stderr)  # fmt: skip
        return 2
    exp = cfg["experiment"]
    seconds = float(experiment.seconds if args.seconds is None else args.seconds)
    task = experiment.make_task().replace(seconds=seconds)
    settle = float(task.config().init_time)
    if not seconds > settle:  # the trajectory is sampled after the settling time: none at all
        given = "--seconds" if args.seconds is not None else f"the run's seconds ({run_dir})"
        raise InvalidParameterError(
            f"{given} must be more than the {settle:g} s settling time (the trajectory starts "
            f"after it), got {seconds:g}; give --seconds above {settle:g}"
        )
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
               "recorded": best.get("objectives"), "files": [str(p) for p in paths]}  # fmt: skip
    print(json.dumps(summary, indent=2))
    return 0


def _require_video() -> None:
    """Refuse ``--video`` at once when the ``video`` extra is missing (before simulating)."""
    from softgym.render.frames import MissingVideoExtraError
    from softgym_cli.flags import extra_hint

    try:
        import imageio.v2  # noqa: F401
        import imageio_ffmpeg  # noqa: F401
    except ImportError as exc:
        raise MissingVideoExtraError(
            f"--video needs imageio and imageio-ffmpeg ({exc.name} is missing): "
            f"{extra_hint('video')}; or drop --video"
        ) from None


def _config_key(cfg: dict) -> str:
    """What makes two runs the same configuration: everything but the seed."""
    from evolvers.evaluation.experiments import Experiment

    exp = Experiment.from_dict(cfg["experiment"]).to_dict()
    exp.pop("generations", None)
    rest = {k: v for k, v in cfg.items() if k not in ("seed", "experiment", "generations")}
    return json.dumps({"experiment": exp, **rest}, sort_keys=True, default=str)


def _cmd_compare(args: argparse.Namespace) -> int:
    import statistics

    from evolvers.recording.recorder import config_difference, read_run_config
    from softgym.render.figures import figure_path, plot_compare, read_log
    from softgym.validate import is_real, show

    figure_path(args.out)  # a format matplotlib writes, checked before the runs are read

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
    column, top = f"{metric}_{args.stat}", f"top_{metric}"
    for d, rows in logs.items():
        if rows and column not in rows[0] and args.stat == "best" and top in rows[0]:
            # e.g. an obstacle run (fitness max_xy_dist) beside flat runs: its log holds the
            # fittest robot's NormFinalDist, which stands in for the best
            logs[d] = [{**r, column: r[top]} for r in rows]
            print(f"softgym compare: {d} logs no {column}; its fittest robot's {metric} "
                  f"({top}) stands in", file=sys.stderr)  # fmt: skip
        elif not rows or column not in rows[0]:
            have = sorted({k.rsplit("_", 1)[0] for k in (rows[0] if rows else {})
                           if k.endswith("_best")})  # fmt: skip
            print(f"softgym compare: {d} did not record {metric!r} (it has: {', '.join(have) or 'no generation yet'}); "
                  f"pick a metric every run has with --metric", file=sys.stderr)  # fmt: skip
            return 2
    for d, rows in logs.items():  # every generation's value a number (a damaged log is named)
        bad = next((n for n, r in enumerate(rows, 1) if not is_real(r.get(column))), None)
        if bad is not None:
            print(f"softgym compare: {Path(d) / 'log.jsonl'}: line {bad} has no number "
                  f"{column!r} (got {show(rows[bad - 1].get(column))})", file=sys.stderr)  # fmt: skip
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
        from evolvers.evaluation.experiments import Experiment
        from evolvers.recording.recorder import read_run_config
        from softgym.design import RobotDesign

        cfg = read_run_config(src)
        exp = Experiment.from_dict(cfg["experiment"])
        task = args.task or exp.make_task()
        seconds = exp.seconds if seconds is None else seconds
        name = f"{src.name}: best robot ({exp.name})"
        if "poet" in cfg:  # POET: the best robot of its pairs, on its own terrain
            from evolvers.drivers.poet import read_pairs
            from softgym.tasks.terrain_genome import TerrainGenome

            pair = max(read_pairs(src), key=lambda p: (p["score"], -p["id"]))
            design = RobotDesign.from_dict(pair["design"])
            if args.task is None:
                terrain = TerrainGenome.from_dict(pair["terrain"]).terrain(exp.shape)
                task = task.replace(terrain=terrain)
            name = f"{src.name}: best robot (POET pair {pair['id']}, {pair['describe']})"
        else:  # the other drivers (native, DEAP, pymoo, QD) write best_design.json
            design = RobotDesign.load(src / "best_design.json")
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
    from evolvers.evaluation.experiments import EXPERIMENTS

    for name, exp in EXPERIMENTS.items():
        objs = ", ".join(f"{o.name} ({'max' if o.maximize else 'min'})" for o in exp.objectives)
        print(f"{name:24s} {exp.selection:16s} {objs}\n{'':24s} {exp.description}")
    return 0



def add_tool_parsers(sub: Any) -> None:
    """``simulate``, ``replay``, ``compare``, ``view``, ``convert`` and ``experiments``."""
    p = sub.add_parser("simulate", help="simulate one robot and plot its trajectory")
    p.add_argument("--design", help="a RobotDesign JSON file (default: the embedded walker)")
    p.add_argument("--seconds", type=float, default=5.0, help="simulated seconds")
    p.add_argument("--actuation", choices=["seed", "symmetric"], default="seed",
                   help="muscle law: the seed's contraction-only, or symmetric")  # fmt: skip
    p.add_argument("--out", default="runs/simulate", help="output folder")
    p.set_defaults(func=_cmd_simulate)

    p = sub.add_parser("replay", help="re-simulate and render the best robot of a run folder")
    p.add_argument("run_dir")
    p.add_argument("--seconds", type=float, help="simulated seconds (default: the run's)")
    p.add_argument("--out", help="output folder (default: RUN_DIR/replay)")
    p.add_argument("--no-gif", action="store_true", help="no GIF")
    p.add_argument("--video", action="store_true", help='also an MP4 (the video extra: pip install "softgym[video]", or '
                   'pip install -e ".[video]" in a checkout)')
    p.set_defaults(func=_cmd_replay)

    p = sub.add_parser(
        "compare",
        help="best fitness per generation of several runs; seeds of one configuration as "
        "median + interquartile band (Fig. 4)",
    )
    p.add_argument("run_dirs", nargs="+", metavar="RUN", help="run folders (any mix)")
    p.add_argument("--metric", help="metric to compare (default: the first run's fitness; with "
                   "--stat best, a run that logs only its fittest robot's value, top_METRIC, "
                   "compares that)")
    p.add_argument("--stat", choices=["best", "median", "mean", "worst"], default="best",
                   help="per-generation statistic of each run")  # fmt: skip
    p.add_argument("--out", default="runs/compare.png", help="figure file")
    p.set_defaults(func=_cmd_compare)

    p = sub.add_parser(
        "view", help="write an interactive 3D viewer (self-contained HTML) of a robot's rollout"
    )
    p.add_argument("source", metavar="RUN_OR_DESIGN",
                   help="a run folder (its best robot, in its task; POET: on its terrain) "
                   "or a design .json / .vxa")  # fmt: skip
    p.add_argument("--out",
                   help="HTML file (default: RUN/view.html, or the design's name with .html)")  # fmt: skip
    p.add_argument("--seconds", type=float, help="simulated seconds (default: the run's, or 5)")
    p.add_argument("--fps", type=float, default=10.0, help="frames per simulated second")
    p.add_argument("--task", metavar="TASK[:ARG=V,...]|FILE.json",
                   help="the world (default: the run's task, or flat)")  # fmt: skip
    p.set_defaults(func=_cmd_view)

    p = sub.add_parser("convert", help="convert a design between JSON and .vxa (both ways)")
    p.add_argument("source", metavar="A", help="a design .json or .vxa file")
    p.add_argument("dest", metavar="B", help="the output .json or .vxa file")
    p.set_defaults(func=_cmd_convert)

    p = sub.add_parser("experiments", help="list the named experiments")
    p.set_defaults(func=_cmd_experiments)

    p = sub.add_parser(
        "info", help="the installed version, the kernel build in use, the builds installed, OpenMP",
        description="Which compiled engine runs: the kernel build in use (baseline, x86-64-v3: "
        "AVX2, x86-64-v4: AVX-512; SOFTGYM_KERNEL forces one), the builds this installation "
        "holds and this CPU runs, and whether OpenMP threads the batch.",
    )  # fmt: skip
    p.add_argument("--json", action="store_true", help="the same as one JSON object")
    p.set_defaults(func=_cmd_info)
