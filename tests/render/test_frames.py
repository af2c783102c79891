"""softgym.render.frames: a robot drawn in its task's world."""

import numpy as np


def test_a_robot_in_a_world_below_the_floor_is_drawn_with_its_objects_and_target():
    # render_in_world (the task gallery's and the leaderboard's frames): a world that goes
    # below z = 0 (gap's pit) is lifted above the renderer's floor; push's box is drawn
    # and its target marked; the frame changes with the world
    from softgym.design import default_walker
    from softgym.engine import Simulation
    from softgym.render import VoxelRenderer, render_in_world
    from softgym.tasks import get_task

    design = default_walker()
    frames = {}
    for name in ("flat", "gap", "push"):
        task = get_task(name)
        terrain = task.terrain_for(design.shape)
        sim = Simulation([design], config=task.config(), terrain=terrain, n_threads=1)
        sim.advance(0.05)
        frames[name] = render_in_world(sim, design, terrain, VoxelRenderer(width=96, height=72))
        assert frames[name].shape == (72, 96, 3) and frames[name].dtype == np.uint8
    assert not np.array_equal(frames["flat"], frames["gap"])
    assert not np.array_equal(frames["flat"], frames["push"])
    from softgym.render import OBJECT_COLOR

    rgb = (np.array(OBJECT_COLOR) * 255).astype(int)
    near = np.all(np.abs(frames["push"].astype(int) - rgb) < 60, axis=-1)
    assert near.sum() > np.all(np.abs(frames["flat"].astype(int) - rgb) < 60, axis=-1).sum()
