"""The report's statistics over seeds: summaries, A12, permutation and sign tests."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from evolvers.study.data import FAILS, HOLDS, PARTLY, UNTESTED

__all__ = [
    "a12",
    "compare",
    "finite_values",
    "median",
    "permutation_pvalue",
    "sign_pvalue",
    "summary",
]


# ---------------------------------------------------------------------------- statistics
def finite_values(values: Sequence[float]) -> np.ndarray:
    """The finite values (None, NaN and infinities dropped), float64."""
    a = np.asarray([v for v in values if v is not None], dtype=np.float64)
    return a[np.isfinite(a)]


def summary(values: Sequence[float], fmt: str = "{:.3g}") -> str:
    """``median [Q1, Q3], n=N`` of the finite values."""
    a = finite_values(values)
    if a.size == 0:
        return "none"
    q1, med, q3 = np.percentile(a, [25, 50, 75])
    return f"{fmt.format(med)} [{fmt.format(q1)}, {fmt.format(q3)}], n={a.size}"


def median(values: Sequence[float]) -> float:
    """The median of the finite values (NaN without any)."""
    a = finite_values(values)
    return float(np.median(a)) if a.size else float("nan")


def a12(x: Sequence[float], y: Sequence[float]) -> float:
    """Vargha-Delaney A12: P(X > Y) + P(X = Y) / 2 over pairs (NaN if either is empty)."""
    x, y = finite_values(x), finite_values(y)
    if x.size == 0 or y.size == 0:
        return float("nan")
    d = x[:, None] - y[None, :]
    return float(((d > 0).sum() + 0.5 * (d == 0).sum()) / d.size)


def permutation_pvalue(
    x: Sequence[float], y: Sequence[float], n_perm: int = 20000, seed: int = 0
) -> float:
    """One-sided p-value that X tends to be larger than Y (Mann-Whitney statistic, permutations).

    The statistic is A12 (:func:`a12`); labels are permuted ``n_perm`` times
    with a fixed seed, so the value is reproducible. NaN if a sample is empty.
    """
    x, y = finite_values(x), finite_values(y)
    if x.size == 0 or y.size == 0:
        return float("nan")
    pooled = np.concatenate([x, y])
    ranks = _ranks(pooled)
    nx = x.size
    observed = ranks[:nx].sum()
    rng = np.random.default_rng(seed)
    perms = np.argsort(rng.random((n_perm, pooled.size)), axis=1)[:, :nx]
    stats = ranks[perms].sum(axis=1)
    return float((1 + (stats >= observed - 1e-9).sum()) / (n_perm + 1))


def _ranks(a: np.ndarray) -> np.ndarray:
    """Ranks with ties averaged."""
    order = np.argsort(a, kind="mergesort")
    ranks = np.empty(a.size)
    ranks[order] = np.arange(1, a.size + 1)
    for v in np.unique(a):
        tie = a == v
        if tie.sum() > 1:
            ranks[tie] = ranks[tie].mean()
    return ranks


def sign_pvalue(k: int, n: int) -> float:
    """One-sided binomial p of at least ``k`` successes in ``n`` fair trials."""
    if n == 0:
        return float("nan")
    return sum(math.comb(n, i) for i in range(k, n + 1)) / 2.0**n


def compare(
    a: Sequence[float], b: Sequence[float], larger: bool = True
) -> tuple[str, str, float, float]:
    """Verdict of "A is larger (or smaller) than B" and its evidence text."""
    a, b = finite_values(a), finite_values(b)
    if a.size == 0 or b.size == 0:
        return UNTESTED, "a scenario has no finished seed", float("nan"), float("nan")
    x, y = (a, b) if larger else (-a, -b)
    p = permutation_pvalue(x, y)
    eff = a12(x, y)
    better = np.median(x) > np.median(y)
    verdict = HOLDS if better and p < 0.05 else PARTLY if better else FAILS
    return verdict, f"one-sided permutation p={p:.3g}, A12={eff:.2f}", p, eff
