"""Every code block of the README runs verbatim (issue 13).

Python blocks run as scripts and bash blocks line by line, in order, in one scratch
folder, with ``SOFTGYM_SMOKE=1`` (every evolution run cut to one generation of four
small robots). Lines that install (``pip``, venvs), run the test suite, or run
``softgym study`` (its own test, tests/evolvers/test_study.py) are left out.
"""

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SKIP = ("pip ", "python3 -m venv", "python -m pytest", "ruff ", "softgym study")


def _blocks():
    text = (ROOT / "README.md").read_text()
    return [(m.group(1), m.group(2)) for m in re.finditer(r"```(\w+)\n(.*?)```", text, re.S)]


def test_readme_has_code_blocks():
    kinds = [k for k, _ in _blocks()]
    assert kinds.count("python") >= 5 and kinds.count("bash") >= 2


@pytest.mark.slow
def test_every_readme_block_runs_verbatim(tmp_path):
    env = {**os.environ, "SOFTGYM_SMOKE": "1", "MPLBACKEND": "Agg"}
    bindir = Path(sys.executable).parent
    env["PATH"] = f"{bindir}{os.pathsep}{env.get('PATH', '')}"  # softgym = this install
    ran = 0
    for k, (kind, code) in enumerate(_blocks()):
        if kind == "python":
            res = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, env=env,
                                 capture_output=True, text=True, timeout=600)  # fmt: skip
            assert res.returncode == 0, f"README python block {k}:\n{code}\n{res.stderr[-3000:]}"
            ran += 1
        elif kind == "bash":
            for line in code.splitlines():
                cmd = line.split("  #")[0].strip()
                if not cmd or cmd.startswith("#"):
                    continue
                if "&&" in cmd:  # the quick start: keep what follows the install
                    parts = [p.strip() for p in cmd.split("&&")]
                    cmd = " && ".join(p for p in parts if not p.startswith(SKIP) and
                                      not p.startswith(". .venv"))  # fmt: skip
                if not cmd or cmd.startswith(SKIP):
                    continue
                res = subprocess.run(["bash", "-c", cmd], cwd=tmp_path, env=env,
                                     capture_output=True, text=True, timeout=600)  # fmt: skip
                assert res.returncode == 0, f"README line: {cmd}\n{res.stderr[-3000:]}"
                ran += 1
    assert ran >= 15
