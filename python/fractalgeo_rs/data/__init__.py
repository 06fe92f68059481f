"""Small real data sets bundled with the package (see ``DATA.md`` beside
this file for provenance and licences).

Each loader returns ``(array, info)`` where ``info`` is a dict with
``description``, ``attribution``, ``crs``, ``transform`` (affine
coefficients ``(a, b, c, d, e, f)`` in ``rasterio.Affine`` order) and, where it applies, ``cell_size`` in metres and
``nodata``. ``cell_size`` is ``(dy, dx)``, row spacing (north-south) then column
spacing (east-west), numpy's axis order as every ``cell_size`` pair of the
package takes it: pass it on as is (``hillshade``, ``fractal_resample``,
``radar.simulate``, ``radiometry.Scene.from_dem``). rasterio's ``res`` is
``(x, y)``: reverse it.
"""
from __future__ import annotations

import os
from typing import Any, Dict, Tuple

import numpy as np

__all__ = ["srtm_alps", "srtm_po_plain", "kilauea_land_mask", "sentinel1_vv_db", "sentinel1_vh_db"]

_HERE = os.path.dirname(__file__)
_SRTM = "NASA SRTM 3 arc-second DEM, tile N44E007 (US public domain)"


def _load(name: str):
    return np.load(os.path.join(_HERE, name), allow_pickle=False)


def _ground_cell(a: float, e: float, lat: float) -> Tuple[float, float]:
    """``(dy, dx)`` metres (row spacing north-south, column spacing
    east-west) of a cell of ``a`` x ``e`` degrees at latitude ``lat``
    on the WGS84 ellipsoid, as the CLI and ``hillshade`` convert geographic
    grids (a degree of latitude is 111.1 km at 44 N, not the equator's
    110.57 km)."""
    from fractalgeo_rs._geodesy import metres_per_degree

    m_lat, m_lon = metres_per_degree(lat)
    return (float(abs(e) * m_lat), float(abs(a) * m_lon))


def _srtm(key: str, description: str) -> Tuple[np.ndarray, Dict[str, Any]]:
    with _load("srtm_n44e007_crops.npz") as f:
        z = f[key].copy()
        r0, c0 = (int(v) for v in f[f"{key}_origin"])
        a, b, c, d, e, g = (float(v) for v in f["transform"])
    transform = (a, b, c + c0 * a, d, e, g + r0 * e)
    cell = _ground_cell(a, e, transform[5] + e * z.shape[0] / 2)
    return z, {
        "description": description,
        "attribution": _SRTM,
        "crs": "EPSG:4326",
        "transform": transform,
        "cell_size": cell,  # (dy, dx) metres, from latitude
        "nodata": -32768,
        "units": "m",
    }


def srtm_alps() -> Tuple[np.ndarray, Dict[str, Any]]:
    """SRTM DEM of the Maritime Alps, 256 x 256 int16 metres (no voids).

    Returns
    -------
    dem : numpy.ndarray of int16, shape (256, 256)
        Heights in metres above the EGM96 geoid.
    info : dict
        ``description``, ``attribution``, ``crs`` (EPSG:4326), ``transform``
        (the crop's affine transform, rasterio order), ``cell_size`` (metres,
        ``(dy, dx)``: north-south then east-west), ``nodata`` and ``units``.

    References
    ----------
    Farr et al. (2007), doi:10.1029/2005RG000183; full entry in the
    :ref:`bibliography <ref-farr2007>`.

    NASA JPL (2013), doi:10.5067/MEaSUREs/SRTM/SRTMGL3.003; full entry in the
    :ref:`bibliography <ref-nasa2013>`.

    Examples
    --------
    >>> import fractalgeo_rs as fg
    >>> dem, info = fg.data.srtm_alps()
    >>> dem.shape, dem.dtype.name, int(dem.min()), int(dem.max())
    ((256, 256), 'int16', 494, 2328)
    """
    return _srtm("alps", "SRTM N44E007 rows 536:792, cols 288:544: Maritime Alps")


def srtm_po_plain() -> Tuple[np.ndarray, Dict[str, Any]]:
    """SRTM DEM of the Po plain, 400 x 400 int16 metres (no voids).

    Returns
    -------
    dem : numpy.ndarray of int16, shape (400, 400)
        Heights in metres above the EGM96 geoid.
    info : dict
        ``description``, ``attribution``, ``crs`` (EPSG:4326), ``transform``
        (the crop's affine transform, rasterio order), ``cell_size`` (metres,
        ``(dy, dx)``: north-south then east-west), ``nodata`` and ``units``.

    References
    ----------
    Farr et al. (2007), doi:10.1029/2005RG000183; full entry in the
    :ref:`bibliography <ref-farr2007>`.

    NASA JPL (2013), doi:10.5067/MEaSUREs/SRTM/SRTMGL3.003; full entry in the
    :ref:`bibliography <ref-nasa2013>`.

    Examples
    --------
    >>> import fractalgeo_rs as fg
    >>> dem, info = fg.data.srtm_po_plain()
    >>> dem.shape, dem.dtype.name, int(dem.min()), int(dem.max())
    ((400, 400), 'int16', 171, 544)
    """
    return _srtm("po_plain", "SRTM N44E007 rows 170:570, cols 740:1140: Po plain")


def kilauea_land_mask() -> Tuple[np.ndarray, Dict[str, Any]]:
    """Land mask of the Kilauea 30 m DEM, 793 x 857 bool (False = ocean).

    Returns
    -------
    land : numpy.ndarray of bool, shape (793, 857)
        True on land, False on the ocean (the DEM's nodata), 30 m cells.
    info : dict
        ``description``, ``attribution``, ``crs`` (EPSG:32605), ``transform``
        and ``cell_size`` (metres).

    References
    ----------
    P. Wessel, J. F. Luis, L. Uieda, R. Scharroo, F. Wobbe, W. H. F. Smith
    and D. Tian, The Generic Mapping Tools version 6, *Geochemistry,
    Geophysics, Geosystems* 20 (2019) 5556-5564, doi:10.1029/2019GC008515.

    Examples
    --------
    >>> import fractalgeo_rs as fg
    >>> land, info = fg.data.kilauea_land_mask()
    >>> land.shape, land.dtype.name, round(float(land.mean()), 3)
    ((793, 857), 'bool', 0.923)
    """
    with _load("kilauea_land_mask.npz") as f:
        shape = tuple(int(v) for v in f["shape"])
        mask = np.unpackbits(f["packed"], axis=1, count=shape[1]).astype(bool)
    return mask, {
        "description": "Land mask of the 30 m DEM of Kilauea, Hawaii (ocean = DEM nodata)",
        "attribution": "Kilauea 30 m DEM as distributed with the GMT example data (origin presumably USGS)",
        "crs": "EPSG:32605",
        "transform": (30.0, 0.0, 254325.0, 0.0, -30.0, 2153655.0),
        "cell_size": (30.0, 30.0),
    }


_S1_TRANSFORM = (8.983152841195215e-05, 0.0, -0.7818936232976315, 0.0, -8.983152841195215e-05, 38.12881257139627)


def _sentinel1(key: str, pol: str) -> Tuple[np.ndarray, Dict[str, Any]]:
    with _load("s1_vega_baja_vv_vh_db.npz") as f:
        band = f[key].copy()
    a, e, f0 = _S1_TRANSFORM[0], _S1_TRANSFORM[4], _S1_TRANSFORM[5]
    cell = _ground_cell(a, e, f0 + e * band.shape[0] / 2)
    return band, {
        "description": f"Sentinel-1 IW GRD sigma0 {pol} (dB), Vega Baja del Segura, Sept 2019 flood",
        "attribution": "Contains modified Copernicus Sentinel data 2019 (Sen1Floods11 sample)",
        "crs": "EPSG:4326",
        "transform": _S1_TRANSFORM,
        "cell_size": cell,  # (dy, dx) metres, from latitude (the grid is in degrees)
        "units": "dB",
    }


def sentinel1_vv_db() -> Tuple[np.ndarray, Dict[str, Any]]:
    """Sentinel-1 sigma0 VV in dB, Vega Baja del Segura (Spain), 512 x 512 float32.

    Returns
    -------
    vv : numpy.ndarray of float32, shape (512, 512)
        Backscatter coefficient sigma0 in dB on a 0.3 arc-second grid (about
        8 x 10 m).
    info : dict
        ``description``, ``attribution`` ("Contains modified Copernicus
        Sentinel data 2019"), ``crs`` (EPSG:4326), ``transform``, ``cell_size``
        (metres, ``(dy, dx)``) and ``units``.

    References
    ----------
    Bonafilia et al. (2020), doi:10.1109/CVPRW50498.2020.00113; full entry in the
    :ref:`bibliography <ref-bonafilia2020>`.

    Examples
    --------
    >>> import numpy as np, fractalgeo_rs as fg
    >>> vv, info = fg.data.sentinel1_vv_db()
    >>> vv.shape, vv.dtype.name, round(float(np.nanmedian(vv)), 1)
    ((512, 512), 'float32', -10.5)
    """
    return _sentinel1("vv_db", "VV")


def sentinel1_vh_db() -> Tuple[np.ndarray, Dict[str, Any]]:
    """Sentinel-1 sigma0 VH in dB, the same scene and grid as :func:`~fractalgeo_rs.data.sentinel1_vv_db`.

    Returns
    -------
    vh : numpy.ndarray of float32, shape (512, 512)
        Backscatter coefficient sigma0 in dB on a 0.3 arc-second grid (about
        8 x 10 m).
    info : dict
        ``description``, ``attribution`` ("Contains modified Copernicus
        Sentinel data 2019"), ``crs`` (EPSG:4326), ``transform``, ``cell_size``
        (metres, ``(dy, dx)``) and ``units``.

    References
    ----------
    Bonafilia et al. (2020), doi:10.1109/CVPRW50498.2020.00113; full entry in the
    :ref:`bibliography <ref-bonafilia2020>`.

    Examples
    --------
    >>> import numpy as np, fractalgeo_rs as fg
    >>> vh, info = fg.data.sentinel1_vh_db()
    >>> vv, _ = fg.data.sentinel1_vv_db()
    >>> vh.shape == vv.shape, bool(np.nanmedian(vv - vh) > 0)  # co-polarised returns are stronger
    (True, True)
    """
    return _sentinel1("vh_db", "VH")
