"""Momentum and energy: conservation without external forces, dissipation with damping."""

import numpy as np
import pytest
from engine_builders import reference_robot

from softgym.engine import SimConfig, Simulation


@pytest.mark.parametrize("precision", ["double", "single"])
def test_linear_momentum_constant_while_muscles_actuate(precision):
    # No gravity, floor or global damping: internal forces cancel pairwise (the two
    # muscles differ only in CTE, so voxel 2 of a link between them takes exactly -F1 as
    # in the seed's own arithmetic), so the total momentum keeps its initial value: to
    # 1e-9 relative with double links, whose forces are summed in double; with float
    # links each voxel's sum of its links' forces is a float sum (their turn to the world
    # and sums in float, issue 29), whose rounding does not cancel between voxels: 2e-8
    # to 8e-8 relative after 1 s for 3^3 to 6^3 bodies (the AVX-512 and portable builds),
    # held to 3e-7 (a force that did not cancel would be off by its whole size).
    cfg = SimConfig(gravity=0.0, floor=False, global_damping=0.0, init_time=0.0,
                    actuation="symmetric", link_precision=precision)
    sim = Simulation(reference_robot(4), cfg)
    state = sim.get_state()
    state["vel"] = state["vel"] + np.array([0.03, -0.02, 0.01])
    sim.set_state(state)
    p0 = sim.momentum()[0].copy()
    scale = np.linalg.norm(p0)
    for _ in range(10):
        sim.advance(0.1)
        # the muscles really move the body
        assert np.abs(sim.velocities(0) - sim.velocities(0).mean(axis=0)).max() > 1e-4
        tol = 1e-9 if precision == "double" else 3e-7
        np.testing.assert_allclose(sim.momentum()[0], p0, rtol=0, atol=tol * scale)


@pytest.mark.parametrize("model", ["seed", "corotational"])
@pytest.mark.parametrize("floor", [False, True])
def test_energy_never_increases_with_damping_and_no_actuation(floor, model):
    # Actuation off (CTE 0), damping on: the mechanical energy sampled every
    # 1 ms never increases (tolerance 1e-9 of the initial energy for rounding).
    # The seed model damps finite differences of the links' bond-frame state,
    # remembered from the previous step: its bodies start from a consistent
    # state (velocities only), the corotational model's also from displaced
    # positions.
    rng = np.random.default_rng(0)
    cfg = SimConfig(floor=floor, gravity=9.81 if floor else 0.0, model=model)
    sim = Simulation(reference_robot(4, cte=0.0), cfg)
    state = sim.get_state()
    mass = sim.masses(0)
    state["vel"] = rng.normal(0.0, 0.05, (mass.size, 3))
    state["angvel"] = rng.normal(0.0, 0.06, (mass.size, 3))
    if model == "corotational":
        state["pos"] = state["pos"] + rng.normal(0.0, 2e-4, state["pos"].shape)
    sim.set_state(state)
    energies = [sim.energy()[0].sum()]
    for _ in range(400):
        sim.advance(0.001)
        energies.append(sim.energy()[0].sum())
    energies = np.array(energies)
    kinetic0 = 0.5 * (mass[:, None] * state["vel"] ** 2).sum()
    assert energies[0] - energies[-1] > 0.5 * kinetic0  # damping really dissipates
    assert np.all(np.diff(energies) <= 1e-9 * energies[0])
