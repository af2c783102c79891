"""Wall time of a preset in two or more checkouts, alternating: which build is faster.

On a shared VM the same build's time moves by 20 % from run to run, more than most
single kernel changes; a median of a few runs of each build in turn does not
resolve them. This script alternates the builds round after round (build A, build
B, build A, ...), runs the reference robot (``bench_engine.reference_design``,
alone, self-collision on, one thread, ``--seconds`` simulated) ``--runs`` times per
turn and keeps the quickest, then prints each build's minimum and median over the
rounds and their ratios to the first build. A background load that comes and goes
falls on every build alike.

Each tree must be a checkout whose extensions are built in place
(``python setup.py build_ext --inplace``). Its runs import softgym from that tree
(``PYTHONPATH``), which the script checks: run from a copy, the other scripts in
``benchmarks/`` import the installed (editable) checkout instead.

    python benchmarks/compare_builds.py /tmp/before . --rounds 10
    python benchmarks/compare_builds.py /tmp/before . --model corotational
    python benchmarks/compare_builds.py /tmp/before . --box-fence   # the scalar voxel loop

``--box-fence`` runs the robot in the seed's fence as terrain boxes with surface contact
(``Terrain.fence()``, ``box_contact="surface"``): a robot with terrain boxes steps every
voxel in the voxel update's scalar loop, which the reference run does not exercise.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
from pathlib import Path

from tree_run import run_in_tree

CHILD = """
import json, sys, time
sys.path.insert(0, {bench!r})
import softgym
from bench_engine import reference_design
from softgym.engine import SimConfig, Simulation
design = reference_design()
terrain = None
if {box_fence!r}:
    import dataclasses
    from softgym.terrain import Terrain
    terrain = dataclasses.replace(Terrain.fence(), box_contact="surface")
best = float("inf")
for _ in range({runs}):
    sim = Simulation([design.to_body()], SimConfig(self_collision=True, model={model!r}),
                     terrain=terrain, n_threads=1)
    t0 = time.perf_counter()
    sim.run({seconds})
    best = min(best, time.perf_counter() - t0)
print("RESULT " + json.dumps({{"best": best, "module": softgym.__file__, "model": sim.config.model}}))
"""


def run_once(tree: Path, runs: int, seconds: float, model: str = "seed",
             box_fence: bool = False) -> float:
    """The quickest of ``runs`` runs of the reference robot with the softgym of ``tree`` (s);
    with ``box_fence``, in the seed's fence as terrain boxes."""
    code = CHILD.format(bench=str(tree / "benchmarks"), runs=runs, seconds=seconds, model=model,
                        box_fence=bool(box_fence))
    out = run_in_tree(tree, code, "RESULT", "compare_builds", env={"OMP_NUM_THREADS": "1"})
    if out["model"] != model:
        raise SystemExit(f"compare_builds: the run in {tree} stepped {out['model']!r}, not {model!r}")
    return float(out["best"])


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("trees", nargs="+", help="checkouts with built extensions (two or more)")
    ap.add_argument("--rounds", type=int, default=10, help="turns of every build")
    ap.add_argument("--runs", type=int, default=3, help="runs per turn, the quickest kept")
    ap.add_argument("--seconds", type=float, default=5.0, help="simulated time per run")
    ap.add_argument("--model", choices=("seed", "corotational"), default="seed",
                    help="the preset (SimConfig.model) to time")
    ap.add_argument("--box-fence", action="store_true",
                    help="the robot in the seed's fence as terrain boxes (the scalar voxel loop)")
    ap.add_argument("--json", action="store_true", help="print one JSON object as the last line")
    args = ap.parse_args(argv)
    trees = [Path(t).resolve() for t in args.trees]
    if len(trees) < 2:
        ap.error("give two or more trees")
    if args.rounds < 1 or args.runs < 1 or not args.seconds > 0:
        ap.error("--rounds and --runs must be >= 1, --seconds > 0")
    times: list[list[float]] = [[] for _ in trees]
    for k in range(args.rounds):
        row = [run_once(t, args.runs, args.seconds, args.model, args.box_fence) for t in trees]
        for col, t in zip(times, row):
            col.append(t)
        print(f"round {k + 1:3d}: " + "  ".join(f"{t:.4f} s" for t in row), flush=True)
    base_min, base_med = min(times[0]), statistics.median(times[0])
    summary = []
    for tree, col in zip(trees, times):
        lo, med = min(col), statistics.median(col)
        summary.append({"tree": str(tree), "min_s": lo, "median_s": med,
                        "speedup_min": base_min / lo, "speedup_median": base_med / med})  # fmt: skip
        print(f"{str(tree):40s} min {lo:.4f} s  median {med:.4f} s  "
              f"speed-up vs the first: {base_min / lo:.3f}x (minima), {base_med / med:.3f}x (medians)")
    if args.json:
        print(json.dumps({"rounds": args.rounds, "runs": args.runs, "seconds": args.seconds,
                          "model": args.model, "box_fence": args.box_fence,
                          "builds": summary}))  # fmt: skip
    return 0


if __name__ == "__main__":
    sys.exit(main())
