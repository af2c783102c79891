"""Instructions per voxel-step of the engine, per function (callgrind).

Counts instructions, not seconds: the count is the same on a loaded and on a
quiet machine (for the same build and inputs), so a change to the kernel can be
judged on a shared 2-core machine where wall-clock timings scatter by 10 %.
Instructions are not time (a divide, a gather or a cache miss costs more than
an add): confirm a gain with ``bench_engine.py`` before keeping it.

Runs the reference robot of ``bench_engine.py`` (6x6x6, two muscle groups,
5 s simulated, one thread) under ``valgrind --tool=callgrind``, collecting only
inside the per-robot step function, and prints each kernel function's share,
its instructions per voxel-step and per link-step:

    python benchmarks/profile_engine.py                      # seed preset, self-collision on
    python benchmarks/profile_engine.py --model corotational --no-collision
    python benchmarks/profile_engine.py --json               # last line: the counts as JSON

Profile another build of the kernel with ``SOFTGYM_KERNEL=baseline`` (the
portable one; ``x86-64-v3``, ``x86-64-v4``: ``softgym/engine/_dispatch.py``).
Needs valgrind (``apt-get install valgrind``).

``--cycles`` measures time instead, in the build this machine loads: it copies the
working tree to a temporary folder, builds it with ``SOFTGYM_PROFILE_CYCLES=1`` (cycle
probes around each stage and pass of the seed model's step,
``softgym/engine/include/softgym_prof.h``; about 2 minutes), runs the reference robot
``--repeats`` times and prints the time-stamp-counter cycles per voxel-step of each
stage and pass in the quickest run (x86-64 only; the counter ticks at a constant rate,
which it prints). It sees what instruction counts miss (a gather or a division costs
more than one instruction):

    python benchmarks/profile_engine.py --cycles --repeats 6

``--baseline GITREF`` builds that revision too and runs the two builds alternately (a
background load that comes and goes then falls on both), printing each pass's change:
on a shared VM whose runs scatter by 5 %, the way to judge a change of a few per cent:

    python benchmarks/profile_engine.py --cycles --repeats 8 --baseline HEAD

``--perf`` finds the time outside the loops (the step's glue: set-up, remainders, tests,
library calls), which the port model of the loops (``port_bound.py``) does not see: it
runs the reference robot under ``perf record`` (sampling the build this machine loads),
and prints for each of the engine's hottest functions its share of the engine's samples,
the share of those outside its innermost loops (``objdump``'s disassembly of the module,
a loop being a conditional jump back) and the hottest instructions there, each with the
inlined function it came from. Sampled addresses skid to the instruction after the one
that waited, so read them as places to look, and confirm a change with
``compare_builds.py``. Needs ``perf`` and ``objdump`` (binutils):

    python benchmarks/profile_engine.py --perf

``--modes`` prints how the reference robot's links split between the seed model's
small- and large-angle modes over its run (sampled every 0.05 s from the state): the
share of links in large-angle mode and of blocks of 16 links all in small-angle mode (the
blocks for which the frames pass takes its small-angle copy):

    python benchmarks/profile_engine.py --modes
"""

from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

from tree_run import build_tree, copy_tree, run_in_tree

HERE = Path(__file__).resolve().parent

# the child: one reference robot, alone, one thread, run `runs` times (callgrind: once;
# --perf: enough for its samples); it prints the steps, sizes, kernel build and the
# folder of the loaded kernel modules
CHILD = r"""
import os
import sys
sys.path.insert(0, {bench!r})
from bench_engine import reference_robot
from softgym.engine import SimConfig, Simulation, kernel_build
cfg = SimConfig(self_collision={coll}, model={model!r}, link_precision={prec!r})
for _ in range({runs}):
    sim = Simulation([reference_robot({n})], cfg, n_threads=1)
    r = sim.run({seconds})
mod = [m for k, m in sys.modules.items() if k.endswith("._seed") and hasattr(m, "__file__")]
print("STEPS", int(r.steps[0]), sim.n_voxels, sim.n_links, kernel_build(),
      os.path.dirname(mod[0].__file__))
"""

# the per-robot step function: everything the engine does per step runs under it
TOGGLE = "*advance_robot*"

# the engine's modules, by the start of their file names
ENGINE_MODULES = ("_seed", "_integrate", "_contact", "_core", "_corotational", "_record", "_bind",
                  "_cache")


def demangle(name: str) -> str:
    """``__pyx_f_7softgym_6engine_5_core__links_seed`` -> ``_core._links_seed``."""
    if not name.startswith("__pyx_f_"):
        return name
    rest, parts = name[len("__pyx_f_"):], []
    while (m := re.match(r"(\d+)", rest)) is not None:
        k = int(m.group(1))
        start = len(m.group(1))
        parts.append(rest[start:start + k])
        rest = rest[start + k + 1:]
    return f"{parts[-1]}.{rest}" if parts else name


def profile(model: str, collisions: bool, seconds: float, n: int, toggle: str,
            precision: str | None = None) -> dict:
    """Run the child under callgrind; return totals and per-function counts."""
    if shutil.which("valgrind") is None:
        raise SystemExit("profile_engine: valgrind is not installed (apt-get install valgrind)")
    with tempfile.TemporaryDirectory(prefix="softgym-cg-") as tmp:
        out = os.path.join(tmp, "cg.out")
        code = CHILD.format(bench=str(HERE), n=n, coll=collisions, model=model, seconds=seconds,
                            prec=precision, runs=1)
        res = subprocess.run(
            ["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}",
             f"--toggle-collect={toggle}", sys.executable, "-c", code],
            capture_output=True, text=True, check=False,
        )  # fmt: skip
        m = re.search(r"STEPS (\d+) (\d+) (\d+) (\S+)", res.stdout)
        if res.returncode != 0 or m is None:
            raise SystemExit(f"profile_engine: the profiled run failed:\n{res.stderr[-2000:]}")
        steps, n_voxels, n_links = (int(g) for g in m.groups()[:3])
        build = m.group(4)
        ann = subprocess.run(["callgrind_annotate", "--inclusive=no", out],
                             capture_output=True, text=True, check=True).stdout  # fmt: skip
    total = 0
    funcs: dict[str, int] = {}
    for line in ann.splitlines():
        t = re.match(r"\s*([\d,]+)\s+(?:\([\s\d.]+%\)\s+)?PROGRAM TOTALS", line)
        if t:
            total = int(t.group(1).replace(",", ""))
            continue
        f = re.match(r"\s*([\d,]+)\s+(?:\([\s\d.]+%\)\s+)?\S+?:(\S+)", line)
        if f and total:
            name = demangle(f.group(2))
            funcs[name] = funcs.get(name, 0) + int(f.group(1).replace(",", ""))
    if total == 0:
        raise SystemExit("profile_engine: nothing was collected (is the toggle pattern right?)")
    return {"model": model, "kernel_build": build, "collisions": collisions, "seconds": seconds, "steps": steps,
            "n_voxels": n_voxels, "n_links": n_links, "instructions": total,
            "per_voxel_step": total / (steps * n_voxels),
            "functions": dict(sorted(funcs.items(), key=lambda kv: -kv[1]))}  # fmt: skip


# the child of --cycles: the reference robot in the probed build, one thread
CYCLES_CHILD = r"""
import json, sys, time
sys.path.insert(0, {bench!r})
from bench_engine import reference_robot
from softgym.engine import SimConfig, Simulation, kernel_build, _core
sim = Simulation([reference_robot({n})], SimConfig(self_collision={coll}, model="seed",
                 link_precision={prec!r}), n_threads=1)
_core.cycle_counts(reset=True)
t0 = time.perf_counter()
r = sim.run({seconds})
wall = time.perf_counter() - t0
print("CYCLES", json.dumps(dict(counts=_core.cycle_counts(), steps=int(r.steps[0]),
      n_voxels=sim.n_voxels, wall=wall, build=kernel_build(), module=_core.__file__)))
"""

#: the rows of the --cycles table: (label, key, indented: a part of the stage above it)
CYCLE_ROWS = (
    ("contacts_seed (collision list)", "contacts", False),
    ("links_seed", "links", False),
    ("softgym_seed_geom (+ modes, AVX-512)", "geometry", True),
    ("softgym_seed_modes (other builds)", "modes", True),
    ("softgym_seed_frames", "frames", True),
    ("_seed_frame_one (acos links)", "frames_acos", True),
    ("softgym_seed_forces", "forces", True),
    ("softgym_seed_scatter", "scatter", True),
    ("collide (contact forces)", "collide", False),
    ("integrate_seed", "integrate", False),
    ("softgym_seed_voxels8, scalar loop", "voxels", True),
    ("_orient (quaternions)", "orient", True),
    ("drive, record", "drive_record", False),
)


def _ref_copy(dest: Path, ref: str) -> None:
    """The files of git revision ``ref`` (``git archive``), extracted into ``dest``."""
    root = HERE.parent
    archive = subprocess.run(["git", "archive", "--format=tar", ref], cwd=root,
                             capture_output=True, check=False)  # fmt: skip
    if archive.returncode != 0:
        raise SystemExit(f"profile_engine: git archive {ref}: {archive.stderr.decode().strip()}")
    subprocess.run(["tar", "-x", "-C", str(dest)], input=archive.stdout, check=True)


def _total(counts: dict) -> int:
    """A run's cycles in all: the sum of its stages (the passes are inside "links")."""
    return sum(counts[k] for _, k, sub in CYCLE_ROWS if not sub)


def _quickest(runs: list[dict], repeats: int) -> dict:
    """The run with the fewest cycles in all, with every run's total per voxel-step."""
    best = min(runs, key=lambda r: _total(r["counts"]))
    best["repeats"] = repeats
    best["totals"] = sorted(_total(r["counts"]) / (r["steps"] * r["n_voxels"]) for r in runs)
    return best


def profile_cycles(collisions: bool, seconds: float, n: int, repeats: int,
                   precision: str | None = None, baseline: str | None = None) -> list[dict]:
    """Build a probed copy of the tree, run it ``repeats`` times; the quickest run's counts.

    With ``baseline`` (a git revision) a probed build of that revision too, the two
    run alternately (a load that comes and goes falls on both): [tree, baseline].
    """
    with tempfile.TemporaryDirectory(prefix="softgym-cycles-") as tmp:
        trees = [Path(tmp) / "tree"]
        trees[0].mkdir()
        copy_tree(trees[0])
        if baseline is not None:
            trees.append(Path(tmp) / "baseline")
            trees[1].mkdir()
            _ref_copy(trees[1], baseline)
        for tree in trees:
            build_tree(tree, {"SOFTGYM_PROFILE_CYCLES": "1"}, "profile_engine", "the probed build")
        runs: list[list[dict]] = [[] for _ in trees]
        for _ in range(repeats):
            for tree, out in zip(trees, runs):
                code = CYCLES_CHILD.format(bench=str(tree / "benchmarks"), n=n, coll=collisions,
                                           seconds=seconds, prec=precision)  # fmt: skip
                run = run_in_tree(tree, code, "CYCLES", "profile_engine")
                if run["counts"] is None:
                    raise SystemExit("profile_engine: the run did not load the probed build")
                out.append(run)
    return [_quickest(r, repeats) for r in runs]


def precision_label(model: str, precision: str | None) -> str:
    """", single-precision links" / ", double-precision links" for the seed preset (the
    precision its SimConfig resolves to), "" for the corotational one."""
    if model != "seed":
        return ""
    from softgym.engine import SimConfig

    return f", {SimConfig(model=model, link_precision=precision).effective_link_precision}-precision links"


def print_cycles(p: dict, n: int, collisions: bool, precision: str | None = None) -> None:
    vs = p["steps"] * p["n_voxels"]
    c = p["counts"]
    total = _total(c)
    prec = precision_label("seed", precision)
    print(f"seed preset{prec}, kernel build {p['build']}, {n}^3 reference robot, self-collision "
          f"{'on' if collisions else 'off'}, {p['steps']} steps, one thread: the quickest of "
          f"{p['repeats']} runs, {total / vs:.1f} cycles per voxel-step (time-stamp counter at "
          f"{total / p['wall'] / 1e9:.2f} GHz; every run: "
          f"{', '.join(f'{t:.1f}' for t in p['totals'])})")
    print(f"{'stage / pass':40s} {'cycles/voxel-step':>18s} {'share':>7s}")
    for label, key, sub in CYCLE_ROWS:
        name = ("  " + label) if sub else label
        print(f"{name:40s} {c[key] / vs:18.1f} {100 * c[key] / total:6.1f}%")


def print_cycles_against(p: dict, q: dict, baseline: str) -> None:
    """The tree's cycles per voxel-step (p) beside the baseline's (q), each pass."""
    vp, vq = p["steps"] * p["n_voxels"], q["steps"] * q["n_voxels"]
    print(f"against {baseline} (built and run alternately; every run of it: "
          f"{', '.join(f'{t:.1f}' for t in q['totals'])})")
    print(f"{'stage / pass':40s} {'this tree':>10s} {baseline[:12]:>12s} {'change':>8s}")
    for label, key, sub in [*CYCLE_ROWS, ("total", None, False)]:
        if key is None:
            a, b = _total(p["counts"]) / vp, _total(q["counts"]) / vq
        elif key not in q["counts"]:  # a part the baseline's probes do not time
            name = ("  " + label) if sub else label
            print(f"{name:40s} {p['counts'][key] / vp:10.1f} {'-':>12s} {'':>8s}")
            continue
        else:
            a, b = p["counts"][key] / vp, q["counts"][key] / vq
        name = ("  " + label) if sub else label
        print(f"{name:40s} {a:10.1f} {b:12.1f} {100 * (a - b) / b if b else 0.0:+7.1f}%")


def split_by_loops(annotation: str, loops: list[tuple[int, int]], fn_at: dict[int, str],
                   hottest: int = 3) -> dict:
    """The per-instruction percentages of ``perf annotate --stdio`` text (lines
    ``  PCT :   ADDR:   INSTRUCTION``), summed inside the address ranges ``loops`` (inclusive)
    and outside them, with the ``hottest`` instructions outside as (percent, address,
    inlined function from ``fn_at``, instruction)."""
    inside = outside = 0.0
    out = []
    for line in annotation.splitlines():
        m = re.match(r"\s+([0-9.]+) :\s+([0-9a-f]+):\s+(.*)$", line)
        if not m:
            continue
        pct, addr, text = float(m.group(1)), int(m.group(2), 16), m.group(3).strip()
        if any(lo <= addr <= hi for lo, hi in loops):
            inside += pct
        else:
            outside += pct
            out.append((pct, addr, fn_at.get(addr, "?"), text))
    out.sort(key=lambda t: -t[0])
    return {"inside": inside, "outside": outside, "hottest_outside": out[:hottest]}


def perf_functions(report: str) -> list[tuple[float, str, str]]:
    """(percent, module file, symbol) of the engine's functions in ``perf report --stdio
    --sort dso,sym`` text, hottest first."""
    rows = []
    for line in report.splitlines():
        m = re.match(r"\s+([0-9.]+)%\s+(\S+)\s+\[\.\]\s+(\S+)", line)
        if m and m.group(2).startswith(tuple(f"{k}." for k in ENGINE_MODULES)):
            rows.append((float(m.group(1)), m.group(2), m.group(3)))
    return sorted(rows, key=lambda r: -r[0])


def profile_perf(model: str, collisions: bool, seconds: float, n: int,
                 precision: str | None = None, top: int = 8, runs: int = 20) -> dict:
    """perf's samples of the reference robot, per engine function, split into its innermost
    loops and the rest (split_by_loops)."""
    for tool in ("perf", "objdump"):
        if shutil.which(tool) is None:
            raise SystemExit(f"profile_engine: --perf needs {tool}")
    import port_bound

    code = CHILD.format(bench=str(HERE), n=n, coll=collisions, model=model, seconds=seconds,
                        prec=precision, runs=runs)
    with tempfile.TemporaryDirectory(prefix="softgym-perf-") as tmp:
        data = os.path.join(tmp, "perf.data")
        res = subprocess.run(["perf", "record", "-q", "-F", "10000", "-o", data, sys.executable,
                              "-c", code], capture_output=True, text=True, check=False)
        m = re.search(r"STEPS \d+ \d+ \d+ (\S+) (.+)", res.stdout)
        if res.returncode != 0 or m is None:
            raise SystemExit(f"profile_engine: the sampled run failed:\n{res.stderr[-2000:]}")
        build, moddir = m.group(1), Path(m.group(2).strip())
        report = subprocess.run(["perf", "report", "-i", data, "--no-children", "--sort",
                                 "dso,sym", "--stdio"], capture_output=True, text=True,
                                check=True).stdout  # fmt: skip
        funcs = perf_functions(report)
        engine = sum(f[0] for f in funcs) or 1.0
        disasm: dict[str, tuple] = {}
        rows = []
        for pct, dso, sym in funcs[:top]:
            if dso not in disasm:
                so = moddir / dso
                ins = port_bound.disassemble(so) if so.exists() else []
                disasm[dso] = ([(ins[s][0], ins[e][0]) for s, e in port_bound.innermost_loops(ins)],
                               {a: fn for a, _sym, fn, _t in ins})
            loops, fn_at = disasm[dso]
            ann = subprocess.run(["perf", "annotate", "-i", data, "--stdio", "-s", sym],
                                 capture_output=True, text=True, check=False).stdout  # fmt: skip
            split = split_by_loops(ann, loops, fn_at)
            total = split["inside"] + split["outside"] or 1.0
            rows.append({"symbol": sym, "module": dso, "share": pct / engine,
                         "outside": split["outside"] / total,
                         "hottest_outside": split["hottest_outside"]})
    return {"kernel_build": build, "functions": rows}


def link_modes(seconds: float, n: int, collisions: bool, precision: str | None = None,
               every: float = 0.05, block: int = 16) -> dict:
    """The reference robot's links by mode (seed preset) over ``seconds``, sampled every
    ``every`` s: the mean share of links in large-angle mode and of ``block``-link blocks
    (in link order) whose links are all in small-angle mode."""
    import numpy as np
    from bench_engine import reference_robot

    from softgym.engine import SimConfig, Simulation

    sim = Simulation([reference_robot(n)],
                     SimConfig(self_collision=collisions, link_precision=precision), n_threads=1)
    large, small_blocks, samples = 0.0, 0.0, 0
    for _ in range(max(int(round(seconds / every)), 1)):
        sim.run(every)
        sa = np.asarray(sim.get_state()["link_sa"]).ravel() != 0
        large += 1.0 - sa.mean()
        small_blocks += np.logical_and.reduceat(sa, np.arange(0, sa.size, block)).mean()
        samples += 1
    return {"links": int(sa.size), "samples": samples, "large_angle_share": large / samples,
            "all_small_block_share": small_blocks / samples, "block": block}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--model", default="seed", choices=("seed", "corotational"))
    ap.add_argument("--no-collision", action="store_true", help="self-collision off")
    ap.add_argument("--seconds", type=float, default=5.0, help="simulated time")
    ap.add_argument("--size", type=int, default=6, help="robot edge in voxels")
    ap.add_argument("--toggle", default=TOGGLE, help="callgrind --toggle-collect pattern")
    ap.add_argument("--json", action="store_true", help="print one JSON object as the last line")
    ap.add_argument("--link-precision", default=None, choices=("double", "single"),
                    help="SimConfig.link_precision of the seed preset")
    ap.add_argument("--cycles", action="store_true",
                    help="time each pass (a probed build of a copy of the tree; seed preset)")
    ap.add_argument("--repeats", type=int, default=5, help="--cycles: runs, the quickest kept")
    ap.add_argument("--baseline", metavar="GITREF", default=None,
                    help="--cycles: also a probed build of this git revision, run alternately "
                         "with the tree's, and each pass's change against it")
    ap.add_argument("--modes", action="store_true",
                    help="the links' small- and large-angle modes over the run (seed preset)")
    ap.add_argument("--perf", action="store_true",
                    help="perf's samples per engine function, inside its innermost loops and "
                         "outside them (needs perf and objdump)")
    args = ap.parse_args(argv)
    if args.perf:
        got = profile_perf(args.model, not args.no_collision, args.seconds, args.size,
                           args.link_precision)
        print(f"{args.model} preset{precision_label(args.model, args.link_precision)}, kernel "
              f"build {got['kernel_build']}, {args.size}^3 reference robot: perf's samples of "
              f"the engine's hottest functions, and the share of each outside its innermost "
              f"loops (skid: a sample lands after the instruction that waited)")
        print(f"{'function':44s} {'share':>6s} {'outside':>8s}  hottest outside (inlined "
              f"function: instruction)")
        for f in got["functions"]:
            hot = "; ".join(f"{p:.1f}% {fn}: {t[:40]}" for p, _a, fn, t in f["hottest_outside"])
            print(f"{f['symbol'][:44]:44s} {100 * f['share']:5.1f}% {100 * f['outside']:7.1f}%  "
                  f"{hot}")
        if args.json:
            print(json.dumps(got))
        return 0
    if args.modes:
        if args.model != "seed":
            raise SystemExit("profile_engine: --modes counts the seed preset's link modes only")
        m = link_modes(args.seconds, args.size, not args.no_collision, args.link_precision)
        print(f"seed preset, {args.size}^3 reference robot, self-collision "
              f"{'off' if args.no_collision else 'on'}, {m['links']} links, {m['samples']} "
              f"samples over {args.seconds:g} s: {100 * m['large_angle_share']:.1f} % of the "
              f"links in large-angle mode, {100 * m['all_small_block_share']:.1f} % of the "
              f"blocks of {m['block']} links all in small-angle mode")
        if args.json:
            print(json.dumps(m))
        return 0
    if args.cycles:
        if args.model != "seed":
            raise SystemExit("profile_engine: --cycles times the seed preset's passes only")
        if args.repeats < 1:
            raise SystemExit("profile_engine: --repeats must be at least 1")
        got = profile_cycles(not args.no_collision, args.seconds, args.size, args.repeats,
                             args.link_precision, args.baseline)
        print_cycles(got[0], args.size, not args.no_collision, args.link_precision)
        if args.baseline is not None:
            print_cycles_against(got[0], got[1], args.baseline)
        if args.json:
            print(json.dumps(got[0] if args.baseline is None else got))
        return 0
    p = profile(args.model, not args.no_collision, args.seconds, args.size, args.toggle,
                args.link_precision)
    vs = p["steps"] * p["n_voxels"]
    ls = p["steps"] * p["n_links"]
    prec = precision_label(args.model, args.link_precision)
    print(f"{p['model']} preset{prec}, kernel build {p['kernel_build']}, {args.size}^3 reference "
          f"robot, self-collision "
          f"{'on' if p['collisions'] else 'off'}, {p['steps']} steps: "
          f"{p['instructions']:,} instructions, {p['per_voxel_step']:.0f} per voxel-step")
    print(f"{'function':40s} {'share':>7s} {'/voxel-step':>12s} {'/link-step':>11s}")
    for name, count in p["functions"].items():
        if count < 0.002 * p["instructions"]:
            continue
        print(f"{name[:40]:40s} {100 * count / p['instructions']:6.1f}% "
              f"{count / vs:12.1f} {count / ls:11.1f}")
    if args.json:
        print(json.dumps(p))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
