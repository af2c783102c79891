"""The claim-by-claim report of a study, written from its run folders alone.

``softgym study report RUNS`` (:func:`write_report`) reads every run folder
under ``RUNS`` (``config.json``, ``log.jsonl``, ``best_designs.json``; the
scenario from ``scenario.json`` beside it, see :mod:`evolvers.study`) and
writes ``README.md`` and figures:

* a table of what ran (seeds, generations reached, complete or not);
* one row per claim of the seed report: what the report says, what we
  measured (median, interquartile range, number of seeds), holds / partly /
  does not hold, and why;
* per scenario, the best-of-generation fitness (median and IQR band over
  seeds) vs. generation, with the report's single-run curve where it has one
  (Fig. 1, Fig. 4; values read from its plots, the seed study);
* the materials and controller genes of the winners (one point per seed);
* the generation at which a robot first crossed the wall (one point per seed).

Statistics are over seeds: ``median [Q1, Q3], n``. A comparison "A beats B"
holds when A's median is better and a one-sided permutation test of the
Mann-Whitney statistic gives p < 0.05 (20 000 permutations, fixed seed), is
"partly" when the median is better but p >= 0.05, and does not hold
otherwise; A12 (Vargha-Delaney: the chance that a seed of A beats one of B)
is given with it.
"""

from __future__ import annotations

import json
import logging
import math
import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from evolvers.study.claims import claims
from evolvers.study.data import REPORT_GENERATIONS, RunData, load_runs
from evolvers.study.figures import (
    controller_figure,
    crossing_figure,
    fitness_figure,
    group_figure,
    materials_figure,
    repeats_figure,
)

__all__ = [
    "write_report",
]

log = logging.getLogger(__name__)

# ---------------------------------------------------------------------------- README
def _cell(text: str) -> str:
    return str(text).replace("|", "\\|").replace("\n", " ")


def _settings(rs: Sequence[RunData]) -> str:
    e = rs[0].experiment
    sim = e.get("sim") or {}
    return (f"pop {e['pop_size']}, {e['seconds']:g} s, shape {'x'.join(map(str, e['shape']))}, "
            f"{e['selection']}" + (f", sim {json.dumps(sim)}" if sim else "")
            + (", seed's centre of mass" if e.get("seed_centre_of_mass") else ""))  # fmt: skip


def write_report(
    root: str | os.PathLike[str],
    out: str | os.PathLike[str] | None = None,
    command: str | None = None,
) -> Path:
    """Write ``out/README.md`` and ``out/figures/*.png`` from the run folders under ``root``.

    Parameters
    ----------
    root : path
        A study's root folder (or any folder holding run folders).
    out : path, optional
        Where the README and its figures go (default ``root/report``: a
        report never lands on the committed ``docs/study`` unless asked).
    command : str, optional
        The command that made the runs (quoted in the README).

    Returns
    -------
    Path
        The README.
    """
    runs = load_runs(root)
    out = Path(root) / "report" if out is None else Path(out)
    figs = out / "figures"
    figs.mkdir(parents=True, exist_ok=True)
    rows = claims(runs)
    pictures: list[tuple[str, Path]] = []
    for name, rs in runs.items():
        if rs and rs[0].rows:
            pictures.append((f"{name}: best-of-generation fitness over seeds",
                             fitness_figure(name, rs, figs / f"fitness_{name}.png")))  # fmt: skip
    for caption, p in (
        ("Fig. 4 trio: basic vs. controller evolution (dashed: the report's runs)",
         group_figure(("basic", "controller-tournament", "controller-pareto"), runs,
                      figs / "fig4_trio.png", "Fig. 4 over seeds")),
        ("Novelty vs. fitness-based selection: best fitness",
         group_figure(("novelty", "novelty-archive", "basic-200"), runs,
                      figs / "novelty_vs_fitness.png", "Novelty vs. fitness-based selection")),
        ("Repeated phenotypes per generation (the 'patterns loop')",
         repeats_figure(runs, figs / "repeated_phenotypes.png")),
        ("Materials of the winners", materials_figure(runs, figs / "winners_materials.png")),
        ("Controllers of the winners", controller_figure(runs, figs / "winners_controller.png")),
        ("Obstacle crossing generation, one point per seed",
         crossing_figure(runs, figs / "obstacle_crossing.png")),
    ):  # fmt: skip
        if p is not None:
            pictures.append((caption, p))

    lines = [
        "# The seed report's claims over many seeds",
        "",
        "Written by `softgym study report` from the run folders alone "
        f"(`{Path(root)}`; regenerate with `softgym study report {Path(root)} --out {out}`).",
        "",
    ]
    if command:
        lines += [f"Runs made with `{command}`.", ""]
    lines += ["## Runs", "",
              "| scenario | experiment | seeds | complete | generations asked | reached (min-max) | report's | settings |",
              "|---|---|---|---|---|---|---|---|"]  # fmt: skip
    for name, rs in runs.items():
        reached = [r.generation for r in rs]
        lines.append(
            f"| {name} | {rs[0].experiment['name']} | {len(rs)} | {sum(r.complete for r in rs)} "
            f"| {max(r.target for r in rs)} | {min(reached)}-{max(reached)} "
            f"| {REPORT_GENERATIONS.get(name, '-')} | {_cell(_settings(rs))} |"
        )
    unfinished = [(n, r) for n, rs in runs.items() for r in rs if not r.complete]
    if unfinished:
        lines += ["", "Not finished: " + ", ".join(
            f"{n} seed {r.seed} (generation {r.generation} of {r.target})" for n, r in unfinished) + "."]  # fmt: skip
    noted = [(n, r) for n, rs in runs.items() for r in rs if r.notes]
    if noted:
        lines += ["", "Notes the run folders carry (`notes.jsonl`):", ""]
        for n, r in noted:
            for note in r.notes:
                when = f" ({note['time'][:10]})" if "time" in note else ""
                lines.append(f"* {n} seed {r.seed}{when}: {note['text']}")
    lines += [
        "",
        "## Claims",
        "",
        "Values are over seeds: median [first quartile, third quartile], n seeds.",
        "",
        "| # | claim | section | the report says | we measured | verdict | why |",
        "|---|---|---|---|---|---|---|",
    ]
    for i, c in enumerate(rows, 1):
        lines.append(
            f"| {i} | {c.id} | {c.section} | {_cell(c.report)} | {_cell(c.measured)} | **{c.verdict}** | {_cell(c.why)} |"
        )
    lines += ["", "## Figures", ""]
    for caption, p in pictures:
        lines += [f"### {caption}", "", f"![{caption}](figures/{p.name})", ""]
    lines += [
        "## How it is measured",
        "",
        "* **Best of generation**: the `<fitness>_best` column of each run's `log.jsonl` (the "
        "population after selection); the report's curves are read from its Fig. 1 and Fig. 4 by eye.",
        "* **Winner**: the first entry of `best_designs.json` (the best robot a run found). Its "
        "materials are voxel-weighted over the materials its body uses.",
        "* **Crossed the wall**: a robot's final centre of mass lies outside the footprint of the "
        "fence (past its outer face); the log's `crossed` column counts them per generation; the "
        "crossing generation is the first generation whose population holds one.",
        "* **Obstacle scores**: the obstacle scenarios select on the seed's centre of mass, "
        "which counts the fence's 44 one-kilogram wall voxels (MaxXYDist scaled by m_robot / "
        "(m_robot + 44 kg)), as the seed's runs did; the `-robot-com` scenarios are the same "
        "experiments selected on the robot's own centre of mass. Crossing the wall is judged "
        "on the robot's own centre of mass in both.",
        "* **Repeated phenotype**: a robot evaluated for the first time (child or newcomer) whose "
        "phenotype (body, used materials, controller) was already simulated earlier in the run; "
        "the share is over generations >= 1.",
        "* **Verdicts**: comparisons use a one-sided permutation test of the Mann-Whitney statistic "
        "(p < 0.05 holds; right direction but p >= 0.05 partly) and A12; other rules are in each row.",
        "* **Unfinished seeds**: a scenario with complete runs is judged on those only (an "
        "unfinished seed's early generation is not compared with other seeds' last one; the row "
        "names the seeds left out); a scenario with none is judged on what has run, marked "
        "provisional. A claim read at a fixed generation (T2-voxels: T1 at generation 50) also "
        "counts unfinished runs that have passed it. The figures show every seed.",
        "",
    ]
    readme = out / "README.md"
    readme.write_text("\n".join(lines))
    (out / "claims.json").write_text(
        json.dumps([_plain(dict(c.__dict__)) for c in rows], indent=1, allow_nan=False) + "\n"
    )
    return readme


def _plain(v: Any) -> Any:
    """JSON-ready values (NaN and infinities as None)."""
    if isinstance(v, Mapping):
        return {str(k): _plain(x) for k, x in v.items()}
    if isinstance(v, (list, tuple, np.ndarray)):
        return [_plain(x) for x in v]
    if isinstance(v, (np.generic, int, float)) and not isinstance(v, bool):
        f = float(v)
        if not math.isfinite(f):
            return None
        return int(v) if isinstance(v, (int, np.integer)) else f
    return v
