"""Synthetic SAR scenes from DEMs: geometry and projection in Rust
(``_core.radar_geometry``, ``_core.radar_project``, ``_core.speckle_f64``),
sigma0 from a table of :func:`~fractalgeo_rs.radar.backscatter` over the local incidence."""
from __future__ import annotations

import math
import numbers
import warnings
from dataclasses import dataclass
from typing import Any

import numpy as np

from fractalgeo_rs import _core, _progress
from fractalgeo_rs._backend import array_kind
from fractalgeo_rs._validation import check_n_threads, check_real_array, warn_void_sentinel
from fractalgeo_rs._warn import user_stacklevel
from fractalgeo_rs.radar._backscatter import MODELS, RadarValidityWarning, check_positive, backscatter, validity
from fractalgeo_rs.radar._speckle import check_looks
from fractalgeo_rs._validation import check_seed as resolve_seed

__all__ = ["SARScene", "simulate"]

# rotations of the DEM into the range frame (columns = ground range away
# from the radar) per look azimuth, and back
_TO_RANGE = {
    90: lambda a: a,
    270: lambda a: a[:, ::-1],
    180: lambda a: a.T,
    0: lambda a: a[::-1, :].T,
}
_FROM_RANGE = {
    90: lambda a: a,
    270: lambda a: a[:, ::-1],
    180: lambda a: a.T,
    0: lambda a: a.T[::-1, :],
}


_DASK_ROTATED = (
    "look_azimuth: with a Dask DEM, expected a multiple of 90 degrees (range lines along the grid's rows "
    "or columns, so that strips of whole range lines are exact), got {!r}. Other azimuths resample the "
    "whole scene onto a rotated grid: pass a numpy array (dem.compute()), or rotate the DEM yourself.")


@dataclass(frozen=True)
class SARScene:
    """A simulated SAR scene (the output of :func:`~fractalgeo_rs.radar.simulate`).

    Attributes
    ----------
    image : ndarray or xarray.DataArray
        Intensity (linear sigma0 with speckle when ``looks`` is given),
        on the DEM's grid (``ground_range=True``) or in slant range.
    sigma0 : ndarray or xarray.DataArray
        The same without speckle.
    layover, shadow : ndarray of bool
        Masks on the grid of ``image``.
    local_incidence : ndarray
        Local incidence angle per DEM cell, degrees (> 90 facing away).
    slant_range_spacing : float
        Bin size of the slant-range axis, ``dx sin(theta)`` metres.
    geometry : str
        ``"ground"`` or ``"slant"``.

    References
    ----------
    Curlander, J. C. & McDonough, R. N. (1991). *Synthetic Aperture Radar:
    Systems and Signal Processing*, ch. 8. Wiley.

    Examples
    --------
    >>> import numpy as np, fractalgeo_rs as fg
    >>> s = fg.radar.simulate(np.zeros((8, 8)), 10.0, look_azimuth=90, incidence=35, wavelength=0.056, seed=1)
    >>> s.geometry, s.image.shape, round(s.slant_range_spacing, 3)
    ('ground', (8, 8), 5.736)
    """

    image: Any
    sigma0: Any
    layover: np.ndarray
    shadow: np.ndarray
    local_incidence: np.ndarray
    slant_range_spacing: float
    geometry: str


def _cell_pair(cell_size, dem):
    if cell_size is None:
        if array_kind(dem) == "xarray":
            from fractalgeo_rs._geodesy import is_geographic_xarray

            if is_geographic_xarray(dem):
                raise ValueError("cell_size: the DataArray's coordinates are in degrees; pass cell_size in "
                                 "metres, (row spacing, column spacing) (e.g. from "
                                 "fractalgeo_rs.dem.metres_per_degree)")
            steps = []
            for dim in dem.dims[-2:]:
                try:
                    c = np.asarray(dem[dim].values, dtype=float)
                except (KeyError, TypeError, ValueError):
                    c = np.empty(0)
                steps.append(abs(float(c[1] - c[0])) if c.size >= 2 else None)
            if None not in steps and all(s > 0 for s in steps):
                return steps[0], steps[1]
        raise ValueError("cell_size: the DEM carries no cell size; pass cell_size= in the units of the heights "
                         "(metres), or a DataArray with x/y coords")
    if isinstance(cell_size, numbers.Real) and not isinstance(cell_size, bool):
        v = check_positive(cell_size, "cell_size")
        return v, v
    try:
        dy, dx = (float(v) for v in cell_size)
    except (TypeError, ValueError):
        raise TypeError(f"cell_size: expected a number or (row spacing, column spacing), got {cell_size!r}") from None
    return check_positive(dy, "cell_size"), check_positive(dx, "cell_size")


def _look(look_azimuth):
    """The look azimuth in [0, 360) and, when it is a multiple of 90 degrees, that multiple (range lines
    follow the grid) else None (the DEM is resampled onto a grid rotated to the look direction)."""
    if isinstance(look_azimuth, bool) or not isinstance(look_azimuth, numbers.Real):
        raise TypeError(f"look_azimuth: expected degrees clockwise from north, got {look_azimuth!r}")
    a = float(look_azimuth)
    if not math.isfinite(a):
        raise ValueError(f"look_azimuth: expected finite degrees, got {look_azimuth!r}")
    a %= 360.0
    key = int(round(a))
    if key % 90 == 0 and abs(a - key) <= 1e-9:
        return a, key % 360
    return a, None


def _multilook(multilook):
    if multilook is None:
        return None
    if isinstance(multilook, numbers.Integral) and not isinstance(multilook, bool):
        pair = (int(multilook), int(multilook))
    else:
        try:
            pair = tuple(int(v) if isinstance(v, numbers.Integral) and not isinstance(v, bool) else None
                         for v in multilook)
        except TypeError:
            raise TypeError(f"multilook: expected an int or (azimuth, range) ints, got {multilook!r}") from None
        if len(pair) != 2 or None in pair:
            raise TypeError(f"multilook: expected an int or (azimuth, range) ints, got {multilook!r}")
    if min(pair) < 1:
        raise ValueError(f"multilook: expected block sizes >= 1, got {multilook!r}")
    return None if pair == (1, 1) else pair


def _block_sums(a, az, rg):
    """Sums and counts of the finite values of ``a`` over (az, rg) blocks from (0, 0); the last blocks
    are partial (padded with NaN)."""
    r, c = a.shape
    pr, pc = -r % az, -c % rg
    b = np.pad(a, ((0, pr), (0, pc)), constant_values=np.nan).reshape((r + pr) // az, az, (c + pc) // rg, rg)
    fin = np.isfinite(b)
    return np.where(fin, b, 0.0).sum(axis=(1, 3)), fin.sum(axis=(1, 3))


def _block_mean(a, az, rg):
    s, n = _block_sums(a, az, rg)
    return np.divide(s, n, out=np.full(s.shape, np.nan), where=n > 0)


def _rotated_grid(shape, dy, dx, azimuth):
    """The grid rotated so that its columns step along the look direction (ground range away from the
    radar) and its rows along the azimuth, spacing ``h = min(dy, dx)``, covering the DEM padded by 2
    cells. Returns ``(u, v, g0, a0, h, n_az, n_rg)``: unit vectors (east, north) of range and azimuth and
    the grid's origin in those coordinates."""
    rows, cols = shape
    t = math.radians(azimuth)
    u = (math.sin(t), math.cos(t))            # look direction
    v = (math.cos(t), -math.sin(t))           # u turned 90 degrees clockwise
    h = min(dy, dx)
    east = np.array([-2.0, cols + 1.0]) * dx  # DEM cell (i, j) at east = j dx, north = -i dy
    north = -np.array([-2.0, rows + 1.0]) * dy
    e, n = np.meshgrid(east, north)
    g = e * u[0] + n * u[1]
    a = e * v[0] + n * v[1]
    g0, a0 = float(g.min()), float(a.min())
    n_rg = int(math.floor((g.max() - g0) / h + 1e-9)) + 1
    n_az = int(math.floor((a.max() - a0) / h + 1e-9)) + 1
    return u, v, g0, a0, h, n_az, n_rg


def _to_rotated(z, dy, dx, frame):
    """Bilinear resampling of the DEM (edge-padded by 2 cells, NaN beyond) onto the rotated grid (exact
    for a plane)."""
    from scipy import ndimage

    u, v, g0, a0, h, n_az, n_rg = frame
    gg = g0 + h * np.arange(n_rg)
    aa = a0 + h * np.arange(n_az)
    coords = np.empty((2, n_az, n_rg))
    # DEM (fractional) row -north / dy and column east / dx, + 2 for the padding
    np.add((-v[1] / dy) * aa[:, None], (-u[1] / dy) * gg[None, :] + 2.0, out=coords[0])
    np.add((v[0] / dx) * aa[:, None], (u[0] / dx) * gg[None, :] + 2.0, out=coords[1])
    zp = np.pad(np.asarray(z, dtype=np.float64), 2, mode="edge")
    return ndimage.map_coordinates(zp, coords, order=1, mode="constant", cval=np.nan, prefilter=False)


def _from_rotated(shape, dy, dx, frame):
    """Flat index ``m * n_rg + k`` of the rotated-grid cell nearest to each DEM cell."""
    u, v, g0, a0, h, n_az, n_rg = frame
    i, j = np.arange(shape[0]), np.arange(shape[1])
    out = np.empty(shape, dtype=np.intp)
    idx = np.empty(shape)
    for unit, origin, n, scale in ((v, a0, n_az, n_rg), (u, g0, n_rg, 1)):
        # (east u0 + north u1 - origin) / h with east = j dx, north = -i dy
        np.add(((-i * dy * unit[1] - origin) / h)[:, None], (j * dx * unit[0] / h)[None, :], out=idx)
        np.rint(idx, out=idx)
        np.clip(idx, 0, n - 1, out=idx)
        if scale == 1:
            out += idx.astype(np.intp)
        else:
            np.multiply(idx.astype(np.intp), scale, out=out)
    return out


def simulate(dem, cell_size=None, *, look_azimuth, incidence, wavelength, model="kirchhoff",
             permittivity=5 + 0.5j, rms_height=None, correlation_length=None, correlation="exponential",
             hurst=None, topothesy=None, polarization="vv", looks=1, seed=None, multilook=None, ground_range=True,
             n_threads=None, progress=None):
    r"""Synthetic SAR intensity image of a DEM, with layover, shadow and speckle.

    Side-looking geometry with a distant radar (plane wave, the same
    ``incidence`` everywhere), looking along ``look_azimuth``:

    1. local incidence from facet normals (central differences):
       ``cos theta_loc = (cos theta + sin theta z_r) / sqrt(1 + |grad z|^2)``,
       ``z_r`` the slope along range;
    2. radar shadow: a cell is hidden when a cell nearer the radar rises
       above the ray (a running maximum of ``z + x cot theta`` along each
       range line, exact for the heightfield) or faces away beyond grazing;
    3. sigma0 per facet from :func:`~fractalgeo_rs.radar.backscatter` at the local incidence
       (the microscale roughness given by the keywords), times the facet's
       area over the ground cell's;
    4. slant-range projection: each cell's footprint between the midpoints to
       its neighbours lands on bins of ``dx sin theta`` (``r = x sin theta -
       z cos theta``) with its power split by overlap; a bin covered by more
       than one footprint is layover (slopes facing the radar steeper than
       ``theta``);
    5. speckle on the slant-range image (:func:`~fractalgeo_rs.radar.speckle`, ``looks``-look
       Gamma intensity; ``looks=None`` for none);
    6. optional spatial multilooking (``multilook``, block averages);
    7. ``ground_range=True``: each DEM cell takes the value of the slant bin
       it falls in (terrain-geocoded, so cells in layover share the summed
       power of their bin); else the slant-range image itself.

    Flat ground gives ``sigma0(incidence)`` exactly.

    Parameters
    ----------
    dem : array_like, dask.array.Array or xarray.DataArray, shape (rows, cols)
        Heights in metres, row 0 to the north. NaN = missing. Not modified.
        A Dask array (or a DataArray of one) gives Dask outputs computed in
        strips of whole range lines (of whole multilook blocks), equal to the
        numpy result bit for bit, in ground or slant range; it needs a
        ``look_azimuth`` that is a multiple of 90 (else a ValueError saying
        why).
    cell_size : float, (float, float) or None
        Cell size (or (row, column) spacing) in metres; ``None`` reads it
        from a DataArray's coords, else a ValueError.
    look_azimuth : float
        Direction the radar looks, degrees clockwise from north (90: the radar
        is west of the scene looking east, range increases with the column).
        0, 90, 180 and 270 trace range lines along the grid; any other azimuth
        resamples the DEM bilinearly (exact for a plane) onto a grid rotated so
        that its columns follow the look direction, spacing ``min(cell_size)``,
        edge-padded by 2 cells, and takes each DEM cell's values back from the
        nearest rotated cell (so speckle stays unsmoothed).
    incidence : float
        Incidence angle at the scene in degrees, in (0, 90).
    wavelength : float
        Metres (C band 0.056).
    model, permittivity, rms_height, correlation_length, correlation, hurst, topothesy, polarization
        The facet backscatter, as in :func:`~fractalgeo_rs.radar.backscatter`;
        ``rms_height`` and ``correlation_length`` default to 0.01 m and
        0.1 m for the Gaussian and exponential correlations, and are not
        used with ``correlation="fbm"`` (``hurst`` and ``topothesy``).
    looks : int or None
        Looks of the speckle (1: single look); ``None``: no speckle.
    seed : int or None
        Speckle seed; ``None`` draws one.
    multilook : int, (int, int) or None
        Spatial multilooking: the speckled slant-range image (and ``sigma0``)
        averaged over blocks of (azimuth lines, slant-range bins) from the
        first line and bin. With uncorrelated speckle a block of ``n`` bins
        has ENL ``looks * n`` (Gamma(``looks n``)). ``ground_range=False``
        returns the block image (``slant_range_spacing`` times the range
        block; layover where any bin of the block is, shadow where every
        covered bin is); ``ground_range=True`` gives each DEM cell its
        block's value.
    ground_range : bool
        Output on the DEM's grid (True) or in slant range (False; rows along
        azimuth in the range frame, columns slant-range bins from near range).
    n_threads : int or None
        Threads of the Rust kernels.
    progress : bool or None
        A progress bar on stderr (needs tqdm; ``None`` and ``False``: none),
        in DEM cells of the range frame: the fused kernel (``ground_range``
        without ``multilook``) ticks once per range line as it finishes it;
        a look azimuth off the grid adds the resampling as one step before,
        and ``multilook`` or ``ground_range=False`` advance the bar per stage
        (geometry, projection, speckle, geocoding). With a Dask DEM, Dask's
        bar over the pass that finds the slant-range extent (the result stays
        lazy: wrap its ``compute`` in ``dask.diagnostics.ProgressBar``). The
        result does not depend on it.

    Returns
    -------
    SARScene
        ``image``, ``sigma0`` (no speckle), ``layover`` and ``shadow`` masks,
        ``local_incidence``; with a DataArray DEM and ``ground_range``, the
        images are DataArrays with its coords and attrs; with a Dask DEM,
        Dask arrays.

    References
    ----------
    Curlander, J. C. & McDonough, R. N. (1991). *Synthetic Aperture Radar:
    Systems and Signal Processing*, ch. 8. Wiley.
    Franceschetti, G., Migliaccio, M., Riccio, D. & Schirinzi, G. (1992).
    SARAS: a synthetic aperture radar (SAR) raw signal simulator. *IEEE
    Trans. Geosci. Remote Sens.* 30(1), 110-123, doi:10.1109/36.124221.
    Goodman, J. W. (1976). Some fundamental properties of speckle. *J. Opt.
    Soc. Am.* 66(11), 1145-1150, doi:10.1364/JOSA.66.001145.

    Examples
    --------
    >>> import numpy as np, fractalgeo_rs as fg
    >>> flat = np.zeros((64, 64))
    >>> s = fg.radar.simulate(flat, 10.0, look_azimuth=90, incidence=35, wavelength=0.056, looks=None)
    >>> ref = fg.radar.backscatter(35.0, wavelength=0.056, permittivity=5 + 0.5j, rms_height=0.01,
    ...                            correlation_length=0.1, correlation="exponential")
    >>> bool(np.allclose(s.image, ref)), bool(s.layover.any()), bool(s.shadow.any())
    (True, False, False)
    """
    kind = array_kind(dem)
    data = dem.data if kind == "xarray" else dem
    lazy = array_kind(data) == "dask"
    z = data if lazy else check_real_array(data, "dem")
    if z.ndim != 2 or min(z.shape) < 2:
        raise ValueError(f"dem: expected a 2D array of at least 2 x 2, got shape {z.shape}")
    if z.dtype.kind not in "iuf":
        raise TypeError(f"dem: expected a numeric array, got dtype {z.dtype}")
    if not lazy:
        warn_void_sentinel(z, "dem", hint="set those cells to NaN or fill them before simulating")
    dy, dx = _cell_pair(cell_size, dem)
    if not (isinstance(correlation, str) and correlation == "fbm"):
        rms_height = 0.01 if rms_height is None else rms_height
        correlation_length = 0.1 if correlation_length is None else correlation_length
    azimuth, look = _look(look_azimuth)
    ml = _multilook(multilook)
    if isinstance(incidence, bool) or not isinstance(incidence, numbers.Real):
        raise TypeError(f"incidence: expected degrees, got {incidence!r}")
    inc = float(incidence)
    if not 0 < inc < 90:
        raise ValueError(f"incidence: expected degrees in (0, 90), got {incidence}")
    if not isinstance(model, str) or model not in MODELS:
        raise ValueError(f"model: expected one of {list(MODELS)}, got {model!r}")
    if looks is not None:
        looks = check_looks(looks)
    seed = resolve_seed(seed)
    n_threads = check_n_threads(n_threads)
    show = _progress.resolve(progress)
    # facet backscatter on a table of local incidence (validates the surface)
    step = 0.1
    table_deg = np.arange(900) * step
    with warnings.catch_warnings():
        # judged below at the scene's incidence, not at the table's 89.9 degrees
        warnings.simplefilter("ignore", RadarValidityWarning)
        table = np.asarray(backscatter(table_deg, model=model, wavelength=wavelength, permittivity=permittivity,
                                       rms_height=rms_height, correlation_length=correlation_length,
                                       correlation=correlation, hurst=hurst, topothesy=topothesy,
                                       polarization=polarization), dtype=np.float64)
    val = validity(wavelength=wavelength, rms_height=rms_height, correlation_length=correlation_length,
                   correlation=correlation, hurst=hurst, topothesy=topothesy, incidence=inc)
    if not val.valid[model]:
        warnings.warn(f"simulate: model={model!r} is outside its range of validity at incidence {inc:g}: "
                      f"{val.ranges[model]}; here k*sigma = {val.k_sigma:.3g}, k*l = {val.k_l:.3g}, "
                      f"rms slope = {val.rms_slope:.3g}", RadarValidityWarning, stacklevel=user_stacklevel())
    if lazy:
        if look is None:
            raise ValueError(_DASK_ROTATED.format(look_azimuth))
        with _progress.dask_bar(show):
            return _simulate_dask(z, dem, kind, dy, dx, look, inc, table, step, looks, seed, ml, ground_range,
                                  n_threads)
    z64 = np.asarray(z, dtype=np.float64)
    frame = None
    fused = ground_range and ml is None
    if look is not None:
        zr_shape = z64.shape if look in (90, 270) else z64.shape[::-1]
    else:
        frame = _rotated_grid(z.shape, dy, dx, azimuth)
        zr_shape = (frame[5], frame[6])
    cells = int(zr_shape[0]) * int(zr_shape[1])
    # the bar: the resampling (rotated looks) as one step, then the range frame's cells (per line from the
    # fused kernel; per stage otherwise: geometry, projection, speckle, geocoding)
    total = (z64.size if frame is not None else 0) + cells * (1 if fused else 4 if ground_range else 3)
    with _progress.Steps(total, "radar.simulate", show) as steps:
        return _simulate_numpy(z64, dem, kind, dy, dx, look, frame, inc, table, step, looks, seed, ml,
                               ground_range, n_threads, steps)


def _simulate_numpy(z64, dem, kind, dy, dx, look, frame, inc, table, step, looks, seed, ml, ground_range,
                    n_threads, steps):
    """:func:`simulate` of an in-memory DEM, advancing ``steps`` (a :class:`_progress.Steps`)."""
    if look is not None:
        zr = np.ascontiguousarray(_TO_RANGE[look](z64))
        d_range, d_az = (dx, dy) if look in (90, 270) else (dy, dx)
    else:
        zr = _to_rotated(z64, dy, dx, frame)
        d_range = d_az = frame[4]
        steps.step(z64.size)
    if ground_range and ml is None:
        # fused per range line (the same values as the steps below, without whole-scene intermediates)
        lk = 0 if looks is None else looks
        theta_l, g_img, g_s0, g_lay, g_shd = steps.counted(
            lambda pr: _core.radar_scene(zr, d_range, d_az, inc, table.tolist(), step, lk, seed, n_threads,
                                         progress=pr), zr.size)
        spacing = d_range * math.sin(math.radians(inc))
        return _to_ground(g_img, g_s0, g_lay.view(bool), g_shd.view(bool), theta_l, z64, dem, kind, look,
                          frame, dy, dx, spacing)
    spacing = d_range * math.sin(math.radians(inc))
    out = _range_lines(zr, 0, zr.shape[0], 0, d_range, d_az, inc, table.tolist(), step, looks, seed, ml,
                       ground_range, n_threads, None, steps)
    if not ground_range:
        return SARScene(*out, spacing * (1 if ml is None else ml[1]), "slant")
    return _to_ground(*out, z64, dem, kind, look, frame, dy, dx, spacing)


def _range_lines(zr, lo_row, hi_row, row0, d_range, d_az, inc, table, step, looks, seed, ml, ground_range,
                 n_threads, slant, steps=None):
    """The scene's steps one by one (geometry, projection, speckle, multilook, geocoding) for the range
    lines ``[lo_row, hi_row)`` of ``zr`` (whole range lines, with the neighbouring line on each side
    where the scene has one), the first at global line ``row0``, on the slant axis ``slant = (lo,
    n_bins)`` (``None``: the lines' own). Returns ``(image, sigma0, layover, shadow, theta_local)``:
    slant-range arrays (block averages with ``ml``) when not ``ground_range``, range-frame ground
    arrays otherwise. Multilook blocks start at line ``row0``, which must be a multiple of ``ml[0]``.
    ``steps`` (a :class:`_progress.Steps`) advances by the lines' cells per stage."""
    def done():
        if steps is not None:
            steps.step((hi_row - lo_row) * zr.shape[1])

    theta_l, power, pos, flags, n_bins = (
        a[lo_row:hi_row] if isinstance(a, np.ndarray) else a
        for a in _core.radar_geometry(zr, d_range, d_az, inc, table, step, n_threads, slant))
    done()
    slant_img, count, nlit = _core.radar_project(power, pos, flags, n_bins, n_threads)
    done()
    speckled = slant_img if looks is None else _core.speckle_f64(slant_img, looks, seed, (row0, 0), n_bins,
                                                                 n_threads)
    done()
    if ml is not None:
        az, rg = ml
        ml_img, ml_s0 = _block_mean(speckled, az, rg), _block_mean(slant_img, az, rg)
        if not ground_range:
            lay_n, _ = _block_sums((count > 1).astype(np.float64), az, rg)
            shd_n, cov_n = _block_sums(np.where(count > 0, (nlit == 0).astype(np.float64), np.nan), az, rg)
            return ml_img, ml_s0, lay_n > 0, (cov_n > 0) & (shd_n == cov_n), theta_l
        r, c = slant_img.shape
        speckled = np.ascontiguousarray(np.repeat(np.repeat(ml_img, az, axis=0), rg, axis=1)[:r, :c])
        slant_img = np.ascontiguousarray(np.repeat(np.repeat(ml_s0, az, axis=0), rg, axis=1)[:r, :c])
    if not ground_range:
        return speckled, slant_img, count > 1, (count > 0) & (nlit == 0), theta_l
    g_img, g_s0, g_lay = _core.radar_geocode(speckled, slant_img, count, pos, flags, n_threads)
    done()
    return g_img, g_s0, g_lay.view(bool), (flags & 1).view(bool), theta_l


def _strip(block, lo_row, hi_row, row0, d_range, d_az, inc, table, step, looks, seed, slant, n_threads):
    """``radar_scene`` of the range lines ``[lo_row, hi_row)`` of ``block`` (whole range lines, with the
    neighbouring line on each side where the scene has one), placed at global line ``row0`` of the
    block's first line on the whole scene's slant axis."""
    zb = np.ascontiguousarray(check_real_array(block, "dem"), dtype=np.float64)
    out = _core.radar_scene(zb, d_range, d_az, inc, table, step, looks, seed, n_threads, row0, slant)
    theta_l, img, s0, lay, shd = (a[lo_row:hi_row] for a in out)
    return theta_l, img, s0, lay.view(bool), shd.view(bool)


def _extent(block, d_range, inc, n_threads):
    return _core.radar_slant_extent(np.ascontiguousarray(check_real_array(block, "dem"), dtype=np.float64),
                                    d_range, inc, n_threads)


def _lines_strip(block, lo_row, hi_row, row0, d_range, d_az, inc, table, step, looks, seed, ml, ground_range,
                 slant, n_threads):
    """:func:`_range_lines` of a Dask strip (``block``: its lines with their neighbours)."""
    zb = np.ascontiguousarray(check_real_array(block, "dem"), dtype=np.float64)
    return _range_lines(zb, lo_row, hi_row, row0, d_range, d_az, inc, table, step, looks, seed, ml, ground_range,
                        n_threads, slant)


def _simulate_dask(z, dem, kind, dy, dx, look, inc, table, step, looks, seed, ml, ground_range, n_threads):
    """:func:`simulate` of a Dask DEM: strips of whole range lines (the range axis rechunked to one
    chunk, the azimuth chunks kept), each with one neighbouring line on each side for the derivative
    across lines, on the slant axis of the whole scene (one pass over the DEM for its extent) and
    with the speckle placed by the global line: the numpy result, bit for bit. With ``multilook``,
    strips hold whole blocks of ``az`` lines; without it and in ground range, each strip runs the
    fused kernel."""
    import dask
    import dask.array as da
    import dask.utils

    zr = _TO_RANGE[look](z).rechunk({1: -1})  # whole range lines in every chunk
    d_range, d_az = (dx, dy) if look in (90, 270) else (dy, dx)
    rows, cols = zr.shape
    # strips no taller than dask's chunk-size budget allows for float64 lines (the user's azimuth
    # chunks otherwise; the result does not depend on them), whole multilook blocks
    max_rows = max(1, dask.utils.parse_bytes(dask.config.get("array.chunk-size")) // (8 * cols))
    if ml is not None:
        az = ml[0]
        zr = zr.rechunk({0: max(az, min(max(zr.chunks[0]), max_rows) // az * az)})
    elif max(zr.chunks[0]) > max_rows:
        zr = zr.rechunk({0: max_rows})
    bounds = np.concatenate([[0], np.cumsum(zr.chunks[0])]).astype(int)
    ext = dask.compute(*(dask.delayed(_extent)(b, d_range, inc, n_threads) for b in zr.to_delayed().ravel()))
    lo, hi = min(e[0] for e in ext), max(e[1] for e in ext)
    if not math.isfinite(lo):
        lo, hi = 0.0, 0.0
    span = hi - lo
    if span > 1e9:
        raise ValueError(f"dem: the scene spans {span:.3e} slant-range bins: heights and cell_size in the "
                         "same units?")
    slant = (lo, math.ceil(span) + 1)
    table_l = table.tolist()
    fused = ground_range and ml is None
    spacing = d_range * math.sin(math.radians(inc))
    if ground_range:
        shapes = [lambda n: (n, cols)] * 5
        dtypes = (np.float64, np.float64, bool, bool, np.float64)
    elif ml is None:
        shapes = [lambda n: (n, slant[1])] * 4 + [lambda n: (n, cols)]
        dtypes = (np.float64, np.float64, bool, bool, np.float64)
    else:
        nb = -(-slant[1] // ml[1])
        shapes = [lambda n: (-(-n // ml[0]), nb)] * 4 + [lambda n: (n, cols)]
        dtypes = (np.float64, np.float64, bool, bool, np.float64)
    tasks = []
    for a, b in zip(bounds[:-1], bounds[1:]):
        h0, h1 = max(a - 1, 0), min(b + 1, rows)
        if fused:
            d = dask.delayed(_strip, nout=5)(zr[h0:h1], a - h0, b - h0, h0, d_range, d_az, inc, table_l, step,
                                             0 if looks is None else looks, seed, slant, n_threads)
            d = (d[1], d[2], d[3], d[4], d[0])  # as _range_lines: image, sigma0, layover, shadow, theta
        else:
            d = dask.delayed(_lines_strip, nout=5)(zr[h0:h1], a - h0, b - h0, a, d_range, d_az, inc, table_l,
                                                   step, looks, seed, ml, ground_range, slant, n_threads)
        tasks.append((d, b - a))
    out = tuple(da.concatenate([da.from_delayed(d[k], shape=shapes[k](n), dtype=dtypes[k]) for d, n in tasks],
                               axis=0) for k in range(5))
    if not ground_range:
        return SARScene(*out, spacing * (1 if ml is None else ml[1]), "slant")
    return _to_ground(*out, None, dem, kind, look, None, dy, dx, spacing)


def _to_ground(g_img, g_s0, g_lay, g_shd, theta_l, z64, dem, kind, look, frame, dy, dx, spacing):
    """Range-frame images on the DEM's grid (DataArrays for a DataArray DEM)."""
    if look is not None:
        back = _FROM_RANGE[look]
        keep = (lambda a: a) if array_kind(g_img) == "dask" else np.ascontiguousarray
        out_img, out_s0, inc_map, lay, shd = (keep(back(a)) for a in (g_img, g_s0, theta_l, g_lay, g_shd))
    else:
        flat = _from_rotated(z64.shape, dy, dx, frame)
        out_img, out_s0, inc_map, lay, shd = (np.take(a.ravel(), flat) for a in (g_img, g_s0, theta_l, g_lay, g_shd))
        missing = ~np.isfinite(z64)
        if missing.any():
            for arr in (out_img, out_s0, inc_map):
                arr[missing] = np.nan
            lay[missing] = False
            shd[missing] = False
    if kind == "xarray":
        out_img = dem.copy(data=out_img).rename("sar_intensity")
        out_s0 = dem.copy(data=out_s0).rename("sigma0")
        for a in (out_img, out_s0):
            a.attrs = {**dem.attrs, "long_name": a.name, "units": "m2/m2"}
    return SARScene(out_img, out_s0, lay, shd, inc_map, spacing, "ground")


