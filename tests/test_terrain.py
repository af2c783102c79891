"""Terrain builders, validation and JSON."""

import json

import numpy as np
import pytest

from softgym.engine import Body, Simulation
from softgym.exceptions import InvalidTerrainError
from softgym.terrain import Box, Terrain


def _union_mask(terrain, size=40, offset=-15):
    # occupancy of integer cells (voxel lengths) by the terrain's boxes
    occ = np.zeros((size, size), dtype=int)
    for b in terrain.boxes:
        for x in range(size):
            for y in range(size):
                cx, cy = x + offset + 0.5, y + offset + 0.5
                if b.lo[0] < cx < b.hi[0] and b.lo[1] < cy < b.hi[1]:
                    occ[x, y] += 1
    return occ


def test_fence_is_the_seeds_geometry():
    # 10x10 interior around a 6x6 robot at the origin: a 2-voxel gap on every
    # side, 1-voxel walls, 44 wall cells (the seed's 44 wall voxels), no overlaps.
    fence = Terrain.fence()
    occ = _union_mask(fence)
    assert occ.max() == 1
    assert occ.sum() == 44
    assert all(b.hi[2] == 1 and b.lo[2] == 0 for b in fence.boxes)
    xs = [b.lo[0] for b in fence.boxes] + [b.hi[0] for b in fence.boxes]
    assert min(xs) == -3 and max(xs) == 9  # walls at cells -3 and 8: gap 2 to the robot's [0, 6)


def test_stairs_rise_one_step_per_ring_and_seed_variant_is_flat():
    stairs = Terrain.stairs(n_rings=3, step_height=1, ring_width=2)
    heights = sorted({b.hi[2] for b in stairs.boxes})
    assert heights == [1, 2, 3]
    assert _union_mask(stairs, size=60, offset=-25).max() == 1
    seed = Terrain.stairs(n_rings=3, equal_heights=True)
    assert {b.hi[2] for b in seed.boxes} == {1}


@pytest.mark.parametrize(
    "make",
    [
        lambda: Box((0, 0, 0), (1, 0, 1)),
        lambda: Box((0, 0, 0), (1, -1, 1)),
        lambda: Box((0, 0, float("nan")), (1, 1, 1)),
        lambda: Terrain.fence(inner=0),
        lambda: Terrain.stairs(n_rings=0),
        lambda: Terrain.stairs(step_height=-1),
    ],
)
def test_invalid_terrains_raise(make):
    with pytest.raises(InvalidTerrainError):
        make()


def test_terrain_overlapping_the_robot_start_is_rejected():
    bad = Terrain.from_boxes([Box((1, 1, 0), (2, 2, 1))])
    with pytest.raises(InvalidTerrainError, match="overlaps the robot"):
        Simulation(Body.uniform(np.ones((3, 3, 3))), terrain=bad)
    with pytest.raises(InvalidTerrainError, match="one per robot"):
        Simulation([Body.uniform(np.ones((2, 2, 2)))] * 2, terrain=[Terrain.flat()])


def test_json_round_trip_and_version_errors():
    for t in (Terrain.flat(), Terrain.fence(height=2), Terrain.stairs(n_rings=2)):
        back = Terrain.from_json(t.to_json())
        assert back.boxes == t.boxes and back.floor == t.floor and back.name == t.name
    data = json.loads(Terrain.fence().to_json())
    data["version"] = 99
    with pytest.raises(InvalidTerrainError, match="version 99"):
        Terrain.from_dict(data)
    with pytest.raises(InvalidTerrainError):
        Terrain.from_json("{not json")
    with pytest.raises(InvalidTerrainError):
        Terrain.from_dict({"schema": "softgym.terrain", "version": 1, "boxes": [{"lo": [0, 0]}]})
