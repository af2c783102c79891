"""The suite's families and its second half: every task declared fully, built as documented, run.

Each task added with the families is run with the default walker, a passive block (it
never moves) and a pumping block (every voxel a strong muscle, in phase) for 3 s: the
walker's score is finite, the three scores are not all the same, and the passive block
is not thrown about by its world (nothing starts inside it). The env and
``softgym.evaluate`` agree on each new measure.
"""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import softgym
from softgym.design import RobotDesign, default_walker
from softgym.envs import env_id
from softgym.exceptions import InvalidParameterError
from softgym.tasks import FAMILIES, KINDS, REWARDS, TaskKind, flat_layout, get_task, tasks_of_family

SHAPE = (6, 6, 6)
#: The tasks added with the families (the first 16 are checked in test_suite.py).
NEW = ("downhill", "moon", "goal", "hurdles", "course", "mattress", "chimney", "ledge", "beam",
       "balance", "stones", "push_uphill", "throw", "catch", "lift", "shrink", "squeeze")  # fmt: skip


def _still() -> RobotDesign:
    return RobotDesign(np.ones(SHAPE, dtype=np.int8))  # Passive_Soft: no muscle


def _pump() -> RobotDesign:
    return RobotDesign(np.full(SHAPE, 8, dtype=np.int8))  # New_Active_+: all in phase


def test_at_least_32_tasks_in_at_least_six_families():
    assert len(KINDS) >= 32 and len(FAMILIES) >= 6 and set(NEW) <= set(KINDS)
    members = [tasks_of_family(f) for f in FAMILIES]
    assert sorted(n for m in members for n in m) == sorted(KINDS)  # each task in one family
    assert all(len(m) >= 2 for m in members)
    assert {KINDS[n].family for n in ("flat", "wall", "stairs", "beam", "push", "grow")} == set(
        FAMILIES
    )


def test_a_kind_needs_a_known_family():
    with pytest.raises(InvalidParameterError, match=r"family must be one of .*'dance'"):
        TaskKind("x", "a task", flat_layout, "x_progress", family="dance")
    with pytest.raises(InvalidParameterError, match="family must be one of"):
        TaskKind("x", "a task", flat_layout, "x_progress")
    with pytest.raises(InvalidParameterError, match="family must be one of"):
        tasks_of_family("dance")


@pytest.mark.parametrize("name", NEW)
def test_a_new_task_is_declared_fully(name):
    kind = KINDS[name]
    assert kind.summary and kind.reward in REWARDS and kind.options
    for arg, opt in kind.options.items():
        assert opt.lo <= opt.default <= opt.hi and opt.lo < opt.hi and opt.doc
        assert opt.check(name, arg, opt.default) == opt.default
        with pytest.raises(InvalidParameterError, match=rf"{arg} must be"):
            get_task(f"{name}:{arg}={opt.hi + 1}")
        # the hardest setting of each argument changes the world, its meta or the engine settings
        hard = get_task(f"{name}:{arg}={opt.hi!r}")
        world, hard_world = get_task(name).terrain_for(SHAPE), hard.terrain_for(SHAPE)
        assert (world, world.meta, get_task(name).engine_settings) != (
            hard_world,
            hard_world.meta,
            hard.engine_settings,
        ), arg
    # what the robot must perceive is declared: the object, the goal, the terrain
    senses = {s.name for s in kind.senses}
    world = get_task(name).terrain_for(SHAPE)
    if world.objects and name != "mattress":  # (the mattress is ground, felt through touch)
        assert "object" in senses
    if "target" in world.meta:
        assert senses & {"target", "goal"}
    if world.boxes:
        assert "terrain" in senses


@pytest.mark.parametrize("name", NEW)
def test_a_new_task_scores_the_walker_and_tells_designs_apart(name):
    m = softgym.evaluate([default_walker(), _still(), _pump()], task=name, seconds=3.0, traces=True)
    score = m["score"]
    assert not m["diverged"].any() and np.isfinite(score).all()
    assert score.max() - score.min() > 0.1, score  # not a constant
    # the passive block settles where it was put: nothing launched it or started inside it
    start = m["traces"][1][0, :3] / 0.01
    assert np.abs(start[:2] - 3.0).max() < 0.1 and 1.0 < start[2] < 3.2
    assert m["max_xy_dist"][1] < 0.1


@pytest.mark.parametrize("name", ["goal", "balance", "beam", "throw", "catch", "lift", "chimney",
                                  "shrink"])  # fmt: skip
def test_the_controller_env_and_evaluate_agree_on_a_new_measure(name):
    m = softgym.evaluate([default_walker()], task=name, seconds=3.0)
    env = gym.make(env_id(name), drive="controller", control_dt=0.1, episode_seconds=2.0,
                   max_episode_steps=20)  # fmt: skip
    env.reset(seed=0)
    ret = 0.0
    for _ in range(20):
        _, r, _, _, info = env.step(env.action_space.sample())
        ret += r
    env.close()
    assert info["score"] == pytest.approx(m["score"][0], rel=1e-9, abs=1e-12)
    assert ret == pytest.approx(info["score"], abs=1e-9)


def test_the_worlds_are_built_as_documented():
    # chimney: two walls `gap` from the grid's y sides, open along x
    lo, hi = get_task("chimney:gap=0.5").terrain_for(SHAPE).boxes
    assert lo.hi[1] == -0.5 and hi.lo[1] == 6.5 and lo.lo[0] < 0 < 6 < lo.hi[0]
    # ledge: a platform `height` high, `gap` from the -x side
    (ledge,) = get_task("ledge:height=2,gap=1.5").terrain_for(SHAPE).boxes
    assert ledge.hi[0] == -1.5 and ledge.hi[2] == 2.0
    # beam, balance, stones: no floor, a top at z = 0 under the grid's centre, ground far below
    for name in ("beam", "balance", "stones"):
        t = get_task(name).terrain_for(SHAPE)
        assert not t.floor and min(b.lo[2] for b in t.boxes) <= -20
        under = [
            b
            for b in t.boxes
            if b.lo[0] <= 3 <= b.hi[0] and b.lo[1] <= 3 <= b.hi[1] and b.hi[2] == 0
        ]
        assert len(under) == 1
    beam = get_task("beam:width=2").terrain_for(SHAPE).boxes[0]
    assert (beam.lo[1], beam.hi[1]) == (2.0, 4.0)
    # hurdles: `count` rings of 4 bars, each ring `spacing` farther out
    h = get_task("hurdles:count=5,spacing=3,height=0.25").terrain_for(SHAPE)
    assert len(h.boxes) == 20 and {b.hi[2] for b in h.boxes} == {0.25}
    assert sorted({b.lo[0] for b in h.boxes})[:2] == [3 - 5 - 4 * 3 - 1, 3 - 5 - 3 * 3 - 1]
    # squeeze: a slit `slit` wide in each side of a wall higher than the robot
    sq = get_task("squeeze:slit=2").terrain_for(SHAPE)
    assert len(sq.boxes) == 8 and min(b.hi[2] for b in sq.boxes) > 6
    south = sorted((b for b in sq.boxes if b.hi[1] <= -2), key=lambda b: b.lo[0])
    assert south[1].lo[0] - south[0].hi[0] == 2.0
    # the objects rest at the self-contact distance (1.5 voxels between centres) or above it
    (cube,) = get_task("throw").terrain_for(SHAPE).objects
    assert cube.origin[2] == 6.5 and cube.center[:2].tolist() == [3.0, 3.0]
    (plate,) = get_task("lift").terrain_for(SHAPE).objects
    assert plate.shape == (6, 6, 1) and plate.origin[2] == 6.5
    (feather,) = get_task("catch:height=10,offset=2").terrain_for(SHAPE).objects
    assert feather.center.tolist() == [1.0, 3.0, 17.0] and feather.density < 1e6
    assert get_task("catch").config().fluid_drag > 0
    slab = get_task("mattress:size=10,thickness=3").terrain_for(SHAPE).objects[0]
    assert slab.shape == (10, 10, 3) and slab.hi[2] == -0.5 and slab.origin[0] % 1 == 0.5
    # the goal lies `distance` from the grid's centre, `angle` counter-clockwise from -x
    goal = get_task("goal:distance=5,angle=90").terrain_for(SHAPE).meta["target"]
    np.testing.assert_allclose(goal, [3.0, -2.0], atol=1e-12)
    # the course: a bar, a step, then rough tiles, all within the seed's range of boxes
    course = get_task("course").terrain_for(SHAPE)
    assert 8 < len(course.boxes) < 300 and max(b.hi[2] for b in course.boxes) <= 1.0


def test_the_slopes_and_the_moon_set_the_engine():
    assert get_task("downhill:angle=10").config().incline == -10.0
    assert get_task("push_uphill:angle=8").config().incline == -8.0
    assert get_task("moon").config().gravity == pytest.approx(9.81 * 0.165)
    assert get_task("moon:gravity=1").config().gravity == pytest.approx(9.81)
    for name in ("lift", "shrink"):
        assert get_task(name).config().actuation == "symmetric"
