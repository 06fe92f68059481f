"""Raster input/output: ``.npy``, 8/16-bit PNG, float EXR and GeoTIFF.

=========== ================================= ===================================
format      read                              write
=========== ================================= ===================================
``.npy``    ``numpy.load`` (no pickles)       any array
``.png``    Rust ``image`` crate              2D uint8 / uint16 (grey)
``.exr``    Rust ``exr`` crate, channel "Y"   2D real array, stored as float32
``.tif``    rasterio (keeps CRS, transform,   2D array with ``profile`` / ``crs``
``.tiff``   nodata); without rasterio 8/16-   / ``transform`` / ``nodata``
            bit TIFF via the ``image`` crate  (needs rasterio: the ``geo`` extra)
other       rasterio (any GDAL format)        --
=========== ================================= ===================================

Every write is atomic: the file is written beside the target under a
temporary name and renamed over it, so it appears whole or not at all.
Values are never rescaled.
"""
from __future__ import annotations

import os
from typing import Optional, Tuple

import numpy as np

from fractalgeo_rs import _core
from fractalgeo_rs._validation import as_array, atomic_write_path

__all__ = ["read_raster", "write_raster"]


def _ext(path) -> str:
    return os.path.splitext(os.fspath(path))[1].lower()


def _rasterio():
    try:
        import rasterio
    except ImportError:
        return None
    return rasterio


def read_raster(path, band: int = 1) -> Tuple[np.ndarray, Optional[dict]]:
    """Read one band of a raster file.

    Parameters
    ----------
    path : str or os.PathLike
        ``.npy``, ``.png``, ``.exr``, ``.tif``/``.tiff`` or, with rasterio
        installed, any format GDAL reads (e.g. SRTM ``.hgt``).
    band : int
        1-based band (channel) number; a 2D ``.npy`` has the single band 1, a
        3D one is ``(bands, rows, cols)`` like rasterio.

    Returns
    -------
    (numpy.ndarray, dict or None)
        The 2D array in the file's own dtype (row 0 = first/top row), and the
        rasterio profile (``crs``, ``transform``, ``nodata``, ``dtype``, ...)
        for files read through rasterio, else ``None``. Nodata values are
        returned as stored: mask them with ``profile["nodata"]``.

    References
    ----------
    GDAL/OGR contributors, *GDAL/OGR Geospatial Data Abstraction software
    Library*, Open Source Geospatial Foundation, doi:10.5281/zenodo.5884351.

    Examples
    --------
    >>> import numpy as np, os, tempfile, fractalgeo_rs as fg
    >>> p = os.path.join(tempfile.mkdtemp(), "a.npy")
    >>> fg.write_raster(p, np.eye(3))
    >>> a, prof = fg.read_raster(p)
    >>> a.shape, prof
    ((3, 3), None)
    """
    p = os.fspath(path)
    if isinstance(band, bool) or not isinstance(band, (int, np.integer)) or band < 1:
        raise ValueError(f"band: expected a 1-based band number, got {band!r}")
    if not os.path.exists(p):
        raise FileNotFoundError(f"path: no such file: {p!r}")
    ext = _ext(p)
    if ext == ".npy":
        a = np.load(p, allow_pickle=False)
        if a.ndim == 2:
            if band != 1:
                raise ValueError(f"band: {p!r} has 1 band, asked for {band}")
            return a, None
        if a.ndim == 3:
            if band > a.shape[0]:
                raise ValueError(f"band: {p!r} has {a.shape[0]} bands, asked for {band}")
            return np.ascontiguousarray(a[band - 1]), None
        raise ValueError(f"path: {p!r} holds a {a.ndim}D array, expected 2D or 3D")
    if ext == ".exr":
        if band != 1:
            raise ValueError(f"band: EXR files are read as one band (channel \"Y\"), asked for {band}")
        return _core.read_exr(p), None
    rio = _rasterio()
    if ext == ".png" or (rio is None and ext in (".tif", ".tiff")):
        img = _core.read_image(p)
        if band > img.shape[2]:
            raise ValueError(f"band: {p!r} has {img.shape[2]} channels, asked for {band}")
        return np.ascontiguousarray(img[:, :, band - 1]), None
    if rio is None:
        raise OSError(
            f"path: unsupported raster format {ext or '(none)'!r} without rasterio: .npy, .png, .exr and "
            "8/16-bit .tif are read natively; other formats need pip install 'fractalgeo_rs[geo]'"
        )
    try:
        src = rio.open(p)
    except rio.errors.RasterioIOError as exc:
        raise OSError(f"path: unsupported or unreadable raster {p!r}: {exc}") from None
    with src:
        if band > src.count:
            raise ValueError(f"band: {p!r} has {src.count} bands, asked for {band}")
        return src.read(band), dict(src.profile)


def write_raster(path, data, *, profile: Optional[dict] = None, crs=None, transform=None, nodata=None) -> None:
    """Write a 2D array to a raster file, atomically.

    Parameters
    ----------
    path : str or os.PathLike
        The format follows the extension: ``.npy``, ``.png`` (uint8/uint16
        only: no silent rescaling), ``.exr`` (stored as float32), ``.tif`` /
        ``.tiff`` (GeoTIFF through rasterio).
    data : array_like, shape (rows, cols)
        Not modified.
    profile : dict or None
        GeoTIFF only: a rasterio profile, e.g. the one :func:`read_raster`
        returned; its ``crs``, ``transform`` and ``nodata`` are kept, the
        size, count and dtype follow ``data``.
    crs, transform, nodata
        GeoTIFF only: override the profile's (``transform`` an ``Affine``).

    Returns
    -------
    None
        The file is written next to its final name and renamed into place, so a
        reader never sees a partial file.

    References
    ----------
    GDAL/OGR contributors, *GDAL/OGR Geospatial Data Abstraction software
    Library*, Open Source Geospatial Foundation, doi:10.5281/zenodo.5884351.

    Examples
    --------
    >>> import os, tempfile
    >>> import numpy as np, fractalgeo_rs as fg
    >>> path = os.path.join(tempfile.mkdtemp(), 'heights.npy')
    >>> fg.write_raster(path, np.arange(6.0).reshape(2, 3))
    >>> z, profile = fg.read_raster(path)
    >>> z.tolist(), profile
    ([[0.0, 1.0, 2.0], [3.0, 4.0, 5.0]], None)
    """
    a = as_array(data, "data")
    p = os.fspath(path)
    ext = _ext(p)
    geo = profile is not None or crs is not None or transform is not None or nodata is not None
    if a.ndim != 2 and not (ext == ".npy" and not geo):
        raise ValueError(f"data: expected a 2D array, got shape {a.shape}")
    if geo and ext not in (".tif", ".tiff"):
        raise ValueError(f"profile: georeferencing can only be written to GeoTIFF (.tif), not {ext!r}")
    if ext == ".npy":
        with atomic_write_path(p) as tmp:
            np.save(tmp, a, allow_pickle=False)
        return
    if ext == ".png":
        if a.dtype not in (np.uint8, np.uint16):
            raise TypeError(f"data: PNG holds uint8 or uint16, got {a.dtype} (convert it explicitly)")
        _core.write_png(p, np.ascontiguousarray(a))
        return
    if ext == ".exr":
        if a.dtype == bool or not (np.issubdtype(a.dtype, np.integer) or np.issubdtype(a.dtype, np.floating)):
            raise TypeError(f"data: EXR holds real numbers, got {a.dtype}")
        _core.write_exr(p, np.ascontiguousarray(a, dtype=np.float32))
        return
    if ext in (".tif", ".tiff"):
        rio = _rasterio()
        if rio is None:
            raise OSError("path: writing GeoTIFF needs rasterio (pip install 'fractalgeo_rs[geo]')")
        prof = {"driver": "GTiff"}
        if profile:
            prof.update({k: v for k, v in profile.items() if k not in ("blockxsize", "blockysize", "tiled")})
        prof.update(driver="GTiff", width=a.shape[1], height=a.shape[0], count=1, dtype=a.dtype.name)
        if crs is not None:
            prof["crs"] = crs
        if transform is not None:
            # a plain 6-tuple is read in rasterio.Affine order (a, b, c, d, e, f)
            prof["transform"] = transform if isinstance(transform, rio.Affine) else rio.Affine(*transform)
        if nodata is not None:
            prof["nodata"] = nodata
        if a.dtype == bool:
            raise TypeError("data: convert boolean masks to uint8 before writing GeoTIFF")
        with atomic_write_path(p) as tmp:
            with rio.open(tmp, "w", **prof) as dst:
                dst.write(a, 1)
        return
    raise ValueError(f"path: unknown raster extension {ext!r} (use .npy, .png, .exr, .tif)")
