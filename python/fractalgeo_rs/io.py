"""Raster input/output: ``.npy``, 8/16-bit PNG, float EXR and GeoTIFF.

``.npy``
    read with ``numpy.load`` (no pickles); any array is written.
``.png``
    read with the Rust ``image`` crate (grey; colour needs ``band=``);
    2D uint8 / uint16 (grey) written, a ``transform`` to a world file
    (``.pgw``) and a ``crs`` to ``.prj``.
``.exr``
    the Rust ``exr`` crate, channel "Y"; a 2D real array is stored as
    float32.
``.tif``, ``.tiff``
    rasterio (keeps CRS, transform, nodata; without rasterio 8/16-bit TIFF
    is read by the ``image`` crate); a 2D array is written with
    ``profile`` / ``crs`` / ``transform`` / ``nodata`` (needs rasterio, the
    ``geo`` extra).
other extensions
    read through rasterio (any GDAL format); not written.

Every write is atomic: the file is written beside the target under a
temporary name and renamed over it, so it appears whole or not at all.
Values are never rescaled; complex data is refused (write ``np.abs(z)`` or
``z.real``).

Every reader error is an ``OSError`` (``FileNotFoundError`` for a missing
file) whose message names the path and the cause, so a corrupt, truncated or
empty file never surfaces as a decoder's internal exception.
"""
from __future__ import annotations

import os
from typing import Any, Dict, Optional, Tuple

import numpy as np

from fractalgeo_rs import _core
from fractalgeo_rs._validation import atomic_write_path

__all__ = ["read_raster", "write_raster", "is_binary_mask"]


def is_binary_mask(data) -> bool:
    """True for a binary mask: a bool array, or an integer array whose values
    are 0 and at most one other value (0/1, 0/255 as 1-bit and 8-bit mask
    PNGs and TIFFs store them). The nonzero value is the foreground."""
    a = np.asarray(data)
    if a.dtype == bool:
        return True
    if a.dtype.kind not in "iu" or a.size == 0:
        return False
    values = np.unique(a)
    return values.size <= 2 and values[0] == 0


def _ext(path) -> str:
    return os.path.splitext(os.fspath(path))[1].lower()


def _rasterio():
    try:
        import rasterio
    except ImportError:
        return None
    return rasterio


def _unreadable(p, exc) -> OSError:
    cause = str(exc) or type(exc).__name__
    return OSError(f"path: cannot read {p!r}: {cause}")


def read_raster(path, band: Optional[int] = None) -> Tuple[np.ndarray, Optional[dict]]:
    """Read one band of a raster file.

    Parameters
    ----------
    path : str or os.PathLike
        ``.npy``, ``.png``, ``.exr``, ``.tif``/``.tiff`` or, with rasterio
        installed, any format GDAL reads (e.g. SRTM ``.hgt``).
    band : int or None
        1-based band (channel) number; a 2D ``.npy`` has the single band 1, a
        3D one is ``(bands, rows, cols)`` like rasterio. ``None`` (default):
        the only band; a file with several bands (an RGB or RGBA PNG, a
        multi-band GeoTIFF) raises ``ValueError`` asking for ``band=`` (no
        channel is picked silently; for a grey level of a colour image use
        e.g. the luminance ``0.299 R + 0.587 G + 0.114 B`` of the three bands).

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
    if band is not None and (isinstance(band, bool) or not isinstance(band, (int, np.integer)) or band < 1):
        raise ValueError(f"band: expected a 1-based band number or None, got {band!r}")
    if not os.path.exists(p):
        raise FileNotFoundError(f"path: no such file: {p!r}")
    if os.path.isdir(p):
        raise IsADirectoryError(f"path: {p!r} is a directory, not a raster file")
    ext = _ext(p)

    def pick(n_bands):
        if band is None:
            if n_bands > 1:
                raise ValueError(f"band: {p!r} has {n_bands} bands (e.g. a colour image); pass band=1..{n_bands} "
                                 f"(CLI: --band), or convert it to one grey band first")
            return 1
        if band > n_bands:
            raise ValueError(f"band: {p!r} has {n_bands} band{'s' if n_bands > 1 else ''}, asked for {band}")
        return band

    if ext == ".npy":
        try:
            a = np.load(p, allow_pickle=False)
        except ValueError as exc:
            if "allow_pickle" in str(exc):
                raise OSError(f"path: {p!r} is not a numeric .npy array (it holds Python objects, which are "
                              f"never unpickled)") from None
            raise _unreadable(p, exc) from None
        except (Exception, MemoryError) as exc:  # numpy's header parser raises many kinds
            raise _unreadable(p, exc) from None
        if not isinstance(a, np.ndarray) or a.dtype.kind not in "biuf":
            raise OSError(f"path: {p!r} does not hold a real numeric array")
        if a.ndim == 2:
            pick(1)
            return a, None
        if a.ndim == 3:
            return np.ascontiguousarray(a[pick(a.shape[0]) - 1]), None
        raise OSError(f"path: {p!r} holds a {a.ndim}D array, expected 2D or 3D")
    if ext == ".exr":
        if band not in (None, 1):
            raise ValueError(f"band: EXR files are read as one band (channel \"Y\"), asked for {band}")
        try:
            return _core.read_exr(p), None
        except (OSError, ValueError, RuntimeError, MemoryError) as exc:
            raise _unreadable(p, exc) from None
    rio = _rasterio()
    if ext == ".png" or (rio is None and ext in (".tif", ".tiff")):
        try:
            img = _core.read_image(p)
        except (OSError, ValueError, RuntimeError, MemoryError) as exc:
            raise _unreadable(p, exc) from None
        return np.ascontiguousarray(img[:, :, pick(img.shape[2]) - 1]), None
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
        b = pick(src.count)
        try:
            a = src.read(b)
        except rio.errors.RasterioError as exc:
            cause = str(exc)
            if exc.__cause__ is not None or exc.__context__ is not None:
                cause = f"{cause}: {exc.__cause__ or exc.__context__}"
            raise OSError(f"path: cannot read band {b} of {p!r} (truncated or corrupt file?): {cause}") from None
        if a.dtype.kind == "c":
            raise OSError(f"path: {p!r} band {b} is complex ({a.dtype}); read it with rasterio and pass a real "
                          f"array (np.abs or .real)")
        return a, dict(src.profile)


def _world_file_lines(t) -> str:
    """ESRI world file of an affine transform (pixel size and the centre of
    the upper-left pixel)."""
    a, b, c, d, e, f = (float(v) for v in tuple(t)[:6])
    vals = (a, d, b, e, c + a / 2 + b / 2, f + d / 2 + e / 2)
    return "".join(f"{v!r}\n" for v in vals)


def _write_sidecar(path, text) -> None:
    with atomic_write_path(path) as tmp:
        with open(tmp, "w") as fh:
            fh.write(text)


def write_raster(path, data, *, profile: Optional[dict] = None, crs=None, transform=None, nodata=None,
                 tags: Optional[dict] = None) -> None:
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
        Override the profile's (``transform`` an ``Affine`` or a 6-tuple in
        its order). GeoTIFF stores all three; PNG stores the transform in a
        world file beside it (``name.pgw``) and the CRS as WKT in
        ``name.prj`` (PNG has no nodata field: 0 is nodata by convention of
        the hillshade bytes). ``.npy`` and ``.exr`` cannot hold
        georeferencing: a ``ValueError`` says so.
    tags : dict or None
        GeoTIFF only: metadata tags (e.g. ``{"CELL_SIZE": "30", "UNITS": "m"}``).

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
    if data is None or isinstance(data, (str, bytes)):
        raise TypeError(f"data: expected an array, got {type(data).__name__}")
    a = np.asarray(data)  # values written as they are (±inf too)
    if a.dtype == object:
        raise TypeError("data: expected a numeric array, got dtype object")
    if a.dtype.kind == "c":
        raise TypeError(f"data: complex data ({a.dtype}) is not written; write np.abs(data) or data.real")
    p = os.fspath(path)
    if os.path.isdir(p):
        raise IsADirectoryError(f"path: {p!r} is a directory; give a file name such as {os.path.join(p, 'out.tif')!r}")
    ext = _ext(p)
    geo = profile is not None or crs is not None or transform is not None or nodata is not None
    if a.ndim != 2 and not (ext == ".npy" and not geo):
        raise ValueError(f"data: expected a 2D array, got shape {a.shape}")
    if tags and ext not in (".tif", ".tiff"):
        raise ValueError(f"tags: metadata tags can only be written to GeoTIFF (.tif), not {ext!r}")
    if geo and ext not in (".tif", ".tiff", ".png"):
        raise ValueError(f"profile: georeferencing can be written to GeoTIFF (.tif) or PNG (world file), "
                         f"not {ext!r}")
    if ext == ".npy":
        with atomic_write_path(p) as tmp:
            np.save(tmp, a, allow_pickle=False)
        return
    if ext == ".png":
        if a.dtype not in (np.uint8, np.uint16):
            raise TypeError(f"data: PNG holds uint8 or uint16, got {a.dtype} (convert it explicitly)")
        t = transform if transform is not None else (profile or {}).get("transform")
        c = crs if crs is not None else (profile or {}).get("crs")
        stem = os.path.splitext(p)[0]
        _core.write_png(p, np.ascontiguousarray(a))
        if t is not None:
            _write_sidecar(stem + ".pgw", _world_file_lines(t))
        if c is not None:
            wkt = c.to_wkt() if hasattr(c, "to_wkt") else None
            if wkt is None:
                rio = _rasterio()
                if rio is None:
                    raise OSError("crs: writing a CRS needs rasterio (pip install 'fractalgeo_rs[geo]')")
                wkt = rio.crs.CRS.from_user_input(c).to_wkt()
            _write_sidecar(stem + ".prj", wkt)
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
        prof: Dict[str, Any] = {"driver": "GTiff"}
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
                if tags:
                    dst.update_tags(**{str(k): str(v) for k, v in tags.items()})
        return
    raise ValueError(f"path: unknown raster extension {ext or '(none)'!r} in {p!r} (use .npy, .png, .exr, .tif)")
