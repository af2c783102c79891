"""``softgym study``: the seed report's scenarios over many seeds, and ``study report``."""

from __future__ import annotations

import argparse
import json
import logging
import sys
import time
from pathlib import Path
from typing import Any

from softgym_cli.flags import options_after, subcommands, with_checkout_hint
from softgym_cli.runs import quiet_dask, settling_seconds

__all__ = ["add_study_parser"]


def _cmd_study(args: argparse.Namespace) -> int:
    if getattr(args, "study_command", None) == "report":
        return _cmd_study_report(args)
    from evolvers.study import runs as study_runs
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
        study = study_runs.get_study(args.study)
        specs = study_runs.plan(
            args.out, study, scenarios=names or None, seeds=args.seeds,
            generations=args.generations, first_seed=args.first_seed, n_threads=args.threads,
            **overrides,
        )  # fmt: skip
    except SoftGymError as exc:
        print(f"softgym study: {with_checkout_hint(' '.join(str(exc).split()))}", file=sys.stderr)
        return 2
    if args.seconds is not None and specs:
        settle = min(settling_seconds(s.experiment) for s in specs)
        if not args.seconds > settle:
            print(f"softgym study: warning: --seconds {args.seconds:g} is not more than the "
                  f"{settle:g} s settling time: a robot is measured only after it, so every "
                  "fitness will be ~0", file=sys.stderr)  # fmt: skip
    if args.plan:
        ordered = study_runs.run_order(specs)  # the order the runs start in
        other = {id(s): d for s in ordered if (d := study_runs.settings_difference(s)) is not None}
        ok = [s for s in ordered if id(s) not in other]  # the study refuses the others
        togo = dict(zip(map(id, ok), study_runs.time_to_go(ok)))
        for s in ordered:
            if id(s) in other:
                status, left_text = "other", f"run with other settings: {other[id(s)]}"
            else:
                status = study_runs.run_status(s.out, s.generations)
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

    n_runs, started, finished = len(specs), [0], [0]

    def start(spec):
        started[0] += 1
        if not args.quiet:
            print(f"{spec.scenario:24s} seed {spec.seed:<4d} started  [{started[0]}/{n_runs}] "
                  f"{spec.out}", flush=True)  # fmt: skip

    def report(res):
        finished[0] += 1
        if not args.quiet:
            err = f"  {res['error']}" if res["status"] == "failed" else ""
            print(f"{res['scenario']:24s} seed {res['seed']:<4d} {res['status']:8s} "
                  f"generation {res['generation']:<4d} {res['wall']:8.1f} s  "
                  f"[{finished[0]}/{n_runs} done]{err}", flush=True)  # fmt: skip

    if args.quiet:
        logging.getLogger("evolvers").setLevel(logging.WARNING)
    if args.workers > 1 or args.dask:
        quiet_dask(args.verbose)
    t0 = time.perf_counter()
    try:
        results = study_runs.run_study(specs, workers=args.workers, scheduler=args.dask,
                            study=study.name, on_result=report, on_start=start)  # fmt: skip
    except SoftGymError as exc:
        print(f"softgym study: {with_checkout_hint(' '.join(str(exc).split()))}", file=sys.stderr)
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
    from evolvers.study import claims, load_runs, write_report
    from softgym_cli.commands import describe_folder

    root = Path(args.runs)
    kind = describe_folder(root) if root.is_dir() else None
    if kind is not None and (root / "config.json").is_file():  # one run, not a study
        print(f"softgym study report: {root} is {kind[0]}, not a study's root folder "
              f"(softgym study --out, which holds study.json); try {kind[1]}",
              file=sys.stderr)  # fmt: skip
        return 2
    if not root.is_dir() or not load_runs(root):
        print(f"softgym study report: no run folders under {root} (a study's root folder, "
              "softgym study --out)", file=sys.stderr)  # fmt: skip
        return 2
    readme = write_report(root, args.report_out)
    for c in claims(load_runs(root)):
        print(f"{c.id:22s} {c.verdict}")
    print(readme)
    return 0


def add_study_parser(sub: Any) -> None:
    """``softgym study [run] ...`` and ``softgym study report RUNS``."""
    p = sub.add_parser(
        "study",
        help="run the seed report's scenarios over many seeds (resumable); 'study report RUNS'",
        description="Run a study: every scenario x seed as a resumable run folder under --out "
        "(complete runs are skipped, interrupted ones resume; run the same command again to "
        "continue). 'softgym study report RUNS' writes the claim-by-claim report.",
    )

    def options(p: argparse.ArgumentParser) -> None:
        p.add_argument("--study", default="seed-report", help="the named study")
        p.add_argument("--scenarios", nargs="+", metavar="NAME",
                       help="scenarios to run (default: all of the study's; comma- or space-separated)")  # fmt: skip
        p.add_argument("--seeds", type=int, help="seeds per scenario (default: the scenario's)")
        p.add_argument("--first-seed", type=int, default=0, help="seeds are FIRST, FIRST+1, ...")
        p.add_argument("--generations", type=int, help="generations per run (default: the scenario's)")
        p.add_argument("--out", default="runs/study", help="the study's root folder")
        p.add_argument("--workers", type=int, default=1,
                       help="runs at a time on a Dask LocalCluster (1: one after the other, no Dask)")  # fmt: skip
        p.add_argument("--dask", metavar="tcp://ADDRESS",
                       help="run on an existing Dask scheduler's workers (the distributed "
                       'extra: pip install "softgym[distributed]", or pip install -e '
                       '".[distributed]" in a checkout)')  # fmt: skip
        p.add_argument("--pop", type=int, help="population size (default: 15; small values for tests)")
        p.add_argument("--seconds", type=float, help="simulated seconds per evaluation (default: 5)")
        p.add_argument("--shape", type=int, nargs=3, metavar=("NX", "NY", "NZ"),
                       help="robot grid (default: 6 6 6)")  # fmt: skip
        p.add_argument(
            "--threads", type=int, help="OpenMP threads per run (default: 1 with --workers > 1, else all usable CPUs)"
        )
        p.add_argument(
            "--plan", action="store_true", help="list the runs and their status; run nothing"
        )

    options(p)
    ss = subcommands(p, "study_command", default="run", command="study",
                     default_help="run the study (the default; the options go before or after it)")  # fmt: skip
    options_after(p, ss.choices["run"], options)
    r = ss.add_parser("report", help="write README.md and figures from a study's run folders")
    r.add_argument("runs", help="the study's root folder (softgym study --out)")
    r.add_argument("--out", dest="report_out",
                   help="where README.md and figures/ go (default: RUNS/report; the "
                   "committed report is --out docs/study)")  # fmt: skip
    p.set_defaults(func=_cmd_study)
