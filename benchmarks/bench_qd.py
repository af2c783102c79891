"""MAP-Elites against NSGA-II and the seed's novelty search at the same number of simulations.

Three searches over CPPN robots (the ``basic`` experiment's bodies on flat
ground) each get the same budget of simulations (distinct phenotypes; cache
hits are free for all three) and the same seeds:

* ``map-elites``: :class:`evolvers.drivers.qd.QDRun` (pyribs GridArchive, stiff x
  filled descriptors, softgym's mutation);
* ``nsga2``: :class:`evolvers.drivers.pymoo_runner.PymooRun` on ``basic`` (distance up,
  muscle voxels down);
* ``novelty``: :class:`evolvers.drivers.runner.EvolutionRun` on ``novelty`` (the seed's
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
    python benchmarks/bench_qd.py --seeds 5 --budget 1000 --data benchmarks/data/qd/qd_6x6x6_1000.json \
        --figure docs/figures/qd_6x6x6_1000.png            # resumable; redraws from the stored runs
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
from pathlib import Path

import numpy as np
import results_log

from evolvers.drivers.pymoo_runner import PymooRun
from evolvers.drivers.qd import QDConfig, QDRun, archive_stats, make_archive
from evolvers.drivers.runner import EvolutionRun
from evolvers.evaluation.descriptors import MOURET_CLUNE_2015, descriptor_values
from evolvers.evaluation.evaluator import local_batch_fn
from evolvers.evaluation.experiments import get_experiment
from softgym.io import atomic_write_text

METHODS = ("map-elites", "nsga2", "novelty")
METRICS = ("qd_score", "coverage", "best")
CURVE_POINTS = 10


class BudgetReached(Exception):
    """Raised from a run's on_generation once the budget of simulations is spent."""


class RecordingBatchFn:
    """A batch_fn that simulates locally and keeps every simulated robot's grid and distance."""

    def __init__(self) -> None:
        self.grids: list[np.ndarray] = []
        self.distances: list[float] = []

    def __call__(self, designs, task):
        res = local_batch_fn(designs, task, progress=False)  # the script prints one line a run
        for d, dist, div in zip(designs, res["norm_final_dist"], res["diverged"]):
            self.grids.append(np.asarray(d.grid))  # the evaluator passes RobotDesigns
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
    distances = np.asarray(rec.distances[:n])
    descriptors = descriptor_values(rec.grids[:n], MOURET_CLUNE_2015)
    # the archive after every tenth of the budget, in the order the search simulated them
    # (adding in chunks keeps the best robot of each cell, as one add of all of them would)
    curve = []
    marks = np.unique(np.linspace(0, n, CURVE_POINTS + 1).astype(int))
    for lo, hi in zip(marks[:-1], marks[1:]):
        archive.add(
            np.array([None] * (hi - lo), dtype=object), distances[lo:hi], descriptors[lo:hi]
        )
        st = archive_stats(archive)
        curve.append([int(hi), st["qd_score"], st["coverage"], st["qd_best"]])
    return {"qd_score": st["qd_score"], "coverage": st["coverage"], "best": st["qd_best"],
            "curve": curve}, wall  # fmt: skip


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
    ap.add_argument("--data", help="JSON file of finished runs: each (method, seed) is stored as "
                    "it ends and skipped when the same command is run again (resume)")  # fmt: skip
    ap.add_argument("--figure", help="draw QD-score, coverage and best against simulations here")
    ap.add_argument("--json", action="store_true", help="print a JSON line at the end")
    ap.add_argument("--no-append", action="store_true", help="do not append to RESULTS.md")
    args = ap.parse_args(argv)
    q = args.quick
    args.budget = args.budget or (160 if q else 2000)
    args.shape = args.shape or ([4, 4, 4] if q else [6, 6, 6])
    args.seconds = args.seconds or (1.5 if q else 5.0)
    args.cells = args.cells or (32 if q else 128)

    config = {k: getattr(args, k) for k in ("budget", "batch", "shape", "seconds", "cells")}
    store = _load_store(args.data, config)
    results: dict[str, list[dict[str, float]]] = {m: [] for m in args.methods}
    walls: dict[str, float] = dict.fromkeys(args.methods, 0.0)
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(args.out or tmp)
        for seed in range(args.seeds):
            for m in args.methods:
                key = f"{m}/{seed}"
                if key in store["runs"]:
                    res, wall = store["runs"][key], store["runs"][key]["wall"]
                    print(f"seed {seed} {m:10s} (stored in {args.data})", flush=True)
                else:
                    res, wall = run_method(m, seed, args, root / f"seed-{seed}")
                    if args.data:
                        store["runs"][key] = {**res, "wall": wall}
                        atomic_write_text(args.data, json.dumps(store, indent=1) + "\n")
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
    if args.figure:
        _figure(results, args)
        print(f"wrote {args.figure}")
    if args.json:
        print(json.dumps({"results": results, "wall": walls, "args": vars(args)}))
    return 0


def _load_store(path: str | None, config: dict) -> dict:
    """The ``--data`` file's runs (empty if none); refuses a file made with other sizes."""
    if not path or not Path(path).exists():
        return {"config": config, "runs": {}}
    store = json.loads(Path(path).read_text())
    if store.get("config") != config:
        raise SystemExit(f"bench_qd: {path} holds runs of {store.get('config')}, not {config}; "
                         "use another --data file")  # fmt: skip
    return store


def _figure(results: dict[str, list[dict]], args) -> None:
    """QD-score, coverage and best distance against simulations: median and IQR over seeds."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    labels = {"qd_score": "QD-score (sum of elites' distances,\nvoxel lengths)",
              "coverage": "coverage (filled cells / cells)",
              "best": "best distance (voxel lengths)"}  # fmt: skip
    fig, axes = plt.subplots(1, 3, figsize=(12, 3.8), layout="constrained")
    for m, runs in results.items():
        curves = np.array([r["curve"] for r in runs])  # seeds x points x (n, qd, coverage, best)
        x = curves[0, :, 0]
        for ax, col in zip(axes, (1, 2, 3)):
            q1, med, q3 = np.percentile(curves[:, :, col], [25, 50, 75], axis=0)
            (line,) = ax.plot(x, med, label=f"{m} ({len(runs)} seeds)")
            ax.fill_between(x, q1, q3, color=line.get_color(), alpha=0.2, lw=0)
    for ax, key in zip(axes, METRICS):
        ax.set_xlabel("simulations")
        ax.set_ylabel(labels[key])
        ax.grid(alpha=0.3)
    axes[0].legend(loc="upper left", fontsize=8)
    shape = "x".join(map(str, args.shape))
    fig.suptitle(f"MAP-Elites vs NSGA-II vs novelty search: {shape} CPPN robots, {args.seconds:g} s, "
                 f"archive stiff x filled, {args.cells} x {args.cells} cells (median, IQR)")  # fmt: skip
    fig.savefig(args.figure, dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    raise SystemExit(main())
