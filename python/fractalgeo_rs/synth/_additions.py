"""Variance schedule of the crease-free successive random additions.

One level of ``_core.additions_refine_2d`` (see ``rust/synth/additions.rs``
and docs/synthesis.md, "Successive random additions without creases") turns
a grid of spacing ``s`` into one of spacing ``s/2``:

* cell centres ``C``: tensor 4-point rule of the 4 x 4 old samples, plus a
  Gaussian of variance ``c1``;
* edge points ``E``: mean of the 4-point rules along the row and the column
  (old samples along one axis, centres along the other, distances 1 and 3),
  plus ``e``;
* additions: old samples ``O`` get ``a2``, centres another ``c2``.

Every fine value is a linear combination of coarse values plus independent
Gaussians, so the variance of any combination ``sum_k u_k Z(x_k)`` with
``sum u_k = 0`` is

    -1/2 sum_kl u_k u_l gamma(x_k - x_l) + sum over Gaussians (coefficient^2 variance),

with ``gamma(h) = |h|^(2H)`` when the coarse grid is fBm (unit ``s`` and
``sigma``). The second differences along a row centred on the four kinds of
fine positions (row even/odd x column even/odd) must have one variance
(3 equations; the columns follow by symmetry), and the lag-one differences
of both kinds of rows must have the variance ``(1/2)^(2H)`` (2 equations);
the unknowns ``(a2, c1, c2, e) >= 0`` solve them by non-negative least
squares. The tension ``w`` of the 4-point rule (weights
``(-w, 1/2 + w, 1/2 + w, -w)``) grows with ``H``: smoother fields need more
weight on the outer neighbours so that the old samples' second differences
do not exceed the new ones'.
"""
from __future__ import annotations

import functools
import itertools

import numpy as np

KINDS = ("a2", "c1", "c2", "e")


def tension(h: float) -> float:
    """Tension ``w`` of the 4-point rule: 0 (bilinear) at H <= 0.2, rising
    linearly to 1/8 at H >= 0.8 (1/16 is the cubic rule)."""
    return float(np.clip(0.125 * (h - 0.2) / 0.6, 0.0, 0.125))


def _rule(w):
    return ((-1, -w), (0, 0.5 + w), (1, 0.5 + w), (2, -w))


def _acc(d, k, v):
    d[k] = d.get(k, 0.0) + v


def _point(i, j, w):
    """Fine sample (i, j) as (coarse weights {(a, b): u}, Gaussians {(kind, i, j): u})."""
    co, nz = {}, {}
    if i % 2 == 0 and j % 2 == 0:
        co[(i // 2, j // 2)] = 1.0
        nz[("a2", i, j)] = 1.0
    elif i % 2 == 1 and j % 2 == 1:
        for ka, wa in _rule(w):
            for kb, wb in _rule(w):
                _acc(co, (i // 2 + ka, j // 2 + kb), wa * wb)
        nz[("c1", i, j)] = 1.0
        nz[("c2", i, j)] = 1.0
    else:
        for di, dj in ((1, 0), (0, 1)):
            for k, wk in ((-3, -w), (-1, 0.5 + w), (1, 0.5 + w), (3, -w)):
                c2, n2 = _point(i + k * di, j + k * dj, w)
                for key, v in c2.items():
                    _acc(co, key, 0.5 * wk * v)
                for key, v in n2.items():
                    if key[0] == "c1":  # additions a2, c2 come after the square step
                        _acc(nz, key, 0.5 * wk * v)
        nz[("e", i, j)] = 1.0
    return co, nz


def _combination(pts, w, h):
    """(variance of the coarse part, coefficients of the 4 variances)."""
    co, nz = {}, {}
    for u, i, j in pts:
        c, n = _point(i, j, w)
        for k, v in c.items():
            _acc(co, k, u * v)
        for k, v in n.items():
            _acc(nz, k, u * v)
    keys = list(co)
    u = np.array([co[k] for k in keys])
    p = np.array(keys, dtype=np.float64)
    g = np.linalg.norm(p[:, None, :] - p[None, :, :], axis=2) ** (2 * h)
    coef = dict.fromkeys(KINDS, 0.0)
    for (kind, _, _), v in nz.items():
        coef[kind] += v * v
    return float(-0.5 * u @ g @ u), np.array([coef[k] for k in KINDS])


def equations(h: float, w: float):
    """Rows ``(coarse variance, coefficients)`` of the second differences at
    the four kinds of positions and of the lag-one differences of even and
    odd rows (positions far from the edges)."""
    d2 = [_combination([(1, 8 + r, 8 + q - 1), (-2, 8 + r, 8 + q), (1, 8 + r, 8 + q + 1)], w, h)
          for r, q in itertools.product((0, 1), (0, 1))]
    lag1 = [_combination([(1, 8 + r, 9), (-1, 8 + r, 8)], w, h) for r in (0, 1)]
    return d2, lag1


@functools.lru_cache(maxsize=64)
def schedule(h: float):
    """``(w, (a2, c1, c2, e))`` for ``hurst = h``: tension and variances in
    units of ``sigma^2 s^(2H)`` (``s`` the coarse spacing)."""
    from scipy.optimize import nnls

    w = tension(h)
    d2, lag1 = equations(h, w)
    a = [d2[k][1] - d2[0][1] for k in (1, 2, 3)] + [c for _, c in lag1]
    b = [d2[0][0] - d2[k][0] for k in (1, 2, 3)] + [0.5 ** (2 * h) - v for v, _ in lag1]
    x, _ = nnls(np.array(a), np.array(b))
    return w, tuple(float(v) for v in x)
