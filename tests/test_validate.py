"""softgym.validate: the shared checks name the field, refuse bools and strings, and show
any bad value in at most 80 characters."""

import math

import numpy as np
import pytest

from softgym.exceptions import InvalidParameterError, InvalidTerrainError
from softgym.validate import MAX_THREADS, is_int, is_real, number, positive, show, threads


def test_number_refuses_what_is_not_a_real_number():
    assert number("x", 3) == 3.0 and number("x", np.float32(0.5)) == 0.5
    for bad in (True, "0.5", b"1", [1.0], None, 1j):
        with pytest.raises(InvalidParameterError, match="x must be a number"):
            number("x", bad)
    with pytest.raises(InvalidTerrainError, match="x must be finite"):
        number("x", math.inf, error=InvalidTerrainError)
    assert math.isnan(number("x", math.nan, finite=False))


def test_positive_names_the_unit_and_takes_numpy_scalars():
    assert positive("dt", np.array(0.25)) == 0.25 and positive("dt", 10**400 // 10**399) == 10
    for bad in (0, -1.0, math.nan, math.inf, 10**400, "1", True):
        with pytest.raises(InvalidParameterError, match=r"dt must be a finite number > 0 \(s\)"):
            positive("dt", bad, unit=" (s)")


def test_ints_reals_and_how_values_are_shown():
    assert is_int(np.int8(3)) and not is_int(True) and not is_int(3.0)
    assert is_real(np.float64(1)) and not is_real(np.bool_(True)) and not is_real("1")
    assert show(10**5000) == "<a 16610-bit integer, too large to print>"
    assert show((1, "a")) == "(1, 'a')" and show([2**70]) == "[<a 71-bit integer, too large to print>]"
    assert len(show("x" * 500)) == 80


@pytest.mark.parametrize("bad", [0, -1, 1.5, 2.0, True, "2", MAX_THREADS + 1, [2]])
def test_every_entry_checks_a_thread_count_the_same_way(bad):
    # one check, one message: the engine, softgym.evaluate and the envs agree on what a
    # thread count is (they once had four bounds between them)
    import gymnasium as gym

    import softgym
    from softgym.design import default_walker
    from softgym.engine import Simulation

    msg = rf"n_threads must be an integer in 1\.\.{MAX_THREADS} \(None for all usable CPUs\)"
    with pytest.raises(InvalidParameterError, match=msg):
        threads(bad)
    with pytest.raises(InvalidParameterError, match=msg):
        Simulation([default_walker()], n_threads=bad)
    with pytest.raises(InvalidParameterError, match=msg):
        softgym.evaluate([default_walker()], seconds=1.5, n_threads=bad)
    with pytest.raises(InvalidParameterError, match=msg):
        gym.make("SoftWalker-Flat-v0", n_threads=bad)
    assert threads(None) is None and threads(np.int64(3)) == 3 and threads(MAX_THREADS) == MAX_THREADS
