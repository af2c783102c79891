"""Budgets (issue 62, item 2): every driver stops on each kind, counts on across resumes.

Tiny runs (4 robots of 4x4x4, 1.5 s simulated); POET on the fake terrain evaluation of
``poet_helpers`` (its search is the point here, not the physics).
"""

import json
import math

import pytest
from brain_helpers import brainy
from evolver_helpers import tiny
from poet_helpers import fake_batch_fn

from evolvers.drivers.budget import STOP_ORDER, Budget, BudgetUsage
from evolvers.drivers.deap_runner import DeapRun
from evolvers.drivers.poet import PoetConfig, PoetRun, poet_experiment
from evolvers.drivers.pymoo_runner import PymooRun
from evolvers.drivers.runner import EvolutionRun, population_summary
from evolvers.recording.recorder import RunInterrupted
from softgym.exceptions import InvalidParameterError
from softgym.io import latest_checkpoint, load_checkpoint

SECONDS = 1.5
DRIVERS = ("native", "deap", "pymoo-nsga2", "pymoo-cmaes", "qd", "poet")
COMMON = {"figures": False, "progress": False}


def _make(kind, out, generations=30, **kw):
    """A tiny run of a driver (``generations`` large: the budget stops it)."""
    kw = {**COMMON, **kw}
    if kind == "poet":
        cfg = PoetConfig(reproduce_every=2, transfer_every=2, max_active=3, mutation_sigma=0.4)
        return PoetRun(poet_experiment(pop_size=4, seconds=SECONDS), out, seed=1,
                       iterations=generations, config=cfg, batch_fn=fake_batch_fn, **kw)  # fmt: skip
    if kind == "qd":
        pytest.importorskip("ribs")
        from evolvers.drivers.qd import QDConfig, QDRun

        return QDRun(tiny("basic"), out, seed=1, generations=generations,
                     config=QDConfig(cells=(4,)), **kw)  # fmt: skip
    if kind == "pymoo-cmaes":
        return PymooRun(brainy(body=True), out, seed=1, generations=generations,
                        algorithm="cmaes", gif=False, **kw)  # fmt: skip
    if kind == "pymoo-nsga2":
        return PymooRun(tiny("controller-pareto"), out, seed=1, generations=generations, **kw)
    cls = {"native": EvolutionRun, "deap": DeapRun}[kind]
    return cls(tiny(), out, seed=1, generations=generations, **kw)


def _result(run, result):
    """What a run found, as comparable plain data (POET: its pairs)."""
    if isinstance(run, PoetRun):
        return [p.to_dict() for p in result]
    return population_summary(result)


def _rows(run):
    # wall-clock columns differ between any two runs; everything else must match
    return [json.dumps({k: v for k, v in r.items() if "wall" not in k}) for r in run.rows]


def _checkpoint_budget(run):
    state, _ = load_checkpoint(latest_checkpoint(run.checkpoint_dir))
    return state["budget"]


# ---------------------------------------------------------------------- units
def test_budget_checks_name_the_flag_and_the_range():
    for kw, flag in [
        ({"max_evals": 0}, "--max-evals must be an integer >= 1"),
        ({"max_evals": 2.5}, "--max-evals must be an integer >= 1"),
        ({"max_evals": True}, "--max-evals must be an integer >= 1"),
        ({"max_robot_seconds": -1.0}, "--max-robot-seconds must be a finite number of seconds > 0"),
        ({"max_wall_seconds": math.nan}, "--max-wall-seconds must be a finite number of seconds > 0"),
        ({"max_wall_seconds": "10"}, "--max-wall-seconds must be"),
        ({"target_score": math.inf}, "--target-score must be a finite number"),
    ]:  # fmt: skip
        with pytest.raises(InvalidParameterError, match=flag):
            Budget(**kw)
    with pytest.raises(InvalidParameterError, match="unknown budget limit"):
        Budget.from_dict({"max_evaluations": 3})
    b = Budget(max_evals=10, target_score=2)
    assert b.to_dict() == {"max_evals": 10, "target_score": 2.0} and b.limited
    assert Budget.from_dict(b.to_dict()) == b and not Budget().limited


def test_reached_names_the_first_budget_in_stop_order():
    b = Budget(max_evals=10, max_robot_seconds=15.0, max_wall_seconds=60.0, target_score=1.0)
    used = BudgetUsage(generation=3, evaluations=9, robot_seconds=13.5, wall_seconds=1.0,
                       best_score=0.5)  # fmt: skip
    assert b.reached(used, generations=5) is None
    assert b.reached(used, generations=3) == "generations"
    more = BudgetUsage(generation=3, evaluations=10, robot_seconds=15.0, wall_seconds=1.0,
                       best_score=1.0)  # fmt: skip
    assert b.reached(more, generations=3) == "target_score" == STOP_ORDER[0]
    assert Budget(max_evals=10, max_robot_seconds=15.0).reached(more, 9) == "max_evals"
    # a minimised score reaches its target from above
    low = BudgetUsage(best_score=0.5)
    assert Budget(target_score=1.0).reached(low, 9, maximize=False) == "target_score"
    assert Budget(target_score=0.1).reached(low, 9, maximize=False) is None
    assert Budget(target_score=0.1).reached(BudgetUsage(), 9) is None  # no score yet


# ---------------------------------------------------------------------- every driver
@pytest.mark.parametrize("kind", DRIVERS)
@pytest.mark.parametrize("budget", ["generations", "max_evals", "max_robot_seconds",
                                    "max_wall_seconds", "target_score"])  # fmt: skip
def test_every_driver_stops_on_each_kind_of_budget(tmp_path, kind, budget):
    if budget == "generations":
        run = _make(kind, tmp_path / "r", generations=2)
    elif budget == "target_score":
        ref = _make(kind, tmp_path / "ref", generations=3)
        ref.run()
        target = ref.best_score()
        run = _make(kind, tmp_path / "r", budget={"target_score": target})
    else:
        limit = {"max_evals": 6, "max_robot_seconds": 6 * SECONDS, "max_wall_seconds": 1e-3}[budget]
        run = _make(kind, tmp_path / "r", budget={budget: limit})
    run.run()
    assert run.stopped_by == budget
    last, before = run.rows[-1], run.rows[:-1]
    # the first generation at which the budget was reached, and not the 30 generations
    if budget == "generations":
        assert run.generation == 2
    elif budget == "max_evals":
        assert last["evaluations_total"] >= 6 and all(r["evaluations_total"] < 6 for r in before)
    elif budget == "max_robot_seconds":
        assert last["robot_seconds_total"] >= 9.0
        assert all(r["robot_seconds_total"] < 9.0 for r in before)
    elif budget == "max_wall_seconds":
        assert run.generation == 0 and last["wall_clock_total"] >= 1e-3
    else:
        assert run.best_score() >= target and run.generation <= 3
    assert run.generation < 30
    # robot-seconds: the simulated robots' seconds; the log, the checkpoint and the
    # final files say what was used and what stopped the run
    for r in run.rows:
        assert r["robot_seconds_total"] == pytest.approx(r["evaluations_total"] * SECONDS)
        assert r["robot_seconds"] == pytest.approx(r["evaluations"] * SECONDS)
    record = _checkpoint_budget(run)
    assert record["stopped_by"] == budget
    assert record["used"]["evaluations"] == run.evaluations_total == last["evaluations_total"]
    assert record["used"]["robot_seconds"] == last["robot_seconds_total"]
    assert record["used"]["generation"] == run.generation
    assert record["limits"]["generations"] == run.generations
    final = json.loads((tmp_path / "r" / "final_population.json").read_text())
    assert final["stopped_by"] == budget
    cfg = json.loads((tmp_path / "r" / "config.json").read_text())
    assert cfg.get("budget", {}) == run.budget.to_dict()


@pytest.mark.parametrize("kind", DRIVERS)
def test_resume_across_a_budget_counts_on_and_equals_a_straight_run(tmp_path, kind):
    straight = _make(kind, tmp_path / "straight", budget=Budget(max_evals=16))
    ref = straight.run()
    assert straight.stopped_by == "max_evals"

    first = _make(kind, tmp_path / "cut", budget=Budget(max_evals=8))
    first.run()
    assert first.stopped_by == "max_evals" and first.generation < straight.generation
    # the same budget again: spent, nothing more runs
    again = _make(kind, tmp_path / "cut", budget=Budget(max_evals=8))
    again.run(resume=True)
    assert again.stopped_by == "max_evals" and _rows(again) == _rows(first)
    # a larger one goes on, counting from the checkpoint, to the straight run's end
    more = _make(kind, tmp_path / "cut", budget=Budget(max_evals=16))
    res = more.run(resume=True)
    assert more.stopped_by == "max_evals"
    assert _result(more, res) == _result(straight, ref)
    assert _rows(more) == _rows(straight)
    assert more.evaluations_total == straight.evaluations_total
    assert more.recorder.robot_seconds_total == straight.recorder.robot_seconds_total
    assert [h["individual"] for h in more.hall_of_fame] == [
        h["individual"] for h in straight.hall_of_fame
    ]
    # wall seconds add up over the sittings
    assert more.recorder.wall_clock_total > first.recorder.wall_clock_total > 0
    assert json.loads((tmp_path / "cut" / "config.json").read_text())["budget"] == {"max_evals": 16}


def test_an_interrupted_budgeted_run_resumes_to_the_straight_run(tmp_path):
    straight = _make("native", tmp_path / "straight", budget={"max_robot_seconds": 20.0})
    ref = straight.run()

    def ctrl_c(run, row):
        if row["generation"] == 1:
            raise KeyboardInterrupt

    with pytest.raises(RunInterrupted):
        _make("native", tmp_path / "cut", budget={"max_robot_seconds": 20.0},
              on_generation=ctrl_c).run()  # fmt: skip
    assert _checkpoint_budget(straight)["stopped_by"] == "max_robot_seconds"
    resumed = _make("native", tmp_path / "cut", budget={"max_robot_seconds": 20.0})
    assert population_summary(resumed.run(resume=True)) == population_summary(ref)
    assert resumed.stopped_by == "max_robot_seconds" and _rows(resumed) == _rows(straight)


def test_cached_re_evaluations_are_not_counted(tmp_path):
    run = _make("native", tmp_path / "r", generations=2)
    run.run()
    # each later generation re-scores the parents from the cache: never simulated again
    assert any(r["cache_hits"] > 0 for r in run.rows[1:])
    assert run.evaluations_total == sum(r["evaluations"] for r in run.rows)
    assert run.evaluations_total == run.evaluator.n_evaluations


def test_a_bad_budget_is_refused_before_anything_is_written(tmp_path):
    with pytest.raises(InvalidParameterError, match="--max-evals"):
        _make("native", tmp_path / "r", budget={"max_evals": -1})
    with pytest.raises(InvalidParameterError, match="--target-score"):
        _make("poet", tmp_path / "p", budget={"target_score": "high"})
    assert not (tmp_path / "r").exists() and not (tmp_path / "p").exists()
