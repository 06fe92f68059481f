"""Increment-based estimators: variogram, madogram, power variations (1D) and
their 2D versions (transect medians, isotropic variogram, Kent-Wood
increment filters).

For a profile with Hurst exponent ``H`` the mean ``p``-th power of increments
at lag ``l`` scales as ``l^(pH)``, so the slope of ``log V_p(l)`` against
``log l`` is ``pH`` and

    D = 2 - slope / p      (profiles),        D = 3 - slope / p   (surfaces).

Gneiting, Sevcikova and Percival (2012) show that the smallest lags (1 and 2)
give the most accurate estimates; that is the default.

References
----------
Gneiting, T., Sevcikova, H., Percival, D. B. (2012). Estimators of fractal
dimension: assessing the roughness of time series and spatial data.
*Statistical Science* 27(2), 247-277.
Kent, J. T., Wood, A. T. A. (1997). Estimating the fractal dimension of a
locally self-similar Gaussian process by using increments. *J. R. Statist.
Soc. B* 59(3), 679-699.
Chan, G., Wood, A. T. A. (2000). Increment-based estimators of fractal
dimension for two-dimensional surface data. *Statistica Sinica* 10, 343-376.
"""
from __future__ import annotations

from dataclasses import replace
from typing import Optional, Sequence

import numpy as np

from fractalgeo_rs._validation import check_choice, check_integer_lags, check_positive_float
from fractalgeo_rs.dimension._common import real_array, with_nodata
from fractalgeo_rs.fit import DimensionFit, ScaleRange, check_domain, fit_loglog

__all__ = ["power_variation", "variogram", "madogram", "surface_variation"]


def _check_lags(lags, n_max: int, name="lags") -> np.ndarray:
    try:
        lg = np.asarray(check_integer_lags(lags, name, minimum=-(2**62)), dtype=np.int64)
    except (TypeError, ValueError) as exc:
        raise TypeError(f"{name}: expected a sequence of positive integer lags (1.5 is not a lag), "
                        f"got {lags!r}") from exc
    if lg.size < 2:
        raise ValueError(f"{name}: need at least 2 distinct lags, got {lg.size}")
    if lg[0] < 1:
        raise ValueError(f"{name}: lags must be positive, got {lg[0]}")
    if lg[-1] > n_max:
        raise ValueError(f"{name}: lag {lg[-1]} leaves no increment (largest usable lag {n_max})")
    return lg


def _increments(z: np.ndarray, lag: int, order: int, axis: int) -> np.ndarray:
    """First or second differences at ``lag`` along ``axis`` (NaN propagates)."""
    n = z.shape[axis]

    def take(a, b):  # a view, not a copy
        idx = [slice(None)] * z.ndim
        idx[axis] = slice(a, b)
        return z[tuple(idx)]

    if order == 1:
        return take(lag, n) - take(0, n - lag)
    return take(2 * lag, n) - 2 * take(lag, n - lag) + take(0, n - 2 * lag)


def _powers(inc: np.ndarray, p: float) -> np.ndarray:
    """``|inc|^p`` (in place on the temporary ``inc``)."""
    if p == 2.0:
        return np.square(inc, out=inc)
    np.abs(inc, out=inc)
    return inc if p == 1.0 else np.power(inc, p, out=inc)


def _mean_power(inc: np.ndarray, p: float) -> float:
    """Half the mean of ``|inc|^p`` over the non-NaN increments (``inc`` is
    a temporary and is overwritten)."""
    v = _powers(inc, p)
    nan = np.isnan(v)
    if nan.any():
        v = v[~nan]
    if v.size == 0:
        return np.nan
    return float(np.mean(v)) / 2.0


def _line_means(z: np.ndarray, lag: int, p: float, axis: int) -> np.ndarray:
    """Per line (rows for ``axis=1``) half mean of ``|first difference|^p``
    at ``lag``, NaN increments left out (NaN for a line without any)."""
    v = _powers(_increments(z, lag, 1, axis), p)
    nan = np.isnan(v)
    if not nan.any():
        return v.mean(axis=axis) / 2.0
    cnt = np.count_nonzero(~nan, axis=axis)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(cnt > 0, np.where(nan, 0.0, v).sum(axis=axis) / np.maximum(cnt, 1), np.nan) / 2.0


def power_variation(
    data,
    *,
    p: float = 1.0,
    order: int = 2,
    lags: Sequence[int] = (1, 2),
    nodata: Optional[float] = None,
    scale_range: ScaleRange = None,
) -> DimensionFit:
    """Power-variation estimator of the dimension of a profile.

    .. math::

        V_p(l) = \\frac{1}{2 (n - k l)} \\sum_i |\\Delta^k_l x_i|^p \\propto l^{pH},
        \\qquad D = 2 - \\frac{\\text{slope}}{p}

    with first (``order=1``, ``Delta x_i = x_{i+l} - x_i``) or second
    (``order=2``, ``x_{i+2l} - 2 x_{i+l} + x_i``) differences. ``p=2, order=1``
    is the variogram, ``p=1, order=1`` the madogram; second differences stay
    unbiased for H close to 1 (Gneiting et al. 2012, Kent and Wood 1997).

    Parameters
    ----------
    data : array_like, shape (n,)
        Profile sampled at regular spacing. NaN (and ``nodata``) samples are
        skipped: an increment touching one is left out.
    p : float, default 1
        Power (> 0).
    order : {1, 2}, default 2
        Order of the differences.
    lags : sequence of int, default (1, 2)
        Lags in samples; the default is the recommendation of Gneiting et al.
    nodata : float, optional
        Value marking missing samples, in addition to NaN.
    scale_range : None, "auto" or (low, high)
        Lags used in the fit.

    Returns
    -------
    DimensionFit
        ``scales`` are the lags, ``measures`` ``V_p(l)``; ``extra["hurst"]``
        is ``slope / p``. With two lags the fit is exact: ``stderr`` and
        ``ci95`` are NaN.

    References
    ----------
    Gneiting, Sevcikova and Percival (2012), doi:10.1214/11-STS370; full entry in the
    :ref:`bibliography <ref-gneiting2012>`.

    Kent and Wood (1997), doi:10.1111/1467-9868.00091; full entry in the
    :ref:`bibliography <ref-kent1997>`.

    Examples
    --------
    >>> import fractalgeo_rs as fg
    >>> x = fg.fbm(4096, 0.5, method='exact', seed=0)  # D = 2 - H = 1.5
    >>> round(fg.power_variation(x).dimension, 1)  # p = 1, second-order increments
    1.5
    >>> round(fg.power_variation(x, p=2.0, order=1).dimension, 1)  # the variogram
    1.5
    """
    z = with_nodata(real_array(data, (1,)), data, nodata)
    p = check_positive_float(p, "p")
    if order not in (1, 2) or isinstance(order, bool):
        raise ValueError(f"order: expected 1 or 2, got {order!r}")
    lg = _check_lags(lags, (len(z) - 1) // order)
    meas = np.array([_mean_power(_increments(z, int(l), order, 0), p) for l in lg])
    if np.isnan(meas).any() or (meas == 0).all():
        raise ValueError("data: no valid increments at some lag (too many NaN) or a constant profile")
    # the dispatcher key of the estimator, so that
    # dimension(data, method=fit.method) computes the same fit again
    name = {(2.0, 1): "variogram", (1.0, 1): "madogram"}.get((p, order), "variation")
    fit = fit_loglog(lg, meas, method=name, dim_offset=2.0, dim_factor=-1.0 / p, scale_range=scale_range,
                     min_scales=2, x_label="lag l (samples)", y_label=f"V_{p:g}(l)",
                     domain=(1.0, 2.0), open_domain=True, restrict=True,
                     extra={"p": p, "order": order})
    fit.extra["hurst"] = fit.slope / p
    return fit


def _first_order(data, p: float, name: str, lags, nodata, scale_range) -> DimensionFit:
    if np.ndim(data) == 2:
        fit = surface_variation(data, estimator="first", p=p, lags=lags, nodata=nodata, scale_range=scale_range)
        return replace(fit, method=name)
    return power_variation(data, p=p, order=1, lags=lags, nodata=nodata, scale_range=scale_range)


def variogram(data, *, lags: Sequence[int] = (1, 2), nodata: Optional[float] = None,
              scale_range: ScaleRange = None) -> DimensionFit:
    """Variogram estimator of the dimension of a profile or a surface.

    Profiles: :func:`power_variation` with ``p=2, order=1`` (Gneiting et al.
    2012), ``D = 2 - slope / 2``. Surfaces (2D input): the isotropic
    variogram on the axes, :func:`surface_variation` with
    ``estimator="first", p=2``, ``D = 3 - slope / 2``.

    Parameters
    ----------
    data : array_like, shape (n,) or (rows, cols)
        The profile or surface, on a regular grid. NaN and ``nodata`` are skipped.
    lags : sequence of int, default (1, 2)
        Lags in samples; the default pair is the recommendation of Gneiting et
        al. (2012).
    nodata : float, optional
        Value meaning "no data".
    scale_range : None, "auto" or (low, high)
        Lags used in the fit; see :func:`fractalgeo_rs.fit.fit_loglog`.

    Returns
    -------
    DimensionFit
        ``measures`` are half the mean squared increments at ``lags`` (the
        semivariogram);
        ``extra["hurst"]`` is ``2 - D``. With two lags the fit is exact and its
        interval is NaN.

    References
    ----------
    Gneiting, Sevcikova and Percival (2012), doi:10.1214/11-STS370; full entry in the
    :ref:`bibliography <ref-gneiting2012>`.

    Examples
    --------
    >>> import numpy as np, fractalgeo_rs as fg
    >>> round(fg.variogram(np.arange(100.0)).dimension, 6)  # a line: gamma(k) = k^2, D = 1
    1.0
    >>> x = fg.fbm(4096, 0.3, method='exact', seed=0)  # D = 2 - H = 1.7
    >>> round(fg.variogram(x).dimension, 1)
    1.7
    """
    return _first_order(data, 2.0, "variogram", lags, nodata, scale_range)


def madogram(data, *, lags: Sequence[int] = (1, 2), nodata: Optional[float] = None,
             scale_range: ScaleRange = None) -> DimensionFit:
    """Madogram estimator of the dimension of a profile or a surface.

    Profiles: :func:`power_variation` with ``p=1, order=1`` (Gneiting et al.
    2012), ``D = 2 - slope``. Surfaces (2D input): :func:`surface_variation`
    with ``estimator="first", p=1``, ``D = 3 - slope``.

    Parameters
    ----------
    data : array_like, shape (n,) or (rows, cols)
        The profile or surface, on a regular grid. NaN and ``nodata`` are skipped.
    lags : sequence of int, default (1, 2)
        Lags in samples; the default pair is the recommendation of Gneiting et
        al. (2012).
    nodata : float, optional
        Value meaning "no data".
    scale_range : None, "auto" or (low, high)
        Lags used in the fit; see :func:`fractalgeo_rs.fit.fit_loglog`.

    Returns
    -------
    DimensionFit
        ``measures`` are half the mean absolute increments at ``lags``;
        ``extra["hurst"]`` is ``2 - D``. With two lags the fit is exact and its
        interval is NaN.

    References
    ----------
    Gneiting, Sevcikova and Percival (2012), doi:10.1214/11-STS370; full entry in the
    :ref:`bibliography <ref-gneiting2012>`.

    Examples
    --------
    >>> import numpy as np, fractalgeo_rs as fg
    >>> round(fg.madogram(np.arange(100.0)).dimension, 6)  # a line: mean |increment| = k, D = 1
    1.0
    >>> x = fg.fbm(4096, 0.3, method='exact', seed=0)  # D = 2 - H = 1.7
    >>> round(fg.madogram(x).dimension, 1)
    1.7
    """
    return _first_order(data, 1.0, "madogram", lags, nodata, scale_range)


def surface_variation(
    data,
    *,
    estimator: str = "square",
    p: float = 2.0,
    lags: Sequence[int] = (1, 2),
    nodata: Optional[float] = None,
    scale_range: ScaleRange = None,
) -> DimensionFit:
    """Increment estimators of the dimension of a surface ``z(i, j)``.

    ``estimator`` chooses the increments at dilation ``u`` (in pixels):

    ``"square"`` (default)
        The square increment (Chan and Wood 2000),
        ``z(i+u, j+u) - z(i+u, j) - z(i, j+u) + z(i, j)``, whose mean ``p``-th
        power scales as ``u^(pH)`` for every ``H < 1``; it stays accurate for
        smooth surfaces (H >= 0.7) where first differences lose precision.
    ``"first"``
        First differences along rows and columns pooled
        (``z(i, j+u) - z(i, j)`` and ``z(i+u, j) - z(i, j)``): the isotropic
        variogram on the axes (Kent and Wood 1997).
    ``"transect"``
        The robust transect estimator: the profile estimator
        (:func:`power_variation` with first differences and power ``p``) on
        every row and every column, and the median of the dimensions, plus 1.

    ``D = 3 - slope / p`` (for ``"transect"``, 1 + the median profile D).

    Parameters
    ----------
    data : array_like, shape (rows, cols)
        Surface on a regular grid. NaN and ``nodata`` are skipped.
    p : float, default 2
        Power of the increments (2: variogram, 1: madogram).
    lags : sequence of int, default (1, 2)
        Dilations in pixels.

    Returns
    -------
    DimensionFit
        ``extra["hurst"]`` is ``3 - D``. For ``"transect"`` the fit shown is
        that of the pooled increments; ``dimension`` is the median and
        ``extra["transect_dimensions"]`` holds every row's and column's value.

    References
    ----------
    G. Chan and A. T. A. Wood, Increment-based estimators of fractal
    dimension for two-dimensional surface data, *Statistica Sinica* 10
    (2000) 343-376.

    Kent and Wood (1997), doi:10.1111/1467-9868.00091; full entry in the
    :ref:`bibliography <ref-kent1997>`.

    Examples
    --------
    >>> import fractalgeo_rs as fg
    >>> z = fg.fbm_surface((256, 256), 0.7, method='exact', seed=1)  # D = 3 - H = 2.3
    >>> fit = fg.surface_variation(z)
    >>> round(fit.dimension, 1), round(fit.extra['hurst'], 1)
    (2.3, 0.7)
    >>> round(fg.surface_variation(z, estimator='transect').dimension, 1)
    2.3
    """
    z = with_nodata(real_array(data, (2,)), data, nodata)
    check_choice(estimator, "estimator", ("square", "first", "transect"))
    p = check_positive_float(p, "p")
    lg = _check_lags(lags, min(z.shape) - 1)

    def pooled(order_fn) -> np.ndarray:
        return np.array([_mean_power(order_fn(int(u)), p) for u in lg])

    if estimator == "square":
        def inc(u):
            return (z[u:, u:] - z[u:, :-u] - z[:-u, u:] + z[:-u, :-u]).ravel()
    else:
        def inc(u):
            return np.concatenate([_increments(z, u, 1, 1).ravel(), _increments(z, u, 1, 0).ravel()])
    meas = pooled(inc)
    if np.isnan(meas).any() or (meas == 0).all():
        raise ValueError("data: no valid increments at some lag (too many NaN) or a constant surface")
    fit = fit_loglog(lg, meas, method="surface_variation", dim_offset=3.0, dim_factor=-1.0 / p,
                     scale_range=scale_range, min_scales=2, x_label="dilation u (pixels)",
                     domain=(2.0, 3.0), open_domain=True, validate=False, restrict=True,
                     y_label=f"V_{p:g}(u)", extra={"p": p, "estimator": estimator})
    if estimator == "transect":
        used = fit.scales[fit.used].astype(int)
        # (lines, lags) table of V_p per row, then per column; least-squares
        # slope of every line at once (the same as np.polyfit per line)
        m = np.concatenate([np.stack([_line_means(z, int(u), p, a) for u in used], axis=1) for a in (1, 0)])
        ok = np.all(m > 0, axis=1) & np.isfinite(m).all(axis=1)
        x = np.log(used.astype(np.float64))
        xc = x - x.mean()
        y = np.log(m[ok])
        slope = (y - y.mean(axis=1, keepdims=True)) @ xc / np.dot(xc, xc)
        dims = list(2.0 - slope / p)
        if not dims:
            raise ValueError("data: no row or column with valid increments")
        med = float(np.median(dims)) + 1.0
        # standard error of a median: sqrt(pi / 2) * sd / sqrt(n)
        se = float(np.sqrt(np.pi / 2) * np.std(dims, ddof=1) / np.sqrt(len(dims))) if len(dims) > 1 else float("nan")
        object.__setattr__(fit, "dimension", med)
        object.__setattr__(fit, "stderr", se)
        object.__setattr__(fit, "ci95", (med - 1.96 * se, med + 1.96 * se))
        fit.extra["transect_dimensions"] = np.asarray(dims) + 1.0
    fit = check_domain(fit, open_domain=True)
    fit.extra["hurst"] = 3.0 - fit.dimension
    return fit
