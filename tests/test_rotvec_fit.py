"""benchmarks/rotvec_fit.py: the float frames' cubic for k is the fit it prints (issue 29).

The header's SOFTGYM_RSQ_D0..D3 are the float roundings of the script's Remez fit, and the
header's arithmetic (the cubic, one Newton step) keeps k within 2 float roundings.
"""

import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SCRIPT = ROOT / "benchmarks" / "rotvec_fit.py"
HEADER = ROOT / "softgym" / "engine" / "include" / "softgym_seed.h"


def _defines(text: str) -> dict[str, float]:
    pat = r"#define (SOFTGYM_RSQ_D\d) \(?(-?[0-9.e-]+)f\)?"
    return {name: float(value) for name, value in re.findall(pat, text)}


def test_the_headers_cubic_is_the_fit_and_k_holds_to_two_roundings():
    res = subprocess.run([sys.executable, str(SCRIPT)], capture_output=True, text=True)
    assert res.returncode == 0, res.stdout + res.stderr
    fitted = _defines(res.stdout)
    assert len(fitted) == 4
    assert _defines(HEADER.read_text()) == fitted
    k = float(re.search(r"k within ([0-9.]+)", res.stdout).group(1))
    assert 1.0 <= k < 2.0
