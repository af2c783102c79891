"""Building the C probes of the engine's passes (``dense_links_probe.c``, ``frames_probe.c``).

Each probe includes the engine's headers (``softgym/engine/include``) as they are and is
compiled with the flags of the engine's kernel (setup.py: ``-O3 -ffp-contract=fast
-fno-math-errno -fno-trapping-math``) for each x86-64 level, so that what it times is the
engine's own code.
"""

from __future__ import annotations

import os
import platform
import shutil
import subprocess
from pathlib import Path

HERE = Path(__file__).resolve().parent
INCLUDE = HERE.parent / "softgym" / "engine" / "include"
FLAGS = ["-O3", "-ffp-contract=fast", "-fno-math-errno", "-fno-trapping-math"]
LEVELS = {"baseline": [], "x86-64-v3": ["-march=x86-64-v3"], "x86-64-v4": ["-march=x86-64-v4"]}


def unavailable(name: str) -> str | None:
    """Why probe ``name`` cannot run here (off x86-64, no C compiler), or None."""
    if platform.machine().lower() not in {"x86_64", "amd64"}:
        return f"{name}: x86-64 only (it reads the time-stamp counter)"
    if shutil.which(os.environ.get("CC", "cc")) is None:
        return f"{name}: no C compiler (cc) on PATH"
    return None


def build(source: str, level: str, out: Path, extra: list[str] | None = None) -> Path | None:
    """``source`` (a C file next to this script) compiled for ``level`` in ``out`` (with
    ``extra`` flags), or None if the compiler refuses it (printed)."""
    exe = out / f"{Path(source).stem}_{level}"
    cmd = [os.environ.get("CC", "cc"), *FLAGS, *LEVELS[level], *(extra or []), f"-I{INCLUDE}",
           str(HERE / source), "-o", str(exe), "-lm"]  # fmt: skip
    res = subprocess.run(cmd, capture_output=True, text=True, check=False)
    if res.returncode != 0:
        print(f"{level}: the compiler refused it ({res.stderr.strip().splitlines()[-1:]})")
        return None
    return exe
