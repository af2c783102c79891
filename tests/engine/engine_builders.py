"""Small builders shared by the engine tests."""

import numpy as np

from softgym.engine import Body


def two_material_body(grid, cte=0.01, E=5e6, density=1e6, **kw):
    """The benchmark's reference robot law: material 1 CTE +cte, material 2 CTE -cte."""
    return Body(
        grid=np.asarray(grid, dtype=np.int32),
        youngs_modulus=[0.0, E, E],
        density=[0.0, density, density],
        poisson=[0.0, 0.35, 0.35],
        cte=[0.0, cte, -cte],
        mu_static=[0.0, 1.0, 1.0],
        mu_kinetic=[0.0, 0.5, 0.5],
        **kw,
    )


def reference_robot(n=6, **kw):
    """A n^3 block, x < n/2 muscle with CTE +0.01, x >= n/2 with CTE -0.01."""
    g = np.ones((n, n, n), dtype=np.int32)
    g[n // 2 :] = 2
    return two_material_body(g, **kw)


def settled_block(mu_s=1.0, mu_k=0.5, terrain=None, z0=0.0, model="seed"):
    """A 2x2x1 block settled for 0.5 s (global damping off: the closed forms have no drag)."""
    from softgym.engine import SimConfig, Simulation

    body = Body.uniform(np.ones((2, 2, 1)), mu_static=mu_s, mu_kinetic=mu_k, origin=(0.0, 0.0, z0))
    cfg = SimConfig(init_time=0.0, global_damping=0.0, model=model)
    sim = Simulation(body, cfg, terrain=terrain)
    sim.advance(0.5)
    return sim


def static_slip(sim, fraction=0.9, mu_s=1.0, seconds=1.0):
    """Largest in-plane drift (m) under a push of `fraction` mu_s N per voxel."""
    m = sim.masses(0)[0]
    x0 = sim.positions(0)[:, :2].copy()
    f = fraction * mu_s * m * 9.81
    sim.set_external_force(0, [0.8 * f, 0.6 * f, 0.0])
    sim.advance(seconds)
    return np.abs(sim.positions(0)[:, :2] - x0).max()


def kinetic_acceleration(sim, force):
    """Mean x acceleration (m/s^2) between 0.1 s and 0.4 s after pushing with `force` per voxel."""
    sim.set_external_force(0, [force, 0.0, 0.0])
    sim.advance(0.1)
    v1, t1 = sim.velocities(0)[:, 0].mean(), sim.time[0]
    sim.advance(0.3)
    v2, t2 = sim.velocities(0)[:, 0].mean(), sim.time[0]
    return (v2 - v1) / (t2 - t1)
