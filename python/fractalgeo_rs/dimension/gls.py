"""Generalised least squares over the log quadratic variations of increment
filters (estimator ``"gls"``), and the anisotropy of the directional
variations.

For a filter ``f`` (taps ``w_a`` at offsets ``a``, ``sum w_a = 0``) the
quadratic variation of a grid is ``V_f = mean_x (sum_a w_a z(x + a))^2``
over the anchors ``x`` whose taps all lie on the grid. For fBm with
variogram ``E (z(p) - z(q))^2 = sigma^2 |p - q|^(2H)``,

    E V_f = sigma^2 c_f(H),     c_f(H) = -1/2 sum_{a, a'} w_a w_a' |a - a'|^(2H),

and for Gaussian fields ``Cov(V_f, V_g) = 2 / (N_f N_g) sum_{x, y}
C_fg(x - y)^2`` with ``C_fg(l) = -1/2 sum_{a, b} w_a w_b |l + a - b|^(2H)``
(sums over the anchors of each filter, counted exactly on the grid). With
``r_f = Var(V_f) / (E V_f)^2``, ``y_f = log V_f`` has mean (delta method)
``a_f(H) = log c_f(H) - r_f(H) / 2 + log sigma^2`` and covariance

    Sigma_fg = Cov(V_f, V_g) / (E V_f E V_g) + [f = g] (psi'(1 / r_f) - r_f),

the delta method's covariance plus, per filter, an independent term: the
excess of ``Var log V_f`` under the Welch-Satterthwaite approximation ``V_f
~ (E V_f / nu_f) chi2(nu_f)``, ``nu_f = 2 / r_f`` (Satterthwaite 1946),
which is ``psi'(nu_f / 2)`` (trigamma), over the delta method's ``r_f``
(about ``r_f^2 / 2``). It is negligible for second differences (``r_f``
below 0.02 at windows of 33 or more) and keeps the first differences of
smooth fields (``r_f`` 0.1-0.3 at ``H = 0.8``, window 33, where ``log V_f``
is far from Gaussian) from being weighted through contrasts whose
delta-method variance is too small, so every filter enters the fit. Scaling
the whole covariance to the Welch-Satterthwaite variances (correlations
kept), a cut-off on ``r_f`` or the delta method alone give a larger spread
of ``H`` at ``H >= 0.7`` on exact fBm. ``H`` is the
generalised least squares fit of ``y`` on ``a(H) + log sigma^2`` with
weights ``Sigma^-1``: starting from ``H = 0.5``, each step is the
Gauss-Newton update

    H <- H + g(H) . (y - a(H)),   g = first row of (X' W X)^-1 X' W,
    X = [da/dH, 1],  W = Sigma(H)^-1,

(``g . 1 = 0``: ``sigma`` drops out; ``da/dH`` is the exact derivative of
``a``, including that of ``r_f``), with ``a`` (and ``da/dH``) and ``g``
tabulated on a grid of ``H`` (0.02 to 0.98 by 0.02; ``a`` interpolated by
cubic Hermite, ``g`` linearly) per grid shape. Its standard error is
``sqrt((X' W X)^-1)_HH`` at the estimate. ``D = 2 - H`` (profiles) or
``3 - H`` (surfaces).

Filters: first differences ``z(x + u e) - z(x)`` and second differences
``z(x + 2u e) - 2 z(x + u e) + z(x)`` at dilations ``u = 1 .. k`` along
``e`` = rows, columns and both diagonals (surfaces) or along the profile.

References
----------
Kent, J. T., Wood, A. T. A. (1997). Estimating the fractal dimension of a
locally self-similar Gaussian process by using increments. *J. R. Statist.
Soc. B* 59(3), 679-699. https://doi.org/10.1111/1467-9868.00091
Istas, J., Lang, G. (1997). Quadratic variations and estimation of the
local Hölder index of a Gaussian process. *Ann. Inst. H. Poincaré Probab.
Statist.* 33(4), 407-436. https://doi.org/10.1016/S0246-0203(97)80099-4
Chan, G., Wood, A. T. A. (2000). Increment-based estimators of fractal
dimension for two-dimensional surface data. *Statistica Sinica* 10, 343-376.
Satterthwaite, F. E. (1946). An approximate distribution of estimates of
variance components. *Biometrics Bulletin* 2(6), 110-114.
https://doi.org/10.2307/3002019
"""
from __future__ import annotations

from functools import lru_cache
from typing import Any, Optional, Sequence, Tuple

import numpy as np

from fractalgeo_rs._validation import check_positive_int
from fractalgeo_rs.dimension._common import real_array, with_nodata
from fractalgeo_rs.fit import DimensionFit

__all__ = ["gls_dimension", "anisotropy_from_variations"]

#: Grid of H on which the GLS tables are computed.
H_GRID = np.round(np.arange(0.02, 0.985, 0.02), 10)
#: Gauss-Newton steps from H = 0.5.
N_STEPS = 4
#: Largest grid side whose covariance is computed exactly (larger grids
#: take the weights of this size; their standard error is scaled by the
#: number of samples).
DESIGN_CAP = {1: 4097, 2: 65}
# direction unit steps (row, col) for surfaces: rows, columns, diagonal, anti-diagonal
_DIRS = ((0, 1), (1, 0), (1, 1), (1, -1))


def filters(ndim: int, dilations: int) -> list:
    """Taps of every filter: a list of (offsets (m, ndim) int array with
    non-negative entries, weights (m,) array, span (ndim,) = max offsets,
    label (order, direction, dilation))."""
    out = []
    dirs = ((1,),) if ndim == 1 else _DIRS
    for order, w in ((1, (-1.0, 1.0)), (2, (1.0, -2.0, 1.0))):
        for di, e in enumerate(dirs):
            for u in range(1, dilations + 1):
                offs = np.array([[t * u * c for c in e] for t in range(order + 1)], dtype=np.int64)
                offs -= offs.min(axis=0)  # anti-diagonal: shift to non-negative columns
                out.append((offs, np.array(w), offs.max(axis=0), (order, di, u)))
    return out


def _overlap(n1: int, n2: int, lags: np.ndarray) -> np.ndarray:
    """#{x in [0, n1), y in [0, n2): x - y = d} for each d."""
    return np.clip(np.minimum(n1, n2 + lags) - np.maximum(0, lags), 0, None).astype(np.float64)


@lru_cache(maxsize=32)
def tables(shape: Tuple[int, ...], dilations: int) -> dict:
    """GLS tables for grids of ``shape`` on :data:`H_GRID`: ``a``, ``da``,
    ``g``, ``rel_var`` (each (nH, K)), ``sigma`` (nH, K, K), ``se`` (nH,),
    ``counts`` (K,) full-grid anchors.

    A grid too small for its filters (fewer than two anchors, or a singular
    covariance) is a ``ValueError`` naming ``window_size``."""
    try:
        return _tables(tuple(shape), dilations)
    except np.linalg.LinAlgError:
        raise ValueError(f"window_size: the GLS filters with dilations={dilations} are degenerate on a "
                         f"{' x '.join(map(str, shape))} grid (singular covariance); use a larger window "
                         f"or fewer dilations") from None


def _moments(fl: list, shape: Tuple[int, ...], counts: np.ndarray, H: float, geo: dict):
    """Exact fBm moments of the quadratic variations at ``H`` (unit
    ``sigma``): ``c`` (E V_f), ``dc`` (its H-derivative), ``cov`` (Cov(V_f,
    V_g)) and ``dvar`` (the H-derivative of Var V_f)."""
    ndim, pad, lag_axes, dist2, logd, ovs = (geo[k] for k in ("ndim", "pad", "lag_axes", "dist2", "logd", "ovs"))
    K = len(fl)
    G = np.exp(2 * H * logd) * (dist2 > 0)  # |d|^(2H), 0 at d = 0
    dG = 2 * logd * G  # its H-derivative
    c = np.empty(K)
    dc = np.empty(K)
    for k, (offs, w, _, _) in enumerate(fl):
        dd = offs[:, None, :] - offs[None, :, :]
        r = np.sqrt((dd.astype(np.float64) ** 2).sum(-1))
        ww = w[:, None] * w[None, :]
        lr = np.log(np.where(r > 0, r, 1.0))
        c[k] = -0.5 * np.sum(ww * r ** (2 * H))
        dc[k] = -0.5 * np.sum(ww * 2 * lr * r ** (2 * H) * (r > 0))
    cov = np.empty((K, K))
    dvar = np.empty(K)
    for i, (oi, wi, _, _) in enumerate(fl):
        for j in range(i, K):
            oj, wj = fl[j][0], fl[j][1]
            C: Any = 0.0
            dC: Any = 0.0
            for ta, wa in zip(oi, wi):
                for tb, wb in zip(oj, wj):
                    sl = tuple(slice(pad + int(x), pad + int(x) + len(lg)) for x, lg in zip(ta - tb, lag_axes))
                    C = C + (-0.5 * wa * wb) * G[sl]
                    if i == j:
                        dC = dC + (-0.5 * wa * wb) * dG[sl]
            ov = ovs[i, j]

            def pairsum(M):
                return ov[0] @ M if ndim == 1 else ov[0] @ M @ ov[1]

            cov[i, j] = cov[j, i] = 2.0 * pairsum(C * C) / (counts[i] * counts[j])
            if i == j:
                dvar[i] = 4.0 * pairsum(C * dC) / (counts[i] * counts[i])
    return c, dc, cov, dvar


def log_moments(c: np.ndarray, dc: np.ndarray, cov: np.ndarray, dvar: np.ndarray):
    """Model of ``y_f = log V_f`` (unit ``sigma``) from the moments of
    :func:`_moments`: ``(a, da, Sigma, r)`` with ``r_f = Var V_f / (E
    V_f)^2``, ``a_f = log c_f - r_f / 2``, ``da`` its exact H-derivative and
    ``Sigma`` the delta method's covariance plus the independent
    Welch-Satterthwaite excess ``psi'(1 / r_f) - r_f`` per filter (module
    docstring)."""
    from scipy.special import polygamma

    var = np.diag(cov)
    r = var / c**2
    dr = dvar / c**2 - 2.0 * r * dc / c
    a = np.log(c) - r / 2
    da = dc / c - dr / 2
    sig = cov / np.outer(c, c) + np.diag(polygamma(1, 1.0 / r) - r)
    return a, da, sig, r


def _tables(shape: Tuple[int, ...], dilations: int, h_grid: Optional[np.ndarray] = None) -> dict:
    h_grid = H_GRID if h_grid is None else np.asarray(h_grid, dtype=np.float64)
    ndim = len(shape)
    fl = filters(ndim, dilations)
    K = len(fl)
    counts = np.array([np.prod([n - s for n, s in zip(shape, sp)]) for _, _, sp, _ in fl], dtype=np.float64)
    if (counts < 2).any():
        raise ValueError(f"window_size: a grid of {shape} is too small for dilations up to {dilations}")
    pad = 2 * dilations
    lag_axes = [np.arange(-(n - 1), n) for n in shape]
    ext = [np.arange(-(n - 1) - pad, n + pad) for n in shape]
    dist2 = sum(np.meshgrid(*[e.astype(np.float64) ** 2 for e in ext], indexing="ij"))
    logd = 0.5 * np.log(np.where(dist2 > 0, dist2, 1.0))
    # overlaps of the anchor ranges of each pair of filters, per axis
    ovs = {}
    for i, (_, _, si, _) in enumerate(fl):
        for j in range(i, K):
            sj = fl[j][2]
            ovs[i, j] = [_overlap(n - a, n - b, lg) for n, a, b, lg in zip(shape, si, sj, lag_axes)]
    geo = dict(ndim=ndim, pad=pad, lag_axes=lag_axes, dist2=dist2, logd=logd, ovs=ovs)
    nH = len(h_grid)
    a = np.empty((nH, K))
    da = np.empty((nH, K))
    g = np.empty((nH, K))
    se = np.empty(nH)
    sigs = np.empty((nH, K, K))
    rel = np.empty((nH, K))
    for hi, H in enumerate(h_grid):
        c, dc, cov, dvar = _moments(fl, shape, counts, float(H), geo)
        a[hi], da[hi], sig, rel[hi] = log_moments(c, dc, cov, dvar)
        sigs[hi] = sig
        X = np.column_stack([da[hi], np.ones(K)])
        Wx = np.linalg.solve(sig + 1e-12 * np.trace(sig) / K * np.eye(K), X)
        Minv = np.linalg.inv(X.T @ Wx)
        g[hi] = (Minv @ Wx.T)[0]
        se[hi] = np.sqrt(Minv[0, 0])
    return {"a": a, "da": da, "g": g, "se": se, "sigma": sigs, "rel_var": rel, "counts": counts, "filters": fl, "shape": tuple(shape),
            "dilations": dilations}


def interp(t: dict, H: float):
    """(a(H), g(H), se(H)): ``a`` by cubic Hermite from ``a`` and ``da``,
    ``g`` and ``se`` linearly, on :data:`H_GRID` (the same formulas as the
    Rust kernel)."""
    h0, dh = H_GRID[0], H_GRID[1] - H_GRID[0]
    x = (H - h0) / dh
    i = int(min(max(np.floor(x), 0), len(H_GRID) - 2))
    s = x - i
    h00, h10, h01, h11 = 2 * s**3 - 3 * s**2 + 1, s**3 - 2 * s**2 + s, -2 * s**3 + 3 * s**2, s**3 - s**2
    a = h00 * t["a"][i] + h10 * dh * t["da"][i] + h01 * t["a"][i + 1] + h11 * dh * t["da"][i + 1]
    g = (1 - s) * t["g"][i] + s * t["g"][i + 1]
    se = (1 - s) * t["se"][i] + s * t["se"][i + 1]
    return a, g, se


def solve(t: dict, y: np.ndarray) -> Tuple[float, float]:
    """Gauss-Newton GLS fit of ``y = log V`` (K,): (H, se of H)."""
    H = 0.5
    for _ in range(N_STEPS):
        a, g, _ = interp(t, H)
        H = float(np.clip(H + g @ (y - a), H_GRID[0], H_GRID[-1]))
    return H, float(interp(t, H)[2])


def quadratic_variations(z: np.ndarray, dilations: int):
    """(V, n): mean square and number of valid anchors of every filter of
    :func:`filters` on ``z`` (NaN = missing; increments touching NaN left out)."""
    fl = filters(z.ndim, dilations)
    V = np.empty(len(fl))
    n = np.empty(len(fl))
    for k, (offs, w, span, _) in enumerate(fl):
        ext = [m - s for m, s in zip(z.shape, span)]
        if min(ext) <= 0:
            V[k], n[k] = np.nan, 0
            continue
        d: Any = 0.0
        for o, wt in zip(offs, w):
            d = d + wt * z[tuple(slice(int(oo), int(oo) + e) for oo, e in zip(o, ext))]
        ok = ~np.isnan(d)
        n[k] = ok.sum()
        V[k] = np.mean(d[ok] ** 2) if n[k] else np.nan
    return V, n


def check_dilations(dilations) -> int:
    k = check_positive_int(dilations, "dilations")
    if k > 8:
        raise ValueError(f"dilations: expected an int in [1, 8], got {k}")
    return k


def _design(shape, design) -> Tuple[int, ...]:
    if design is None:
        cap = DESIGN_CAP[len(shape)]
        return tuple(min(int(n), cap) for n in shape)
    if isinstance(design, (str, bytes)) or np.ndim(design) != 1:
        raise TypeError(f"design: expected a sequence of {len(shape)} positive ints, got {design!r}")
    if len(design) != len(shape):
        raise ValueError(f"design: expected {len(shape)} positive ints, got {design!r}")
    design = tuple(check_positive_int(v, "design") for v in design)
    cap = DESIGN_CAP[len(shape)]
    if max(design) > cap:
        raise ValueError(f"design: at most {cap} per side (the tables grow as its square), got {design}")
    return design


def gls_dimension(
    data,
    *,
    dilations: int = 2,
    nodata: Optional[float] = None,
    design: Optional[Sequence[int]] = None,
    anisotropy: bool = False,
) -> DimensionFit:
    """Fractal dimension of a profile or surface by generalised least squares
    over the log quadratic variations of increment filters.

    The log mean squares ``log V_f`` of first and second differences at
    dilations ``1 .. dilations`` (surfaces: along rows, columns and both
    diagonals) are fitted by ``log c_f(H) + log sigma^2``, where
    ``c_f(H)`` is the exact expected quadratic variation of filter ``f``
    under fBm with Hurst exponent ``H``, weighted by the inverse of their
    exact covariance under fBm on the grid (delta method, with the
    Welch-Satterthwaite excess variance of each log as an independent term),
    iterated at the current ``H`` (see the module docstring for the formulas). ``D = 2 - H``
    (profiles) or ``3 - H`` (surfaces). Scale free (no height unit).

    On exact fBm the estimate is unbiased to 0.005 and its spread is close to
    the Cramér-Rao bound (docs/transform.md, ``benches/accuracy_gls.py``).
    It is the per-window estimator of ``fractal_transform(...,
    method="gls")``.

    Parameters
    ----------
    data : array_like, shape (n,) or (rows, cols)
        Profile or surface, unit spacing. NaN (and ``nodata``) are missing:
        the increments touching them are left out.
    dilations : int, default 2
        Largest dilation ``k`` (1 to 8): ``2 k`` filters on profiles, ``8 k``
        on surfaces.
    nodata : float, optional
        Value marking missing samples, in addition to NaN.
    design : sequence of int, optional
        Grid shape whose exact covariance sets the weights and the standard
        error (default: the data's shape, each side capped at 65 for
        surfaces and 4097 for profiles; beyond the cap the standard error is
        scaled by ``sqrt(cells of the design / cells of the data)``, an
        approximation). The moving-window map uses the full window's design
        also for windows clipped by the image border.
    anisotropy : bool, default False
        Surfaces: also estimate the direction and ratio of geometric
        anisotropy (a least-squares fit of ``sigma^2 |A h|^(2H)`` to the
        four first-order directional variations), in ``extra["anisotropy_angle"]``
        (degrees) and ``extra["anisotropy_ratio"]``.

    Returns
    -------
    DimensionFit
        Model fit (``range_selection="model"``): ``scales`` are the filters'
        dilations, ``measures`` the quadratic variations ``V_f``, ``model``
        the fitted ``sigma^2 exp(a_f(H))``; ``extra`` holds ``hurst``,
        ``filters`` (order, direction, dilation) and ``counts``.

    References
    ----------
    Kent, J. T., Wood, A. T. A. (1997). *J. R. Statist. Soc. B* 59(3),
    679-699. https://doi.org/10.1111/1467-9868.00091
    Istas, J., Lang, G. (1997). *Ann. Inst. H. Poincaré* 33(4), 407-436.
    https://doi.org/10.1016/S0246-0203(97)80099-4

    Examples
    --------
    >>> import fractalgeo_rs as fg
    >>> z = fg.fbm_surface((32, 32), 0.5, method="exact", seed=1)
    >>> fit = fg.dimension(z, method="gls")
    >>> abs(fit.dimension - 2.5) < 4 * fit.stderr
    True
    """
    z = with_nodata(real_array(data, (1, 2)), data, nodata)
    if not isinstance(anisotropy, (bool, np.bool_)):
        raise TypeError(f"anisotropy: expected True or False, got {anisotropy!r}")
    k = check_dilations(dilations)
    shape = _design(z.shape, design)
    t = tables(shape, k)
    V, n = quadratic_variations(z, k)
    if not np.all(n > 0) or not np.all(V > 0):
        raise ValueError("data: too few valid increments (or a constant input) for the GLS fit")
    H, se = solve(t, np.log(V))
    cells = np.prod(shape)
    valid = np.count_nonzero(~np.isnan(z))
    se *= np.sqrt(cells / valid)
    off = 2.0 if z.ndim == 1 else 3.0
    a, _, _ = interp(t, H)
    labels = [f[3] for f in t["filters"]]
    extra = {"hurst": H, "filters": labels, "counts": n}
    if anisotropy:
        if z.ndim != 2:
            raise ValueError("anisotropy: defined for surfaces (2D) only")
        extra["anisotropy_angle"], extra["anisotropy_ratio"] = anisotropy_from_variations(V, labels, H)
    log_s2 = float(np.mean(np.log(V) - a))
    fit = DimensionFit.from_model(
        dimension=off - H, stderr=se, scales=[lab[2] for lab in labels], measures=V,
        model=np.exp(a + log_s2), method="gls", dim_offset=off, x_label="dilation",
        y_label="quadratic variation",
        extra=extra,
    )
    msg = _pinned_message(H, off)
    if msg:
        from fractalgeo_rs.fit import mark_invalid

        fit = mark_invalid(fit, "pinned", f"gls: {msg}")
    return fit


def _pinned_message(H: float, off: float) -> str:
    """Why an estimate at an end of :data:`H_GRID` is not a valid one ('' if
    it is inside)."""
    lo, hi = float(H_GRID[0]), float(H_GRID[-1])
    if H >= hi - 1e-6:
        return (f"H = {H:.3f} is pinned at the upper end of the H grid (D = {off - H:.3f}): the data are "
                f"smoother than fBm at dilations 1-2 (H >= 1 there), beyond the model; no valid interval. Use "
                f"an estimator over larger scales (e.g. variogram or surface_variation with larger lags)")
    if H <= lo + 1e-6:
        return (f"H = {H:.3f} is pinned at the lower end of the H grid (D = {off - H:.3f}): the data are "
                f"rougher than fBm (white noise, speckle); no valid interval")
    return ""


def warn_pinned_map(d: np.ndarray, off: float = 3.0) -> None:
    """One ``FractalRangeWarning`` giving the fraction of a GLS map's
    windows pinned at an end of the H grid, when there are any."""
    import warnings

    from fractalgeo_rs._warn import user_stacklevel
    from fractalgeo_rs.fit import FractalRangeWarning

    v = d[np.isfinite(d)]
    if v.size == 0:
        return
    hi = np.mean(v <= off - float(H_GRID[-1]) + 1e-4)
    lo = np.mean(v >= off - float(H_GRID[0]) - 1e-4)
    for frac, end, what in [(hi, "upper", "smoother than fBm at dilations 1-2 (use a larger-scale method)"),
                            (lo, "lower", "rougher than fBm (white noise, speckle)")]:
        if frac > 0:
            warnings.warn(f"gls: {100 * frac:.1f} % of the windows are pinned at the {end} end of the H grid "
                          f"(D = {off - (float(H_GRID[-1]) if end == 'upper' else float(H_GRID[0])):.2f}): "
                          f"the data there are {what}; those values are bounds, not estimates",
                          FractalRangeWarning, stacklevel=user_stacklevel())


def anisotropy_from_variations(V: np.ndarray, labels: Sequence[tuple], hurst: float) -> Tuple[float, float]:
    """(direction in degrees, ratio >= 1) of geometric anisotropy from the
    first-order directional quadratic variations of a surface.

    Model: the variogram is ``sigma^2 |A h|^(2H)`` for a 2 x 2 matrix ``A``
    (an affine change of coordinates of an isotropic field). With ``M = A'
    A``, the first differences along the step ``e`` at dilation ``u`` have
    ``E V = sigma^2 (u^2 e' M e)^H``, so ``q_e = exp(mean over u of (log V /
    H - 2 log u))`` is proportional to ``e' M e`` for the four steps rows
    ``(0, 1)``, columns ``(1, 0)``, diagonal ``(1, 1)`` and anti-diagonal
    ``(1, -1)`` (``(row, col)``). ``M`` is their least-squares fit (closed
    form), the direction is that of its leading eigenvector, i.e. of the
    fastest variation, in degrees in ``[0, 180)`` from the column axis
    ``+j`` towards the row axis ``+i``, and the ratio is ``sqrt(lambda_max /
    lambda_min)`` (the ratio of the singular values of ``A``; 1 for an
    isotropic field, NaN when ``M`` is not positive definite). The same
    formulas as the map's ``anisotropy=True``.
    """
    k = max(u for o, _, u in labels)
    q = np.zeros(4)
    for v, (order, di, u) in zip(V, labels):
        if order == 1:
            q[di] += (np.log(v) / hurst - 2 * np.log(u)) / k
    q = np.exp(q)
    m_rc = (q[2] - q[3]) / 4.0
    e = (q[0] + q[1] - (q[2] + q[3]) / 2.0) / 5.0
    m_cc, m_rr = q[0] - 2.0 * e, q[1] - 2.0 * e
    half = (m_rr + m_cc) / 2.0
    rad = np.hypot((m_rr - m_cc) / 2.0, m_rc)
    phi = 0.5 * np.arctan2(2.0 * m_rc, m_rr - m_cc)
    ang = float((90.0 - np.degrees(phi)) % 180.0)
    lmin = half - rad
    return ang, float(np.sqrt((half + rad) / lmin)) if lmin > 0 else float("nan")


def gls_grid(z: np.ndarray, w: int, dilations: int, min_valid: float, step: int, n_threads,
             anisotropy: bool = False) -> list:
    """Maps of ``fractal_transform(..., method="gls")`` on the ``step`` grid:
    [D, se of D] (and [angle, ratio] with ``anisotropy``), float32."""
    from fractalgeo_rs import _core

    k = check_dilations(dilations)
    if 4 * k >= w:
        raise ValueError(f"dilations: {k} needs a window of at least {4 * k + 1} pixels, got {w}")
    t = tables((w, w), k)
    dh = float(H_GRID[1] - H_GRID[0])
    maps = _core.gls_transform_map(z, w, k, float(H_GRID[0]), dh, t["a"], t["da"], t["g"], t["se"].tolist(),
                                   N_STEPS, min_valid, step, anisotropy, n_threads)
    np.subtract(np.float32(3.0), maps[0], out=maps[0])  # H -> D in place (float32, as returned)
    return maps
