#!/usr/bin/env python3
"""Run the seed's engine (the oracle) on robots that softgym's evolution produced; write evolved.json.

The other case sets (``make_oracle_data.py``) hold hand-made and random bodies
with the seed's default materials. Evolution goes further: materials treatment 1
evolves densities down to 1e3 kg/m^3 (the seed's lower bound, 1000x lighter than
the default) and its winners leave the ground for metres. Whether the seed's own
engine rewards such robots the same way is what this set measures.

Each given run folder contributes the designs of its hall of fame
(``best_designs.json``) and, with ``--population N``, N more individuals of its
latest checkpoint spread over the population's fitness range. A design on a task
with obstacles (the wall) is written as the seed wrote its fence workspace
(``make_oracle_data.fence_vxa``), others with ``to_vxa(design, **SIM_SETTINGS)``.
Draw k > 0 multiplies one voxel's density by 1 + 1e-6 (``fidelity_cases.perturb``).
Not run by CI (it needs ``../shared/oracle``); resumable (records already stored are
skipped; a run folder already in the file keeps the designs first taken from it, though
the run has moved on); the file embeds every design, so ``benchmarks/fidelity_evolved.py`` needs
nothing else::

    python benchmarks/data/seed_engine/make_evolved_data.py RUN [RUN ...] --population 5 --draws 5
"""

from __future__ import annotations

import argparse
import datetime as _dt
import os
import sys
import time
from concurrent.futures import FIRST_COMPLETED, ThreadPoolExecutor, wait
from pathlib import Path
from typing import Any

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "benchmarks"))
sys.path.insert(0, HERE)

import fidelity_cases as fc  # noqa: E402
import make_oracle_data as mod  # noqa: E402

from evolvers import Experiment, Individual  # noqa: E402
from softgym.design.robot import RobotDesign  # noqa: E402
from softgym.design.vxa import to_vxa  # noqa: E402
from softgym.io import latest_checkpoint, load_checkpoint, read_json  # noqa: E402

OUT = os.path.join(HERE, "evolved.json")


def run_designs(run: Path, population: int) -> dict[str, dict[str, Any]]:
    """``{name: {"design", "terrain", "source"}}`` of a run folder's chosen individuals."""
    config = read_json(run / "config.json")
    exp = Experiment.from_dict(config["experiment"])
    terrain = "fence" if exp.task.name == "wall" else "flat"
    if exp.task.spec not in ("flat", "wall"):
        raise SystemExit(
            f"{run}: task {exp.task.spec!r}: only flat and wall runs can be written for the seed"
        )
    stem = f"{exp.name}-s{config['seed']}"
    out: dict[str, dict[str, Any]] = {}
    for e in read_json(run / "best_designs.json")["best"]:
        src = {"run": str(run), "id": e["id"], "generation": e["generation"], "from": "hall of fame",
               "softgym_objectives": e["objectives"]}  # fmt: skip
        out[f"{stem}-id{e['id']}"] = {"design": e["design"], "terrain": terrain, "source": src}
    if population:
        state, _ = load_checkpoint(latest_checkpoint(run / "checkpoints"))
        inds = [Individual.from_dict(d) for d in state["population"]]
        inds = [i for i in inds if i.objectives and f"{stem}-id{i.id}" not in out]
        fit = exp.objectives[0].name
        inds.sort(key=lambda i: i.objectives.get(fit, -np.inf))
        picks = np.unique(
            np.linspace(0, len(inds) - 1, num=min(population, len(inds))).round().astype(int)
        )
        for k in picks.tolist():
            ind = inds[k]
            src = {"run": str(run), "id": ind.id, "generation": state["generation"],
                   "from": "population", "softgym_objectives": ind.objectives}  # fmt: skip
            design = ind.design(exp.shape).to_dict()
            out[f"{stem}-id{ind.id}"] = {"design": design, "terrain": terrain, "source": src}
    return out


def vxa_text(entry: dict[str, Any], name: str, draw: int) -> str:
    """The .vxa the oracle runs for a design and draw."""
    design = fc.perturb(RobotDesign.from_dict(entry["design"]), draw, name=name)
    if entry["terrain"] == "fence":
        return mod.fence_vxa(design)
    return to_vxa(design, **fc.SIM_SETTINGS)


def main(argv: list[str] | None = None) -> int:
    """Command line (see the module docstring)."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument(
        "runs",
        nargs="+",
        type=Path,
        help="run folders (config.json, best_designs.json, checkpoints/)",
    )
    ap.add_argument(
        "--population",
        type=int,
        default=0,
        help="also this many individuals of the latest population",
    )
    ap.add_argument("--draws", type=int, default=5, help="draws 0..N-1 (0 unperturbed)")
    ap.add_argument("--workers", type=int, default=1)
    ap.add_argument("--timeout", type=float, default=900.0)
    ap.add_argument("--retry-hung", action="store_true", help="run the records marked hung again")
    ap.add_argument("--oracle", default=os.path.join(ROOT, "..", "shared", "oracle"))
    ap.add_argument("--out", default=OUT)
    a = ap.parse_args(argv)
    if os.nice(0) < 10:
        os.nice(10 - os.nice(0))
    sys.path.insert(0, os.path.abspath(a.oracle))
    from seed_oracle import run_vxa

    command = "python " + " ".join(
        [os.path.relpath(os.path.abspath(__file__), ROOT)] + sys.argv[1:]
    )
    data = mod.load(a.out) or {
        "header": mod.make_header("evolved", command, a.timeout),
        "cases": {},
        "records": [],
    }
    h = data["header"]
    h["what"] = ("Results of the seed study's own physics engine (seed-voxelyze, ../shared/oracle) on robots "
                 "evolved by softgym (make_evolved_data.py): one record per (design, draw); regime 'evolved' "
                 "means the design's own materials and controller.")  # fmt: skip
    h["regimes"] = {"evolved": "the evolved design's own controller and materials"}
    h.setdefault("runs", []).append({"started": _dt.datetime.now().astimezone().isoformat(timespec="seconds"),
                                     "command": command})  # fmt: skip
    known = {c["source"]["run"] for c in data["cases"].values()}
    for run in a.runs:  # a run already in the file adds nothing: its designs stay as first drawn
        if str(run) not in known:
            data["cases"].update(run_designs(run, a.population))
    order = {
        (n, "evolved", d): i * 100 + d for i, n in enumerate(data["cases"]) for d in range(100)
    }
    if a.retry_hung:  # a run past the timeout on a loaded machine need not have diverged
        data["records"] = [r for r in data["records"] if not r["hung"]]
    done = {(r["case"], r["draw"]) for r in data["records"]}
    tasks = [(n, d) for d in range(a.draws) for n in data["cases"] if (n, d) not in done]
    print(f"{len(tasks)} oracle runs to do ({len(done)} stored), {a.workers} worker(s)", flush=True)
    t0, n_done = time.time(), 0

    def flush() -> None:
        h["updated"] = _dt.datetime.now().astimezone().isoformat(timespec="seconds")
        h["n_cases"], h["n_records"] = len(data["cases"]), len(data["records"])
        mod.write_atomic(a.out, data, order)

    it = iter(tasks)
    pending: dict[Any, tuple[str, int]] = {}
    try:
        with ThreadPoolExecutor(max_workers=a.workers) as pool:

            def submit_next() -> None:
                for n, d in it:
                    text = vxa_text(data["cases"][n], n, d)
                    pending[pool.submit(run_vxa, text, mod.TRACE_DT, a.timeout)] = (n, d)
                    return

            for _ in range(2 * a.workers):
                submit_next()
            while pending:
                finished, _ = wait(list(pending), return_when=FIRST_COMPLETED)
                for fut in finished:
                    n, d = pending.pop(fut)
                    res = fut.result()
                    voxel = fc.perturbed_voxel(
                        RobotDesign.from_dict(data["cases"][n]["design"]), d, name=n
                    )
                    rec = {"case": n, "regime": "evolved", "draw": d,
                           "perturbed_voxel": list(voxel) if voxel is not None else None,
                           "hung": bool(res.get("hung", False)),
                           "wall_s": round(float(res.get("wall_s", float("nan"))), 3)}  # fmt: skip
                    rec.update({k: res.get(k) for k in mod.METRICS})
                    trace = res.get("trace")
                    rec["trace"] = [[round(v, 7) for v in row] for row in trace] if trace else None
                    data["records"].append(rec)
                    n_done += 1
                    print(f"[{n_done}/{len(tasks)}] {n} draw {d}: NormFinalDist {rec['NormFinalDist']} "
                          f"MaxXYDist {rec['MaxXYDist']} hung {rec['hung']} {rec['wall_s']:.0f} s "
                          f"| {(time.time() - t0) / 60:.1f} min", flush=True)  # fmt: skip
                    flush()
                    submit_next()
    finally:
        flush()
    return 0


if __name__ == "__main__":
    sys.exit(main())
