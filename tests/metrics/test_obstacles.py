"""softgym.metrics.obstacles: the obstacles' footprint and whether a robot ended past it."""

import math

import numpy as np

from softgym.metrics import crossed_obstacles, final_xy, obstacle_footprint
from softgym.tasks import get_task
from softgym.terrain import Terrain


def test_footprint_of_the_wall_and_of_flat_ground():
    terrain = get_task("wall").terrain_for((6, 6, 6))
    x0, x1, y0, y1 = obstacle_footprint(terrain)
    assert x0 < 0 < 6 < x1 and y0 < 0 < 6 < y1  # a ring around the robot's grid
    assert not crossed_obstacles((3.0, 3.0), (x0, x1, y0, y1))
    assert crossed_obstacles((x1 + 0.1, 3.0), (x0, x1, y0, y1))
    assert obstacle_footprint(Terrain()) is None


def test_final_xy_in_voxel_lengths():
    trace = np.array([[0.0, 0.0, 0.0, 0.0], [0.02, -0.01, 0.0, 1.0]])
    assert final_xy(trace, 0.01) == (2.0, -1.0)
    assert all(math.isnan(v) for v in final_xy(None, 0.01))
