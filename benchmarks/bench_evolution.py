"""Seconds per generation of the seed's evolutionary setup.

The seed's generation: 31 evaluations (15 parents, 15 children, 1 random
newcomer) of 6x6x6 CPPN robots, 5 s simulated each. Here the parents come
from the previous generation and every one of the 31 is simulated again
(``--cached`` lets the phenotype cache skip the parents, as real runs do),
all in one batched Simulation, plus the variation (CPPN mutation with
validity retries, controller GA) and selection.

Robots with bone (Passive_Hard, 100x stiffer) need a 10x smaller time step,
so the time per generation depends on how many robots hold bone: the bone
fraction is printed beside every time.

Reference (issue 7): the seed's engine at -O3, one process per robot, needs
about 0.75 s per soft 6x6x6 robot and 3.5-12 s per robot with bone on one
core of this machine kind: roughly 0.5 to 3 minutes per generation on 2
cores. The estimate printed for the same population uses 0.75 s per soft
robot and 7 s per bone robot. Target: under 5 s per generation on 2 cores.

    python benchmarks/bench_evolution.py                 # 3 generations
    python benchmarks/bench_evolution.py --generations 1 --json
"""

from __future__ import annotations

import argparse
import json
import sys
import time

import numpy as np
import results_log

from evolvers.evaluation.evaluator import Evaluator, PhenotypeCache
from evolvers.evaluation.experiments import get_experiment
from evolvers.operators.genome import Individual
from evolvers.operators.selection import sel_fitness_tournament
from evolvers.operators.variation import make_children
from softgym.engine import default_num_threads, openmp_enabled

SEED_SOFT_S = 0.75  # s per soft 6x6x6 robot, 5 s simulated, the seed's engine at -O3, one core
SEED_BONE_S = (3.5, 12.0)  # s per robot with bone


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--generations", type=int, default=3)
    ap.add_argument("--experiment", default="controller-tournament")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--seconds", type=float, default=5.0)
    ap.add_argument(
        "--cached", action="store_true", help="let the phenotype cache skip the parents"
    )
    ap.add_argument("--json", action="store_true", help="print a JSON line at the end")
    ap.add_argument("--no-append", action="store_true", help="do not append to RESULTS.md")
    args = ap.parse_args(argv)

    exp = get_experiment(args.experiment, seconds=args.seconds)
    rng = np.random.default_rng(args.seed)
    ids = iter(range(10**9))
    evaluator = Evaluator(exp)
    pop = [
        Individual.random(rng, next(ids), exp.shape, exp.cppn_outputs, exp.rules)
        for _ in range(exp.pop_size)
    ]
    t0 = time.perf_counter()
    evaluator.evaluate(pop)
    print(
        f"generation 0: {len(pop)} robots in {time.perf_counter() - t0:.2f} s "
        f"(threads {default_num_threads()}, OpenMP {'on' if openmp_enabled() else 'off'})",
        file=sys.stderr,
    )
    rows = []
    for g in range(1, args.generations + 1):
        if not args.cached:
            evaluator.cache = PhenotypeCache()
        t0 = time.perf_counter()
        c0 = time.process_time()
        for ind in pop:
            ind.age += 1
        children = make_children(pop, rng, lambda: next(ids), shape=exp.shape, rules=exp.rules,
                                 evolve_controller=exp.evolve_controller,
                                 evolve_materials=exp.evolve_materials)  # fmt: skip
        newcomer = Individual.random(rng, next(ids), exp.shape, exp.cppn_outputs, exp.rules)
        t_var = time.perf_counter() - t0
        everyone = pop + children + [newcomer]
        t1 = time.perf_counter()
        stats = evaluator.evaluate(everyone)
        t_eval = time.perf_counter() - t1
        pop = sel_fitness_tournament(everyone, exp.pop_size, exp.fitness.name, rng)
        total = time.perf_counter() - t0
        cpu = time.process_time() - c0
        n_bone = stats.n_bone
        n = len(everyone)
        seed_lo = ((n - n_bone) * SEED_SOFT_S + n_bone * SEED_BONE_S[0]) / 2.0
        seed_hi = ((n - n_bone) * SEED_SOFT_S + n_bone * SEED_BONE_S[1]) / 2.0
        row = {
            "generation": g, "evaluations": n, "simulated": stats.n_simulated,
            "bone_fraction": n_bone / n, "seconds": total, "cpu_seconds": cpu, "eval_seconds": t_eval,
            "variation_seconds": t_var, "seed_estimate_seconds": [seed_lo, seed_hi],
            "best": max(ind.objectives[exp.fitness.name] for ind in pop),
        }  # fmt: skip
        rows.append(row)
        print(f"generation {g}: {total:6.2f} s (CPU {cpu:.2f} s) for {n} evaluations ({stats.n_simulated} simulated; "
              f"eval {t_eval:.2f} s, variation {t_var:.2f} s), bone fraction {n_bone / n:.2f} "
              f"({n_bone} robots); seed's engine on 2 cores ~{seed_lo:.0f}-{seed_hi:.0f} s", flush=True)  # fmt: skip
    mean = float(np.mean([r["seconds"] for r in rows])) if rows else float("nan")
    cpu_mean = float(np.mean([r["cpu_seconds"] for r in rows])) if rows else float("nan")
    bone = float(np.mean([r["bone_fraction"] for r in rows])) if rows else float("nan")
    seed_mid = (
        float(np.mean([sum(r["seed_estimate_seconds"]) / 2 for r in rows]))
        if rows
        else float("nan")
    )
    print(
        f"mean: {mean:.2f} s per generation, CPU {cpu_mean:.2f} s (bone fraction {bone:.2f}); "
        f"seed's engine ~{seed_mid:.0f} s for the same robots ({seed_mid / mean:.0f}x); target < 5 s"
    )
    if not args.no_append:
        lines = [
            results_log.heading("bench_evolution.py", details=[f"{default_num_threads()} threads"]),
            "",
            f"Seed setup: {args.experiment}, 31 evaluations of 6x6x6 CPPN robots per generation, "
            f"{args.seconds:g} s simulated, {'parents cached' if args.cached else 'all 31 simulated'}.",
            "",
            "| generation | s / generation | CPU s | simulated | bone fraction | seed's engine, 2 cores (est.) |",
            "|---|---|---|---|---|---|",
        ]
        for r in rows:
            lo, hi = r["seed_estimate_seconds"]
            lines.append(f"| {r['generation']} | {r['seconds']:.2f} | {r['cpu_seconds']:.2f} | {r['simulated']} | "
                         f"{r['bone_fraction']:.2f} | {lo:.0f}-{hi:.0f} s |")  # fmt: skip
        lines.append("")
        lines.append(f"Mean {mean:.2f} s per generation (CPU {cpu_mean:.2f} s; on a shared machine "
                     f"CPU / 2 is the uncontended 2-core time) at bone fraction {bone:.2f} "
                     f"(target < 5 s; the seed's engine ~{seed_mid:.0f} s).")  # fmt: skip
        results_log.append("\n".join(lines))
    if args.json:
        print(json.dumps({"seconds_per_generation": mean, "cpu_seconds_per_generation": cpu_mean,
                          "bone_fraction": bone, "rows": rows}))  # fmt: skip
    return 0


if __name__ == "__main__":
    sys.exit(main())
