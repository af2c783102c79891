"""The task layer: one registry, custom terrains everywhere, one metrics path for evaluate and envs."""

import json

import gymnasium as gym
import numpy as np
import pytest
from fuzzing import fifo_code, refused_in_child

import softgym
from evolvers.evaluation.experiments import Experiment, get_experiment
from softgym.design import RobotDesign, default_walker
from softgym.exceptions import InvalidParameterError
from softgym.tasks import ALIASES, TASKS, Task, get_task, register_task, task_names
from softgym.terrain import Terrain


def small_design() -> RobotDesign:
    grid = np.zeros((4, 4, 4), dtype=np.int8)
    grid[:2] = 3
    grid[2:] = 4
    grid[:, :, 3] = 2
    return RobotDesign(grid)


def test_one_name_per_task_and_fence_is_an_alias_of_wall():
    assert task_names()[:3] == ["flat", "wall", "stairs"]
    assert len(task_names()) >= 14 and "fence" not in task_names()
    assert ALIASES == {"fence": "wall"}
    assert get_task("fence") is TASKS["wall"] and Task("fence") == Task("wall")
    assert [TASKS[n].reward for n in task_names()[:3]] == [
        "norm_final_dist",
        "max_xy_dist",
        "max_xy_dist",
    ]
    with pytest.raises(InvalidParameterError, match="unknown task 'lava'"):
        get_task("lava")
    with pytest.raises(InvalidParameterError, match="reward"):
        Task("flat", reward="l_coefficient")


def test_the_wall_and_the_stairs_surround_the_robot_grid():
    wall = get_task("wall").terrain_for((6, 6, 6))
    assert wall == Terrain.fence(inner=10, center=(3, 3))
    assert get_task("stairs").terrain_for((8, 4, 3)) == Terrain.stairs(inner=12, center=(4, 2))
    assert get_task("flat").terrain_for((6, 6, 6)) == Terrain.flat()


def test_a_terrain_its_json_file_and_a_task_dict_are_tasks(tmp_path):
    boxes = Terrain.from_boxes([((8, -5, 0), (9, 11, 2))], name="one_wall")
    path = tmp_path / "one_wall.json"
    path.write_text(boxes.to_json())
    for spec in (boxes, path, str(path), boxes.to_dict()):
        task = get_task(spec)
        assert task.terrain == boxes and task.name == "one_wall"
        assert task.terrain_for((6, 6, 6)) == boxes and task.reward == "max_xy_dist"
    t = get_task(boxes, seconds=2.0, sim={"actuation": "symmetric"})
    back = Task.from_dict(json.loads(json.dumps(t.to_dict())))
    assert back == t and back.config().actuation == "symmetric"
    with pytest.raises(InvalidParameterError, match="does not exist"):
        get_task(tmp_path / "missing.json")


def test_evaluate_takes_a_terrain_and_a_registered_task():
    d = default_walker()
    by_terrain = softgym.evaluate(d, task=Terrain.stairs(), seconds=1.5)
    by_name = softgym.evaluate(d, task="stairs", seconds=1.5)
    for key in ("norm_final_dist", "max_xy_dist", "l_coefficient"):
        np.testing.assert_array_equal(by_terrain[key], by_name[key])
    try:
        register_task("low_fence", Terrain.fence(height=0.5))
        assert "low_fence" in task_names()
        softgym.envs.register_envs()
        env = gym.make("SoftWalker-LowFence-v0", episode_seconds=0.1)
        assert env.unwrapped.task.name == "fence" and env.unwrapped.terrain.boxes[0].hi[2] == 0.5
        with pytest.raises(InvalidParameterError, match="exists"):
            register_task("low_fence", Terrain.flat())
    finally:
        TASKS.pop("low_fence", None)
        softgym.envs.ENV_IDS.pop("SoftWalker-LowFence-v0", None)
        gym.registry.pop("SoftWalker-LowFence-v0", None)


def _episode(task, design, grid_shape=(6, 6, 6)):
    env = gym.make(
        "SoftWalker-Flat-v0", task=task, design=design, grid_shape=grid_shape,
        control_dt=0.1, drive="controller",
    )  # fmt: skip
    env.reset(seed=0)
    done = False
    total = 0.0
    while not done:
        _, r, term, trunc, info = env.step(env.action_space.sample())
        total += r
        done = term or trunc
    assert trunc and info["time"] == pytest.approx(5.0)
    return info, total, env.unwrapped.task


@pytest.mark.parametrize(
    "task, design",
    [
        ("flat", default_walker()),
        ("wall", default_walker()),
        ("stairs", small_design()),
        (Terrain.from_boxes([((-3, 7, 0), (9, 8, 1))], name="north_wall"), default_walker()),
    ],
)
def test_same_design_same_task_same_metrics_through_evaluate_and_an_env_episode(task, design):
    # the env run by the design's own controller, sampled as often as evaluate samples
    info, total, env_task = _episode(task, design)
    m = softgym.evaluate(design, task=task, trace_interval=0.1)
    for key in ("norm_final_dist", "max_xy_dist", "l_coefficient", "diverged"):
        assert info[key] == m[key][0], key
    assert total == pytest.approx(
        m[env_task.reward][0], abs=1e-12
    )  # the return is the reward metric


def test_experiments_and_old_run_configs_go_through_the_registry(tmp_path):
    exp = get_experiment("obstacles")
    assert exp.task.spec == "wall" and exp.make_task().name == "wall"
    old = {**exp.to_dict()}
    old["terrain"] = "fence"  # a config.json written before the task layer
    del old["task"]
    assert Experiment.from_dict(old) == exp
    path = tmp_path / "boxes.json"
    path.write_text(Terrain.stairs(n_rings=2).to_json())
    custom = get_experiment("basic", task=str(path))
    assert isinstance(custom.task.terrain, Terrain)
    assert Experiment.from_dict(json.loads(json.dumps(custom.to_dict()))) == custom
    assert get_experiment("basic", task="stairs").make_task(n_threads=1).n_threads == 1


def test_task_strings_files_and_fifos_are_refused_with_typed_errors(tmp_path):
    # issue 31: a repeated argument took the last; a FIFO blocked forever; a task
    # JSON 100,000 deep gave a 48-line RecursionError; a 37 MB terrain file was read
    import os

    from softgym.exceptions import InvalidParameterError, InvalidTerrainError
    from softgym.tasks import get_task
    from softgym.terrain import MAX_TERRAIN_JSON_BYTES

    with pytest.raises(InvalidParameterError, match="'width' is given twice"):
        get_task("gap:width=2,width=3")
    deep = tmp_path / "deep.json"
    deep.write_text("[" * 100_000 + "]" * 100_000)
    with pytest.raises(InvalidTerrainError, match="nested too deeply"):
        get_task(str(deep))
    big = tmp_path / "big.json"
    big.write_bytes(b" " * (MAX_TERRAIN_JSON_BYTES + 1))
    with pytest.raises(InvalidParameterError, match="more than the cap"):
        get_task(str(big))
    if hasattr(os, "mkfifo"):
        fifo = tmp_path / "task.json"
        os.mkfifo(fifo)
        out = refused_in_child(fifo_code("from softgym.tasks import get_task", "get_task",
                                         str(fifo), "InvalidParameterError"))  # fmt: skip
        assert "not a regular file" in out


@pytest.mark.parametrize("spec", ["flat", "wall", "swim", "incline:angle=20", "ice"])
def test_engine_settings_are_assembled_in_one_place(spec, monkeypatch):
    # Task.config builds what task.py, softgym.evaluate and the envs' make_config each built
    from softgym.engine import SimConfig
    from softgym.envs.walker import make_config

    task = get_task(spec, sim={"actuation": "symmetric"}, trace_interval=0.25, seconds=0.05)
    base = SimConfig(voxel_size=0.02, friction=2.0, trace_interval=0.3)
    own = task.engine_settings
    assert task.config() == SimConfig(**own).replace(trace_interval=0.25)
    assert task.config(base) == base.replace(**own).replace(trace_interval=0.25)
    assert task.config(base, settings=False) == base.replace(trace_interval=0.25)
    assert make_config(base, "seed", False, task) == base.replace(**own).replace(
        trace_interval=1e9, actuation="seed", self_collision=False
    )
    assert make_config(base, None, None, task) == base.replace(**own).replace(trace_interval=1e9)
    assert make_config(None, "symmetric", None, None) == SimConfig(
        trace_interval=1e9, actuation="symmetric"
    )
    built = []
    config = Task.config

    def spy(self, *args, **kwargs):
        built.append(config(self, *args, **kwargs))
        return built[-1]

    monkeypatch.setattr(Task, "config", spy)
    softgym.evaluate([small_design()], task=task)
    softgym.evaluate([small_design()], task=task, config=base)
    make_config(base, "seed", True, task)
    assert built == [
        SimConfig(**own).replace(trace_interval=0.25),
        base.replace(trace_interval=0.25),  # a full config replaces the task's settings
        base.replace(**own).replace(trace_interval=1e9, actuation="seed", self_collision=True),
    ]


def test_unknown_task_fields_and_sim_keys_are_typed_errors_naming_them(tmp_path):
    with pytest.raises(InvalidParameterError, match="bogus"):
        get_task("gap", bogus=1)
    with pytest.raises(InvalidParameterError, match="gravty"):
        Task("flat", sim={"gravty": 1.0})
    path = tmp_path / "t.json"
    path.write_text(json.dumps({**Task("flat").to_dict(), "sim": {"no_such_field": 1}}))
    with pytest.raises(InvalidParameterError, match="no_such_field"):
        get_task(str(path))
