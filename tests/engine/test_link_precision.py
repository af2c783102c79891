"""The seed model's single-precision link math (``SimConfig.link_precision="single"``,
the seed model's default since issue 29; ``"double"`` keeps the seed's own operations).

The frames and forces passes run in float, and the forces' turn to the world and
the voxels' sums of them (the push); positions, geometry, modes and the voxel
update stay double. Checked here: the float
frames follow the seed's scalar code in double to float accuracy (including
the near-identity rotations where the seed's own formula cancels), the
closed-form cases hold, and results stay deterministic (threads, batches,
resume). The seed engine's micro-cases are checked in both precisions by
test_seed_oracle.py; ``benchmarks/fidelity_seed.py`` is the whole-body check
against the seed's engine.
"""

import json
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from softgym.design import RobotDesign
from softgym.engine import Body, SimConfig, Simulation, _core
from softgym.exceptions import InvalidParameterError
from softgym.fidelity import case_design, cases_from_data

DATA = Path(__file__).resolve().parents[2] / "benchmarks" / "data" / "seed_engine"
SINGLE = SimConfig(link_precision="single")


def test_link_precision_is_validated():
    with pytest.raises(InvalidParameterError, match="link_precision"):
        SimConfig(link_precision="half")
    with pytest.raises(InvalidParameterError, match='link_precision "single" needs model "seed"'):
        SimConfig(model="corotational", link_precision="single")
    assert SimConfig.from_dict(SINGLE.to_dict()) == SINGLE


def test_single_precision_is_the_seed_models_default():
    # None: the model's default, float links for the seed step, double for the
    # corotational one (whose links have no float path); an explicit "double"
    # (a checkpoint's config from before the default changed) stays double
    assert SimConfig().link_precision is None
    assert SimConfig().effective_link_precision == "single"
    assert SimConfig.seed().effective_link_precision == "single"
    assert SimConfig.corotational().effective_link_precision == "double"
    assert SimConfig().replace(model="corotational").effective_link_precision == "double"
    double = SimConfig(link_precision="double")
    assert SimConfig.from_dict(double.to_dict()).effective_link_precision == "double"
    assert SimConfig.from_dict(SimConfig().to_dict()) == SimConfig()
    sims = {p: Simulation([Body.uniform(np.ones((2, 2, 2)))], SimConfig(link_precision=p))
            for p in (None, "single", "double")}  # fmt: skip
    assert sims[None]._a["link_last"].dtype == np.float32
    assert sims["single"]._a["link_last"].dtype == np.float32
    assert sims["double"]._a["link_last"].dtype == np.float64


def _column(p, angle, axis, nominal, small):
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    q = [np.cos(angle / 2), *(np.sin(angle / 2) * axis)]
    return [*p, *q, nominal, float(np.linalg.norm(p)), small]


_ANGLE = st.sampled_from([0.0, 1e-6, 1e-4, 0.01, 0.05, 0.1, 0.3, 1.0, 3.0])


@st.composite
def _links(draw):
    p0 = draw(st.floats(0.5, 1.5))
    spread = draw(st.sampled_from([0.0, 1e-4, 1e-2, 0.02, 0.3]))
    p = [p0, draw(st.floats(-1, 1)) * spread, draw(st.floats(-1, 1)) * spread]
    axis = [draw(st.floats(-1, 1)) for _ in range(3)]
    if np.linalg.norm(axis) < 1e-3:
        axis = [0.0, 0.0, 1.0]
    return _column(p, draw(_ANGLE), axis, draw(st.floats(0.5, 1.5)), float(draw(st.booleans())))


@settings(max_examples=60, deadline=None)
@given(st.lists(_links(), min_size=1, max_size=40))
def test_single_precision_frames_follow_the_seed_code(columns):
    geom = np.ascontiguousarray(np.array(columns).T)
    single = _core.seed_frames(geom, single=True)
    reference = _core.seed_frames(geom, scalar=True)
    assert np.all(np.isfinite(single))
    # float rounding on O(1) quantities, and the seed's own cancellation near
    # the identity (about 1e-7 relative in double there)
    np.testing.assert_allclose(single, reference, rtol=2e-5, atol=2e-6)


@pytest.mark.parametrize("angle", [1e-6, 1e-4, 3e-3])
@pytest.mark.parametrize("small", [1.0, 0.0])
def test_a_tiny_rotation_survives_single_precision(angle, small):
    # cos(angle / 2) rounds to 1 in float below ~5e-4 rad: the seed's formula
    # 2 sqrt((2 - 2w) / (1 - w^2)) would return 0 there and drop the bend; the
    # float pass uses 2 sqrt(2 / (1 + w)), the same function without the
    # cancellation, so voxel 2's rotation vector keeps its length
    geom = np.ascontiguousarray(np.array([_column((1.0, 0.0, 0.0), angle, (0, 1, 1), 1.0, small)]).T)
    a2 = _core.seed_frames(geom, single=True)[5:8, 0]
    assert np.linalg.norm(a2) == pytest.approx(angle, rel=1e-5)


@pytest.mark.parametrize("angle", [0.1, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0])
@pytest.mark.parametrize("small", [1.0, 0.0])
def test_the_acos_branch_in_float_lanes_gives_the_rotation_angle(angle, small):
    # past ~5.6 degrees the seed's k(w) = 2 acos(w) / sqrt(1 - w^2) (its acos branch):
    # the float lanes take it as 2 / sqrt(1 - z) times asin's polynomial in z = (1 - w) / 2
    # up to 120 degrees (2.09 rad), the double fix-up beyond; either way |a2| is the angle
    geom = np.ascontiguousarray(np.array([_column((1.0, 0.0, 0.0), angle, (1, -2, 0.5), 1.0, small)]).T)
    a2 = _core.seed_frames(geom, single=True)[5:8, 0]
    assert np.linalg.norm(a2) == pytest.approx(angle, rel=1e-6)


def test_cantilever_and_free_fall_hold_in_single_precision():
    # the closed-form cases of test_closed_form.py, same tolerances
    L, E, P = 0.01, 5e6, 0.015
    grid = np.ones((10, 1, 1), dtype=np.int32)
    fixed = np.zeros_like(grid, dtype=bool)
    fixed[0] = True
    body = Body.uniform(grid, youngs_modulus=E, density=1e3, fixed=fixed)
    sim = Simulation(body, SINGLE.replace(gravity=0.0, floor=False, init_time=0.0))
    force = np.zeros((10, 3))
    force[9, 2] = -P
    sim.set_external_force(0, force)
    sim.advance(1.5)
    z = sim.positions(0)[:, 2]
    assert z[0] - z[9] == pytest.approx(P * (9 * L) ** 3 / (3 * E * L**4 / 12), rel=0.03)

    cfg = SINGLE.replace(floor=False, bond_damping=0.0, global_damping=0.0, collision_damping=0.0)
    sim = Simulation(Body.uniform(np.ones((2, 2, 2)), origin=(0.0, 0.0, 1.0)), cfg)
    z0 = sim.center_of_mass()[0, 2]
    sim.advance(1.0)
    drop = z0 - sim.center_of_mass()[0, 2]
    assert drop == pytest.approx(9.81 * sim.time[0] ** 2 / 2, rel=5e-3)


def _bodies():
    cases = cases_from_data(json.loads((DATA / "structured.json").read_text()))
    return [case_design(c, "strong") for c in cases[:3]]


def test_single_precision_is_deterministic():
    designs = _bodies()
    alone = []
    for d in designs:
        sim = Simulation([d], SINGLE, n_threads=1)
        sim.advance(1.2)
        alone.append(sim.all_positions.copy())
    batch = Simulation(designs, SINGLE, n_threads=2)
    batch.advance(1.2)
    for k, pos in enumerate(alone):
        assert np.array_equal(batch.positions(k), pos)
    # resumed from a checkpoint: the same bits as one run
    one = Simulation(designs, SINGLE, n_threads=1)
    one.advance(1.4)
    half = Simulation(designs, SINGLE, n_threads=1)
    half.advance(1.2)
    resumed = Simulation(designs, SINGLE, n_threads=1)
    resumed.set_state(half.get_state())
    resumed.advance(0.2)
    assert np.array_equal(resumed.all_positions, one.all_positions)
    # and it is the single-precision path: while the bodies settle (no drive
    # before init_time) the double one differs, in the last digits
    single = Simulation(designs, SINGLE, n_threads=1)
    double = Simulation(designs, SimConfig(link_precision="double"), n_threads=1)
    single.advance(0.5)
    double.advance(0.5)
    gap = np.abs(double.all_positions - single.all_positions).max()
    assert 0.0 < gap < 1e-8


def test_links_turned_past_120_degrees_take_the_double_fix_up_in_the_step():
    # three voxels turned 130-150 degrees against their neighbours: their links leave the
    # float frames for _seed_frame_one in double (the reference runs never take it). The
    # two precisions then agree to float accuracy, where a fix-up that read stale rows for
    # those links put them 1e-3 apart (a version that kept p1, p2 and n in float only)
    grid = np.full((6, 6, 6), 3, dtype=np.int8)
    grid[3:] = 4
    design = RobotDesign(grid)
    runs = {}
    for prec in ("single", "double"):
        sim = Simulation([design.to_body()], SimConfig(self_collision=True, link_precision=prec),
                         n_threads=1)  # fmt: skip
        state = sim.get_state()
        for v, ax, deg in ((100, 2, 150.0), (40, 0, 130.0), (7, 1, -140.0)):
            q = np.zeros(4)
            q[0], q[1 + ax] = np.cos(np.radians(deg) / 2), np.sin(np.radians(deg) / 2)
            state["quat"][v] = q
        sim.set_state(state)
        sim.advance(40 * float(sim.dt[0]) * 0.999)
        runs[prec] = (sim.positions(0).copy(), sim.orientations(0).copy())
    assert np.abs(runs["single"][0] - runs["double"][0]).max() < 1e-8
    assert np.abs(runs["single"][1] - runs["double"][1]).max() < 1e-6


@given(st.one_of(st.text(max_size=8), st.integers(), st.none(), st.floats(), st.booleans()))
def test_only_the_two_precisions_are_accepted(value):
    if value is None or value in ("double", "single"):
        assert SimConfig(link_precision=value).link_precision == value
    else:
        with pytest.raises(InvalidParameterError, match="link_precision"):
            SimConfig(link_precision=value)
