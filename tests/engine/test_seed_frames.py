"""The seed model's vectorised bond-frame pass equals the seed's branchy code.

``_core.seed_frames`` runs the pass the kernel runs (every candidate computed,
one selected, the acos and backward-chord cases redone by the scalar code) or,
with ``scalar=True``, the seed's scalar code for every link. In a build that
does not fuse multiply-adds (the portable one) the two agree bit for bit; in
one that does (x86-64-v3/v4) the compiler fuses the vector loop's and the
scalar code's products in its own way, so they agree to the fusing's rounding:
every branch taken alike (the same NaNs and infinities), values within 1e-10
relative (measured: 2e-12 at most over 120,000 random links).
"""

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from softgym.engine import FUSED_KERNELS, _core, kernel_build


def _assert_same_frames(fast, reference):
    if kernel_build() not in FUSED_KERNELS:
        assert np.array_equal(fast, reference, equal_nan=True)
        return
    assert np.array_equal(np.isfinite(fast), np.isfinite(reference))
    finite = np.isfinite(reference)
    np.testing.assert_allclose(fast[finite], reference[finite], rtol=1e-10, atol=1e-15)
    assert np.array_equal(fast[~finite], reference[~finite], equal_nan=True)

_COORD = st.one_of(
    st.floats(-2.0, 2.0, allow_nan=False),
    st.sampled_from([0.0, -0.0, 1e-12, -1e-12, 1e-3, 0.01, -0.01]),
)


@st.composite
def links(draw):
    """One column of geometry: relative position, orientation, lengths, mode."""
    p = np.array([draw(_COORD) for _ in range(3)])
    if draw(st.booleans()):
        # near-aligned chord, as on a lattice (ratios around the small-ratio cut)
        p[0] = draw(st.floats(0.5, 1.5))
        p[1:] *= draw(st.sampled_from([1e-4, 1e-2, 0.02, 1.0]))
    angle = draw(st.sampled_from([0.0, 1e-4, 0.01, 0.05, 0.1, 0.3, 1.0, 3.0]))
    axis = np.array([draw(st.floats(-1.0, 1.0)) for _ in range(3)])
    norm = np.linalg.norm(axis)
    axis = axis / norm if norm > 1e-6 else np.array([0.0, 0.0, 1.0])
    q = np.concatenate([[np.cos(angle / 2)], np.sin(angle / 2) * axis])
    nominal = draw(st.floats(0.5, 1.5))
    small = float(draw(st.booleans()))
    return np.concatenate([p, q, [nominal, np.linalg.norm(p), small]])


@settings(max_examples=60, deadline=None)
@given(st.lists(links(), min_size=1, max_size=40))
def test_vectorised_pass_equals_the_scalar_seed_code(columns):
    geom = np.ascontiguousarray(np.array(columns).T)
    fast = _core.seed_frames(geom)
    reference = _core.seed_frames(geom, scalar=True)
    assert fast.shape == (11, geom.shape[1])
    _assert_same_frames(fast, reference)


def test_every_branch_of_the_pass_is_exercised_and_equal():
    # small angle; large angle with small ratios, with a tilted chord, with
    # rotations past the seed's acos cut (~5.6 degrees), a backward chord and a
    # zero chord: each once, in one call (one vector block)
    rng = np.random.default_rng(3)
    cols = []
    for p, angle, small in [
        ((1.0, 0.001, -0.002), 0.005, 1.0),
        ((1.0, 0.001, -0.002), 0.005, 0.0),
        ((1.0, 0.3, -0.2), 0.05, 0.0),
        ((1.0, 0.3, -0.2), 0.8, 0.0),
        ((-1.0, 0.1, 0.05), 0.2, 0.0),
        ((-1.0, 0.0, 0.0), 0.2, 0.0),
        ((0.0, 0.0, 0.0), 0.1, 0.0),
        ((0.9, 0.02, 0.0), 2.5, 0.0),
    ]:
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        q = [np.cos(angle / 2), *(np.sin(angle / 2) * axis)]
        cols.append([*p, *q, 1.0, float(np.linalg.norm(p)), small])
    geom = np.ascontiguousarray(np.array(cols).T)
    fast = _core.seed_frames(geom)
    reference = _core.seed_frames(geom, scalar=True)
    _assert_same_frames(fast, reference)
    # the large-angle rows moved off the identity frame where the chord is tilted
    assert fast[8, 2] < 1.0 and fast[8, 3] < 1.0
    # a tilted backward chord turns the frame by nearly pi (rw = cos(th / 2)
    # small); an exactly backward one passes the seed's small-ratio test
    # (p1 / p0 = 0) and keeps the identity frame
    assert 0.0 < fast[8, 4] < 0.2
    assert fast[8, 5] == 1.0
    # a small-angle link keeps its offsets in voxel 1's frame: P1, P2 = p1, p2
    assert (fast[1, 0], fast[2, 0]) == (0.001, -0.002)


def _mixed_geometry(n, seed, small_share=0.4):
    """n links of every kind the float pass meets: small-angle links (a share
    small_share); large-angle links with chords along the axis (the small-ratio frame),
    tilted, backward or zero; turns from none to past 120 degrees (the double-precision
    fix-up)."""
    rng = np.random.default_rng(seed)
    kind = rng.integers(0, 6, n)
    strain = rng.uniform(-0.3, 0.3, n)
    off = np.select([kind == 0, kind == 1, kind == 2],
                    [rng.uniform(0, 0.02, n), rng.uniform(0, 0.3, n), rng.uniform(1.5, 3.1, n)],
                    rng.uniform(0, 0.05, n))  # fmt: skip
    phi = rng.uniform(0.0, 2 * np.pi, n)
    length = 0.01 * (1.0 + strain)
    p = np.stack([length * np.cos(off), length * np.sin(off) * np.cos(phi),
                  length * np.sin(off) * np.sin(phi)])  # fmt: skip
    p[:, kind == 5] = 0.0
    angle = np.select([kind == 3, kind == 4], [rng.uniform(0, 0.01, n), rng.uniform(1.5, 3.0, n)],
                      rng.uniform(0.0, 0.6, n))  # fmt: skip
    axis = rng.normal(size=(3, n))
    axis /= np.linalg.norm(axis, axis=0)
    q = np.vstack([np.cos(angle / 2), axis * np.sin(angle / 2)])
    small = (rng.random(n) < small_share).astype(float)
    return np.ascontiguousarray(
        np.vstack([p, q, np.full(n, 0.01), np.linalg.norm(p, axis=0), small]))


def test_single_precision_pass_pairs_of_blocks_equal_its_loop():
    # The float pass takes a chunk's mixed links in pairs of blocks (softgym_seed_frames32_x2,
    # its multiply-adds written out: 2 x 16 lanes with AVX-512, 2 x 8 with AVX2) and the
    # rest in the compiler's loop: a chunk of 64 links goes through the pairs, one of 28
    # through the loop (AVX-512) or a pair and the loop (AVX2). Their results are the same
    # bits, link by link (elsewhere, and for chunks all in small-angle mode, both are the
    # loop).
    for seed in range(4):
        for small_share in (0.4, 1.0):
            geom = _mixed_geometry(64, seed, small_share)
            both = _core.seed_frames(geom, single=True)
            for lo in (0, 32):
                part = _core.seed_frames(np.ascontiguousarray(geom[:, lo:lo + 28]),
                                         single=True)
                assert np.array_equal(both[:, lo:lo + 28].view(np.uint64),
                                      part.view(np.uint64))
