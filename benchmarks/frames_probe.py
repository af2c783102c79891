"""The seed model's single-precision frames pass alone, per mix of link modes (a probe).

Builds ``frames_probe.c`` (next to this script) with the flags of the engine's kernel
(setup.py: ``-O3 -ffp-contract=fast -fno-math-errno -fno-trapping-math``) for each
x86-64 level this machine runs. It times the engine's own frames pass
(``softgym_seed_frames32`` from ``softgym/engine/include/softgym_seed.h``, chunk by chunk
as ``links_seed`` calls it) on link geometry with a given share of large-angle links,
and prints time-stamp-counter cycles per 16 links and per voxel-step (at the reference
robot's 2.5 links a voxel). It also checks the probe's results against the engine's
compiled pass (``softgym.engine._core.seed_frames(geom, single=True)``) bit for bit, for
the levels that fuse multiply-adds like the running kernel (links whose rotation the pass
hands to the double-precision fix-up are left out of the comparison):

    python benchmarks/frames_probe.py                        # shares 0, 0.25, 0.5, 1
    python benchmarks/frames_probe.py --large 0.5 --levels x86-64-v4 --flags -mprefer-vector-width=256

A chunk of links all in small-angle mode runs the loop without the large-angle
candidates; any mix computes both for every link. x86-64 only, needs a C compiler
(``cc``). Findings in ``benchmarks/RESULTS.md`` (issue 29).
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from c_probe import LEVELS, build, unavailable  # noqa: E402

CHUNK = 64  # SOFTGYM_CHUNK_LINKS
LINKS_PER_VOXEL = 2.5  # the 6^3 reference robot: 540 links, 216 voxels


def geometry(n: int, large: float, rng: np.random.Generator) -> np.ndarray:
    """(10, n) link geometry as the frames pass reads it: a share ``large`` of the links
    in large-angle mode (relative turns of 0.03-0.3 rad, chords 1-6 degrees off the
    axis), the rest small-angle (turns under 0.01 rad), strains within +-3 %."""
    nom = np.full(n, 0.01)
    is_large = rng.random(n) < large
    strain = rng.uniform(-0.03, 0.03, n)
    off = np.where(is_large, rng.uniform(0.02, 0.1, n), rng.uniform(0.0, 0.008, n))
    phi = rng.uniform(0.0, 2 * np.pi, n)
    length = nom * (1.0 + strain)
    p = np.stack([length * np.cos(off), length * np.sin(off) * np.cos(phi),
                  length * np.sin(off) * np.sin(phi)])  # fmt: skip
    angle = np.where(is_large, rng.uniform(0.03, 0.3, n), rng.uniform(0.0, 0.01, n))
    axis = rng.normal(size=(3, n))
    axis /= np.linalg.norm(axis, axis=0)
    q = np.vstack([np.cos(angle / 2), axis * np.sin(angle / 2)])
    return np.vstack([p, q, nom, np.linalg.norm(p, axis=0), np.where(is_large, 0.0, 1.0)])


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--large", type=float, nargs="+", default=[0.0, 0.25, 0.5, 1.0],
                    help="shares of large-angle links, each in [0, 1]")  # fmt: skip
    ap.add_argument("--chunks", type=int, default=40,
                    help="chunks of 64 links swept (1-4096; 40 keep to the L1 and L2 caches)")  # fmt: skip
    ap.add_argument("--reps", type=int, default=2000, help="sweeps timed, the quickest kept")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--levels", nargs="+", choices=sorted(LEVELS), default=sorted(LEVELS))
    ap.add_argument("--flags", nargs="*", default=[], help="extra compiler flags (experiments)")
    args = ap.parse_args(argv)
    if (
        not 1 <= args.chunks <= 4096
        or args.reps < 1
        or not all(0.0 <= s <= 1.0 for s in args.large)
    ):
        ap.error("--chunks in [1, 4096], --reps >= 1, --large shares in [0, 1]")
    why = unavailable("frames_probe")
    if why:
        print(why)
        return 2
    from softgym.engine import _core
    from softgym.engine._dispatch import FUSED_KERNELS, kernel_build

    engine = kernel_build()
    n = CHUNK * args.chunks
    status = 0
    with tempfile.TemporaryDirectory() as tmp:
        tmpd = Path(tmp)
        inputs = []
        for k, share in enumerate(args.large):
            geom = geometry(n, share, np.random.default_rng(args.seed + k))
            path = tmpd / f"geom{k}.bin"
            with open(path, "wb") as fh:
                fh.write(np.int64(n).astype("<i8").tobytes())
                fh.write(np.ascontiguousarray(geom, dtype="<f8").tobytes())
            inputs.append((share, geom, path))
        for level in args.levels:
            exe = build("frames_probe.c", level, tmpd, args.flags)
            if exe is None:  # (the engine's headers changed under it: a failure)
                status = 1
                continue
            comparable = (level in FUSED_KERNELS) == (engine in FUSED_KERNELS) and not args.flags
            print(f"--- {level} (engine kernel {engine})")
            for k, (share, geom, path) in enumerate(inputs):
                out = tmpd / f"out{k}.bin"
                res = subprocess.run([str(exe), str(path), str(out), str(args.reps)],
                                     capture_output=True, text=True, check=False)  # fmt: skip
                if res.returncode < 0:  # SIGILL: this CPU lacks the level's instructions
                    print("  not run (this CPU lacks its instructions)")
                    break
                if res.returncode != 0:
                    print(res.stdout.rstrip(), res.stderr.rstrip())
                    status = 1
                    break
                per16 = float(res.stdout.split()[-1])
                line = (f"  large-angle share {share:4.2f}: {per16:6.1f} cycles per 16 links, "
                        f"{per16 / 16 * LINKS_PER_VOXEL:5.1f} per voxel-step")  # fmt: skip
                if comparable:
                    probe = np.fromfile(out, dtype="<f4").reshape(12, n)
                    ref = _core.seed_frames(geom, single=True).astype(np.float32)
                    keep = probe[11] == 0.0  # the fix-up's links: redone in double
                    diff = int(
                        np.count_nonzero(
                            probe[:11, keep].view(np.uint32) != ref[:, keep].view(np.uint32)
                        )
                    )
                    line += f"; bit identity: differing {diff} of {11 * int(keep.sum())} values"
                    status |= diff != 0
                print(line)
    return status


if __name__ == "__main__":
    sys.exit(main())
