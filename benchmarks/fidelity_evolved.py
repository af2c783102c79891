"""Fidelity of the seed preset on robots softgym's evolution produced (evolved materials included).

Reads ``benchmarks/data/seed_engine/evolved.json`` (the seed's own engine on
hall-of-fame and population members of study runs, each design embedded; made
by ``make_evolved_data.py``), runs the same designs and perturbation draws in
softgym's seed preset, and prints per design the oracle's and softgym's values
(median and range over the draws) of the seed's fitness (NormFinalDist on flat
ground; on the fence, MaxXYDist on the seed's diluted centre of mass), then the
agreement of per-design medians as in ``fidelity_seed.py``: softgym's draws
A against the oracle's draws B, and the oracle's draws A against its draws B
(its self-agreement, the yardstick), with A and B disjoint halves of the draws.
Chaotic bodies (the flying winners of materials treatment 1 change by up to 7x
between draws in either engine) are compared as pooled distributions over
designs and draws: median and quartiles per engine, A12 and a two-sided
permutation test (``evolvers.study.stats``).

    python benchmarks/fidelity_evolved.py            # every design (minutes to an hour: light
                                                     # evolved materials shrink dt up to 30x)
    python benchmarks/fidelity_evolved.py --json     # last line: the figures as JSON
    python benchmarks/fidelity_evolved.py --softgym-values /tmp/sg.json  # reuse softgym's
                                                     # values if the file exists, else save them

softgym's values are deterministic, so a saved file only skips recomputing them
(it is keyed by design name and draw and checked against the data's designs).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import fidelity_cases as fc  # noqa: E402
from fidelity_seed import agreement  # noqa: E402

from evolvers.study.stats import a12, permutation_pvalue  # noqa: E402
from softgym.design.robot import RobotDesign  # noqa: E402
from softgym.engine import SimConfig, Simulation  # noqa: E402
from softgym.fidelity import METRIC, SOFTGYM_METRIC, fence_terrain, load_evolved  # noqa: E402
from softgym.metrics import dilute, walk_metrics  # noqa: E402

DATA = HERE / "data" / "seed_engine" / "evolved.json"


def run_softgym(cases: dict[str, dict[str, Any]], draws: list[int],
                threads: int | None = None) -> dict[tuple[str, int], float]:  # fmt: skip
    """softgym's value of each design's metric per draw (one batch per terrain)."""
    out = {}
    for terrain in ("flat", "fence"):
        jobs = [(n, d) for n, c in cases.items() if c["terrain"] == terrain for d in draws]
        if not jobs:
            continue
        designs = [
            fc.perturb(RobotDesign.from_dict(cases[n]["design"]), d, name=n) for n, d in jobs
        ]
        world = fence_terrain() if terrain == "fence" else None
        r = Simulation(designs, SimConfig(model="seed"), n_threads=threads, terrain=world).run(5.0)
        if terrain == "fence":
            r = dilute(r)
        values = walk_metrics(r)[SOFTGYM_METRIC[METRIC[terrain]]]
        for (n, d), v, div in zip(jobs, values, r.diverged):
            out[(n, d)] = float("nan") if div else float(v)
    return out


def main() -> int:
    """Command line (see the module docstring)."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--threads", type=int, default=None)
    ap.add_argument("--json", action="store_true")
    ap.add_argument("--softgym-values", type=Path, default=None,
                    help="JSON of softgym's values: read if it exists, else written")  # fmt: skip
    a = ap.parse_args()
    cases, oracle = load_evolved(DATA)
    draws = sorted({d for _, d in oracle})
    half_a, half_b = draws[: (len(draws) + 1) // 2], draws[(len(draws) + 1) // 2 :]
    t0 = time.time()
    if a.softgym_values is not None and a.softgym_values.exists():
        saved = json.loads(a.softgym_values.read_text())
        ours = {(k.rsplit("|", 1)[0], int(k.rsplit("|", 1)[1])): float(v) for k, v in saved.items()}
        missing = {(n, d) for n in cases for d in draws} - set(ours)
        if missing:
            raise SystemExit(f"{a.softgym_values}: no value for {sorted(missing)[:3]}...")
    else:
        ours = run_softgym(cases, draws, a.threads)
        if a.softgym_values is not None:
            a.softgym_values.write_text(json.dumps({f"{n}|{d}": v for (n, d), v in ours.items()}))
    wall = time.time() - t0
    print(
        f"{len(cases)} evolved designs, draws {draws} (A {half_a}, B {half_b}); softgym {wall:.0f} s\n"
    )
    print(f"{'design':34s} {'terrain':7s} {'metric':13s} {'oracle median [min, max]':>30s} "
          f"{'softgym median [min, max]':>30s}")  # fmt: skip
    report: dict[str, Any] = {"designs": {}, "draws": draws, "softgym_wall_s": wall}
    for terrain in ("flat", "fence"):
        names = [n for n, c in cases.items() if c["terrain"] == terrain]
        o_all = [oracle.get((n, d), np.nan) for n in names for d in draws]
        s_all = [ours.get((n, d), np.nan) for n in names for d in draws]
        o_fin, s_fin = np.array(o_all)[np.isfinite(o_all)], np.array(s_all)[np.isfinite(s_all)]
        if o_fin.size and s_fin.size:
            q_o, q_s = np.percentile(o_fin, [25, 50, 75]), np.percentile(s_fin, [25, 50, 75])
            p = min(
                1.0, 2 * min(permutation_pvalue(s_fin, o_fin), permutation_pvalue(o_fin, s_fin))
            )
            pooled = {"oracle_quartiles": q_o.tolist(), "softgym_quartiles": q_s.tolist(),
                      "n_oracle": int(o_fin.size), "n_softgym": int(s_fin.size),
                      "a12_softgym_over_oracle": a12(s_fin, o_fin), "p_two_sided": p}  # fmt: skip
            report[f"{terrain}_pooled"] = pooled
            print(f"{terrain}: pooled over {len(names)} designs x draws, {METRIC[terrain]}: oracle "
                  f"{q_o[1]:.3g} [{q_o[0]:.3g}, {q_o[2]:.3g}] (n={o_fin.size}), softgym {q_s[1]:.3g} "
                  f"[{q_s[0]:.3g}, {q_s[2]:.3g}] (n={s_fin.size}); A12 {pooled['a12_softgym_over_oracle']:.2f}, "
                  f"two-sided permutation p {p:.3f}")  # fmt: skip
        rows = []
        for n, c in cases.items():
            if c["terrain"] != terrain:
                continue
            o = np.array([oracle.get((n, d), np.nan) for d in draws])
            s = np.array([ours.get((n, d), np.nan) for d in draws])
            if np.isnan(o).any() or np.isnan(s).any():
                print(
                    f"{n:34s} {terrain:7s} incomplete: a draw missing, hung or diverged (oracle {o}, softgym {s})"
                )
                continue
            print(f"{n:34s} {terrain:7s} {METRIC[terrain]:13s} "
                  f"{np.median(o):10.3g} [{o.min():8.3g}, {o.max():8.3g}] "
                  f"{np.median(s):10.3g} [{s.min():8.3g}, {s.max():8.3g}]")  # fmt: skip
            report["designs"][n] = {"oracle": o.tolist(), "softgym": s.tolist()}
            idx_a = [draws.index(d) for d in half_a]
            idx_b = [draws.index(d) for d in half_b]
            rows.append((np.median(s[idx_a]), np.median(o[idx_a]), np.median(o[idx_b])))
        if len(rows) < 2:
            continue
        s_a, o_a, o_b = (np.array(x) for x in zip(*rows))
        soft, self_ = agreement(s_a, o_b), agreement(o_a, o_b)
        report[terrain] = {"softgym_vs_oracle": soft, "oracle_vs_oracle": self_}
        print(
            f"\n{terrain}: {len(rows)} designs; Spearman, median |log10 ratio|, within 2x, within 3x"
        )
        for label, g in (("softgym vs oracle", soft), ("oracle vs oracle", self_)):
            print(f"  {label:18s} {g['spearman']:6.3f} {g['median_abs_log10']:6.3f} "
                  f"{100 * g['within_2x']:5.0f} % {100 * g['within_3x']:5.0f} %")  # fmt: skip
        print()
    if a.json:
        print(json.dumps(report))
    return 0


if __name__ == "__main__":
    sys.exit(main())
