"""The cost guard's memory estimate against the measured peak RSS (issue 61, item 10).

For solid cubes of k^3 voxels (default config: seed model, self-collision on), each in
a fresh interpreter: import softgym, build a ``Simulation`` and advance it two steps,
then read its peak RSS (``VmHWM`` of ``/proc/self/status``: ``getrusage``'s ``ru_maxrss``
also holds the parent's RSS at the fork, where that is larger); minus the peak RSS of
an interpreter that only imported softgym. Prints that against
``Simulation.estimated_memory["total"]`` (``softgym.engine.layout.memory_estimate``),
and the construction time::

    python benchmarks/bench_memory.py                 # 30, 50, 70 (27k, 125k, 343k voxels)
    python benchmarks/bench_memory.py --sizes 20 30 --model corotational --threads 2
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys

CHILD = r"""
import json, resource, sys, time
import numpy as np
import softgym
from softgym.engine import Body, SimConfig, Simulation

k, model, threads = int(sys.argv[1]), sys.argv[2], int(sys.argv[3])
out = {}
if k > 0:
    body = Body.uniform(np.ones((k, k, k)))
    t0 = time.perf_counter()
    sim = Simulation([body], SimConfig(model=model), n_threads=threads)
    out["build_s"] = time.perf_counter() - t0
    sim.advance(2 * float(sim.dt[0]))
    out["estimate"] = sim.estimated_memory["total"]
    out["voxels"] = sim.n_voxels
try:
    # the peak RSS of this process's memory since its exec: ru_maxrss also keeps the
    # parent's RSS at the fork (Linux carries it over exec), so from a large parent
    # (pytest) every child read the same
    with open("/proc/self/status") as f:
        out["maxrss"] = next(int(x.split()[1]) for x in f if x.startswith("VmHWM:")) * 1024
except OSError:
    out["maxrss"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024  # KiB on Linux
print(json.dumps(out))
"""


def measure(k: int, model: str = "seed", threads: int = 1) -> dict:
    """Peak RSS (bytes) of a fresh interpreter that builds and steps a k^3 cube (k = 0: none)."""
    proc = subprocess.run([sys.executable, "-c", CHILD, str(k), model, str(threads)],
                          capture_output=True, text=True, check=True)
    return json.loads(proc.stdout.strip().splitlines()[-1])


def peak_vs_estimate(k: int, model: str = "seed", threads: int = 1) -> dict:
    """One row: voxels, estimate, measured peak RSS over the import-only baseline (bytes)."""
    base = measure(0, model, threads)["maxrss"]
    r = measure(k, model, threads)
    r["measured"] = r["maxrss"] - base
    r["ratio"] = r["estimate"] / r["measured"]
    return r


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[30, 50, 70])
    ap.add_argument("--model", default="seed", choices=["seed", "corotational"])
    ap.add_argument("--threads", type=int, default=1)
    args = ap.parse_args()
    print(f"model {args.model}, {args.threads} thread(s)")
    print(f"{'cube':>6} {'voxels':>9} {'estimate MB':>12} {'measured MB':>12} {'est/meas':>9} {'build s':>8}")
    for k in args.sizes:
        r = peak_vs_estimate(k, args.model, args.threads)
        print(f"{k:>4}^3 {r['voxels']:>9,} {r['estimate'] / 2**20:>12,.0f} {r['measured'] / 2**20:>12,.0f} "
              f"{r['ratio']:>9.2f} {r['build_s']:>8.2f}", flush=True)


if __name__ == "__main__":
    main()
