"""What a dense-lattice layout would save in the seed model's link passes (a probe).

Builds ``dense_links_probe.c`` (next to this script) with the flags of the engine's
kernel (setup.py: ``-O3 -ffp-contract=fast -fno-math-errno -fno-trapping-math``) for
each x86-64 level this machine runs, and prints, per level, the time-stamp-counter
cycles per voxel-step of the engine's geometry pass (gathers) and force scatter (link
order) beside those of the same passes on a dense lattice (packed rows, a slot per
cell, the forces pulled by each cell), and whether the two agree bit for bit:

    python benchmarks/dense_links_probe.py                  # the 6^3 reference lattice
    python benchmarks/dense_links_probe.py --n 6 --fill 0.6 # a sparser body

x86-64 only, needs a C compiler (``cc``). The probe's findings are in
``benchmarks/RESULTS.md`` (issue 29, session of 2026-12-04, second).
"""

from __future__ import annotations

import argparse
import os
import platform
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
INCLUDE = HERE.parent / "softgym" / "engine" / "include"
FLAGS = ["-O3", "-ffp-contract=fast", "-fno-math-errno", "-fno-trapping-math"]
LEVELS = {"baseline": [], "x86-64-v3": ["-march=x86-64-v3"], "x86-64-v4": ["-march=x86-64-v4"]}


def build(level: str, out: Path) -> Path | None:
    """The probe compiled for ``level`` in ``out``, or None if the compiler refuses."""
    exe = out / f"dense_links_probe_{level}"
    cmd = [os.environ.get("CC", "cc"), *FLAGS, *LEVELS[level], f"-I{INCLUDE}",
           str(HERE / "dense_links_probe.c"), "-o", str(exe), "-lm"]  # fmt: skip
    res = subprocess.run(cmd, capture_output=True, text=True, check=False)
    if res.returncode != 0:
        print(f"{level}: the compiler refused it ({res.stderr.strip().splitlines()[-1:]})")
        return None
    return exe


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--n", type=int, default=6, help="lattice edge (voxels), 2-40")
    ap.add_argument("--fill", type=float, default=1.0, help="share of occupied cells, (0, 1]")
    ap.add_argument("--seed", type=int, default=7, help="seed of the body and state")
    ap.add_argument("--levels", nargs="+", choices=sorted(LEVELS), default=sorted(LEVELS))
    args = ap.parse_args(argv)
    if not 2 <= args.n <= 40 or not 0.0 < args.fill <= 1.0:
        ap.error("--n in [2, 40], --fill in (0, 1]")
    if platform.machine().lower() not in {"x86_64", "amd64"}:
        print("dense_links_probe: x86-64 only (it reads the time-stamp counter)")
        return 2
    if shutil.which(os.environ.get("CC", "cc")) is None:
        print("dense_links_probe: no C compiler (cc) on PATH")
        return 2
    status = 0
    with tempfile.TemporaryDirectory() as tmp:
        for level in args.levels:
            exe = build(level, Path(tmp))
            if exe is None:  # (the engine's headers changed under it: a failure)
                status = 1
                continue
            res = subprocess.run([str(exe), str(args.n), str(args.fill), str(args.seed)],
                                 capture_output=True, text=True, check=False)  # fmt: skip
            if res.returncode < 0:  # SIGILL: this CPU lacks the level's instructions
                print(f"{level}: not run (this CPU lacks its instructions)")
                continue
            print(f"--- {level}")
            print(res.stdout.rstrip())
            if res.returncode != 0:
                print(res.stderr.rstrip())
                status = 1
    return status


if __name__ == "__main__":
    sys.exit(main())
