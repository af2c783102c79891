"""Bit-identity check of the "seed" preset's kernel against a saved reference.

Runs a varied set of designs through ``SimConfig(model="seed")`` and saves, or
compares exactly (``np.array_equal`` on every byte-for-byte state array, no
tolerance), the full dynamic state after a few thousand steps: positions,
velocities, orientations, angular velocities, rotation matrices, sizes, the
links' mode and memory, the centre-of-mass traces and the metrics.

Cases: the default walker, the benchmark's reference robot (self-collision off),
seed-style random CPPN bodies (plain, with bone, obstacle rules, mutated) under
the three actuation regimes, bodies on the seed's fence, an evolved design with
light materials (``--vxa``), and a body dropped from a height (large-angle links);
each robot alone and the whole set as one batch, on 1 and 2 threads.

    # with the unmodified build: write the reference
    PYTHONPATH=/work/main python benchmarks/check_bitident.py --save /tmp/speed_ref.npz
    # with the modified build: compare
    PYTHONPATH=. python benchmarks/check_bitident.py --compare /tmp/speed_ref.npz
    # every build of the kernel (softgym/engine/_dispatch.py) against the same reference
    SOFTGYM_KERNEL=baseline python benchmarks/check_bitident.py --compare /tmp/speed_ref.npz
    # the same for the corotational preset's kernel
    python benchmarks/check_bitident.py --model corotational --save /tmp/corot_ref.npz
    # the same for the seed model's double-precision link operations (the default
    # is its single-precision link math)
    python benchmarks/check_bitident.py --link-precision double --save /tmp/double_ref.npz
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from softgym.design.robot import default_walker  # noqa: E402
from softgym.engine import SimConfig, Simulation  # noqa: E402
from softgym.terrain import Terrain  # noqa: E402

VXA = "/work/runs/study/materials-t1/seed-0/best_design.vxa"


def cases(quick: bool = False, vxa: str | None = VXA):
    """[(name, design or body, terrain or None, self_collision)]"""
    import fidelity_cases as fc
    from bench_engine import reference_robot

    out = [("walker", default_walker(), None, True),
           ("reference6_nocol", reference_robot(6), None, False),
           ("reference4_col", reference_robot(4), None, True)]  # fmt: skip
    rnd = {c.name: c for c in fc.random_bodies()}
    picks = ["rand_p00", "rand_p03", "rand_p07", "rand_b00", "rand_b05", "rand_o01", "rand_m02_x3"]
    if quick:
        picks = picks[:3]
    regimes = ["gentle", "medium", "strong"]
    for k, name in enumerate(picks):
        regime = regimes[k % 3]
        out.append((f"{name}_{regime}", fc.case_design(rnd[name], regime), None, True))
    fence = fc.fence_cases()
    fence_t = Terrain.fence(inner=10, height=1, thickness=1, center=(3, 3))
    for c in fence[:: (8 if quick else 4)]:
        out.append((f"{c.name}_strong", fc.case_design(c, "strong"), fence_t, True))
    # a body dropped from 3 voxel lengths: a hard landing bends links out of
    # the small-angle mode
    walker = fc.case_design(rnd["rand_p01"], "strong")
    out.append(("dropped_p01", walker.to_body(origin=(0.0, 0.0, 0.03)), None, True))
    if vxa and os.path.exists(vxa):
        from softgym.design.vxa import from_vxa

        out.append(("vxa_light", from_vxa(Path(vxa).read_bytes()), None, True))
    else:
        print(f"warning: {vxa} not found, the light-material case is skipped", file=sys.stderr)
    return out


def state_of(sim: Simulation, robot: int, rollout) -> dict[str, np.ndarray]:
    """Every per-robot array worth comparing, from a batch."""
    a = sim._a
    vlo, vhi = int(a["vox_start"][robot]), int(a["vox_start"][robot + 1])
    llo, lhi = int(a["link_start"][robot]), int(a["link_start"][robot + 1])
    out = {}
    for k in ("pos", "vel", "quat", "angvel", "rot", "scale", "col_ref"):
        out[k] = np.array(a[k][vlo:vhi])
    out["link_sa"] = np.array(a["link_sa"][llo:lhi], dtype=np.int8)  # as states show it
    last = a["link_last"]
    # (n_links, 9) before the speed work, (9, n_links) after: compared as (n_links, 9)
    out["link_last"] = np.array(last[llo:lhi] if last.shape == (sim.n_links, 9) else last[:, llo:lhi].T)
    for k in ("steps", "diverged", "diverged_code", "diverged_time", "cm_init", "col_acc",
              "col_vmax", "aux_init", "trace_n"):  # fmt: skip
        out[k] = np.array(a[k][robot])
    n = int(a["trace_n"][robot])
    for k in ("trace_t", "trace_cm", "trace_aux"):
        out[k] = np.array(a[k][robot, :n])
    for k, v in rollout.__dict__.items() if hasattr(rollout, "__dict__") else ():
        if isinstance(v, np.ndarray) and v.ndim >= 1 and v.shape[0] == sim.n_robots:
            out["rollout_" + k] = np.array(v[robot])
    return out


def run_all(seconds: float, quick: bool, vxa: str | None, log=print, model: str = "seed",
            link_precision: str | None = None):
    """{key: array} of every case alone (1 and 2 threads) and all in batches."""
    res = {}
    cs = cases(quick, vxa)
    for threads in (1, 2):
        for col in (True, False):
            group = [c for c in cs if c[3] == col]
            # each robot alone
            for name, d, terr, _ in group:
                t0 = time.perf_counter()
                sim = Simulation([d], SimConfig(model=model, self_collision=col,
                                                link_precision=link_precision),
                                 n_threads=threads, terrain=terr)  # fmt: skip
                ro = sim.run(seconds)
                for k, v in state_of(sim, 0, ro).items():
                    res[f"alone/t{threads}/{name}/{k}"] = v
                if threads == 1:
                    sa = sim._a["link_sa"]
                    log(f"  {name:28s} voxels {sim.n_voxels:4d} links {sim.n_links:4d} "
                        f"steps {int(sim._a['steps'][0]):6d} large-angle links at end "
                        f"{int((sa == 0).sum()):4d} diverged {bool(sim.diverged[0])} "
                        f"({time.perf_counter() - t0:.1f} s)")  # fmt: skip
            # all of them in one batch (per-robot terrains)
            cfg = SimConfig(model=model, self_collision=col, link_precision=link_precision)
            sim = Simulation([d for _, d, _, _ in group], cfg,
                             n_threads=threads, terrain=[t or Terrain.flat() for _, _, t, _ in group])  # fmt: skip
            ro = sim.run(seconds)
            for r, (name, _, _, _) in enumerate(group):
                for k, v in state_of(sim, r, ro).items():
                    res[f"batch/t{threads}/{name}/{k}"] = v
    return res


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    g = ap.add_mutually_exclusive_group(required=True)
    g.add_argument("--save", metavar="NPZ")
    g.add_argument("--compare", metavar="NPZ")
    ap.add_argument("--seconds", type=float, default=1.5, help="simulated time per run")
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--vxa", default=VXA)
    ap.add_argument("--model", default="seed", choices=("seed", "corotational"),
                    help="preset whose kernel is checked (a reference holds one preset)")
    ap.add_argument("--link-precision", default=None, choices=("double", "single"),
                    help="SimConfig.link_precision (a reference holds one)")
    args = ap.parse_args(argv)
    import softgym.engine._core as core
    from softgym.engine import kernel_build

    print(f"engine: {core.__file__} (kernel build {kernel_build()})", file=sys.stderr)
    res = run_all(args.seconds, args.quick, args.vxa, log=lambda s: print(s, file=sys.stderr),
                  model=args.model, link_precision=args.link_precision)
    # alone vs batch must agree too (the kernel's own promise)
    bad = [k for k in res if k.startswith("batch/") and not k.endswith("/rollout_" + "")
           and k.replace("batch/", "alone/", 1) in res
           and not np.array_equal(res[k], res[k.replace("batch/", "alone/", 1)])]  # fmt: skip
    bad = [k for k in bad if "/rollout_" not in k]
    if bad:
        print(f"note: {len(bad)} arrays differ between batch and alone (same build): {bad[:5]}",
              file=sys.stderr)  # fmt: skip
    if args.save:
        np.savez_compressed(args.save, **res)
        print(f"saved {len(res)} arrays to {args.save}")
        return 0
    ref = dict(np.load(args.compare))
    missing = sorted(set(ref) ^ set(res))
    diff = [k for k in sorted(set(ref) & set(res))
            if ref[k].dtype != res[k].dtype or ref[k].shape != res[k].shape
            or ref[k].tobytes() != res[k].tobytes()]  # fmt: skip
    if missing:
        print(f"MISSING/EXTRA keys: {missing[:10]} ({len(missing)})")
    if diff:
        print(f"DIFFERENT: {len(diff)} of {len(ref)} arrays, e.g.:")
        for k in diff[:15]:
            a, b = ref[k], res[k]
            d = np.max(np.abs(a.astype(float) - b.astype(float))) if a.shape == b.shape else "shape"
            print(f"  {k}: max |diff| {d}")
        return 1
    if missing:
        return 1
    print(f"BIT-IDENTICAL: {len(ref)} arrays")
    return 0


if __name__ == "__main__":
    sys.exit(main())
