"""Fractal resampling of DEMs: finer grids that keep the terrain's roughness."""
from __future__ import annotations

import numbers
import warnings
from dataclasses import dataclass
from typing import Optional, Tuple

import numpy as np

from fractalgeo_rs import _core
from fractalgeo_rs._backend import array_kind
from fractalgeo_rs._compat import renamed_parameters
from fractalgeo_rs._warn import user_stacklevel
from fractalgeo_rs._validation import (as_array, check_choice, check_memory, check_n_threads, check_nodata,
                                      check_positive_float, check_window)

from fractalgeo_rs.dem._resample_grid import (  # noqa: F401  (re-exported for the other modules)
    H_TABLE,
    HURST_RANGE,
    STEP,
    block_variogram,
    interp_nodes,
    node_sums,
    ratio_table,
)

__all__ = ["resample_analysis", "ResampleAnalysis", "HURST_RANGE"]

_HALO = int(_core.RESAMPLE_HALO)


@dataclass(frozen=True)
class ResampleAnalysis:
    """Local fractal analysis of a DEM: the result of
    :func:`~fractalgeo_rs.dem.resample_analysis`, and the maps
    :func:`fractalgeo_rs.fractal_resample` refines the DEM with.

    Attributes
    ----------
    hurst : ndarray of float64, shape of the DEM
        Local Hurst exponent, clipped to ``HURST_RANGE`` (0.5 where the
        window has no valid increments).
    sigma : ndarray of float64, shape of the DEM
        Local standard deviation of the point-process increments at a lag of
        one input cell, height units (0 where the window has none).
    fraction_clipped : float
        Fraction of the valid cells whose raw ``H`` was outside
        ``HURST_RANGE``.
    window_size : int
        Side of the square window (cells; 0 when no map was estimated).
    model : {"fbm", "smooth"}
        The model the maps describe: ``"fbm"`` (``hurst`` and ``sigma`` are
        the constant-H fBm of lags 1-2 or the user's values) or
        ``"smooth"`` (the structure function with an inner scale of
        docs/resampling.md; ``hurst`` is then the fitted ``H`` of the
        fractal regime and ``sigma`` the level-0 increment scale: the
        window's lag-1 increment sd times the local amplitude factor).
    level_hurst, level_sigma : ndarray of float64, shape (levels, rows, cols), or None
        The per-level exponent and increment scale the kernel draws level
        ``l`` (coarse spacing ``2^-l`` input cells) with (``"smooth"``: the
        scale includes the local amplitude factor, the rms lag-1 increment
        of the 3 x 3 cells around a sample over the window's); None from
        :func:`~fractalgeo_rs.dem.resample_analysis` without ``factor``.
    inner_scale : ndarray of float64, shape of the DEM, or None
        ``model="smooth"``: the fitted inner scale ``r`` (input cells;
        0 where the window is fBm down to the pixel or has no fit): the
        terrain is smooth below it, and the detail drawn below it is
        tapered accordingly.
    inner_scale_global : float
        ``r`` of the model fitted to the whole DEM's variogram (lags 1, 2,
        4, ... up to a quarter of its shorter side), input cells; NaN when
        not computed (Dask input, ``model="fbm"``).
    hurst_global : float
        ``H`` of that global fit (NaN when not computed).
    fraction_smoother, fraction_rougher : float
        Fractions of the analysis windows (nodes of the ``STEP`` grid with
        a valid centre) whose lag-1/lag-2 exponent is above / below
        ``HURST_RANGE``: smoother than any fBm at the pixel scale (the
        ``"smooth"`` model represents them with its inner scale; ``"fbm"``
        draws them with ``H = 0.95``, too rough) / rougher than fBm of
        ``H = 0.05`` (drawn with ``H = 0.05``: too smooth). NaN when not
        computed.
    fraction_tapered : float
        ``model="smooth"``: fraction of the windows whose inner scale is
        above one output cell, where the detail of the finest level is
        smaller than constant-H fBm would draw (NaN otherwise).
    cell_size : tuple of float or None
        ``(dy, dx)`` ground size of an input cell when known.
    notes : tuple of str
        What the diagnostics mean for the output, in sentences (also the
        text of the warnings emitted).
    window : int
        Deprecated alias of ``window_size`` (renamed in 0.2.0; reading it
        emits a DeprecationWarning; removed in the next release).

    References
    ----------
    T. Gneiting, H. Sevcikova and D. B. Percival, Estimators of fractal
    dimension: assessing the roughness of time series and spatial data,
    *Statistical Science* 27(2) (2012) 247-277, doi:10.1214/11-STS370.

    Examples
    --------
    >>> import fractalgeo_rs as fg
    >>> z = fg.fbm_surface(128, 0.6, method="exact", seed=3)
    >>> a = fg.dem.resample_analysis(z, window_size=33)
    >>> a.hurst.shape, a.window_size, a.fraction_clipped
    ((128, 128), 33, 0.0)
    >>> round(float(a.hurst[64, 64]), 2), round(float(a.sigma[64, 64]), 2)  # fBm of H = 0.6, sigma = 1
    (0.59, 0.96)
    """

    hurst: np.ndarray
    sigma: np.ndarray
    fraction_clipped: float
    window_size: int
    model: str = "fbm"
    level_hurst: Optional[np.ndarray] = None
    level_sigma: Optional[np.ndarray] = None
    inner_scale: Optional[np.ndarray] = None
    inner_scale_global: float = float("nan")
    hurst_global: float = float("nan")
    fraction_smoother: float = float("nan")
    fraction_rougher: float = float("nan")
    fraction_tapered: float = float("nan")
    cell_size: Optional[Tuple[float, float]] = None
    notes: Tuple[str, ...] = ()

    @property
    def inner_scale_ground(self) -> Optional[np.ndarray]:
        """:attr:`inner_scale` in ground units (times the geometric mean of
        the cell's sides), or None when the cell size or the map is unknown."""
        if self.inner_scale is None or self.cell_size is None:
            return None
        return self.inner_scale * float(np.sqrt(self.cell_size[0] * self.cell_size[1]))

    @property
    def window(self) -> int:
        """Deprecated alias of :attr:`window_size` (renamed in 0.2.0)."""
        warnings.warn("ResampleAnalysis: the attribute 'window' is now called 'window_size' "
                      "(renamed in 0.2.0; the old name will be removed in the next release)",
                      DeprecationWarning, stacklevel=user_stacklevel())
        return self.window_size


# ---------------------------------------------------------------- analysis --

def _pad_width(half, step=STEP):
    """NaN halo (a multiple of ``step``) the analysis of a block needs: the
    window, the lag-2 increments and one node spacing for the interpolation."""
    return -(-(half + 2 + step) // step) * step


def _analyse_padded(z, half, support, block=2, step=STEP, border=0, n_threads=None):
    """Local maps ``(hurst, sigma, n_clipped, n_valid)`` of a NaN-padded
    block whose origin is a multiple of ``step``, trimmed by
    ``_pad_width(half, step)`` (``border`` cells of that halo are virtual:
    not in ``z``). ``hurst`` is clipped to ``HURST_RANGE`` (0.5 where there
    is none), ``sigma`` is 0 where there is none; ``n_clipped`` of the
    ``n_valid`` finite raw values were outside the range. The Rust kernel
    (``rust/dem/analysis.rs``): window sums at the nodes of a ``step`` grid,
    each formed in a fixed order from its window only, interpolated
    bilinearly, so any such block of a larger array gives the same bits."""
    table = None if support == "point" else ratio_table(block)
    return _core.resample_local_maps(z, half, step, border, HURST_RANGE, table, n_threads)


@renamed_parameters({"window": "window_size"}, since="0.2.0")
def resample_analysis(dem, *, window_size=33, support="point", block=2, nodata=None, n_threads=None,
                      model="fbm", factor=2, cell_size=None):
    r"""Local Hurst exponent and increment scale of a DEM.

    Over each ``window_size x window_size`` window, the mean squared increments at lags
    1 and 2 cells (rows and columns pooled, NaN-free pairs only) give
    :math:`H = \tfrac12 \log_2(\gamma_2 / \gamma_1)` and
    :math:`\sigma^2 = \gamma_1`: the variogram map of
    :func:`fractalgeo_rs.fractal_transform` with ``method="variogram"`` and
    ``lags=(1, 2)`` (``D = 3 - H``). With ``support="area"`` the cells are
    taken as block means: ``H`` inverts the ratio of the block-mean
    variogram (blocks of 2 x 2 points at spacing 1/2, the model of the
    resampling kernel) and :math:`\sigma^2 = \gamma_1 / \bar\gamma_B(1; H)`.
    ``H`` is clipped to ``HURST_RANGE`` (0.05, 0.95) with a warning giving
    the fraction clipped.

    Parameters
    ----------
    dem : array_like, shape (rows, cols)
        Heights; NaN and ``nodata`` are missing. Not modified.
    window_size : int, default 33
        Odd window side in cells (>= 5). (Called ``window`` before 0.2.0;
        the old keyword still works, with a DeprecationWarning.)
    support : {"point", "area"}, default "point"
        ``"point"``: the heights are point samples; ``"area"``: each cell is
        the mean height over its area (block-mean variogram model).
    block : int, default 2
        ``support="area"``: the block mean is modelled by ``block x block``
        points at spacing ``1 / block`` of a cell.
    nodata : float, optional
        Height value meaning "no data" (NaN is always missing).
    n_threads : int, optional
        Threads (default all cores); the maps do not depend on it.
    model : {"fbm", "smooth"}, default "fbm"
        ``"smooth"``: also fit the inner-scale model of
        :func:`fractalgeo_rs.fractal_resample` (its default) and return its
        maps, diagnostics and the per-level parameters for ``factor``.
    factor : int, default 2
        ``model="smooth"``: the resampling factor the per-level maps are for.
    cell_size : float or (float, float), optional
        ``model="smooth"``: ground size of a cell, for
        :attr:`~fractalgeo_rs.dem.ResampleAnalysis.inner_scale_ground`.

    Returns
    -------
    ResampleAnalysis

    References
    ----------
    T. Gneiting, H. Sevcikova and D. B. Percival, Estimators of fractal
    dimension: assessing the roughness of time series and spatial data,
    *Statistical Science* 27(2) (2012) 247-277, doi:10.1214/11-STS370.

    Examples
    --------
    >>> import numpy as np, fractalgeo_rs as fg
    >>> z = fg.fbm_surface(128, 0.6, method="exact", seed=3)
    >>> a = fg.dem.resample_analysis(z, window_size=33)
    >>> round(float(a.hurst[64, 64]), 3), round(float(np.median(a.hurst)), 3)  # fBm of H = 0.6
    (0.593, 0.584)
    """
    check_choice(support, "support", ("point", "area"))
    check_choice(model, "model", ("fbm", "smooth"))
    n_threads = check_n_threads(n_threads)
    z = _as_float(dem, nodata)
    window = check_window(window_size, minimum=5, shape=z.shape, cover=True)
    if model == "smooth":
        levels = levels_of(factor)
        cell = cell_size_of(cell_size, dem)
        _warn_window(window, z.shape)
        return _smooth_maps(z, window, support, block, levels, cell, True, n_threads)
    half = window // 2
    hurst, sigma, n_clip, n_ok = _analyse_padded(z, half, support, block, border=_pad_width(half),
                                                 n_threads=n_threads)
    frac = n_clip / n_ok if n_ok else 0.0
    _warn_clipped(frac, hurst)
    return ResampleAnalysis(hurst, sigma, frac, window)


def _warn_clipped(frac, hurst=None):
    if frac > 0:
        side = ""
        if hurst is not None:
            lo, hi = HURST_RANGE
            n_hi = int(np.count_nonzero(hurst >= hi))
            n_lo = int(np.count_nonzero(hurst <= lo))
            side = (f" ({n_hi} pixels above {hi}: smoother than fBm at lags 1-2; "
                    f"{n_lo} below {lo}: rougher)")
        warnings.warn(f"hurst: {100 * frac:.2g} % of the local H values were outside "
                      f"{HURST_RANGE} and were clipped{side}", RuntimeWarning, stacklevel=user_stacklevel())


def _as_float(dem, nodata):
    z = as_array(dem, "dem")
    if z.ndim != 2:
        raise ValueError(f"dem: expected a 2D array, got shape {z.shape}")
    if not (np.issubdtype(z.dtype, np.number) and not np.issubdtype(z.dtype, np.complexfloating)):
        raise TypeError(f"dem: expected a real numeric array, got dtype {z.dtype}")
    # No copy unless needed: nothing downstream writes into ``z``.
    z = np.ascontiguousarray(z, dtype=np.float64)
    nodata = check_nodata(nodata)
    if nodata is not None and not np.isnan(nodata):
        z = np.where(z == nodata, np.nan, z)
    return z


# ------------------------------------------------------- numpy reference --
# The analysis in numpy, for the tests and the benchmark only.

def _box_sum(a, half, t, step=STEP):
    """Window sums of ``a`` over ``(2 half + 1)^2`` cells at the nodes of a
    ``step`` grid, interpolated bilinearly to the pixels of ``a`` trimmed by
    ``t`` (a value depends only on the values in the windows of its 4 nodes,
    computed in a fixed order)."""
    r, k0 = node_sums(a, half, step)
    c, k1 = node_sums(np.ascontiguousarray(r.T), half, step)
    v = interp_nodes(c, k1, t, a.shape[1] - t, step).T
    return interp_nodes(np.ascontiguousarray(v), k0, t, a.shape[0] - t, step)


def _analyse_padded_reference(z, half, support, block=2, step=STEP):
    """numpy twin of :func:`_analyse_padded` (the same window sums, interpolation
    and fit in the same order), kept as the reference the kernel is tested
    and benchmarked against; returns the same four values."""
    t = _pad_width(half, step)
    m = np.isfinite(z)
    zz = np.where(m, z, 0.0)
    n0 = z.shape[0]
    sums = {lag: (np.zeros(z.shape), np.zeros(z.shape)) for lag in (1, 2)}
    # Squared increments (each assigned to its first sample), rows then
    # columns, in strips of rows so that the temporaries stay small.
    for r0 in range(0, n0, 256):
        r1 = min(r0 + 256, n0)
        for lag, (s, c) in sums.items():
            e = min(r1, n0 - lag)
            if e > r0:
                ok = m[r0 + lag:e + lag] & m[r0:e]
                d = zz[r0 + lag:e + lag] - zz[r0:e]
                s[r0:e] += np.where(ok, d * d, 0.0)
                c[r0:e] += ok
            ok = m[r0:r1, lag:] & m[r0:r1, :-lag]
            d = zz[r0:r1, lag:] - zz[r0:r1, :-lag]
            s[r0:r1, :-lag] += np.where(ok, d * d, 0.0)
            c[r0:r1, :-lag] += ok
    g = [(_box_sum(s, half, t, step), _box_sum(c, half, t, step)) for s, c in sums.values()]
    core = (slice(t, z.shape[0] - t), slice(t, z.shape[1] - t))
    (s1, c1), (s2, c2) = g
    with np.errstate(divide="ignore", invalid="ignore"):
        g1 = s1 / c1
        g2 = s2 / c2
        ratio = g2 / g1
    ok = np.isfinite(ratio) & (g1 > 0)
    if support == "point":
        hraw = np.where(ok, 0.5 * np.log2(np.where(ok, ratio, 1.0)), np.nan)
        var1 = np.where(ok, g1, np.nan)
    else:
        # Block means: invert the regularised variogram ratio for H, then
        # sigma^2 = g1 / gamma_block(1; H).
        hh, rr, g1tab = ratio_table(block)
        hraw = np.where(ok, np.interp(np.where(ok, ratio, 1.0), rr, hh, left=-1.0, right=9.0), np.nan)
        hraw = np.where(hraw == -1.0, 0.0, np.where(hraw == 9.0, 2.0, hraw))
        hc = np.clip(np.where(ok, hraw, 0.5), *HURST_RANGE)
        var1 = np.where(ok, g1 / np.interp(hc, hh, g1tab), np.nan)
    # An interior pixel of the core is only valid if it was a valid sample.
    hraw = np.where(m[core], hraw, np.nan)
    return _finish(hraw, var1)


def _finish(hraw, var1):
    """Clipped H (0.5 where none), sigma (0 where none) and the counts."""
    ok = np.isfinite(hraw)
    lo, hi = HURST_RANGE
    n_clip = int(np.count_nonzero(ok & ((hraw < lo) | (hraw > hi))))
    n_ok = int(np.count_nonzero(ok))
    hurst = np.where(ok, np.clip(np.where(ok, hraw, 0.5), lo, hi), 0.5)
    sigma = np.where(np.isfinite(var1) & ok, np.sqrt(np.where(np.isfinite(var1), var1, 0.0)), 0.0)
    return hurst, sigma, n_clip, n_ok


# ------------------------------------------------------------------- main --

def levels_of(factor):
    if isinstance(factor, bool) or not isinstance(factor, numbers.Integral):
        raise TypeError(f"factor: expected a power of 2 >= 2, got {factor!r}")
    f = int(factor)
    if f < 2 or f & (f - 1):
        raise ValueError(f"factor: expected a power of 2 >= 2, got {f}")
    levels = f.bit_length() - 1
    if levels > 12:
        raise ValueError(f"factor: at most 4096, got {f}")
    return levels


def _param_map(value, name, shape, lo, hi, lo_open, hi_open):
    """A number or an array on the input grid, checked against its range."""
    if isinstance(value, str):
        raise ValueError(f"{name}: expected 'local', a number or an array, got {value!r}")
    if isinstance(value, bool):
        raise TypeError(f"{name}: expected a number or an array, got {value!r}")
    a = as_array(value, name).astype(np.float64)
    if a.ndim != 0 and a.shape != shape:
        raise ValueError(f"{name}: expected a number or an array of shape {shape}, got {a.shape}")
    f = a[np.isfinite(a)]
    bad = (f <= lo if lo_open else f < lo).any() | (f >= hi if hi_open else f > hi).any()
    if bad or np.isinf(a).any():
        lb = "(" if lo_open else "["
        rb = ")" if hi_open else "]"
        raise ValueError(f"{name}: expected values in {lb}{lo}, {hi}{rb}, got "
                         f"min {np.nanmin(a):.4g}, max {np.nanmax(a):.4g}")
    if a.ndim == 0:
        # A read-only broadcast view (no memory of the DEM's size).
        return np.broadcast_to(a, shape)
    return a if a.strides == (0, 0) else np.ascontiguousarray(a)


def cell_size_of(cell_size, dem):
    """``(dy, dx)`` ground size of an input cell: ``cell_size`` (a number or
    a pair), else from xarray coords, else None (unknown)."""
    if cell_size is None:
        if array_kind(dem) == "xarray":
            return _coord_step(dem)
        return None
    if isinstance(cell_size, (tuple, list, np.ndarray)) and not isinstance(cell_size, str):
        if len(cell_size) != 2:
            raise ValueError(f"cell_size: expected a number or a pair (dy, dx), got {cell_size!r}")
        return (check_positive_float(cell_size[0], "cell_size"),
                check_positive_float(cell_size[1], "cell_size"))
    c = check_positive_float(cell_size, "cell_size")
    return (c, c)


def detail_levels(levels, cell, min_scale):
    """Detail flag per level: level ``l`` makes cells of ``cell / 2^(l+1)``;
    detail where the larger side of them is at least ``min_scale``.
    ``cell``: a number or a pair ``(dy, dx)``."""
    if min_scale is None:
        return [True] * levels
    if isinstance(min_scale, bool) or not isinstance(min_scale, numbers.Real):
        raise TypeError(f"min_scale: expected a number >= 0 or None, got {min_scale!r}")
    ms = float(min_scale)
    if not (np.isfinite(ms) and ms >= 0):
        raise ValueError(f"min_scale: expected a finite number >= 0 or None, got {ms}")
    c = float(max(cell)) if isinstance(cell, (tuple, list)) else float(cell)
    return [c / 2 ** (lvl + 1) >= ms for lvl in range(levels)]


def _check_memory(shape, f):
    """The package's memory policy (``check_memory``: MemoryLimitError naming
    ``factor``): the output and the last level's input, in float64."""
    nbytes = 8.0 * shape[0] * shape[1] * f * f * 1.5
    check_memory(nbytes, "factor", what=f"a {f}x finer grid of {shape[0]} x {shape[1]} (use a dask array)")


def _coord_step(da):
    """``(dy, dx)`` from the last two dims' coords, or None."""
    steps = []
    for dim in da.dims[-2:]:
        try:
            c = np.asarray(da[dim].values, dtype=float)
        except (KeyError, TypeError, ValueError):
            return None
        if c.size < 2 or not np.isfinite(c[1] - c[0]) or c[1] == c[0]:
            return None
        steps.append(abs(float(c[1] - c[0])))
    return (steps[0], steps[1])


def run_numpy(dem, levels, hurst, sigma, window, detail, support, nodata, seed, n_threads,
              model=None, cell=None, clip_min=None, warn=True):
    """In-memory run on checked options; returns ``(out, analysis)``."""
    z = _as_float(dem, nodata)
    _check_shape(z.shape)
    if not np.isfinite(z).any():
        raise ValueError("dem: every sample is NaN or nodata")
    _check_memory(z.shape, 1 << levels)
    local_h = isinstance(hurst, str) and hurst == "local"
    local_s = isinstance(sigma, str) and sigma == "local"
    model = check_model(model, local_h, local_s)
    an = _maps(z, hurst, sigma, window, support, local_h, local_s, min(1 << levels, 8), n_threads,
               levels=levels, model=model, cell=cell, warn=warn)
    h, s = an.level_hurst, an.level_sigma
    if h.strides[1:] == (0, 0) and s.strides[1:] == (0, 0):
        # Constant maps: the kernel takes them as 1 x 1.
        h, s = np.ascontiguousarray(h[:, :1, :1]), np.ascontiguousarray(s[:, :1, :1])
    else:
        h, s = np.ascontiguousarray(h), np.ascontiguousarray(s)
    out = _core.fractal_resample(z, h, s, levels, support == "area", seed, detail,
                                 (0, 0), z.shape[1], n_threads)
    if clip_min is not None:
        np.maximum(out, clip_min, out=out)
    return out, an


def _check_shape(shape):
    if min(shape) < 4:
        raise ValueError(f"dem: the kriging stencil needs at least 4 x 4 samples, got {shape}")


def _maps(z, hurst, sigma, window, support, local_h, local_s, block=2, n_threads=None, *,
          levels=1, model="fbm", cell=None, warn=True):
    """The parameters of a run: a :class:`ResampleAnalysis` whose
    ``level_hurst`` / ``level_sigma`` are what the kernel takes (stacks of
    ``levels``, or of 1 for every level). Warnings only about what was
    estimated (never about a parameter the user fixed)."""
    # Fixed parameters are checked before anything is estimated.
    h_fix = None if local_h else _param_map(hurst, "hurst", z.shape, 0.0, 1.0, True, True)
    s_fix = None if local_s else _param_map(sigma, "sigma", z.shape, 0.0, np.inf, False, False)
    if warn and (local_h or local_s):
        _warn_window(window, z.shape)
    if model == "smooth":
        return _smooth_maps(z, window, support, block, levels, cell, warn, n_threads)
    frac = 0.0
    h_raw = None
    fr_s = fr_r = float("nan")
    if local_h or local_s:
        half = window // 2
        h_map, s_map, n_clip, n_ok = _analyse_padded(z, half, support, block, border=_pad_width(half),
                                                     n_threads=n_threads)
        if local_h:
            frac = n_clip / n_ok if n_ok else 0.0
            h_raw = h_map
            ok = s_map > 0
            n = max(int(np.count_nonzero(ok)), 1)
            fr_s = int(np.count_nonzero(ok & (h_map >= HURST_RANGE[1]))) / n
            fr_r = int(np.count_nonzero(ok & (h_map <= HURST_RANGE[0]))) / n
    h = h_map if local_h else h_fix
    if local_s:
        s = s_map
        if support == "area" and not local_h:
            # sigma^2 = g1 / gamma_block(1; H) with the user's H, not the
            # local one the kernel divided by.
            hh, _, g1tab = ratio_table(block)
            g1 = s_map**2 * np.interp(h_map, hh, g1tab)
            s = np.sqrt(g1 / np.interp(np.clip(h, hh[0], hh[-1]), hh, g1tab))
    else:
        s = s_fix
    if (h.strides == (0, 0)) != (s.strides == (0, 0)):
        h, s = np.ascontiguousarray(h), np.ascontiguousarray(s)
    notes = []
    if h_raw is not None:
        lo, hi = HURST_RANGE
        if fr_s > 0:
            notes.append(f"hurst: {100 * fr_s:.3g} % of the windows are smoother than fBm at lags 1-2 "
                         f"(H > {hi}): detail there is drawn with H = {hi} and is rougher than the DEM "
                         f"below the coarse cell; model='smooth' (the default with hurst and sigma "
                         f"'local') tapers it below the fitted inner scale")
        if fr_r > 0:
            notes.append(f"hurst: {100 * fr_r:.3g} % of the windows are rougher than fBm of H = {lo} at "
                         f"lags 1-2: detail there is drawn with H = {lo} and is smoother than the DEM")
        if warn:
            for msg in notes:
                warnings.warn(msg, RuntimeWarning, stacklevel=user_stacklevel())
    # An estimated H map on the nodes of the kernel's tables (steps of
    # 0.0049): its lookups are then redone only where H changes, from a node.
    lh = _on_kernel_nodes(h) if local_h else h
    return ResampleAnalysis(h, s, frac, window if (local_h or local_s) else 0, model="fbm",
                            level_hurst=lh[None], level_sigma=s[None],
                            fraction_smoother=fr_s, fraction_rougher=fr_r, cell_size=cell,
                            notes=tuple(notes))


def _on_kernel_nodes(h):
    """``h`` rounded to the nodes of the kernel's full-stencil tables (201
    in [0.01, 0.99])."""
    lo, hi, n = 0.01, 0.99, 201
    q = (hi - lo) / (n - 1)
    return lo + np.rint((np.asarray(h) - lo) / q) * q


def _warn_window(window, shape):
    if window > min(shape):
        warnings.warn(f"window_size: {window} is larger than the DEM's shorter side {min(shape)}: "
                      f"the local maps are close to one fit of the whole DEM",
                      RuntimeWarning, stacklevel=user_stacklevel())


def _smooth_maps(z, window, support, block, levels, cell, warn, n_threads=None):
    """The scale-aware model (``_resample_model``): per-level maps from the
    fit at the analysis nodes, interpolated to the pixels."""
    from fractalgeo_rs.dem import _resample_model as M

    half = window // 2
    t = M.pad_width(half)
    mb = 0 if support == "point" else block
    f = 1 << levels
    zp = np.pad(z, t, constant_values=np.nan)
    lh, ls, r_map, h_map, counts = M.analyse_padded(zp, half, mb, levels, M.INNER_SCALE_FLOOR / f,
                                                     n_threads=n_threads)
    n_ok, n_smooth, n_rough, n_taper, n_centre = counts
    r_glob, h_glob = M.global_fit(z, mb)
    fr_s = n_smooth / n_ok if n_ok else 0.0
    fr_r = n_rough / n_ok if n_ok else 0.0
    fr_t = n_taper / n_ok if n_ok else 0.0
    lo = HURST_RANGE[0]
    notes, warn_msgs = [], []
    unit = ""
    scale = 1.0
    if cell is not None:
        scale = float(np.sqrt(cell[0] * cell[1]))
        unit = " ground units"
    if fr_t > 0:
        notes.append(f"{100 * fr_t:.3g} % of the windows have an inner scale above one output cell "
                     f"(global fit: r = {scale * r_glob:.3g}{unit or ' input cells'}, H = {h_glob:.2f}): "
                     f"the detail below it was tapered (smoother than constant-H fBm), "
                     f"{100 * fr_s:.3g} % of the windows are smoother than fBm at lags 1-2")
    if fr_r > 0:
        msg = (f"hurst: {100 * fr_r:.3g} % of the windows are rougher than fBm of H = {lo} at lags 1-2: "
               f"detail there is drawn with H >= {lo} and is smoother than the DEM")
        notes.append(msg)
        warn_msgs.append(msg)
    if n_centre > n_ok:
        msg = (f"window_size: {100 * (n_centre - n_ok) / n_centre:.3g} % of the windows with a valid "
               f"centre have no valid increments (holes): no random detail there; a larger "
               f"window_size fills them")
        notes.append(msg)
        warn_msgs.append(msg)
    if warn:
        for msg in warn_msgs:
            warnings.warn(msg, RuntimeWarning, stacklevel=user_stacklevel())
    return ResampleAnalysis(h_map, ls[0], fr_r, window, model="smooth", level_hurst=lh,
                            level_sigma=ls, inner_scale=r_map, inner_scale_global=r_glob,
                            hurst_global=h_glob, fraction_smoother=fr_s, fraction_rougher=fr_r,
                            fraction_tapered=fr_t, cell_size=cell, notes=tuple(notes))


def check_model(model, local_h, local_s):
    """``model``: None -> "smooth" when H and sigma are both estimated."""
    if model is None:
        return "smooth" if (local_h and local_s) else "fbm"
    check_choice(model, "model", ("smooth", "fbm"))
    if model == "smooth" and not (local_h and local_s):
        raise ValueError("model: 'smooth' fits H, sigma and the inner scale from the DEM; it needs "
                         "hurst='local' and sigma='local' (use model='fbm' with fixed values)")
    return model


def _bicubic_aligned(c, f, support="point"):
    """Cubic-spline interpolation (``scipy.ndimage.map_coordinates``,
    order 3) at the cell centres of :func:`fractal_resample`'s finer grid:
    input index ``a / f`` (point support: the input samples are kept) or
    ``(a + 0.5) / f - 0.5`` (area support). The baseline of
    docs/resampling.md; ``ndimage.zoom(c, f)`` cut to the output shape is
    not on this grid (it stretches the input by ``(f n - 1) / (n - 1)``)."""
    from scipy import ndimage

    c = np.asarray(c, dtype=np.float64)
    if support == "point":
        ax = [np.arange(f * (n - 1) + 1) / f for n in c.shape]
    else:
        ax = [(np.arange(f * n) + 0.5) / f - 0.5 for n in c.shape]
    yy, xx = np.meshgrid(ax[0], ax[1], indexing="ij")
    return ndimage.map_coordinates(c, [yy, xx], order=3, mode="nearest")


def fine_coords(c, f, support):
    """Cell-centre coordinates of the finer grid from those of the input.

    Point support: ``f (n - 1) + 1`` values from ``c[0]`` to ``c[-1]``;
    area support: ``f n`` centres inside the same outer edges.
    """
    n = c.size
    if n < 2:
        raise ValueError("dem: coordinates need at least 2 values per axis")
    d = (c[-1] - c[0]) / (n - 1)
    if support == "point":
        return c[0] + d / f * np.arange(f * (n - 1) + 1)
    return c[0] - d / 2 + d / f * (np.arange(f * n) + 0.5)


def fine_transform(transform, f, support):
    """The affine transform of the finer grid (rasterio ``Affine``):
    pixel size divided by ``f``; area support keeps the outer edges, point
    support keeps the first cell centre (the edges move in by
    ``(1 - 1/f) / 2`` input cells)."""
    from affine import Affine

    a, b, c, d, e, g = transform.a, transform.b, transform.c, transform.d, transform.e, transform.f
    if support == "area":
        return Affine(a / f, b / f, c, d / f, e / f, g)
    # Centre of input pixel (0, 0) = centre of fine pixel (0, 0).
    c0 = c + 0.5 * a + 0.5 * b
    g0 = g + 0.5 * d + 0.5 * e
    return Affine(a / f, b / f, c0 - 0.5 * (a + b) / f, d / f, e / f, g0 - 0.5 * (d + e) / f)
