"""Shared harness of the property-based (Hypothesis) tests of hostile inputs.

Every public entry must give a valid object or a :class:`~softgym.exceptions.SoftGymError`,
never another exception. ``outcome`` calls an entry and counts what it gave in ``OUTCOMES``
(the tally of issue 12); ``SOFTGYM_FUZZ_EXAMPLES`` raises the example count for a deeper run.
"""

import os
from collections import Counter

import pytest
from hypothesis import HealthCheck, settings

from softgym.exceptions import SoftGymError

#: Examples per property (the default keeps the suite fast).
FUZZ_EXAMPLES = int(os.environ.get("SOFTGYM_FUZZ_EXAMPLES", "150"))

FUZZ = settings(
    max_examples=FUZZ_EXAMPLES,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
    database=None,
)

#: (kind, "valid" or the error class name) -> count, over the whole run.
OUTCOMES: Counter = Counter()


def outcome_and_result(kind, fn, *args, **kwargs):
    """Call ``fn``; count and return ("valid" or the SoftGymError's class name, its result or
    None); fail on anything else."""
    try:
        result = fn(*args, **kwargs)
    except SoftGymError as exc:
        label, result = type(exc).__name__, None
    except Exception as exc:  # noqa: BLE001 - the property under test
        pytest.fail(f"{kind}: {type(exc).__name__} escaped: {exc!s:.300}")
    else:
        label = "valid"
    OUTCOMES[(kind, label)] += 1
    return label, result


def outcome(kind, fn, *args, **kwargs):
    """Call ``fn``; count and return "valid" or the SoftGymError's class name; fail on anything else."""
    return outcome_and_result(kind, fn, *args, **kwargs)[0]


def refused_in_child(code: str, timeout: float = 60.0) -> str:
    """Run ``code`` in a child Python (a hang fails the test by ``timeout``); return its stdout.

    For inputs that could block a reader forever (a FIFO given as a path): the
    code catches the expected error and prints ``REFUSED <message>``.
    """
    import subprocess
    import sys

    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=timeout)  # fmt: skip
    assert "REFUSED" in res.stdout, res.stderr[-2000:]
    return res.stdout


def fifo_code(imports: str, call: str, path: str, error: str) -> str:
    """The child code of :func:`refused_in_child` for ``call(path)`` raising ``error``."""
    return (f"{imports}\nfrom softgym.exceptions import {error}\n"
            f"try:\n    {call}({path!r})\nexcept {error} as e:\n    print('REFUSED', e)\n")
