"""Network controllers as designs: sizes, bounds, typed errors, JSON, the batched forward pass."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from softgym.design import WEIGHT_BOUND, Brain, BrainSpec, RobotDesign, default_walker
from softgym.design.brain import forward
from softgym.exceptions import InvalidDesignError


def test_sizes_of_both_kinds():
    c = BrainSpec("central", 10, 4, hidden=3)
    assert c.n_params == 3 * 11 + 4 * 4
    assert BrainSpec("central", 10, 4, hidden=0).n_params == 4 * 11
    d = BrainSpec("distributed", 20, 3, hidden=5, signals=2)
    assert d.n_params == 5 * 21 + 3 * 6
    lo, hi = d.bounds
    assert lo.shape == (d.n_params,) and np.all(lo == -WEIGHT_BOUND) and np.all(hi == WEIGHT_BOUND)


@pytest.mark.parametrize(
    "kwargs, field",
    [
        ({"kind": "cortex"}, "kind"),
        ({"hidden": -1}, "hidden"),
        ({"hidden": 2.5}, "hidden"),
        ({"signals": 1, "n_outputs": 2}, "signals"),  # a central brain sends none
        ({"control_dt": 0.0}, "control_dt"),
        ({"control_dt": float("nan")}, "control_dt"),
        ({"n_inputs": 0}, "n_inputs"),
        ({"n_inputs": True}, "n_inputs"),
    ],
)
def test_bad_specs_are_typed_errors_naming_the_field(kwargs, field):
    args = {"kind": "central", "n_inputs": 10, "n_outputs": 4, **kwargs}
    with pytest.raises(InvalidDesignError, match=field):
        BrainSpec(**args)


def test_distributed_sizes_are_checked():
    with pytest.raises(InvalidDesignError, match="1 \\+ signals"):
        BrainSpec("distributed", 20, 2, signals=2)
    with pytest.raises(InvalidDesignError, match="neighbour signals"):
        BrainSpec("distributed", 5, 3, signals=2)
    with pytest.raises(InvalidDesignError, match="MAX_BRAIN_PARAMS"):
        BrainSpec("central", 10_000, 10_000, hidden=200)


@pytest.mark.parametrize(
    "weights, message",
    [
        (np.zeros(3), "shape"),
        (np.full(49, np.nan), "NaN"),
        (np.full(49, 3.5), "outside"),
        (np.array(["a"] * 49), "real numbers"),
        ([[1.0] * 49], "shape"),
    ],
)
def test_bad_weights_are_typed_errors(weights, message):
    spec = BrainSpec("central", 10, 4, hidden=3)
    with pytest.raises(InvalidDesignError, match=message):
        spec.brain(weights)


def test_clipped_and_random_stay_in_bounds_and_are_read_only():
    spec = BrainSpec("distributed", 27, 2, hidden=4, signals=1)
    b = spec.clipped(np.linspace(-10, 10, spec.n_params))
    assert np.abs(b.weights).max() == WEIGHT_BOUND
    with pytest.raises(ValueError):
        b.weights[0] = 0.0
    r1, r2 = spec.random(3), spec.random(3)
    assert r1 == r2 and np.abs(r1.weights).max() <= WEIGHT_BOUND


def test_a_design_carries_its_brain_through_json():
    spec = BrainSpec("distributed", 27, 2, hidden=4, signals=1)
    d = default_walker().replace(brain=spec.random(0))
    back = RobotDesign.from_json(d.to_json())
    assert back == d and back.brain == d.brain
    assert back != d.replace(brain=spec.random(1))
    assert "brain" not in default_walker().to_dict()  # open-loop designs' files are unchanged
    with pytest.raises(InvalidDesignError, match="brain"):
        RobotDesign(d.grid, brain="a brain")
    bad = d.to_dict()
    bad["brain"]["weights"] = bad["brain"]["weights"][:-1]
    with pytest.raises(InvalidDesignError, match="shape"):
        RobotDesign.from_dict(bad)


def test_forward_of_parts_equals_forward_of_their_concatenation():
    rng = np.random.default_rng(0)
    spec = BrainSpec("distributed", 12, 2, hidden=5, signals=1)
    w = np.stack([spec.random(i).weights for i in range(3)])
    cells, shared, sig = rng.normal(size=(3, 7, 4)), rng.normal(size=(3, 1, 2)), rng.normal(size=(3, 7, 6))
    whole = np.concatenate([cells, np.broadcast_to(shared, (3, 7, 2)), sig], axis=2)
    a = forward(spec, w, whole)
    b = forward(spec, w, [cells, shared, sig])
    assert a.shape == (3, 7, 2)
    np.testing.assert_allclose(a, b, rtol=0, atol=1e-12)
    # each robot's network is its own: robot 1 alone gives its row of the batch
    np.testing.assert_allclose(forward(spec, w[1:2], whole[1:2]), a[1:2], rtol=0, atol=1e-12)


@settings(max_examples=40, deadline=None)
@given(
    st.lists(st.floats(allow_nan=False, allow_infinity=False, min_value=-1e6, max_value=1e6),
             min_size=33, max_size=33),
    st.integers(0, 3),
)
def test_any_finite_vector_clips_into_a_brain_whose_outputs_are_bounded(values, hidden):
    spec = BrainSpec("central", 7, 3, hidden=hidden)
    w = (values * (spec.n_params // len(values) + 1))[: spec.n_params]
    b = spec.clipped(w)
    x = np.random.default_rng(0).normal(size=(1, 1, 7)) * 100
    y = forward(spec, b.weights[None, :], x)
    assert y.shape == (1, 1, 3) and np.all(np.abs(y) <= 1.0)
    assert Brain.from_dict(b.to_dict()) == b
