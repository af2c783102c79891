"""Checkpoints damaged by the positional cache read, and scripts/repair_cache_columns.py.

Before checkpoints stored the cache's column names, a run checkpointed before
``score`` joined the stored metrics and resumed after read every cached result
one column off. These tests damage a real run's checkpoints the way that bug
did, check that the damage is refused with a message naming the repair script,
and that the script restores the exact results, so the run resumes as if
nothing had happened.
"""

import importlib.util
import json
import math
import shutil
from pathlib import Path

import numpy as np
import pytest
from evolver_helpers import tiny

from evolvers.drivers.runner import EvolutionRun, population_summary
from evolvers.recording.recorder import read_run_notes
from softgym.design import CompositionRules
from softgym.exceptions import CheckpointError
from softgym.io import list_checkpoints, load_checkpoint, read_json, save_checkpoint

ROOT = Path(__file__).resolve().parents[3]
_spec = importlib.util.spec_from_file_location(
    "repair", ROOT / "scripts" / "repair_cache_columns.py"
)
repair = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(repair)

COUNTS = ("n_voxels", "n_muscle", "n_old_materials", "n_bone", "n_tissue")


def _shift(obj):
    """What the bug did to one result (written independently of the script)."""
    out = {k: obj[k] for k in ("norm_final_dist", "max_xy_dist", "l_coefficient")}
    out.update(score=obj["diverged"], diverged=obj["n_voxels"], n_voxels=obj["n_muscle"],
               n_muscle=obj["n_old_materials"], n_old_materials=obj["n_bone"],
               n_bone=obj["n_tissue"])  # fmt: skip
    return out


def _damage(run: Path) -> None:
    for path in list_checkpoints(run / "checkpoints"):
        state, arrays = load_checkpoint(path)
        names = [str(m) for m in arrays.pop("cache_metrics").tolist()]
        assert tuple(names) == repair.DAMAGED_COLUMNS
        values = np.array(arrays["cache_values"])
        for i in range(0, len(values), 2):  # every other cached result read shifted
            row = _shift(dict(zip(names, values[i])))
            values[i] = [row.get(m, np.nan) for m in names]
        arrays["cache_values"] = values
        for ind in state["population"][::2]:
            ind["objectives"] = _shift(ind["objectives"])
        for row in state["rows"][-1:]:
            shifted = _shift({**{m: row[f"top_{m}"] for m in COUNTS}, "diverged": 0.0,
                              "norm_final_dist": 0, "max_xy_dist": 0, "l_coefficient": 0})  # fmt: skip
            row.update({f"top_{m}": shifted.get(m, math.nan) for m in COUNTS})
        doc = read_json(path)
        save_checkpoint(run / "checkpoints", doc["step"], state, arrays, keep=10,
                        identity=doc["identity"])  # fmt: skip


def test_a_damaged_checkpoint_is_refused_and_the_repair_restores_it_exactly(tmp_path):
    exp = tiny("materials-t1", rules=CompositionRules.seed())
    EvolutionRun(exp, tmp_path / "ref", seed=3, generations=1, figures=False).run()
    shutil.copytree(tmp_path / "ref", tmp_path / "bad")
    _damage(tmp_path / "bad")

    with pytest.raises(CheckpointError, match="repair_cache_columns"):
        EvolutionRun(exp, tmp_path / "bad", seed=3, generations=2, figures=False).run(resume=True)

    assert repair.main([str(tmp_path / "bad")]) == 0
    for good, fixed in zip(list_checkpoints(tmp_path / "ref" / "checkpoints"),
                           list_checkpoints(tmp_path / "bad" / "checkpoints")):  # fmt: skip
        (s_ref, a_ref), (s_fix, a_fix) = load_checkpoint(good), load_checkpoint(fixed)
        assert s_fix["population"] == s_ref["population"]
        assert s_fix["rows"][-1] == s_ref["rows"][-1]
        for k in ("cache_keys", "cache_metrics", "cache_values"):
            np.testing.assert_array_equal(a_fix[k], a_ref[k])
    assert (tmp_path / "bad" / "log.csv").read_text() == (tmp_path / "ref" / "log.csv").read_text()

    ref = EvolutionRun(exp, tmp_path / "ref", seed=3, generations=2, figures=False)
    fixed = EvolutionRun(exp, tmp_path / "bad", seed=3, generations=2, figures=False)
    assert population_summary(fixed.run(resume=True)) == population_summary(ref.run(resume=True))


def test_the_repair_leaves_a_note_that_says_what_it_cannot_undo(tmp_path):
    exp = tiny("materials-t1", rules=CompositionRules.seed())
    EvolutionRun(exp, tmp_path / "run", seed=3, generations=1, figures=False).run()
    _damage(tmp_path / "run")
    assert repair.main([str(tmp_path / "run"), "--resumed-at", "1"]) == 0
    [note] = read_run_notes(tmp_path / "run")
    assert note["resumed_at"] == 1 and note["repaired"]["individuals"] > 0
    assert "n_old_materials" in note["text"] and "cannot be undone" in note["text"]
    rows = [json.loads(x) for x in (tmp_path / "run" / "log.jsonl").read_text().splitlines()]
    assert math.isnan(rows[1]["n_voxels_median"]) and not math.isnan(rows[0]["n_voxels_median"])
