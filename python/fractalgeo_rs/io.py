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
empty file never surfaces as a decoder's internal exception. The size of
the array is estimated from the file's header (``.npy``, ``.png``,
``.exr``, TIFF read without rasterio, rasterio formats) before anything is
read: above the memory limit of
``_validation.check_memory`` (``$FRACTALGEO_MAX_MEMORY``, default half the
available memory) the reader raises :class:`RasterMemoryError`, an
``OSError`` and a ``MemoryError``.
"""
from __future__ import annotations

import os
import warnings
from typing import Any, Dict, Optional, Tuple

import numpy as np

from fractalgeo_rs import _core
from fractalgeo_rs._validation import MemoryLimitError, atomic_write_path, check_memory

__all__ = ["read_raster", "write_raster", "is_binary_mask", "RasterMemoryError"]


class RasterMemoryError(OSError, MemoryError):
    """A raster whose header announces more data than the memory limit
    allows (nothing was read).

    Raised by :func:`~fractalgeo_rs.read_raster` before it reads: the
    array's size is computed from the file's header (``.npy``, PNG, or the
    rasterio profile) and compared with the memory limit of
    ``docs/input_policy.md``. It is both an :class:`OSError` (the file
    cannot be read as asked) and a :class:`MemoryError`, so either
    ``except`` clause catches it.

    Parameters
    ----------
    message : str
        Names the path, the estimated bytes and the limit.

    References
    ----------
    NumPy Enhancement Proposal 1, *A simple file format for NumPy arrays*
    (the ``.npy`` header read for the estimate),
    https://numpy.org/neps/nep-0001-npy-format.html.

    Examples
    --------
    >>> import os, tempfile, numpy as np
    >>> from fractalgeo_rs.io import RasterMemoryError, read_raster
    >>> old = os.environ.get("FRACTALGEO_MAX_MEMORY")
    >>> os.environ["FRACTALGEO_MAX_MEMORY"] = "100000"  # a 100 kB limit
    >>> with tempfile.TemporaryDirectory() as d:
    ...     path = os.path.join(d, "big.npy")
    ...     np.save(path, np.zeros((256, 256)))  # 512 KiB of float64
    ...     try:
    ...         read_raster(path)
    ...     except RasterMemoryError as e:
    ...         print(isinstance(e, OSError), isinstance(e, MemoryError))
    True True
    >>> _ = os.environ.pop("FRACTALGEO_MAX_MEMORY") if old is None else os.environ.update(FRACTALGEO_MAX_MEMORY=old)
    """


def _check_raster_bytes(p, n_bytes, what: str) -> None:
    """:class:`RasterMemoryError` naming the path when reading ``n_bytes``
    would exceed the memory limit."""
    try:
        check_memory(n_bytes, "path", what=what)
    except MemoryLimitError as exc:
        raise RasterMemoryError(f"path: {p!r} holds {what}: {str(exc)[len('path: '):]}") from None


def _npy_header(p):
    """``(shape, dtype)`` from a ``.npy`` header, or None when it cannot be
    parsed (``numpy.load`` then reports the problem)."""
    fmt = np.lib.format
    try:
        with open(p, "rb") as fh:
            version = fmt.read_magic(fh)
            read = {(1, 0): fmt.read_array_header_1_0, (2, 0): fmt.read_array_header_2_0}.get(version)
            if read is None:
                return None
            shape, _, dtype = read(fh)
    except Exception:  # numpy's header parser raises many kinds
        return None
    return tuple(int(n) for n in shape), np.dtype(dtype)


#: PNG colour type -> channels as decoded (palette images expand to RGBA at most)
_PNG_CHANNELS = {0: 1, 2: 3, 3: 4, 4: 2, 6: 4}


def _png_header(p):
    """``(width, height, channels, bytes per sample)`` from the PNG's IHDR
    chunk, or None when the file does not start like a PNG."""
    try:
        with open(p, "rb") as fh:
            head = fh.read(26)
    except OSError:
        return None
    if len(head) < 26 or head[:8] != b"\x89PNG\r\n\x1a\n" or head[12:16] != b"IHDR":
        return None
    width, height = int.from_bytes(head[16:20], "big"), int.from_bytes(head[20:24], "big")
    return width, height, _PNG_CHANNELS.get(head[25], 4), 2 if head[24] == 16 else 1


def is_binary_mask(data) -> bool:
    """Whether an array is a binary mask.

    True for a bool array, or an integer array whose values are 0 and at
    most one other value (0/1 or 0/255, as 1-bit and 8-bit mask PNGs and
    TIFFs store them); the nonzero value is the foreground. Float arrays are
    never masks (a 0/1 float image is a grey-level image). The ``fractalgeo
    dimension`` command uses it to choose between box counting of a set and
    of a surface.

    Parameters
    ----------
    data : array_like
        Any array, e.g. the output of :func:`fractalgeo_rs.read_raster`.

    Returns
    -------
    bool
        True for a binary mask; False for an empty array.

    References
    ----------
    W3C (2003). *Portable Network Graphics (PNG) Specification (Second
    Edition)*, section 6 (bit depths 1-16 of greyscale images),
    https://www.w3.org/TR/png/.
    Adobe (1992). *TIFF Revision 6.0*, section 3 (bilevel images).

    Examples
    --------
    >>> import numpy as np
    >>> from fractalgeo_rs.io import is_binary_mask
    >>> is_binary_mask(np.array([[0, 255], [255, 0]], np.uint8)), is_binary_mask(np.zeros((2, 2), bool))
    (True, True)
    >>> is_binary_mask(np.array([[0, 1, 2]], np.uint8)), is_binary_mask(np.array([[3, 5]], np.uint8))
    (False, False)
    >>> is_binary_mask(np.array([[0.0, 1.0]]))
    False
    """
    a = np.asarray(data)
    if a.dtype == bool:
        return True
    if a.dtype.kind not in "iu" or a.size == 0:
        return False
    values = np.unique(a)
    return bool(values.size <= 2 and values[0] == 0)


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
    GDAL/OGR contributors, doi:10.5281/zenodo.5884351; full entry in the
    :ref:`bibliography <ref-gdal>`.

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
        head = _npy_header(p)
        if head is not None:
            shape, dtype = head
            n = 1
            for k in shape:
                n *= k
            _check_raster_bytes(p, n * dtype.itemsize, f"a {' x '.join(map(str, shape)) or 'scalar'} {dtype} array")
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
            rows, cols, ch = _core.exr_header(p)
        except (OSError, ValueError, RuntimeError, MemoryError) as exc:
            raise _unreadable(p, exc) from None
        # every channel decoded as float32, then the float32 band
        _check_raster_bytes(p, 4 * rows * cols * (ch + 1), f"a {rows} x {cols} EXR image of {ch} channel(s)")
        try:
            return _core.read_exr(p), None
        except (OSError, ValueError, RuntimeError, MemoryError) as exc:
            raise _unreadable(p, exc) from None
    rio = _rasterio()
    if ext == ".png" or (rio is None and ext in (".tif", ".tiff")):
        head = _png_header(p) if ext == ".png" else None
        if head is None and ext != ".png":
            try:
                h, w, ch, bpp = _core.image_header(p)
            except (OSError, ValueError, RuntimeError, MemoryError) as exc:
                raise _unreadable(p, exc) from None
            head = w, h, ch, bpp // max(ch, 1)
        if head is not None:
            w, h, ch, bps = head
            # the decoded buffer and the array made of it
            _check_raster_bytes(p, 2 * w * h * ch * bps, f"a {h} x {w} image of {ch} channel(s)")
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
        with warnings.catch_warnings():
            # a TIFF without georeferencing is read as such (profile transform = identity, crs None)
            warnings.simplefilter("ignore", rio.errors.NotGeoreferencedWarning)
            src = rio.open(p)
    except rio.errors.RasterioIOError as exc:
        raise OSError(f"path: unsupported or unreadable raster {p!r}: {exc}") from None
    with src:
        b = pick(src.count)
        try:
            itemsize = np.dtype(src.dtypes[b - 1]).itemsize
        except TypeError:  # GDAL types numpy has no name for (complex_int16)
            itemsize = 8
        _check_raster_bytes(p, src.width * src.height * itemsize,
                            f"a {src.height} x {src.width} {src.dtypes[b - 1]} band")
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
    GDAL/OGR contributors, doi:10.5281/zenodo.5884351; full entry in the
    :ref:`bibliography <ref-gdal>`.

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
        with atomic_write_path(p) as tmp, warnings.catch_warnings():
            # an array without georeferencing is written without it (not a fault)
            warnings.simplefilter("ignore", rio.errors.NotGeoreferencedWarning)
            with rio.open(tmp, "w", **prof) as dst:
                dst.write(a, 1)
                if tags:
                    dst.update_tags(**{str(k): str(v) for k, v in tags.items()})
        return
    raise ValueError(f"path: unknown raster extension {ext or '(none)'!r} in {p!r} (use .npy, .png, .exr, .tif)")
