"""Render one frame per task of the suite into a grid image (docs/figures/task_gallery.png).

Each task's world around the default walker after ``--seconds`` (1 s: the end of
settling; later, the walker's own controller, the seed's sinusoid) in that task's
engine settings, the tasks grouped by family (``softgym.tasks.FAMILIES``); movable
objects are drawn in grey, worlds below z = 0 lifted over the renderer's floor, a
task's target point (push, goal) marked by a flat tile that is not part of its world,
and the chimney seen along its walls.

    python scripts/task_gallery.py                     # docs/figures/task_gallery.png
    python scripts/task_gallery.py --out gallery.png --seconds 2
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from softgym.design import default_walker
from softgym.engine import Simulation
from softgym.render import VoxelRenderer, render_in_world
from softgym.tasks import FAMILIES, KINDS, get_task, tasks_of_family

#: Camera angles other than the renderer's default, by task: walls that would hide the robot.
VIEWS = {"chimney": {"azimuth": 0.0, "elevation": 50.0}}


def frame(name: str, seconds: float, renderer: VoxelRenderer) -> np.ndarray:
    """The default walker in task ``name`` after ``seconds``, as an RGB frame."""
    design = default_walker()
    task = get_task(name)
    terrain = task.terrain_for(design.shape)
    sim = Simulation([design], config=task.config(), terrain=terrain, n_threads=1)
    sim.advance(seconds)
    return render_in_world(sim, design, terrain, renderer)


def main() -> None:
    """Render the gallery (command line)."""
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--out", default=str(Path(__file__).resolve().parents[1] / "docs" / "figures"
                                        / "task_gallery.png"))  # fmt: skip
    p.add_argument("--seconds", type=float, default=1.0)
    p.add_argument("--columns", type=int, default=6)
    args = p.parse_args()
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = [n for f in FAMILIES for n in tasks_of_family(f)]
    cols = args.columns
    rows = -(-len(names) // cols)
    fig, axes = plt.subplots(rows, cols, figsize=(3.2 * cols, 2.6 * rows))
    for ax in np.ravel(axes):
        ax.axis("off")
    for ax, name in zip(np.ravel(axes), names):
        renderer = VoxelRenderer(320, 240, pixels_per_voxel=9.0, **VIEWS.get(name, {}))
        ax.imshow(frame(name, args.seconds, renderer))
        ax.set_title(f"{name} ({KINDS[name].family})\n{get_task(name).reward}", fontsize=9)
    fig.tight_layout()
    fig.savefig(args.out, dpi=100)
    print(args.out)


if __name__ == "__main__":
    main()
