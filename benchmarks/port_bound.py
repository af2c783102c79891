"""Static port bound of the engine's hot loops (llvm-mca), against the measured cycles.

The VM this project runs on exposes no hardware counters (``perf`` offers software
events only), so whether a pass is bound by its instructions or by something else
(latency, store forwarding, the divider's queue) cannot be read off a counter. This
script gives the other half of the answer. It disassembles the x86-64-v4 build of the
engine with its line tables, finds each pass's innermost vector loop (attributed by the
inlined function its instructions come from), and asks LLVM's machine-code analyser
(``llvm-mca``, which models a core's ports and latencies) how many core cycles an
iteration needs at best. Divided by the links (or voxels) an iteration handles and
scaled to a voxel-step of the reference robot, that is the pass's floor on that core
model; ``profile_engine.py --cycles`` measures what the pass takes.

    python benchmarks/port_bound.py                  # the in-place build, seed preset
    python benchmarks/port_bound.py --model corotational
    python benchmarks/port_bound.py --build DIR      # another tree, built in place
    python benchmarks/port_bound.py --cpu icelake-server --calibrate --json

The in-place build has the line tables where Python's compiler flags carry -g (they
usually do); where they do not, a copy of the tree is built with CFLAGS=-g.

LLVM 14's model of ``sapphirerapids`` is Skylake-server's (its resources are named
SKXPort0-7: two load ports where Sapphire Rapids has three, one store-data port where it
has two), so the floors are those of the older core and, for load-heavy loops, above the
newer one's. ``--calibrate`` also times a chain of dependent integer additions (one core
cycle each) against the time-stamp counter, which ``profile_engine.py --cycles`` counts in:
core cycles per TSC cycle, to put the two in one unit (the clock under 512-bit code may
be lower).

A loop with a branch inside (the scatter's carried rows along x) is analysed as one
straight run of both paths: its floor is an upper bound of the path taken. The seed
scatter is its AVX-512 loop of 8 links (the links before and after its blocks go one by
one). The seed geometry's
paths are reported apart (its rows path is a loop of its own; its gather path is taken
as the rows loop's arithmetic with the gathers in place of the rows' loads). Needs ``objdump`` (binutils) and ``llvm-mca`` (LLVM) on the
PATH; the numbers are a model's, not a measurement.
"""

from __future__ import annotations

import argparse
import collections
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

from tree_run import build_tree, copy_tree

ROOT = Path(__file__).resolve().parent.parent

# the inlined functions each pass's instructions come from (objdump -l names them);
# helpers shared by several passes (the record/row transposes) count for none
SEED_PASSES = {
    "geometry": ("softgym_seed_geom_ax", "softgym_seed_gather", "softgym_seed_gather4",
                 "softgym_seed_gather_rows", "softgym_seed_rows8", "softgym_seed_modes8v"),
    "modes": ("softgym_seed_modes",),
    "frames (float)": ("softgym_seed_frames32_impl", "softgym_rotvec_k32",
                       "softgym_rotvec_k32_acos", "softgym_seed_frames32_x2"),
    "forces (float)": ("softgym_seed_forces32", "softgym_seed_forces32_impl",
                       "softgym_seed_forces32_small", "softgym_seed_forces32_mixed",
                       "softgym_seed_forces32_neg2", "softgym_seed_forces32_small_neg2",
                       "softgym_seed_forces32_block16"),
    "scatter": ("softgym_seed_push32_ax", "softgym_seed_push32_16", "softgym_push16",
                "softgym_seed_push32_links"),
    "voxel update": ("softgym_seed_voxels8", "softgym_v8_finish"),
}
COROT_PASSES = {
    "links": ("softgym_corot_links_ax",),
    "scatter": ("softgym_corot_scatter",),
    "voxel update": ("softgym_corot_voxels8", "softgym_v8_finish"),
}
# the geometry's two paths for 8 links: the voxels' records loaded as rows (a loop of its
# own while the runs last) and gathered (the rest of the loop around it)
GEOMETRY_PATHS = ("  rows path", "  gather path")
# per model: its passes, its link module, the voxel loop's symbol (the lanes inlined there)
MODELS = {
    "seed": (SEED_PASSES, "_seed", "integrate_integrate_seed"),
    "corotational": (COROT_PASSES, "_corotational", "integrate_integrate_corotational"),
}
# what one iteration of a pass's main loop handles: links, except the voxel update (the
# seed preset's float push takes blocks of 16 links, both their sides, the corotational
# scatter blocks of 8 with AVX-512; the corotational links 8 a vector from its voxels'
# rows; the float frames' main loop in the x86-64-v4 build is its pairs of 16-lane blocks,
# softgym_seed_frames32_x2)
PER_ITERATION = {"geometry": 8, "  rows path": 8, "  gather path": 8, "modes": 8,
                 "frames (float)": 32, "forces (float)": 16, "scatter": 16, "voxel update": 8,
                 "links": 8}
PER_ITERATION_OF = {"seed": PER_ITERATION, "corotational": {**PER_ITERATION, "scatter": 8}}


def build_copy(dest: Path) -> Path:
    """A copy of the working tree, built in place with -g (line tables)."""
    copy_tree(dest)
    cflags = (os.environ.get("CFLAGS", "") + " -g").strip()
    build_tree(dest, {"CFLAGS": cflags}, "port_bound", "the build with -g")
    return dest


def disassemble(so: Path) -> list[tuple[int, str, str, str]]:
    """(address, symbol, inlined function, instruction) for every instruction of `so`."""
    out = subprocess.run(["objdump", "-d", "-l", "--no-show-raw-insn", "-M", "att", str(so)],
                         capture_output=True, text=True, check=True).stdout
    rows, sym, fn = [], None, None
    for line in out.splitlines():
        m = re.match(r"^[0-9a-f]+ <(.+)>:$", line)
        if m:
            sym = fn = m.group(1)
            continue
        m = re.match(r"^([A-Za-z_]\w*)\(\):$", line)
        if m:
            fn = m.group(1)
            continue
        m = re.match(r"^\s+([0-9a-f]+):\s+(.*)$", line)
        if m and sym:
            rows.append((int(m.group(1), 16), sym, fn, m.group(2).split("#")[0].strip()))
    return rows


def all_loops(rows):
    """Index ranges [start, end] of loops: a conditional jump back within a symbol."""
    at = {a: k for k, (a, *_rest) in enumerate(rows)}
    loops = []
    for k, (a, sym, _fn, text) in enumerate(rows):
        m = re.match(r"^(j\w+)\s+([0-9a-f]+) <", text)
        if m and m.group(1) != "jmp":
            target = int(m.group(2), 16)
            if target <= a and target in at and rows[at[target]][1] == sym:
                loops.append((at[target], k))
    return loops


def innermost_loops(rows):
    """The loops with no loop inside."""
    loops = all_loops(rows)
    return [(s, e) for s, e in loops
            if not any(s <= s2 and e2 <= e and (s2, e2) != (s, e) for s2, e2 in loops)]


def pass_of(rows, s, e, passes) -> str | None:
    counts = collections.Counter()
    for _a, _sym, fn, _t in rows[s:e + 1]:
        for name, fns in passes.items():
            if fn in fns:
                counts[name] += 1
    if not counts:
        return None
    name, n = counts.most_common(1)[0]
    return name if n >= (e - s + 1) // 3 else None


def mca(body: list[str], cpu: str) -> dict:
    """llvm-mca's figures for the straight run `body` repeated."""
    src = ".Ltop:\n" + "\n".join(body) + "\n"
    r = subprocess.run(["llvm-mca", f"-mcpu={cpu}", "-iterations=100"], input=src,
                       capture_output=True, text=True)
    if r.returncode != 0:
        raise SystemExit(f"port_bound: llvm-mca failed: {r.stderr.strip()[:300]}")

    def num(key):
        m = re.search(rf"{key}:\s+([\d.]+)", r.stdout)
        return float(m.group(1)) if m else float("nan")

    return {"rthroughput": num("Block RThroughput"), "cycles": num("Total Cycles") / 100,
            "uops": num("Total uOps") / 100}


# instructions left out of a body: branches (it runs as one straight block), padding
SKIP = ("j", "call", "nop", "data16", "cs nop", "xchg   %ax,%ax", "ret")
# the voxel update's helpers (record/row transposes, intrinsics) inlined with it
VOXEL_HELPERS = ("softgym_v8_", "_mm512_", "_mm256_")


def loop_body(rows, s, e) -> list[str]:
    return [text for _a, _sym, _fn, text in rows[s:e + 1] if not text.startswith(SKIP)]


def find_loops(tree: Path, model: str = "seed") -> dict[str, tuple] | None:
    """Each pass's largest innermost loop in the x86-64-v4 build of `tree` (None: no
    such build; empty: no line tables to attribute the loops by)."""
    passes, link_module, voxel_symbol = MODELS[model]
    best: dict[str, tuple] = {}
    for mod in (link_module, "_integrate"):
        sos = sorted((tree / "softgym" / "engine" / "_x86_64_v4").glob(f"{mod}.*.so"))
        if not sos:
            return None
        rows = disassemble(sos[0])
        if mod == "_integrate":
            # the voxel update's lanes are straight code (8 voxels a block) inlined into
            # the model's voxel loop: its instructions there, as one block
            body = [t for _a, sym, fn, t in rows
                    if sym.endswith(voxel_symbol)
                    and (fn in passes["voxel update"] or fn.startswith(VOXEL_HELPERS))]
            body = [t for t in body if not t.startswith(SKIP)]
            if body:
                best["voxel update"] = (body, 0)
            continue
        for s, e in innermost_loops(rows):
            name = pass_of(rows, s, e, passes)
            body = loop_body(rows, s, e)
            if name == "links" and not _corot_rows_loop(body):
                continue  # the 4-lane gathers, which the x86-64-v4 build no longer runs
            if name and (name not in best or len(body) > len(best[name][0])):
                best[name] = (body, rows[s][0])
        if mod == "_seed":
            _geometry_paths(rows, best)
    return best


def _corot_rows_loop(body) -> bool:
    """Whether a loop of the corotational links is its 8-lane path over runs of voxels (the
    one the reference robot's links along y and z take: 512-bit arithmetic on the voxels'
    rows, no permutes, no gathers), not its window, gather or 4-lane paths."""
    zmm = sum("zmm" in t for t in body)
    return (zmm > len(body) // 2
            and not any(t.startswith(("vpermt2pd", "vpermi2pd", "vgather")) for t in body))


_ROWS_ONLY = ("softgym_seed_rows8", "softgym_v8_load3", "softgym_v8_load4x4",
              "_mm512_permutex2var_pd", "_mm512_loadu_pd")
_GATHER_ONLY = ("softgym_seed_gather", "softgym_seed_gather4", "softgym_seed_gather_rows",
                "_mm512_i64gather_pd", "_mm512_insertf64x4", "_mm512_castpd256_pd512")
# the gather path's loads: from the voxel rows where the seed step keeps its state there
# (AVX-512 builds), else from the records
_GATHER_FNS = ("softgym_seed_gather_rows", "softgym_seed_gather4")


def _geometry_paths(rows, best) -> None:
    """The geometry's rows path (the innermost loop of softgym_seed_rows8) and its gather
    path: GCC folds the gathers, the scalar remainder and the rows loop into one loop nest,
    so the gather path is taken as the rows loop's arithmetic with the gathers (the
    instructions of softgym_seed_gather_rows, or softgym_seed_gather4 where the build
    gathers from the records, and their intrinsics in the smallest loop around them) in
    place of the rows' loads."""
    loops = all_loops(rows)

    def has(s, e, fn_name):
        return any(fn == fn_name for _a, _sym, fn, _t in rows[s:e + 1])

    inner = [(s, e) for s, e in innermost_loops(rows) if has(s, e, "softgym_seed_rows8")]
    outer = next(([(s, e) for s, e in loops if has(s, e, fn)] for fn in _GATHER_FNS
                  if any(has(s, e, fn) for s, e in loops)), [])
    if not inner or not outer:
        return
    s, e = max(inner, key=lambda r: r[1] - r[0])
    best["  rows path"] = (loop_body(rows, s, e), rows[s][0])
    arithmetic = [t for _a, _sym, fn, t in rows[s:e + 1]
                  if not t.startswith(SKIP) and fn not in _ROWS_ONLY]
    def gathers_of(r):
        return [t for _a, _sym, fn, t in rows[r[0]:r[1] + 1] if not t.startswith(SKIP)
                and (fn in _GATHER_ONLY or fn.startswith(("_mm256_", "_mm_")))]

    # the smallest loop among those with the most gather instructions (GCC may also copy
    # a few of the gathers' loads into smaller loops of the nest, without their gathers)
    s, e = min(outer, key=lambda r: (-sum(t.startswith("vgather") for t in gathers_of(r)),
                                     r[1] - r[0]))
    best["  gather path"] = (arithmetic + gathers_of((s, e)), rows[s][0])


CLOCK_C = r"""
#include <stdio.h>
#include <x86intrin.h>
/* core cycles per TSC cycle: 8 dependent integer additions (1 core cycle each); with
   ZMM defined, a chain of dependent 512-bit multiply-adds (4 core cycles each on every
   core with AVX-512 this project runs on: Intel since Skylake-SP, AMD Zen 4 and 5),
   the clock while 512-bit arithmetic runs, which may be lower */
int main(void)
{
    unsigned long long x = 1, y = 3, best = ~0ull;
    const long n = 50000000;
    for (int rep = 0; rep < 5; rep++) {
        unsigned long long t0 = __rdtsc();
#ifdef ZMM
        __m512d a = _mm512_set1_pd(1.0), b = _mm512_set1_pd(0.999999), c = _mm512_set1_pd(1e-9);
        for (long i = 0; i < n; i++) {  /* 2 dependent multiply-adds: 8 core cycles */
            a = _mm512_fmadd_pd(a, b, c);
            a = _mm512_fmadd_pd(a, b, c);
            __asm__ volatile("" : "+v"(a));
        }
        double lanes[8];
        _mm512_storeu_pd(lanes, a);
        x += lanes[0] > 2.0;
#else
        for (long i = 0; i < n; i++)  /* 8 dependent additions: 8 core cycles */
            __asm__ volatile("add %1, %0\n\tadd %1, %0\n\tadd %1, %0\n\tadd %1, %0\n\t"
                             "add %1, %0\n\tadd %1, %0\n\tadd %1, %0\n\tadd %1, %0"
                             : "+r"(x) : "r"(y));
#endif
        unsigned long long t = __rdtsc() - t0;
        if (t < best)
            best = t;
    }
    printf("%.4f\n", 8.0 * n / (double)best);
    return (int)(x & 1);
}
"""


def core_cycles_per_tsc(zmm: bool = False) -> float | None:
    """Core cycles per time-stamp-counter cycle (the fastest of 5 timings), or None
    without a C compiler (``zmm``: under 512-bit multiply-adds, or None where the
    compiler or the CPU has no AVX-512)."""
    cc = shutil.which("cc") or shutil.which("gcc")
    if cc is None:
        return None
    flags = ["-DZMM", "-mavx512f", "-mfma"] if zmm else []
    with tempfile.TemporaryDirectory() as tmp:
        src, exe = Path(tmp) / "clock.c", Path(tmp) / "clock"
        src.write_text(CLOCK_C)
        if subprocess.run([cc, "-O2", *flags, str(src), "-o", str(exe)],
                          capture_output=True).returncode:
            return None
        run = subprocess.run([str(exe)], capture_output=True, text=True)
    if run.returncode not in (0, 1) or not run.stdout.strip():  # (an illegal instruction)
        return None
    return float(run.stdout)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--build", type=Path, default=ROOT,
                    help="a tree built in place (default: this one)")
    ap.add_argument("--cpu", default="sapphirerapids", help="llvm-mca's core model")
    ap.add_argument("--model", choices=tuple(MODELS), default="seed",
                    help="the preset whose passes are analysed")
    ap.add_argument("--links-per-voxel", type=float, default=540 / 216,
                    help="links a voxel-step (the 6^3 reference robot: 540 / 216)")
    ap.add_argument("--calibrate", action="store_true",
                    help="also measure core cycles per time-stamp-counter cycle")
    ap.add_argument("--json", action="store_true", help="print one JSON object as the last line")
    args = ap.parse_args(argv)
    for tool in ("objdump", "llvm-mca"):
        if shutil.which(tool) is None:
            print(f"port_bound: {tool} is not on the PATH", file=sys.stderr)
            return 2
    tmp = None
    best = find_loops(args.build, args.model)
    if best is None:
        print(f"port_bound: no x86-64-v4 build under {args.build} (python setup.py "
              "build_ext --inplace on an x86-64 machine builds one)", file=sys.stderr)
        return 2
    if not best:  # no line tables: a copy built with -g
        tmp = tempfile.TemporaryDirectory()
        best = find_loops(build_copy(Path(tmp.name)), args.model) or {}
    print(f"llvm-mca -mcpu={args.cpu}, {args.model} preset: each pass's main loop in the "
          f"x86-64-v4 build (the "
          f"voxel update: its 8-voxel block); core cycles an iteration and per voxel-step at "
          f"{args.links_per_voxel:.2f} links a voxel")
    print(f"{'pass':18s} {'insns':>6s} {'stack':>6s} {'uops':>6s} {'per iter':>9s} "
          f"{'bound':>7s} {'sim':>7s} {'bound/vs':>9s} {'sim/vs':>7s}")
    total_b = total_s = 0.0
    report = {"cpu": args.cpu, "model": args.model, "links_per_voxel": args.links_per_voxel,
              "passes": {}}
    passes = MODELS[args.model][0]
    names = ("geometry", *GEOMETRY_PATHS, *list(passes)[1:]) if args.model == "seed" else passes
    for name in names:
        if name not in best:
            # the x86-64-v4 build decides the modes in the geometry's loop (modes8v)
            fused = name == "modes" and args.model == "seed" and "geometry" in best
            print(f"{name:18s} " + ("(in the geometry's loop)" if fused else "(loop not found)"))
            continue
        body, _addr = best[name]
        m = mca(body, args.cpu)
        per = PER_ITERATION_OF[args.model][name]
        scale = (1.0 if name == "voxel update" else args.links_per_voxel) / per
        b, c = m["rthroughput"] * scale, m["cycles"] * scale
        stack = sum(bool(re.search(r"\(%r[sb]p\)", t)) for t in body)
        report["passes"][name.strip()] = {
            "instructions": len(body), "stack": stack, "uops": m["uops"], "per_iteration": per,
            "bound": m["rthroughput"], "sim": m["cycles"], "bound_per_voxel_step": b,
            "sim_per_voxel_step": c}
        if name not in GEOMETRY_PATHS:
            total_b += b
            total_s += c
        print(f"{name:18s} {len(body):6d} {stack:6d} {m['uops']:6.0f} {per:9d} "
              f"{m['rthroughput']:7.1f} {m['cycles']:7.1f} {b:9.1f} {c:7.1f}")
    print(f"{'total':18s} {'':6s} {'':6s} {'':6s} {'':9s} {'':7s} {'':7s} {total_b:9.1f} "
          f"{total_s:7.1f}")
    print("stack: instructions of the loop that load or store a stack slot (spilled "
          "registers); bound: llvm-mca's block reciprocal throughput (the ports alone), sim: "
          "its simulated cycles an iteration; /vs: per voxel-step")
    if args.calibrate:
        ratio = core_cycles_per_tsc()
        ratio512 = core_cycles_per_tsc(zmm=True)
        report["core_cycles_per_tsc"] = ratio
        report["core_cycles_per_tsc_512"] = ratio512
        print("core cycles per time-stamp-counter cycle: "
              + (f"{ratio:.3f} (a chain of dependent additions)" if ratio else "no C compiler"))
        if ratio512:
            # the passes' loops run 512-bit arithmetic: their totals at that clock, in the
            # unit of profile_engine.py --cycles
            print(f"  under 512-bit multiply-adds: {ratio512:.3f} (a chain of dependent "
                  f"multiply-adds); the totals in TSC cycles a voxel-step at that clock: "
                  f"bound {total_b / ratio512:.1f}, sim {total_s / ratio512:.1f}")
            report.update(total_bound_tsc=total_b / ratio512, total_sim_tsc=total_s / ratio512)
    if args.json:
        report.update(total_bound=total_b, total_sim=total_s)
        print(json.dumps(report))
    if tmp is not None:
        tmp.cleanup()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
