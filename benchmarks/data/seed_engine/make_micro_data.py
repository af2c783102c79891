"""Micro-case traces from the seed study's own engine (issue 16, point 1).

Small bodies whose centre-of-mass trace softgym's seed model must follow
sample by sample: a voxel dropped on the floor, muscle columns of 2, 5 and 6
voxels (the 5- and 6-voxel columns fold far enough for the seed's
self-collision schedule to act), bars of two materials, a 2x2x2 block hopping,
a body whose two legs collide, and a half-muscle block. Each runs in the seed
engine (``../shared/oracle``, not in CI) with the centre of mass recorded at
every step of the settling-free run (``InitCmTime`` 0 for the drop) or every
0.01 s, and the result is written to ``micro.json`` next to this script.

    python benchmarks/data/seed_engine/make_micro_data.py [--oracle ../shared/oracle]

The tests (``tests/engine/test_seed_oracle.py``) and ``benchmarks/fidelity_seed.py``
read ``micro.json``; neither needs ``../shared``.
"""

from __future__ import annotations

import argparse
import datetime as _dt
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np

from softgym.design.controller import Controller
from softgym.design.robot import RobotDesign
from softgym.design.vxa import to_vxa

HERE = Path(__file__).resolve().parent
OUT = HERE / "micro.json"

#: (dT degC, period s, muscle CTE) of the benchmark's regimes
REGIMES = {"gentle": (14.0, 0.25, 0.01), "medium": (18.0, 0.15, 0.025), "strong": (20.0, 0.1, 0.04)}


def _bar(*ids: int) -> list:
    return np.array(ids).reshape(-1, 1, 1).tolist()


def _legs() -> list:
    # an arch in the x-z plane: legs at x = 0 and x = 2, an Active_+ top bar;
    # the contracting bar swings the feet (6 bond hops apart) into each other
    g = np.zeros((3, 1, 3), dtype=int)
    g[0, 0, :] = 1
    g[2, 0, :] = 1
    g[:, 0, 2] = 3
    return g.tolist()


def _half_block() -> list:
    g = np.ones((4, 4, 4), dtype=int)
    g[:2] = 3
    return g.tolist()


#: name -> (grid as nested lists, regime, init_time s, sim_time s, trace interval s,
#:          sensitive: True where the case is known to amplify rounding-level differences)
CASES: dict[str, tuple] = {
    "drop_soft_voxel": ([[[1]]], "gentle", 0.0, 0.5, 0.002, False),
    "drop_bone_voxel": ([[[2]]], "gentle", 0.0, 0.2, 0.002, False),
    "column2_active_plus_strong": (np.full((1, 1, 2), 3).tolist(), "strong", 1.0, 3.0, 0.01, False),
    "column5_active_minus_strong": (np.full((1, 1, 5), 4).tolist(), "strong", 1.0, 3.0, 0.01, False),
    "column6_active_minus_strong": (np.full((1, 1, 6), 4).tolist(), "strong", 1.0, 3.0, 0.01, False),
    "column6_active_minus_gentle": (np.full((1, 1, 6), 4).tolist(), "gentle", 1.0, 3.0, 0.01, False),
    "bar_soft_muscle_strong": (_bar(1, 3), "strong", 1.0, 5.0, 0.01, False),
    "bar_muscle_soft_medium": (_bar(3, 1), "medium", 1.0, 5.0, 0.01, False),
    "bar_bone_muscle_gentle": (_bar(2, 3), "gentle", 1.0, 3.0, 0.01, True),
    "block2_active_plus_strong": (np.full((2, 2, 2), 3).tolist(), "strong", 1.0, 5.0, 0.01, False),
    "block2_half_active_strong": ([[[3, 3], [3, 3]], [[1, 1], [1, 1]]], "strong", 1.0, 5.0, 0.01, False),
    "arch_feet_collide_strong": (_legs(), "strong", 1.0, 3.0, 0.01, False),
    "block4_half_active_gentle": (_half_block(), "gentle", 1.0, 5.0, 0.01, False),
}


def design_of(grid: list, regime: str) -> RobotDesign:
    """The design of a micro-case grid under a regime of :data:`REGIMES`."""
    dT, period, cte = REGIMES[regime]
    return RobotDesign(np.asarray(grid), controller=Controller(dT, period, cte))


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--oracle", default=str(HERE.parents[2].parent / "shared" / "oracle"))
    a = ap.parse_args()
    sys.path.insert(0, a.oracle)
    from seed_oracle import run_vxa  # noqa: PLC0415  (needs ../shared)

    commit = subprocess.run(["git", "rev-parse", "HEAD"], capture_output=True, text=True,
                            cwd=HERE).stdout.strip()
    cases = {}
    for name, (grid, regime, init_time, sim_time, every, sensitive) in CASES.items():
        d = design_of(grid, regime)
        r = run_vxa(to_vxa(d, sim_time=sim_time, init_time=init_time), traces=every, timeout=300)
        if r.get("hung") or "trace" not in r:
            raise SystemExit(f"{name}: the oracle gave no trace ({r})")
        cases[name] = {
            "grid": grid, "regime": regime, "init_time": init_time, "sim_time": sim_time,
            "trace_interval": every, "sensitive": sensitive,
            "NormFinalDist": r.get("NormFinalDist"),
            "trace": [[round(v, 10) for v in row] for row in r["trace"]],
        }
        print(f"{name}: {len(r['trace'])} samples, NormFinalDist {r.get('NormFinalDist')}", flush=True)
    doc = {
        "header": {
            "what": "centre-of-mass traces of micro-cases from the seed study's engine (the oracle)",
            "trace_rows": "x, y, z (m), t (s); first row at the first step with t > InitCmTime, then "
                          "each at least trace_interval later (the engine prints 6 significant digits)",
            "regimes": {k: dict(zip(("dT", "period", "cte"), v)) for k, v in REGIMES.items()},
            "settings": "softgym.design.vxa.to_vxa defaults (the seed's): DtFrac 0.9, damping 1/0.8/0.01, "
                        "self-collision on, L 0.01 m",
            "command": "python benchmarks/data/seed_engine/make_micro_data.py",
            "created": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
            "softgym_commit": commit,
        },
        "cases": cases,
    }
    tmp = OUT.with_suffix(".tmp")
    tmp.write_text(json.dumps(doc, separators=(",", ":")) + "\n")
    os.replace(tmp, OUT)
    print(f"wrote {OUT}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
