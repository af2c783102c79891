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
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from c_probe import LEVELS, build, unavailable  # noqa: E402


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--n", type=int, default=6, help="lattice edge (voxels), 2-40")
    ap.add_argument("--fill", type=float, default=1.0, help="share of occupied cells, (0, 1]")
    ap.add_argument("--seed", type=int, default=7, help="seed of the body and state")
    ap.add_argument("--levels", nargs="+", choices=sorted(LEVELS), default=sorted(LEVELS))
    args = ap.parse_args(argv)
    if not 2 <= args.n <= 40 or not 0.0 < args.fill <= 1.0:
        ap.error("--n in [2, 40], --fill in (0, 1]")
    why = unavailable("dense_links_probe")
    if why:
        print(why)
        return 2
    status = 0
    with tempfile.TemporaryDirectory() as tmp:
        for level in args.levels:
            exe = build("dense_links_probe.c", level, Path(tmp))
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
