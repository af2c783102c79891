"""The single-precision frames' cubic for the rotation vector's k (``SOFTGYM_RSQ_D0..D3``).

The seed's square-root branch takes a unit quaternion (w, v) to the rotation vector k v
with k = 2 sqrt(2 / (1 + w)). ``softgym_rotvec_k32`` (include/softgym_seed.h) takes k from
a cubic in w (its coefficients rounded to float) and one Newton step for 1 / sqrt; this
script fits that cubic by Remez's exchange (least maximal *relative* error on [0.5, 1], the
links the float frames keep), prints the coefficients as the header spells them, and checks
the header's arithmetic on 200,001 floats of [0.5, 1] (numpy, each float operation rounded,
each fused multiply-add rounded once): the cubic's error and k's, in float roundings
(units of 2^-24 relative).

    python benchmarks/rotvec_fit.py
"""

from __future__ import annotations

import sys

import numpy as np

LO, HI, DEG = 0.5, 1.0, 3


def remez(iterations: int = 30) -> tuple[list[float], float]:
    """The minimax-relative cubic's coefficients (constant first) and its error (in double:
    the error sought is 1.5e-5, far above double's rounding)."""

    def k(w):
        return np.sqrt(8.0 / (1.0 + w))

    n = DEG + 2
    xs = (LO + HI) / 2 - (HI - LO) / 2 * np.cos(np.pi * np.arange(n) / (n - 1))
    grid = np.linspace(LO, HI, 20001)
    sol = np.zeros(n)
    for _ in range(iterations):
        # c0 + c1 x + ... + c3 x^3 - k(x) = (-1)^i E k(x) at the n reference points
        A = np.column_stack([xs**j for j in range(DEG + 1)] + [(-1.0) ** np.arange(n) * k(xs)])
        sol = np.linalg.solve(A, k(xs))
        err = np.polyval(sol[DEG::-1], grid) / k(grid) - 1.0
        turn = np.nonzero(np.diff(np.sign(np.diff(err))))[0] + 1
        ext = np.concatenate([[grid[0]], grid[turn], [grid[-1]]])
        if ext.size != n:
            break
        xs = ext
    return [float(x) for x in sol[: DEG + 1]], float(abs(sol[DEG + 1]))


def check(coef: list[float]) -> tuple[float, float]:
    """The float cubic's and k's largest relative errors in float roundings (2^-24)."""
    f32 = np.float32
    d0, d1, d2, d3 = (np.float64(f32(x)) for x in coef)
    w = np.linspace(LO, HI, 200001).astype(f32).astype(np.float64)

    def r(x):  # one float rounding
        return x.astype(f32).astype(np.float64)

    w2 = r(w * w)
    e = r(r(d3 * w + d2) * w2 + r(d1 * w + d0))  # fma(fma(D3, w, D2), w2, fma(D1, w, D0))
    x16 = r(w * 0.0625 + 0.0625)
    u = r(0.5 - x16 * r(e * e))
    k = r(e * u + e)
    exact = np.sqrt(8.0 / (1.0 + w))
    unit = 2.0**-24
    return float(np.max(np.abs(e / exact - 1.0)) / unit), float(np.max(np.abs(k / exact - 1.0)) / unit)


def main() -> int:
    coef, err = remez()
    print(f"minimax relative error of the cubic: {err:.3e}")
    for j in reversed(range(DEG + 1)):
        v = float(np.float32(coef[j]))
        text = f"{v!r}f" if v >= 0 else f"({v!r}f)"
        print(f"#define SOFTGYM_RSQ_D{j} {text}")
    e, k = check(coef)
    print(f"float cubic within {e:.0f} float roundings of k; after the Newton step k within {k:.2f}")
    return 0 if k < 2.0 else 1


if __name__ == "__main__":
    sys.exit(main())
