"""What the tests of the benchmarks' C probes share: the skip where no probe can run (off
x86-64, no C compiler), and running a probe's script as a user does (a child process)."""

import os
import platform
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

needs_cc_on_x86_64 = pytest.mark.skipif(
    shutil.which(os.environ.get("CC", "cc")) is None
    or platform.machine().lower() not in {"x86_64", "amd64"},
    reason="needs a C compiler on x86-64",
)


def run_probe(script: str, *args: str, timeout: float = 600) -> subprocess.CompletedProcess:
    """``python benchmarks/<script> args...``, its output captured."""
    return subprocess.run([sys.executable, str(ROOT / "benchmarks" / script), *args],
                          capture_output=True, text=True, timeout=timeout)  # fmt: skip
