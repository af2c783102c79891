"""benchmarks/frames_probe.py: the frames-pass probe still builds against the engine's
headers, and its pass agrees with the engine's compiled one bit for bit.

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
SCRIPT = ROOT / "benchmarks" / "frames_probe.py"


@pytest.mark.skipif(shutil.which(os.environ.get("CC", "cc")) is None
                    or platform.machine().lower() not in {"x86_64", "amd64"},
                    reason="needs a C compiler on x86-64")  # fmt: skip
def test_the_probe_builds_and_matches_the_engine_bit_for_bit():
    res = subprocess.run([sys.executable, str(SCRIPT), "--chunks", "2", "--reps", "3",
                          "--large", "0", "0.5"],
                         capture_output=True, text=True, timeout=600)  # fmt: skip
    assert res.returncode == 0, res.stdout + res.stderr
    timed = [line for line in res.stdout.splitlines() if "cycles per 16 links" in line]
    assert len(timed) >= 2, res.stdout  # at least one build ran both shares
    checked = [line for line in timed if "bit identity:" in line]
    assert checked, res.stdout  # at least the build that matches the running kernel
    for line in checked:
        assert "differing 0 of" in line and "of 0 values" not in line, line


def test_the_probe_refuses_bad_shares():
    res = subprocess.run([sys.executable, str(SCRIPT), "--large", "1.5"],
                         capture_output=True, text=True, timeout=120)  # fmt: skip
    assert res.returncode == 2 and "--large" in res.stderr
