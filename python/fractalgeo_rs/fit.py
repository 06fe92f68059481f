"""The result object every dimension estimator returns.

An estimator measures a quantity ``M(s)`` at scales ``s`` (box counts against
box size, areas against radius, ...) and the dimension follows from the slope
of the ordinary least-squares line through ``(log s, log M(s))``:

    D = dim_offset + dim_factor * slope

(box counting: ``D = -slope``; Minkowski sausage in the plane:
``D = 2 - slope``). :func:`fit_loglog` does the fit, the choice of scale range
and the uncertainty; :class:`DimensionFit` holds the result and draws it.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

__all__ = ["DimensionFit", "fit_loglog"]

ScaleRange = Union[None, str, Tuple[float, float]]


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
        :func:`fit_loglog`).
    extra : mapping
        Method-specific results (e.g. ``hurst`` for self-affine counting, the
        counts of every lattice offset).
    model : ndarray or None
        Model-based estimates only (``range_selection == "model"``, built by
        :meth:`from_model`, e.g. the Whittle likelihood): the fitted model's
        value of the measure at each scale, drawn by :meth:`plot` instead of
        a line. ``None`` for log-log regressions.

    References
    ----------
    K. Falconer, *Fractal Geometry: Mathematical Foundations and
    Applications*, Wiley, 1990.

    T. Gneiting, H. Sevcikova and D. B. Percival, Estimators of fractal
    dimension: assessing the roughness of time series and spatial data,
    *Statistical Science* 27(2) (2012) 247-277, doi:10.1214/11-STS370.

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
    extra: Mapping[str, Any] = field(default_factory=dict)
    model: Optional[np.ndarray] = None

    @classmethod
    def from_model(
        cls,
        *,
        dimension: float,
        stderr: float,
        scales: Sequence[float],
        measures: Sequence[float],
        model: Sequence[float],
        method: str,
        dim_offset: float = 0.0,
        x_label: str = "scale",
        y_label: str = "measure",
        extra: Optional[Mapping[str, Any]] = None,
    ) -> "DimensionFit":
        """A dimension estimated by fitting a model rather than a line.

        Likelihood estimators (e.g. :func:`fractalgeo_rs.whittle`) estimate
        ``D`` directly; there is no regression line. Their fit object keeps
        the log-log data for :meth:`plot` (``scales``, ``measures`` and the
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
            Axis labels of :meth:`plot`.
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
        return (
            f"DimensionFit(method={self.method!r}, dimension={self.dimension:.4f}{extra}, "
            f"ci95=({lo:.4f}, {hi:.4f}), r_squared={self.r_squared:.6f}, "
            f"scales {self.scale_range[0]:g}..{self.scale_range[1]:g} "
            f"({self.n_used} of {len(self.scales)}, {self.range_selection}))"
        )

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
            ax.loglog(s[u], self.model[u], "-", color=color,
                      label=f"D = {self.dimension:.3f} ± {1.96 * self.stderr:.3f} (model)")
        else:
            xs = np.array(self.scale_range, dtype=float)
            ax.loglog(xs, np.exp(self.intercept + self.slope * np.log(xs)), "-", color=color,
                      label=f"D = {self.dimension:.3f} ± {1.96 * self.stderr:.3f}")
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
    scales: Sequence[float],
    measures: Sequence[float],
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
    scale_range : None, "auto" or (float, float)
        ``None`` fits every scale; a ``(low, high)`` pair fits the scales with
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

    Returns
    -------
    DimensionFit
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
    if scale_range is None:
        used = valid.copy()
        selection = "all"
    elif isinstance(scale_range, str):
        if scale_range != "auto":
            raise ValueError(f"scale_range: expected None, 'auto' or (low, high), got {scale_range!r}")
        idx = np.flatnonzero(valid)
        n = len(idx)
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
            raise ValueError(f"scale_range: expected None, 'auto' or (low, high), got {scale_range!r}") from None
        if not (lo <= hi):
            raise ValueError(f"scale_range: low must not exceed high, got ({lo}, {hi})")
        used = valid & (s >= lo) & (s <= hi)
        if np.count_nonzero(used) < min_scales:
            raise ValueError(
                f"scale_range: ({lo:g}, {hi:g}) holds {np.count_nonzero(used)} usable scales, need at least {min_scales}"
            )
        selection = "user"
    x, y = np.log(s[used]), np.log(m[used])
    slope, intercept, r2, se = _ols(x, y)
    dim = dim_offset + dim_factor * slope
    dse = abs(dim_factor) * se
    # Student t quantile from scipy.special (what scipy.stats.t.ppf calls;
    # importing scipy.stats would cost about a second on first use)
    from scipy.special import stdtrit

    if len(x) > 2:
        half = float(stdtrit(len(x) - 2, 0.975)) * dse
    else:
        dse = half = float("nan")
    return DimensionFit(
        dimension=float(dim),
        slope=float(slope),
        intercept=float(intercept),
        r_squared=float(r2),
        stderr=float(dse),
        ci95=(float(dim - half), float(dim + half)),
        scales=s,
        measures=m,
        used=used,
        scale_range=(float(s[used][0]), float(s[used][-1])),
        method=method,
        range_selection=selection,
        dim_offset=float(dim_offset),
        dim_factor=float(dim_factor),
        x_label=x_label,
        y_label=y_label,
        extra=dict(extra or {}),
    )
