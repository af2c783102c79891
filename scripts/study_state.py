#!/usr/bin/env python3
"""Carry a study's run folders between machines: what resuming needs, nothing more.

A study (``softgym study``) runs for many hours and is resumed many times, but
the machines it runs on do not keep their disks between sessions. This script
copies the part of each run folder that resuming and ``softgym study report``
need into a folder that can be committed or copied (``save``), and puts it back
into a run root (``restore``):

* per run: ``config.json``, ``identity.json`` (the run's identity, which its
  checkpoints record), ``log.jsonl``, ``notes.jsonl``,
  ``best_designs.json``, ``best_design.json``, ``final_population.json``;
* for a run that is not complete (``evolvers.study.run_status`` against its
  scenario's generations), the newest *intact* checkpoint too (its ``.json``
  and ``.npz``; checked with :func:`softgym.io.load_latest_intact`, so a
  checkpoint half written by a running study is never taken). A complete run
  needs none (the study skips it; the report reads its log), and checkpoints
  are most of a run folder's bytes: the phenotype cache holds the trajectory of
  every robot simulated. Extending a complete run to more generations after a
  restore starts it again from generation 0 (same seed, same result);
* per scenario and study: ``scenario.json`` and ``study.json``.

Figures, ``.vxa`` files, ``log.csv`` (``log.jsonl`` holds the same rows), the
``best_designs/`` folder and older checkpoints are left out: a run writes them
again when it resumes. Files in the saved copy
that the run no longer has (an older checkpoint) are removed; run folders and
scenarios that the run root no longer has (moved aside or renamed) only with
``--prune`` (a partly restored root would otherwise empty the copy); files whose
bytes did not change are not rewritten, so a committed copy only changes where
the study moved on.

``restore`` never moves a run back: a run folder whose newest checkpoint is at
or past the saved one is left alone (the message says so).

    python scripts/study_state.py save /work/runs/study benchmarks/data/study/runs [--prune]
    python scripts/study_state.py restore benchmarks/data/study/runs /work/runs/study
"""

from __future__ import annotations

import argparse
import shutil
import sys
from pathlib import Path

from evolvers.recording.recorder import IDENTITY_FILE
from evolvers.study import run_status
from softgym.exceptions import CheckpointError
from softgym.io import list_checkpoints, load_latest_intact, read_json

RUN_FILES = (
    "config.json",
    IDENTITY_FILE,
    "log.jsonl",
    "notes.jsonl",
    "best_designs.json",
    "best_design.json",
    "final_population.json",
)
ROOT_FILES = ("scenario.json", "study.json")


class StudyStateError(Exception):
    """A folder that is not there, or a run whose checkpoints are all damaged."""


def _run_dirs(root: Path) -> list[Path]:
    return sorted(p.parent for p in root.rglob("config.json") if p.parent != root)


def _copy_if_changed(src: Path, dst: Path) -> bool:
    """Copy ``src`` to ``dst`` unless ``dst`` holds the same bytes; True if written."""
    if dst.exists() and dst.read_bytes() == src.read_bytes():
        return False
    dst.parent.mkdir(parents=True, exist_ok=True)
    tmp = dst.with_name(dst.name + ".tmp")
    shutil.copyfile(src, tmp)
    tmp.replace(dst)
    return True


def _selected(run: Path) -> list[Path]:
    """The files of one run folder that are kept (relative to it)."""
    keep = [Path(n) for n in RUN_FILES if (run / n).is_file()]
    ckdir = run / "checkpoints"
    if _complete(run):
        return keep
    if ckdir.is_dir() and list_checkpoints(ckdir):
        try:
            ck = load_latest_intact(ckdir).path
        except CheckpointError as exc:
            raise StudyStateError(f"{run}: {exc}") from None
        keep += [Path("checkpoints") / ck.name, Path("checkpoints") / ck.with_suffix(".npz").name]
    return keep


def _complete(run: Path) -> bool:
    """Whether the run reached its scenario's generations (False without a scenario.json)."""
    scenario = run.parent / "scenario.json"
    if not scenario.is_file():
        return False
    generations = read_json(scenario).get("generations")
    return isinstance(generations, int) and run_status(run, generations) == "complete"


def _step(run: Path) -> int:
    """Newest checkpoint step of a run folder, -1 if none."""
    ckdir = run / "checkpoints"
    if not ckdir.is_dir() or not list_checkpoints(ckdir):
        return -1
    try:
        return int(load_latest_intact(ckdir).state["step"])
    except CheckpointError:
        return -1


def _mirror(src_root: Path, dst_root: Path, runs: list[Path], prune: bool) -> tuple[int, int]:
    written = removed = 0
    for name in ROOT_FILES:
        for f in sorted(src_root.rglob(name)):
            rel = f.relative_to(src_root)
            written += _copy_if_changed(f, dst_root / rel)
    for run in runs:
        rel = run.relative_to(src_root)
        files = _selected(run)
        for f in files:
            written += _copy_if_changed(run / f, dst_root / rel / f)
        if prune:
            wanted = {dst_root / rel / f for f in files}
            for old in sorted((dst_root / rel).rglob("*")):
                if old.is_file() and old not in wanted:
                    old.unlink()
                    removed += 1
    return written, removed


def _gone(src_root: Path, dst_root: Path, runs: list[Path]) -> list[Path]:
    """Run folders of ``dst_root`` that ``src_root`` does not have."""
    if not dst_root.is_dir():
        return []
    keep = {run.relative_to(src_root) for run in runs}
    return [r for r in _run_dirs(dst_root) if r.relative_to(dst_root) not in keep]


def _prune_gone(src_root: Path, dst_root: Path, runs: list[Path]) -> int:
    """Remove the run folders and scenario files that ``src_root`` no longer has.

    E.g. a scenario renamed or moved aside. Returns the number of files removed.
    """
    removed = 0
    for run in _gone(src_root, dst_root, runs):
        removed += sum(f.is_file() for f in run.rglob("*"))
        shutil.rmtree(run)
    for name in ROOT_FILES:
        for f in sorted(dst_root.rglob(name)):
            if not (src_root / f.relative_to(dst_root)).is_file():
                f.unlink()
                removed += 1
    for d in sorted((p for p in dst_root.rglob("*") if p.is_dir()), reverse=True):
        if not any(d.iterdir()):
            d.rmdir()
    return removed


def save(runs_root: Path, dest: Path, prune: bool = False) -> str:
    """Copy what resuming needs from ``runs_root`` into ``dest``; one line of what changed.

    With ``prune``, also remove the run folders and scenario files of ``dest``
    that ``runs_root`` no longer has; without, the line counts them.
    """
    if not runs_root.is_dir():
        raise StudyStateError(f"{runs_root} is not a folder")
    runs = _run_dirs(runs_root)
    written, removed = _mirror(runs_root, dest, runs, prune=True)
    msg = f"saved {len(runs)} run folders into {dest}: {written} files written, {removed} removed"
    gone = _gone(runs_root, dest, runs)
    if gone and prune:
        n = _prune_gone(runs_root, dest, runs)
        msg += f"; pruned {len(gone)} run folders {runs_root} no longer has ({n} files)"
    elif gone:
        msg += (f"; {len(gone)} run folders in {dest} are not in {runs_root} (moved or "
                "renamed?): --prune removes them")  # fmt: skip
    return msg


def restore(saved: Path, runs_root: Path) -> str:
    """Put a saved study back under ``runs_root``, never moving a run folder backwards."""
    if not saved.is_dir():
        raise StudyStateError(f"{saved} is not a folder")
    runs = _run_dirs(saved)

    def already_there(run: Path) -> bool:
        there = runs_root / run.relative_to(saved)
        if _complete(there):
            return True
        saved_step = _step(run)
        return saved_step >= 0 and _step(there) >= saved_step

    newer = [r for r in runs if already_there(r)]
    todo = [r for r in runs if r not in newer]
    written, _ = _mirror(saved, runs_root, todo, prune=False)
    msg = f"restored {len(todo)} run folders into {runs_root} ({written} files)"
    if newer:
        msg += f"; left {len(newer)} alone (already at or past the saved checkpoint)"
    return msg


def main(argv: list[str] | None = None) -> int:
    """The command line: ``save RUNS DEST`` or ``restore SAVED RUNS``."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = ap.add_subparsers(dest="verb", required=True)
    s = sub.add_parser("save", help="copy a study's resumable state out of its run root")
    s.add_argument("runs", type=Path)
    s.add_argument("dest", type=Path)
    s.add_argument(
        "--prune",
        action="store_true",
        help="also remove the run folders of DEST that RUNS no longer has (moved or renamed)",
    )
    r = sub.add_parser("restore", help="put a saved study back into a run root")
    r.add_argument("saved", type=Path)
    r.add_argument("runs", type=Path)
    args = ap.parse_args(argv)
    try:
        if args.verb == "save":
            print(save(args.runs, args.dest, prune=args.prune))
        else:
            print(restore(args.saved, args.runs))
    except StudyStateError as exc:
        print(f"study_state: {exc}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
