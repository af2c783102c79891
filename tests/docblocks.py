"""Run the code blocks of Markdown documents verbatim (the README's and the site's tests).

Python blocks run as scripts and bash blocks line by line, in order, in one scratch
folder, with ``SOFTGYM_SMOKE=1`` (every evolution run cut to one generation of four
small robots). Lines that install (``pip``, venvs), run the test suite or the linter, or
run ``softgym study`` (its own test, tests/evolvers/study/test_study.py) are left out.
"""

import os
import re
import subprocess
import sys
from pathlib import Path

SKIP = ("pip ", "python3 -m venv", "python -m pytest", "ruff ", "softgym study", "bash .ci/run")


def code_blocks(text: str) -> list[tuple[str, str]]:
    """The ``(language, code)`` of every fenced block with a language tag, in order."""
    return [(m.group(1), m.group(2)) for m in re.finditer(r"```(\w+)\n(.*?)```", text, re.S)]


def bash_commands(code: str) -> list[str]:
    """The lines of a bash block that the tests run (comments and install lines left out)."""
    out = []
    for line in code.splitlines():
        cmd = line.split("  #")[0].strip()
        if not cmd or cmd.startswith("#"):
            continue
        if "&&" in cmd:  # the quick start: keep what follows the install
            parts = [p.strip() for p in cmd.split("&&")]
            cmd = " && ".join(p for p in parts if not p.startswith(SKIP) and
                              not p.startswith(". .venv"))  # fmt: skip
        if cmd and not cmd.startswith(SKIP):
            out.append(cmd)
    return out


def run_blocks(blocks: list[tuple[str, str]], cwd: Path, label: str) -> int:
    """Run the python and bash blocks in ``cwd``; assert each succeeds; return how many ran."""
    env = {**os.environ, "SOFTGYM_SMOKE": "1", "MPLBACKEND": "Agg"}
    bindir = Path(sys.executable).parent
    env["PATH"] = f"{bindir}{os.pathsep}{env.get('PATH', '')}"  # softgym = this install
    ran = 0
    for k, (kind, code) in enumerate(blocks):
        if kind == "python":
            res = subprocess.run([sys.executable, "-c", code], cwd=cwd, env=env,
                                 capture_output=True, text=True, timeout=600)  # fmt: skip
            assert res.returncode == 0, f"{label} python block {k}:\n{code}\n{res.stderr[-3000:]}"
            ran += 1
        elif kind == "bash":
            for cmd in bash_commands(code):
                res = subprocess.run(["bash", "-c", cmd], cwd=cwd, env=env,
                                     capture_output=True, text=True, timeout=600)  # fmt: skip
                assert res.returncode == 0, f"{label} line: {cmd}\n{res.stderr[-3000:]}"
                ran += 1
    return ran
