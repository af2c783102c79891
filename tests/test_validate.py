"""softgym.validate: the shared checks name the field, refuse bools and strings, and show
any bad value in at most 80 characters."""

import math

import numpy as np
import pytest

from softgym.exceptions import InvalidParameterError, InvalidTerrainError
from softgym.validate import is_int, is_real, number, positive, show


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
