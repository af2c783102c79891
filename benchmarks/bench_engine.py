"""Engine throughput: voxel-steps per second of the batched Cython kernel.

The reference robot (issue 3): a 6x6x6 block, x < 3 muscle with CTE +0.01,
x >= 3 muscle with CTE -0.01, E 5e6 Pa, density 1e6 kg/m^3, Poisson 0.35,
L 0.01 m, floor and gravity, seed damping, dT 14, period 0.25 s, 5 s simulated.

Prints voxel-steps/s for batches of 1, 16 and 64 robots with 1 and 2 threads,
robot sizes 4^3, 6^3 and 10^3, peak memory per robot, and ratios to the
reference engines, for the default "seed" preset (SimConfig.model, the seed
engine's step) and rows of the "corotational" preset. Appends a table to
benchmarks/RESULTS.md.

The seed's own engine is timed in the same run when its program is given
(``--seed-engine PATH/seed_oracle.py``, the oracle of issue 16; not part of the
project): the reference robot as a .vxa (``softgym.design.vxa.to_vxa``, the
seed's settings, self-collision on as the seed always ran), median of 3 interleaved
repeats, against
softgym's seed preset on the same robot, alone, one thread, self-collision on.
Without it the ratios use figures quoted from an earlier machine of this kind
(the seed's engine at -O3 ~2.3 M voxel-steps/s per core, the 2015 Voxelyze
library 1.4-2.1 M) and say so.

    python benchmarks/bench_engine.py            # full table (about 2 minutes)
    python benchmarks/bench_engine.py --quick --json   # < 60 s, last line is JSON
    python benchmarks/bench_engine.py --seed-engine ../shared/oracle/seed_oracle.py
    python benchmarks/bench_engine.py --scale --repeats 3   # batches of 1 to 1,024, ~10 min
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time

import numpy as np
import results_log

from softgym.engine import Body, SimConfig, Simulation, kernel_build, openmp_enabled
from softgym.terrain import Terrain

SEED_ENGINE_O3 = 2.3e6  # voxel-steps/s per core, the seed's engine compiled with -O3 (issue 3)
VOXELYZE_2015 = (1.4e6, 2.1e6)  # the 2015 Voxelyze library on this machine kind (issue 3)


def reference_robot(n: int = 6) -> Body:
    grid = np.ones((n, n, n), dtype=np.int32)
    grid[n // 2 :] = 2
    return Body(
        grid=grid,
        youngs_modulus=[0.0, 5e6, 5e6],
        density=[0.0, 1e6, 1e6],
        poisson=[0.0, 0.35, 0.35],
        cte=[0.0, 0.01, -0.01],
        mu_static=[0.0, 1.0, 1.0],
        mu_kinetic=[0.0, 0.5, 0.5],
        temp_amplitude=14.0,
        period=0.25,
    )


def measure(n: int, batch: int, threads: int, seconds: float, repeats: int,
            collisions: bool = False, world: str = "flat", model: str = "seed"):  # fmt: skip
    """Best-of-`repeats` voxel-steps/s for `batch` reference robots of size n^3."""
    best = 0.0
    nbytes = 0
    diverged = 0
    cfg = SimConfig(self_collision=collisions, model=model)
    # the seed's fence: a 2-voxel gap around the robot on every side
    terrain = Terrain.fence(inner=n + 4, center=(n / 2, n / 2)) if world == "fence" else None
    for _ in range(repeats):
        sim = Simulation([reference_robot(n)] * batch, cfg, n_threads=threads, terrain=terrain)
        t0 = time.perf_counter()
        rollout = sim.run(seconds)
        wall = time.perf_counter() - t0
        vsteps = float(np.sum(np.diff(rollout.voxel_offsets) * rollout.steps))
        best = max(best, vsteps / wall)
        nbytes = sim.nbytes
        diverged = int(rollout.diverged.sum())
    return {
        "size": f"{n}^3",
        "batch": batch,
        "threads": threads,
        "collisions": collisions,
        "world": world,
        "model": model,
        "seconds_simulated": seconds,
        "voxel_steps_per_s": best,
        "bytes_per_robot": nbytes / batch,
        "diverged": diverged,
    }


SCALE_BATCHES = (1, 16, 256, 1024)


def scale_seconds(batch: int) -> float:
    """The actuated seconds :func:`measure_scale` times for `batch` robots: 1 s, and more
    for small batches (64 robot-seconds, at most 8 s), so that no timing is a tenth of a
    second (at 16 robots 1 s took 0.13 s on 2 threads, and the 2-thread figure moved by
    20 % between repeats on this project's VM)."""
    return min(8.0, max(1.0, 64.0 / batch))


def measure_scale(batch: int, threads: int, settle: float = 1.0,
                  seconds: float | None = None) -> dict:
    """Voxel-steps/s and memory per robot of `batch` reference robots at scale.

    The seed preset with self-collision on, each robot inside the seed's
    fence. The robots settle for ``settle`` s (untimed: the drive starts
    after SimConfig.init_time), then ``seconds`` of actuated motion are timed
    (:func:`scale_seconds` by default), so a large batch costs a few minutes,
    not 5 s of simulation per robot.
    """
    if seconds is None:
        seconds = scale_seconds(batch)
    cfg = SimConfig(self_collision=True)
    terrain = Terrain.fence(inner=10, center=(3, 3))
    sim = Simulation([reference_robot(6)] * batch, cfg, n_threads=threads, terrain=terrain)
    sim.advance(settle)
    t_start = sim.time
    t0 = time.perf_counter()
    sim.advance(seconds)
    wall = time.perf_counter() - t0
    steps = np.rint((sim.time - t_start) / sim.dt)
    vsteps = float(np.sum(steps * np.diff(sim.voxel_offsets)))
    return {"batch": batch, "threads": threads, "voxel_steps_per_s": vsteps / wall,
            "bytes_per_robot": sim.nbytes / batch, "wall_s": wall,
            "diverged": int(np.sum(sim.diverged))}  # fmt: skip


def scale_table(log=print, repeats: int = 1) -> list[dict]:
    """The scale rows: batches of 1 to 1,024 robots on 1 and 2 threads.

    Each batch runs ``repeats`` times on 1, then 2 threads, alternating, and keeps
    each thread count's quickest run: a background load that comes and goes (this
    VM's timings move by 20 %) falls on both alike and slows, never speeds, a run.
    The 2 / 1 ratio is the median over the repeats of each repeat's pair, run one
    after the other (``pair_ratio`` of the 2-thread row): the quickest runs of the
    two thread counts may come from different minutes of the VM.
    """
    rows = []
    for batch in SCALE_BATCHES:
        best = {}
        pairs = []
        for _ in range(max(1, repeats)):
            pair = {}
            for threads in (1, 2):
                row = measure_scale(batch, threads)
                pair[threads] = row["voxel_steps_per_s"]
                log(f"  scale: batch {batch:5d} threads {threads}: "
                    f"{row['voxel_steps_per_s'] / 1e6:7.2f} M voxel-steps/s, "
                    f"{row['bytes_per_robot'] / 1024:7.1f} KiB/robot ({row['wall_s']:.1f} s)")
                row["repeats"] = max(1, repeats)
                if threads not in best or row["voxel_steps_per_s"] > best[threads]["voxel_steps_per_s"]:
                    best[threads] = row
            pairs.append(pair[2] / pair[1])
        best[2]["pair_ratio"] = statistics.median(pairs)
        rows.extend([best[1], best[2]])
    return rows


def scale_lines(rows: list[dict]) -> list[str]:
    """Markdown table of :func:`scale_table` with the 2-thread / 1-thread ratio per batch."""
    reps = rows[0].get("repeats", 1)
    lines = ["", "At scale (seed preset, 6^3 reference robot, self-collision on, in the seed's "
             f"fence; 1 s settled untimed, then 64 / batch s actuated timed, 1 s to 8 s; the "
             f"quickest of {reps} alternating runs; 2 / 1: the median of the repeats' "
             "paired ratios):", "",
             "| batch | M voxel-steps/s, 1 thread | 2 threads | 2 / 1 | KiB per robot | diverged |",
             "|---|---|---|---|---|---|"]  # fmt: skip
    for batch in SCALE_BATCHES:
        one = next(r for r in rows if r["batch"] == batch and r["threads"] == 1)
        two = next(r for r in rows if r["batch"] == batch and r["threads"] == 2)
        lines.append(f"| {batch} | {one['voxel_steps_per_s'] / 1e6:.2f} | "
                     f"{two['voxel_steps_per_s'] / 1e6:.2f} | "
                     f"{two.get('pair_ratio', two['voxel_steps_per_s'] / one['voxel_steps_per_s']):.2f}x | "
                     f"{one['bytes_per_robot'] / 1024:.1f} | {one['diverged'] + two['diverged']} |")
    return lines


def reference_design():
    """The reference robot as a design of the seed palette (Active_+ x < 3, Active_- x >= 3)."""
    from softgym.design import RobotDesign

    grid = np.full((6, 6, 6), 3, dtype=np.int8)  # Active_+ (CTE +0.01)
    grid[3:] = 4  # Active_- (CTE -0.01)
    return RobotDesign(grid)


def seed_engine_ratio(oracle_py: str, repeats: int = 3) -> dict:
    """Voxel-steps/s of the seed's engine and of softgym on the same robot, in this run.

    ``oracle_py`` is the oracle's ``seed_oracle.py`` (issue 16); its ``run_vxa``
    runs one .vxa in the seed's program (one process, one thread) and reports
    the wall time. The two engines alternate, ``repeats`` times each, and their
    median wall times are compared. softgym runs the same design alone on one thread with the
    seed preset and self-collision on (the .vxa's settings). Both take the same
    steps (the seed preset's time step is the seed's), counted by softgym.
    """
    import importlib.util
    from pathlib import Path

    from softgym.design.vxa import to_vxa

    spec = importlib.util.spec_from_file_location("seed_oracle", Path(oracle_py))
    oracle = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(oracle)
    design = reference_design()
    text = to_vxa(design)
    walls = []
    # softgym's configurations on the same robot: the seed preset (its default
    # single-precision link math), the corotational preset, the seed preset with
    # the seed's own double-precision link operations
    configs = {"seed": SimConfig(self_collision=True),
               "corotational": SimConfig(self_collision=True, model="corotational"),
               "double": SimConfig(self_collision=True, link_precision="double")}  # fmt: skip
    times = {name: [] for name in configs}
    # interleaved repeats (seed engine, softgym, seed engine, ...): a background
    # load that comes and goes falls on both engines alike; the medians are compared
    for _ in range(repeats):
        res = oracle.run_vxa(text)
        if res.get("hung") or "error" in res:
            raise SystemExit(f"bench_engine: the seed's engine did not finish: {res}")
        walls.append(res["wall_s"])
        for name, cfg in configs.items():
            sim = Simulation([design.to_body()], cfg, n_threads=1)
            t0 = time.perf_counter()
            r = sim.run(5.0)
            times[name].append(time.perf_counter() - t0)
            if name == "seed":
                rollout = r
    ours, corot, double = times["seed"], times["corotational"], times["double"]
    vsteps = float(design.n_voxels * rollout.steps[0])
    return {
        "seed_engine_voxel_steps_per_s": vsteps / statistics.median(walls),
        "softgym_voxel_steps_per_s": vsteps / statistics.median(ours),
        "ratio": statistics.median(walls) / statistics.median(ours),
        "seed_engine_wall_s": statistics.median(walls),
        "softgym_wall_s": statistics.median(ours),
        "repeats": repeats,
        # the corotational preset on the same robot and steps (its own time step is the same)
        "corotational_ratio": statistics.median(walls) / statistics.median(corot),
        # the seed preset with SimConfig.link_precision="double" (the same steps)
        "double_ratio": statistics.median(walls) / statistics.median(double),
        "steps": int(rollout.steps[0]),
    }


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="short runs, finishes in < 60 s")
    ap.add_argument("--json", action="store_true", help="print one JSON object as the last line")
    ap.add_argument("--no-append", action="store_true", help="do not append to RESULTS.md")
    ap.add_argument("--seed-engine", metavar="SEED_ORACLE_PY",
                    help="time the seed's own engine (../shared/oracle/seed_oracle.py) in this run")  # fmt: skip
    ap.add_argument("--ratio-only", action="store_true",
                    help="with --seed-engine: only the ratio to the seed's engine (no table)")
    ap.add_argument("--scale", action="store_true",
                    help="only the scale table (batches of 1 to 1,024 robots, 1 and 2 threads)")
    ap.add_argument("--repeats", type=int, default=3,
                    help="interleaved repeats of the ratio measurement (median taken); with "
                         "--scale, alternating runs of each batch (quickest kept)")
    args = ap.parse_args(argv)

    if args.ratio_only:
        if not args.seed_engine:
            ap.error("--ratio-only needs --seed-engine")
        m = seed_engine_ratio(args.seed_engine, args.repeats)
        print(f"seed's engine {m['seed_engine_wall_s']:.3f} s, softgym seed preset "
              f"{m['softgym_wall_s']:.3f} s: {m['ratio']:.2f}x; double-precision links "
              f"{m['double_ratio']:.2f}x; corotational preset "
              f"{m['corotational_ratio']:.2f}x (reference robot, {m['steps']} steps, one "
              f"thread, median of {m['repeats']} interleaved repeats)")
        if args.json:
            print(json.dumps(m))
        return 0
    if args.scale:
        srows = scale_table(log=lambda m: print(m, file=sys.stderr), repeats=args.repeats)
        lines = scale_lines(srows)
        print("\n".join(lines))
        if not args.no_append:
            results_log.append("\n".join([results_log.heading("bench_engine.py --scale"),
                                          *lines[1:], ""]))  # fmt: skip
        if args.json:
            print(json.dumps(srows))
        return 0
    seconds = 5.0
    repeats = 1 if args.quick else 2  # best of
    rows = []
    print(f"softgym engine benchmark: OpenMP {'on' if openmp_enabled() else 'off'}, "
          f"kernel build {kernel_build()}, {seconds} s simulated per robot", file=sys.stderr)

    def run(n, batch, threads, collisions=False, world="flat", model="seed"):
        row = measure(n, batch, threads, seconds, repeats, collisions, world, model)
        rows.append(row)
        print(f"  {model:12s} {row['size']:>5} batch {batch:3d} threads {threads} "
              f"{'self-collision' if collisions else 'no collision  '} {world:5s}: "
              f"{row['voxel_steps_per_s'] / 1e6:7.2f} M voxel-steps/s, "
              f"{row['bytes_per_robot'] / 1024:7.1f} KiB/robot", file=sys.stderr)
        return row

    # both presets: "seed" (the default, the seed engine's step) and "corotational"
    if args.quick:
        plan = [(6, 16, 1, False, "flat"), (6, 16, 2, False, "flat"), (6, 16, 1, True, "flat"),
                (6, 16, 1, False, "flat", "corotational")]
    else:
        plan = [(6, b, t, False, "flat") for b in (1, 16, 64) for t in (1, 2)]
        plan += [(n, 16, t, False, "flat") for n in (4, 10) for t in (1, 2)]
        # the world (issue 4): self-collision on, flat and inside the fence,
        # sizes 4^3 .. 16^3 show how the collision cost grows
        plan += [(n, 16 if n < 16 else 4, 1, True, w) for n in (4, 6, 10, 16)
                 for w in ("flat", "fence")]  # fmt: skip
        plan += [(6, 16, 2, True, "fence")]
        plan += [(6, 16, t, c, "flat", "corotational") for t in (1, 2) for c in (False, True)]
    for p in plan:
        run(*p)

    def find(size, threads, collisions, world="flat", model="seed"):
        return next(r for r in rows if r["size"] == size and r["batch"] == 16
                    and r["threads"] == threads and r["collisions"] == collisions
                    and r["world"] == world and r["model"] == model)["voxel_steps_per_s"]  # fmt: skip

    v1, v2 = find("6^3", 1, False), find("6^3", 2, False)
    vc = find("6^3", 1, True)
    vco = find("6^3", 1, False, model="corotational")
    measured = seed_engine_ratio(args.seed_engine) if args.seed_engine else None
    # measured: the same robot with the same settings in both engines; quoted: batch 16 vs a
    # figure from an earlier machine
    vs_seed = measured["ratio"] if measured else v1 / SEED_ENGINE_O3
    how = ("same robot and settings, measured in this run" if measured
           else "its speed quoted from an earlier machine, not measured")  # fmt: skip
    summary = {
        "voxel_steps_per_s_1thread": v1,
        "voxel_steps_per_s_2threads": v2,
        "voxel_steps_per_s_1thread_collisions": vc,
        "voxel_steps_per_s_1thread_corotational": vco,
        "seed_vs_corotational": v1 / vco,
        "thread_scaling": v2 / v1,
        "vs_seed_engine_O3_per_core": vs_seed,
        "seed_engine_measured": measured,
        "vs_voxelyze_2015_per_core": [v1 / VOXELYZE_2015[1], v1 / VOXELYZE_2015[0]],
        "seconds_per_soft_robot_5s_1thread": 216 * (5.0 / Simulation(reference_robot()).dt[0]) / v1,
        "openmp": openmp_enabled(),
        "kernel_build": kernel_build(),
        "quick": args.quick,
    }
    print(f"reference robot, batch 16: {v1 / 1e6:.2f} M voxel-steps/s on 1 thread, "
          f"{v2 / 1e6:.2f} M on 2 threads ({v2 / v1:.2f}x), {vc / 1e6:.2f} M on 1 thread "
          f"with self-collision (seed preset); the corotational preset {vco / 1e6:.2f} M "
          f"(seed preset = {v1 / vco:.2f}x it); "
          f"{vs_seed:.1f}x the seed's engine at -O3 per core ({how}), "
          f"{v1 / VOXELYZE_2015[1]:.1f}-{v1 / VOXELYZE_2015[0]:.1f}x Voxelyze 2015 per core (quoted); "
          f"{summary['seconds_per_soft_robot_5s_1thread'] * 1000:.0f} ms per 6^3 soft robot "
          f"(5 s simulated) on one core", file=sys.stderr)

    if not args.no_append:
        lines = [
            results_log.heading("bench_engine.py", args.quick),
            "| preset | robot | batch | threads | self-collision | world | M voxel-steps/s | KiB per robot | diverged |",
            "|---|---|---|---|---|---|---|---|---|",
        ]
        for r in rows:
            lines.append(f"| {r['model']} | {r['size']} | {r['batch']} | {r['threads']} | "
                         f"{'on' if r['collisions'] else 'off'} | {r['world']} | "
                         f"{r['voxel_steps_per_s'] / 1e6:.2f} | {r['bytes_per_robot'] / 1024:.1f} | "
                         f"{r['diverged']} |")
        lines.append(f"\n2 threads / 1 thread (6^3, batch 16): {v2 / v1:.2f}x; with self-collision "
                     f"{vc / 1e6:.2f} M voxel-steps/s on 1 thread; "
                     f"seed preset / corotational preset: {v1 / vco:.2f}x; "
                     f"vs the seed's engine at -O3: {vs_seed:.1f}x per core ({how}).")
        if measured:
            lines.append(
                f"The seed's own engine on this machine, in this run (`--seed-engine`): the "
                f"reference robot alone, self-collision on, {measured['steps']} steps: "
                f"{measured['seed_engine_wall_s']:.3f} s ({measured['seed_engine_voxel_steps_per_s'] / 1e6:.2f} M "
                f"voxel-steps/s) against softgym's seed preset {measured['softgym_wall_s']:.3f} s "
                f"({measured['softgym_voxel_steps_per_s'] / 1e6:.2f} M), one thread each: "
                f"{measured['ratio']:.1f}x (median of {measured['repeats']} interleaved repeats each).")
        lines.append("")
        results_log.append("\n".join(lines))
    if args.json:
        print(json.dumps(summary))
    return 0


if __name__ == "__main__":
    sys.exit(main())
