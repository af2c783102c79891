"""The engine against closed-form mechanics (tolerances stated per test)."""

import numpy as np
import pytest
from engine_builders import kinetic_acceleration, settled_block, static_slip

from softgym.engine import Body, SimConfig, Simulation

NO_WORLD = dict(gravity=0.0, floor=False)


def test_cantilever_tip_deflection_within_3_percent():
    # 10 voxels in a row along x, voxel 0 clamped, tip load P along -z, no gravity.
    # Euler-Bernoulli: delta = P l^3 / (3 E I), l = 9 L (clamped centre to tip centre),
    # I = L^4 / 12. Tolerance: 3 % (the 2015 Voxelyze library gets 1.9 %).
    L, E = 0.01, 5e6
    grid = np.ones((10, 1, 1), dtype=np.int32)
    fixed = np.zeros_like(grid, dtype=bool)
    fixed[0] = True
    body = Body.uniform(grid, youngs_modulus=E, density=1e3, fixed=fixed)
    sim = Simulation(body, SimConfig(**NO_WORLD, init_time=0.0))
    P = 0.015
    force = np.zeros((10, 3))
    force[9, 2] = -P
    sim.set_external_force(0, force)
    sim.advance(1.5)
    z = sim.positions(0)[:, 2]
    deflection = z[0] - z[9]
    ell = 9 * L
    expected = P * ell**3 / (3 * E * L**4 / 12)
    assert deflection == pytest.approx(expected, rel=0.03)
    # and it is static: another 0.2 s changes it by < 0.1 %
    sim.advance(0.2)
    z2 = sim.positions(0)[:, 2]
    assert (z2[0] - z2[9]) == pytest.approx(deflection, rel=1e-3)


@pytest.mark.parametrize("shape", [(4, 1, 1), (3, 3, 3)])
def test_free_thermal_expansion_within_0_1_percent(shape):
    # An unconstrained block at uniform temperature T: span = n L (1 + CTE T), 0.1 %.
    L, cte, T = 0.01, 0.01, 8.0
    grid = np.ones(shape, dtype=np.int32)
    body = Body.uniform(grid, cte=cte, density=1e3)
    sim = Simulation(body, SimConfig(**NO_WORLD, actuation="symmetric", global_damping=0.05))
    sim.set_temperature(0, np.full(shape, T))
    sim.advance(0.3)
    pos = sim.positions(0)
    size = L * (1 + cte * T)
    for ax, n in enumerate(shape):
        span = pos[:, ax].max() - pos[:, ax].min() + size
        assert span == pytest.approx(n * L * (1 + cte * T), rel=1e-3)


def test_free_fall_within_0_5_percent():
    # No floor, no damping: z(t) = z0 - g t^2 / 2 within 0.5 %.
    cfg = SimConfig(floor=False, bond_damping=0.0, global_damping=0.0, collision_damping=0.0)
    body = Body.uniform(np.ones((2, 2, 2)), origin=(0.0, 0.0, 1.0))
    sim = Simulation(body, cfg)
    z0 = sim.center_of_mass()[0, 2]
    t = 1.0
    sim.advance(t)
    drop = z0 - sim.center_of_mass()[0, 2]
    assert drop == pytest.approx(9.81 * sim.time[0] ** 2 / 2, rel=5e-3)


def test_static_friction_holds_below_threshold():
    # F = 0.9 mu_s N: the block does not slide (< 1e-6 m in 1 s).
    assert static_slip(settled_block()) < 1e-6


def test_kinetic_friction_acceleration_within_2_percent():
    # F = 1.5 mu_s N: a = (F - mu_k N) / m within 2 %.
    mu_s, mu_k = 1.0, 0.5
    sim = settled_block(mu_s, mu_k)
    m = sim.masses(0)[0]
    N = m * 9.81
    F = 1.5 * mu_s * N
    assert kinetic_acceleration(sim, F) == pytest.approx((F - mu_k * N) / m, rel=0.02)


def test_block_settles_on_floor_at_rest():
    # A 6^3 soft block comes to rest on the floor under gravity, bottom near z = L/2.
    sim = Simulation(Body.uniform(np.ones((6, 6, 6))))
    sim.advance(1.0)
    v = sim.velocities(0)
    assert np.abs(v).max() < 1e-3
    z = sim.positions(0)[:, 2]
    assert z.min() == pytest.approx(0.005, abs=0.0015)
