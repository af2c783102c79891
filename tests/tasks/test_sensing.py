"""The sensors: layout per task, touch, orientation, the task's senses; alone or batched, the same."""

import numpy as np
import pytest

from softgym.design import RobotDesign, default_walker
from softgym.engine import SimConfig
from softgym.tasks import KINDS, EpisodeBatch, get_task
from softgym.tasks.sensing import CELL_SENSORS, ROBOT_SENSORS, SENSES, sensing_layout


def _batch(designs, task, grid=(6, 6, 6)):
    t = get_task(task)
    cfg = t.config(trace_interval=1e9)
    b = EpisodeBatch(designs, t, grid, 0.05, 1.0, None, cfg, n_threads=1, observe="sensing")
    b.reset_all()
    return b


def test_every_kind_declares_its_senses_and_the_layout_counts_them():
    assert SENSES["terrain"] in KINDS["gap"].senses and SENSES["terrain"] in KINDS["stairs"].senses
    assert KINDS["push"].senses == (SENSES["object"], SENSES["target"])
    assert KINDS["carry"].senses == (SENSES["object"],)
    assert KINDS["turn"].senses == (SENSES["heading"],) and KINDS["flat"].senses == ()
    for name in KINDS:
        lay = sensing_layout(get_task(name), (6, 6, 6))
        assert lay.size == 8 * 216 + 11 + lay.n_task == len(lay.labels()) == lay.bounds().size
        assert len(lay.table()) == len(CELL_SENSORS) + len(ROBOT_SENSORS) + len(lay.task_senses)


def test_settled_walker_feels_the_floor_below_and_stands_upright():
    b = _batch([default_walker()], "flat")
    cells, robot, task = b.sensing.read(b.clock(), b.period)
    grid = cells.reshape(6, 6, 6, 8)
    assert np.all(grid[:, :, 0, 6] == 1.0)  # the bottom layer touches the floor
    assert np.all(grid[:, :, 2:, 6] == 0.0)
    np.testing.assert_allclose(robot[0, 3:6], [0, 0, 1], atol=0.02)  # up
    np.testing.assert_allclose(robot[0, 6:9], [1, 0, 0], atol=0.02)  # forward
    assert task.shape == (1, 0)
    assert np.abs(grid[..., 7]).max() < 0.2  # bonds near their rest length
    obs = b.observations()
    assert obs.shape == (1, sensing_layout(get_task("flat"), (6, 6, 6)).size) and obs.dtype == np.float32


def test_gap_push_turn_and_incline_senses():
    gap = _batch([default_walker()], "gap")
    _, _, t = gap.sensing.read(gap.clock(), gap.period)
    ahead4 = t[0, :8]  # 4 voxel lengths out, 8 directions from forward (+x)
    assert ahead4[0] == -4.0 and ahead4[2] == -4.0 and ahead4[1] == 0.0  # the pit on the axes
    push = _batch([default_walker()], "push")
    _, _, t = push.sensing.read(push.clock(), push.period)
    assert t[0, 0] < -3.0 and abs(t[0, 1]) < 0.1  # the box lies -x of the robot
    assert t[0, 6] == pytest.approx(-10.0, abs=1e-6)  # the target 10 further along -x
    turn = _batch([default_walker()], "turn")
    _, _, t = turn.sensing.read(turn.clock(), turn.period)
    np.testing.assert_allclose(t[0], [0.0, 1.0], atol=1e-6)  # nothing turned yet
    inc = _batch([default_walker()], "incline:angle=20")
    _, _, t = inc.sensing.read(inc.clock(), inc.period)
    # gravity's pull along -x (the soft body shears under it: a few degrees more than the slope)
    np.testing.assert_allclose(t[0], [-np.sin(np.radians(20)), 0, -np.cos(np.radians(20))], atol=0.2)
    assert t[0, 0] < -0.3 and np.linalg.norm(t[0]) == pytest.approx(1.0)


def test_the_goal_sense_points_from_the_robot_to_its_goal():
    assert KINDS["goal"].senses == (SENSES["goal"],)
    b = _batch([default_walker()], "goal:distance=10,angle=90")  # the goal 10 along -y
    _, _, t = b.sensing.read(b.clock(), b.period)
    cm = b.sim.center_of_mass()[0] / b.L
    np.testing.assert_allclose(t[0], [3.0 - cm[0], -7.0 - cm[1]], atol=1e-9)
    assert abs(t[0, 0]) < 0.1 and t[0, 1] == pytest.approx(-10.0, abs=0.1)
    for k in range(20):  # its sinusoid (5 steps a period): the walker shuffles towards -x
        b.apply(np.full((1, b.n_cells), np.sin(2 * np.pi * k / 5 + 0.5)))
        b.advance()
    _, _, later = b.sensing.read(b.clock(), b.period)
    moved = b.sim.center_of_mass()[0] / b.L
    assert moved[0] < cm[0] - 0.2
    np.testing.assert_allclose(later[0], [3.0 - moved[0], -7.0 - moved[1]], atol=1e-9)


def test_a_robot_senses_the_same_alone_and_in_a_batch_of_other_bodies():
    small = RobotDesign(np.full((3, 4, 2), 3, dtype=np.int8))
    alone = _batch([default_walker()], "push")
    mixed = _batch([small, default_walker(), small], "push")
    for b in (alone, mixed):
        b.apply(np.ones((b.n_robots, b.n_cells)) * -0.5)
        b.advance()
    np.testing.assert_array_equal(alone.observations()[0], mixed.observations()[1])


def test_a_custom_terrain_senses_its_boxes_and_objects():
    from softgym.tasks import Task
    from softgym.terrain import Terrain

    t = Task(terrain=Terrain.stairs())
    assert t.senses == (SENSES["terrain"],)
    assert Task(terrain=Terrain.flat()).senses == ()


def test_the_blind_observation_is_unchanged():
    t = get_task("push")
    b = EpisodeBatch([default_walker()], t, (6, 6, 6), 0.05, 1.0, None, SimConfig(), n_threads=1)
    b.reset_all()
    assert b.observations().shape == (1, 6 * 216 + 5)
