"""Movable terrain objects, fluid drag, friction and incline: conservation and closed forms."""

from __future__ import annotations

import math

import numpy as np
import pytest

from softgym.engine import Body, SimConfig, Simulation
from softgym.exceptions import InvalidParameterError, InvalidTerrainError
from softgym.terrain import Block, Terrain

L = 0.01
MODELS = ("seed", "corotational")


def _cube(n: int = 3) -> Body:
    return Body.uniform(np.ones((n, n, n)))


def _muscle() -> Body:
    grid = np.ones((4, 4, 3), dtype=np.int32)
    grid[2:] = 2
    return Body(grid=grid, youngs_modulus=[0.0, 5e6, 5e6], density=[0.0, 1e6, 1e6],
                poisson=[0.0, 0.35, 0.35], cte=[0.0, 0.01, -0.01], mu_static=[0.0, 1.0, 1.0],
                mu_kinetic=[0.0, 0.5, 0.5])  # fmt: skip


def _box_world(x: float = 3.5) -> Terrain:
    return Terrain(objects=(Block.box((x, 0.5, 0.0), (2, 2, 2)),), name="box")


@pytest.mark.parametrize("model", MODELS)
def test_momentum_is_conserved_when_an_object_hits_the_robot(model):
    # no floor, no gravity, no global damping: the robot and the block exchange momentum only
    cfg = SimConfig(model=model, gravity=0.0, floor=False, global_damping=0.0)
    sim = Simulation(_cube(), config=cfg, terrain=_box_world(x=4.0), n_threads=1)
    state = sim.get_state()
    n = sim.n_voxels  # the robot's voxels come first, then the block's
    state["vel"][n:, 0] = -0.5  # the block flies at the robot (m/s)
    sim.set_state(state)
    p0 = sim.momentum(objects=True)[0].copy()
    assert np.allclose(sim.momentum()[0], 0.0)
    sim.advance(0.3)
    p1 = sim.momentum(objects=True)[0]
    # (the seed model's float links sum the voxels' link and contact forces in float: their
    # rounding does not cancel between voxels, 4e-9 to 6e-9 of p0 here; double sums 1e-15)
    tol = 1e-9 if cfg.effective_link_precision == "double" else 1e-7
    np.testing.assert_allclose(p1, p0, rtol=0, atol=tol * abs(p0[0]))
    # the robot took part of it: it now moves towards -x
    assert sim.momentum()[0][0] < -0.1 * abs(p0[0])
    assert not sim.diverged[0]


def test_objects_are_not_actuated_and_not_in_the_robots_centre_of_mass():
    sim = Simulation(_muscle(), config=SimConfig(), terrain=_box_world(x=6.0), n_threads=1)
    alone = Simulation(_muscle(), config=SimConfig(), n_threads=1)
    np.testing.assert_array_equal(sim.center_of_mass(), alone.center_of_mass())
    assert sim.n_voxels == alone.n_voxels == 48
    assert sim.object_positions(0).shape == (8, 3)
    sim.advance(1.5)
    np.testing.assert_array_equal(sim.object_scales(0), np.full(8, L))  # never actuated
    assert sim.scales(0).min() < L  # the robot's muscles are
    ro = sim.rollout()
    assert ro.positions.shape == (48, 3) and ro.aux.shape[2] == 10
    np.testing.assert_allclose(ro.aux_final[0, :3], sim.object_positions(0).mean(axis=0))


def test_a_far_object_leaves_the_robot_untouched_in_the_corotational_model():
    cfg = SimConfig.corotational()
    far = Terrain(objects=(Block.box((20.0, 0.0, 0.0), (2, 2, 2)),))
    a = Simulation(_muscle(), config=cfg, terrain=far, n_threads=1).run(1.5)
    b = Simulation(_muscle(), config=cfg, n_threads=1).run(1.5)
    np.testing.assert_array_equal(a.cm, b.cm)
    np.testing.assert_array_equal(a.positions, b.positions)


@pytest.mark.parametrize("model", MODELS)
def test_objects_and_drag_are_bit_identical_across_threads_and_batching(model):
    cfg = SimConfig(model=model, fluid_drag=5e5, gravity=0.0, floor=False)
    worlds = [_box_world(x=4.5), Terrain.flat(), _box_world(x=5.0)]
    bodies = [_muscle(), _muscle(), _muscle()]
    one = Simulation(bodies, config=cfg, terrain=worlds, n_threads=1).run(1.3)
    two = Simulation(bodies, config=cfg, terrain=worlds, n_threads=2).run(1.3)
    alone = Simulation([bodies[2]], config=cfg, terrain=worlds[2], n_threads=1).run(1.3)
    for name in ("cm", "positions", "aux", "aux_final"):
        np.testing.assert_array_equal(getattr(one, name), getattr(two, name), err_msg=name)
    np.testing.assert_array_equal(one.cm[2], alone.cm[0])
    np.testing.assert_array_equal(one.aux[2], alone.aux[0])


def _voxel_sim(model: str, drag: float, **cfg) -> Simulation:
    config = SimConfig(model=model, gravity=0.0, floor=False, global_damping=0.0,
                       fluid_drag=drag, self_collision=False, **cfg)  # fmt: skip
    return Simulation(Body.uniform(np.ones((1, 1, 1))), config=config, n_threads=1)


@pytest.mark.parametrize("model", MODELS)
def test_drag_slows_a_voxel_as_the_closed_form(model):
    # m dv/dt = -k v^2 with k = fluid_drag L^2 (one leading face): v = v0 / (1 + k v0 t / m)
    drag, v0 = 5e5, 0.2
    sim = _voxel_sim(model, drag)
    state = sim.get_state()
    state["vel"][0] = (v0, 0.0, 0.0)
    sim.set_state(state)
    sim.advance(0.5)
    t = float(sim.time[0])
    m = 1e6 * L**3
    expected = v0 / (1.0 + drag * L**2 * v0 * t / m)
    assert sim.velocities(0)[0, 0] == pytest.approx(expected, rel=2e-3)
    assert expected < 0.5 * v0  # the drag mattered


@pytest.mark.parametrize("model", MODELS)
def test_drag_gives_the_closed_form_terminal_velocity(model):
    # a constant force F along +y from rest: v = v_t tanh(t k v_t / m), v_t = sqrt(F / k)
    drag, force = 5e5, 0.02
    k, m = drag * L**2, 1e6 * L**3
    v_t = math.sqrt(force / k)
    sim = _voxel_sim(model, drag)
    sim.set_external_force(0, (0.0, force, 0.0))
    for seconds in (1.0, 6.0):
        sim.advance_to(seconds)
        t = float(sim.time[0])
        assert sim.velocities(0)[0, 1] == pytest.approx(v_t * math.tanh(t * k * v_t / m), rel=2e-3)
    assert sim.velocities(0)[0, 1] == pytest.approx(v_t, rel=1e-4)  # terminal


def test_a_voxel_slides_down_a_frictionless_incline_at_g_sin_theta():
    cfg = SimConfig(incline=20.0, friction=0.0, global_damping=0.0, self_collision=False)
    sim = Simulation(Body.uniform(np.ones((1, 1, 1))), config=cfg, n_threads=1)
    x0 = sim.positions(0)[0, 0]
    sim.advance(0.4)
    t = float(sim.time[0])
    dx = sim.positions(0)[0, 0] - x0
    assert dx == pytest.approx(-0.5 * 9.81 * math.sin(math.radians(20.0)) * t**2, rel=1e-2)


def test_high_friction_holds_a_voxel_on_an_incline_that_ice_does_not():
    def slide(friction):
        cfg = SimConfig(incline=25.0, friction=friction, self_collision=False)
        sim = Simulation(_cube(2), config=cfg, n_threads=1)
        x0 = sim.center_of_mass()[0, 0]
        sim.advance(1.0)
        return sim.center_of_mass()[0, 0] - x0

    assert abs(slide(1.0)) < 0.05 * L  # mu_s = 1 > tan 25 deg
    assert slide(0.1) < -5 * L


def test_typed_errors_for_the_new_settings_and_objects():
    with pytest.raises(InvalidParameterError, match="friction"):
        SimConfig(friction=-1.0)
    with pytest.raises(InvalidParameterError, match="incline"):
        SimConfig(incline=75.0)
    with pytest.raises(InvalidParameterError, match="fluid_drag"):
        SimConfig(fluid_drag=float("nan"))
    with pytest.raises(InvalidTerrainError, match="block shape"):
        Block((0, 0, 0), (0, 1, 1))
    with pytest.raises(InvalidTerrainError, match="overlaps the robot"):
        Simulation(_cube(), terrain=Terrain(objects=(Block.box((1.0, 1.0, 1.0), (1, 1, 1)),)))
    with pytest.raises(InvalidParameterError, match="self_collision"):
        Simulation(_cube(), config=SimConfig(self_collision=False), terrain=_box_world())
    with pytest.raises(InvalidTerrainError, match="box_contact"):
        Terrain(box_contact="sticky")


def test_terrain_objects_round_trip_through_json():
    cells = np.ones((3, 3, 2), dtype=bool)
    cells[1, 1, 0] = False
    t = Terrain(objects=(Block((0.5, -1.5, 2.0), (3, 3, 2), cells, density=2e5),),
                box_contact="surface", floor=False)  # fmt: skip
    back = Terrain.from_json(t.to_json())
    assert back == t and back.objects[0].n_voxels == 17
    assert Terrain.flat().to_dict().keys() == {"schema", "version", "name", "floor", "boxes", "meta"}
