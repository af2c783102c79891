"""The report's figures: fitness bands, repeats, materials, controller genes, crossings."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from evolvers.study.claims import crossing_generation, decided, winners
from evolvers.study.data import (
    OBSTACLE_SCENARIOS,
    REPORT_CROSSING_GENERATION,
    REPORT_CURVES,
    ROBOT_COM,
    RunData,
)
from evolvers.study.stats import finite_values
from softgym.design import CONTROLLER_BOUNDS, Controller
from softgym.design.material import EVOLVABLE_BOUNDS
from softgym.render.figures import pyplot

__all__ = [
    "controller_figure",
    "crossing_figure",
    "fitness_figure",
    "group_figure",
    "materials_figure",
    "repeats_figure",
]


# ---------------------------------------------------------------------------- figures
def _save(fig: Any, path: Path) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    pyplot().close(fig)
    return path


def _band(rs: Sequence[RunData], key: str) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Generations, median, Q1, Q3 of ``key`` over seeds (generations where any seed has it)."""
    n = max(r.generation for r in rs) + 1
    m = np.full((len(rs), n), np.nan)
    for i, r in enumerate(rs):
        s = r.series(key)
        m[i, : len(s)] = s
    ok = np.isfinite(m).any(axis=0)
    g = np.flatnonzero(ok)
    q1, med, q3 = (np.nanpercentile(m[:, ok], q, axis=0) for q in (25, 50, 75))
    return g, med, q1, q3


def _plot_band(ax: Any, rs: Sequence[RunData], key: str, label: str, color: Any) -> None:
    g, med, q1, q3 = _band(rs, key)
    ax.fill_between(g, q1, q3, color=color, alpha=0.25, linewidth=0)
    ax.plot(g, med, color=color, label=f"{label}: median, IQR (n={len(rs)})")


def _plot_reference(ax: Any, name: str, color: Any) -> None:
    pts = REPORT_CURVES.get(name)
    if pts:
        x, y = zip(*pts)
        ax.plot(x, y, "--", color=color, linewidth=1.2, label=f"{name}: the report's single run")


def _log_if_wide(ax: Any, decades: float = 2.0) -> None:
    """Log y axis when the plotted values span more than ``decades`` (e.g. a run that found the
    low-density flying exploit next to the report's curve), so the smaller curves stay readable.
    """
    ys = [np.asarray(line.get_ydata(), dtype=float) for line in ax.get_lines()]
    ys = [y[np.isfinite(y) & (y > 0)] for y in ys]
    y = np.concatenate(ys) if ys else np.empty(0)
    if y.size and np.log10(y.max() / y.min()) > decades:
        ax.set_yscale("log")
        ax.set_ylabel(f"{ax.get_ylabel()}, log scale")


def fitness_figure(name: str, rs: Sequence[RunData], path: Path) -> Path:
    """Best-of-generation fitness of one scenario: median and IQR over seeds, seeds thin, report dashed."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(6.4, 4.0))
    key = f"{rs[0].fitness}_best"
    for r in rs:
        s = r.series(key)
        ax.plot(np.arange(len(s)), s, color="0.75", linewidth=0.6)
    _plot_band(ax, rs, key, name, "C0")
    _plot_reference(ax, name, "C3")
    ax.set_xlabel("generation")
    ax.set_ylabel(f"best {rs[0].fitness} (voxel lengths)")
    _log_if_wide(ax)
    ax.set_title(f"{name}: best of generation over {len(rs)} seeds")
    ax.legend(fontsize=7, loc="best")
    fig.tight_layout()
    return _save(fig, path)


def group_figure(
    names: Sequence[str], runs: Mapping[str, list[RunData]], path: Path, title: str
) -> Path | None:
    """Several scenarios' best-of-generation bands in one axes, each with its report curve."""
    present = [n for n in names if runs.get(n)]
    if not present:
        return None
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(6.4, 4.0))
    for i, n in enumerate(present):
        rs = runs[n]
        _plot_band(ax, rs, f"{rs[0].fitness}_best", n, f"C{i}")
        _plot_reference(ax, n, f"C{i}")
    ax.set_xlabel("generation")
    ax.set_ylabel("best fitness (voxel lengths)")
    _log_if_wide(ax)
    ax.set_title(title)
    ax.legend(fontsize=7, loc="best")
    fig.tight_layout()
    return _save(fig, path)


def repeats_figure(runs: Mapping[str, list[RunData]], path: Path) -> Path | None:
    """Share of new robots with an already-simulated phenotype per generation (novelty, archive, basic)."""
    names = [n for n in ("novelty", "novelty-archive", "basic-200") if runs.get(n)]
    if not names:
        return None
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(6.4, 4.0))
    for i, n in enumerate(names):
        rs = runs[n]
        shares = []
        for r in rs:
            with np.errstate(invalid="ignore", divide="ignore"):
                shares.append(r.series("repeated_phenotypes") / r.series("new_individuals"))
        m = np.full((len(rs), max(len(s) for s in shares)), np.nan)
        for j, s in enumerate(shares):
            m[j, : len(s)] = s
        ok = np.isfinite(m).any(axis=0)
        if not ok.any():
            continue
        g = np.flatnonzero(ok)
        q1, med, q3 = (np.nanpercentile(m[:, ok], q, axis=0) for q in (25, 50, 75))
        ax.fill_between(g, q1, q3, color=f"C{i}", alpha=0.2, linewidth=0)
        ax.plot(g, med, color=f"C{i}", label=f"{n} (n={len(rs)})")
    ax.set_xlabel("generation")
    ax.set_ylabel("repeated phenotypes / new robots")
    ax.set_ylim(-0.02, 1.02)
    ax.set_title("'Patterns loop': new robots that repeat an earlier phenotype")
    ax.legend(fontsize=7)
    fig.tight_layout()
    return _save(fig, path)


def _strip(
    ax: Any, groups: Sequence[tuple[str, Sequence[float]]], rng: np.random.Generator
) -> None:
    for i, (_, vals) in enumerate(groups):
        v = finite_values(vals)
        if v.size:
            ax.scatter(i + rng.uniform(-0.12, 0.12, v.size), v, s=16, color=f"C{i}", zorder=3)
            ax.hlines(np.median(v), i - 0.25, i + 0.25, color="k", linewidth=1.5, zorder=4)
    ax.set_xticks(range(len(groups)))
    ax.set_xticklabels([g for g, _ in groups], fontsize=7, rotation=15)


def materials_figure(runs: Mapping[str, list[RunData]], path: Path) -> Path | None:
    """Materials of the winners of treatments 1 and 2 (one point per seed, black bar the median)."""
    names = [n for n in ("materials-t1", "materials-t2") if runs.get(n)]
    if not names:
        return None
    ws = {n: winners(runs[n]) for n in names}
    panels = (
        ("muscle |CTE| (1/°C)", "muscle_abs_cte", EVOLVABLE_BOUNDS.cte_magnitude, 0.04),
        ("muscle density (kg/m^3)", "muscle_density", EVOLVABLE_BOUNDS.density, 586635.0),
        ("tissue density (kg/m^3)", "tissue_density", EVOLVABLE_BOUNDS.density, 1273400.0),
        ("tissue Young's modulus (Pa)", "tissue_youngs", EVOLVABLE_BOUNDS.youngs_modulus, 5e6),
        ("voxels", "n_voxels", (0, None), None),
    )
    plt = pyplot()
    fig, axes = plt.subplots(1, len(panels), figsize=(3.0 * len(panels), 3.4))
    rng = np.random.default_rng(0)
    for ax, (label, attr, bounds, ref) in zip(axes, panels):
        _strip(ax, [(n, [getattr(w, attr) for w in ws[n]]) for n in names], rng)
        for b in bounds:
            if b:
                ax.axhline(b, color="0.6", linestyle=":", linewidth=1)
        if ref is not None:
            ax.axhline(ref, color="C3", linestyle="--", linewidth=1, label="report (T1 fastest)")
        if "density" in attr or "youngs" in attr:
            ax.set_yscale("log")
        ax.set_title(label, fontsize=8)
    axes[0].legend(fontsize=6)
    fig.suptitle(
        "Materials of the winners (dotted: GA bounds; dashed: the report's fastest T1 robot)",
        fontsize=9,
    )
    fig.tight_layout()
    return _save(fig, path)


def controller_figure(runs: Mapping[str, list[RunData]], path: Path) -> Path | None:
    """Controller genes and muscle voxels of the winners of the controller-evolving scenarios."""
    names = [n for n in ("controller-tournament", "controller-pareto", "obstacles-attempt2", "obstacles")
             if runs.get(n)]  # fmt: skip
    if not names:
        return None
    ws = {n: winners(runs[n]) for n in names}
    init = Controller()
    panels = [(f"{g} ({CONTROLLER_BOUNDS[g][2]})", g, CONTROLLER_BOUNDS[g][:2], getattr(init, g))
              for g in ("period", "temp_amplitude", "muscle_cte")]  # fmt: skip
    plt = pyplot()
    fig, axes = plt.subplots(1, 4, figsize=(12.5, 3.4))
    rng = np.random.default_rng(0)
    for ax, (label, gene, bounds, ref) in zip(axes, panels):
        _strip(ax, [(n, [w.genes[gene] for w in ws[n]]) for n in names], rng)
        for b in bounds:
            ax.axhline(b, color="0.6", linestyle=":", linewidth=1)
        ax.axhline(ref, color="C3", linestyle="--", linewidth=1, label="initial")
        ax.set_title(label, fontsize=8)
    _strip(axes[3], [(n, [w.n_muscle for w in ws[n]]) for n in names], rng)
    axes[3].set_title("muscle voxels", fontsize=8)
    axes[0].legend(fontsize=6)
    fig.suptitle(
        "Controllers of the winners (dotted: GA bounds; dashed: the initial controller)", fontsize=9
    )
    fig.tight_layout()
    return _save(fig, path)


def crossing_figure(runs: Mapping[str, list[RunData]], path: Path) -> Path | None:
    """First generation with a robot past the wall, one point per seed; seeds that never crossed on top."""
    names = [m for n in OBSTACLE_SCENARIOS for m in (n, n + ROBOT_COM) if runs.get(m)]
    if not names:
        return None
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(3.2 + 1.1 * len(names), 3.6))
    rng = np.random.default_rng(0)
    top = max(REPORT_CROSSING_GENERATION, *(r.generation for n in names for r in runs[n])) + 5
    for i, n in enumerate(names):
        g = np.array([crossing_generation(r) for r in runs[n]])
        _, undecided = decided(runs[n], REPORT_CROSSING_GENERATION)
        running = np.array([r.seed in undecided for r in runs[n]], dtype=bool)
        reached = np.array([r.generation for r in runs[n]], dtype=float)
        x = i + rng.uniform(-0.12, 0.12, g.size)
        hit = np.isfinite(g)
        never = ~hit & ~running
        ax.scatter(x[hit], g[hit], s=18, color=f"C{i}", zorder=3)
        ax.scatter(x[never], np.full(never.sum(), top), marker="x", s=22, color=f"C{i}", zorder=3)
        # a seed still running: an open circle at the generation it has reached
        ax.scatter(x[running], reached[running], s=22, facecolors="none", edgecolors=f"C{i}",
                   zorder=3)  # fmt: skip
        more = f" ({running.sum()} running)" if running.any() else ""
        ax.text(i, top + 2, f"{hit.sum()}/{(~running).sum()} crossed{more}", ha="center",
                fontsize=7)  # fmt: skip
    ax.axhline(REPORT_CROSSING_GENERATION, color="C3", linestyle="--", linewidth=1,
               label=f"report: final setup crossed at generation {REPORT_CROSSING_GENERATION}")  # fmt: skip
    ax.set_xticks(range(len(names)))
    ax.set_xticklabels([n.replace(ROBOT_COM, "\n(robot CoM)") for n in names], fontsize=7)
    ax.set_ylabel("first generation past the wall\n(x: not crossed; o: running, before gen. 80)")
    ax.set_ylim(-2, top + 8)
    ax.legend(fontsize=7, loc="lower right")
    fig.tight_layout()
    return _save(fig, path)
