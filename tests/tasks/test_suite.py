"""The task suite: arguments, worlds and each task's measure on hand-made cases."""

from __future__ import annotations

import math

import numpy as np
import pytest

import softgym
from evolvers.evaluation.experiments import get_experiment
from softgym.design import RobotDesign, default_walker
from softgym.exceptions import InvalidParameterError
from softgym.metrics import WORST_FITNESS, task_measure_from_arrays
from softgym.tasks import KINDS, TASKS, Task, get_task, task_names

L = 0.01
N_AUX = len(softgym.engine.AUX_NAMES)


def _arrays(cm, aux, cm0=None, aux0=None):
    """(cm_init, aux_init, trace_cm, trace_aux, valid) of one robot from its samples (m)."""
    cm = np.asarray(cm, dtype=np.float64)[None]
    aux = np.asarray(aux, dtype=np.float64)[None]
    cm0 = cm[:, 0] if cm0 is None else np.asarray(cm0, dtype=np.float64)[None]
    aux0 = aux[:, 0] if aux0 is None else np.asarray(aux0, dtype=np.float64)[None]
    return cm0, aux0, cm, aux, np.ones(cm.shape[:2], dtype=bool)


def _aux(obj=(0, 0, 0), heading=(1, 0), box=(0, 0, 0, 0, 0)):
    return [*obj, *heading, *box]


def test_the_suite_has_at_least_14_tasks_each_with_a_gym_id():
    from softgym.envs import ENV_IDS

    assert len(task_names()) >= 14
    assert set(ENV_IDS.values()) == set(task_names())
    for name in ("stairs_down", "rough", "gap", "tunnel", "incline", "ice", "mud", "jump",
                 "turn", "push", "carry", "swim", "grow"):  # fmt: skip
        assert name in KINDS and TASKS[name].reward == KINDS[name].reward


def test_arguments_are_checked_with_their_field_and_range():
    assert Task("gap", options={"width": 3}).options == {"width": 3.0, "depth": 4.0}
    with pytest.raises(InvalidParameterError, match=r"width must be a number in \[0.5, 10\]"):
        Task("gap", options={"width": 30})
    with pytest.raises(InvalidParameterError, match="has no argument"):
        Task("gap", options={"height": 1})
    with pytest.raises(InvalidParameterError, match=r"n_steps must be an integer"):
        Task("stairs_down", options={"n_steps": 2.5})
    with pytest.raises(InvalidParameterError, match="takes no options"):
        Task("flat", options={"width": 1})
    with pytest.raises(InvalidParameterError, match="name=number"):
        get_task("gap:width")
    t = get_task("gap:width=3,depth=5")
    assert t.options == {"width": 3.0, "depth": 5.0} and t.spec == "gap:depth=5.0,width=3.0"
    assert get_task(t.spec) == t and Task.from_dict(t.to_dict()) == t


def test_difficulty_arguments_change_the_world():
    shape = (6, 6, 6)
    assert get_task("rough:roughness=2").terrain_for(shape) != get_task("rough").terrain_for(shape)
    assert get_task("rough:seed=1").terrain_for(shape) != get_task("rough").terrain_for(shape)
    hi = get_task("stairs_down:step_height=2").terrain_for(shape)
    assert min(b.hi[2] for b in hi.boxes) == -6.0
    gap = get_task("gap:width=4").terrain_for(shape)
    assert not gap.floor and gap.meta["edge"] == 3.0 and gap.box_contact == "surface"
    assert get_task("incline:angle=20").config().incline == 20.0
    swim = get_task("swim").config()
    assert swim.gravity == 0.0 and swim.floor is False and swim.fluid_drag > 0
    assert get_task("swim", sim={"fluid_drag": 1e3}).config().fluid_drag == 1e3
    assert get_task("ice").config().friction == 0.1 and get_task("mud").config().friction == 4.0


def test_push_measure_of_a_box_pushed_a_known_distance():
    target = np.array([[-10.0, 3.0]])
    aux0 = _aux(obj=(-2 * L, 3 * L, 1.5 * L))
    moved = _aux(obj=(-5 * L, 3 * L, 1.5 * L))  # 3 voxels towards the target
    args = _arrays([[0, 0, 0], [0, 0, 0]], [aux0, moved])
    out = task_measure_from_arrays("push_progress", *args, L, {"target": target})
    assert out[0] == pytest.approx(3.0)
    sideways = _aux(obj=(-2 * L, 7 * L, 1.5 * L))  # 4 voxels across: farther from the target
    args = _arrays([[0, 0, 0], [0, 0, 0]], [aux0, sideways])
    assert task_measure_from_arrays("push_progress", *args, L, {"target": target})[0] < 0


def test_gap_measure_is_zero_on_the_platform_or_in_the_pit():
    params = {"center": np.array([[3.0, 3.0]]), "edge": np.array([3.0])}
    start = [3 * L, 3 * L, 2.7 * L]
    on = _aux(box=(0.5 * L, 5.5 * L, 0.5 * L, 5.5 * L, 5.5 * L))  # the voxel centres at rest
    reach = _aux(box=(-2.5 * L, 3.5 * L, 0.5 * L, 5.5 * L, 5.5 * L))  # 2.5 past the -x edge
    moved = [0.0, 3 * L, 2.7 * L]
    fell = [0.0, 3 * L, -1.5 * L]

    def gap(cm, aux):
        return task_measure_from_arrays("gap_crossed", *_arrays(cm, aux), L, params)[0]

    assert gap([start, start], [on, on]) == 0.0
    assert gap([start, moved], [on, reach]) == pytest.approx(2.5)
    assert gap([start, fell], [on, reach]) == 0.0


def test_a_robot_that_never_leaves_the_platform_scores_zero_on_gap():
    still = RobotDesign(np.ones((6, 6, 6), dtype=np.int8))  # passive: it never moves
    m = softgym.evaluate([still, default_walker()], task="gap", seconds=2.0)
    assert m["score"][0] == 0.0 and m["gap_crossed"][0] == 0.0
    assert m["max_xy_dist"][0] < 0.01 and not m["diverged"][0]


def test_yaw_unwraps_a_turn_of_more_than_half_a_turn():
    angles = np.linspace(0.0, 3.0 * np.pi, 13)
    aux = [_aux(heading=(math.cos(a), math.sin(a))) for a in angles]
    cm = np.zeros((13, 3))
    assert task_measure_from_arrays("yaw", *_arrays(cm, aux), L)[0] == pytest.approx(3 * np.pi)
    back = [_aux(heading=(math.cos(-a), math.sin(-a))) for a in angles]
    assert task_measure_from_arrays("yaw", *_arrays(cm, back), L)[0] == pytest.approx(3 * np.pi)


def test_peak_height_footprint_swim_and_carry_on_hand_made_samples():
    z = [[0, 0, 3 * L], [0, 0, 5 * L], [0, 0, 2 * L]]
    a = [_aux()] * 3
    assert task_measure_from_arrays("peak_height", *_arrays(z, a), L)[0] == pytest.approx(2.0)
    boxes = [_aux(box=(0, 5 * L, 0, 5 * L, 0)), _aux(box=(-L, 6 * L, 0, 5 * L, 0)),
             _aux(box=(0, 5 * L, 0, 5 * L, 0))]  # fmt: skip
    # footprint 6 x 6 = 36 cells, then 8 x 6 = 48
    assert task_measure_from_arrays("footprint_gain", *_arrays(z, boxes), L)[0] == pytest.approx(12)
    swim = [[0, 0, 0], [3 * L, 4 * L, 12 * L]]
    assert task_measure_from_arrays("swim_dist", *_arrays(swim, a[:2]), L)[0] == pytest.approx(13)
    robot = [[0, 0, 3 * L], [4 * L, 0, 3 * L]]
    # the robot's voxel centres span x -2.5..2.5 L, then 1.5..6.5 L, and y -2.5..2.5 L
    box0, box1 = (-2.5 * L, 2.5 * L, -2.5 * L, 2.5 * L, 5 * L), (1.5 * L, 6.5 * L, -2.5 * L, 2.5 * L, 5 * L)
    held = [_aux(obj=(0, 0, 7 * L), box=box0), _aux(obj=(4 * L, 0, 7 * L), box=box1)]
    dropped = [_aux(obj=(0, 0, 7 * L), box=box0), _aux(obj=(4 * L, 0, 1 * L), box=box1)]
    # slid off behind the robot, resting higher than its centre of mass: not carried
    beside = [_aux(obj=(0, 0, 7 * L), box=box0), _aux(obj=(9 * L, 0, 4 * L), box=box1)]
    carried = [task_measure_from_arrays("carried_dist", *_arrays(robot, c), L)[0]
               for c in (held, dropped, beside)]  # fmt: skip
    assert carried == [pytest.approx(4), 0.0, 0.0]
    div = task_measure_from_arrays("swim_dist", *_arrays(swim, a[:2]), L, diverged=[True])
    assert div[0] == WORST_FITNESS


def test_evaluate_and_the_controller_env_agree_on_a_suite_measure():
    import gymnasium as gym

    m = softgym.evaluate([default_walker()], task="jump", seconds=3.0)
    env = gym.make("SoftWalker-Jump-v0", drive="controller", control_dt=0.1, episode_seconds=2.0,
                   max_episode_steps=20)  # fmt: skip
    env.reset(seed=0)
    ret = 0.0
    for _ in range(20):
        _, r, _, trunc, info = env.step(env.action_space.sample())
        ret += r
    assert info["score"] == pytest.approx(m["score"][0], rel=1e-9) and m["score"][0] > 0.05
    assert ret == pytest.approx(info["score"])


def test_evolution_on_a_suite_task_selects_on_its_score():
    exp = get_experiment("basic", task="jump")
    assert exp.fitness.name == "score" and exp.task.spec == "jump"
    assert get_experiment("basic", task="gap:width=3").make_task().options["width"] == 3.0
    assert get_experiment("basic", task="swim").make_task().config().fluid_drag > 0
    assert get_experiment("basic").fitness.name == "norm_final_dist"


def test_stairs_down_ground_reaches_beyond_what_a_fast_robot_covers():
    # the pyramid has no floor under it: the ground ring must reach farther than the
    # fastest evolved walkers get in a task's run (~50 voxel lengths), or a robot walking
    # off its edge scores max_xy_dist while it falls
    from softgym.tasks.suite import stairs_down_layout

    for n_steps in (1, 3, 10):
        world = stairs_down_layout((6, 6, 6), n_steps=n_steps, step_width=10.0)
        lo = min(b.lo[0] for b in world.boxes), min(b.lo[1] for b in world.boxes)
        hi = max(b.hi[0] for b in world.boxes), max(b.hi[1] for b in world.boxes)
        assert min(3.0 - lo[0], 3.0 - lo[1], hi[0] - 3.0, hi[1] - 3.0) >= 150.0


def test_a_task_kinds_shaping_names_task_measures_with_positive_weights():
    from softgym.exceptions import InvalidParameterError
    from softgym.metrics import TASK_MEASURES
    from softgym.tasks.suite import KINDS, TaskKind, flat_layout

    shaped = {k.name for k in KINDS.values() if k.shaping}
    assert {"push", "push_uphill", "gap"} <= shaped
    for kind in KINDS.values():
        for measure, weight in kind.shaping:
            assert measure in TASK_MEASURES and weight > 0
    for bad in ((("speed", 0.5),), (("top_dist", 0.0),), (("top_dist", 1),)):
        with pytest.raises(InvalidParameterError, match="shaping needs"):
            TaskKind("t", "t", flat_layout, "x_progress", family="locomotion", shaping=bad)
