"""The result object every dimension estimator returns.

An estimator measures a quantity ``M(s)`` at scales ``s`` (box counts against
box size, areas against radius, ...) and the dimension follows from the slope
of the ordinary least-squares line through ``(log s, log M(s))``:

    D = dim_offset + dim_factor * slope

(box counting: ``D = -slope``; Minkowski sausage in the plane:
``D = 2 - slope``). :func:`~fractalgeo_rs.fit.fit_loglog` does the fit, the choice of scale range
and the uncertainty; :class:`~fractalgeo_rs.DimensionFit` holds the result and draws it.
"""
from __future__ import annotations

import functools
import math
import warnings
from dataclasses import dataclass, field, replace
from typing import Any, Dict, Mapping, Optional, Tuple, Union

import numpy as np
from numpy.typing import ArrayLike

from fractalgeo_rs._scales import MIN_SEGMENT, find_break
from fractalgeo_rs._warn import user_stacklevel

__all__ = ["DimensionFit", "FractalRangeWarning", "ScaleSegment", "fit_loglog"]

ScaleRange = Union[None, str, Tuple[float, float]]

SMOOTH_HURST = 0.85
"""Of two regimes of a graph, one with ``H >= SMOOTH_HURST`` is the smooth
range (not fractal), whatever the other."""

SET_TOLERANCE = 0.02
"""A set's box dimension this far outside ``[0, n]`` is still valid."""

BREAK_MARGIN = 2.0
"""The default fit of a fractal range starts this factor beyond the break."""


class FractalRangeWarning(UserWarning):
    """A dimension outside its valid domain, pinned at a bound of a search,
    or fitted on part of the scales only (the data are not fractal over the
    whole range).

    The message names the cause and the remedy; the fit object carries the
    same text in ``warning`` and the cause in ``flags``.

    Attributes
    ----------
    args : tuple of str
        The message.

    References
    ----------
    Gneiting, Sevcikova and Percival (2012), doi:10.1214/11-STS370; full entry in the
    :ref:`bibliography <ref-gneiting2012>`.

    Examples
    --------
    >>> import warnings, numpy as np, fractalgeo_rs as fg
    >>> with warnings.catch_warnings(record=True) as rec:
    ...     warnings.simplefilter("always")
    ...     fit = fg.variogram(np.arange(100.0))  # a line: H = 1, smooth
    >>> fit.valid, fit.flags, rec[0].category.__name__
    (False, ('below_domain',), 'FractalRangeWarning')
    """


@dataclass(frozen=True)
class ScaleSegment:
    """One regime of a log-log relation: an element of
    :attr:`fractalgeo_rs.DimensionFit.ranges`.

    When a continuous broken line (two least-squares segments meeting at a
    break scale) fits ``(log s, log M)`` better than one line by the
    Bayesian information criterion, with at least 4 scales on each side,
    the fit reports the two segments; otherwise one segment over the fitted
    scales.

    Attributes
    ----------
    scale_range : tuple of float
        Smallest and largest scale of the segment (the break scale is shared
        by the two segments of a broken line), in the units of the scales.
    dimension, slope : float
        Dimension (``dim_offset + dim_factor * slope``) and log-log slope of
        the segment (continuous broken-line fit).
    n_scales : int
        Measured scales inside the segment.
    valid : bool
        Whether the dimension lies in the estimator's valid domain.

    References
    ----------
    Schwarz (1978), doi:10.1214/aos/1176344136; full entry in the
    :ref:`bibliography <ref-schwarz1978>`.

    Examples
    --------
    A power law whose exponent changes from -2 to -1.2 at scale 16 (box
    counts of a set that is 2-dimensional below 16 and 1.2-dimensional
    above):

    >>> import numpy as np
    >>> from fractalgeo_rs.fit import fit_loglog
    >>> s = 2.0 ** np.arange(12)
    >>> m = np.where(s <= 16, s ** -2.0, 16.0 ** -2.0 * (s / 16) ** -1.2)
    >>> fit = fit_loglog(s, m, method="broken")
    >>> [(round(r.scale_range[0], 3), round(r.scale_range[1], 3), round(r.dimension, 6), r.n_scales)
    ...  for r in fit.ranges]
    [(1.0, 16.0, 2.0, 4), (16.0, 2048.0, 1.2, 8)]
    """

    scale_range: Tuple[float, float]
    dimension: float
    slope: float
    n_scales: int
    valid: bool


@dataclass(frozen=True)
class DimensionFit:
    """A fractal dimension estimated from a log-log regression.

    Attributes
    ----------
    dimension : float
        The estimated dimension ``D = dim_offset + dim_factor * slope``.
    slope, intercept : float
        OLS line ``log M = intercept + slope * log s`` (natural logarithms)
        over the scales used.
    r_squared : float
        Coefficient of determination of that line (1.0 for a perfect power law).
    stderr : float
        Standard error of ``dimension`` (``|dim_factor|`` times the slope's
        OLS standard error; 0 when the points are exactly collinear).
    ci95 : tuple of float
        95 % confidence interval of ``dimension`` from Student's t with
        ``n_used - 2`` degrees of freedom. The log-log residuals of nested
        boxes are correlated, so this interval is nominal: it measures how
        straight the line is, not the spread over realisations of a random set.
    scales : ndarray
        Every scale measured (box sizes, radii, ...), ascending, in the data's
        units (samples for rasters, coordinate units for point sets).
    measures : ndarray
        The measure at each scale (e.g. the number of occupied boxes).
    used : ndarray of bool
        Which scales entered the fit.
    scale_range : tuple of float
        Smallest and largest scale used.
    method : str
        Name of the estimator.
    range_selection : str
        ``"all"``, ``"user"`` or ``"auto"`` (the most linear range, see
        :func:`~fractalgeo_rs.fit.fit_loglog`).
    extra : mapping
        Method-specific results (e.g. ``hurst`` for self-affine counting, the
        counts of every lattice offset).
    model : ndarray or None
        Model-based estimates only (``range_selection == "model"``, built by
        :meth:`~fractalgeo_rs.DimensionFit.from_model`, e.g. the Whittle likelihood): the fitted model's
        value of the measure at each scale, drawn by :meth:`~fractalgeo_rs.DimensionFit.plot` instead of
        a line. ``None`` for log-log regressions.
    valid : bool
        ``False`` when ``dimension`` lies outside the estimator's valid
        domain (``domain``; e.g. ``H >= 1`` or ``H <= 0`` for a graph) or a
        likelihood search stopped at its bound; ``stderr`` and ``ci95`` are
        then NaN and a :class:`~fractalgeo_rs.FractalRangeWarning` was issued.
    flags : tuple of str
        Causes: ``"below_domain"`` (smooth at the fitted scales),
        ``"above_domain"`` (rougher than any graph: noise or speckle),
        ``"pinned"`` (search bound), ``"range_restricted"`` (the default fit
        dropped a regime outside the domain and fitted the fractal range),
        ``"unresolved"`` (point box counting: fewer than 3 fitted box sizes
        with distinct counts, not an estimate; ``valid`` is False),
        ``"undersampled"`` (point box counting: too few points per box).
    warning : str
        The warning's text ("" when none).
    ranges : tuple of ScaleSegment
        The regimes found among the fitted scales: one segment when the
        log-log relation is straight, two when a broken line fits better by
        BIC (a continuous two-segment least-squares line, its break searched
        between the scales) with at least 4 scales per segment; empty with
        fewer than 8 scales. Of two
        regimes of a graph, one with ``H >= SMOOTH_HURST`` (0.85) or a
        dimension outside ``domain`` is not valid (smooth, or noise); the
        default fit then uses the other regime from ``BREAK_MARGIN`` (2)
        times the break scale on (the transition fades over about an
        octave: on Gaussian-smoothed fBm profiles the dimension fitted from
        the break itself reads 0.02-0.05 too smooth, from twice the break
        within 0.025, ``tests/test_scales.py``).
    domain : tuple of float or None
        Valid interval of ``dimension`` (``None``: not checked).

    References
    ----------
    Falconer (1990); full entry in the :ref:`bibliography <ref-falconer1990>`.

    Gneiting, Sevcikova and Percival (2012), doi:10.1214/11-STS370; full entry in the
    :ref:`bibliography <ref-gneiting2012>`.

    Examples
    --------
    >>> import numpy as np, fractalgeo_rs as fg
    >>> fit = fg.box_counting(np.ones((64, 64), dtype=bool))  # a filled square: D = 2
    >>> round(fit.dimension, 6), round(fit.r_squared, 6)
    (2.0, 1.0)
    >>> fit.scales.tolist()
    [1.0, 2.0, 4.0, 8.0, 16.0]
    >>> fit.measures.tolist()
    [4096.0, 1024.0, 256.0, 64.0, 16.0]
    """

    dimension: float
    slope: float
    intercept: float
    r_squared: float
    stderr: float
    ci95: Tuple[float, float]
    scales: np.ndarray
    measures: np.ndarray
    used: np.ndarray
    scale_range: Tuple[float, float]
    method: str
    range_selection: str = "all"
    dim_offset: float = 0.0
    dim_factor: float = -1.0
    x_label: str = "scale"
    y_label: str = "measure"
    extra: Dict[str, Any] = field(default_factory=dict)
    model: Optional[np.ndarray] = None
    valid: bool = True
    flags: Tuple[str, ...] = ()
    warning: str = ""
    ranges: Tuple[ScaleSegment, ...] = ()
    domain: Optional[Tuple[float, float]] = None

    @classmethod
    def from_model(
        cls,
        *,
        dimension: float,
        stderr: float,
        scales: "ArrayLike",
        measures: "ArrayLike",
        model: "ArrayLike",
        method: str,
        dim_offset: float = 0.0,
        x_label: str = "scale",
        y_label: str = "measure",
        extra: Optional[Mapping[str, Any]] = None,
    ) -> "DimensionFit":
        """A dimension estimated by fitting a model rather than a line.

        Likelihood estimators (e.g. :func:`fractalgeo_rs.whittle`) estimate
        ``D`` directly; there is no regression line. Their fit object keeps
        the log-log data for :meth:`~fractalgeo_rs.DimensionFit.plot` (``scales``, ``measures`` and the
        fitted ``model`` at the same scales), ``slope`` and ``intercept``
        are NaN, ``r_squared`` is the coefficient of determination of
        ``log measures`` by ``log model``, ``ci95`` is
        ``dimension +- 1.96 stderr`` (normal approximation) and
        ``range_selection`` is ``"model"``.

        Parameters
        ----------
        dimension, stderr : float
            The estimate and its standard error.
        scales, measures, model : sequence of float
            Log-log data and the fitted model at the same scales (positive).
        method : str
            Name recorded in the result.
        dim_offset : float
            Recorded as ``dim_offset`` (e.g. 3 for ``D = 3 - H``); the
            ``dim_factor`` is -1.
        x_label, y_label : str
            Axis labels of :meth:`~fractalgeo_rs.DimensionFit.plot`.
        extra : mapping, optional
            Method-specific results.

        Returns
        -------
        DimensionFit
        """
        s = np.asarray(scales, dtype=float)
        m = np.asarray(measures, dtype=float)
        mo = np.asarray(model, dtype=float)
        if s.ndim != 1 or s.shape != m.shape or s.shape != mo.shape or s.size == 0:
            raise ValueError("scales: scales, measures and model must be non-empty 1D arrays of the same length")
        order = np.argsort(s, kind="stable")
        s, m, mo = s[order], m[order], mo[order]
        used = np.isfinite(s) & np.isfinite(m) & np.isfinite(mo) & (s > 0) & (m > 0) & (mo > 0)
        r2 = float("nan")
        if np.count_nonzero(used) > 1:
            ly, lm = np.log(m[used]), np.log(mo[used])
            syy = float(np.sum((ly - ly.mean()) ** 2))
            r2 = 1.0 - float(np.sum((ly - lm) ** 2)) / syy if syy > 0 else 1.0
        half = 1.959963984540054 * float(stderr)
        lo, hi = (float(s[used][0]), float(s[used][-1])) if used.any() else (float("nan"), float("nan"))
        return cls(
            dimension=float(dimension), slope=float("nan"), intercept=float("nan"), r_squared=r2,
            stderr=float(stderr), ci95=(float(dimension) - half, float(dimension) + half),
            scales=s, measures=m, used=used, scale_range=(lo, hi), method=method,
            range_selection="model", dim_offset=float(dim_offset), dim_factor=-1.0,
            x_label=x_label, y_label=y_label, extra=dict(extra or {}), model=mo,
        )

    @property
    def n_used(self) -> int:
        """Number of scales in the fit."""
        return int(np.count_nonzero(self.used))

    def __repr__(self) -> str:
        lo, hi = self.ci95
        extra = ""
        if "hurst" in self.extra:
            extra = f", hurst={self.extra['hurst']:.4f}"
        tail = ""
        if len(self.ranges) > 1:
            tail += ", ranges " + "; ".join(
                f"{r.scale_range[0]:.4g}..{r.scale_range[1]:.4g}: D={r.dimension:.3f}" for r in self.ranges)
        if self.flags:
            tail += f", flags={self.flags!r}"
        return (
            f"DimensionFit(method={self.method!r}, dimension={self.dimension:.4f}{extra}, "
            f"ci95=({lo:.4f}, {hi:.4f}), r_squared={self.r_squared:.6f}, "
            f"scales {self.scale_range[0]:g}..{self.scale_range[1]:g} "
            f"({self.n_used} of {len(self.scales)}, {self.range_selection}){tail})"
        )

    def interval_label(self) -> str:
        """``"D = 1.234, 95 % CI [1.200, 1.268]"``: the dimension and the
        interval ``ci95`` (the one printed by the demo and the CLI), or
        ``"D = 1.234 (no interval)"`` when ``ci95`` is undefined (an exact
        two-scale fit, or an invalid one).

        Returns
        -------
        str

        Examples
        --------
        >>> from fractalgeo_rs.fit import fit_loglog
        >>> fit = fit_loglog([1, 2, 4, 8], [100, 26, 6, 1.6], method="demo")
        >>> fit.interval_label() == f"D = {fit.dimension:.3f}, 95 % CI [{fit.ci95[0]:.3f}, {fit.ci95[1]:.3f}]"
        True
        """
        lo, hi = self.ci95
        if not (np.isfinite(lo) and np.isfinite(hi)):
            return f"D = {self.dimension:.3f} (no interval)"
        return f"D = {self.dimension:.3f}, 95 % CI [{lo:.3f}, {hi:.3f}]"

    def plot(self, ax=None, *, label: Optional[str] = None, color: Optional[str] = None):
        """Draw the log-log points and the fitted line.

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Axes to draw into; a new figure is made when omitted.
        label : str, optional
            Legend label of the points (default: the method name).
        color : str, optional
            Colour of points and line (default: the next colour of the
            cycle, so several fits can share one axes).

        Returns
        -------
        matplotlib.axes.Axes
        """
        try:
            import matplotlib.pyplot as plt
        except ImportError as exc:  # pragma: no cover - depends on the install
            raise ImportError(
                "DimensionFit.plot needs matplotlib: pip install 'fractalgeo_rs[plot]'"
            ) from exc
        if ax is None:
            _, ax = plt.subplots(figsize=(4.5, 3.6))
        s, m, u = self.scales, self.measures, self.used
        ok = m > 0
        if color is None:
            n_prev = sum(1 for line in ax.lines if str(line.get_label()).startswith("D = "))
            color = f"C{n_prev % 10}"
        ax.loglog(s[u & ok], m[u & ok], "o", color=color, label=label or self.method)
        if np.any(~u & ok):
            ax.loglog(s[~u & ok], m[~u & ok], "o", mfc="none", color=color, label="not fitted")
        if self.model is not None:
            ax.loglog(s[u], self.model[u], "-", color=color, label=self.interval_label() + " (model)")
        else:
            xs = np.array(self.scale_range, dtype=float)
            ax.loglog(xs, np.exp(self.intercept + self.slope * np.log(xs)), "-", color=color,
                      label=self.interval_label())
        if len(self.ranges) > 1:
            # the regimes: a broken line through the fitted points, and the
            # break scale
            ls = np.log(s[ok])
            lm = np.log(m[ok])
            for r in self.ranges:
                a, b = r.scale_range
                sel = (s[ok] >= a * (1 - 1e-9)) & (s[ok] <= b * (1 + 1e-9))
                if not sel.any():
                    continue
                c = float(np.mean(lm[sel] - r.slope * ls[sel]))
                xs = np.array([a, b])
                ax.loglog(xs, np.exp(c + r.slope * np.log(xs)), "--", color=color, alpha=0.6,
                          label=f"range {a:.4g}..{b:.4g}: D = {r.dimension:.3f}" + ("" if r.valid else " (invalid)"))
            ax.axvline(self.ranges[0].scale_range[1], color=color, lw=0.8, ls=":")
        from matplotlib.ticker import NullFormatter

        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.set_xlabel(self.x_label)
        ax.set_ylabel(self.y_label)
        ax.legend(fontsize="small")
        return ax


def _ols(x: np.ndarray, y: np.ndarray):
    n = len(x)
    xm, ym = x.mean(), y.mean()
    sxx = float(np.sum((x - xm) ** 2))
    sxy = float(np.sum((x - xm) * (y - ym)))
    slope = sxy / sxx
    intercept = ym - slope * xm
    resid = y - (intercept + slope * x)
    sse = float(np.sum(resid**2))
    syy = float(np.sum((y - ym) ** 2))
    r2 = 1.0 - sse / syy if syy > 0 else 1.0
    se = math.sqrt(sse / (n - 2) / sxx) if n > 2 else float("nan")
    return slope, float(intercept), r2, se


def _auto_range(x: np.ndarray, y: np.ndarray, min_points: int) -> Tuple[int, int]:
    """Contiguous range ``[i, j)`` of at least ``min_points`` scales that
    minimises the slope's standard error; ties go to the longer range, then to
    the finer scales."""
    n = len(x)
    best_key, best = None, (0, n)
    for i in range(n):
        for j in range(i + min_points, n + 1):
            se = _ols(x[i:j], y[i:j])[3]
            key = (round(se, 12), -(j - i), i)
            if best_key is None or key < best_key:
                best_key, best = key, (i, j)
    return best


def fit_loglog(
    scales: "ArrayLike",
    measures: "ArrayLike",
    *,
    method: str,
    dim_offset: float = 0.0,
    dim_factor: float = -1.0,
    scale_range: ScaleRange = None,
    min_points: Optional[int] = None,
    min_scales: int = 3,
    x_label: str = "scale",
    y_label: str = "measure",
    extra: Optional[Mapping[str, Any]] = None,
    domain: Optional[Tuple[float, float]] = None,
    open_domain: bool = False,
    validate: bool = True,
    restrict: bool = False,
) -> DimensionFit:
    """Fit ``log M = a + b log s`` and map the slope to a dimension.

    Parameters
    ----------
    scales, measures : sequence of float
        Scales (ascending after sorting) and positive measures.
    method : str
        Name recorded in the result.
    dim_offset, dim_factor : float
        ``D = dim_offset + dim_factor * slope``.
    scale_range : None, "all", "auto" or (float, float)
        ``None`` (default) fits every scale unless ``restrict`` and the scales show two
        regimes (see ``DimensionFit.ranges``) of which one gives a dimension
        outside ``domain`` (e.g. smooth below a few cells): then only the
        valid regime, the fractal range, is fitted
        (``range_selection == "fractal"``, flag ``"range_restricted"``, a
        :class:`~fractalgeo_rs.FractalRangeWarning`). ``"all"`` fits every scale whatever
        the regimes. A ``(low, high)`` pair fits the scales with
        ``low <= s <= high``; ``"auto"`` picks the contiguous range of at least
        ``min_points`` scales whose slope has the smallest standard error (a
        long straight range beats a short one; curvature at either end raises
        the error), and records the choice in ``scale_range`` and
        ``range_selection``.
    min_points : int, optional
        Fewest scales in an automatic range (default ``max(3, ceil(n / 2))``).
    min_scales : int, default 3
        Fewest scales a fit may use. Estimators that by design fit two lags
        (variogram and madogram at lags 1 and 2, Gneiting et al. 2012) pass 2;
        such a fit is exact, its ``stderr`` and ``ci95`` are NaN.
    domain : (float, float), optional
        Valid interval of the dimension: ``[d, d + 1]`` for the graph of a
        profile (``d = 1``) or surface (``d = 2``), ``[0, n]`` for a set in
        ``n`` dimensions. A fit outside it has ``valid=False``, NaN
        ``stderr`` and ``ci95``, a flag and a :class:`~fractalgeo_rs.FractalRangeWarning`
        naming the cause and the remedy.
    open_domain : bool, default False
        The bounds themselves are invalid (increment and spectral
        estimators: ``D = d`` means ``H = 1``, a smooth surface beyond the
        model, where the estimator saturates).
    restrict : bool, default False
        Let the default (``scale_range=None``) fit only the fractal range
        when the scales show a smooth or noise regime next to it. The
        increment estimators pass ``True`` (their scales are lags, whose
        measure is an unbiased mean at every scale); estimators whose
        large-scale measures are few and correlated (Higuchi, scale space,
        box counts) only report ``ranges``.
    validate : bool, default True
        Check the domain and warn now; estimators that change ``dimension``
        after the fit pass ``False`` and call ``fractalgeo_rs.fit.check_domain``.
    x_label, y_label : str
        Axis labels of :meth:`~fractalgeo_rs.DimensionFit.plot` (e.g. ``"box
        size (pixels)"``, ``"occupied boxes"``).
    extra : mapping, optional
        Method-specific results, kept in ``DimensionFit.extra``.

    Returns
    -------
    DimensionFit
        The dimension, the line (``slope``, ``intercept`` in natural
        logarithms, ``r_squared``), its uncertainty (``stderr``, ``ci95``)
        and the scales used.

    Notes
    -----
    The line is the ordinary least-squares fit over the scales used; the
    standard error of ``D`` is ``|dim_factor|`` times that of the slope and
    ``ci95`` uses Student's t with ``n_used - 2`` degrees of freedom.

    References
    ----------
    Falconer (1990), chapter 3 (box-counting dimension); full entry in the
    :ref:`bibliography <ref-falconer1990>`.

    Gneiting, Sevcikova and Percival (2012), doi:10.1214/11-STS370; full entry in the
    :ref:`bibliography <ref-gneiting2012>`.

    Examples
    --------
    Box counts ``N(s) = 5 s^-1.5`` give ``D = -slope = 1.5``:

    >>> import numpy as np
    >>> from fractalgeo_rs.fit import fit_loglog
    >>> s = 2.0 ** np.arange(6)
    >>> fit = fit_loglog(s, 5.0 * s ** -1.5, method="box counts", domain=(0.0, 2.0))
    >>> round(fit.dimension, 12), round(float(np.exp(fit.intercept)), 12), fit.r_squared
    (1.5, 5.0, 1.0)
    >>> fit.scale_range, fit.range_selection, fit.valid
    ((1.0, 32.0), 'all', True)
    """
    s = np.asarray(scales, dtype=float)
    m = np.asarray(measures, dtype=float)
    if s.shape != m.shape or s.ndim != 1:
        raise ValueError("scales: scales and measures must be 1D arrays of the same length")
    order = np.argsort(s, kind="stable")
    s, m = s[order], m[order]
    valid = np.isfinite(s) & np.isfinite(m) & (s > 0) & (m > 0)
    if np.count_nonzero(valid) < min_scales:
        raise ValueError(
            f"box_sizes: need at least {min_scales} scales with a positive measure for a fit, got {np.count_nonzero(valid)}"
        )
    if scale_range is None or (isinstance(scale_range, str) and scale_range == "all"):
        used = valid.copy()
        selection = "all"
    elif isinstance(scale_range, str):
        if scale_range != "auto":
            raise ValueError(f"scale_range: expected None, 'all', 'auto' or (low, high), got {scale_range!r}")
        idx = np.flatnonzero(valid)
        n = len(idx)
        if n < 3:
            raise ValueError(f"scale_range: 'auto' picks a range of at least 3 of the scales and there are {n} "
                             f"(give more scales, e.g. lags or box_sizes, or leave scale_range None)")
        mp = max(3, math.ceil(n / 2)) if min_points is None else int(min_points)
        if mp < 3 or mp > n:
            raise ValueError(f"min_points: expected an int in [3, {n}], got {min_points!r}")
        i, j = _auto_range(np.log(s[idx]), np.log(m[idx]), mp)
        used = np.zeros_like(valid)
        used[idx[i:j]] = True
        selection = "auto"
    else:
        try:
            lo, hi = (float(v) for v in scale_range)
        except (TypeError, ValueError):
            raise ValueError(f"scale_range: expected None, 'all', 'auto' or (low, high), got {scale_range!r}") from None
        if not (lo <= hi):
            raise ValueError(f"scale_range: low must not exceed high, got ({lo}, {hi})")
        used = valid & (s >= lo) & (s <= hi)
        if np.count_nonzero(used) < min_scales:
            raise ValueError(
                f"scale_range: ({lo:g}, {hi:g}) holds {np.count_nonzero(used)} usable scales, need at least {min_scales}"
            )
        selection = "user"
    dom = None if domain is None else (float(domain[0]), float(domain[1]))
    common = dict(scales=s, measures=m, method=method, dim_offset=float(dim_offset), dim_factor=float(dim_factor),
                  x_label=x_label, y_label=y_label, extra=dict(extra or {}), domain=dom)
    fit = _line_fit(used, selection, common)
    ranges = _ranges(s, used, m, dim_offset, dim_factor, dom, open_domain)
    fit = replace(fit, ranges=ranges)
    # graphs only: the broken line of a set's box counts can overshoot
    # [0, n] at the saturated ends without a second regime
    if (scale_range is None and restrict and dom is not None and dom[1] - dom[0] == 1.0 and len(ranges) > 1
            and any(r.valid for r in ranges) and not all(r.valid for r in ranges)):
        good = max((r for r in ranges if r.valid), key=lambda r: r.n_scales)
        bad = [r for r in ranges if not r.valid][0]
        sub = used & (s >= good.scale_range[0]) & (s <= good.scale_range[1])
        # the transition from the other regime fades over about an octave:
        # fit from one octave beyond the break when 3 scales remain there
        if good is ranges[1]:
            far = sub & (s >= BREAK_MARGIN * good.scale_range[0])
        else:
            far = sub & (s <= good.scale_range[1] / BREAK_MARGIN)
        if np.count_nonzero(far) >= 3:
            sub = far
        if np.count_nonzero(sub) >= max(min_scales, 3):
            fit = replace(_line_fit(sub, "fractal", common), ranges=ranges)
            cause = "smooth" if _below(bad.dimension, dom) else "rougher than a graph (noise)"
            msg = (f"{method}: the data are {cause} over {x_label} {bad.scale_range[0]:g}..{bad.scale_range[1]:g} "
                   f"(D = {bad.dimension:.3f}, outside [{dom[0]:g}, {dom[1]:g}]); fitted the fractal range "
                   f"{good.scale_range[0]:g}..{good.scale_range[1]:g} only (D = {fit.dimension:.3f}); "
                   f"pass scale_range='all' to fit every scale")
            fit = replace(fit, flags=("range_restricted",), warning=msg)
            warnings.warn(FractalRangeWarning(msg), stacklevel=user_stacklevel())
    if validate:
        fit = check_domain(fit, open_domain=open_domain)
    return fit


def _in_domain(d: float, dom: Tuple[float, float], open_domain: bool) -> bool:
    if not np.isfinite(d):
        return False
    # sets (domain [0, n]): finite samplings read a few hundredths outside
    tol = 1e-9 if dom[1] - dom[0] == 1.0 else SET_TOLERANCE
    if open_domain:
        return dom[0] + tol < d < dom[1] - tol
    return dom[0] - tol <= d <= dom[1] + tol


def _below(d: float, dom: Tuple[float, float]) -> bool:
    return d <= 0.5 * (dom[0] + dom[1])


def _t_central(t: float, df: int) -> float:
    """``P(|T| <= t)`` of Student's t with integer ``df`` degrees of freedom,
    in closed form (Abramowitz and Stegun 26.7.3 and 26.7.4): with
    ``theta = atan(t / sqrt(df))``, a finite series in ``cos(theta)^2``."""
    theta = math.atan(t / math.sqrt(df))
    c2 = math.cos(theta) ** 2
    if df % 2:  # odd: (2 / pi) (theta + sin cos (1 + 2/3 c2 + 2*4/(3*5) c2^2 + ...)), df - 3 / 2 terms
        total, term = 0.0, 1.0
        for k in range(1, (df - 1) // 2 + 1):
            total += term
            term *= c2 * (2 * k) / (2 * k + 1)
        series = math.sin(theta) * math.cos(theta) * total if df > 1 else 0.0
        return 2.0 / math.pi * (theta + series)
    total, term = 0.0, 1.0  # even: sin (1 + 1/2 c2 + 1*3/(2*4) c2^2 + ...), df / 2 terms
    for k in range(1, df // 2 + 1):
        total += term
        term *= c2 * (2 * k - 1) / (2 * k)
    return math.sin(theta) * total


@functools.lru_cache(maxsize=None)
def t_quantile_975(df: int) -> float:
    """The 0.975 quantile of Student's t with integer ``df >= 1`` degrees of
    freedom (the half-width factor of a 95 % interval): bisection on the
    closed-form distribution :func:`_t_central` to float precision (equal to
    ``scipy.special.stdtrit(df, 0.975)`` to 1e-12, without importing scipy,
    which costs about 0.3 s on first use)."""
    z = 1.959963984540054  # the normal quantile
    if df > 1000:  # Cornish-Fisher expansion in 1/df (Abramowitz and Stegun 26.7.5), error O(df^-5)
        v = float(df)
        return (z + (z**3 + z) / (4 * v) + (5 * z**5 + 16 * z**3 + 3 * z) / (96 * v**2)
                + (3 * z**7 + 19 * z**5 + 17 * z**3 - 15 * z) / (384 * v**3)
                + (79 * z**9 + 776 * z**7 + 1482 * z**5 - 1920 * z**3 - 945 * z) / (92160 * v**4))
    lo, hi = z, 12.71  # the df = 1 value is 12.706
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if mid in (lo, hi):
            break
        if _t_central(mid, df) < 0.95:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def _line_fit(used: np.ndarray, selection: str, common: dict) -> DimensionFit:
    s, m = common["scales"], common["measures"]
    dim_offset, dim_factor = common["dim_offset"], common["dim_factor"]
    x, y = np.log(s[used]), np.log(m[used])
    slope, intercept, r2, se = _ols(x, y)
    dim = dim_offset + dim_factor * slope
    dse = abs(dim_factor) * se
    if len(x) > 2:
        half = t_quantile_975(len(x) - 2) * dse
    else:
        dse = half = float("nan")
    return DimensionFit(
        dimension=float(dim),
        slope=float(slope),
        intercept=float(intercept),
        r_squared=float(r2),
        stderr=float(dse),
        ci95=(float(dim - half), float(dim + half)),
        used=used,
        scale_range=(float(s[used][0]), float(s[used][-1])),
        range_selection=selection,
        **common,
    )


def _ranges(s, used, m, dim_offset, dim_factor, dom, open_domain) -> Tuple[ScaleSegment, ...]:
    """One or two regimes among the used scales (see ``fractalgeo_rs._scales``)."""
    su = s[used]
    if su.size < 2 * MIN_SEGMENT:
        return ()
    x, y = np.log(su), np.log(m[used])
    brk = find_break(x, y, dim_factor=dim_factor)

    graph = dom is not None and dom[1] - dom[0] == 1.0

    def seg(a, b, slope, n, two):
        d = float(dim_offset + dim_factor * slope)
        ok = True if dom is None else _in_domain(d, dom, open_domain)
        # one of two regimes of a graph with H >= SMOOTH_HURST is the smooth
        # range (a broken line reaches the slope of H = 1 only at its end)
        if ok and two and graph and d - dom[0] <= 1.0 - SMOOTH_HURST:
            ok = False
        return ScaleSegment((float(a), float(b)), d, float(slope), int(n), bool(ok))

    if brk is None:
        slope = _ols(x, y)[0]
        return (seg(su[0], su[-1], slope, su.size, False),)
    xb, below, above = brk
    sb = float(np.exp(xb))
    return (seg(su[0], sb, below, np.count_nonzero(x <= xb), True),
            seg(sb, su[-1], above, np.count_nonzero(x >= xb), True))


def mark_invalid(fit: DimensionFit, flag: str, message: str) -> DimensionFit:
    """``fit`` with ``valid=False``, ``flag`` added, NaN ``stderr`` and
    ``ci95``, and ``message`` as its warning (issued as a
    ``FractalRangeWarning``)."""
    nan = float("nan")
    out = replace(fit, valid=False, flags=tuple(fit.flags) + (flag,), stderr=nan, ci95=(nan, nan),
                  warning=(fit.warning + " " + message).strip())
    warnings.warn(FractalRangeWarning(message), stacklevel=user_stacklevel())
    return out


def check_domain(fit: DimensionFit, *, open_domain: bool = False) -> DimensionFit:
    """Flag and warn when ``fit.dimension`` lies outside ``fit.domain``.

    Below the domain (``H >= 1`` for a graph): the data are smooth at the
    fitted scales; the remedy is larger scales (or the fractal range of
    ``fit.ranges`` when one was found). Above it (``H <= 0``): rougher than
    any graph, e.g. white noise or speckle.
    """
    dom = fit.domain
    if dom is None or _in_domain(fit.dimension, dom, open_domain):
        return fit
    a, b = fit.scale_range
    where = f"{fit.x_label} {a:g}..{b:g}"
    if not np.isfinite(fit.dimension):
        return mark_invalid(fit, "undefined", f"{fit.method}: D is undefined over {where}")
    good = [r for r in fit.ranges if r.valid]
    hint = ""
    if good:
        g = max(good, key=lambda r: r.n_scales)
        hint = (f"; the log-log relation breaks and D = {g.dimension:.3f} over "
                f"{g.scale_range[0]:g}..{g.scale_range[1]:g}: use scale_range=({g.scale_range[0]:g}, "
                f"{g.scale_range[1]:g})")
    if dom[1] - dom[0] != 1.0:
        msg = (f"{fit.method}: D = {fit.dimension:.3f} is outside [{dom[0]:g}, {dom[1]:g}] at {where}: not a "
               f"dimension of a set (too few occupied boxes or a saturated range); choose the scales with "
               f"scale_range{hint}")
        return mark_invalid(fit, "below_domain" if _below(fit.dimension, dom) else "above_domain", msg)
    if _below(fit.dimension, dom):
        msg = (f"{fit.method}: D = {fit.dimension:.3f} is below {dom[0]:g} (H >= 1): the data are smooth at "
               f"{where}; use larger scales (scale_range, lags, box_sizes or epsilons above {b:g}){hint}")
        return mark_invalid(fit, "below_domain", msg)
    msg = (f"{fit.method}: D = {fit.dimension:.3f} is above {dom[1]:g} (H <= 0): the data are rougher than "
           f"a graph at {where} (white noise, speckle); use larger scales or smooth the data{hint}")
    return mark_invalid(fit, "above_domain", msg)
