"""Matplotlib figures of evolutionary runs and robots.

* :func:`plot_fitness_trend`: average / best / worst / median of an objective
  per generation (the report's Fig. 1).
* :func:`plot_best_fitness`: best fitness per generation of several runs
  (the report's Fig. 4).
* :func:`plot_robot`: a design as matplotlib voxels coloured by material.
* :func:`plot_trajectory`: a centre-of-mass trace, top view and height.
* :func:`save_robot_gif`: a GIF of a design moving (frames from
  :mod:`softgym.render.frames`).
* :func:`run_figures`: all of the above for a run folder.

Every function writes a file and returns its path; matplotlib runs headless (Agg).
"""

from __future__ import annotations

import json
import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

__all__ = [
    "design_colors",
    "plot_best_fitness",
    "plot_fitness_trend",
    "plot_robot",
    "plot_trajectory",
    "read_log",
    "run_figures",
    "save_robot_gif",
]


def _plt():
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    return plt


def _save(fig: Any, path: str | os.PathLike[str]) -> Path:
    """Write ``fig`` to ``path`` (folders created) and close it."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    _plt().close(fig)
    return path


def read_log(run_dir: str | os.PathLike[str]) -> list[dict[str, Any]]:
    """The per-generation rows of a run folder's ``log.jsonl``."""
    path = Path(run_dir) / "log.jsonl"
    return [json.loads(line) for line in path.read_text().splitlines() if line.strip()]


def plot_fitness_trend(
    rows: Sequence[Mapping[str, Any]],
    metric: str,
    path: str | os.PathLike[str],
    title: str | None = None,
    ylabel: str = "Fitness",
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
    plt = _plt()
    gens = [r["generation"] for r in rows]
    fig, ax = plt.subplots(figsize=(6.4, 4.8))
    for stat, label in (
        ("mean", "average"),
        ("best", "best"),
        ("worst", "worst"),
        ("median", "median"),
    ):
        ax.plot(gens, [r[f"{metric}_{stat}"] for r in rows], label=label)
    ax.set_xlabel("Generations")
    ax.set_ylabel(ylabel)
    if title:
        ax.set_title(title)
    ax.legend(loc="upper left")
    fig.tight_layout()
    return _save(fig, path)


def plot_best_fitness(
    curves: Mapping[str, Sequence[Mapping[str, Any]]],
    metric: str,
    path: str | os.PathLike[str],
    ylabel: str = "Best fitness",
) -> Path:
    """Best ``metric`` per generation of several runs, one line each (report Fig. 4).

    Parameters
    ----------
    curves : mapping of label to log rows
    metric : str
    path : path
    """
    plt = _plt()
    fig, ax = plt.subplots(figsize=(6.4, 4.8))
    for label, rows in curves.items():
        ax.plot([r["generation"] for r in rows], [r[f"{metric}_best"] for r in rows], label=label)
    ax.set_xlabel("Generation")
    ax.set_ylabel(ylabel)
    ax.legend(loc="upper left")
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
    plt = _plt()
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
    """
    plt = _plt()
    L = float(voxel_size)
    tr = np.asarray(trace, dtype=np.float64)
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
    """Simulate ``design`` and write a GIF of it moving.

    Frames come from :func:`softgym.render.frames.simulation_frames` (a NumPy
    software renderer), written by :func:`softgym.render.frames.save_gif`.

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
    from softgym.render.frames import save_gif, simulation_frames

    sim = Simulation([design], config=config, terrain=terrain)
    gi = sim.grid_index(0)
    grid = np.asarray(design.grid)
    mids = grid[gi[:, 0], gi[:, 1], gi[:, 2]]
    colors = np.array([design.palette[int(m)].color[:3] for m in mids])
    frames = simulation_frames(sim, seconds, fps=fps, colors=colors)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
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
        ``fitness_trend``, ``best_robot``, ``best_trajectory`` and ``best_gif``.
    """
    from softgym.design import RobotDesign
    from softgym.engine import Simulation
    from softgym.tasks import get_task

    run_dir = Path(run_dir)
    fig_dir = run_dir / "figures"
    cfg = json.loads((run_dir / "config.json").read_text())
    exp = cfg["experiment"]
    first = exp["objectives"][0]["name"]
    metric = first if first != "age" else "norm_final_dist"
    out: dict[str, Path] = {}
    rows = read_log(run_dir)
    if rows:
        out["fitness_trend"] = plot_fitness_trend(
            rows, metric, fig_dir / "fitness_trend.png",
            title=f"{exp['name']}: {metric} (voxel lengths)",
        )  # fmt: skip
    design = RobotDesign.load(run_dir / "best_design.json")
    out["best_robot"] = plot_robot(
        design, fig_dir / "best_robot.png", title=f"best robot ({exp['name']})"
    )
    secs = float(exp["seconds"] if seconds is None else seconds)
    world = exp.get("task", exp.get("terrain", "flat"))  # "terrain": run folders before tasks
    task = get_task(world, seconds=secs, trace_interval=0.05, sim=exp.get("sim", {}))
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
