"""The seed model's orientation step: q + (w dt / 2) x q, renormalised.

The seed renormalises with a square root and a division, which softgym keeps with
double-precision links (the seed's own operations). With single-precision links (the
default) it takes two Newton steps of 1 / sqrt from 1 where |q|^2 is within 2^-14 of 1
(softgym/engine/include/softgym_orient.h), whose error is then far below the pair's
rounding, and the seed's square root and division further out (a voxel turning faster than
about 24 rad/s at the seed's time step). Both are checked here against the formula in
numpy, on voxels spinning from rest to far past the Newton steps' range: two steps from 1
alone would leave those off unit length by 1e-9 to 1e-3, and steps from 1 diverge for
|q|^2 >= 3.
"""

import numpy as np
import pytest

from softgym.engine import Body, SimConfig, Simulation


def _plate(link_precision=None):
    # voxels with no neighbour (a checkerboard): no link turns them, so each spins at its rate
    grid = np.zeros((9, 9, 1), dtype=np.int32)
    grid[::2, ::2] = 1
    grid[1::2, 1::2] = 1
    body = Body(grid=grid, youngs_modulus=[0.0, 5e6], density=[0.0, 1e3], poisson=[0.0, 0.35],
                cte=[0.0, 0.0], mu_static=[0.0, 1.0], mu_kinetic=[0.0, 0.5],
                origin=(0.0, 0.0, 0.05))
    return Simulation([body], SimConfig(model="seed", link_precision=link_precision),
                      n_threads=1)


def _seed_quat_step(q, w, dt):
    """The seed's step in float64 (its square root and division), voxel by voxel."""
    h = 0.5 * dt * w
    qw = q[:, 0] - h[:, 0] * q[:, 1] - h[:, 1] * q[:, 2] - h[:, 2] * q[:, 3]
    qx = q[:, 1] + h[:, 0] * q[:, 0] + h[:, 1] * q[:, 3] - h[:, 2] * q[:, 2]
    qy = q[:, 2] + h[:, 1] * q[:, 0] + h[:, 2] * q[:, 1] - h[:, 0] * q[:, 3]
    qz = q[:, 3] + h[:, 2] * q[:, 0] + h[:, 0] * q[:, 2] - h[:, 1] * q[:, 1]
    out = np.stack([qw, qx, qy, qz], axis=1)
    s = (out**2).sum(axis=1)
    out /= np.sqrt(s)[:, None]
    return out, s


@pytest.mark.parametrize("link_precision", ["single", "double"])
def test_the_renormalised_quaternions_are_the_seeds_near_and_far_from_unit_length(
        link_precision):
    sim = _plate(link_precision)
    dt = float(sim.dt[0])
    rng = np.random.default_rng(3)
    state = sim.get_state()
    n = state["quat"].shape[0]
    # turned voxels (not the identity) spinning at rates up to |w dt / 2| = 1
    axis = rng.normal(size=(n, 3))
    axis /= np.linalg.norm(axis, axis=1)[:, None]
    angle = rng.uniform(0.1, 2.0, n)
    state["quat"] = np.hstack([np.cos(angle / 2)[:, None], axis * np.sin(angle / 2)[:, None]])
    rate = np.geomspace(1e-4, 2.0, n) / dt
    rng.shuffle(rate)
    spin = rng.normal(size=(n, 3))
    state["angvel"] = spin / np.linalg.norm(spin, axis=1)[:, None] * rate[:, None]
    sim.set_state(state)
    q0 = sim.get_state()["quat"].copy()
    sim.advance(dt)
    after = sim.get_state()
    assert int(after["steps"][0]) == 1
    expect, s = _seed_quat_step(q0, after["angvel"], dt)
    near = np.abs(s - 1.0) <= 2.0**-14
    assert near.sum() >= 8 and (~near).sum() >= 8  # both ranges, in vector blocks
    assert (s[~near] > 1.1).sum() >= 4  # and past where two steps from 1 leave 1e-3
    got = after["quat"]
    np.testing.assert_allclose(got, expect, rtol=0, atol=4e-16)
    np.testing.assert_allclose(np.linalg.norm(got, axis=1), 1.0, rtol=0, atol=4e-16)


@pytest.mark.parametrize("link_precision", ["single", "double"])
def test_a_voxel_turned_back_to_the_identity_snaps_to_it(link_precision):
    # the seed snaps a renormalised quaternion whose w reaches 1 to the identity; a voxel at
    # rest stays exactly there (no Newton step leaves it off by an ulp)
    sim = _plate(link_precision)
    sim.advance(float(sim.dt[0]) * 3)
    q = sim.get_state()["quat"]
    w = sim.get_state()["angvel"]
    still = np.all(w == 0.0, axis=1)
    assert np.array_equal(q[still], np.tile([1.0, 0.0, 0.0, 0.0], (still.sum(), 1)))
