"""POET co-evolution (evolvers.drivers.poet) with a fake evaluation: criterion, PATA-EC, ANNECS, resume.

The fake (poet_helpers.fake_batch_fn) scores a robot from its muscle share and controller
and a terrain from its obstacles: the search logic is the point, not the physics. One
small run simulates, with figures.
"""

import json
import os
import signal
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest
from evolver_helpers import tiny
from poet_helpers import fake_batch_fn

from evolvers.drivers.poet import (
    PoetConfig,
    PoetRun,
    centered_ranks,
    novelty,
    pata_ec,
    poet_experiment,
    poet_thresholds,
)
from evolvers.recording.recorder import RunInterrupted
from softgym.exceptions import CheckpointError, InvalidParameterError
from softgym.io import list_checkpoints

HELPERS = Path(__file__).resolve().parents[1]  # tests/evolvers: poet_helpers
EXP = {"pop_size": 4, "seconds": 1.5}
CFG = {"reproduce_every": 2, "transfer_every": 2, "max_active": 3, "mutation_sigma": 0.4}


def _run(path, seed=0, iterations=12, config=None, **kw):
    cfg = PoetConfig(**CFG) if config is None else config
    return PoetRun(poet_experiment(**EXP), path, seed=seed, iterations=iterations, config=cfg,
                   batch_fn=fake_batch_fn, figures=False, progress=False, **kw)  # fmt: skip


def _rows(rows):
    # comparable as JSON text (NaN == NaN there); wall-clock columns differ between any two runs
    return [json.dumps({k: v for k, v in r.items() if "wall" not in k}) for r in rows]


# ---------------------------------------------------------------------- units
def test_thresholds_map_poet_rewards_and_config_checks():
    t = poet_thresholds(trapped=3.0, solved=10.0)
    assert t["solved_threshold"] == pytest.approx(10.0)
    assert t["mc_low"] == pytest.approx(3 + 7 * 25 / 230)
    assert t["mc_high"] == pytest.approx(3 + 7 * 340 / 230)
    assert t["mc_low"] < t["repro_threshold"] < t["solved_threshold"] < t["mc_high"]
    assert PoetConfig.from_dict(json.loads(json.dumps(PoetConfig().to_dict()))) == PoetConfig()
    for bad in ({"mc_low": 5.0, "mc_high": 4.0}, {"generator": "x"}, {"max_children": 0},
                {"reproduce_every": -1}, {"start_terrain": {"fence_height": 9}}):  # fmt: skip
        with pytest.raises(InvalidParameterError if "start_terrain" not in bad else ValueError):
            PoetConfig(**bad)


def test_centered_ranks_ties_and_range():
    r = centered_ranks([3.0, 1.0, 3.0, 2.0])
    np.testing.assert_allclose(r, [0.5 - 1 / 6, -0.5, 0.5 - 1 / 6, -0.5 + 1 / 3])
    assert centered_ranks([7.0]).tolist() == [0.0]


def test_pata_ec_is_unchanged_by_monotone_score_transforms():
    rng = np.random.default_rng(0)
    low, high = 3.0, 13.0
    scores = rng.uniform(0, 20, size=(6, 9))  # 6 terrains x 9 robots
    scores[:, 2] = scores[:, 5]  # ties
    for f in (lambda x: 2 * x + 1, np.exp, lambda x: x**3, np.sqrt, lambda x: np.log1p(x) * 10):
        for row in scores:
            np.testing.assert_array_equal(pata_ec(row, low, high), pata_ec(f(row), f(low), f(high)))
        vecs = np.array([pata_ec(r, low, high) for r in scores])
        tvecs = np.array([pata_ec(f(r), f(low), f(high)) for r in scores])
        assert novelty(vecs[0], vecs[1:], 5) == novelty(tvecs[0], tvecs[1:], 5)
    assert novelty(np.zeros(3), np.zeros((0, 3))) == float("inf")
    v = pata_ec(scores[0], low, high)
    assert v.min() >= -0.5 and v.max() <= 0.5


# ---------------------------------------------------------------------- the loop
def test_criterion_rejects_trivial_and_impossible_terrains(tmp_path):
    run = _run(tmp_path / "r", iterations=16)
    run.run()
    cfg = run.config
    reasons = [x for r in run.rows for x in r["rejected"]]
    trivial = [x for x in reasons if x["reason"].startswith("trivial: parent")]
    impossible = [x for x in reasons if x["reason"].startswith("impossible: parent")]
    assert trivial and impossible
    assert all(x["parent_score"] > cfg.mc_high for x in trivial)
    assert all(x["parent_score"] < cfg.mc_low for x in impossible)
    admitted = [x for r in run.rows[1:] for x in r["admitted"]]
    assert admitted and all(cfg.mc_low <= x["parent_score"] <= cfg.mc_high for x in admitted)
    assert all(cfg.mc_low <= x["best_active_score"] <= cfg.mc_high for x in admitted)
    assert all(len(r["admitted"]) <= cfg.max_admitted for r in run.rows[1:])
    assert max(r["n_active"] for r in run.rows) == cfg.max_active  # the oldest retire
    assert run.archived() and all(len(p.population) == 1 for p in run.archived())


def test_annecs_never_decreases_and_counts_novel_solved_terrains(tmp_path):
    run = _run(tmp_path / "r", iterations=16)
    pairs = run.run()
    a = [r["annecs"] for r in run.rows]
    assert all(y >= x for x, y in zip(a, a[1:])) and a[-1] > 0
    assert a[-1] == sum(p.novel and p.solved is not None for p in pairs)
    assert a[-1] <= sum(len(r["admitted"]) for r in run.rows[1:])
    b = [r["annecs_archive"] for r in run.rows]
    assert all(y >= x for x, y in zip(b, b[1:]))
    transfers = [t for r in run.rows for t in r["transfers"]]
    assert all(t["score"] > t["previous"] and t["from"] != t["to"] for t in transfers)
    m = next(r["score_matrix"] for r in run.rows if r["score_matrix"])
    assert np.array(m["scores"]).shape == (len(m["robots"]), len(m["terrains"]))


def test_random_terrain_control_runs_the_same_loop(tmp_path):
    run = _run(tmp_path / "c", iterations=8, config=PoetConfig(**{**CFG, "generator": "random"}))
    run.run()
    assert [r["generation"] for r in run.rows] == list(range(9))
    assert any(r["rejected"] or len(r["admitted"]) for r in run.rows[1:])


def test_reproducible_under_a_seed_and_resumes_exactly_after_ctrl_c(tmp_path):
    ref = _run(tmp_path / "ref", seed=3, iterations=8)
    ref.run()
    same = _run(tmp_path / "same", seed=3, iterations=8)
    same.run()
    assert _rows(same.rows) == _rows(ref.rows)
    other = _run(tmp_path / "other", seed=4, iterations=8)
    other.run()
    assert _rows(other.rows) != _rows(ref.rows)

    def crash(run, row):
        if row["generation"] == 5:
            raise KeyboardInterrupt

    cut = _run(tmp_path / "cut", seed=3, iterations=8, on_iteration=crash)
    with pytest.raises(RunInterrupted) as info:
        cut.run()
    assert info.value.generation == 5
    again = _run(tmp_path / "cut", seed=3, iterations=8)
    again.run(resume=True)
    assert _rows(again.rows) == _rows(ref.rows)
    assert [p.to_dict() for p in again.pairs] == [p.to_dict() for p in ref.pairs]
    with pytest.raises(CheckpointError, match="poet.max_active"):
        _run(tmp_path / "cut", seed=3, config=PoetConfig(**{**CFG, "max_active": 5})).run(
            resume=True
        )


def test_kill9_then_corrupt_latest_resumes_identically(tmp_path):
    ref = _run(tmp_path / "ref", seed=5, iterations=6)
    ref.run()
    child = textwrap.dedent(
        f"""
        import os, signal, sys
        sys.path.insert(0, {str(HELPERS)!r})
        from poet_helpers import fake_batch_fn
        from evolvers.drivers.poet import PoetConfig, PoetRun, poet_experiment

        def kill9(run, row):
            if row["generation"] == 4:
                os.kill(os.getpid(), signal.SIGKILL)

        PoetRun(poet_experiment(**{EXP!r}), {str(tmp_path / "b")!r}, seed=5, iterations=6,
                config=PoetConfig(**{CFG!r}), batch_fn=fake_batch_fn, figures=False,
                progress=False, on_iteration=kill9).run()
        """
    )
    env = {**os.environ, "OMP_NUM_THREADS": "1"}
    proc = subprocess.run([sys.executable, "-c", child], env=env, capture_output=True, timeout=300)
    assert proc.returncode == -signal.SIGKILL, proc.stderr.decode()[-2000:]
    ckpts = list_checkpoints(tmp_path / "b" / "checkpoints")
    assert ckpts[-1].name == "ckpt-000004.json"
    text = ckpts[-1].read_text()
    ckpts[-1].write_text(text[: len(text) // 2])  # the newest checkpoint is corrupt
    resumed = _run(tmp_path / "b", seed=5, iterations=6)
    resumed.run(resume=True)
    assert _rows(resumed.rows) == _rows(ref.rows)
    assert [p.to_dict() for p in resumed.pairs] == [p.to_dict() for p in ref.pairs]
    logged = [json.loads(x) for x in (tmp_path / "b" / "log.jsonl").read_text().splitlines()]
    assert _rows(logged) == _rows(ref.rows)


def test_poet_evaluates_through_the_drivers_evaluator_keyed_by_terrain(tmp_path):
    from evolvers.drivers.runner import EvolutionRun
    from evolvers.evaluation.evaluator import Evaluator, PhenotypeCache

    run = _run(tmp_path / "r", iterations=4)
    ordinary = EvolutionRun(tiny(), tmp_path / "o", figures=False, progress=False)
    assert type(run.evaluator) is type(ordinary.evaluator) is Evaluator
    run.run()
    assert run.n_simulated == run.evaluator.n_evaluations == run.evaluations_total > 0
    pair = run.pairs[0]
    best = pair.best
    key = PhenotypeCache.key(best.phenotype_key(run.experiment.shape), pair.terrain.key())
    assert run.evaluator.cache.get(key)[0]["max_xy_dist"] == best.objectives["max_xy_dist"]
    n = run.n_simulated
    (score,), st = run.evaluate([(pair.terrain, [best])])  # the same terrain: cached
    assert st.n_simulated == 0 and st.n_cached == 1 and score[0] == pair.best_score
    other = next(t for t in (pair.terrain.mutate(run.rng, 0.4) for _ in range(20))
                 if t.key() not in {p.terrain.key() for p in run.pairs})  # fmt: skip
    _, st = run.evaluate([(other, [best, best])])  # a new terrain: simulated once
    assert st.n_simulated == 1 and st.n_cached == 1 and run.n_simulated == n + 1


# ---------------------------------------------------------------------- physics, figures
def test_simulated_run_writes_pairs_and_figures(tmp_path):
    exp = tiny("obstacles-attempt2", seconds=1.0, pop_size=3)
    cfg = PoetConfig(reproduce_every=1, transfer_every=1, mc_low=0.0, mc_high=50.0,
                     repro_threshold=0.0, solved_threshold=0.0)  # fmt: skip
    run = PoetRun(exp, tmp_path / "r", seed=0, iterations=1, config=cfg, progress=False)
    pairs = run.run()
    assert len(pairs) >= 1 and pairs[0].solved == 0
    for name in ("annecs.png", "transfers.png", "gallery.png"):
        assert (tmp_path / "r" / "figures" / name).is_file()
    data = json.loads((tmp_path / "r" / "pairs.json").read_text())
    assert data["pairs"][0]["describe"] == "flat" and data["pairs"][0]["design"]["schema"]


def test_pairs_on_dask_equal_local(tmp_path):
    pytest.importorskip("distributed")
    from evolvers.evaluation.distributed import DaskBatchFn, dask_client

    exp = tiny("obstacles-attempt2", seconds=1.0, pop_size=3)
    cfg = PoetConfig(reproduce_every=1, transfer_every=1, mc_low=0.0, mc_high=50.0,
                     repro_threshold=0.0, solved_threshold=5.0)  # fmt: skip
    common = {"seed": 2, "iterations": 2, "config": cfg, "figures": False, "progress": False}
    local = PoetRun(exp, tmp_path / "local", **common)
    local.run()
    with dask_client("local", n_workers=2, processes=False) as client:
        remote = PoetRun(exp, tmp_path / "dask", batch_fn=DaskBatchFn(client), **common)
        remote.run()
    assert len(local.pairs) > 1  # a terrain was admitted: several terrains were evaluated at once
    assert _rows(remote.rows) == _rows(local.rows)


def test_score_cap_saturates_scores_so_nothing_is_trivial(tmp_path):
    with pytest.raises(InvalidParameterError, match="score_cap"):
        PoetConfig(score_cap=1.0)
    run = _run(tmp_path / "r", iterations=8, config=PoetConfig(**CFG, score_cap=12.0))
    run.run()
    assert all(t["score"] <= 12.0 for r in run.rows for t in r["terrains"])
    reasons = [x["reason"] for r in run.rows for x in r["rejected"]]
    assert not any(x.startswith("trivial") for x in reasons)
