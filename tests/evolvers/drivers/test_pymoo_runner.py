import json

import numpy as np
import pytest
from evolver_helpers import tiny
from fuzzing import refused_in_child  # tests/fuzzing.py
from pymoo.algorithms.moo.nsga2 import NSGA2
from pymoo.core.problem import Problem

from evolvers.drivers.pymoo_runner import PymooRun, SoftbotProblem, constraint_values
from evolvers.drivers.runner import population_summary
from evolvers.evaluation.evaluator import Evaluator
from evolvers.operators.genome import Individual
from softgym.design import CompositionRules
from softgym.exceptions import CheckpointError


def test_problem_fills_minimised_F_and_feasible_G():
    exp = tiny("obstacles", rules=CompositionRules.obstacles())
    problem = SoftbotProblem(exp, Evaluator(exp))
    assert isinstance(problem, Problem) and problem.n_obj == 3 and problem.n_ieq_constr == 5
    rng = np.random.default_rng(0)
    X = np.array(
        [[Individual.random(rng, i, exp.shape, rules=exp.rules)] for i in range(2)], dtype=object
    )
    out = problem.evaluate(X, return_as_dictionary=True)
    assert out["F"].shape == (2, 3) and out["G"].shape == (2, 5)
    assert (out["G"] <= 0).all()  # valid robots are feasible
    np.testing.assert_array_equal(out["F"][:, 0], [-x[0].objectives["max_xy_dist"] for x in X])
    grid = np.zeros(exp.shape, dtype=np.int8)
    grid[0, 0, 0] = 3
    assert (constraint_values(grid, exp.rules) > 0).any()


def test_pymoo_nsga2_runs_and_resumes_exactly(tmp_path):
    exp = tiny("controller-pareto")
    ref_run = PymooRun(exp, tmp_path / "a", seed=3, generations=2, figures=False)
    ref = ref_run.run()
    assert [r["generation"] for r in ref_run.rows] == [0, 1, 2]

    class Crash(Exception):
        pass

    def crash(run, row):
        if row["generation"] == 1:
            raise Crash

    try:
        PymooRun(
            exp, tmp_path / "b", seed=3, generations=2, figures=False, on_generation=crash
        ).run()
    except Crash:
        pass
    resumed = PymooRun(exp, tmp_path / "b", seed=3, generations=2, figures=False).run(resume=True)
    assert population_summary(resumed) == population_summary(ref)


@pytest.mark.parametrize("algorithm", ["nsga3", "sms-emoa", "ga", NSGA2])
def test_any_pymoo_algorithm_through_ask_and_tell(tmp_path, algorithm):
    exp = tiny("controller-pareto")
    run = PymooRun(exp, tmp_path / "r", seed=1, generations=1, figures=False, algorithm=algorithm)
    pop = run.run()
    assert len(pop) == exp.pop_size and [r["generation"] for r in run.rows] == [0, 1]
    assert run.algorithm.problem.n_obj == (1 if algorithm == "ga" else 2)
    cfg = json.loads((tmp_path / "r" / "config.json").read_text())
    assert cfg["algorithm"] == (algorithm if isinstance(algorithm, str) else "NSGA2")


def test_ga_resumes_exactly_and_resume_refuses_another_algorithm(tmp_path):
    exp = tiny("controller-tournament")
    ref = PymooRun(exp, tmp_path / "a", seed=2, generations=2, figures=False, algorithm="ga").run()

    def crash(run, row):
        if row["generation"] == 1:
            raise RuntimeError("crash")

    with pytest.raises(RuntimeError):
        PymooRun(
            exp, tmp_path / "b", seed=2, generations=2, figures=False, algorithm="ga",
            on_generation=crash,
        ).run()  # fmt: skip
    resumed = PymooRun(exp, tmp_path / "b", seed=2, generations=2, figures=False, algorithm="ga")
    assert population_summary(resumed.run(resume=True)) == population_summary(ref)
    assert resumed.rows[-1]["evaluations"] > 0 and resumed.evaluations_total > 0
    with pytest.raises(CheckpointError, match="algorithm"):
        PymooRun(exp, tmp_path / "b", seed=2, generations=3, figures=False).run(resume=True)


@pytest.mark.parametrize("algorithm", ["nsga3", "sms-emoa"])
@pytest.mark.parametrize("experiment", ["controller-tournament", "novelty"])
def test_a_multi_objective_algorithm_on_one_objective_is_refused_not_hung(
    tmp_path, algorithm, experiment
):
    # issue 61: NSGA-III's reference-direction loop never ended on one objective (the
    # default experiment); SMS-EMOA's hypervolume raised a ValueError at generation 1
    out = tmp_path / "r"
    code = (
        "from evolvers.drivers.pymoo_runner import PymooRun\n"
        "from evolvers.evaluation.experiments import get_experiment\n"
        "from softgym.exceptions import InvalidParameterError\n"
        "try:\n"
        f"    PymooRun(get_experiment({experiment!r}, pop_size=4), {str(out)!r}, "
        f"algorithm={algorithm!r})\n"
        "except InvalidParameterError as e:\n"
        "    print('REFUSED', e)\n"
    )
    stdout = refused_in_child(code, timeout=60)
    assert f"'{algorithm}' needs at least 2 objectives" in stdout and "nsga2" in stdout
    assert not out.exists()


def test_cmaes_searches_the_design_vector_of_a_cppn_body_and_resumes_exactly(tmp_path):
    from evolvers.drivers.pymoo_runner import DesignProblem, design_encoding

    exp = tiny("codesign")
    kw = {"seed": 2, "figures": False, "gif": False, "progress": False, "algorithm": "cmaes"}
    ref_run = PymooRun(exp, tmp_path / "ref", generations=3, **kw)
    ref = ref_run.run()
    assert isinstance(ref_run.problem, DesignProblem)
    enc = design_encoding(exp)
    assert ref_run.problem.n_var == enc.size == 86  # 83 CPPN weights, 3 controller genes
    assert all(len(ind.cppn.hidden) == 7 and len(ind.cppn.edges) == 83 for ind in ref)
    assert len({ind.controller for ind in ref}) > 1  # the controller genes are searched too
    best = [r["best_so_far"] for r in ref_run.rows]
    assert best == sorted(best) and ref_run.rows[-1]["evaluations_total"] > 4
    # a run extended by resume replays its generations from the cache, then goes on
    PymooRun(exp, tmp_path / "ext", generations=1, **kw).run()
    ext = PymooRun(exp, tmp_path / "ext", generations=3, **kw).run(resume=True)
    assert population_summary(ext) == population_summary(ref)
