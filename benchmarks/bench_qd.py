"""MAP-Elites against NSGA-II and the seed's novelty search at the same number of simulations.

Three searches over CPPN robots (the ``basic`` experiment's bodies on flat
ground) each get the same budget of simulations (distinct phenotypes; cache
hits are free for all three) and the same seeds:

* ``map-elites``: :class:`evolvers.qd.QDRun` (pyribs GridArchive, stiff x
  filled descriptors, softgym's mutation);
* ``nsga2``: :class:`evolvers.pymoo_runner.PymooRun` on ``basic`` (distance up,
  muscle voxels down);
* ``novelty``: :class:`evolvers.runner.EvolutionRun` on ``novelty`` (the seed's
  AMSS novelty within each generation).

Every simulated robot of a run is recorded (a wrapper around the batch
evaluation); the first ``--budget`` of them are inserted into a fresh archive
with the same descriptors and cells, which gives each search's QD-score
(sum of the archive's distances, voxel lengths), coverage (filled cells /
cells) and best distance (``norm_final_dist``, voxel lengths; diverged robots
count 0). Printed: median [quartiles] over the seeds, and per metric how many
seeds MAP-Elites beat each baseline on (same seed).

    python benchmarks/bench_qd.py --quick              # 4x4x4 robots, 1.5 s, 5 seeds
    python benchmarks/bench_qd.py --seeds 5 --budget 2000   # 6x6x6, 5 s: hours on 2 cores
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
from pathlib import Path

import numpy as np
import results_log

from evolvers.descriptors import MOURET_CLUNE_2015, descriptor_values
from evolvers.evaluation import local_batch_fn
from evolvers.experiments import get_experiment
from evolvers.pymoo_runner import PymooRun
from evolvers.qd import QDConfig, QDRun, archive_stats, make_archive
from evolvers.runner import EvolutionRun
from softgym.design import RobotDesign

METHODS = ("map-elites", "nsga2", "novelty")
METRICS = ("qd_score", "coverage", "best")


class BudgetReached(Exception):
    """Raised from a run's on_generation once the budget of simulations is spent."""


class RecordingBatchFn:
    """A batch_fn that simulates locally and keeps every simulated robot's grid and distance."""

    def __init__(self) -> None:
        self.grids: list[np.ndarray] = []
        self.distances: list[float] = []

    def __call__(self, designs, task):
        res = local_batch_fn(designs, task)
        for d, dist, div in zip(designs, res["norm_final_dist"], res["diverged"]):
            self.grids.append(np.asarray(RobotDesign.from_dict(d).grid))
            self.distances.append(0.0 if div else max(float(dist), 0.0))
        return res


def run_method(method: str, seed: int, args, out: Path) -> tuple[dict[str, float], float]:
    rec = RecordingBatchFn()
    sizes = {"pop_size": args.batch, "seconds": args.seconds, "shape": tuple(args.shape)}

    def stop(run, row):
        if len(rec.distances) >= args.budget:
            raise BudgetReached

    common = {"seed": seed, "generations": 10 * args.budget, "batch_fn": rec,
              "on_generation": stop, "figures": False, "gif": False, "progress": False}  # fmt: skip
    if method == "map-elites":
        run = QDRun(get_experiment("basic", **sizes), out / method, config=_config(args), **common)
    elif method == "nsga2":
        run = PymooRun(get_experiment("basic", **sizes), out / method, algorithm="nsga2", **common)
    else:
        run = EvolutionRun(get_experiment("novelty", **sizes), out / method, **common)
    t0 = time.perf_counter()
    try:
        run.run()
    except BudgetReached:
        pass
    wall = time.perf_counter() - t0
    n = args.budget
    if len(rec.distances) < n:
        raise RuntimeError(f"{method} seed {seed}: only {len(rec.distances)} simulations")
    archive = make_archive(_config(args), seed)
    archive.add(
        np.array([None] * n, dtype=object),
        np.asarray(rec.distances[:n]),
        descriptor_values(rec.grids[:n], MOURET_CLUNE_2015),
    )
    st = archive_stats(archive)
    return {"qd_score": st["qd_score"], "coverage": st["coverage"], "best": st["qd_best"]}, wall


def _config(args) -> QDConfig:
    return QDConfig(descriptors=MOURET_CLUNE_2015, cells=(args.cells,))


def _fmt(values) -> str:
    q1, med, q3 = np.percentile(values, [25, 50, 75])
    return f"{med:.3g} [{q1:.3g}, {q3:.3g}]"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true",
                    help="4x4x4 robots, 1.5 s, budget 160, 32 x 32 cells (a few minutes)")  # fmt: skip
    ap.add_argument("--seeds", type=int, default=5)
    ap.add_argument("--budget", type=int, help="simulations per run (default 2000; quick 160)")
    ap.add_argument("--batch", type=int, default=16, help="robots per generation (all methods)")
    ap.add_argument("--shape", type=int, nargs=3, help="robot grid (default 6 6 6; quick 4 4 4)")
    ap.add_argument("--seconds", type=float, help="simulated seconds (default 5; quick 1.5)")
    ap.add_argument("--cells", type=int, help="cells per descriptor (default 128; quick 32)")
    ap.add_argument("--methods", nargs="+", choices=METHODS, default=list(METHODS))
    ap.add_argument("--out", help="keep the run folders here (default: a temporary folder)")
    ap.add_argument("--json", action="store_true", help="print a JSON line at the end")
    ap.add_argument("--no-append", action="store_true", help="do not append to RESULTS.md")
    args = ap.parse_args(argv)
    q = args.quick
    args.budget = args.budget or (160 if q else 2000)
    args.shape = args.shape or ([4, 4, 4] if q else [6, 6, 6])
    args.seconds = args.seconds or (1.5 if q else 5.0)
    args.cells = args.cells or (32 if q else 128)

    results: dict[str, list[dict[str, float]]] = {m: [] for m in args.methods}
    walls: dict[str, float] = dict.fromkeys(args.methods, 0.0)
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(args.out or tmp)
        for seed in range(args.seeds):
            for m in args.methods:
                res, wall = run_method(m, seed, args, root / f"seed-{seed}")
                results[m].append(res)
                walls[m] += wall
                print(f"seed {seed} {m:10s} QD-score {res['qd_score']:8.3f}  coverage "
                      f"{res['coverage']:.4f}  best {res['best']:.3f}  {wall:6.1f} s", flush=True)  # fmt: skip

    head = (f"{args.seeds} seeds, {args.budget} simulations each, {'x'.join(map(str, args.shape))} "
            f"CPPN robots, {args.seconds} s simulated, batch {args.batch}; archive stiff x filled, "
            f"{args.cells} x {args.cells} cells")  # fmt: skip
    lines = [head, "", "| method | QD-score | coverage | best distance (voxel lengths) | wall s |",
             "|---|---|---|---|---|"]  # fmt: skip
    for m in args.methods:
        cols = [_fmt([r[k] for r in results[m]]) for k in METRICS]
        lines.append(f"| {m} | {' | '.join(cols)} | {walls[m]:.0f} |")
    lines.append("")
    lines.append("Median [25th, 75th percentile] over seeds.")
    if "map-elites" in results:
        for m in args.methods:
            if m == "map-elites":
                continue
            wins = []
            for k in METRICS:
                me = np.array([r[k] for r in results["map-elites"]])
                other = np.array([r[k] for r in results[m]])
                ratio = np.median(me) / np.median(other) if np.median(other) else float("inf")
                wins.append(f"{k} {int((me > other).sum())}/{args.seeds} seeds "
                            f"(median ratio {ratio:.2f}x)")  # fmt: skip
            lines.append(f"MAP-Elites above {m} on the same seed: " + "; ".join(wins) + ".")
    text = "\n".join(lines)
    print()
    print(text)
    if not args.no_append:
        results_log.append(results_log.heading("bench_qd.py", q) + "\n" + text + "\n")
    if args.json:
        print(json.dumps({"results": results, "wall": walls, "args": vars(args)}))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
