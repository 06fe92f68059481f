"""Break-point detection on log-log points: where is the relation straight?

A measure ``M(s)`` of real data follows one power law only over a range of
scales (a DEM is smooth below a few cells, a SAR scene is white speckle
there). :func:`find_break` compares, by the Bayesian information criterion,
one straight line through the points ``(x, y) = (log s, log M)`` with a
continuous broken line (a hinge)

.. math::

    y = a + b x + c \\max(x - x_b, 0)

whose break ``x_b`` is searched on a fine grid between the
``MIN_SEGMENT``-th point from either end, so that each segment holds at least
``MIN_SEGMENT`` scales. The hinge is kept when

* its BIC, ``n log(SSE / n) + k log n`` with ``k = 4`` parameters against
  ``k = 2`` for the line, is lower, and
* the two slopes give dimensions at least ``MIN_DIM_CHANGE`` apart (smaller
  changes are the lacunar oscillations of exact fractals, not two regimes).

At most one break is looked for (two regimes: e.g. a smooth range and a
fractal range).

References
----------
Schwarz, G. (1978). Estimating the dimension of a model. *Annals of
Statistics* 6(2), 461-464. doi:10.1214/aos/1176344136
Muggeo, V. M. R. (2003). Estimating regression models with unknown
break-points. *Statistics in Medicine* 22, 3055-3071. doi:10.1002/sim.1545
"""
from __future__ import annotations

import math
from typing import Optional, Tuple

import numpy as np

MIN_SEGMENT = 4
"""Fewest scales on each side of a break."""

MIN_DIM_CHANGE = 0.05
"""Smallest change of dimension between two regimes that counts as a break."""

_GRID = 64  # candidate breaks between the admissible end points


def _sse_line(x: np.ndarray, y: np.ndarray) -> float:
    A = np.column_stack([np.ones_like(x), x])
    coef, *_ = np.linalg.lstsq(A, y, rcond=None)
    r = y - A @ coef
    return float(r @ r)


def _hinge(x: np.ndarray, y: np.ndarray, xb: float) -> Tuple[float, np.ndarray]:
    A = np.column_stack([np.ones_like(x), x, np.maximum(x - xb, 0.0)])
    coef, *_ = np.linalg.lstsq(A, y, rcond=None)
    r = y - A @ coef
    return float(r @ r), coef


def find_break(x, y, *, dim_factor: float, min_segment: int = MIN_SEGMENT,
               min_dim_change: float = MIN_DIM_CHANGE) -> Optional[Tuple[float, float, float]]:
    """The break of a two-regime log-log relation, or ``None``.

    Parameters
    ----------
    x, y : array_like
        Log scales (ascending) and log measures.
    dim_factor : float
        ``D = dim_offset + dim_factor * slope`` (to compare the regimes in
        units of dimension).
    min_segment : int
        Fewest points per segment (no search below ``2 * min_segment``
        points).
    min_dim_change : float
        Smallest change of dimension that counts.

    Returns
    -------
    (x_break, slope_below, slope_above) or None
    """
    x = np.asarray(x, dtype=float)
    y = np.asarray(y, dtype=float)
    n = x.size
    if n < 2 * min_segment:
        return None
    # a floor on the residuals: exact power laws have SSE ~ 0 and would
    # otherwise compare log(0) with log(tiny)
    floor = n * (1e-9 * (1.0 + float(np.std(y)))) ** 2
    sse1 = _sse_line(x, y) + floor
    lo, hi = x[min_segment - 1], x[n - min_segment]
    if not hi > lo:
        return None
    grid = np.linspace(lo, hi, _GRID)
    sses = [_hinge(x, y, float(xb))[0] for xb in grid]
    k = int(np.argmin(sses))
    # refine between the neighbours of the best grid point (bounded Brent)
    from scipy.optimize import minimize_scalar

    a, b = grid[max(k - 1, 0)], grid[min(k + 1, _GRID - 1)]
    res = minimize_scalar(lambda v: _hinge(x, y, v)[0], bounds=(a, b), method="bounded",
                          options={"xatol": 1e-10})
    xb = float(res.x) if res.fun <= sses[k] else float(grid[k])
    sse, coef = _hinge(x, y, xb)
    best = (sse, xb, coef)
    sse2 = best[0] + floor
    bic1 = n * math.log(sse1 / n) + 2 * math.log(n)
    bic2 = n * math.log(sse2 / n) + 4 * math.log(n)
    _, xb, coef = best
    below, above = float(coef[1]), float(coef[1] + coef[2])
    if not bic2 < bic1 or abs(dim_factor * (above - below)) < min_dim_change:
        return None
    return xb, below, above
