"""benchmarks/dense_links_probe.py: the dense-lattice probe still builds against the engine's
headers and agrees with the engine's passes bit for bit.

Run as a user runs it (a child process); skipped without a C compiler or off x86-64.
"""

import os
import platform
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SCRIPT = ROOT / "benchmarks" / "dense_links_probe.py"


@pytest.mark.skipif(shutil.which(os.environ.get("CC", "cc")) is None
                    or platform.machine().lower() not in {"x86_64", "amd64"},
                    reason="needs a C compiler on x86-64")  # fmt: skip
def test_the_probe_builds_and_matches_the_engine_bit_for_bit():
    res = subprocess.run([sys.executable, str(SCRIPT), "--n", "3", "--fill", "0.8"],
                         capture_output=True, text=True, timeout=600)  # fmt: skip
    assert res.returncode == 0, res.stdout + res.stderr
    runs = [line for line in res.stdout.splitlines() if line.startswith("  bit identity:")]
    assert runs, res.stdout  # at least the portable build ran
    for line in runs:
        assert "differing 0 of" in line and "components differing 0 of" in line, line
