"""Matplotlib figures of evolutionary runs and robots.

* :func:`plot_fitness_trend`: average / best / worst / median of an objective
  per generation (the report's Fig. 1).
* :func:`plot_best_fitness`: best fitness per generation of several runs
  (the report's Fig. 4).
* :func:`plot_compare`: runs grouped by configuration (seeds), the median
  of their best fitness per generation with the interquartile band.
* :func:`plot_pareto_front`: the final population of a multi-objective run
  in objective space, its non-dominated front highlighted.
* :func:`plot_robot`: a design as matplotlib voxels coloured by material.
* :func:`plot_trajectory`: a centre-of-mass trace, top view and height.
* :func:`save_robot_gif`: a GIF (or, for ``.mp4``, a video) of a design
  moving, time and distance overlaid (frames from :mod:`softgym.render.frames`).
* :func:`run_figures`: all of the above for a run folder.

Every function writes a file and returns its path; matplotlib runs headless (Agg).
Axes carry units (:func:`metric_label`).
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from softgym.exceptions import InvalidParameterError

__all__ = [
    "METRIC_LABELS",
    "design_colors",
    "figure_path",
    "metric_label",
    "plot_best_fitness",
    "plot_compare",
    "plot_fitness_trend",
    "plot_pareto_front",
    "plot_robot",
    "plot_trajectory",
    "pyplot",
    "read_log",
    "run_figures",
    "save_robot_gif",
    "trace_interval_for",
]

#: Axis labels (with units) of the recorded metrics.
METRIC_LABELS: dict[str, str] = {
    "norm_final_dist": "NormFinalDist (voxel lengths)",
    "max_xy_dist": "MaxXYDist (voxel lengths)",
    "l_coefficient": "L coefficient (voxel lengths$^2$/s)",
    "time_max_xy_dist": "time of MaxXYDist (s)",
    "age": "age (generations)",
    "novelty": "novelty (AMSS distance, voxel lengths)",
    "bone_fraction": "robots with bone (fraction)",
    "evaluations_total": "simulations (count)",
    "wall_total": "wall time (s)",
}


def metric_label(metric: str) -> str:
    """Axis label of a metric, with its unit (the metric's name if it is unknown)."""
    return METRIC_LABELS.get(metric, metric)


def trace_interval_for(design: Any, default: float = 0.01) -> float:
    """Centre-of-mass sampling interval (s) fine enough to show a design's gait.

    At least 20 samples per actuation period (``design.controller.period``),
    and never coarser than ``default``: a coarser trace aliases against the
    gait and draws a wrong height curve.
    """
    period = getattr(getattr(design, "controller", None), "period", None)
    if period is None or not period > 0:
        return float(default)
    return float(min(default, period / 20.0))


def pyplot():
    """``matplotlib.pyplot`` on the headless Agg backend (unless one was chosen already)."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    return plt


def figure_path(path: str | os.PathLike[str]) -> Path:
    """``path`` if matplotlib writes its format (its suffix: .png, .pdf, .svg...).

    Raises
    ------
    InvalidParameterError
        Naming the file and the formats matplotlib writes.
    """
    path = Path(path)
    plt = pyplot()
    fig = plt.figure()
    try:
        formats = fig.canvas.get_supported_filetypes()
    finally:
        plt.close(fig)
    fmt = path.suffix.lstrip(".").lower()
    if fmt not in formats:
        raise InvalidParameterError(
            f"figure file {str(path)!r}: {'.' + fmt if fmt else 'no suffix'} is not a format "
            f"matplotlib writes ({', '.join(sorted(formats))})"
        )
    return path


def _save(fig: Any, path: str | os.PathLike[str]) -> Path:
    """Write ``fig`` to ``path`` (folders created) and close it."""
    path = figure_path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110, bbox_inches="tight", pad_inches=0.1)  # no clipped labels
    pyplot().close(fig)
    return path


def read_log(run_dir: str | os.PathLike[str]) -> list[dict[str, Any]]:
    """The per-generation rows of a run folder's ``log.jsonl`` ([] when it has none yet).

    Raises
    ------
    CheckpointError
        Naming the file and line, if a line is not a JSON object (the log is
        written atomically, so this is damage, not a run still writing).
    """
    from softgym.io import read_json_lines

    path = Path(run_dir) / "log.jsonl"
    if not (path.exists() or path.is_symlink()):
        return []
    return read_json_lines(path)


def plot_fitness_trend(
    rows: Sequence[Mapping[str, Any]],
    metric: str,
    path: str | os.PathLike[str],
    title: str | None = None,
    ylabel: str | None = None,
) -> Path:
    """Average, best, worst and median of ``metric`` per generation (report Fig. 1).

    Parameters
    ----------
    rows : sequence of dict
        Log rows with ``generation`` and ``{metric}_{best,median,mean,worst}``.
    metric : str
        Metric name, e.g. ``"norm_final_dist"`` (voxel lengths).
    path : path
        Output image.
    """
    plt = pyplot()
    gens = [r["generation"] for r in rows]
    fig, ax = plt.subplots(figsize=(6.4, 4.8))
    for stat, label in (
        ("mean", "average"),
        ("best", "best"),
        ("worst", "worst"),
        ("median", "median"),
    ):
        ax.plot(gens, [r[f"{metric}_{stat}"] for r in rows], label=label)
    ax.set_xlabel("generation")
    ax.set_ylabel(ylabel or metric_label(metric))
    if title:
        ax.set_title(title)
    ax.legend(loc="upper left")
    fig.tight_layout()
    return _save(fig, path)


def plot_best_fitness(
    curves: Mapping[str, Sequence[Mapping[str, Any]]],
    metric: str,
    path: str | os.PathLike[str],
    ylabel: str | None = None,
) -> Path:
    """Best ``metric`` per generation of several runs, one line each (report Fig. 4).

    Parameters
    ----------
    curves : mapping of label to log rows
    metric : str
    path : path
    """
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(6.4, 4.8))
    for label, rows in curves.items():
        ax.plot([r["generation"] for r in rows], [r[f"{metric}_best"] for r in rows], label=label)
    ax.set_xlabel("generation")
    ax.set_ylabel(ylabel or f"best {metric_label(metric)}")
    ax.legend(loc="upper left")
    fig.tight_layout()
    return _save(fig, path)


def plot_compare(
    groups: Mapping[str, Sequence[Sequence[Mapping[str, Any]]]],
    metric: str,
    path: str | os.PathLike[str],
    stat: str = "best",
    title: str | None = None,
) -> Path:
    """Runs grouped by configuration: median of ``metric`` per generation and the IQR band.

    Parameters
    ----------
    groups : mapping of label to list of log rows lists
        One entry per configuration, holding the logs of its runs (seeds).
        A group of one run is drawn as a plain line.
    metric : str
        Logged metric, e.g. ``"norm_final_dist"``.
    path : path
    stat : str
        Which per-generation statistic of each run: ``"best"`` (default),
        ``"median"``, ``"mean"`` or ``"worst"``.

    Notes
    -----
    Runs of a group may have different lengths: each generation's median and
    quartiles use the runs that reached it (the legend gives the count).
    """
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(7.0, 4.8))
    key = f"{metric}_{stat}"
    for i, (label, runs) in enumerate(groups.items()):
        color = f"C{i % 10}"
        n_gen = max((len(rows) for rows in runs), default=0)
        table = np.full((len(runs), n_gen), np.nan)
        for r, rows in enumerate(runs):
            for k, row in enumerate(rows):
                table[r, k] = float(row.get(key, np.nan))
        gens = np.arange(n_gen)
        have = np.isfinite(table).any(axis=0)
        if not have.any():
            continue
        med = np.full(n_gen, np.nan)
        q1 = np.full(n_gen, np.nan)
        q3 = np.full(n_gen, np.nan)
        med[have] = np.nanmedian(table[:, have], axis=0)
        q1[have], q3[have] = np.nanpercentile(table[:, have], [25, 75], axis=0)
        n = len(runs)
        ax.plot(gens, med, color=color, marker="o" if n_gen < 30 else None, ms=3,
                label=f"{label} (median of {n} runs)" if n > 1 else label)  # fmt: skip
        if n > 1:
            ax.fill_between(gens, q1, q3, color=color, alpha=0.25, lw=0)
    ax.set_xlabel("generation")
    ax.set_ylabel(f"{stat} {metric_label(metric)}")
    if title:
        ax.set_title(title)
    if any(len(r) > 1 for r in groups.values()):
        ax.text(0.99, 0.01, "bands: interquartile range over seeds", transform=ax.transAxes,
                ha="right", va="bottom", fontsize=7, color="0.3")  # fmt: skip
    ax.legend(loc="upper left", fontsize=8)
    fig.tight_layout()
    return _save(fig, path)


def _non_dominated(F: np.ndarray) -> np.ndarray:
    """Mask of the rows of ``F`` (minimised objectives) that no other row dominates."""
    n = len(F)
    keep = np.ones(n, dtype=bool)
    for i in range(n):
        dominated = np.all(F <= F[i], axis=1) & np.any(F < F[i], axis=1)
        keep[i] = not dominated.any()
    return keep


def plot_pareto_front(
    objectives: np.ndarray,
    names: Sequence[str],
    maximize: Sequence[bool],
    path: str | os.PathLike[str],
    title: str | None = None,
) -> Path:
    """A population in objective space, its non-dominated front highlighted.

    Parameters
    ----------
    objectives : ndarray of shape (n_individuals, n_objectives), float64
        Objective values as recorded (maximised ones not negated).
    names : sequence of str
        Objective names (axis labels with units from :func:`metric_label`).
    maximize : sequence of bool
        Direction of each objective.
    path : path

    With two objectives one panel; with more, one panel per pair.
    """
    plt = pyplot()
    F = np.asarray(objectives, dtype=np.float64)
    if F.ndim != 2 or F.shape[1] != len(names) or len(names) < 2:
        raise ValueError(f"need (n, >= 2) objectives matching names, got {F.shape} and {names}")
    ok = np.isfinite(F).all(axis=1)
    F = F[ok]
    sign = np.where(np.asarray(maximize, dtype=bool), -1.0, 1.0)
    front = _non_dominated(F * sign) if len(F) else np.zeros(0, dtype=bool)
    pairs = [(i, j) for i in range(len(names)) for j in range(i + 1, len(names))]
    fig, axes = plt.subplots(1, len(pairs), figsize=(4.6 * len(pairs), 4.2), squeeze=False)
    for ax, (i, j) in zip(axes[0], pairs):
        ax.scatter(F[~front, i], F[~front, j], s=18, color="0.6", label="dominated")
        pts = F[front][np.argsort(F[front, i])]
        ax.plot(pts[:, i], pts[:, j], "o-", color="C3", ms=5, lw=1, label="non-dominated")
        arrow = {True: " (max)", False: " (min)"}
        ax.set_xlabel(metric_label(names[i]) + arrow[bool(maximize[i])])
        ax.set_ylabel(metric_label(names[j]) + arrow[bool(maximize[j])])
        ax.legend(fontsize=7)
    fig.suptitle(title or f"final population: {int(front.sum())} non-dominated of {len(F)}")
    fig.tight_layout()
    return _save(fig, path)


def design_colors(design: Any) -> np.ndarray:
    """RGBA colour of every grid cell, ndarray of shape (nx, ny, nz, 4); empty cells transparent."""
    grid = np.asarray(design.grid)
    rgba = np.zeros((*grid.shape, 4))
    for mid in np.unique(grid):
        if mid == 0:
            continue
        rgba[grid == mid] = design.palette[int(mid)].color
    return rgba


def plot_robot(design: Any, path: str | os.PathLike[str], title: str | None = None) -> Path:
    """A design drawn with matplotlib's ``voxels``, coloured by material.

    Colours are the palette's (the seed's: soft tissue cyan, bone blue,
    muscles red / green, evolved materials brown / dark red / yellow / orange).
    """
    plt = pyplot()
    grid = np.asarray(design.grid)
    colors = design_colors(design)
    fig = plt.figure(figsize=(5, 5))
    ax = fig.add_subplot(projection="3d")
    ax.voxels(grid > 0, facecolors=colors, edgecolor=(0, 0, 0, 0.4), linewidth=0.3)
    n = max(grid.shape)
    ax.set(xlim=(0, n), ylim=(0, n), zlim=(0, n), xlabel="x", ylabel="y", zlabel="z")
    ax.set_box_aspect((1, 1, 1))
    names = {}
    for mid in np.unique(grid):
        if mid:
            names[int(mid)] = design.palette[int(mid)]
    from matplotlib.patches import Patch

    ax.legend(
        handles=[Patch(color=m.color, label=f"{k}: {m.name} ({int((grid == k).sum())})") for k, m in names.items()],
        loc="upper left", fontsize=7,
    )  # fmt: skip
    if title:
        ax.set_title(title)
    fig.tight_layout()
    return _save(fig, path)


def plot_trajectory(
    trace: np.ndarray,
    path: str | os.PathLike[str],
    voxel_size: float = 0.01,
    init_time: float = 1.0,
    title: str | None = None,
    terrain: Any = None,
) -> Path:
    """Centre-of-mass trajectory: top view (voxel lengths) and height over time.

    Parameters
    ----------
    trace : ndarray of shape (n_points, 4), float64
        Rows (x, y, z, t) in m and s (``Rollout.trace``).
    path : path
    voxel_size : float
        L (m): positions are drawn in voxel lengths.
    init_time : float
        Settling time (s), marked on the height plot.
    terrain : Terrain, optional
        Boxes drawn (outlined) in the top view.

    Raises
    ------
    InvalidParameterError
        If ``trace`` holds no (x, y, z, t) row (a run no longer than its settling time).
    """
    L = float(voxel_size)
    tr = np.asarray(trace, dtype=np.float64)
    if tr.ndim != 2 or tr.shape[0] == 0 or tr.shape[1] < 4:
        raise InvalidParameterError(
            f"trace must be an array of (x, y, z, t) rows with at least one row, got shape "
            f"{tr.shape} (a run no longer than its {init_time:g} s settling time samples none)"
        )
    plt = pyplot()
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4))
    if terrain is not None:
        from matplotlib.patches import Rectangle

        for b in terrain.boxes:
            ax1.add_patch(
                Rectangle(b.lo[:2], b.hi[0] - b.lo[0], b.hi[1] - b.lo[1], color="orange", alpha=0.5)
            )
    ax1.plot(tr[:, 0] / L, tr[:, 1] / L, "-", lw=1.5)
    ax1.plot(tr[0, 0] / L, tr[0, 1] / L, "gs", label="start")
    ax1.plot(tr[-1, 0] / L, tr[-1, 1] / L, "r^", label="end")
    pts = tr[:, :2] / L
    if terrain is not None and terrain.boxes:
        corners = np.array([b.lo[:2] for b in terrain.boxes] + [b.hi[:2] for b in terrain.boxes])
        pts = np.vstack([pts, corners])
    centre = (pts.min(axis=0) + pts.max(axis=0)) / 2.0
    half = max(float((pts.max(axis=0) - pts.min(axis=0)).max()) / 2.0, 3.0) + 1.0
    ax1.set_xlim(centre[0] - half, centre[0] + half)
    ax1.set_ylim(centre[1] - half, centre[1] + half)
    ax1.set(
        xlabel="x (voxels)", ylabel="y (voxels)", title="centre of mass, top view", aspect="equal"
    )
    ax1.legend()
    ax2.plot(tr[:, 3], tr[:, 2] / L)
    ax2.axvline(init_time, color="k", ls=":", label="init time")
    ax2.set(xlabel="t (s)", ylabel="z (voxels)", title="centre-of-mass height")
    ax2.legend()
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    return _save(fig, path)


def save_robot_gif(
    design: Any,
    path: str | os.PathLike[str],
    terrain: Any = None,
    seconds: float = 5.0,
    fps: float = 10.0,
    config: Any = None,
) -> Path:
    """Simulate ``design`` and write a GIF (or an MP4 for a ``.mp4`` path) of it moving.

    Frames come from :func:`softgym.render.frames.simulation_frames` (a NumPy
    software renderer; simulated time and distance overlaid), written by
    :func:`softgym.render.frames.save_gif`, or :func:`~softgym.render.frames.save_video`
    (the ``video`` extra) for ``.mp4``.

    Parameters
    ----------
    design : RobotDesign
    path : path
    terrain : Terrain, optional
        Default: flat ground.
    seconds : float
        Simulated time (s).
    fps : float
        Frames per simulated second (and GIF frame rate).
    config : SimConfig, optional
    """
    from softgym.engine import Simulation
    from softgym.render.frames import save_gif, save_video, simulation_frames

    sim = Simulation([design], config=config, terrain=terrain)
    gi = sim.grid_index(0)
    grid = np.asarray(design.grid)
    mids = grid[gi[:, 0], gi[:, 1], gi[:, 2]]
    colors = np.array([design.palette[int(m)].color[:3] for m in mids])
    frames = simulation_frames(sim, seconds, fps=fps, colors=colors)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    if path.suffix.lower() == ".mp4":
        save_video(frames, path, fps=fps)
    else:
        save_gif(frames, path, fps=fps)
    return path


def run_figures(
    run_dir: str | os.PathLike[str], gif: bool = True, seconds: float | None = None
) -> dict[str, Path]:
    """Write the figures of a run folder into ``run_dir/figures``.

    Re-simulates the best design (``best_design.json``) in the run's task to
    draw its trajectory and GIF.

    Returns
    -------
    dict of str to Path
        ``fitness_trend``, ``pareto_front`` (runs with two objectives or
        more), ``best_robot``, ``best_trajectory`` (sampled at least 20 times
        per gait period, :func:`trace_interval_for`) and ``best_gif``.
    """
    from softgym.design import RobotDesign
    from softgym.engine import Simulation
    from softgym.io import read_json
    from softgym.tasks import get_task

    run_dir = Path(run_dir)
    fig_dir = run_dir / "figures"
    cfg = read_json(run_dir / "config.json")
    exp = cfg["experiment"]
    first = exp["objectives"][0]["name"]
    metric = first if first != "age" else "norm_final_dist"
    out: dict[str, Path] = {}
    rows = read_log(run_dir)
    if rows:
        out["fitness_trend"] = plot_fitness_trend(
            rows, metric, fig_dir / "fitness_trend.png",
            title=f"{exp['name']}: {metric}",
        )  # fmt: skip
    objectives = exp["objectives"]
    final = run_dir / "final_population.json"
    if len(objectives) >= 2 and final.is_file():
        final_doc = read_json(final)
        pop = final_doc["population"]
        names = [o["name"] for o in objectives]
        F = np.array(
            [[d["age"] if n == "age" else d["objectives"].get(n, np.nan) for n in names]
             for d in pop if d.get("objectives")],
            dtype=np.float64,
        ).reshape(-1, len(names))  # fmt: skip
        out["pareto_front"] = plot_pareto_front(
            F, names, [bool(o["maximize"]) for o in objectives], fig_dir / "pareto_front.png",
            title=f"{exp['name']}: final population, generation {final_doc['generation']}",
        )  # fmt: skip
    design = RobotDesign.load(run_dir / "best_design.json")
    out["best_robot"] = plot_robot(
        design, fig_dir / "best_robot.png", title=f"best robot ({exp['name']})"
    )
    secs = float(exp["seconds"] if seconds is None else seconds)
    world = exp.get("task", exp.get("terrain", "flat"))  # "terrain": run folders before tasks
    task = get_task(
        world, seconds=secs, trace_interval=trace_interval_for(design), sim=exp.get("sim", {})
    )
    terrain = task.terrain_for(design.shape)
    rollout = Simulation([design], config=task.config(), terrain=terrain).run(secs)
    out["best_trajectory"] = plot_trajectory(
        rollout.trace(0), fig_dir / "best_trajectory.png", rollout.voxel_size, rollout.init_time,
        title=f"best robot's centre of mass ({exp['name']})", terrain=terrain,
    )  # fmt: skip
    if gif:
        out["best_gif"] = save_robot_gif(
            design, fig_dir / "best_robot.gif", terrain, secs, config=task.config()
        )
    return out
