"""A fake terrain evaluation for the POET tests: the search logic is the point, not the physics.

A robot's "strength" grows with its share of muscle voxels and its controller's
amplitude (both of which softgym's operators vary gradually); a terrain's
"difficulty" grows with its obstacles. The score is ``strength - difficulty`` (voxel
lengths) when positive, else 2 (a trapped robot wiggling in the start area).
"""

import numpy as np

from softgym.design import RobotDesign

_COUNTS = ("n_voxels", "n_muscle", "n_old_materials", "n_bone", "n_tissue")


def difficulty(genome: dict) -> float:
    g = genome
    return (
        8.0 * g["fence_height"]
        + 6.0 * g["stair_count"] * g["stair_height"]
        + 3.0 * g["gap_width"] * (g["stair_count"] > 0)
        + 5.0 * g["rough_amplitude"]
    )


def strength(design: RobotDesign) -> float:
    grid = design.grid
    filled = max(1, int((grid > 0).sum()))
    muscle = float(np.isin(grid, (3, 4)).sum()) / filled
    return 4.0 + 10.0 * muscle + 0.3 * design.controller.temp_amplitude


def fake_batch_fn(designs, task):
    n = len(designs)
    out = {
        k: np.zeros(n)
        for k in ("norm_final_dist", "max_xy_dist", "l_coefficient", "time_max_xy_dist")
    }
    out["diverged"] = np.zeros(n, dtype=bool)
    out.update({k: np.zeros(n, dtype=np.int64) for k in _COUNTS})
    out["traces"] = [None] * n
    terrain = task.terrain
    genome = terrain.meta.get("genome") if hasattr(terrain, "meta") else None
    d = 0.0 if genome is None else difficulty(genome)
    for i, dd in enumerate(designs):
        assert isinstance(dd, RobotDesign)  # designs stay objects within one process
        s = strength(dd)
        v = s - d if s - d > 2.0 else 2.0
        out["max_xy_dist"][i] = v
        out["norm_final_dist"][i] = v
    return out
