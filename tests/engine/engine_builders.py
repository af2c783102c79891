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
