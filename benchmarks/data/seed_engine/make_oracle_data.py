#!/usr/bin/env python3
"""Run the seed study's own engine (the oracle) on the fidelity case set; write the JSON data.

Not run by CI: it needs ``../shared/oracle`` (``seed_oracle.py`` and the engine binary,
see its README). The cases, regimes and perturbations are defined in
``benchmarks/fidelity_cases.py``; this script writes one file per case set
(``structured.json``, ``random.json``, ``fence.json``) beside itself::

    nohup nice -n 10 python benchmarks/data/seed_engine/make_oracle_data.py > /tmp/oracle_gen.log 2>&1 &

Every (case, regime, draw) is one oracle run of ``softgym.design.vxa.to_vxa`` of
``fidelity_cases.case_design(case, regime, draw)`` with ``fidelity_cases.SIM_SETTINGS``
and centre-of-mass traces every 0.1 s. Fence cases are written the way the seed's
obstacle code wrote them (the seed study; ``to_vxa`` cannot write obstacles): a
50x50x6 workspace with the robot at voxel (22, 22, 0), the 44 wall voxels of material 5
in the structure and four ``<FRegion>`` boundary conditions with ``DofFixed`` 63 that
fix them.

Draws 0 and 1 of every case and regime run first, then draws 2.. so that partial data
is already usable. The script resumes: records already in the files are skipped
(``--retry-hung`` runs the hung ones again). Files are rewritten atomically (temp file
+ ``os.replace``) after every few results. Two oracle processes run at a time.
"""

from __future__ import annotations

import argparse
import datetime as _dt
import json
import os
import subprocess
import sys
import tempfile
import time
from concurrent.futures import FIRST_COMPLETED, ThreadPoolExecutor, wait
from typing import Any

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "benchmarks"))

import fidelity_cases as fc  # noqa: E402

from softgym.design.robot import RobotDesign  # noqa: E402
from softgym.design.vxa import to_vxa  # noqa: E402

SETS = ("structured", "random", "fence", "heldout")
TRACE_DT = 0.1
METRICS = ("NormFinalDist", "MaxXYDist", "TimeMaxXYDist", "LCoefficient")
_NO_BCS = "<Fixed_Regions><NumFixed>0</NumFixed></Fixed_Regions>"


# --------------------------------------------------------------------------------------------
# .vxa text of a run
# --------------------------------------------------------------------------------------------


def _fence_walls() -> list[tuple[float, float, float, float]]:
    """The seed's four wall regions (X, Y, dX, dY as fractions of the workspace), as its Obstacle class."""
    ex, ey, _ = fc.FENCE["env_size"]
    d = fc.FENCE["side"]
    lo_x, lo_y = (ex - d) / 2, (ey - d) / 2
    return [
        (lo_x / ex, lo_y / ey, 1 / ex, d / ey),  # x = 19, y 19..30
        (lo_x / ex, (ey - lo_y - 1) / ey, d / ex, 1 / ey),  # y = 30, x 19..30
        ((ex - lo_x - 1) / ex, lo_y / ey, 1 / ex, d / ey),  # x = 30
        (lo_x / ex, lo_y / ey, d / ex, 1 / ey),  # y = 19
    ]


def _py2str(v: float) -> str:
    """A float as the seed's Python 2 ``str()`` wrote it (12 significant digits)."""
    return f"{v:.12g}"


def fence_vxa(design: RobotDesign) -> str:
    """The .vxa of ``design`` (a <= 6x6x6 robot) inside the seed's fence (the seed study)."""
    ex, ey, ez = fc.FENCE["env_size"]
    ox, oy, oz = fc.FENCE["robot_offset"]
    lo, hi, h, wall = (
        fc.FENCE["wall_lo"],
        fc.FENCE["wall_hi"],
        fc.FENCE["height"],
        fc.FENCE["wall_material"],
    )
    if wall not in design.palette or design.palette[wall].name != "Obstacle":
        raise ValueError(f"the design's palette has no Obstacle material at id {wall}")
    grid = np.zeros((ex, ey, ez), dtype=np.int8)
    grid[lo, lo : hi + 1, :h] = wall
    grid[hi, lo : hi + 1, :h] = wall
    grid[lo : hi + 1, lo, :h] = wall
    grid[lo : hi + 1, hi, :h] = wall
    if int((grid == wall).sum()) != fc.FENCE["n_wall_voxels"]:
        raise AssertionError("fence voxel count")
    nx, ny, nz = design.shape
    grid[ox : ox + nx, oy : oy + ny, oz : oz + nz] = design.grid
    env = design.replace(grid=grid)
    text = to_vxa(env, **fc.SIM_SETTINGS)
    if text.count(_NO_BCS) != 1:
        raise RuntimeError(
            "to_vxa's output changed: cannot find its empty <Fixed_Regions> to replace"
        )
    walls = _fence_walls()
    bcs = [f"<Boundary_Conditions><NumBCs>{len(walls)}</NumBCs>"]
    for x, y, dx, dy in walls:
        bcs.append(
            f"<FRegion><PrimType>0</PrimType><X>{_py2str(x)}</X><Y>{_py2str(y)}</Y><Z>0</Z>"
            f"<dX>{_py2str(dx)}</dX><dY>{_py2str(dy)}</dY><dZ>{_py2str(h / ez)}</dZ>"
            "<alfa>1</alfa><DofFixed>63</DofFixed></FRegion>"
        )
    bcs.append("</Boundary_Conditions>")
    return text.replace(_NO_BCS, "".join(bcs))


def run_text(case: fc.Case, regime: str, draw: int) -> str:
    """The .vxa text the oracle runs for (case, regime, draw)."""
    design = fc.case_design(case, regime, draw)
    if case.terrain == "fence":
        return fence_vxa(design)
    return to_vxa(design, **fc.SIM_SETTINGS)


# --------------------------------------------------------------------------------------------
# Records and files
# --------------------------------------------------------------------------------------------


def make_record(case: fc.Case, regime: str, draw: int, res: dict[str, Any]) -> dict[str, Any]:
    voxel = fc.perturbed_voxel(case, draw)
    rec: dict[str, Any] = {
        "case": case.name,
        "regime": regime,
        "draw": draw,
        "perturbed_voxel": list(voxel) if voxel is not None else None,
        "hung": bool(res.get("hung", False)),
        "wall_s": round(float(res.get("wall_s", float("nan"))), 3),
    }
    for key in METRICS:
        rec[key] = res.get(key)
    if "error" in res:
        rec["error"] = res["error"]
    trace = res.get("trace")
    rec["trace"] = (
        [[round(x, 7), round(y, 7), round(z, 7), round(t, 6)] for x, y, z, t in trace]
        if trace
        else None
    )
    return rec


def _git_commit() -> str:
    try:
        out = subprocess.run(
            ["git", "rev-parse", "HEAD"], cwd=ROOT, capture_output=True, text=True, check=True
        )
        return out.stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def make_header(set_name: str, command: str, timeout: float) -> dict[str, Any]:
    now = _dt.datetime.now().astimezone().isoformat(timespec="seconds")
    header: dict[str, Any] = {
        "what": (
            "Results of the seed study's own physics engine (seed-voxelyze, ../shared/oracle) on the "
            f"{set_name!r} cases of benchmarks/fidelity_cases.py: one record per (case, regime, draw)."
        ),
        "set": set_name,
        "created": now,
        "updated": now,
        "command": command,
        "runs": [],
        "softgym_commit": _git_commit(),
        "oracle": {
            "engine": "seed-voxelyze (Ev-SoftBots evosoro/_voxcad voxelyze, g++ -O3), via seed_oracle.run_vxa",
            "traces_s": TRACE_DT,
            "timeout_s": timeout,
            "vxa_writer": "softgym.design.vxa.to_vxa(design, **SIM_SETTINGS)",
            "sim_settings": fc.SIM_SETTINGS,
            "vxa_fixed": {
                "Integrator": 0,
                "BondDampingZ": 1,
                "ColDampingZ": 0.8,
                "SlowDampingZ": 0.01,
                "SelfColEnabled": 1,
                "ColSystem": 3,
                "CollisionHorizon": 2,
                "GravAcc": -9.81,
                "FloorEnabled": 1,
                "TempBase": 25,
                "TempAmp": "25 + dT",
                "StopConditionType": 2,
                "StopConditionValue": 5,
                "InitCmTime": 1,
            },
            "parallel_runs": 2,
        },
        "regimes": fc.REGIMES,
        "perturbation": {
            "draw_0": "unperturbed",
            "draw_k": "one robot voxel (perturbed_voxel, grid index i, j, k) gets a palette copy of its "
            f"material with density x (1 + {fc.PERTURBATION}); see fidelity_cases.perturb",
        },
        "record_fields": {
            "case": "case name (fidelity_cases)",
            "regime": "key of regimes",
            "draw": "0 = unperturbed, k >= 1 = perturbed",
            "perturbed_voxel": "[i, j, k] grid index of the perturbed voxel, null for draw 0",
            "hung": "true: the engine did not finish within timeout_s (it spins forever after a "
            "divergence); metrics and trace are then null",
            "wall_s": "oracle wall time (s)",
            "NormFinalDist": "XY distance of the CM from t = InitCmTime to the end, voxel lengths",
            "MaxXYDist": "max(|dx|, |dy|) of the final CM, voxel lengths (the seed study)",
            "TimeMaxXYDist": "first trace time within 0.1 voxel of MaxXYDist (s)",
            "LCoefficient": "MaxXYDist^2 / TimeMaxXYDist",
            "trace": "CM samples [x, y, z (m, rounded to 1e-7; the engine prints 6 significant digits), "
            "t (s)], the first at the first step with t > 1 s, then every >= 0.1 s",
        },
        "notes": [
            "The oracle reports no final CM (FinalCOM); the last trace sample is at ~4.9 s.",
            "Flat cases: the robot grid's corner is at the origin, voxel (i, j, k) centred at "
            "((i + 0.5) L, (j + 0.5) L, (k + 0.5) L), L = 0.01 m.",
        ],
    }
    if set_name == "fence":
        header["fence"] = dict(fc.FENCE)
        header["notes"] += [
            "Fence cases: the oracle's frame is the 50x50x6 workspace; the robot grid's corner is at "
            "robot_offset * L = (0.22, 0.22, 0) m.",
            "The seed's CM (trace and every metric) includes the 44 fixed 1 kg wall voxels "
            "(docs/PHYSICS.md): robot-only displacement = diluted x (robot_mass_kg + 44) / "
            "robot_mass_kg; the walls' own CM is (0.25, 0.25, 0.005) m.",
            "The walls are written as the seed did: material 5 voxels plus four <FRegion> boundary "
            "conditions (DofFixed 63) in <Boundary_Conditions>; softgym's to_vxa cannot write them.",
        ]
    return header


def load(path: str) -> dict[str, Any] | None:
    if not os.path.exists(path):
        return None
    with open(path, encoding="utf-8") as fh:
        return json.load(fh)


def write_atomic(path: str, data: dict[str, Any], order: dict[tuple[str, str, int], int]) -> None:
    """Write ``data`` as JSON, one record per line, via a temp file and os.replace."""
    recs = sorted(
        data["records"], key=lambda r: order.get((r["case"], r["regime"], r["draw"]), 1 << 30)
    )
    parts = [
        "{\n",
        '"header": ' + json.dumps(data["header"], indent=1) + ",\n",
        '"cases": {\n'
        + ",\n".join(
            json.dumps(k) + ": " + json.dumps(v, separators=(",", ":"))
            for k, v in data["cases"].items()
        )
        + "\n},\n",
        '"records": [\n'
        + ",\n".join(json.dumps(r, separators=(",", ":")) for r in recs)
        + "\n]\n}\n",
    ]
    fd, tmp = tempfile.mkstemp(prefix=".tmp_", suffix=".json", dir=os.path.dirname(path))
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as fh:
            fh.write("".join(parts))
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


# --------------------------------------------------------------------------------------------
# Main
# --------------------------------------------------------------------------------------------


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sets", nargs="+", default=list(SETS), choices=SETS)
    ap.add_argument("--cases", default="", help="comma-separated case names to run (default: all)")
    ap.add_argument("--regimes", nargs="+", default=list(fc.REGIMES), choices=list(fc.REGIMES))
    ap.add_argument(
        "--draws", type=int, default=7, help="draws 0..N-1 (default 7: 0 and six perturbed)"
    )
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--timeout", type=float, default=120.0)
    ap.add_argument("--retry-hung", action="store_true", help="run the records marked hung again")
    ap.add_argument("--oracle", default=os.path.join(ROOT, "..", "shared", "oracle"))
    ap.add_argument("--out-dir", default=HERE)
    ap.add_argument(
        "--write-every", type=int, default=8, help="rewrite the files after this many results"
    )
    a = ap.parse_args(argv)

    if os.nice(0) < 10:  # be kind to the machine's other users, as `nice -n 10` would
        os.nice(10 - os.nice(0))
    sys.path.insert(0, os.path.abspath(a.oracle))
    from seed_oracle import run_vxa

    command = "python " + " ".join(
        [os.path.relpath(os.path.abspath(__file__), ROOT)] + sys.argv[1:]
    )
    only = {n for n in a.cases.split(",") if n}
    sets = fc.case_sets()
    os.makedirs(a.out_dir, exist_ok=True)

    files: dict[str, dict[str, Any]] = {}
    done: set[tuple[str, str, int]] = set()
    order: dict[tuple[str, str, int], int] = {}
    cases_by_name: dict[str, fc.Case] = {}
    for s in a.sets:
        path = os.path.join(a.out_dir, f"{s}.json")
        data = load(path) or {
            "header": make_header(s, command, a.timeout),
            "cases": {},
            "records": [],
        }
        started = _dt.datetime.now().astimezone().isoformat(timespec="seconds")
        data["header"].setdefault("runs", []).append({"started": started, "command": command})
        for c in sets[s]:
            cases_by_name[c.name] = c
            grid = c.design.to_dict()["grid"]
            if c.name in data["cases"]:
                fc.check_grid(c, data["cases"][c.name]["grid"])
            data["cases"][c.name] = {"terrain": c.terrain, "grid": grid, "meta": c.meta}
            for r in fc.REGIMES:
                for d in range(max(a.draws, 7)):
                    order[(c.name, r, d)] = len(order)
        if a.retry_hung:
            data["records"] = [r for r in data["records"] if not r["hung"]]
        done |= {(r["case"], r["regime"], r["draw"]) for r in data["records"]}
        files[s] = data

    # draws 0 and 1 of everything first, then the others
    tasks: list[tuple[str, fc.Case, str, int]] = []
    for phase in (range(0, min(2, a.draws)), range(2, a.draws)):
        for s in a.sets:
            for c in sets[s]:
                if only and c.name not in only:
                    continue
                for d in phase:
                    for r in a.regimes:
                        if (c.name, r, d) not in done:
                            tasks.append((s, c, r, d))
    print(
        f"{len(tasks)} runs to do ({len(done)} records already stored); workers {a.workers}, "
        f"timeout {a.timeout} s, niceness {os.nice(0)}",
        flush=True,
    )

    t0 = time.time()
    dirty: set[str] = set()
    since_write = 0
    n_done = 0
    busy = 0.0

    def flush() -> None:
        stamp = _dt.datetime.now().astimezone().isoformat(timespec="seconds")
        for s in sorted(dirty):
            files[s]["header"]["updated"] = stamp
            files[s]["header"]["n_cases"] = len(files[s]["cases"])
            files[s]["header"]["n_records"] = len(files[s]["records"])
            write_atomic(os.path.join(a.out_dir, f"{s}.json"), files[s], order)
        dirty.clear()

    it = iter(tasks)
    pending: dict[Any, tuple[str, fc.Case, str, int]] = {}
    try:
        with ThreadPoolExecutor(max_workers=a.workers) as pool:

            def submit_next() -> bool:
                for task in it:
                    s, c, r, d = task
                    pending[pool.submit(run_vxa, run_text(c, r, d), TRACE_DT, a.timeout)] = task
                    return True
                return False

            for _ in range(2 * a.workers):
                submit_next()
            while pending:
                finished, _ = wait(list(pending), return_when=FIRST_COMPLETED)
                for fut in finished:
                    s, c, r, d = pending.pop(fut)
                    res = fut.result()
                    rec = make_record(c, r, d, res)
                    files[s]["records"].append(rec)
                    dirty.add(s)
                    since_write += 1
                    n_done += 1
                    busy += rec["wall_s"]
                    elapsed = time.time() - t0
                    eta = elapsed / n_done * (len(tasks) - n_done)
                    print(
                        f"[{n_done}/{len(tasks)}] {s} {c.name} {r} draw {d}: "
                        f"NormFinalDist {rec['NormFinalDist']} hung {rec['hung']} {rec['wall_s']:.1f} s "
                        f"| elapsed {elapsed / 60:.1f} min, eta {eta / 60:.1f} min",
                        flush=True,
                    )
                    submit_next()
                if since_write >= a.write_every:
                    flush()
                    since_write = 0
    finally:
        flush()
    print(
        f"done: {n_done} runs in {(time.time() - t0) / 60:.1f} min (oracle busy {busy / 60:.1f} min)",
        flush=True,
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
