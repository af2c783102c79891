"""Bad input gets a typed error naming what is wrong, and changes nothing."""

import numpy as np
import pytest
from engine_builders import reference_robot

from softgym.engine import Body, SimConfig, Simulation
from softgym.exceptions import (
    InvalidActionError,
    InvalidDesignError,
    InvalidIndexError,
    InvalidParameterError,
    SoftGymError,
)

TABLES = dict(
    youngs_modulus=[0, 5e6], density=[0, 1e6], poisson=[0, 0.35], cte=[0, 0.0],
    mu_static=[0, 1.0], mu_kinetic=[0, 0.5],
)  # fmt: skip


def _body(**over):
    kw = dict(grid=np.ones((2, 2, 2), dtype=np.int8), **TABLES)
    kw.update(over)
    return Body(**kw)


@pytest.mark.parametrize(
    ("over", "error", "match"),
    [
        (dict(grid=np.ones((2, 2))), InvalidDesignError, "3-D"),
        (dict(grid=np.ones((2, 2, 2), dtype=float)), InvalidDesignError, "integer dtype"),
        (dict(grid=np.zeros((2, 2, 2), dtype=int)), InvalidDesignError, "empty robot"),
        (dict(grid=np.full((2, 2, 2), 3)), InvalidDesignError, "unknown material ids \\[3\\]"),
        (dict(grid=np.full((2, 2, 2), -1)), InvalidDesignError, "unknown material ids"),
        (dict(youngs_modulus=[0, -5e6]), InvalidParameterError, "youngs_modulus must lie in"),
        (dict(youngs_modulus=[0, np.nan]), InvalidParameterError, "not finite"),
        (dict(density=[0, 0.0]), InvalidParameterError, "density must lie in"),
        (dict(poisson=[0, 0.5]), InvalidParameterError, "poisson"),
        (dict(poisson=[0, -0.1]), InvalidParameterError, "poisson"),
        (dict(mu_static=[0, -1.0]), InvalidParameterError, "friction"),
        (dict(cte=[0, 0.0, 1.0]), InvalidParameterError, "one entry per material"),
        (dict(period=0.0), InvalidParameterError, "period"),
        (dict(temp_amplitude=float("inf")), InvalidParameterError, "temp_amplitude"),
        (dict(fixed=np.ones((3, 3, 3), dtype=bool)), InvalidDesignError, "fixed mask"),
        (dict(origin=(0, 0)), InvalidParameterError, "origin"),
    ],
)
def test_invalid_bodies_raise_typed_errors(over, error, match):
    with pytest.raises(error, match=match):
        _body(**over)


def test_errors_subclass_builtins():
    with pytest.raises(ValueError):
        _body(density=[0, -1.0])
    assert issubclass(InvalidDesignError, SoftGymError)


@pytest.mark.parametrize(
    ("name", "value"),
    [
        ("voxel_size", 0.0), ("voxel_size", float("nan")), ("dt_frac", 0.0), ("dt_frac", 50.0),
        ("gravity", -9.81), ("bond_damping", -1.0), ("init_time", -1.0), ("min_scale", 0.0),
        ("max_strain", 0.0), ("trace_interval", 0.0), ("actuation", "both"),
        ("on_divergence", "ignore"), ("collision_exclusion", 0), ("voxel_size", "big"),
        # issue 31: a time step of 0 (a run that never advances) or buffers sized to overflow
        ("voxel_size", 1e-300), ("voxel_size", 1e300), ("gravity", "9.81"), ("init_time", True),
    ],
)  # fmt: skip
def test_invalid_config_raises_naming_the_field(name, value):
    with pytest.raises(InvalidParameterError, match=f"SimConfig.{name}"):
        SimConfig(**{name: value})


@pytest.mark.parametrize(
    ("field", "value"),
    [("density", 1e-300), ("density", 1e300), ("youngs_modulus", 1e300),
     ("youngs_modulus", 1e-30)],
)  # fmt: skip
def test_materials_beyond_physical_ranges_are_refused_naming_the_range(field, value):
    # issue 31: such materials gave a time step of 0 (run() never advanced) or
    # buffers of petabytes
    with pytest.raises(InvalidParameterError, match=f"{field} must lie in \\[.*\\]"):
        Body.uniform(np.ones((2, 2, 2)), **{field: value})


def test_a_batch_beyond_the_memory_budget_is_refused_before_anything_is_allocated():
    # issue 31: 2 robots at the grid cap (100^3) died in the layout at 3.8 GB after 92 s;
    # they need ~4.6 GB since issue 61 (the layout no longer doubles its peak): 6 need ~13 GiB
    import time

    bodies = [Body.uniform(np.ones((100, 100, 100)))] * 6
    t0 = time.perf_counter()
    with pytest.raises(InvalidParameterError, match="GiB, over Simulation.max_bytes"):
        Simulation(bodies)
    assert time.perf_counter() - t0 < 10.0


def test_a_trace_interval_that_would_exhaust_memory_is_refused_before_the_run():
    # issue 31: evaluate(..., trace_interval=1e-9) asked for 37 GiB
    sim = Simulation(_body(), SimConfig(trace_interval=1e-9))
    state = sim.get_state()
    with pytest.raises(InvalidParameterError, match="SimConfig.trace_interval = 1e-09 s"):
        sim.run(5.0)
    after = sim.get_state()
    assert all(np.array_equal(state[k], after[k]) for k in state)


def test_config_dict_round_trip_and_unknown_keys():
    cfg = SimConfig(gravity=0.0, actuation="symmetric")
    assert SimConfig.from_dict(cfg.to_dict()) == cfg
    with pytest.raises(InvalidParameterError, match="unknown SimConfig keys"):
        SimConfig.from_dict({"gravty": 1.0})


def test_simulation_rejects_bad_arguments():
    with pytest.raises(InvalidDesignError):
        Simulation([])
    with pytest.raises(InvalidDesignError, match="Body or a design"):
        Simulation(["not a body"])
    with pytest.raises(InvalidParameterError, match="n_threads"):
        Simulation(_body(), n_threads=0)
    sim = Simulation(_body())
    with pytest.raises(InvalidParameterError):
        sim.advance(-1.0)
    with pytest.raises(InvalidParameterError):
        sim.advance(float("nan"))
    with pytest.raises(InvalidIndexError, match="robot = 3 is out of range: .* robots 0..0"):
        sim.positions(3)  # issue 31: was a bare IndexError
    with pytest.raises(InvalidIndexError, match="integer index"):
        sim.positions(True)
    assert issubclass(InvalidIndexError, IndexError)


def test_nan_temperatures_raise_and_leave_the_state_unchanged():
    sim = Simulation(reference_robot(3), SimConfig(actuation="symmetric"))
    sim.advance(0.2)
    before = sim.get_state()
    temps = np.zeros(27)
    temps[4] = np.nan
    with pytest.raises(InvalidActionError, match="NaN"):
        sim.set_temperature(0, temps)
    with pytest.raises(InvalidActionError, match="shape"):
        sim.set_temperature(0, np.zeros(5))
    after = sim.get_state()
    for k in before:
        assert np.array_equal(before[k], after[k]), k
    # a grid-shaped temperature field is accepted and drives the muscles
    sim.set_temperature(0, np.full((3, 3, 3), 10.0))
    sim.advance(0.1)
    assert not np.allclose(sim.scales(0), 0.01)


def test_state_round_trip_resumes_bit_for_bit():
    sim = Simulation(reference_robot(3))
    sim.advance(1.2)
    state = sim.get_state()
    sim.advance(0.6)
    end = sim.rollout()
    again = Simulation(reference_robot(3))
    again.set_state(state)
    again.advance(0.6)
    other = again.rollout()
    assert np.array_equal(end.positions, other.positions)
    assert np.array_equal(end.cm, other.cm)
    with pytest.raises(InvalidParameterError, match="missing"):
        again.set_state({"pos": state["pos"]})


def test_batch_temperatures_match_per_robot_calls_and_reject_nan():
    bodies = [reference_robot(3), reference_robot(2)]
    cfg = SimConfig(actuation="symmetric")
    one, many = Simulation(bodies, cfg), Simulation(bodies, cfg)
    temps = np.linspace(-10.0, 10.0, one.n_voxels)
    off = one.voxel_offsets
    for r in range(2):
        one.set_temperature(r, temps[off[r] : off[r + 1]])
    many.set_temperatures(temps)
    one.advance(0.2)
    many.advance(0.2)
    assert np.array_equal(one.all_positions, many.all_positions)
    before = many.get_state()
    bad = temps.copy()
    bad[3] = np.inf
    with pytest.raises(InvalidActionError):
        many.set_temperatures(bad)
    with pytest.raises(InvalidActionError, match="shape"):
        many.set_temperatures(temps[:-1])
    after = many.get_state()
    assert all(np.array_equal(before[k], after[k]) for k in before)
    # only robot 1 switches: robot 0 keeps its values
    many.set_temperatures(np.zeros(many.n_voxels), robots=[1])
    assert np.array_equal(many.get_state()["temp"][: off[1]], temps[: off[1]])


def test_set_state_derives_rotations_from_quaternions():
    # rot is derived state: a state whose quaternion says "twisted" is twisted
    sim = Simulation(Body.uniform(np.ones((2, 1, 1))), SimConfig(gravity=0.0, floor=False))
    assert sim.energy()[0, 1] < 1e-20
    state = sim.get_state()
    angle = 0.2
    state["quat"][1] = [np.cos(angle / 2), 0.0, 0.0, np.sin(angle / 2)]  # bend about z
    sim.set_state(state)
    assert sim.energy()[0, 1] > 1e-6


def test_default_threads_come_from_the_environment_not_openmp_state(monkeypatch):
    from softgym.engine import default_num_threads, openmp_enabled

    monkeypatch.delenv("SOFTGYM_NUM_THREADS", raising=False)
    monkeypatch.setenv("OMP_NUM_THREADS", "3,1")
    assert default_num_threads() == (3 if openmp_enabled() else 1)
    monkeypatch.setenv("SOFTGYM_NUM_THREADS", "2")
    assert default_num_threads() == (2 if openmp_enabled() else 1)
    monkeypatch.setenv("SOFTGYM_NUM_THREADS", "two")
    if openmp_enabled():
        with pytest.raises(InvalidParameterError, match="SOFTGYM_NUM_THREADS"):
            default_num_threads()
    monkeypatch.delenv("SOFTGYM_NUM_THREADS")
    monkeypatch.delenv("OMP_NUM_THREADS")
    assert default_num_threads() >= 1


def test_time_step_is_the_engines_and_cost_follows_it():
    import numpy as np

    from softgym.design import RobotDesign, default_walker
    from softgym.engine import SimConfig, Simulation, time_step, voxel_steps_per_second

    bone = RobotDesign(np.array([[[2, 2], [2, 1]]]))
    for d in (default_walker(), bone):
        for cfg in (SimConfig(), SimConfig.corotational()):
            assert time_step(d, cfg) == Simulation([d], cfg).dt[0]
    assert voxel_steps_per_second(bone) > 5 * voxel_steps_per_second(RobotDesign(np.ones((1, 2, 2), int)))


def test_an_unbounded_run_is_refused_before_it_starts():
    # E 1e12 Pa at density 1e-3 kg/m^3 gives a time step of ~5e-11 s: one second
    # would take days; the call is refused with a typed error and nothing changes
    import numpy as np
    import pytest

    from softgym.engine import Body, Simulation
    from softgym.exceptions import InvalidParameterError

    body = Body.uniform(np.ones((2, 2, 2)), youngs_modulus=1e12, density=1e-3)
    sim = Simulation([body])
    state = sim.get_state()
    with pytest.raises(InvalidParameterError, match="voxel-steps"):
        sim.advance(1.0)
    after = sim.get_state()
    assert all(np.array_equal(state[k], after[k]) for k in state)


def test_cm_init_is_public_and_equals_the_rollouts():
    import numpy as np

    from softgym.design import default_walker
    from softgym.engine import SimConfig, Simulation

    sim = Simulation([default_walker()], SimConfig(init_time=0.2))
    sim.advance(0.5)
    np.testing.assert_array_equal(sim.cm_init, sim.rollout().cm_init)


def test_a_body_placed_below_the_floor_is_refused():
    # issue 31: 5 m below the floor, the penalty force flew it to z = 65 m, not diverged
    with pytest.raises(InvalidDesignError, match="below the floor"):
        Simulation([Body.uniform(np.ones((2, 2, 2)), origin=(0.0, 0.0, -5.0))])
    Simulation([Body.uniform(np.ones((2, 2, 2)), origin=(0.0, 0.0, -5.0))],
               SimConfig(floor=False))  # fmt: skip  (no floor: any height)


def test_a_rollouts_trace_index_is_checked_like_the_simulations():
    # issue 61: trace(7) was a bare IndexError while trace(-1) was taken as the last robot
    rollout = Simulation(_body(), SimConfig(trace_interval=0.01)).run(0.02)
    assert rollout.trace(0).shape[1] == 4
    for bad in (7, 1, -1):
        with pytest.raises(InvalidIndexError, match=f"robot = {bad} is out of range: .* 0..0"):
            rollout.trace(bad)
    with pytest.raises(InvalidIndexError, match="integer index"):
        rollout.trace(0.0)
