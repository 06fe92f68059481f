"""Fractal transform: maps of local fractal dimension (paper section 4.2,
figure 10).

This release has Voss's P(m, L) mass dimension (the paper's method, the
default) and the increment estimators (variogram, madogram, square
increments), computed with summed-area tables in Rust so that the time per
pixel does not grow with the window; DBC and blanket maps come next.
"""
from __future__ import annotations

from typing import Optional, Sequence, Tuple, Union

import numpy as np

from fractalgeo_rs import _core
from fractalgeo_rs._validation import as_array, check_choice, check_n_threads, check_positive_int

from fractalgeo_rs.transform.segment import segment

__all__ = ["fractal_transform", "lacunarity_map", "segment", "TRANSFORM_METHODS"]

TRANSFORM_METHODS = {
    # name: (power p, square increments); "mass" has its own kernel
    "mass": (None, None),
    "variogram": (2.0, False),
    "madogram": (1.0, False),
    "square": (2.0, True),
}


def _check_window(window_size, shape) -> int:
    w = check_positive_int(window_size, "window_size")
    if w < 3 or w % 2 == 0:
        raise ValueError(f"window_size: expected an odd integer >= 3, got {w}")
    if w > max(shape):
        raise ValueError(f"window_size: window {w} is larger than the image {tuple(shape)}")
    return w


def _transform_numpy(z: np.ndarray, w: int, lags, p, square, min_valid, n_threads, mass=None):
    z = np.ascontiguousarray(z, dtype=np.float64)
    if mass is not None:
        sizes, z_scale = mass
        return _core.mass_transform_map(z, w, list(sizes), z_scale, min_valid, n_threads)
    return _core.variation_transform_map(z, w, list(lags), p, square, min_valid, n_threads)


def fractal_transform(
    image,
    window_size: int,
    *,
    method: str = "mass",
    lags: Sequence[int] = (1, 2),
    box_sizes: Optional[Sequence[int]] = None,
    z_scale: float = 1.0,
    nodata: Optional[float] = None,
    min_valid: float = 0.5,
    band: Optional[int] = None,
    n_threads: Optional[int] = None,
    return_fit: bool = False,
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

    Parameters
    ----------
    image : array_like, dask.array.Array or xarray.DataArray, shape (rows, cols)
        A single-band image or DEM (3D input needs ``band``). NaN and
        ``nodata`` are missing samples.
    window_size : int
        Odd window side in pixels (>= 3, at most the image side).
    method : {"mass", "variogram", "madogram", "square"}
    lags : sequence of int, default (1, 2)
        Increment methods: dilations in pixels, each smaller than the window.
    box_sizes : sequence of int, optional
        ``"mass"``: odd box sides, default ``3, 5, 7, 9`` (those not larger
        than the window).
    z_scale : float, default 1
        ``"mass"``: height units per pixel (e.g. 1 grey level or 1 dB).
    min_valid : float, default 0.5
        Output NaN where fewer than this fraction of the window's pixels are
        valid.
    band : int, optional
        0-based band index for a 3D (bands, rows, cols) input.
    n_threads : int, optional
        Threads (default all cores); results are identical for any value.
    return_fit : bool, default False
        Also return the map of r² of the log-log fit (1 with two lags).

    Returns
    -------
    ndarray of float32 (or the input's dask/xarray type), shape (rows, cols)
        NaN where the window has too few valid pixels.

    Notes
    -----
    Edge policy: near the border the window is the part of the full window
    inside the image (the image is taken as padded with NaN), so the map has
    the input's shape and every value is the estimator on the clipped window.
    On Dask the map is computed chunk by chunk with ``map_overlap`` and a
    NaN-filled halo of ``window_size // 2`` (plus ``(max(box_sizes) - 1) / 2``
    for ``"mass"``), which is the same edge policy,
    so results agree with the in-memory call (to 1e-6: window sums come from
    summed-area tables built per block).
    """
    check_choice(method, "method", tuple(TRANSFORM_METHODS))
    p, square = TRANSFORM_METHODS[method]
    if method == "mass":
        if isinstance(z_scale, bool) or not np.isscalar(z_scale) or not (np.isfinite(z_scale) and z_scale > 0):
            raise ValueError(f"z_scale: expected a positive number, got {z_scale!r}")
        z_scale = float(z_scale)
    n_threads = check_n_threads(n_threads)
    if isinstance(min_valid, bool) or not np.isscalar(min_valid) or not (0.0 <= float(min_valid) <= 1.0):
        raise ValueError(f"min_valid: expected a fraction in [0, 1], got {min_valid!r}")
    min_valid = float(min_valid)
    try:
        lags = sorted(set(int(v) for v in lags))
    except (TypeError, ValueError):
        raise TypeError(f"lags: expected a sequence of positive ints, got {lags!r}") from None

    xr_obj = None
    try:  # xarray: compute on its data, re-wrap coords and attrs
        import xarray as xr  # noqa: F401

        if type(image).__module__.startswith("xarray") and hasattr(image, "dims"):
            xr_obj = image
            image = image.data
    except ImportError:
        pass
    is_dask = type(image).__module__.startswith("dask")
    arr = image if is_dask else as_array(image, "image")
    if arr.ndim == 3:
        if band is None:
            raise ValueError(f"band: a 3D input of shape {arr.shape} needs band= (0-based band index)")
        if not (0 <= int(band) < arr.shape[0]):
            raise ValueError(f"band: expected an index in [0, {arr.shape[0]}), got {band}")
        arr = arr[int(band)]
        if xr_obj is not None:
            xr_obj = xr_obj[int(band)]
    if arr.ndim != 2:
        raise ValueError(f"image: expected a 2D image, got {arr.ndim} dimensions")
    if arr.dtype.kind not in "iuf" or arr.dtype.kind == "b":
        raise TypeError(f"image: expected a real numeric array, got dtype {arr.dtype}")
    if 0 in arr.shape:
        raise ValueError(f"image: array is empty (shape {arr.shape})")
    w = _check_window(window_size, arr.shape)
    if method == "mass":
        if box_sizes is None:
            sizes = [L for L in (3, 5, 7, 9) if L <= w]
        else:
            try:
                sizes = sorted(set(int(v) for v in box_sizes))
            except (TypeError, ValueError):
                raise TypeError(f"box_sizes: expected a sequence of odd ints, got {box_sizes!r}") from None
        if len(sizes) < 2 or any(L < 3 or L % 2 == 0 or L > w for L in sizes):
            raise ValueError(f"box_sizes: need at least 2 distinct odd sides in [3, {w}], got {sizes}")
    elif len(lags) < 2 or lags[0] < 1 or lags[-1] >= w:
        raise ValueError(f"lags: need at least 2 distinct lags in [1, {w}), got {lags}")

    def kernel(block):
        z = np.asarray(block, dtype=np.float64)
        if nodata is not None:
            z = np.where(z == nodata, np.nan, z)
        d, r2 = _transform_numpy(z, w, lags, p, square, min_valid, n_threads,
                                 mass=(sizes, z_scale) if method == "mass" else None)
        return np.stack([d, r2]) if return_fit else d

    if is_dask:
        import dask.array as da

        # a window needs its half-width; the mass method's boxes reach
        # (L_max - 1) / 2 further
        half = w // 2 + (max(sizes) // 2 if method == "mass" else 0)
        chunks = arr.chunks
        if min(min(c) for c in chunks) < half:
            # every chunk must hold the halo its neighbours need
            arr = arr.rechunk(tuple(max(half, max(c)) for c in chunks))
        zf = arr.astype(np.float64)

        if return_fit:
            d = da.map_overlap(lambda b: kernel(b)[0], zf, depth=half, boundary=np.nan, dtype=np.float32,
                               meta=np.empty((0, 0), np.float32))
            r = da.map_overlap(lambda b: kernel(b)[1], zf, depth=half, boundary=np.nan, dtype=np.float32,
                               meta=np.empty((0, 0), np.float32))
            out = (d, r)
        else:
            out = da.map_overlap(kernel, zf, depth=half, boundary=np.nan, dtype=np.float32,
                                 meta=np.empty((0, 0), np.float32))
    else:
        zcheck = np.asarray(arr, dtype=np.float64)
        if np.isnan(zcheck).all() or (nodata is not None and np.all((zcheck == nodata) | np.isnan(zcheck))):
            raise ValueError("image: no valid value (all NaN or nodata)")
        res = kernel(arr)
        out = (res[0], res[1]) if return_fit else res
    if xr_obj is not None:
        wrap = lambda a: xr_obj.copy(data=a).astype(np.float32).rename("fractal_dimension")  # noqa: E731
        out = tuple(wrap(a) for a in out) if return_fit else wrap(out)
    return out


def lacunarity_map(
    image,
    window_size: int,
    box_sizes: Optional[Sequence[int]] = None,
    *,
    nodata: Optional[float] = None,
    min_valid: float = 0.5,
    n_threads: Optional[int] = None,
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
    image : array_like, shape (rows, cols)
        Non-negative values (intensity, a binary mask as 0/1; not dB).
    window_size : int
        Odd window side (>= 3).
    box_sizes : sequence of int, optional
        Box sides, default ``1, 2, 4, 8`` (those not larger than the window).
    min_valid : float, default 0.5
        NaN where fewer than this fraction of the window's pixels are valid.

    Returns
    -------
    ndarray of float32, shape (len(box_sizes), rows, cols)

    References
    ----------
    Allain, C., Cloitre, M. (1991). *Physical Review A* 44(6), 3552-3558.
    """
    arr = as_array(image, "image")
    if arr.ndim != 2:
        raise ValueError(f"image: expected a 2D image, got {arr.ndim} dimensions")
    if arr.dtype.kind not in "biuf":
        raise TypeError(f"image: expected a real or boolean array, got dtype {arr.dtype}")
    if 0 in arr.shape:
        raise ValueError(f"image: array is empty (shape {arr.shape})")
    w = _check_window(window_size, arr.shape)
    z = np.array(arr, dtype=np.float64)
    if nodata is not None:
        z[arr == nodata] = np.nan
    if np.isnan(z).all():
        raise ValueError("image: no valid value (all NaN or nodata)")
    if (z[~np.isnan(z)] < 0).any():
        raise ValueError("image: lacunarity needs non-negative masses (e.g. intensity, not dB)")
    if box_sizes is None:
        sizes = [r for r in (1, 2, 4, 8) if r <= w]
    else:
        try:
            sizes = [int(v) for v in box_sizes]
        except (TypeError, ValueError):
            raise TypeError(f"box_sizes: expected a sequence of ints, got {box_sizes!r}") from None
        if not sizes or any(r < 1 or r > w for r in sizes):
            raise ValueError(f"box_sizes: box sides must be in [1, {w}], got {sizes}")
    if isinstance(min_valid, bool) or not np.isscalar(min_valid) or not (0.0 <= float(min_valid) <= 1.0):
        raise ValueError(f"min_valid: expected a fraction in [0, 1], got {min_valid!r}")
    return _core.lacunarity_transform_map(np.ascontiguousarray(z), w, sizes, float(min_valid),
                                          check_n_threads(n_threads))
