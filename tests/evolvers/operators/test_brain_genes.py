"""Brains as genes: Individual round trips and keys, brain variation, Experiment controller fields."""

import json

import numpy as np
import pytest
from brain_helpers import brainy, small_body
from evolver_helpers import tiny

from evolvers.evaluation.experiments import Experiment, get_experiment
from evolvers.operators.genome import Individual
from evolvers.operators.variation import cx_arithmetic, make_children, mut_brain
from evolvers.recording.rows import population_summary
from softgym.design.brain import WEIGHT_BOUND
from softgym.exceptions import InvalidParameterError


def _ids():
    n = iter(range(100, 10_000))
    return lambda: next(n)


def test_individual_with_brain_round_trips_and_hashes_its_weights():
    exp = brainy("central")
    ind = exp.random_individual(np.random.default_rng(0), 7)
    spec = exp.brain_spec()
    assert ind.brain.shape == (spec.n_params,) and ind.brain_spec == spec
    design = ind.design(exp.shape)
    assert design.brain is not None and np.array_equal(design.brain.weights, ind.brain)
    back = Individual.from_dict(json.loads(json.dumps(ind.to_dict())))
    assert back.to_dict() == ind.to_dict() and np.array_equal(back.brain, ind.brain)
    assert back.phenotype_key(exp.shape) == ind.phenotype_key(exp.shape)
    other = ind.child(8)
    assert np.array_equal(other.brain, ind.brain) and other.brain is not ind.brain
    other.brain[0] = -other.brain[0] + 0.5
    assert other.phenotype_key(exp.shape) != ind.phenotype_key(exp.shape)
    # a sinusoid individual's dict is unchanged; an old dict (no brain key) loads with None
    plain = tiny().random_individual(np.random.default_rng(0), 1)
    d = plain.to_dict()
    assert "brain" not in d and "body" not in d
    assert Individual.from_dict(d).brain is None


def test_fixed_body_individuals_share_the_body():
    exp = brainy(body=True)
    rng = np.random.default_rng(1)
    ind = exp.random_individual(rng, 0)
    body = small_body()
    assert ind.cppn is None and np.array_equal(ind.grid(exp.shape), body.grid)
    assert ind.palette() == body.palette and ind.controller == body.controller
    back = Individual.from_dict(json.loads(json.dumps(ind.to_dict())))
    assert back.phenotype_key(exp.shape) == ind.phenotype_key(exp.shape)
    kids = make_children([ind, exp.random_individual(rng, 1)], rng, _ids(), **exp.variation())
    for kid in kids:
        assert np.array_equal(kid.grid(exp.shape), body.grid) and kid.cppn is None
        assert kid.brain is not None


def test_sinusoid_variation_is_unchanged():
    exp = tiny("controller-pareto")
    rng = np.random.default_rng(3)
    parents = [exp.random_individual(rng, i) for i in range(4)]
    old = make_children(
        parents, np.random.default_rng(9), _ids(), shape=exp.shape, rules=exp.rules,
        evolve_controller=True, evolve_materials=False, crossover_rate=exp.crossover_rate,
    )  # fmt: skip
    new = make_children(parents, np.random.default_rng(9), _ids(), **exp.variation())
    assert population_summary(old) == population_summary(new)
    a = Individual.random(np.random.default_rng(2), 0, exp.shape, exp.cppn_outputs, exp.rules)
    b = exp.random_individual(np.random.default_rng(2), 0)
    assert a.to_dict() == b.to_dict()


def test_brain_mutation_and_crossover_stay_in_bounds():
    exp = brainy()
    rng = np.random.default_rng(4)
    ind = exp.random_individual(rng, 0)
    ind.brain[:] = WEIGHT_BOUND
    before = ind.brain.copy()
    mut_brain(ind, rng, sigma=1.0)
    assert not np.array_equal(ind.brain, before) and np.abs(ind.brain).max() <= WEIGHT_BOUND
    p = [exp.random_individual(rng, i) for i in range(2)]
    kids = [p[0].child(5)]
    cx_arithmetic(kids, p, rng, rate=1.0, controller=False, brain=True)
    np.testing.assert_array_equal(kids[0].brain, (p[0].brain + p[1].brain) / 2.0)


def test_experiment_controller_fields_are_checked_and_round_trip():
    exp = brainy("distributed", body=True, hidden=4, signals=2, control_dt=0.1)
    back = Experiment.from_dict(json.loads(json.dumps(exp.to_dict())))
    assert back == exp and back.brain_spec() == exp.brain_spec()
    assert exp.brain_spec().hidden == 4 and exp.brain_spec().signals == 2
    assert tiny().brain_spec() is None and brainy("central").brain_spec().signals == 0
    old = tiny().to_dict()
    for k in ("controller", "hidden", "signals", "control_dt", "body"):
        del old[k]
    assert Experiment.from_dict(old).controller == "sinusoid"
    for bad, word in (
        ({"controller": "lstm"}, "controller"), ({"hidden": -1}, "hidden"),
        ({"signals": 99}, "signals"), ({"control_dt": 0.0}, "control_dt"),
        ({"body": {"grid": 1}}, "body"), ({"body": small_body().to_dict(), "shape": (6, 6, 6)}, "body"),
    ):  # fmt: skip
        with pytest.raises(InvalidParameterError, match=word):
            tiny(**{"controller": "central", **bad})
    with pytest.raises(InvalidParameterError, match="materials"):
        get_experiment("materials", shape=(4, 4, 4), body=small_body().to_dict())
    with pytest.raises(InvalidParameterError, match="nothing"):
        tiny("basic", body=small_body().to_dict())
