"""Running a snippet of Python with the softgym of a given tree (a checkout or a copy).

``copy_tree`` copies this checkout's files (tracked and untracked, not ignored) and
``build_tree`` builds a tree's extensions in place, for the scripts that measure a copy
(``profile_engine.py --cycles``, ``port_bound.py``).

Run from a copy, a script in ``benchmarks/`` imports the installed (editable) checkout,
not the copy. ``run_in_tree`` runs the snippet in a child process with the tree first on
``PYTHONPATH``, reads the JSON the snippet prints after a tag, and refuses a result whose
``module`` (the snippet reports the file of a softgym module it used) lies outside the tree.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def copy_tree(dest: Path) -> None:
    """The repository's tracked and untracked (not ignored) files, copied to ``dest``."""
    listed = subprocess.run(["git", "ls-files", "-z", "--cached", "--others", "--exclude-standard"],
                            cwd=ROOT, capture_output=True, check=True).stdout  # fmt: skip
    for rel in listed.decode().split("\0"):
        if rel and (ROOT / rel).is_file():
            (dest / rel).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(ROOT / rel, dest / rel)


def build_tree(tree: Path, env: dict, who: str, what: str) -> None:
    """``python setup.py build_ext --inplace`` in ``tree`` with ``env`` added to the
    environment; a failure ends ``who`` with ``what`` and the build's last output."""
    res = subprocess.run([sys.executable, "setup.py", "build_ext", "--inplace"], cwd=tree,
                         env=dict(os.environ, **env), capture_output=True, text=True,
                         check=False)  # fmt: skip
    if res.returncode != 0:
        raise SystemExit(f"{who}: {what} failed:\n{res.stderr[-2000:]}")


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
