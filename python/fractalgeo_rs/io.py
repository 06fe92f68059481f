"""Raster input and output.

GeoTIFF goes through rasterio (optional ``geo`` extra), which keeps the CRS,
the affine transform and nodata; PNG and 8/16-bit TIFF through the Rust
``image`` crate; ``.npy`` through numpy. Writes are atomic.
"""
from __future__ import annotations

import os
from typing import Any, Dict, Optional, Tuple

import numpy as np

from fractalgeo_rs import _core
from fractalgeo_rs._validation import atomic_write_path, check_positive_int

__all__ = ["read_raster", "write_png"]


def _rasterio():
    try:
        import rasterio
    except ImportError:
        return None
    return rasterio


def read_raster(path, band: int = 1) -> Tuple[np.ndarray, Optional[Dict[str, Any]]]:
    """Read one band of a raster file.

    Parameters
    ----------
    path : str or os.PathLike
        ``.npy``, ``.png``, ``.tif``/``.tiff`` (GeoTIFF through rasterio when
        it is installed, else 8/16-bit TIFF through the Rust ``image`` crate),
        ``.hgt`` (SRTM, rasterio).
    band : int, default 1
        1-based band (channel) number.

    Returns
    -------
    data : ndarray, shape (rows, cols)
        The band in the file's dtype. Nodata samples of float rasters read
        through rasterio are NaN; for integer rasters see ``profile["nodata"]``.
    profile : dict or None
        ``crs``, ``transform``, ``nodata``, ``dtype`` and ``count`` for
        rasterio reads; None for formats without georeferencing.
    """
    band = check_positive_int(band, "band")
    path = os.fspath(path)
    if not os.path.exists(path):
        raise OSError(f"path: no such file: {path!r}")
    ext = os.path.splitext(path)[1].lower()
    if ext == ".npy":
        arr = np.load(path, allow_pickle=False)
        if arr.ndim == 3:
            if band > arr.shape[-1]:
                raise ValueError(f"band: {path} has {arr.shape[-1]} bands, asked for band {band}")
            arr = arr[..., band - 1]
        elif band != 1:
            raise ValueError(f"band: {path} has one band, asked for band {band}")
        return arr, None
    rio = _rasterio() if ext in (".tif", ".tiff", ".hgt", ".vrt", ".img") else None
    if rio is not None:
        with rio.open(path) as src:
            if band > src.count:
                raise ValueError(f"band: {path} has {src.count} bands, asked for band {band}")
            arr = src.read(band)
            nodata = src.nodatavals[band - 1]
            if nodata is not None and arr.dtype.kind == "f":
                arr = np.where(arr == nodata, np.nan, arr) if not np.isnan(nodata) else arr
            profile = {
                "crs": src.crs,
                "transform": src.transform,
                "nodata": nodata,
                "dtype": str(src.dtypes[band - 1]),
                "count": src.count,
            }
        return arr, profile
    if ext in (".png", ".tif", ".tiff"):
        img = _core.read_image(path)
        if band > img.shape[2]:
            raise ValueError(f"band: {path} has {img.shape[2]} channels, asked for band {band}")
        return np.ascontiguousarray(img[:, :, band - 1]), None
    if ext == ".hgt":
        raise OSError(f"path: reading {ext} files needs rasterio: pip install 'fractalgeo_rs[geo]'")
    raise ValueError(f"path: unsupported raster format {ext!r} (expected .npy, .png, .tif, .tiff)")


def write_png(path, image) -> None:
    """Write a 2D uint8 or uint16 array as a single-band PNG, atomically."""
    arr = np.asarray(image)
    if arr.ndim != 2 or arr.dtype not in (np.uint8, np.uint16):
        raise TypeError(f"image: expected a 2D uint8 or uint16 array, got {arr.ndim}D {arr.dtype}")
    _core.write_png(os.fspath(path), arr)
