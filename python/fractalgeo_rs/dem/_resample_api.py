"""``fractal_resample``: the public entry of fractal resampling, dispatching
numpy, Dask and xarray inputs to the in-memory kernel (``_resample``) or the
blockwise one (``_resample_dask``), which both build on ``_resample``."""
from __future__ import annotations

import numpy as np

import numbers

from fractalgeo_rs._backend import array_kind
from fractalgeo_rs._compat import renamed_parameters
from fractalgeo_rs._geodesy import is_geographic_xarray
from fractalgeo_rs._validation import (
    check_choice,
    check_n_threads,
    check_nodata,
    check_seed,
    check_window,
    warn_void_sentinel,
)
from fractalgeo_rs.dem._resample import (
    cell_size_of,
    check_model,
    detail_levels,
    fine_coords,
    levels_of,
    run_numpy,
)
from fractalgeo_rs.dem._resample_dask import run_dask

__all__ = ["fractal_resample"]


@renamed_parameters({"window": "window_size"}, since="0.2.0")
def fractal_resample(dem, factor=2, *, hurst="local", sigma="local", window_size=33, min_scale=None,
                     support="point", cell_size=None, nodata=None, seed=None, n_threads=None,
                     return_analysis=False, model=None, clip_min=None):
    r"""Resample a DEM on a grid ``factor`` times finer with fractal detail.

    The method of the seed paper's section 4.1 (figure 5), with a
    scale-aware model by default. The DEM is refined in x2 levels; each new
    sample is the conditional (intrinsic kriging) mean of a random field
    given the 16 nearest samples of the current level, plus a Gaussian
    residual with the kriging variance. Level ``l`` (coarse spacing
    :math:`s = 2^{-l}` input cells) uses the power-law semivariogram
    :math:`\gamma(d) = \sigma_l^2 d^{2H_l} / 2` (``d`` in input cells).

    ``model="smooth"`` (the default with ``hurst`` and ``sigma`` both
    ``"local"``): in every analysis window the variogram of the DEM at lags
    1, 2, 4 and 8 cells is fitted with the structure function
    :math:`D(h) = a\,r^{2H}((1 + (h/r)^2)^H - 1)`, smooth below the
    inner scale ``r``, fBm with Hurst exponent ``H`` above it (``r`` at
    least one output cell); level ``l`` then uses the power law through
    :math:`D(s)` and :math:`D(s/2)`:
    :math:`H_l = \tfrac12 \log_2(D(s)/D(s/2))`,
    :math:`\sigma_l^2 s^{2H_l} = D(s)`. Real terrain gets smoother
    towards the pixel (diffusion, gravity, vegetation; the seed paper:
    fractal resampling cannot be applied below a given scale), and constant-H
    fBm extrapolated from the coarse cell makes it too rough there
    (docs/resampling.md measures both on real DEMs). ``model="fbm"``:
    constant ``H`` and ``sigma`` at every level (:math:`\sigma_l =
    \sigma`, :math:`H_l = H`), from
    :func:`~fractalgeo_rs.dem.resample_analysis` (lags 1-2) or fixed by the
    user.

    Point support uses the diamond step (cell centres from the 4 x 4 coarse
    samples around them) then the square step (edge midpoints from the 16
    nearest samples of the 45-degree lattice), each in four phases by the
    parity of the new samples' positions: a sample is also conditioned on
    its (up to 8) neighbours of the same step drawn in an earlier phase, so
    neighbouring residuals get their conditional correlation (sequential
    Gaussian simulation). The weights and variances are tabulated once on
    201 values of ``H`` in [0.01, 0.99] and interpolated.
    The stencils leave no dyadic creases (crease ratio of
    :func:`fractalgeo_rs.validate_surface` about 1.0; see
    docs/resampling.md). Pointwise the result is one sample of the
    conditional distribution: if the model is right, its squared error is
    twice the conditional mean's (RMSE ratio :math:`\sqrt 2`; proof in
    docs/resampling.md): the method keeps statistics (variance at every
    lag, ``H``, spectrum), not pointwise accuracy.

    Parameters
    ----------
    dem : array_like, dask.array.Array or xarray.DataArray, shape (rows, cols)
        Heights. NaN and ``nodata`` are holes. Not modified.
    factor : int, default 2
        Power of 2, at least 2.
    hurst : "local", float or array, default "local"
        ``H`` in (0, 1): a number, a map on the input grid, or ``"local"``
        (estimated over ``window_size``: the smooth model's fit, or with
        ``model="fbm"`` :func:`~fractalgeo_rs.dem.resample_analysis`, clipped to
        ``HURST_RANGE`` = (0.05, 0.95)). A number or a map implies
        ``model="fbm"``.
    sigma : "local", float or array, default "local"
        Standard deviation (height units) of the point increments at a lag of
        one input cell, >= 0; ``"local"`` as for ``hurst``.
    window_size : int, default 33
        Window side (cells) of the ``"local"`` analysis. (Called ``window``
        before 0.2.0; the old keyword still works, with a DeprecationWarning.)
    min_scale : float, optional
        Ground units (those of ``cell_size``): levels producing cells whose
        larger side is smaller than this get the conditional mean only, no
        random detail. Needs the cell size (``cell_size``, or the
        coordinates of a projected DataArray; refused without it, and on
        coordinates in degrees without ``cell_size``). Default None: detail
        at every level, tapered below the fitted inner scale by the default
        model.
    support : {"point", "area"}, default "point"
        ``"point"``: samples are point heights; the output has shape
        ``(factor (rows - 1) + 1, factor (cols - 1) + 1)`` and keeps sample
        ``(i, j)`` exactly at ``(factor i, factor j)``. ``"area"``: cells
        are block means; the output has shape ``(factor rows, factor cols)``
        and the mean of each ``factor x factor`` block equals the input cell
        (to 1e-9 relative).
    cell_size : float or (float, float), optional
        Ground size of an input cell, or ``(dy, dx)`` for rectangular cells
        (e.g. 3 arc-seconds at 44 N: about (92.6, 66.7) m). Default: from
        xarray coords, else unknown. Used by ``min_scale`` (the larger side)
        and to report the inner scale in ground units
        (:attr:`~fractalgeo_rs.dem.ResampleAnalysis.inner_scale_ground`); the model is fitted
        and drawn in cells (rows and columns pooled).
    nodata : float, optional
        Value marking holes, in addition to NaN.
    seed : int, optional
        Random seed (None: a fresh one). The noise is keyed by position, so
        the result does not depend on ``n_threads`` or on Dask chunks.
    n_threads : int, optional
        Threads (default all cores).
    return_analysis : bool, default False
        Also return the :class:`~fractalgeo_rs.dem.ResampleAnalysis` used (the maps actually
        passed to the kernel, per level, and the diagnostics).
    model : {"smooth", "fbm"}, optional
        Default: ``"smooth"`` when ``hurst`` and ``sigma`` are both
        ``"local"``, else ``"fbm"``. ``"smooth"`` with a fixed ``hurst`` or
        ``sigma`` is a ValueError.
    clip_min : float, optional
        Post-process: values below it are set to it (e.g. 0 for heights that
        cannot be negative; input samples below it too). With
        ``support="area"`` clipped blocks no longer keep their mean exactly.

    Returns
    -------
    ndarray of float64 (or the input's dask/xarray type)
        The finer DEM. Holes: a point-support output sample is NaN exactly
        when one of the (up to 4) input samples at the corners of the input
        cell it lies in (on an edge: the 2 ends; on a sample: that sample) is
        a hole, i.e. when bilinear interpolation would use a hole: a hole
        grows by ``factor - 1`` fine cells (less than one input cell); an
        area-support cell is NaN when its input cell is. Samples outside the grid or in holes are left out of
        the other samples' stencils (weights solved for the samples present),
        so nothing leaks from holes. With ``return_analysis``, a pair.

    Notes
    -----
    The kriging given the current level's 16 samples approximates the full
    conditional distribution; on fBm the empirical mean and variance of
    many resamplings at a new point match the exact dense kriging to within
    the tolerances stated in docs/resampling.md. xarray input returns new
    cell-centre coords; Dask input is computed chunk by chunk with a halo of
    16 input cells (plus the analysis window) and equals the in-memory result
    bit for bit.

    References
    ----------
    Mandelbrot, B. B., Van Ness, J. W. (1968). *SIAM Review* 10(4), 422-437.
    https://doi.org/10.1137/1010093. Chilès, J.-P., Delfiner, P. (2012).
    *Geostatistics: Modeling Spatial Uncertainty*, 2nd ed., Wiley, ch. 4
    (intrinsic kriging). https://doi.org/10.1002/9781118136188

    Examples
    --------
    >>> import numpy as np, fractalgeo_rs as fg
    >>> z = fg.fbm_surface(65, 0.7, method="exact", seed=1)
    >>> fine = fg.fractal_resample(z, 4, hurst=0.7, sigma=1.0, seed=2)
    >>> fine.shape
    (257, 257)
    >>> bool(np.array_equal(fine[::4, ::4], z))
    True
    """
    if dem is None or isinstance(dem, (str, bytes)):
        raise TypeError(f"dem: expected an array (numpy, Dask or xarray), got {type(dem).__name__}")
    if np.ndim(dem) != 2:
        raise ValueError(f"dem: expected a 2D array, got shape {np.shape(dem)}")
    levels = levels_of(factor)
    f = 1 << levels
    check_choice(support, "support", ("point", "area"))
    n_threads = check_n_threads(n_threads)
    seed = check_seed(seed)
    local_h = isinstance(hurst, str) and hurst == "local"
    local_s = isinstance(sigma, str) and sigma == "local"
    model = check_model(model, local_h, local_s)
    if clip_min is not None:
        if isinstance(clip_min, bool) or not isinstance(clip_min, numbers.Real) or not np.isfinite(clip_min):
            raise TypeError(f"clip_min: expected a finite number or None, got {clip_min!r}")
        clip_min = float(clip_min)
    cell = cell_size_of(cell_size, dem)
    if min_scale is not None:
        detail_levels(levels, 1.0, min_scale)  # type and range first
        if cell_size is None and array_kind(dem) == "xarray" and is_geographic_xarray(dem):
            raise ValueError("cell_size: the DataArray's coordinates are in degrees; min_scale is in "
                             "ground units: pass cell_size in metres (e.g. (dy, dx) from "
                             "fractalgeo_rs.dem.metres_per_degree)")
        if cell is None:
            raise ValueError("min_scale: a ground length needs the cell size: pass cell_size (a "
                             "number or (dy, dx), ground units of an input cell) or an xarray "
                             "DataArray with projected coordinates")
    detail = detail_levels(levels, cell if cell is not None else 1.0, min_scale)
    window = window_size
    if local_h or local_s:
        window = check_window(window_size, minimum=5, shape=np.shape(dem), cover=True)
    heights = dem.data if array_kind(dem) == "xarray" else dem
    if array_kind(heights) == "numpy":
        warn_void_sentinel(np.asarray(heights), "dem", check_nodata(nodata))
    if array_kind(dem) == "xarray":
        return _run_xarray(dem, f, levels, hurst, sigma, window, detail, support, cell, nodata,
                           seed, n_threads, return_analysis, model, clip_min)
    if array_kind(dem) == "dask":
        return run_dask(dem, levels, hurst, sigma, window, detail, support, nodata, seed,
                        n_threads, return_analysis, model, clip_min)
    out, an = run_numpy(dem, levels, hurst, sigma, window, detail, support, nodata, seed, n_threads,
                        model, cell, clip_min)
    return (out, an) if return_analysis else out


def _run_xarray(da, f, levels, hurst, sigma, window, detail, support, cell, nodata, seed,
                n_threads, return_analysis, model, clip_min):
    import xarray as xr

    if da.ndim != 2:
        raise ValueError(f"dem: expected a 2D DataArray, got dims {da.dims}")
    data = da.data
    if array_kind(data) == "dask":
        r = run_dask(data, levels, hurst, sigma, window, detail, support, nodata, seed,
                     n_threads, return_analysis, model, clip_min)
        out, an = (r if return_analysis else (r, None))
    else:
        out, an = run_numpy(np.asarray(data), levels, hurst, sigma, window, detail, support,
                            nodata, seed, n_threads, model, cell, clip_min)
    ydim, xdim = da.dims
    coords = {}
    for dim, n_out in ((ydim, out.shape[0]), (xdim, out.shape[1])):
        if dim in da.coords:
            c = np.asarray(da[dim].values, dtype=float)
            coords[dim] = fine_coords(c, f, support)
    res = xr.DataArray(out, dims=da.dims, coords=coords, attrs=dict(da.attrs), name=da.name)
    return (res, an) if return_analysis else res


