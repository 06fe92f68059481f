"""Hillshade: invariants, analytic planes and agreement with gdaldem."""
import math
import os
import shutil
import subprocess

import numpy as np
import pytest

import fractalgeo_rs as fg
from fractalgeo_rs.dem import hillshade, metres_per_degree, shade_to_byte

HERE = os.path.dirname(__file__)
CROP = os.path.join(HERE, "data", "bigtujunga_30m_crop128.npy")


def plane(rows, cols, gx, gy, cell):
    # z rises by gx per metre to the east and gy per metre to the north (row 0 north).
    i, j = np.meshgrid(np.arange(rows), np.arange(cols), indexing="ij")
    return gx * j * cell - gy * i * cell


def lambert(gx, gy, az, alt):
    # Independent formula: cosine between the surface normal and the sun.
    n = np.array([-gx, -gy, 1.0]) / math.sqrt(1 + gx * gx + gy * gy)
    a, e = math.radians(az), math.radians(alt)
    s = np.array([math.sin(a) * math.cos(e), math.cos(a) * math.cos(e), math.sin(e)])
    return max(0.0, float(n @ s))


@pytest.mark.parametrize("gx,gy,az,alt", [(0.3, 0.1, 315, 45), (-0.5, 0.2, 135, 30), (0.0, 1.0, 0, 60),
                                          (2.0, -1.0, 90, 10)])
def test_planes_match_lambert(gx, gy, az, alt):
    z = plane(7, 9, gx, gy, 30.0)
    s = hillshade(z, azimuth=az, altitude=alt, cell_size=30.0)[1:-1, 1:-1]  # edges: centre-filled window
    np.testing.assert_allclose(s, lambert(gx, gy, az, alt), atol=1e-6)


def test_rectangular_cells_and_z_factor():
    z = plane(6, 6, 0.2, 0.4, 1.0)  # heights per index step
    # Cells of 10 m (rows) x 20 m (cols): slopes per metre are 0.2/20 and 0.4/10.
    s = hillshade(z, cell_size=(10.0, 20.0), z_factor=3.0)[1:-1, 1:-1]
    np.testing.assert_allclose(s, lambert(3 * 0.01, 3 * 0.04, 315, 45), atol=1e-6)


def test_geographic_grid_uses_metres_per_degree():
    lat = 60.0
    m_lat, m_lon = metres_per_degree(lat)
    assert 111_000 < m_lat < 111_500 and abs(m_lon - 111_320 * 0.5) < 200
    d = 1.0 / 1200  # 3 arc-seconds
    z = plane(8, 8, 0.05, 0.0, 1.0) * (m_lon * d)  # 0.05 m/m eastwards in metres
    s = hillshade(z, cell_size=d, latitude=lat)[1:-1, 1:-1]
    np.testing.assert_allclose(s, lambert(0.05, 0.0, 315, 45), atol=1e-5)


def test_nodata_and_input_untouched():
    z = np.load(CROP).astype(np.float64)
    z[10, 10] = -9999
    before = z.copy()
    s = hillshade(z, cell_size=30.0, nodata=-9999)
    np.testing.assert_array_equal(z, before)
    assert np.isnan(s[10, 10]) and np.isfinite(np.delete(s.ravel(), 10 * 128 + 10)).all()
    assert s.dtype == np.float32 and s.shape == z.shape
    assert shade_to_byte(s)[10, 10] == 0


def test_thread_count_does_not_matter():
    z = fg.fbm_surface((200, 150), 0.6, seed=1, method="spectral")
    np.testing.assert_array_equal(hillshade(z, n_threads=1), hillshade(z, n_threads=2))


def test_multidirectional_flat_and_range():
    s = hillshade(np.zeros((5, 5)), multidirectional=True)
    # GDAL: weights sum to 2 on flat ground (aspect 0), halved: sin(alt).
    np.testing.assert_allclose(s, math.sin(math.radians(45)), atol=1e-6)
    z = np.load(CROP).astype(float)
    m = hillshade(z, cell_size=30.0, multidirectional=True)
    assert np.all((m >= 0) & (m <= 1))


def test_bad_input():
    with pytest.raises(ValueError, match="cell_size"):
        hillshade(np.zeros((3, 3)), cell_size=float("nan"))
    with pytest.raises(ValueError, match="cell_size"):
        hillshade(np.zeros((3, 3)), cell_size=(1.0, 0.0))
    with pytest.raises(ValueError, match="altitude"):
        hillshade(np.zeros((3, 3)), altitude=95)
    with pytest.raises(ValueError, match="dem"):
        hillshade(np.zeros(5))
    with pytest.raises(TypeError, match="dem"):
        hillshade(np.zeros((3, 3), dtype=bool))
    with pytest.raises(ValueError, match="latitude"):
        hillshade(np.zeros((3, 3)), latitude=[10, 20])
    for zf in (-1, 0, float("inf")):  # a negative factor would invert the relief
        with pytest.raises(ValueError, match="z_factor"):
            hillshade(np.zeros((3, 3)), z_factor=zf)
    with pytest.raises(TypeError, match="dem"):
        hillshade(np.zeros((3, 3), dtype=complex))


def _gdaldem(tmp_path, z, extra, cell=(30.0, 30.0), nodata=None):
    rasterio = pytest.importorskip("rasterio")
    from rasterio.transform import from_origin

    src = tmp_path / "dem.tif"
    out = tmp_path / "shade.tif"
    with rasterio.open(src, "w", driver="GTiff", width=z.shape[1], height=z.shape[0], count=1, dtype="float32",
                       crs="EPSG:32611", transform=from_origin(376313.0, 3807917.0, cell[1], cell[0]),
                       nodata=nodata) as dst:
        dst.write(z.astype(np.float32), 1)
    subprocess.run(["gdaldem", "hillshade", str(src), str(out), "-q"] + extra, check=True)
    with rasterio.open(out) as ds:
        return ds.read(1)


GDAL_CASES = [([], {}), (["-az", "135", "-alt", "30", "-z", "2"], {"azimuth": 135, "altitude": 30, "z_factor": 2}),
              (["-multidirectional"], {"multidirectional": True}),
              (["-az", "20", "-alt", "70", "-z", "0.5"], {"azimuth": 20, "altitude": 70, "z_factor": 0.5})]


@pytest.mark.skipif(shutil.which("gdaldem") is None, reason="gdaldem (gdal-bin) not installed")
@pytest.mark.parametrize("extra,kwargs", GDAL_CASES)
@pytest.mark.parametrize("cell", [(30.0, 30.0), (20.0, 30.0)])
def test_bytes_equal_gdaldem_compute_edges_on_every_pixel(tmp_path, extra, kwargs, cell):
    z = np.load(CROP).astype(np.float64)
    ref = _gdaldem(tmp_path, z, extra + ["-compute_edges"], cell=cell)
    ours = hillshade(z, cell_size=cell, byte=True, **kwargs)
    assert ours.dtype == np.uint8 and ours.shape == ref.shape
    assert np.count_nonzero(ours != ref) == 0, np.abs(ours.astype(int) - ref).max()


@pytest.mark.skipif(shutil.which("gdaldem") is None, reason="gdaldem (gdal-bin) not installed")
@pytest.mark.parametrize("extra,kwargs", GDAL_CASES[:3])
def test_bytes_equal_gdaldem_with_voids_and_small_grids(tmp_path, extra, kwargs):
    z = np.load(CROP).astype(np.float64)[:57, :41].copy()
    z[0, 7] = z[10, 0] = z[20:23, 38:41] = z[30, 30] = z[56, 12] = np.nan
    ref = _gdaldem(tmp_path, z, extra + ["-compute_edges"], nodata=float("nan"))
    np.testing.assert_array_equal(hillshade(z, cell_size=30.0, byte=True, **kwargs), ref)
    for shape in [(2, 2), (2, 9), (9, 2), (3, 3)]:
        zz = z[40:40 + shape[0], 3:3 + shape[1]]
        ref = _gdaldem(tmp_path, zz, extra + ["-compute_edges"])
        np.testing.assert_array_equal(hillshade(zz, cell_size=30.0, byte=True, **kwargs), ref)


@pytest.mark.skipif(shutil.which("gdaldem") is None, reason="gdaldem (gdal-bin) not installed")
@pytest.mark.parametrize("extra,kwargs", [([], {}), (["-az", "135", "-alt", "30", "-z", "2"],
                                                     {"azimuth": 135, "altitude": 30, "z_factor": 2}),
                                          (["-multidirectional"], {"multidirectional": True})])
def test_agrees_with_gdaldem(tmp_path, extra, kwargs):
    z = np.load(CROP).astype(np.float64)
    ref = _gdaldem(tmp_path, z, extra).astype(np.float64)
    ours = shade_to_byte(hillshade(z, cell_size=30.0, **kwargs)).astype(np.float64)
    inner = (slice(1, -1), slice(1, -1))  # gdaldem leaves the edges as nodata
    assert np.corrcoef(ref[inner].ravel(), ours[inner].ravel())[0, 1] > 0.999
    assert np.max(np.abs(ref[inner] - ours[inner])) <= 1


def _numpy_reference(z, cell, az, alt):
    # Slow per-pixel reference with the documented edge/nodata rule: pad the
    # grid by linear extrapolation (rows first, then columns on the interior
    # rows only; the corners of the first and last rows repeat the centre
    # column), then a missing value takes the centre.
    rows, cols = z.shape
    out = np.full(z.shape, np.nan)
    for i in range(rows):
        for j in range(cols):
            e = z[i, j]
            if np.isnan(e):
                continue
            w = np.empty((3, 3))
            for di in (-1, 0, 1):
                for dj in (-1, 0, 1):
                    ii, jj = i + di, j + dj
                    if i in (0, rows - 1):
                        jj = min(max(jj, 0), cols - 1)  # the corner columns repeat the centre column
                        if ii < 0:
                            v = 2 * z[0, jj] - z[1, jj]
                        elif ii >= rows:
                            v = 2 * z[rows - 1, jj] - z[rows - 2, jj]
                        else:
                            v = z[ii, jj]
                    elif jj < 0:
                        v = 2 * z[ii, 0] - z[ii, 1]
                    elif jj >= cols:
                        v = 2 * z[ii, cols - 1] - z[ii, cols - 2]
                    else:
                        v = z[ii, jj]
                    w[di + 1, dj + 1] = e if np.isnan(v) else v
            gx = ((w[0, 2] + 2 * w[1, 2] + w[2, 2]) - (w[0, 0] + 2 * w[1, 0] + w[2, 0])) / (8 * cell)
            gy = ((w[0, 0] + 2 * w[0, 1] + w[0, 2]) - (w[2, 0] + 2 * w[2, 1] + w[2, 2])) / (8 * cell)
            out[i, j] = lambert(gx, gy, az, alt)
    return out


def test_matches_slow_reference_with_voids():
    z = fg.fbm_surface((40, 33), 0.5, seed=9, sigma=20.0)
    z[5, 5] = np.nan
    z[0, 10] = np.nan
    z[20:23, 30:33] = np.nan
    s = hillshade(z, azimuth=200, altitude=35, cell_size=10.0)
    np.testing.assert_allclose(s, _numpy_reference(z, 10.0, 200, 35), atol=2e-7, equal_nan=True)
    b = hillshade(z, azimuth=200, altitude=35, cell_size=10.0, byte=True)
    assert b.dtype == np.uint8
    # GDAL's float32 arithmetic: within one grey level of the float64 shade
    assert np.abs(b.astype(int) - shade_to_byte(s)).max() <= 1
    assert (b[np.isnan(s)] == 0).all() and b[np.isfinite(s)].min() >= 1
