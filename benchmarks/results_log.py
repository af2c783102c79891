"""Appending a benchmark's results to ``benchmarks/RESULTS.md``: one heading format for every script."""

from __future__ import annotations

import datetime as _dt
import platform
from collections.abc import Sequence
from pathlib import Path

from softgym.engine import kernel_build, openmp_enabled

RESULTS = Path(__file__).with_name("RESULTS.md")


def heading(script: str, quick: bool = False, details: Sequence[str] = ()) -> str:
    """``### <script>[ --quick] — <UTC time>, <machine>, <details...>, OpenMP on|off``."""
    stamp = _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    parts = [stamp, platform.machine(), f"kernel build {kernel_build()}", *details,
             f"OpenMP {'on' if openmp_enabled() else 'off'}"]  # fmt: skip
    return f"\n### {script}{' --quick' if quick else ''} — {', '.join(parts)}\n"


def append(text: str, path: Path = RESULTS) -> None:
    """Append ``text`` (ending with a newline) to ``RESULTS.md``."""
    with Path(path).open("a", encoding="utf-8") as fh:
        fh.write(text if text.endswith("\n") else text + "\n")
