#!/usr/bin/env python3
"""Repair run folders resumed across the change that added ``score`` to the stored metrics.

The bug (fixed in the commit that added this script): the phenotype cache was
written to checkpoints as a bare value table whose columns were the stored
metrics in their order of the day, and read back by position. The task suite
added ``score`` as the fourth stored metric, so a run checkpointed before that
and resumed after it read every cached result shifted by one column::

    score <- diverged, diverged <- n_voxels, n_voxels <- n_muscle,
    n_muscle <- n_old_materials, n_old_materials <- n_bone,
    n_bone <- n_tissue, n_tissue missing

(the three fitness measures were unaffected). Individuals that got their
results from the cache after the resume carry the shifted values, and so do the
log's ``top_*`` and ``crosser_*`` counts and its population counts
(``n_voxels_*``, ``n_old_materials_*``... of the generations after the resume).
Checkpoints now store the column names (``cache_metrics``); a checkpoint of the
damaged kind (ten unnamed columns) no longer loads and names this script.

What this script does, for each checkpoint of each run folder given:

* cache rows whose ``n_tissue`` is missing (the shifted ones) are shifted back,
  ``score`` set to the measure it equals in the run's intact rows; the column
  names are stored;
* every individual in the state (population, hall of fame, archives) whose
  objectives have ``score`` but no ``n_tissue`` is shifted back the same way;
* log rows: ``top_*`` / ``crosser_*`` counts logged from shifted objectives
  (their ``*_n_tissue`` is NaN) are shifted back, and, with ``--resumed-at G``,
  the population count columns of generations >= G, which mixed shifted and
  intact values and cannot be recomputed, become NaN;

then writes the checkpoint (same step, fresh digests), log.csv / log.jsonl and
the best-design files. Selection that used a count as an objective (e.g.
``n_old_materials`` in materials treatment 1) during the affected generations
cannot be undone: say so wherever the run is reported. ::

    python scripts/repair_cache_columns.py RUN [RUN ...] [--resumed-at G] [--dry-run]
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path
from typing import Any

import numpy as np

from evolvers.evaluation.evaluator import STORED_METRICS
from evolvers.evaluation.experiments import Experiment
from evolvers.recording.recorder import RunRecorder, add_run_note
from softgym.io import list_checkpoints, load_checkpoint, read_json, save_checkpoint

#: The stored metrics when the damage happened (``score`` fourth); the current list.
DAMAGED_COLUMNS = (
    "norm_final_dist", "max_xy_dist", "l_coefficient", "score", "diverged",
    "n_voxels", "n_muscle", "n_old_materials", "n_bone", "n_tissue",
)  # fmt: skip
#: Shifted name -> the true metric whose value it holds.
SHIFT = {
    "score": "diverged",
    "diverged": "n_voxels",
    "n_voxels": "n_muscle",
    "n_muscle": "n_old_materials",
    "n_old_materials": "n_bone",
    "n_bone": "n_tissue",
}
COUNTS = ("n_voxels", "n_muscle", "n_old_materials", "n_bone", "n_tissue")
#: Population columns of a log row computed from every individual's objectives.
POPULATION_COLUMNS = tuple(
    f"{m}_{s}" for m in COUNTS for s in ("best", "median", "mean", "worst")
) + ("muscle_fraction_median",)


def unshift(obj: dict[str, float], score_from: str | None) -> dict[str, float]:
    """The true objectives of a shifted result (see the module docstring)."""
    out = {k: v for k, v in obj.items() if k not in SHIFT}
    for shifted, true in SHIFT.items():
        if shifted in obj:
            out[true] = obj[shifted]
    if score_from is not None and score_from in out:
        out["score"] = out[score_from]
    return out


def is_shifted(obj: dict[str, Any]) -> bool:
    """Whether objectives were read shifted: ``score`` present, ``n_tissue`` missing."""
    return "score" in obj and "n_tissue" not in obj and "n_bone" in obj


def score_metric(rows: list[dict[str, float]]) -> str | None:
    """The fitness measure ``score`` equals in every intact result (None if unknown)."""
    names = []
    for m in ("norm_final_dist", "max_xy_dist", "l_coefficient"):
        same = [r["score"] == r[m] for r in rows if "score" in r and m in r]
        if same and all(same):
            names.append(m)
    return names[0] if names else None


def _walk_objectives(node: Any, found: list[dict[str, Any]]) -> None:
    if isinstance(node, dict):
        if isinstance(node.get("objectives"), dict) and "cppn" in node:
            found.append(node)
        for v in node.values():
            _walk_objectives(v, found)
    elif isinstance(node, list):
        for v in node:
            _walk_objectives(v, found)


def repair_checkpoint(
    state: dict[str, Any], arrays: dict[str, np.ndarray], resumed_at: int | None
) -> dict[str, int]:
    """Repair one checkpoint's state and arrays in place; returns counts of what changed."""
    counts = {"cache_rows": 0, "individuals": 0, "row_tops": 0, "rows_blanked": 0}
    intact: list[dict[str, float]] = []
    cache_objs: list[dict[str, float]] = []
    if "cache_keys" in arrays and "cache_metrics" not in arrays:
        values = np.asarray(arrays["cache_values"], dtype=np.float64)
        if values.shape[1] != len(DAMAGED_COLUMNS):
            raise SystemExit(
                f"cache_values has {values.shape[1]} columns, expected {len(DAMAGED_COLUMNS)}"
            )
        cache_objs = [{m: float(v) for m, v in zip(DAMAGED_COLUMNS, row) if not math.isnan(v)}
                      for row in values]  # fmt: skip
        intact += [o for o in cache_objs if not is_shifted(o)]
    individuals: list[dict[str, Any]] = []
    _walk_objectives(state, individuals)
    intact += [i["objectives"] for i in individuals if not is_shifted(i["objectives"])]
    score_from = score_metric(intact)
    if cache_objs:
        fixed = []
        for o in cache_objs:
            if is_shifted(o):
                o = unshift(o, score_from)
                counts["cache_rows"] += 1
            fixed.append([o.get(m, np.nan) for m in STORED_METRICS])
        arrays["cache_values"] = np.array(fixed, dtype=np.float64).reshape(
            len(fixed), len(STORED_METRICS)
        )
        arrays["cache_metrics"] = np.array(STORED_METRICS, dtype="<U32")
    for ind in individuals:
        if is_shifted(ind["objectives"]):
            ind["objectives"] = unshift(ind["objectives"], score_from)
            counts["individuals"] += 1
    for row in state.get("rows", []):
        for prefix in ("top", "crosser"):
            tissue = row.get(f"{prefix}_n_tissue")
            if isinstance(tissue, float) and math.isnan(tissue) and f"{prefix}_n_voxels" in row \
                    and not math.isnan(row[f"{prefix}_n_voxels"]):  # fmt: skip
                old = {m: row[f"{prefix}_{m}"] for m in COUNTS}
                true = {
                    "n_muscle": old["n_voxels"],
                    "n_old_materials": old["n_muscle"],
                    "n_bone": old["n_old_materials"],
                    "n_tissue": old["n_bone"],
                }
                true["n_voxels"] = true["n_muscle"] + true["n_bone"] + true["n_tissue"]
                row.update({f"{prefix}_{m}": v for m, v in true.items()})
                counts["row_tops"] += 1
        if resumed_at is not None and row.get("generation", -1) >= resumed_at:
            blanked = [c for c in POPULATION_COLUMNS if c in row]
            row.update({c: float("nan") for c in blanked})
            counts["rows_blanked"] += bool(blanked)
    return counts


def note_text(counts: dict[str, int], resumed_at: int | None, objectives: list[str],
              until: int | None = None) -> str:  # fmt: skip
    """The note a repaired run folder gets (``notes.jsonl``)."""
    used = [o for o in objectives if o in COUNTS]
    since = f"from generation {resumed_at} " if resumed_at is not None else ""
    if since and until is not None:
        since = f"in generations {resumed_at}-{until} "
    text = (
        f"resumed across the addition of 'score' to the stored metrics: cached results were read "
        f"one column off {since}(composition counts and 'diverged' only; the fitness measures were "
        f"right). Repaired by scripts/repair_cache_columns.py: {counts['cache_rows']} cached "
        f"results, {counts['individuals']} individuals, {counts['row_tops']} log rows' "
        "best-robot counts restored"
        + (f"; the population count columns of {counts['rows_blanked']} generations are NaN"
           if counts["rows_blanked"] else "")
        + (f". Selection in those generations used the shifted {', '.join(used)} of cached "
           "robots (an objective here): it cannot be undone" if used else
           ". No count is an objective here: selection was not affected")
        + "."
    )  # fmt: skip
    return text


def repair_run(run: Path, resumed_at: int | None, dry_run: bool) -> None:
    """Repair every checkpoint of a run folder, then its logs and best-design files."""
    ckpt_dir = run / "checkpoints"
    paths = list_checkpoints(ckpt_dir)
    if not paths:
        raise SystemExit(f"{run}: no checkpoints")
    last_state, last_counts = None, {}
    for path in paths:
        doc = read_json(path)
        state, arrays = load_checkpoint(path)
        arrays = {k: np.asarray(v) for k, v in arrays.items()}
        counts = repair_checkpoint(state, arrays, resumed_at)
        print(f"{path}: {json.dumps(counts)}")
        if not dry_run:
            save_checkpoint(ckpt_dir, int(doc["step"]), state, arrays, keep=len(paths) + 1,
                            identity=doc.get("identity"))  # still the run's own checkpoint
        last_state, last_counts = state, counts
    if dry_run or last_state is None:
        return
    config = read_json(run / "config.json")
    if any(last_counts.values()):
        objectives = [o["name"] for o in config["experiment"]["objectives"]]
        text = note_text(last_counts, resumed_at, objectives, until=last_state.get("generation"))
        add_run_note(run, text, script="scripts/repair_cache_columns.py", resumed_at=resumed_at,
                     repaired=last_counts)  # fmt: skip
    rec = RunRecorder(run, Experiment.from_dict(config["experiment"]), seed=int(config["seed"]),
                      backend=str(config["backend"]), figures=False, gif=False, progress=False)  # fmt: skip
    rec.rows = list(last_state["rows"])
    rec.hall_of_fame = list(last_state["hall_of_fame"])
    rec.write_log()
    rec.write_best()
    print(f"{run}: log.csv, log.jsonl and best designs rewritten")


def main(argv: list[str] | None = None) -> int:
    """Command line (see the module docstring)."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("runs", nargs="+", type=Path, help="run folders (with checkpoints/)")
    ap.add_argument("--resumed-at", type=int, default=None,
                    help="first generation run after the damaging resume: its and later rows' "
                         "population count columns become NaN")  # fmt: skip
    ap.add_argument("--dry-run", action="store_true", help="report, write nothing")
    args = ap.parse_args(argv)
    for run in args.runs:
        repair_run(run, args.resumed_at, args.dry_run)
    return 0


if __name__ == "__main__":
    sys.exit(main())
