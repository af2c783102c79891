import json
import math
from functools import cache

import numpy as np
import pytest

from softgym.engine.rollout import Rollout
from softgym.exceptions import InvalidParameterError
from softgym.metrics.novelty import (
    NO_TRAJECTORY_NOVELTY,
    NoveltyArchive,
    amss,
    amss_matrix,
    novelty_scores,
    similarity_matrix,
    traces_from_rollout,
    trajectory_vectors,
)


def trace(points, dt=0.0):
    """(x, y) points -> (n, 4) trace with z = 0 and t = k * dt."""
    p = np.asarray(points, dtype=float)
    return np.column_stack([p[:, 0], p[:, 1], np.zeros(len(p)), dt * np.arange(len(p))])


def random_walk(rng, n=40, step=0.003, t0=1.0, dt=0.1):
    xyz = np.cumsum(rng.normal(0, step, (n, 3)), axis=0)
    return np.column_stack([xyz, t0 + dt * np.arange(n)])


def reference_amss(a, b):
    """The seed's recursion, literally (0-based, A = 0 outside)."""
    u, v = trajectory_vectors(a), trajectory_vectors(b)

    def s(i, j):
        nu, nv = np.linalg.norm(u[i]), np.linalg.norm(v[j])
        c = float(u[i] @ v[j] / (nu * nv))
        return c if c >= 0 else 0.0

    @cache
    def A(i, j):
        if i < 0 or j < 0:
            return 0.0
        v0 = 2 * s(i, j) + (A(i - 1, j - 1) if i >= 1 and j >= 1 else 0.0)
        v1 = (
            s(i, j)
            + (2 * s(i - 1, j) if i >= 1 else 0.0)
            + (A(i - 2, j - 1) if i >= 2 and j >= 1 else 0.0)
        )
        v2 = (
            s(i, j)
            + (2 * s(i, j - 1) if j >= 1 else 0.0)
            + (A(i - 1, j - 2) if i >= 1 and j >= 2 else 0.0)
        )
        return max(v0, v1, v2)

    return A(len(u) - 1, len(v) - 1)


def rotate_translate(tr, angle, shift):
    c, s = math.cos(angle), math.sin(angle)
    out = tr.copy()
    out[:, 0] = c * tr[:, 0] - s * tr[:, 1] + shift[0]
    out[:, 1] = s * tr[:, 0] + c * tr[:, 1] + shift[1]
    return out


# ---------------------------------------------------------------- trajectory & similarity


def test_trajectory_rotates_by_the_first_heading_then_differences():
    tr = trace([(1, 1), (1, 3), (0, 3)], dt=0.5)
    v = trajectory_vectors(tr)
    # heading +y -> rotated onto +x; the next step (-1, 0) becomes (0, +1)
    assert np.allclose(v, [[2, 0, 0, 0.5], [0, 1, 0, 0.5]])
    with pytest.raises(InvalidParameterError, match="at least 2 points"):
        trajectory_vectors(tr[:1])
    with pytest.raises(InvalidParameterError, match=r"shape \(n_points, 4\)"):
        trajectory_vectors(np.zeros((5, 3)))
    with pytest.raises(InvalidParameterError, match="non-finite"):
        trajectory_vectors(np.full((3, 4), np.nan))


def test_similarity_is_cosine_or_zero():
    u = [[1, 0, 0, 0], [1, 1, 0, 0], [0, 0, 0, 0]]
    v = [[1, 0, 0, 0], [-1, 0.5, 0, 0], [0, 1, 0, 0]]
    S = similarity_matrix(u, v)
    assert S[0].tolist() == [1.0, 0.0, 0.0]
    assert S[1] == pytest.approx([1 / math.sqrt(2), 0.0, 1 / math.sqrt(2)])
    assert S[2].tolist() == [0.0, 0.0, 0.0]  # a zero vector is similar to nothing


# ---------------------------------------------------------------- AMSS by hand


def test_amss_single_vectors_include_time():
    # vectors (3, 0, 0, 4) and (0, 0, 0, 1): cos = 4/5, A(0, 0) = 2 s
    a = np.array([[0, 0, 0, 0], [3, 0, 0, 4]], dtype=float)
    b = np.array([[5, 5, 0, 0], [5, 5, 0, 1]], dtype=float)
    assert amss(a, b) == pytest.approx(1.6)
    assert amss(a, b, "normalized") == pytest.approx(0.8)


def test_amss_two_by_two_by_hand():
    # a: +x then +x; b: +x then +y  ->  s = [[1, 0], [1, 0]]
    # A00 = 2, A01 = 0 + 2*1 = 2, A10 = 1 + 2*1 = 3, A11 = max(0 + 2, 0 + 0, 0 + 2*1) = 2
    a = trace([(0, 0), (1, 0), (2, 0)])
    b = trace([(0, 0), (1, 0), (1, 1)])
    assert amss(a, b) == pytest.approx(2.0)
    assert amss(a, b, variant="normalized") == pytest.approx(0.5)


def test_amss_with_rotation_by_hand():
    # a: (1,0) then (1,1); b heads +y first, so after rotation: (1,0) then (0,1)
    # s = [[1, 0], [1/sqrt2, 1/sqrt2]]: A00 = 2, A01 = 2, A10 = 1/sqrt2 + 2,
    # A11 = max(2/sqrt2 + A00, 1/sqrt2 + 0, 1/sqrt2 + 2/sqrt2) = 2 + sqrt2
    a = trace([(0, 0), (1, 0), (2, 1)])
    b = trace([(0, 0), (0, 1), (-1, 1)])
    assert amss(a, b) == pytest.approx(2 + math.sqrt(2))
    assert amss(b, a) == pytest.approx(2 + math.sqrt(2))


def test_amss_opposite_steps_score_zero():
    a = trace([(0, 0), (1, 0), (0, 0)])  # forward then back
    b = trace([(0, 0), (1, 0), (2, 0)])
    # s = [[1, 1], [0, 0]]: A11 = max(0 + A00=2, 0 + 2*s01=2, 0 + 2*s10=0) = 2
    assert amss(a, b) == pytest.approx(2.0)


def test_amss_matches_the_seed_recursion():
    rng = np.random.default_rng(0)
    for n1, n2 in [(2, 2), (3, 7), (9, 4), (12, 12)]:
        a, b = random_walk(rng, n1), random_walk(rng, n2)
        assert amss(a, b) == pytest.approx(reference_amss(a, b), rel=1e-12)


# ---------------------------------------------------------------- properties


def test_invariant_to_xy_rotation_and_translation():
    rng = np.random.default_rng(1)
    a, b = random_walk(rng), random_walk(rng, 31)
    base = amss(a, b)
    for angle, shift in [(0.3, (0.5, -2.0)), (math.pi, (0.0, 0.0)), (-2.0, (10.0, 3.0))]:
        assert amss(rotate_translate(a, angle, shift), b) == pytest.approx(base, rel=1e-12)
        assert amss(a, rotate_translate(b, -angle, shift)) == pytest.approx(base, rel=1e-12)


def test_self_similarity_is_the_maximum():
    rng = np.random.default_rng(2)
    a = random_walk(rng, 40)
    assert amss(a, a) == pytest.approx(2 * 39)
    assert amss(a, a, "normalized") == pytest.approx(1.0)
    for _ in range(20):
        b = random_walk(rng, 40)
        assert amss(a, b) <= amss(a, a) + 1e-12
        assert 0.0 <= amss(a, b, "normalized") <= 1.0 + 1e-12
    # normalisation makes a trace and its own prefix comparable
    assert amss(a, a[:21], "normalized") <= 1.0


def test_unknown_variant():
    a = trace([(0, 0), (1, 0)])
    with pytest.raises(InvalidParameterError, match="unknown AMSS variant"):
        amss(a, a, variant="paper")


# ---------------------------------------------------------------- matrix


def test_amss_matrix_matches_pairs_with_mixed_lengths_and_missing_traces():
    rng = np.random.default_rng(3)
    trajs = [
        random_walk(rng, 8),
        None,
        random_walk(rng, 5),
        random_walk(rng, 1),
        random_walk(rng, 12),
    ]
    for variant in ("seed", "normalized"):
        M = amss_matrix(trajs, variant=variant)
        assert M.shape == (5, 5)
        assert np.isnan(M[1]).all() and np.isnan(M[:, 3]).all()
        for i in (0, 2, 4):
            for j in (0, 2, 4):
                assert M[i, j] == pytest.approx(amss(trajs[i], trajs[j], variant), rel=1e-12)
    others = [random_walk(rng, 6), random_walk(rng, 20)]
    C = amss_matrix(trajs, others)
    assert C.shape == (5, 2)
    assert C[4, 1] == pytest.approx(amss(trajs[4], others[1]))
    assert amss_matrix([]).shape == (0, 0)


# ---------------------------------------------------------------- novelty scores


def straight(direction, n=9, speed=0.002, jitter=0.0, rng=None):
    d = np.asarray(direction, dtype=float) / np.linalg.norm(direction)
    steps = np.outer(np.arange(n), d * speed)
    if jitter:
        steps = steps + rng.normal(0, jitter, steps.shape)
    return np.column_stack([steps, np.zeros(n), 1.0 + 0.5 * np.arange(n)])


def zigzag(n=9):
    pts = [(0.3 * k, 0.3 * (k % 2)) for k in range(n)]
    return np.column_stack([np.asarray(pts), np.zeros(n), 1.0 + 0.5 * np.arange(n)])


def test_seed_novelty_sums_similarity_including_self():
    rng = np.random.default_rng(5)
    trajs = [straight((1, 0), jitter=1e-4, rng=rng) for _ in range(4)] + [zigzag(), None]
    scores = novelty_scores(trajs)
    M = amss_matrix(trajs[:5])
    assert scores[:5] == pytest.approx(M.sum(axis=1))
    assert scores[5] == NO_TRAJECTORY_NOVELTY
    assert int(np.argmin(scores)) == 4  # the zigzag is the most novel
    with pytest.raises(InvalidParameterError, match="no archive"):
        novelty_scores(trajs, archive=NoveltyArchive())
    with pytest.raises(InvalidParameterError, match="unknown novelty method"):
        novelty_scores(trajs, "random")


def test_knn_novelty_by_hand():
    a = straight((1, 0))
    b = zigzag()
    trajs = [a, a.copy(), b, None]
    scores = novelty_scores(trajs, "knn", k=1)
    M = amss_matrix(trajs, variant="normalized")
    assert scores[0] == pytest.approx(1.0)  # its twin is its nearest neighbour
    assert scores[2] == pytest.approx(M[2, 0])
    assert scores[3] == NO_TRAJECTORY_NOVELTY
    assert novelty_scores([a], "knn") == pytest.approx([0.0])  # nobody to compare with


def test_archive_remembers_past_behaviours():
    """The seed's "pattern loops": a behaviour that left the population looks novel again.

    With an archive it does not.
    """
    a, b = straight((1, 0)), zigzag()
    archive = NoveltyArchive(k=1, n_add=1)
    archive.update([a, a.copy()])  # generation 1 explores "a"
    assert len(archive) == 1
    later = [b, a]  # generation 5: "a" comes back
    without = novelty_scores(later, "knn", k=1)
    with_archive = archive.score(later)
    assert with_archive[1] == pytest.approx(1.0)
    assert with_archive[1] > without[1]
    assert with_archive[0] == pytest.approx(without[0])


def test_archive_update_order_size_and_json():
    trajs = [straight((1, 0)), zigzag(), None, straight((0, 1), n=5)]
    arch = NoveltyArchive(k=2, n_add=2, max_size=3)
    scores = arch.update(trajs, scores=[0.5, 0.1, NO_TRAJECTORY_NOVELTY, 0.1])
    assert scores.tolist() == [0.5, 0.1, NO_TRAJECTORY_NOVELTY, 0.1]
    assert [len(t) for t in arch.traces] == [9, 5]  # the two lowest scores, ties by index
    arch.update(trajs, scores=[0.0, 1.0, 1.0, 2.0])
    assert len(arch) == 3  # trimmed to max_size, oldest first
    again = NoveltyArchive.from_dict(json.loads(json.dumps(arch.to_dict())))
    assert len(again) == 3 and all(np.array_equal(x, y) for x, y in zip(again.traces, arch.traces))
    assert again.score(trajs) == pytest.approx(arch.score(trajs))
    with pytest.raises(InvalidParameterError, match="scores must have shape"):
        arch.update(trajs, scores=[1.0])
    with pytest.raises(InvalidParameterError):
        NoveltyArchive(k=0)


def test_traces_from_rollout():
    n, m = 2, 5
    times = np.tile(np.arange(m) * 0.5, (n, 1))
    cm = np.random.default_rng(6).normal(size=(n, m, 3))
    r = Rollout(
        times=times,
        cm=cm,
        cm_init=cm[:, 2],
        init_reached=np.ones(n, bool),
        cm_final=cm[:, -1],
        positions=np.zeros((n, 3)),
        orientations=np.zeros((n, 4)),
        voxel_offsets=np.arange(n + 1),
        grid_index=np.zeros((n, 3), dtype=np.int64),
        dt=np.full(n, 1e-3),
        steps=np.full(n, 2000),
        time=np.full(n, 2.0),
        diverged=np.array([False, True]),
        diverged_time=np.array([np.inf, 1.2]),
        mass=np.ones(n),
        voxel_size=0.01,
        init_time=1.0,
        trace_interval=0.5,
    )
    tr = traces_from_rollout(r)
    assert tr[1] is None
    assert tr[0].shape == (3, 4) and tr[0][:, 3].tolist() == [1.0, 1.5, 2.0]
    assert np.array_equal(tr[0][:, :3], cm[0, 2:])
    assert traces_from_rollout(r, since=0.0)[0].shape == (5, 4)
    assert novelty_scores(tr)[1] == NO_TRAJECTORY_NOVELTY


# ---------------------------------------------------------------- time weighting


def test_time_scale_weights_the_time_component():
    tr = trace([(0, 0), (0.001, 0), (0.002, 0.001)], dt=0.5)
    assert trajectory_vectors(tr, time_scale=0.02)[:, 3] == pytest.approx([0.01, 0.01])
    assert trajectory_vectors(tr, time_scale=0.0)[:, 3].tolist() == [0.0, 0.0]
    with pytest.raises(InvalidParameterError, match="time_scale"):
        trajectory_vectors(tr, time_scale=-1.0)
    # same path walked at different pace: identical without time, different with it
    slow = tr.copy()
    slow[:, 3] *= 3.0
    assert amss(tr, slow, "normalized", time_scale=0.0) == pytest.approx(1.0)
    assert amss(tr, slow, "normalized") < 1.0


def test_time_dominates_the_seed_similarity_unless_scaled():
    # millimetre steps 0.5 s apart: with the seed's weighting a straight walk and a
    # zigzag look almost identical; with time_scale=0 they do not
    walk = straight((1, 0), n=9, speed=0.002)
    zig = np.column_stack(
        [0.002 * np.arange(9), 0.002 * (np.arange(9) % 2), np.zeros(9), 1.0 + 0.5 * np.arange(9)]
    )
    assert amss(walk, zig, "normalized") > 0.99
    assert amss(walk, zig, "normalized", time_scale=0.0) < 0.8
    seed0 = novelty_scores([walk, zig, walk.copy()], time_scale=0.0)
    seed1 = novelty_scores([walk, zig, walk.copy()])
    assert seed0[1] < seed0[0] and not np.allclose(seed0, seed1)
    arch = NoveltyArchive(time_scale=0.0)
    again = NoveltyArchive.from_dict(json.loads(json.dumps(arch.to_dict())))
    assert again.time_scale == 0.0
    assert arch.score([walk, zig]) == pytest.approx(
        novelty_scores([walk, zig], "knn", time_scale=0.0)
    )
