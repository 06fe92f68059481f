"""Raster I/O round trips and atomic writes."""
import os

import numpy as np
import pytest

import fractalgeo_rs as fg
from fractalgeo_rs.io import read_raster, write_raster


def test_npy_round_trip(tmp_path):
    a = np.arange(12, dtype=np.int16).reshape(3, 4)
    write_raster(tmp_path / "a.npy", a)
    b, prof = read_raster(tmp_path / "a.npy")
    assert prof is None and b.dtype == a.dtype
    np.testing.assert_array_equal(a, b)
    s = np.stack([a, a + 1])
    write_raster(tmp_path / "s.npy", s)
    np.testing.assert_array_equal(read_raster(tmp_path / "s.npy", band=2)[0], a + 1)


@pytest.mark.parametrize("dtype", [np.uint8, np.uint16])
def test_png_round_trip(tmp_path, dtype):
    a = (np.arange(35).reshape(5, 7) * 7).astype(dtype)
    a[0, 0] = np.iinfo(dtype).max
    write_raster(tmp_path / "a.png", a)
    b, prof = read_raster(tmp_path / "a.png")
    assert b.dtype == dtype and prof is None
    np.testing.assert_array_equal(a, b)


def test_png_refuses_floats(tmp_path):
    with pytest.raises(TypeError, match="data"):
        write_raster(tmp_path / "a.png", np.zeros((3, 3)))
    assert not os.listdir(tmp_path)


def test_exr_round_trip(tmp_path):
    a = fg.fbm_surface((33, 47), 0.6, seed=1).astype(np.float32)
    a[3, 4] = np.nan
    a[5, 6] = -1e30
    write_raster(tmp_path / "a.exr", a)
    b, prof = read_raster(tmp_path / "a.exr")
    assert b.dtype == np.float32 and b.shape == (33, 47)
    np.testing.assert_array_equal(a, b)  # NaN positions compare equal here
    # float64 is stored as float32
    write_raster(tmp_path / "d.exr", a.astype(np.float64))
    np.testing.assert_array_equal(read_raster(tmp_path / "d.exr")[0], a)


def test_geotiff_round_trip_keeps_georeferencing(tmp_path):
    rasterio = pytest.importorskip("rasterio")
    from rasterio.transform import Affine

    a = np.arange(20, dtype=np.float32).reshape(4, 5)
    t = Affine(30.0, 0.0, 376313.0, 0.0, -30.0, 3807917.0)
    write_raster(tmp_path / "a.tif", a, crs="EPSG:32611", transform=t, nodata=-9999.0)
    b, prof = read_raster(tmp_path / "a.tif")
    np.testing.assert_array_equal(a, b)
    assert prof["crs"] == rasterio.crs.CRS.from_epsg(32611)
    assert prof["transform"] == t and prof["nodata"] == -9999.0
    # the profile carries over to a new file of another dtype
    write_raster(tmp_path / "b.tif", (a * 2).astype(np.int16), profile=prof)
    c, prof2 = read_raster(tmp_path / "b.tif")
    assert c.dtype == np.int16 and prof2["transform"] == t and prof2["crs"] == prof["crs"]


def test_atomic_write_leaves_old_file_on_failure(tmp_path):
    p = tmp_path / "a.npy"
    write_raster(p, np.ones((2, 2)))
    with pytest.raises(ValueError):
        write_raster(tmp_path / "a.exr", np.ones((2, 2), dtype=np.float32), crs="EPSG:4326")
    with pytest.raises(TypeError):
        write_raster(p, None)
    np.testing.assert_array_equal(read_raster(p)[0], np.ones((2, 2)))
    assert sorted(os.listdir(tmp_path)) == ["a.npy"]


def test_errors(tmp_path):
    with pytest.raises(FileNotFoundError):
        read_raster(tmp_path / "missing.npy")
    write_raster(tmp_path / "a.npy", np.ones((2, 2)))
    with pytest.raises(ValueError, match="band"):
        read_raster(tmp_path / "a.npy", band=2)
    with pytest.raises(ValueError, match="band"):
        read_raster(tmp_path / "a.npy", band=0)
    with pytest.raises(ValueError, match="extension"):
        write_raster(tmp_path / "a.xyz", np.ones((2, 2)))
    with pytest.raises(OSError):
        write_raster(tmp_path / "nofolder" / "a.exr", np.ones((2, 2)))
