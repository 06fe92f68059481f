"""Shaded relief."""
from __future__ import annotations

import numbers

import numpy as np

from fractalgeo_rs import _core
from fractalgeo_rs._backend import array_kind, run_raster
from fractalgeo_rs._validation import (
    as_array,
    check_n_threads,
    check_nodata,
    check_real_array,
    check_z_factor,
    warn_void_sentinel,
)

from fractalgeo_rs._geodesy import metres_per_degree

__all__ = ["hillshade", "shade_to_byte", "metres_per_degree"]


def _pair(cell_size):
    if isinstance(cell_size, numbers.Real) and not isinstance(cell_size, bool):
        dy = dx = float(cell_size)
    else:
        try:
            dy, dx = (float(v) for v in cell_size)
        except (TypeError, ValueError):
            raise TypeError(f"cell_size: expected a number or a pair (row spacing, column spacing), "
                            f"got {cell_size!r}") from None
    if not (np.isfinite(dy) and np.isfinite(dx) and dy > 0 and dx > 0):
        raise ValueError(f"cell_size: expected positive finite spacings, got {cell_size!r}")
    return dy, dx


def hillshade(dem, *, azimuth=315.0, altitude=45.0, cell_size=1.0, z_factor=1.0, nodata=None,
              multidirectional=False, latitude=None, byte=False, n_threads=None):
    r"""Lambertian shaded relief with Horn's gradients (GDAL's conventions).

    For the 3 x 3 window ``a b c / d e f / g h i`` (row 0 to the north)

    .. math::

        \partial z/\partial x = \frac{(c + 2f + i) - (a + 2d + g)}{8\,\Delta x},\quad
        \partial z/\partial y = \frac{(a + 2b + c) - (g + 2h + i)}{8\,\Delta y}

    (Horn 1981) and the reflectance of a surface lit from azimuth ``A``
    (clockwise from north) at altitude ``E``:

    .. math::

        L = \max\left(0, \frac{\sin E - \cos E\,\zeta(\sin A\,\partial_x z
            + \cos A\,\partial_y z)}{\sqrt{1 + \zeta^2 |\nabla z|^2}}\right)

    with ``zeta = z_factor``. ``gdaldem hillshade`` writes ``1 + 254 L``
    (see :func:`~fractalgeo_rs.dem.shade_to_byte`). The default azimuth 315 (light from the
    north-west) keeps relief from looking inverted; the seed paper's figure 4
    is lit from the south-east: ``azimuth=135``. ``multidirectional`` is
    GDAL's combination of azimuths 225, 270, 315 and 360 weighted by
    ``sin^2(aspect - azimuth)`` (Mark 1992).

    Edges follow ``gdaldem hillshade -compute_edges``: a neighbour outside
    the grid is extrapolated linearly from the two cells inward (``2a - b``;
    in the first and last rows the columns beyond the corners repeat the
    centre column), a nodata neighbour or an extrapolation from one takes
    the centre value, a nodata cell gives NaN. With ``byte=True`` (and no
    ``latitude``) the bytes are those of ``gdaldem hillshade -compute_edges``
    on the float32 DEM, bit for bit (float32 window sums and GDAL's
    reciprocal square root; tests/test_dem_hillshade.py compares every
    pixel with the ``gdaldem`` binary).

    Parameters
    ----------
    dem : array_like, dask.array.Array or xarray.DataArray, shape (rows, cols)
        Heights, row 0 to the north. Not modified. A Dask array is shaded
        lazily block by block with a one-cell halo of real neighbours (the
        edge rule applies to the raster's true edges only, so the result is
        the same for any chunking); a DataArray keeps its coords and attrs.
    azimuth, altitude : float
        Light direction in degrees; ``0 <= altitude <= 90``.
    cell_size : float or (float, float)
        Cell size, or ``(row spacing, column spacing)``, in the height units
        (metres for a DEM in metres), or in degrees when ``latitude`` is given.
    z_factor : float
        Vertical exaggeration (and height-unit conversion), ``> 0`` (a
        negative factor would invert the relief).
    nodata : float or None
        Height value meaning "no data" (NaN is always nodata).
    multidirectional : bool
        GDAL's multidirectional shading (``azimuth`` is then ignored).
    latitude : float, array_like of shape (rows,), or None
        For geographic grids: latitude in degrees of the grid (scalar) or of
        each row's centre. ``cell_size`` is then in degrees and converted to
        metres per row with :func:`~fractalgeo_rs.dem.metres_per_degree` (WGS84).
    byte : bool
        Return GDAL's 8-bit encoding instead: ``1 + 254 L``, 0 at nodata,
        computed as ``gdaldem hillshade -compute_edges`` does (float32 heights);
        with ``latitude`` it is :func:`~fractalgeo_rs.dem.shade_to_byte` of the reflectance.
    n_threads : int or None
        Threads of the Rust kernel.

    Returns
    -------
    numpy.ndarray (or the input's array type)
        float32 reflectance in [0, 1], NaN at nodata; with ``byte=True``
        uint8, ``1 + 254 L`` rounded, 0 at nodata.

    References
    ----------
    Horn, B. K. P. (1981). Hill shading and the reflectance map. Proc. IEEE 69(1), 14-47,
    doi:10.1109/PROC.1981.11918.
    Mark, R. K. (1992). Multidirectional, oblique-weighted, shaded-relief image of
    the Island of Hawaii. USGS Open-File Report 92-422.

    Examples
    --------
    >>> import numpy as np, fractalgeo_rs as fg
    >>> s = fg.hillshade(np.zeros((3, 4)))
    >>> round(float(s[1, 1]), 4)  # flat ground: sin(45 deg)
    0.7071
    """
    kind = array_kind(dem)
    data = dem.data if kind == "xarray" else dem
    lazy = array_kind(data) == "dask"
    z = data if lazy else check_real_array(data, "dem")
    if z.ndim != 2 or min(z.shape) < 1:
        raise ValueError(f"dem: expected a non-empty 2D array, got shape {z.shape}")
    if z.dtype.kind not in "iuf":
        if z.dtype.kind == "c":
            raise TypeError(f"dem: complex data is not accepted (dtype {z.dtype}); pass a real array")
        raise TypeError(f"dem: expected a numeric array, got dtype {z.dtype}")
    nodata = check_nodata(nodata)
    if not lazy:
        warn_void_sentinel(z, "dem", nodata)
    for name, v in (("azimuth", azimuth), ("altitude", altitude)):
        if isinstance(v, bool) or not isinstance(v, numbers.Real) or not np.isfinite(v):
            raise ValueError(f"{name}: expected a finite number, got {v!r}")
    z_factor = check_z_factor(z_factor)
    if not 0 <= altitude <= 90:
        raise ValueError(f"altitude: expected degrees in [0, 90], got {altitude}")
    dy, dx = _pair(cell_size)
    rows = z.shape[0]
    if latitude is None:
        dx_rows = np.full(rows, dx)
    else:
        try:
            lat = np.asarray(latitude, dtype=np.float64)
        except (TypeError, ValueError):
            raise TypeError(f"latitude: expected degrees, a number or one per row, got {latitude!r}") from None
        if lat.ndim == 0:
            lat = np.full(rows, float(lat))
        if lat.shape != (rows,) or not np.all(np.abs(lat) < 90):
            raise ValueError(f"latitude: expected degrees in (-90, 90), a scalar or one per row ({rows})")
        m_lat, m_lon = metres_per_degree(lat)
        dx_rows = dx * m_lon
        dy = dy * float(np.mean(m_lat))
    n_threads = check_n_threads(n_threads)
    gdal_bytes = byte and latitude is None
    # gdaldem's bytes are computed on float32 heights: that path converts
    # once to float32 (no copy of a C-ordered float32 DEM), the reflectance
    # path to float64; with a nodata value the conversion is a copy and the
    # caller's array is never touched.
    work = np.float32 if gdal_bytes else np.float64

    def prepare(block):
        if lazy:  # a Dask block: the package's ±inf rule, block by block
            block = check_real_array(block, "dem")
        if nodata is None:
            return np.ascontiguousarray(block, dtype=work)  # the kernel only reads it
        mask = block == np.float64(nodata)  # compared in float64, whatever the dtype
        out = np.array(block, dtype=work)
        out[mask] = np.nan
        return out

    def kernel(block, origin):
        if gdal_bytes:
            res = _core.hillshade_gdal_byte(block, float(dx), float(dy), float(azimuth), float(altitude),
                                            float(z_factor), bool(multidirectional), n_threads)
        else:
            r0 = origin[0]
            res = _core.hillshade_f64(block, dx_rows[r0:r0 + block.shape[0]].tolist(), float(dy),
                                      float(azimuth), float(altitude), float(z_factor),
                                      bool(multidirectional), n_threads)
            if byte:
                res = _core.shade_to_byte(res, n_threads)
        return res[None]

    if kind == "xarray" and not lazy:
        image = dem.copy(data=z)
    else:
        image = dem if kind == "xarray" else z
    # GDAL's edge rule on the raster's true edges only: Dask chunk borders
    # read their real neighbours (boundary "none")
    return run_raster(kernel, image, depth=1, n_out=1, dtype=np.uint8 if byte else np.float32,
                      prepare=prepare, boundary="none", locate=True,
                      attrs={"long_name": "hillshade"} if kind == "xarray" else None)[0]


def shade_to_byte(shade):
    """GDAL's 8-bit encoding of a shaded-relief reflectance.

    ``round(1 + 254 L)`` for a reflectance ``L`` in [0, 1] (halves rounded
    away from zero, as GDAL's float-to-byte copy), so that 0 stays free for
    nodata: a NaN reflectance becomes 0. This is the encoding ``gdaldem
    hillshade`` writes, and the output of :func:`fractalgeo_rs.hillshade`
    with ``byte=True``.

    Parameters
    ----------
    shade : array_like, shape (rows, cols)
        Reflectance in [0, 1] (dimensionless), NaN at nodata, e.g. the output
        of :func:`fractalgeo_rs.hillshade`. Read as float32. Not modified.

    Returns
    -------
    ndarray of uint8, shape (rows, cols)
        1 (black) to 255 (fully lit), 0 at nodata.

    References
    ----------
    GDAL documentation, *gdaldem*, section "hillshade":
    https://gdal.org/programs/gdaldem.html.
    Horn, B. K. P. (1981). Hill shading and the reflectance map. *Proc.
    IEEE* 69(1), 14-47, doi:10.1109/PROC.1981.11918.

    Examples
    --------
    >>> import numpy as np, fractalgeo_rs as fg
    >>> fg.dem.shade_to_byte(np.array([[0.0, 0.5, 1.0], [np.nan, 0.7071, 0.002]]))
    array([[  1, 128, 255],
           [  0, 181,   2]], dtype=uint8)
    """
    s = as_array(shade, "shade")
    if s.ndim != 2:
        raise ValueError(f"shade: expected a 2D array, got shape {s.shape}")
    return _core.shade_to_byte(np.asarray(s, dtype=np.float32))
