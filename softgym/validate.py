"""The checks every constructor shares: numbers, positive numbers, integers, and how a bad
value is shown in an error message.

Each raises a :class:`~softgym.exceptions.SoftGymError` subclass (``error=``,
:class:`~softgym.exceptions.InvalidParameterError` by default) naming the field
and what it accepts. Bools and strings are never numbers here (``True`` is not
1, ``"0.5"`` is not 0.5): a typo should fail where it is typed.
"""

from __future__ import annotations

import math
from numbers import Real
from typing import Any

import numpy as np

from softgym.exceptions import InvalidParameterError, SoftGymError

__all__ = ["MAX_THREADS", "is_int", "is_real", "number", "positive", "show", "threads"]

#: The most OpenMP threads a simulation, env or run accepts.
MAX_THREADS = 1024


def show(value: Any) -> str:
    """``repr(value)`` for an error message: at most 80 characters, and safe for what repr
    cannot print (an int of thousands of digits) or prints at length.
    """
    if isinstance(value, int) and not isinstance(value, bool) and value.bit_length() > 64:
        return f"<a {value.bit_length()}-bit integer, too large to print>"
    if isinstance(value, (list, tuple)) and len(value) <= 8:
        inner = ", ".join(show(v) for v in value)
        if isinstance(value, tuple):
            return f"({inner}{',' if len(value) == 1 else ''})"
        return f"[{inner}]"
    try:
        text = repr(value)
    except ValueError:
        return f"<{type(value).__name__} too large to print>"
    return text if len(text) <= 80 else text[:77] + "..."


def is_int(value: Any) -> bool:
    """Whether ``value`` is an integer (Python or NumPy), not a bool."""
    return isinstance(value, (int, np.integer)) and not isinstance(value, (bool, np.bool_))


def is_real(value: Any) -> bool:
    """Whether ``value`` is a real number (Python or NumPy int or float), not a bool."""
    return isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(
        value, (bool, np.bool_)
    )


def number(
    name: str, value: Any, error: type[SoftGymError] = InvalidParameterError, finite: bool = True
) -> float:
    """``value`` as a float: a real number (int, float, NumPy scalar), finite unless
    ``finite=False``; a bool, a string or a container raises ``error`` naming ``name``.
    """
    if isinstance(value, (bool, str, bytes)) or not isinstance(value, Real):
        raise error(f"{name} must be a number, got {show(value)}")
    try:
        v = float(value)
    except (TypeError, ValueError, OverflowError):
        raise error(f"{name} must be a finite number, got {show(value)}") from None
    if finite and not math.isfinite(v):
        raise error(f"{name} must be finite, got {v}")
    return v


def positive(
    name: str, value: Any, error: type[SoftGymError] = InvalidParameterError, unit: str = ""
) -> float:
    """``value`` as a finite float > 0 (``unit``, e.g. ``" (s)"``, is named in the message)."""
    if isinstance(value, np.ndarray) and value.ndim == 0:  # a NumPy scalar array
        value = value.item()
    try:
        v = float(value) if is_real(value) else math.nan
    except OverflowError:  # an int beyond float64
        v = math.inf
    if not (math.isfinite(v) and v > 0):
        raise error(f"{name} must be a finite number > 0{unit}, got {show(value)}")
    return v


def threads(value: Any, name: str = "n_threads", absent: str = "None") -> int | None:
    """A thread count as every entry takes it: None (all usable CPUs) or an integer in
    1..:data:`MAX_THREADS`; anything else raises
    :class:`~softgym.exceptions.InvalidParameterError` naming ``name``, the range and how
    all usable CPUs are asked for (``absent``: ``"None"``, or ``"left out"`` for a flag).
    """
    if value is None:
        return None
    if not is_int(value) or not 1 <= int(value) <= MAX_THREADS:
        raise InvalidParameterError(
            f"{name} must be an integer in 1..{MAX_THREADS} ({absent} for all usable CPUs), "
            f"got {show(value)}"
        )
    return int(value)
