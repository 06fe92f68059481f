"""The public map functions of the transform package: argument checks,
band selection, nodata, the numpy / Dask / xarray dispatch
(:func:`fractalgeo_rs._backend.run_raster`) and the result; the methods
themselves are the registry of :mod:`fractalgeo_rs.transform._methods`."""
from __future__ import annotations

from typing import Any, Dict, Optional, Sequence, Tuple, Union

import numpy as np

from fractalgeo_rs import _core, _progress
from fractalgeo_rs._backend import array_kind, run_raster
from fractalgeo_rs._compat import keyword_only_since
from fractalgeo_rs._validation import (
    as_array,
    check_choice,
    check_fraction,
    check_n_threads,
    check_nodata,
    check_positive_int,
    check_window,
)
from fractalgeo_rs._zscale import check_z_scale, resolve_z_scale
from fractalgeo_rs.transform._methods import METHODS, MapOptions
from fractalgeo_rs.transform._result import TransformFit, flag_map, warn_out_of_range

__all__ = ["fractal_transform", "lacunarity_map"]



def _float_dtype(dtype) -> type:
    """float32 stays float32 (the mass and increment kernels read it in
    place, exactly: every float32 is a float64); anything else is float64."""
    return np.float32 if dtype == np.float32 else np.float64


def _nodata_mask(z: np.ndarray, nodata: float) -> np.ndarray:
    """``z == nodata`` with the value compared as given (in float64) also
    for a float32 image, without a float64 copy of it."""
    if z.dtype != np.float32:
        return z == nodata
    with np.errstate(over="ignore"):
        v = np.float32(nodata)
    if float(v) != float(nodata):  # no float32 equals it (or it is NaN)
        return np.zeros(z.shape, dtype=bool)
    return z == v


def fractal_transform(
    image,
    window_size: int,
    *,
    method: str = "mass",
    lags: Sequence[int] = (1, 2),
    box_sizes: Optional[Sequence[int]] = None,
    epsilons: Optional[Sequence[int]] = None,
    z_scale: Union[float, str] = "auto",
    edge_blocks: str = "drop",
    step: int = 1,
    nodata: Optional[float] = None,
    min_valid: float = 0.5,
    band: Optional[int] = None,
    n_threads: Optional[int] = None,
    progress: Optional[bool] = None,
    return_fit: bool = False,
    dilations: int = 2,
    anisotropy: bool = False,
    scale: Optional[str] = None,
):
    """Map of local fractal dimension over a moving window.

    Each output pixel is the dimension of the ``window_size`` x
    ``window_size`` window centred on it:

    ``"mass"`` (default)
        Voss's P(m, L) dimension of the point set ``(i, j, z / z_scale)``
        (the paper's eq. 13 and its SAR transform): for box sides ``L`` in
        ``box_sizes``, ``m_p(L)`` counts the valid pixels ``q`` of the image
        with ``|i_q - i_p|, |j_q - j_p| <= (L - 1) / 2`` and
        ``|z_q - z_p| <= L z_scale / 2``; the window's value is
        ``N(L) = mean over its valid pixels of 1 / m_p(L)`` and
        ``D = -slope`` of ``log N`` against ``log L``. Boxes count every pixel
        of the image, not only the window's, so a point's mass does not
        depend on where the window sits (and the cost does not grow with the
        window). Heights are in ``z_scale`` units per pixel: the estimate
        depends on this unit (see docs/transform.md).
    ``"variogram"`` / ``"madogram"``
        first differences along rows and columns, pooled, power 2 / 1;
    ``"square"``
        square increments ``z(i+u, j+u) - z(i+u, j) - z(i, j+u) + z(i, j)``,
        power 2 (accurate for smooth surfaces, H >= 0.7);

        and ``D = 3 - slope / p`` over ``lags``, exactly as
        :func:`fractalgeo_rs.surface_variation` on the window.
    ``"dbc"``
        differential box counting (Sarkar and Chaudhuri 1994) of the window:
        ``s x s`` blocks anchored at the window's top-left corner (with
        ``edge_blocks="drop"``, the default, the partial blocks of the last
        row and column are left out when ``s`` does not divide the window;
        ``"count"`` counts them), box stacks of height
        ``h = s * z_scale`` from ``z0 = 0``; a block spanning
        ``[zmin, zmax]`` needs ``floor(zmax / h) - floor(zmin / h) + 1``
        boxes, ``N(s)`` is the window's sum and ``D = -slope`` of ``log N``
        against ``log s``: exactly :func:`fractalgeo_rs.differential_box_counting`
        of the window with ``box_sizes``, ``z_scale``, ``z0=0`` and
        ``edge_blocks``. The
        height unit is fixed (not the window's own grey range), so maps of
        different places compare. Cost flat in the window (sliding min/max
        and summed-area tables strided by ``s``).
    ``"blanket"``
        Peleg's covering blanket of the window (dilations clipped to the
        window, 4-neighbourhood, ``z_scale`` data units per step):
        ``A(e) = sum (u_e - b_e) / (2 e)`` and ``D = 2 - slope`` of
        ``log A`` against ``log e`` over ``epsilons``, exactly
        :func:`fractalgeo_rs.blanket` of the window. The blankets are grown
        once per tile of the image; per window only the frame of pixels
        closer than ``e`` to its border is grown again, so the cost grows as
        ``window_size * max(epsilons)**2``.
    ``"whittle"``
        the debiased Whittle likelihood of the window's square increments
        (Sykulski et al. 2019; Guillaumin et al. 2022), ``D = 3 - H``:
        :func:`fractalgeo_rs.whittle` with ``filter="square"`` on the
        window, to about 1e-4 in ``D`` (a cubic search on a grid of 51
        ``H`` values replaces its Brent search). The most accurate map on
        fBm-like surfaces for ``H >= 0.5`` (sd of ``D`` 0.017-0.020 at
        window 65, 1.2-1.3 times the Cramér-Rao bound; docs/transform.md) and
        the slowest: one FFT of
        the window per output pixel, so use ``step`` on large scenes. Scale
        free (no ``z_scale``). With ``return_fit`` the second map is the
        standard error of ``D`` (from the curvature of the likelihood), not
        r². Windows of at least 7 pixels.
    ``"gls"``
        generalised least squares over the log quadratic variations of
        first and second differences along rows, columns and both
        diagonals at dilations ``1 .. dilations``, weighted by their exact
        covariance under fBm on the window's grid and iterated at the
        current ``H`` (:func:`fractalgeo_rs.gls_dimension`, the formulas in
        ``fractalgeo_rs.dimension.gls``), ``D = 3 - H``: exactly
        :func:`fractalgeo_rs.gls_dimension` of the clipped window with
        ``design=(window_size, window_size)``. Unbiased on exact fBm
        (absolute bias at most 0.001) with a spread 1.0-1.2 times the Cramér-Rao bound
        at windows 33 and 65 (docs/transform.md), every window statistic a
        window sum of a filtered image (summed-area tables: cost flat in the
        window). Scale free (no ``z_scale``). With ``return_fit`` the second
        map is the standard error of ``D`` (the GLS covariance at the
        estimate, times ``sqrt(w² / valid pixels)`` for windows with missing
        samples, whose increments touching NaN are left out). The weight
        tables are computed once per window size and process (0.7, 1.2 and
        2.3 s for windows 17, 33 and 65 on 2 cores).

    Parameters
    ----------
    image : array_like, dask.array.Array or xarray.DataArray, shape (rows, cols)
        A single-band image or DEM (3D input needs ``band``). NaN and
        ``nodata`` are missing samples.
    window_size : int
        Odd window side in pixels (>= 3, at most the image side).
    method : {"mass", "variogram", "madogram", "square", "dbc", "blanket", "whittle", "gls"}
    lags : sequence of int, default (1, 2)
        Increment methods: dilations in pixels, each smaller than the window.
    box_sizes : sequence of int, optional
        ``"mass"``: odd box sides, default ``3, 5, 7, 9`` (those not larger
        than the window). ``"dbc"``: block sides, at least three in
        ``[1, window_size]``, default ``2, 4, 8, ...`` up to half the window
        (``2, 3, 4`` for windows under 17).
    epsilons : sequence of int, optional
        ``"blanket"``: blanket thicknesses, at least three, default
        ``1, 2, 3, 4``.
    z_scale : float, "auto" or "range", default "auto"
        ``"mass"``, ``"dbc"``, ``"blanket"``: height units per pixel (e.g. 1
        grey level, 1 dB or 1 metre); the estimates depend on this unit.
        ``"auto"``: :func:`~fractalgeo_rs.transform.default_z_scale` of the whole image, ``1.4826 *
        median |lag-1 increment|`` (one typical step per box); ``"range"``:
        ``(max - min) / max(rows, cols)`` of the whole image (Sarkar and
        Chaudhuri 1994). The same spellings as the whole-image estimators
        (see ``docs/conventions.md``). The value used is recorded in
        the xarray output's ``attrs["z_scale"]``; maps are comparable only
        at equal ``z_scale``, so pass a fixed number across scenes.
    edge_blocks : {"drop", "count"}, default "drop"
        ``"dbc"``: leave out or count the partial blocks of the window's last
        row and column (counting them biases ``D`` low: a 33-pixel window has
        5 rows of 8-pixel blocks, not 4).
    step : int, default 1
        Compute the map on every ``step``-th row and column only (pixels
        ``(k * step, l * step)``): the output has shape
        ``(ceil(rows / step), ceil(cols / step))``, equal to the full map at
        those pixels (to rounding, 1e-6: window sums are taken from tables
        whose origins depend on ``step``). Only those windows are fitted.
    nodata : float, optional
        Value marking missing samples, in addition to NaN.
    min_valid : float, default 0.5
        Output NaN where fewer than this fraction of the window's pixels are
        valid.
    band : int, optional
        1-based band number for a 3D (bands, rows, cols) input, as in
        rasterio, GDAL and :func:`~fractalgeo_rs.read_raster` (0-based
        before 0.2.0: ``band=0`` now raises ValueError saying so).
    progress : bool or None, default None
        A progress bar (tqdm, if installed) while an in-memory image is
        computed in strips of rows (the result is the same bit for bit);
        ``None`` is off (the CLI turns it on when stderr is a terminal). On
        Dask, wrap ``compute`` in ``dask.diagnostics.ProgressBar``.
    n_threads : int, optional
        Threads (default all cores); results are identical for any value.
        For ``"whittle"`` these are the FFT workers; its matrix products run
        on numpy's BLAS threads, which this does not limit (set
        ``OPENBLAS_NUM_THREADS`` before starting Python, e.g. in Dask
        workers).
    scale : {None, "db", "linear", "amplitude"}, default None
        Radiometric scale of a SAR image. The maps depend on it: the
        estimators see the heights of the image surface, and linear
        intensity (a heavy right tail of speckle) gives other maps than dB
        (on linear intensity most windows fall below D = 2 and the
        urban/non-urban ordering can flip). The defaults and the worked
        examples were validated on dB (Sentinel-1 sigma0 in dB).
        ``"linear"`` (intensity, sigma0) is converted to
        ``10 log10(image)``, ``"amplitude"`` to ``20 log10(image)``
        (non-positive values become NaN); ``"db"`` and ``None`` use the
        image as it is. With ``None`` an image that looks like linear
        intensity (non-negative, heavy right tail: 99th percentile above 5
        times the median and mean above 1.2 times the median) gets a
        warning naming ``scale="linear"``. Not for DEMs or optical images
        (leave ``None``).
    return_fit : bool, default False
        Also return the map of r² of the log-log fit (1 with two lags); for
        ``"whittle"`` and ``"gls"``, the map of the standard error of ``D``.
        The result is then a
        :class:`~fractalgeo_rs.transform.TransformFit` (a tuple of the maps) whose
        ``flags`` is the flag layer (uint8 bits: 1 ``D < 2``, 2 ``D > 3``,
        4 pinned at an end of the ``H`` grid, 8 too few valid pixels; 0 =
        valid; ``fractalgeo_rs.transform.FLAGS``) and ``params`` the method, window, step and
        ``z_scale`` used, and no warning is issued (the flags carry the
        information). Without it an in-memory map with values outside
        ``[2, 3]`` raises one :class:`~fractalgeo_rs.FractalRangeWarning`
        giving their fractions, and a ``"gls"`` map with pinned windows one
        giving the pinned fraction.
    dilations : int, default 2
        ``"gls"``: largest dilation ``k`` of the increment filters (``8 k``
        filters; the window must exceed ``4 k``).
    anisotropy : bool, default False
        ``"gls"``: also return the maps of the direction (degrees in
        ``[0, 180)`` from the column axis towards the row axis, the
        direction of fastest variation) and ratio (``>= 1``) of geometric
        anisotropy, fitted to the window's first-order directional
        variations (``anisotropy_from_variations``),
        after the dimension (and standard-error) maps.

    Returns
    -------
    ndarray of float32 (or the input's dask/xarray type)
        Shape (rows, cols) (with ``step``: the strided grid); NaN where the
        window has too few valid pixels. With ``return_fit``, a
        :class:`~fractalgeo_rs.transform.TransformFit` pair (dimension, r²) carrying ``flags`` and
        ``params``; with ``anisotropy`` (``"gls"``), the angle and ratio
        maps follow.

    Notes
    -----
    Edge policy: near the border the window is the part of the full window
    inside the image (the image is taken as padded with NaN), so the map has
    the input's shape and every value is the estimator on the clipped window.
    On Dask the map is computed chunk by chunk with a NaN-filled halo of
    ``window_size // 2`` (plus ``(max(box_sizes) - 1) / 2`` for ``"mass"``,
    rounded up to a multiple of ``step``), which is the same edge policy, so
    results agree with the in-memory call (to 1e-6: window sums come from
    summed-area tables built per block).

    References
    ----------
    Sarkar, N., Chaudhuri, B. B. (1994). *IEEE Trans. SMC* 24(1), 115-120.
    Peleg, S., Naor, J., Hartley, R., Avnir, D. (1984). *IEEE Trans. PAMI*
    6(4), 518-523. Voss, R. F. (1986). *Physica Scripta* T13, 27-32.

    Examples
    --------
    >>> import numpy as np, fractalgeo_rs as fg
    >>> i, j = np.indices((40, 40))
    >>> d = fg.fractal_transform(0.3 * i + 0.3 * j, 9, method="variogram")
    >>> d.shape, d.dtype, float(np.nanmax(np.abs(d - 2.0)))  # a plane: D = 2
    ((40, 40), dtype('float32'), 0.0)
    >>> out = fg.fractal_transform(np.random.default_rng(0).normal(size=(40, 40)), 9,
    ...                            method="variogram", return_fit=True)
    >>> d, r2 = out                      # white noise: D scatters about 3
    >>> bool(np.all((out.flags == 2) == (d > 3 + 1e-6)))   # bit 2: above 3
    True
    >>> fg.fractal_transform(np.zeros((40, 40)), 9, method="blanket", step=4).shape
    (10, 10)
    """
    check_choice(method, "method", tuple(METHODS))
    spec = METHODS[method]
    check_choice(edge_blocks, "edge_blocks", ("drop", "count"))
    nodata = check_nodata(nodata)
    if spec.uses_z_scale:
        z_scale = check_z_scale(z_scale)
    n_threads = check_n_threads(n_threads)
    step = check_positive_int(step, "step")
    min_valid = check_fraction(min_valid, "min_valid")
    try:
        lags = sorted(set(int(v) for v in lags))
    except (TypeError, ValueError):
        raise TypeError(f"lags: expected a sequence of positive ints, got {lags!r}") from None

    arr, image = _select_band(image, band)
    w = check_window(window_size, shape=arr.shape)
    check_choice(scale, "scale", (None, "db", "linear", "amplitude"))
    if scale in ("linear", "amplitude"):
        arr, image = _to_db(arr, image, nodata, 10.0 if scale == "linear" else 20.0)
        nodata = None  # now NaN
    elif scale is None and array_kind(arr) == "numpy":
        warn_if_linear(arr, nodata)
    z_used: Optional[float] = None  # the height unit of the box and mass methods
    if spec.uses_z_scale:
        z_used = resolve_z_scale(z_scale, arr, nodata)
    opts: Dict[str, Any] = {"lags": lags, "z_scale": z_used, "dilations": dilations, "anisotropy": bool(anisotropy)}
    half = w // 2 + spec.configure(w, MapOptions(lags, box_sizes, epsilons, edge_blocks, dilations, anisotropy), opts)

    def prepare(block):
        z = np.asarray(block, dtype=_float_dtype(block.dtype))
        if nodata is not None:
            z = np.where(_nodata_mask(z, nodata), np.nan, z)
        return z

    def kernel(z):
        """The maps (dimension, quality[, ...]) on the ``step`` grid from the block's origin."""
        z = np.ascontiguousarray(z, dtype=_float_dtype(z.dtype) if spec.reads_float32 else np.float64)
        return list(spec.grid(z, w, opts, min_valid, step, n_threads))

    image = _prepared(image, arr, prepare)
    names: Tuple[str, ...] = ("fractal_dimension", spec.quality) + spec.extra_names(opts)
    out = run_raster(kernel, image, depth=half, n_out=len(names), step=step,
                     prepare=prepare if array_kind(arr) == "dask" else None, names=names,
                     progress=_progress.resolve(progress), desc=f"fractal_transform ({method})")
    lazy = array_kind(arr) == "dask"  # (a lazy map is not read here)
    if not return_fit and not lazy:  # with return_fit the flag layer carries this
        if spec.warn_map is not None:
            spec.warn_map(np.asarray(out[0]))
        warn_out_of_range(out[0], method)
    params = {"method": method, "window_size": w, "step": step, "z_scale": z_used,
              "z_units": None if z_used is None else "image units per pixel"}
    if array_kind(image) == "xarray":  # record what makes maps comparable
        for o in out:
            o.attrs.update({"fractal_method": method, "window_size": w})
            if z_used is not None:
                o.attrs["z_scale"] = z_used
    # gls with anisotropy: D[, se], angle, ratio
    out = tuple(out[:2] if return_fit else out[:1]) + tuple(out[2:])
    if return_fit:
        return TransformFit(out, flag_map(out[0], method), params)
    return out if len(out) > 1 else out[0]


def looks_linear(arr: np.ndarray, nodata=None) -> bool:
    """True for an image that looks like linear SAR intensity: the finite
    samples (nodata excluded) are non-negative with a heavy right tail (99th
    percentile above 5 times the median, mean above 1.2 times the median;
    single-look speckle has 6.6 and 1.44, dB images have negative values,
    DEMs and optical images have neither tail)."""
    a = np.asarray(arr)
    if a.dtype.kind not in "iuf" or a.size == 0:
        return False
    if a.size > 1_000_000:  # a regular sample is enough for the quantiles
        k = int(np.ceil(np.sqrt(a.size / 1_000_000)))
        a = a[::k, ::k] if a.ndim == 2 else a.ravel()[:: k * k]
    v = a[np.isfinite(a)] if a.dtype.kind == "f" else a.ravel()
    if nodata is not None and not np.isnan(nodata):
        v = v[v != nodata]
    if v.size < 100 or v.min() < 0:
        return False
    med = float(np.median(v))
    if not med > 0:
        return False
    return float(np.percentile(v, 99)) > 5.0 * med and float(v.mean()) > 1.2 * med


def warn_if_linear(arr: np.ndarray, nodata=None) -> None:
    """Warn when ``arr`` looks like linear intensity (:func:`looks_linear`)."""
    if looks_linear(arr, nodata):
        import warnings

        from fractalgeo_rs._warn import user_stacklevel

        warnings.warn("image: looks like linear SAR intensity or amplitude (non-negative with a heavy right tail); "
                      "the maps were validated on dB: pass scale='linear' (CLI: --scale linear) to convert "
                      "intensity to 10 log10, scale='amplitude' (--scale amplitude) for amplitudes, or scale='db' "
                      "(--scale db) if the image is on a log scale already", UserWarning,
                      stacklevel=user_stacklevel())


def _to_db(arr, image, nodata, factor: float):
    """``factor * log10`` of the image (numpy, Dask or xarray), NaN at
    nodata and at non-positive values."""
    def conv(a):
        a = a.astype(np.float64)
        bad = ~(a > 0)
        if nodata is not None:
            bad = bad | _nodata_mask(a, nodata)
        return factor * np.log10(np.where(bad, np.nan, np.where(bad, 1.0, a)))

    kind = array_kind(image)
    if kind == "xarray":
        image = image.copy(data=conv(image.data))
        return image.data, image
    out = conv(arr)
    return out, out


def _select_band(image, band):
    """``(array, image)``: the 2D array to check (numpy or dask) and the
    object to compute on (the same, or the xarray DataArray), with ``band``
    (1-based, as in rasterio and GDAL) taken from a 3D input."""
    kind = array_kind(image)
    data = image.data if kind == "xarray" else image
    arr = data if array_kind(data) == "dask" else as_array(data, "image")
    if arr.ndim == 3:
        if band is None:
            raise ValueError(f"band: a 3D input of shape {arr.shape} needs band= (1-based band number)")
        if isinstance(band, bool) or not isinstance(band, (int, np.integer)):
            raise TypeError(f"band: expected a 1-based band number, got {band!r}")
        if band == 0:
            raise ValueError("band: band numbers are 1-based, as in rasterio and GDAL (0-based before 0.2.0): "
                             "band=1 is the first band")
        if not (1 <= band <= arr.shape[0]):
            raise ValueError(f"band: expected a band number in [1, {arr.shape[0]}], got {band!r}")
        arr = arr[int(band) - 1]
        image = image[int(band) - 1] if kind == "xarray" else arr
    elif kind != "xarray":
        image = arr
    if arr.ndim != 2:
        raise ValueError(f"image: expected a 2D image, got {arr.ndim} dimensions")
    if arr.dtype.kind not in "iuf":
        raise TypeError(f"image: expected a real numeric array, got dtype {arr.dtype}")
    if 0 in arr.shape:
        raise ValueError(f"image: array is empty (shape {arr.shape})")
    return arr, image


def _prepared(image, arr, prepare):
    """In memory: the image prepared once (float, nodata as NaN) and checked
    for a valid value; on Dask: cast to float so the NaN halo can be added
    (the blocks are prepared by the runner)."""
    if array_kind(arr) == "dask":
        z = arr.astype(_float_dtype(arr.dtype))
    else:
        z = prepare(arr)
        # fmax ignores NaN: the reduction is NaN only when every value is
        if np.isnan(np.fmax.reduce(z, axis=None)):
            raise ValueError("image: no valid value (all NaN or nodata)")
    return image.copy(data=z) if array_kind(image) == "xarray" else z


@keyword_only_since(["box_sizes"], since="0.2.0")
def lacunarity_map(
    image,
    window_size: int,
    *,
    box_sizes: Optional[Sequence[int]] = None,
    nodata: Optional[float] = None,
    min_valid: float = 0.5,
    n_threads: Optional[int] = None,
    progress: Optional[bool] = None,
) -> np.ndarray:
    """Map of gliding-box lacunarity over a moving window.

    For each pixel and box side ``r``, boxes glide over every position inside
    the ``window_size`` window centred on the pixel (clipped to the image at
    the edges); with box masses ``M`` (sums of the values; boxes touching
    NaN or ``nodata`` are left out) the value is ``E[M^2] / E[M]^2``, exactly
    :func:`fractalgeo_rs.lacunarity` on that window. The cost per pixel does
    not grow with the window (summed-area tables, Rust, GIL released).

    Parameters
    ----------
    image : array_like, dask.array.Array or xarray.DataArray, shape (rows, cols)
        Non-negative values (intensity, a binary mask as 0/1; not dB). On
        Dask the sign check is left to the caller (it would read the
        whole scene).
    window_size : int
        Odd window side (>= 3).
    box_sizes : sequence of int, optional
        Box sides, default ``1, 2, 4, 8`` (those not larger than the window).
    min_valid : float, default 0.5
        NaN where fewer than this fraction of the window's pixels are valid.
    n_threads : int, optional
        Threads (default all cores); results are identical for any value.
    progress : bool or None, default None
        A progress bar (tqdm, if installed) while an in-memory image is
        computed in strips of rows (the result is the same bit for bit);
        ``None`` is off (the CLI turns it on when stderr is a terminal). On
        Dask, wrap ``compute`` in ``dask.diagnostics.ProgressBar``.

    Returns
    -------
    ndarray of float32, shape (len(box_sizes), rows, cols)
        Or the input's dask/xarray type (xarray: a leading ``box_size``
        dimension). On Dask each chunk is computed with a NaN halo of
        ``window_size // 2``, the edge policy of the in-memory call, so the
        results are equal.

    References
    ----------
    Allain, C., Cloitre, M. (1991). *Physical Review A* 44(6), 3552-3558.

    Examples
    --------
    >>> import numpy as np, fractalgeo_rs as fg
    >>> lam = fg.lacunarity_map(np.ones((16, 16)), 5, box_sizes=[1, 2])
    >>> lam.shape, float(np.nanmax(np.abs(lam - 1.0)))  # a constant image has no gaps: Lambda = 1
    ((2, 16, 16), 0.0)
    """
    if array_kind(image) == "numpy":
        image = as_array(image, "image")
        if image.dtype == bool:
            image = image.astype(np.uint8)
    arr, image = _select_band(image, None)
    w = check_window(window_size, shape=arr.shape)
    nodata = check_nodata(nodata)
    if box_sizes is None:
        sizes = [r for r in (1, 2, 4, 8) if r <= w]
    else:
        try:
            sizes = [int(v) for v in box_sizes]
        except (TypeError, ValueError):
            raise TypeError(f"box_sizes: expected a sequence of ints, got {box_sizes!r}") from None
        if not sizes or any(r < 1 or r > w for r in sizes):
            raise ValueError(f"box_sizes: box sides must be in [1, {w}], got {sizes}")
    min_valid = check_fraction(min_valid, "min_valid")
    n_threads = check_n_threads(n_threads)

    def prepare(block):
        z = np.array(block, dtype=np.float64)
        if nodata is not None:
            z[block == nodata] = np.nan
        return z

    def kernel(z):
        return _core.lacunarity_transform_map(np.ascontiguousarray(z), w, sizes, min_valid, n_threads)

    if array_kind(arr) == "dask":
        data = arr.astype(np.float64)
        image = image.copy(data=data) if array_kind(image) == "xarray" else data
        prep = prepare
    else:
        z = prepare(arr)
        if np.isnan(z).all():
            raise ValueError("image: no valid value (all NaN or nodata)")
        if (z[~np.isnan(z)] < 0).any():
            raise ValueError("image: lacunarity needs non-negative masses (e.g. intensity, not dB)")
        image = image.copy(data=z) if array_kind(image) == "xarray" else z
        prep = None
    return run_raster(kernel, image, depth=w // 2, n_out=len(sizes), prepare=prep,
                      names=("lacunarity",), stack_dim=("box_size", sizes),
                      progress=_progress.resolve(progress), desc="lacunarity_map")
