"""Cramér-Rao bound of H for exact fBm on a small square grid.

The exact Fisher information of the increments u(x) = Z(x) - Z(x_0) with
covariance sigma^2 R_H (fBm variogram sigma^2 |h|^2H), sigma^2 profiled out:

    I(H) = 1/2 [ tr(A^2) - tr(A)^2 / N ],   A = R_H^{-1} dR_H/dH,

so sd(H) >= I(H)^{-1/2}; the same bound holds for D = 3 - H. Used in
docs/accuracy.md to judge how close the likelihood estimators come to
efficiency. Cost O(N^3) with N = n^2 - 1: seconds at 32², minutes at 64².

Run: ``python benches/crb_fbm_surface.py 32``
"""
from __future__ import annotations

import sys

import numpy as np


def crb(n: int, hurst: float) -> float:
    i, j = np.indices((n, n))
    p = np.column_stack([i.ravel(), j.ravel()]).astype(float)[1:]
    r0 = np.sqrt((p**2).sum(1))
    d = np.sqrt(((p[:, None] - p[None]) ** 2).sum(-1))
    l0 = np.log(r0)
    ld = np.log(np.where(d > 0, d, 1.0))
    a, b = r0 ** (2 * hurst), d ** (2 * hurst)
    R = 0.5 * (a[:, None] + a[None] - b)
    dR = (l0 * a)[:, None] + (l0 * a)[None] - ld * b
    A = np.linalg.solve(R, dR)
    info = 0.5 * (np.sum(A * A.T) - np.trace(A) ** 2 / len(R))
    return float(1.0 / np.sqrt(info))


if __name__ == "__main__":
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 32
    for h in (0.3, 0.5, 0.7):
        print(f"n = {n}, H = {h}: Cramér-Rao bound sd(H) = sd(D) >= {crb(n, h):.4f}")
