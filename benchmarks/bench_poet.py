"""POET co-evolution against a random-terrain control and against direct evolution.

Per seed, three searches over the same robots (4x4x4 CPPN bodies with the
controller GA, 3 s simulated, :func:`evolvers.drivers.poet.poet_experiment`) and the same
thresholds (voxel lengths of ``max_xy_dist``; POET's rewards mapped by
:func:`evolvers.drivers.poet.poet_thresholds`):

* ``poet``: :class:`evolvers.drivers.poet.PoetRun`, candidate terrains mutated from eligible parents;
* ``control``: the same loop with candidate terrains drawn uniformly (``generator="random"``);
* ``direct``: for the hardest terrain the POET run solved (fewest kept robots at the
  solved threshold, then the lowest mean score; the start terrain excluded), one
  pair evolving on that terrain alone from random robots (no reproduction, no
  transfers: the same operators, population and selection) until it has used as
  many simulations as the whole POET run.

Printed and appended to ``benchmarks/RESULTS.md``: final ANNECS of POET and
control per seed, and per seed the hardest solved terrain, the score of the POET
robot that solved it and the best score direct evolution reached on it with the
same budget. ``--figures DIR`` writes the ANNECS figure (median and range over
seeds) and seed 0's gallery and transfer heatmap.

    python benchmarks/bench_poet.py --quick        # 3 seeds, 20 iterations: ~15 min on 2 cores
    python benchmarks/bench_poet.py                # 3 seeds, 40 iterations: about 1-2 h on 2 cores
"""

from __future__ import annotations

import argparse
import json
import shutil
import tempfile
import time
from pathlib import Path

import numpy as np
import results_log

from evolvers.drivers.poet import PoetConfig, PoetRun, plot_annecs, poet_experiment


class BudgetReached(Exception):
    """Raised from a run's on_iteration once its budget of simulations is spent."""


def _config(args, **changes) -> PoetConfig:
    kw = {"reproduce_every": args.k, "transfer_every": args.t, "max_active": args.max_active,
          "score_cap": args.score_cap}  # fmt: skip
    kw.update(changes)
    return PoetConfig(**kw)


def run_seed(seed: int, args, root: Path) -> dict:
    exp = poet_experiment(pop_size=args.pop)
    out: dict = {"seed": seed}
    runs = {}
    for name, gen in (("poet", "mutate"), ("control", "random")):
        t0 = time.perf_counter()
        run = PoetRun(exp, root / f"seed-{seed}" / name, seed=seed, iterations=args.iterations,
                      config=_config(args, generator=gen), figures=bool(args.figures and seed == 0 and name == "poet"),
                      progress=False)  # fmt: skip
        run.run()
        runs[name] = run
        out[name] = {"annecs": run.annecs, "annecs_archive": run.annecs_archive,
                     "pairs": len(run.pairs), "solved": sum(p.solved is not None for p in run.pairs),
                     "evaluations": run.evaluations_total, "wall": time.perf_counter() - t0,
                     "annecs_curve": [r["annecs"] for r in run.rows]}  # fmt: skip
        print(f"seed {seed} {name:8s} ANNECS {run.annecs:2d} (archive {run.annecs_archive}), "
              f"{len(run.pairs)} pairs, {out[name]['solved']} solved, "
              f"{run.evaluations_total} simulations, {out[name]['wall']:.0f} s", flush=True)  # fmt: skip
    poet = runs["poet"]
    hardest = [(p, m) for p, m in poet.hardest_solved(n=len(poet.pairs)) if p.id != 0]
    out["rows"] = {k: r.rows for k, r in runs.items()}
    if not hardest:
        out["direct"] = None
        print(f"seed {seed} direct   no terrain but the start one was solved: nothing to compare")
        return out
    pair, mean = hardest[0]
    budget = poet.evaluations_total

    def stop(run, row):
        if row["evaluations_total"] >= budget:
            raise BudgetReached

    t0 = time.perf_counter()
    direct = PoetRun(exp, root / f"seed-{seed}" / "direct", seed=seed, iterations=100_000,
                     config=_config(args, reproduce_every=0, transfer_every=0,
                                    start_terrain=pair.terrain.to_dict()),
                     on_iteration=stop, figures=False, progress=False)  # fmt: skip
    try:
        direct.run()
    except BudgetReached:
        pass
    d = direct.pairs[0]
    best_direct = max(float(r["max_xy_dist_best"]) for r in direct.rows)
    out["direct"] = {
        "terrain": pair.terrain.to_dict(), "describe": pair.terrain.describe(), "pair": pair.id,
        "poet_score": pair.best_score, "mean_kept_score": mean, "direct_best": best_direct,
        "direct_solved": d.solved is not None, "budget": budget,
        "direct_evaluations": direct.evaluations_total, "wall": time.perf_counter() - t0,
    }  # fmt: skip
    print(f"seed {seed} direct   terrain '{pair.terrain.describe()}' (pair {pair.id}): POET robot "
          f"{pair.best_score:.2f}, direct evolution best {best_direct:.2f} after "
          f"{direct.evaluations_total} simulations (budget {budget}), "
          f"{out['direct']['wall']:.0f} s", flush=True)  # fmt: skip
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument(
        "--quick",
        action="store_true",
        help="20 iterations, 6 robots a pair, K = T = 3, 4 active pairs",
    )
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--iterations", type=int, help="iterations per run (default 40; quick 20)")
    ap.add_argument("--pop", type=int, help="robots per pair (default 8; quick 6)")
    ap.add_argument("--k", type=int, help="reproduce every K iterations (default 5; quick 3)")
    ap.add_argument("--t", type=int, help="transfer every T iterations (default 5; quick 3)")
    ap.add_argument("--max-active", type=int, help="active pairs (default 6; quick 4)")
    ap.add_argument("--score-cap", type=float,
                    help="scores saturate here (PoetConfig.score_cap; default: none)")  # fmt: skip
    ap.add_argument("--out", help="keep the run folders here (default: a temporary folder)")
    ap.add_argument("--figures", help="write the README figures into this folder")
    ap.add_argument("--no-append", action="store_true", help="do not append to RESULTS.md")
    args = ap.parse_args(argv)
    q = args.quick
    args.iterations = args.iterations or (20 if q else 40)
    args.pop = args.pop or (6 if q else 8)
    args.max_active = args.max_active or (4 if q else 6)
    args.k = args.k or (3 if q else 5)
    args.t = args.t or (3 if q else 5)
    t0 = time.perf_counter()
    results = []
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(args.out or tmp)
        for seed in range(args.seeds):
            results.append(run_seed(seed, args, root))
        if args.figures:
            fig = Path(args.figures)
            plot_annecs({"POET": [r["rows"]["poet"] for r in results],
                         "random terrains (control)": [r["rows"]["control"] for r in results]},
                        fig / "poet_annecs.png")  # fmt: skip
            for name in ("gallery", "transfers"):
                src = root / "seed-0" / "poet" / "figures" / f"{name}.png"
                if src.is_file():
                    shutil.copy(src, fig / f"poet_{name}.png")
    wall = time.perf_counter() - t0
    cfg = _config(args)
    head = (f"{args.seeds} seeds, {args.iterations} iterations, 4x4x4 CPPN robots with the "
            f"controller GA, 3 s simulated, {args.pop} robots a pair, K = {args.k}, T = {args.t}, "
            f"at most {args.max_active} active pairs; band [{cfg.mc_low:.2f}, {cfg.mc_high:.2f}], "
            f"reproduction {cfg.repro_threshold:.2f}, solved {cfg.solved_threshold:.2f} voxel lengths "
            f"of max_xy_dist{'' if args.score_cap is None else f', scores capped at {args.score_cap:g}'}; "
            f"{wall / 60:.0f} min wall")  # fmt: skip
    lines = [head, "", "| seed | ANNECS POET | ANNECS control | pairs POET / control | "
             "simulations POET / control | hardest solved terrain | POET robot | direct evolution, "
             "same budget |", "|---|---|---|---|---|---|---|---|"]  # fmt: skip
    for r in results:
        p, c, d = r["poet"], r["control"], r["direct"]
        terr = "-" if d is None else f"{d['describe']} (pair {d['pair']})"
        pr = "-" if d is None else f"{d['poet_score']:.2f}"
        dr = "-" if d is None else f"{d['direct_best']:.2f} ({d['direct_evaluations']} sims)"
        lines.append(f"| {r['seed']} | {p['annecs']} | {c['annecs']} | {p['pairs']} / {c['pairs']} "
                     f"| {p['evaluations']} / {c['evaluations']} | {terr} | {pr} | {dr} |")  # fmt: skip
    a_p = np.array([r["poet"]["annecs"] for r in results])
    a_c = np.array([r["control"]["annecs"] for r in results])
    directs = [r["direct"] for r in results if r["direct"] is not None]
    beaten = sum(not d["direct_solved"] for d in directs)
    lines += ["", f"ANNECS: POET median {np.median(a_p):g} (range {a_p.min()}-{a_p.max()}), control "
              f"median {np.median(a_c):g} (range {a_c.min()}-{a_c.max()}); POET above the control "
              f"on {int((a_p > a_c).sum())}/{len(results)} seeds, equal on {int((a_p == a_c).sum())}.",
              f"Direct evolution on the hardest terrain POET solved, with POET's whole budget: "
              f"did not reach the solved threshold on {beaten}/{len(directs)} seeds "
              f"({len(results) - len(directs)} seed(s) had no solved terrain but the start)."]  # fmt: skip
    text = "\n".join(lines)
    print()
    print(text)
    if not args.no_append:
        results_log.append(results_log.heading("bench_poet.py", q) + "\n" + text + "\n")
    if args.out:
        summary = [{k: v for k, v in r.items() if k != "rows"} for r in results]
        (Path(args.out) / "bench_poet.json").write_text(json.dumps(summary, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
