"""softgym.evaluate refuses bad arguments with typed errors (issue 31), before simulating."""

import pytest

import softgym
from softgym.design import default_walker
from softgym.engine import SimConfig
from softgym.exceptions import InvalidDesignError, InvalidParameterError, SoftGymError


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"seconds": "abc"}, "seconds must be a finite number > 0"),
        ({"seconds": [1]}, "seconds must be a finite number > 0"),
        ({"seconds": 1j}, "seconds must be a finite number > 0"),
        ({"seconds": True}, "seconds must be a finite number > 0"),  # a bool is not 1 s
        ({"seconds": float("inf")}, "seconds must be a finite number > 0"),
        ({"trace_interval": 0.0}, "trace_interval must be a finite number > 0"),
        ({"n_threads": "x"}, r"n_threads must be an integer in 1\.\.1024"),
        ({"n_threads": 0}, r"n_threads must be an integer in 1\.\.1024"),
        ({"config": "seed"}, "config must be a softgym SimConfig"),
        # the memory budget: 5e9 samples per robot
        ({"trace_interval": 1e-9, "seconds": 5.0}, "raise trace_interval"),
    ],
)  # fmt: skip
def test_bad_arguments_raise_typed_errors_naming_the_field(kwargs, message):
    with pytest.raises(InvalidParameterError, match=message):
        softgym.evaluate([default_walker()], **kwargs)


@pytest.mark.parametrize("designs", [None, 3, "robot.json", [None], [default_walker(), 7]])
def test_what_is_not_a_design_is_refused(designs):
    with pytest.raises((InvalidDesignError, InvalidParameterError)) as info:
        softgym.evaluate(designs, seconds=0.1)
    assert isinstance(info.value, SoftGymError)


def test_a_simconfig_is_accepted_and_an_empty_batch_returns_empty_metrics():
    m = softgym.evaluate([default_walker()], seconds=0.05, config=SimConfig(), progress=False)
    assert m["norm_final_dist"].shape == (1,)
    assert softgym.evaluate([], seconds=0.1)["norm_final_dist"].shape == (0,)
