"""CPPNVector: a fixed-topology CPPN, the controller genes and a brain as one real vector."""

import numpy as np
import pytest

from evolvers.operators.encoding import CPPNVector
from softgym.design import (
    CONTROLLER_BOUNDS,
    HIDDEN_ACTIVATIONS,
    INPUT_NAMES,
    MATERIAL_TREE_4,
    MATERIAL_TREE_8,
    CompositionRules,
)
from softgym.design.brain import WEIGHT_BOUND, BrainSpec
from softgym.exceptions import InvalidDesignError, InvalidParameterError


def test_layout_names_and_bounds():
    enc = CPPNVector()
    n_in, n_h, n_out = len(INPUT_NAMES), len(HIDDEN_ACTIVATIONS), len(MATERIAL_TREE_4)
    assert enc.n_weights == n_in * n_h + n_h * n_out + n_in * n_out == 83
    assert enc.size == 86 and len(enc.names) == 86
    assert enc.names[0] == "w[x->0]" and enc.names[-3:] == list(CONTROLLER_BOUNDS)
    assert np.all(enc.lower[:83] == -1.0) and np.all(enc.upper[:83] == 1.0)
    for k, (lo, hi, _) in enumerate(CONTROLLER_BOUNDS.values()):
        assert (enc.lower[83 + k], enc.upper[83 + k]) == (lo, hi)
    no_controller = CPPNVector(MATERIAL_TREE_8, hidden=("sin",), controller=False)
    assert no_controller.size == 5 * 1 + 1 * 8 + 5 * 8


def test_decoding_is_the_cppn_genome_with_these_weights():
    enc = CPPNVector(hidden=("sin", "abs"))
    x = enc.random(0)
    g = enc.cppn(x)
    assert g.hidden == [0, 1] and g.activation(0) == "sin" and g.activation(1) == "abs"
    assert all(g.activation(o) == "sigmoid" for o in MATERIAL_TREE_4)
    assert list(g.edges.values()) == pytest.approx(list(x[: enc.n_weights]))
    # the same graph written by hand evaluates to the same outputs (reference by numpy)
    inputs = np.stack(_inputs((3, 4, 5)))
    w = dict(zip(enc._edges, x))
    hidden = [np.sin(sum(w[(i, 0)] * inputs[k] for k, i in enumerate(INPUT_NAMES))),
              np.abs(sum(w[(i, 1)] * inputs[k] for k, i in enumerate(INPUT_NAMES)))]  # fmt: skip
    out = g.evaluate((3, 4, 5))
    for o in MATERIAL_TREE_4:
        s = sum(w[(h, o)] * hidden[h] for h in (0, 1))
        s = s + sum(w[(i, o)] * inputs[k] for k, i in enumerate(INPUT_NAMES))
        assert np.allclose(out[o].ravel(), (2.0 / (1.0 + np.exp(-s)) - 1.0).ravel(), atol=1e-12)


def _inputs(shape):
    from softgym.design import cppn_inputs

    d = cppn_inputs(shape)
    return [d[name].ravel() for name in INPUT_NAMES]


def test_individual_carries_the_controller_and_brain_and_clips_into_bounds():
    spec = BrainSpec(kind="central", n_inputs=3, n_outputs=2, hidden=2)
    enc = CPPNVector(brain_spec=spec)
    x = enc.random(1)
    x[enc.n_weights] = 1e3  # amplitude far above its bound
    x[-1] = -50.0  # a brain weight far below its bound
    ind = enc.individual(x, 7)
    assert ind.id == 7 and ind.controller.temp_amplitude == CONTROLLER_BOUNDS["temp_amplitude"][1]
    assert ind.brain_spec == spec and ind.brain.shape == (spec.n_params,)
    assert ind.brain[-1] == -WEIGHT_BOUND
    assert ind.cppn == enc.cppn(np.clip(x, enc.lower, enc.upper))
    with pytest.raises(InvalidParameterError, match=r"shape \(" + str(enc.size)):
        enc.individual(x[:-1], 0)
    with pytest.raises(InvalidParameterError, match="finite"):
        enc.individual(np.full(enc.size, np.nan), 0)


def test_random_valid_draws_valid_bodies_reproducibly():
    enc = CPPNVector()
    rules = CompositionRules.seed()
    xs = [enc.random_valid(np.random.default_rng(3), (5, 5, 5), rules) for _ in range(2)]
    assert np.array_equal(xs[0], xs[1])
    rng = np.random.default_rng(4)
    for _ in range(5):
        grid = enc.cppn(enc.random_valid(rng, (5, 5, 5), rules)).to_grid((5, 5, 5))
        assert not rules.violations(grid)
    with pytest.raises(InvalidDesignError, match="3 attempts"):
        enc.random_valid(0, (4, 4, 4), lambda grid: False, max_attempts=3)


@pytest.mark.parametrize(
    "kw, word",
    [
        ({"hidden": ("tanh",)}, "hidden"),
        ({"controller": 1}, "controller"),
        ({"weight_bound": 0.0}, "weight_bound"),
        ({"outputs": ("shape", "shape")}, "outputs"),
        ({"brain_spec": {"kind": "central"}}, "brain_spec"),
    ],
)
def test_bad_arguments_name_the_argument(kw, word):
    with pytest.raises(InvalidParameterError, match=word):
        CPPNVector(**kw)
