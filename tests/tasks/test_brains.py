"""Closed-loop control: brains read their senses, drive any body, and score through softgym.evaluate."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import softgym
from softgym.design import BrainSpec, RobotDesign, default_walker
from softgym.exceptions import InvalidDesignError
from softgym.tasks import EpisodeBatch, get_task
from softgym.tasks.brains import brain_spec, sinusoid_brain
from softgym.tasks.sensing import CELL_SENSORS, sensing_layout

TOUCH = [name for name, _, _ in CELL_SENSORS].index("touch")


def _brain_batch(designs, task="flat", grid=(6, 6, 6)):
    t = get_task(task)
    b = EpisodeBatch(designs, t, grid, 0.05, 1.0, None, t.config(trace_interval=1e9), n_threads=1,
                     drive="brain")  # fmt: skip
    b.reset_all()
    return b


def test_sizes_follow_the_task_and_grid():
    lay = sensing_layout(get_task("push"), (6, 6, 6))
    c = brain_spec("central", get_task("push"), (6, 6, 6), hidden=4)
    assert (c.n_inputs, c.n_outputs) == (lay.size, 216)
    d = brain_spec("distributed", get_task("push"), (6, 6, 6), hidden=4, signals=2)
    assert (d.n_inputs, d.n_outputs) == (lay.local_size + 12, 3)
    assert brain_spec("distributed", get_task("push"), (2, 3, 4)) == brain_spec(
        "distributed", get_task("push"), (6, 6, 6))  # any body
    with pytest.raises(softgym.exceptions.InvalidParameterError, match="signals"):
        brain_spec("central", get_task("flat"), (6, 6, 6), signals=1)


def test_a_controllers_action_depends_on_its_sensors():
    # a distributed brain that reads touch alone: a voxel on the floor pushes, the others rest
    spec = brain_spec("distributed", get_task("flat"), (6, 6, 6), hidden=0, signals=0)
    w = np.zeros(spec.n_params)
    w[TOUCH] = 2.0  # output row 0, touch column
    b = _brain_batch([default_walker().replace(brain=spec.brain(w))])
    out = b.brains.outputs().reshape(6, 6, 6)
    np.testing.assert_allclose(out[:, :, 0], np.tanh(2.0))
    np.testing.assert_allclose(out[:, :, 2:], 0.0)


def test_one_distributed_brain_drives_bodies_of_any_shape_alone_or_together():
    spec = brain_spec("distributed", get_task("flat"), (6, 6, 6), hidden=4, signals=1)
    brain = spec.random(5, scale=2.0)
    bodies = [default_walker(), RobotDesign(np.full((4, 3, 2), 3, dtype=np.int8)),
              RobotDesign(np.where(np.indices((5, 5, 3)).sum(axis=0) % 2, 3, 4).astype(np.int8))]
    designs = [d.replace(brain=brain) for d in bodies]
    together = softgym.evaluate(designs, task="flat", seconds=1.6)
    for i, d in enumerate(designs):
        alone = softgym.evaluate([d], task="flat", seconds=1.6)
        assert alone["norm_final_dist"][0] == together["norm_final_dist"][i]
    assert np.all(np.isfinite(together["score"])) and not together["diverged"].any()


def test_closed_and_open_loop_in_one_call_leave_the_open_loop_bit_identical():
    spec = brain_spec("central", get_task("push"), (6, 6, 6), hidden=2)
    open_d = default_walker()
    mixed = softgym.evaluate([open_d, open_d.replace(brain=spec.random(0))], task="push", traces=True)
    alone = softgym.evaluate([open_d], task="push", traces=True)
    for k in ("norm_final_dist", "max_xy_dist", "push_progress", "score"):
        assert mixed[k][0] == alone[k][0]
    np.testing.assert_array_equal(mixed["traces"][0], alone["traces"][0])
    tr = mixed["traces"][1]
    assert tr.shape[1] == 4 and tr[0, 3] == pytest.approx(1.0, abs=1e-3)  # from the episode start
    again = softgym.evaluate([open_d.replace(brain=spec.random(0))], task="push")
    assert again["score"][0] == mixed["score"][1]  # deterministic


def test_the_sinusoid_as_a_network_walks():
    spec = brain_spec("distributed", get_task("flat"), (6, 6, 6), hidden=4, control_dt=0.02)
    m = softgym.evaluate([default_walker().replace(brain=sinusoid_brain(spec, 3.0))], task="flat")
    assert m["score"][0] > 2.0
    still = softgym.evaluate([default_walker().replace(brain=spec.brain(np.zeros(spec.n_params)))],
                             task="flat")  # fmt: skip
    assert still["score"][0] < 0.2


def test_a_brain_that_does_not_fit_is_a_typed_error():
    central = brain_spec("central", get_task("flat"), (6, 6, 6), hidden=2)
    small = RobotDesign(np.full((3, 3, 3), 3, dtype=np.int8))
    with pytest.raises(InvalidDesignError, match="n_inputs"):
        softgym.evaluate([small.replace(brain=central.random(0))], task="flat")
    with pytest.raises(InvalidDesignError, match="n_inputs"):  # a flat brain on push: no object senses
        softgym.evaluate([default_walker().replace(brain=central.random(0))], task="push")
    d = brain_spec("distributed", get_task("flat"), (6, 6, 6))
    with pytest.raises(InvalidDesignError, match="n_inputs"):
        softgym.evaluate([default_walker().replace(brain=d.random(0))], task="gap")
    with pytest.raises(softgym.exceptions.InvalidParameterError, match="settling"):
        softgym.evaluate([default_walker().replace(brain=d.random(0))], task="flat", seconds=0.9)
    with pytest.raises(InvalidDesignError, match="control_dt"):
        BrainSpec("distributed", 25, 2, signals=1, control_dt=5.0)


@pytest.mark.parametrize("grid", [(0, 6, 6), (6, 6), (6.5, 6, 6), "666", (10**9, 10**9, 10**9)])
def test_a_grid_the_sensors_cannot_read_is_a_typed_error(grid):
    with pytest.raises(softgym.exceptions.InvalidParameterError, match="grid_shape"):
        brain_spec("central", get_task("flat"), grid)
    with pytest.raises(softgym.exceptions.InvalidParameterError, match="grid_shape"):
        sensing_layout(get_task("flat"), grid)


def test_an_unknown_brain_kind_is_a_typed_error():
    with pytest.raises(softgym.exceptions.InvalidParameterError, match="central"):
        brain_spec("cortex", get_task("flat"), (6, 6, 6))
    with pytest.raises(softgym.exceptions.InvalidParameterError, match="Task"):
        sensing_layout("flat", (6, 6, 6))


@pytest.mark.parametrize("task", ["stairs", "rough", "turn"])
def test_a_finer_control_step_scored_every_trace_interval_reports_evaluates_metrics(task):
    # the design's own sinusoid run as episodes of 0.05 s steps, scored on every second
    # sample (0.1 s: the task's trace_interval): exactly softgym.evaluate's open-loop metrics
    t = get_task(task)
    b = EpisodeBatch([default_walker()], t, (6, 6, 6), 0.05, t.seconds - 1.0, None,
                     t.config(trace_interval=1e9), n_threads=1, drive="controller")  # fmt: skip
    b.reset_all()
    for _ in range(b.max_steps):
        b.advance()
        b.update(np.ones(1, dtype=bool))
    got = b.metrics(stride=2)
    want = softgym.evaluate([default_walker()], task=t)
    for k in ("norm_final_dist", "max_xy_dist", "l_coefficient", "score"):
        assert got[k][0] == pytest.approx(want[k][0], rel=1e-9, abs=1e-12), k


@settings(max_examples=12, deadline=None)
@given(
    st.tuples(st.integers(1, 4), st.integers(1, 4), st.integers(1, 3)),
    st.integers(0, 2**31 - 1),
    st.sampled_from(["flat", "push", "gap", "turn"]),
)
def test_any_body_carries_a_distributed_brain_whose_outputs_are_bounded(shape, seed, task):
    rng = np.random.default_rng(seed)
    grid = rng.choice([0, 1, 3, 4], size=shape).astype(np.int8)
    grid[0, 0, 0] = 3  # at least one voxel
    body = RobotDesign(grid).largest_component()
    spec = brain_spec("distributed", get_task(task), (6, 6, 6), hidden=3, signals=1)
    b = _brain_batch([body.replace(brain=spec.random(seed, scale=3.0))], task, grid=body.shape)
    for _ in range(3):
        out = b.brains.outputs()
        assert out.shape == (1, b.n_cells) and np.all(np.abs(out) <= 1.0)
        assert np.all(out[~b.filled_mask] == 0.0)  # empty cells drive nothing
        b.brains.step()
        b.advance()
        b.update(np.ones(1, dtype=bool))
    obs = b.sensing.observation(b.clock(), b.period)
    assert np.isfinite(obs).all() and np.all(np.abs(obs) <= sensing_layout(get_task(task), body.shape).bounds())
