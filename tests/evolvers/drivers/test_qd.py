"""MAP-Elites on pyribs (evolvers.drivers.qd): descriptors, emitter, archive stats, resume, export.

Most runs use a fake batch evaluation (a distance computed from the grid): the
archive logic is the point, not the physics. One run simulates, with figures.
"""

import json
import os

import numpy as np
import pytest
from evolver_helpers import tiny

pytest.importorskip("ribs")

from evolvers.drivers.qd import (  # noqa: E402
    QDConfig,
    QDRun,
    SoftbotEmitter,
    export_elites,
    make_archive,
)
from evolvers.evaluation.descriptors import DESCRIPTORS, descriptor_values  # noqa: E402
from evolvers.operators.genome import Individual  # noqa: E402
from evolvers.recording.recorder import RunInterrupted  # noqa: E402
from softgym.design import RobotDesign  # noqa: E402
from softgym.exceptions import CheckpointError, InvalidParameterError  # noqa: E402
from softgym.metrics import composition_counts  # noqa: E402

_WALL = {"wall_time", "wall_total", "wall_clock_total"}


def fake_batch_fn(designs, task):
    """A deterministic 'distance' from the grid; one diverged robot in seven."""
    n = len(designs)
    out = {k: np.zeros(n) for k in ("norm_final_dist", "max_xy_dist", "l_coefficient")}
    out["diverged"] = np.zeros(n, dtype=bool)
    counts = ("n_voxels", "n_muscle", "n_old_materials", "n_bone", "n_tissue")
    out.update({k: np.zeros(n, dtype=np.int64) for k in counts})
    out["traces"] = []
    for i, d in enumerate(designs):
        assert isinstance(d, RobotDesign)  # designs stay objects within one process
        design = d
        g = design.grid
        h = int(np.ravel_multi_index(np.nonzero(g), g.shape)[:5].sum()) if g.any() else 0
        dist = float(np.isin(g, (3, 4)).mean() + 0.01 * (h % 13))
        diverged = h % 7 == 0
        out["norm_final_dist"][i] = -1e7 if diverged else dist
        out["max_xy_dist"][i] = -1e7 if diverged else dist
        out["diverged"][i] = diverged
        c = composition_counts(design)
        for k in counts:
            out[k][i] = getattr(c, k)
        t = np.linspace(0, 1, 5)
        out["traces"].append(None if diverged else np.c_[t * dist, t, t, t] * 0.01)
    return out


def _run(path, seed=0, generations=3, config=None, **kw):
    exp = tiny("basic", pop_size=6)
    cfg = QDConfig(cells=(8,)) if config is None else config
    return QDRun(exp, path, seed=seed, generations=generations, config=cfg,
                 batch_fn=fake_batch_fn, figures=False, progress=False, **kw)  # fmt: skip


def _rows(run):
    return [{k: v for k, v in r.items() if k not in _WALL} for r in run.rows]


def _archive(run):
    d = run.archive.data()
    order = np.argsort(d["index"])
    return [d["index"][order], d["objective"][order], d["measures"][order]]


# ---------------------------------------------------------------------- descriptors
def test_descriptors_closed_form():
    g = np.zeros((4, 4, 4), dtype=np.int8)
    g[:, 0, 0] = [2, 2, 3, 1]  # a rod along x: 2 stiff, 1 muscle, 4 filled, 1 layer
    v = descriptor_values([g], ["stiff", "filled", "muscle", "height", "elongation"])[0]
    np.testing.assert_allclose(v, [0.5, 4 / 64, 0.25, 0.25, 1.0], atol=1e-12)
    cube = np.ones((2, 2, 2), dtype=np.int8)
    assert descriptor_values([cube], ["elongation", "height"])[0] == pytest.approx([0.0, 1.0])
    empty = np.zeros((3, 3, 3), dtype=np.int8)
    assert (descriptor_values([empty], list(DESCRIPTORS)) == 0).all()


def test_descriptors_stay_in_range():
    rng = np.random.default_rng(0)
    grids = [rng.choice([0, 1, 2, 3, 4, 7, 8], size=(3, 4, 5)).astype(np.int8) for _ in range(50)]
    v = descriptor_values(grids, list(DESCRIPTORS))
    assert v.shape == (50, len(DESCRIPTORS)) and (v >= 0).all() and (v <= 1).all()


def test_config_checks_and_round_trip():
    assert QDConfig().cells == (128, 128)
    c = QDConfig(descriptors=("muscle", "height", "elongation"), cells=(4, 5, 6))
    assert QDConfig.from_dict(json.loads(json.dumps(c.to_dict()))) == c
    for bad in ({"descriptors": ("nope",)}, {"cells": (3, 4, 5)}, {"archive": "x"},
                {"archive": "cvt", "cells": (4, 4)}, {"objective": "n_voxels"}):  # fmt: skip
        with pytest.raises(InvalidParameterError):
            QDConfig(**bad)


# ---------------------------------------------------------------------- emitter, stats
def test_emitter_asks_random_then_mutated_children_of_elites():
    exp = tiny("basic")
    archive = make_archive(QDConfig(cells=(8,)), seed=0)
    em = SoftbotEmitter(archive, exp, batch_size=5, rng=1)
    first = em.ask()
    assert first.dtype == object and first.shape == (5,)
    assert all(isinstance(x, Individual) and not exp.rules.violations(x.grid(exp.shape))
               for x in first)  # fmt: skip
    archive.add(first, np.arange(5.0), descriptor_values([x.grid(exp.shape) for x in first],
                                                         ("stiff", "filled")))  # fmt: skip
    elite_ids = {x.id for x in archive.data("solution")}
    children = em.ask()
    assert {c.parent_id for c in children} <= elite_ids
    assert all(c.id >= 5 and not c.objectives for c in children)


def test_stats_match_ribs_and_qd_score_never_decreases(tmp_path):
    run = _run(tmp_path / "r", generations=5)
    run.run()
    st = run.stats()
    ribs_st = run.archive.stats
    assert st["num_elites"] == ribs_st.num_elites
    assert st["qd_score"] == pytest.approx(float(ribs_st.qd_score), rel=1e-12)
    assert st["coverage"] == pytest.approx(float(ribs_st.coverage))
    assert st["qd_best"] == pytest.approx(float(ribs_st.obj_max))
    qd = [r["qd_score"] for r in run.rows]
    cov = [r["coverage"] for r in run.rows]
    assert all(b >= a for a, b in zip(qd, qd[1:])) and all(b >= a for a, b in zip(cov, cov[1:]))
    assert (run.archive.data("objective") >= 0).all()  # diverged robots score 0
    m = run.archive.data("measures")
    assert (m >= 0).all() and (m <= 1).all()
    assert run.rows[-1]["evaluations_total"] == run.evaluations_total > 0


# ---------------------------------------------------------------------- resume, seeds
@pytest.mark.parametrize("archive", ["grid", "cvt"])
def test_interrupted_run_resumes_exactly(tmp_path, archive):
    cfg = QDConfig(cells=(8,)) if archive == "grid" else QDConfig(archive="cvt", cells=(20,),
                                                                    cvt_samples=500)  # fmt: skip
    ref = _run(tmp_path / "ref", seed=4, generations=3, config=cfg)
    ref.run()

    def crash(run, row):
        if row["generation"] == 1:
            raise KeyboardInterrupt

    cut = _run(tmp_path / "cut", seed=4, generations=3, config=cfg, on_generation=crash)
    with pytest.raises(RunInterrupted):
        cut.run()
    again = _run(tmp_path / "cut", seed=4, generations=3, config=cfg)
    again.run(resume=True)
    assert _rows(again) == _rows(ref)
    for a, b in zip(_archive(again), _archive(ref)):
        np.testing.assert_array_equal(a, b)
    assert [e.to_dict() for e in again.elites()] == [e.to_dict() for e in ref.elites()]
    other = _run(tmp_path / "seed5", seed=5, generations=3, config=cfg)
    other.run()
    assert _rows(other) != _rows(ref)


def test_resume_refuses_another_archive(tmp_path):
    _run(tmp_path / "r", generations=0).run()
    with pytest.raises(CheckpointError, match="qd.cells"):
        _run(tmp_path / "r", generations=1, config=QDConfig(cells=(9,))).run(resume=True)


# ---------------------------------------------------------------------- physics, figures, export
def test_simulated_run_writes_figures_and_exports_elites(tmp_path):
    exp = tiny("basic", pop_size=4, seconds=1.0)
    run = QDRun(exp, tmp_path / "r", seed=0, generations=1, config=QDConfig(cells=(16,)),
                gif=False, progress=False)  # fmt: skip
    elites = run.run()
    assert elites and (tmp_path / "r" / "figures" / "archive_heatmap.png").is_file()
    assert (tmp_path / "r" / "figures" / "qd_progress.png").is_file()
    assert (tmp_path / "r" / "best_design.vxa").is_file()
    index = export_elites(tmp_path / "r", top=2)
    data = json.loads(index.read_text())
    assert len(data["elites"]) == min(2, len(elites))
    best = data["elites"][0]
    assert best["objective"] == pytest.approx(run.stats()["qd_best"])
    for f in best["files"]:
        assert (index.parent / f).is_file()
    RobotDesign.load(index.parent / best["files"][0])
    with pytest.raises(CheckpointError):
        export_elites(tmp_path / "nope")


def test_numba_caches_in_the_users_cache_folder_not_site_packages(tmp_path):
    # issue 61, item 9: `softgym qd` wrote numba's cache (pyribs -> numba) into site-packages
    import subprocess
    import sys

    code = ("import importlib, os\n"
            "import evolvers.drivers.qd as qd, numba.core.config as c\n"
            "print(os.environ['NUMBA_CACHE_DIR'], c.CACHE_DIR)\n"  # the user's own, kept
            "del os.environ['NUMBA_CACHE_DIR']\n"
            "importlib.reload(qd)\n"  # numba imported already: its config follows too
            "print(os.environ['NUMBA_CACHE_DIR'], c.CACHE_DIR)\n")  # fmt: skip
    env = {**os.environ, "XDG_CACHE_HOME": str(tmp_path / "cache"),
           "NUMBA_CACHE_DIR": str(tmp_path / "mine")}  # fmt: skip
    res = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                         timeout=120)  # fmt: skip
    mine, default = str(tmp_path / "mine"), str(tmp_path / "cache" / "softgym" / "numba")
    assert res.stdout.split() == [mine, mine, default, default], res.stderr[-2000:]


# ---------------------------------------------------------------------- a task's score
def _scoring_batch_fn(designs, task):
    """fake_batch_fn with a task score that is negative for most robots."""
    out = fake_batch_fn(designs, task)
    d = out["norm_final_dist"]
    out["score"] = np.where(d < -1e6, -1e7, d - 0.5)
    return out


def test_a_task_score_is_floored_not_clipped_at_zero(tmp_path):
    from evolvers.drivers.qd import OBJECTIVE_FLOORS

    exp = tiny("codesign", pop_size=6)
    run = QDRun(exp, tmp_path / "s", seed=1, generations=4, config=QDConfig(cells=(8,)),
                batch_fn=_scoring_batch_fn, figures=False, progress=False)  # fmt: skip
    run.run()
    assert run.objective == "score" and run.archive.qd_score_offset == OBJECTIVE_FLOORS["score"]
    obj = run.archive.data("objective")
    assert (obj < 0).any() and (obj >= OBJECTIVE_FLOORS["score"]).all()
    scores = [max(float(e.objectives["score"]), -1000.0) for e in run.elites()]
    assert sorted(obj.tolist()) == sorted(scores)
    assert run.stats()["qd_score"] == pytest.approx(float(np.sum(obj + 1000.0)), rel=1e-12)
    best = max(h["individual"]["objectives"]["score"] for h in run.hall_of_fame)
    assert run.rows[-1]["best_so_far"] == best == run.stats()["qd_best"]
