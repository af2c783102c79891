"""Running a snippet of Python with the softgym of a given tree (a checkout or a copy).

Run from a copy, a script in ``benchmarks/`` imports the installed (editable) checkout,
not the copy. ``run_in_tree`` runs the snippet in a child process with the tree first on
``PYTHONPATH``, reads the JSON the snippet prints after a tag, and refuses a result whose
``module`` (the snippet reports the file of a softgym module it used) lies outside the tree.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path


def run_in_tree(tree: Path, code: str, tag: str, who: str, env: dict | None = None) -> dict:
    """The JSON object printed by ``code`` after ``tag + " "``, run with ``tree``'s softgym.

    ``who`` names the calling script in error messages; ``env`` adds environment
    variables. Exits with the child's error output when it fails or prints no result,
    and when the result's ``module`` is not in ``tree``.
    """
    tree = Path(tree).resolve()
    child_env = dict(os.environ, **(env or {}), PYTHONPATH=str(tree))
    res = subprocess.run([sys.executable, "-c", code], cwd=tree, env=child_env,
                         capture_output=True, text=True, check=False)  # fmt: skip
    prefix = tag + " "
    line = next((ln for ln in res.stdout.splitlines() if ln.startswith(prefix)), None)
    if res.returncode != 0 or line is None:
        raise SystemExit(f"{who}: the run in {tree} failed:\n{res.stderr[-2000:]}")
    out = json.loads(line[len(prefix):])
    if not Path(out["module"]).resolve().is_relative_to(tree):
        raise SystemExit(f"{who}: the run in {tree} imported {out['module']}, not that tree")
    return out
