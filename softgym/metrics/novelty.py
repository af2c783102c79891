"""Trajectory similarity (AMSS) and novelty scores (the seed study).

A *trace* is a robot's centre-of-mass samples, an array of shape
(n_points, 4) holding (x, y, z, t) in metres and seconds
(``Rollout.trace``). The seed turns it into a *trajectory*:

1. ``theta = atan2(y1 - y0, x1 - x0)`` of the first two points;
2. every point's (x, y) is rotated by ``-theta``:
   ``(x', y') = (x cos theta + y sin theta, -x sin theta + y cos theta)``;
3. successive differences of the full 4-vectors give n_points - 1 vectors
   ``(dx, dy, dz, dt)``; ``dt`` stays in, as in the seed.

Two trajectories ``u`` (n1 vectors) and ``v`` (n2 vectors) are compared with
``s(i, j) = max(0, cos angle(u_i, v_j))`` (the cosine if the angle is at most
pi/2, else 0; 0 if either vector is zero) and the seed's dynamic programme,
0-based, with ``A(i, j) = 0`` for ``i < 0`` or ``j < 0``::

    A(i, j) = max(2 s(i, j)                + A(i-1, j-1),
                  s(i, j) + 2 s(i-1, j)    + A(i-2, j-1),
                  s(i, j) + 2 s(i, j-1)    + A(i-1, j-2))

with ``s`` = 0 outside the trajectories. ``variant="seed"`` returns
``A(n1-1, n2-1)`` unnormalised (a trajectory compared with itself scores
``2 n``); ``variant="normalized"`` divides by ``n1 + n2``, the total weight
of any full matching path, so the score lies in [0, 1], a trajectory scores
1 against itself, and traces of different lengths compare fairly.

The time component dominates the seed's similarity: with samples 0.5 s
apart and displacements of millimetres, every vector points almost along
the time axis and all trajectories look alike. ``time_scale`` (m/s,
default 1 = the seed) weights the time component before the cosine;
``time_scale=0`` compares the spatial path only, and a value near the
robots' typical speed (e.g. 0.01 m/s) balances the two.

A trace with fewer than 2 points has no trajectory: :func:`amss` raises,
:func:`amss_matrix` puts NaN in its row and column, and the novelty scores
give it :data:`NO_TRAJECTORY_NOVELTY` (the seed's 1e7 for individuals without
a trajectory).

Both novelty scores are similarities: **lower means more novel**, and the
seed keeps the individuals with the smallest scores.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from softgym.exceptions import InvalidParameterError

if TYPE_CHECKING:  # only for annotations: softgym.engine's __init__ loads compiled code
    from softgym.engine.rollout import Rollout

__all__ = [
    "NO_TRAJECTORY_NOVELTY",
    "NoveltyArchive",
    "amss",
    "amss_matrix",
    "novelty_scores",
    "similarity_matrix",
    "traces_from_rollout",
    "trajectory_vectors",
]

#: Novelty score of an individual without a trajectory (the seed's value; such individuals are dropped first).
NO_TRAJECTORY_NOVELTY = 1e7

_VARIANTS = ("seed", "normalized")
_CHUNK_ELEMENTS = 4_000_000  # DP working set per chunk of pairs (float64 elements)


def _check_variant(variant: str) -> str:
    if variant not in _VARIANTS:
        raise InvalidParameterError(
            f"unknown AMSS variant {variant!r}; expected one of {_VARIANTS}"
        )
    return variant


def _check_time_scale(time_scale: float) -> float:
    v = float(time_scale)
    if not (np.isfinite(v) and v >= 0):
        raise InvalidParameterError(f"time_scale must be a finite value >= 0, got {time_scale!r}")
    return v


def _as_trace(trace: Any, name: str = "trace") -> np.ndarray:
    arr = np.asarray(trace, dtype=np.float64)
    if arr.ndim != 2 or arr.shape[1] != 4:
        raise InvalidParameterError(
            f"{name} must have shape (n_points, 4) holding (x, y, z, t), got {arr.shape}"
        )
    return arr


def trajectory_vectors(trace: Any, time_scale: float = 1.0) -> np.ndarray:
    """The seed's trajectory of a trace: rotate by the first heading, then difference.

    Parameters
    ----------
    trace : array_like of shape (n_points, 4), float64
        Rows (x, y, z, t): centre of mass (m) and time (s). n_points >= 2.
    time_scale : float
        Factor (m/s) on the time component (1 in the seed: ``dt`` in seconds
        next to displacements in metres).

    Returns
    -------
    ndarray of shape (n_points - 1, 4), float64
        Displacement vectors (dx', dy', dz, dt) in the rotated frame.

    Raises
    ------
    InvalidParameterError
        If the trace is malformed, not finite, or has fewer than 2 points.
    """
    arr = _as_trace(trace)
    if arr.shape[0] < 2:
        raise InvalidParameterError(
            f"a trace needs at least 2 points for a trajectory, got {arr.shape[0]}"
        )
    if not np.isfinite(arr).all():
        raise InvalidParameterError("trace holds non-finite values")
    theta = np.arctan2(arr[1, 1] - arr[0, 1], arr[1, 0] - arr[0, 0])
    c, s = np.cos(theta), np.sin(theta)
    rot = arr.copy()
    rot[:, 0] = arr[:, 0] * c + arr[:, 1] * s
    rot[:, 1] = -arr[:, 0] * s + arr[:, 1] * c
    rot[:, 3] *= _check_time_scale(time_scale)
    return np.diff(rot, axis=0)


def _unit(vectors: np.ndarray) -> np.ndarray:
    norm = np.linalg.norm(vectors, axis=-1, keepdims=True)
    return np.divide(vectors, norm, out=np.zeros_like(vectors), where=norm > 0)


def similarity_matrix(u: Any, v: Any) -> np.ndarray:
    """Cosine-or-zero similarity of every pair of vectors.

    Parameters
    ----------
    u : array_like of shape (n1, d)
    v : array_like of shape (n2, d)

    Returns
    -------
    ndarray of shape (n1, n2), float64
        ``max(0, cos angle(u_i, v_j))`` in [0, 1]; 0 where a vector is zero.
    """
    uu = _unit(np.asarray(u, dtype=np.float64))
    vv = _unit(np.asarray(v, dtype=np.float64))
    return np.clip(uu @ vv.T, 0.0, 1.0)


def _amss_dp(S: np.ndarray, n1: np.ndarray, n2: np.ndarray) -> np.ndarray:
    """The seed's DP for a batch of similarity matrices.

    Each row ``A(i, :)`` depends only on rows ``i - 1`` and ``i - 2``, so a
    row of every pair is one set of NumPy operations. Arrays are laid out
    (row, column, pair) so each operation streams contiguous memory.

    Parameters
    ----------
    S : ndarray of shape (n_pairs, N1, N2), float64
        Similarities, zero-padded beyond each pair's (n1, n2).
    n1, n2 : ndarray of shape (n_pairs,), int
        Trajectory lengths (>= 1).

    Returns
    -------
    ndarray of shape (n_pairs,), float64
        ``A(n1 - 1, n2 - 1)`` of each pair. A(i, j) depends only on entries
        (i', j') <= (i, j), so the padding does not change it.
    """
    P, N1, N2 = S.shape
    Sp = np.zeros((N1 + 1, N2 + 1, P))  # Sp[i + 1, j + 1] = s(i, j), zero outside
    Sp[1:, 1:, :] = S.transpose(1, 2, 0)
    S2 = 2.0 * Sp
    Ap = np.zeros((N1 + 2, N2 + 2, P))  # Ap[i + 2, j + 2] = A(i, j), zero for i < 0 or j < 0
    diag = np.empty((N2, P))
    up = np.empty((N2, P))
    left = np.empty((N2, P))
    for i in range(N1):
        s = Sp[i + 1, 1:]
        np.add(S2[i + 1, 1:], Ap[i + 1, 1:-1], out=diag)  # 2 s(i, j) + A(i-1, j-1)
        np.add(s, S2[i, 1:], out=up)  # s(i, j) + 2 s(i-1, j) + A(i-2, j-1)
        up += Ap[i, 1:-1]
        np.add(s, S2[i + 1, :-1], out=left)  # s(i, j) + 2 s(i, j-1) + A(i-1, j-2)
        left += Ap[i + 1, :-2]
        np.maximum(diag, up, out=diag)
        np.maximum(diag, left, out=Ap[i + 2, 2:])
    return Ap[n1 + 1, n2 + 1, np.arange(P)]


def amss(traj_a: Any, traj_b: Any, variant: str = "seed", time_scale: float = 1.0) -> float:
    """Angular metric for shape similarity of two centre-of-mass traces.

    Parameters
    ----------
    traj_a, traj_b : array_like of shape (n_points, 4), float64
        Raw traces, rows (x, y, z, t) in m and s, at least 2 points each.
    variant : {"seed", "normalized"}
        ``"seed"``: the DP value, no normalisation (in [0, n1 + n2]).
        ``"normalized"``: divided by ``n1 + n2`` (numbers of vectors), in [0, 1].
    time_scale : float
        Weight (m/s) of the time component of the vectors; see the module docstring.

    Returns
    -------
    float
        Higher = more similar. Symmetric, invariant to rotations and
        translations of either trace in the XY plane.
    """
    _check_variant(variant)
    u = trajectory_vectors(traj_a, time_scale)
    v = trajectory_vectors(traj_b, time_scale)
    S = similarity_matrix(u, v)[None]
    n1, n2 = np.array([len(u)]), np.array([len(v)])
    value = float(_amss_dp(S, n1, n2)[0])
    return value / (len(u) + len(v)) if variant == "normalized" else value


def _prepare(
    trajs: Sequence[Any] | None, time_scale: float
) -> tuple[list[np.ndarray | None], np.ndarray]:
    """Unit trajectory vectors per trace (None if no trajectory) and their lengths (0 if none)."""
    out: list[np.ndarray | None] = []
    lengths = []
    for k, tr in enumerate(trajs or []):
        if tr is None:
            out.append(None)
            lengths.append(0)
            continue
        arr = _as_trace(tr, f"trace {k}")
        if arr.shape[0] < 2 or not np.isfinite(arr).all():
            out.append(None)
            lengths.append(0)
            continue
        vec = _unit(trajectory_vectors(arr, time_scale))
        out.append(vec)
        lengths.append(len(vec))
    return out, np.asarray(lengths, dtype=np.intp)


def _pad(vectors: list[np.ndarray | None], n_max: int) -> np.ndarray:
    U = np.zeros((len(vectors), max(n_max, 1), 4))
    for k, v in enumerate(vectors):
        if v is not None:
            U[k, : len(v)] = v
    return U


def _pairs_amss(
    Ua: np.ndarray, la: np.ndarray, Ub: np.ndarray, lb: np.ndarray, ia: np.ndarray, ib: np.ndarray
) -> np.ndarray:
    out = np.empty(len(ia))
    if not len(ia):
        return out
    N1, N2 = Ua.shape[1], Ub.shape[1]
    chunk = max(1, _CHUNK_ELEMENTS // ((N1 + 2) * (N2 + 2) * 2))
    for start in range(0, len(ia), chunk):
        a = ia[start : start + chunk]
        b = ib[start : start + chunk]
        S = np.clip(Ua[a] @ Ub[b].transpose(0, 2, 1), 0.0, 1.0)
        out[start : start + chunk] = _amss_dp(S, la[a], lb[b])
    return out


def amss_matrix(
    trajs: Sequence[Any],
    others: Sequence[Any] | None = None,
    variant: str = "seed",
    time_scale: float = 1.0,
) -> np.ndarray:
    """AMSS of every pair of traces, batched in NumPy.

    Parameters
    ----------
    trajs : sequence of array_like of shape (n_points_i, 4) or None
        Raw traces (x, y, z, t); lengths may differ. None, or a trace with
        fewer than 2 points or non-finite values, has no trajectory.
    others : sequence of the same, optional
        Compare ``trajs`` against these instead of against themselves.
    variant : {"seed", "normalized"}
        See :func:`amss`.
    time_scale : float
        See :func:`amss`.

    Returns
    -------
    ndarray of shape (len(trajs), len(others or trajs)), float64
        ``M[i, j] = amss(trajs[i], others[j])``; NaN where either has no
        trajectory. Symmetric when ``others`` is None (only the upper
        triangle is computed).
    """
    _check_variant(variant)
    va, la = _prepare(trajs, time_scale)
    same = others is None
    vb, lb = (va, la) if same else _prepare(others, time_scale)
    na, nb = len(va), len(vb)
    M = np.full((na, nb), np.nan)
    if na == 0 or nb == 0:
        return M
    Ua = _pad(va, int(la.max(initial=0)))
    Ub = Ua if same else _pad(vb, int(lb.max(initial=0)))
    if same:
        ia, ib = np.triu_indices(na)
    else:
        ia, ib = (g.ravel() for g in np.meshgrid(np.arange(na), np.arange(nb), indexing="ij"))
    keep = (la[ia] > 0) & (lb[ib] > 0)
    ia, ib = ia[keep], ib[keep]
    values = _pairs_amss(Ua, la, Ub, lb, ia, ib)
    if variant == "normalized":
        values = values / (la[ia] + lb[ib])
    M[ia, ib] = values
    if same:
        M[ib, ia] = values
    return M


def traces_from_rollout(rollout: Rollout, since: float | None = None) -> list[np.ndarray | None]:
    """Centre-of-mass traces of every robot, None for diverged robots.

    Parameters
    ----------
    rollout : Rollout
    since : float, optional
        Keep samples with ``t >= since`` (s); default ``rollout.init_time``
        (the seed's traces start after the settling time).

    Returns
    -------
    list of (ndarray of shape (n_points, 4), float64) or None
    """
    since = rollout.init_time if since is None else since
    return [
        None if rollout.diverged[i] else rollout.trace(i, since=since)
        for i in range(rollout.n_robots)
    ]


def _seed_scores(M: np.ndarray, has: np.ndarray) -> np.ndarray:
    scores = np.full(M.shape[0], NO_TRAJECTORY_NOVELTY)
    if has.any():
        scores[has] = M[np.ix_(has, has)].sum(axis=1)
    return scores


def _knn_scores(M_pop: np.ndarray, M_arch: np.ndarray, has: np.ndarray, k: int) -> np.ndarray:
    n = M_pop.shape[0]
    scores = np.full(n, NO_TRAJECTORY_NOVELTY)
    pop = M_pop.copy()
    np.fill_diagonal(pop, np.nan)  # an individual is not its own neighbour
    sims = np.concatenate([pop, M_arch], axis=1) if M_arch.size else pop
    for i in np.flatnonzero(has):
        row = sims[i][np.isfinite(sims[i])]
        if row.size == 0:
            scores[i] = 0.0
            continue
        kk = min(k, row.size)
        scores[i] = float(np.partition(row, row.size - kk)[row.size - kk :].mean())
    return scores


def novelty_scores(
    trajs: Sequence[Any],
    method: str = "seed",
    *,
    archive: NoveltyArchive | None = None,
    k: int = 15,
    variant: str | None = None,
    time_scale: float | None = None,
) -> np.ndarray:
    """Novelty of every individual of a population; **lower = more novel**.

    Parameters
    ----------
    trajs : sequence of array_like of shape (n_points_i, 4) or None
        Raw centre-of-mass traces of the whole current population (the seed
        scores parents and children together, 31 individuals).
    method : {"seed", "knn"}
        ``"seed"`` (§3.4): ``S_i = sum_j AMSS(T_i, T_j)`` over every
        individual with a trajectory, ``j = i`` included; no memory of past
        generations. ``"knn"``: the mean similarity to the ``k`` most similar
        trajectories among the rest of the population and ``archive`` (past
        generations), so a robot that repeats an archived behaviour is not
        novel; this breaks the seed's "pattern loops".
    archive : NoveltyArchive, optional
        Only for ``"knn"``; not modified (see :meth:`NoveltyArchive.update`).
    k : int
        Neighbours for ``"knn"``.
    variant : {"seed", "normalized"}, optional
        AMSS variant; default ``"seed"`` for ``method="seed"`` and
        ``"normalized"`` (or the archive's) for ``"knn"``.
    time_scale : float, optional
        Weight of the time component (see the module docstring); default 1
        (the seed's), or the archive's.

    Returns
    -------
    ndarray of shape (len(trajs),), float64
        :data:`NO_TRAJECTORY_NOVELTY` for individuals without a trajectory.
        With ``"knn"``, an individual with no neighbour at all scores 0.
    """
    if method == "seed":
        if archive is not None:
            raise InvalidParameterError("method 'seed' has no archive; use method='knn'")
        M = amss_matrix(
            trajs, variant=variant or "seed", time_scale=1.0 if time_scale is None else time_scale
        )
        return _seed_scores(M, ~np.isnan(np.diag(M)) if len(M) else np.zeros(0, bool))
    if method == "knn":
        if k < 1:
            raise InvalidParameterError(f"k must be >= 1, got {k}")
        if variant is None:
            variant = archive.variant if archive is not None else "normalized"
        if time_scale is None:
            time_scale = archive.time_scale if archive is not None else 1.0
        M = amss_matrix(trajs, variant=variant, time_scale=time_scale)
        has = ~np.isnan(np.diag(M)) if len(M) else np.zeros(0, bool)
        if archive is not None and len(archive):
            M_arch = amss_matrix(trajs, archive.traces, variant=variant, time_scale=time_scale)
        else:
            M_arch = np.zeros((len(M), 0))
        return _knn_scores(M, M_arch, has, k)
    raise InvalidParameterError(f"unknown novelty method {method!r}; expected 'seed' or 'knn'")


class NoveltyArchive:
    """Memory of past behaviours for k-nearest-neighbour novelty.

    After each generation, :meth:`update` adds the ``n_add`` most novel
    trajectories of the population (lowest score). Deterministic: no
    randomness is involved.

    Parameters
    ----------
    k : int
        Neighbours averaged by :meth:`score`.
    n_add : int
        Trajectories added per :meth:`update`.
    max_size : int, optional
        Keep at most this many (the oldest are dropped first); unbounded by default.
    variant : {"seed", "normalized"}
        AMSS variant used for scoring; ``"normalized"`` compares traces of
        different lengths fairly.
    time_scale : float
        Weight (m/s) of the time component of trajectory vectors (1: the
        seed's); see the module docstring.
    """

    def __init__(
        self,
        k: int = 15,
        n_add: int = 2,
        max_size: int | None = None,
        variant: str = "normalized",
        time_scale: float = 1.0,
    ) -> None:
        if k < 1 or n_add < 0 or (max_size is not None and max_size < 1):
            raise InvalidParameterError(
                f"need k >= 1, n_add >= 0 and max_size >= 1 or None; got k={k}, n_add={n_add}, max_size={max_size}"
            )
        self.k = int(k)
        self.n_add = int(n_add)
        self.max_size = None if max_size is None else int(max_size)
        self.variant = _check_variant(variant)
        self.time_scale = _check_time_scale(time_scale)
        self.traces: list[np.ndarray] = []

    def __len__(self) -> int:
        return len(self.traces)

    def score(self, trajs: Sequence[Any]) -> np.ndarray:
        """Novelty (k nearest neighbours) of a population against itself and the archive; lower = more novel."""
        return novelty_scores(
            trajs, "knn", archive=self, k=self.k, variant=self.variant, time_scale=self.time_scale
        )

    def add(self, traces: Iterable[Any]) -> None:
        """Append traces (those without a trajectory are skipped), then trim to ``max_size``."""
        for tr in traces:
            if tr is None:
                continue
            arr = _as_trace(tr)
            if arr.shape[0] >= 2 and np.isfinite(arr).all():
                self.traces.append(arr.copy())
        if self.max_size is not None and len(self.traces) > self.max_size:
            del self.traces[: len(self.traces) - self.max_size]

    def update(self, trajs: Sequence[Any], scores: Any | None = None) -> np.ndarray:
        """Add the ``n_add`` most novel trajectories of ``trajs`` (ties: lower index first).

        Parameters
        ----------
        trajs : sequence of array_like of shape (n_points_i, 4) or None
        scores : array_like of shape (len(trajs),), optional
            Their novelty; computed with :meth:`score` if omitted.

        Returns
        -------
        ndarray of shape (len(trajs),), float64
            The scores used.
        """
        sc = self.score(trajs) if scores is None else np.asarray(scores, dtype=np.float64)
        if sc.shape != (len(trajs),):
            raise InvalidParameterError(f"scores must have shape ({len(trajs)},), got {sc.shape}")
        order = np.argsort(sc, kind="stable")
        chosen = [int(i) for i in order if sc[i] < NO_TRAJECTORY_NOVELTY][: self.n_add]
        self.add(trajs[i] for i in chosen)
        return sc

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict (for checkpoints; no pickle)."""
        return {
            "k": self.k,
            "n_add": self.n_add,
            "max_size": self.max_size,
            "variant": self.variant,
            "time_scale": self.time_scale,
            "traces": [t.tolist() for t in self.traces],
        }

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> NoveltyArchive:
        """Inverse of :meth:`to_dict`."""
        arch = cls(
            k=data["k"],
            n_add=data["n_add"],
            max_size=data["max_size"],
            variant=data["variant"],
            time_scale=data.get("time_scale", 1.0),
        )
        arch.add(np.asarray(t, dtype=np.float64) for t in data["traces"])
        return arch
