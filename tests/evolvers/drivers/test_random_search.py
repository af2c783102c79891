"""Random search (``--backend random``): fresh random genomes each generation, the best kept;
budgets, checkpoints and exact resume as every driver.
"""

import numpy as np
import pytest
from evolver_helpers import tiny

from evolvers.drivers.random_search import RandomSearchRun, keep_best, random_genome
from evolvers.drivers.runner import population_summary
from evolvers.operators.genome import Individual
from evolvers.operators.selection import Objective
from evolvers.operators.variation import MATERIAL_MUTATION
from evolvers.recording.recorder import RunInterrupted
from softgym.design import CONTROLLER_BOUNDS, Controller

COMMON = {"figures": False, "gif": False, "progress": False}


def _scored(values):
    out = []
    for i, v in enumerate(values):
        ind = Individual.random(np.random.default_rng(i), i, (4, 4, 4))
        ind.objectives = {"score": float(v)}
        out.append(ind)
    return out


def test_keep_best_ranks_by_the_fitness_then_the_older_id():
    inds = _scored([1.0, 3.0, 2.0, 3.0])
    assert [i.id for i in keep_best(inds, 3, Objective("score", True))] == [1, 3, 2]
    assert [i.id for i in keep_best(inds, 2, Objective("score", False))] == [0, 2]


def test_random_genomes_cover_the_experiments_genes():
    rng = np.random.default_rng(0)
    plain = random_genome(tiny("basic"), rng, 0)
    assert plain.controller == Controller() and plain.cppn is not None
    genomes = [random_genome(tiny("codesign"), rng, i) for i in range(20)]
    for name, (lo, hi, _) in CONTROLLER_BOUNDS.items():
        values = [getattr(g.controller, name) for g in genomes]
        assert all(lo <= v <= hi for v in values) and np.std(values) > 0.1 * (hi - lo)
    mats = random_genome(tiny("materials"), rng, 0).materials
    for row, col, _, lo, hi in MATERIAL_MUTATION:
        assert lo <= mats[row, col] <= hi
    assert mats[3, 2] == -mats[2, 2]  # material 9 the counter-phase of 8


def test_the_population_is_the_best_found_and_each_generation_is_fresh(tmp_path):
    exp = tiny("codesign")
    run = RandomSearchRun(exp, tmp_path / "r", seed=2, generations=3, **COMMON)
    pop = run.run()
    assert [r["evaluations_total"] for r in run.rows] == [4, 8, 12, 16]  # 4 fresh robots each
    assert len({ind.id for ind in pop}) == 4
    best = [r["best_so_far"] for r in run.rows]
    assert best == sorted(best)
    assert best[-1] == pop[0].objectives["score"] == max(h["individual"]["objectives"]["score"]
                                                          for h in run.hall_of_fame)  # fmt: skip
    assert [r["score_best"] for r in run.rows] == best  # the kept population holds the best
    assert run.recorder.config["backend"] == "random"


def test_interrupted_run_resumes_exactly_and_a_budget_stops_it(tmp_path):
    exp = tiny("codesign")
    ref = RandomSearchRun(exp, tmp_path / "ref", seed=5, generations=3, **COMMON)
    ref_pop = ref.run()

    def crash(run, row):
        if row["generation"] == 1:
            raise KeyboardInterrupt

    cut = RandomSearchRun(
        exp, tmp_path / "cut", seed=5, generations=3, on_generation=crash, **COMMON
    )
    with pytest.raises(RunInterrupted):
        cut.run()
    again = RandomSearchRun(exp, tmp_path / "cut", seed=5, generations=3, **COMMON)
    assert population_summary(again.run(resume=True)) == population_summary(ref_pop)
    assert [r["best_so_far"] for r in again.rows] == [r["best_so_far"] for r in ref.rows]

    capped = RandomSearchRun(exp, tmp_path / "cap", seed=5, generations=50,
                             budget={"max_evals": 10}, **COMMON)  # fmt: skip
    capped.run()
    assert capped.stopped_by == "max_evals" and capped.evaluations_total == 12
