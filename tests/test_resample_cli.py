"""``fractalgeo resample``."""
import os

import numpy as np
import pytest

import fractalgeo_rs as fg
from fractalgeo_rs.cli import main

rasterio = pytest.importorskip("rasterio")
pytest.importorskip("dask.array")


def _write(path, z):
    from rasterio.transform import from_origin

    with rasterio.open(path, "w", driver="GTiff", height=z.shape[0], width=z.shape[1], count=1,
                       dtype="float32", crs="EPSG:32611", transform=from_origin(1000, 5000, 30, 30),
                       nodata=-9999) as d:
        d.write(z.astype(np.float32), 1)


def test_resample_geotiff(tmp_path, capsys):
    z = (fg.fbm_surface(40, 0.7, method="exact", seed=1) * 20 + 500).astype(np.float32)
    src, dst = str(tmp_path / "in.tif"), str(tmp_path / "out.tif")
    _write(src, z)
    assert main(["resample", src, dst, "--factor", "4", "--seed", "1", "--chunks", "16",
                 "--min-scale", "10", "--window", "9", "--progress"]) == 0
    err = capsys.readouterr().err
    assert "resample:" in err and "0/9" in err  # tqdm's bar over the 3 x 3 output blocks (first draw)
    with rasterio.open(dst) as d:
        out = d.read(1)
        assert out.shape == (157, 157)
        assert d.crs.to_epsg() == 32611
        assert d.transform.a == pytest.approx(7.5) and d.transform.e == pytest.approx(-7.5)
        # Point support: fine pixel (0, 0) has the centre of input pixel (0, 0).
        assert d.transform.c + 3.75 == pytest.approx(1015.0)
    np.testing.assert_array_equal(out[::4, ::4], z)
    ref = fg.fractal_resample(z.astype(float), 4, seed=1, window_size=9, cell_size=30.0, min_scale=10)
    np.testing.assert_allclose(out, ref.astype(np.float32))


def test_resample_area_edges(tmp_path):
    z = (fg.fbm_surface(32, 0.5, method="exact", seed=1) + 100).astype(np.float32)
    src, dst = str(tmp_path / "in.tif"), str(tmp_path / "out.tif")
    _write(src, z)
    assert main(["resample", src, dst, "--factor", "2", "--support", "area", "--no-progress",
                 "--window", "9", "--seed", "2"]) == 0
    with rasterio.open(dst) as d:
        assert d.shape == (64, 64)
        assert d.bounds == pytest.approx((1000, 5000 - 960, 1960, 5000))


def test_resample_bad_factor_writes_nothing(tmp_path, capsys):
    src, dst = str(tmp_path / "in.tif"), str(tmp_path / "out.tif")
    _write(src, np.zeros((16, 16)))
    assert main(["resample", src, dst, "--factor", "3"]) == 1
    assert "factor" in capsys.readouterr().err
    assert not os.path.exists(dst)


def test_resample_quiet_is_no_progress(tmp_path, capsys):
    z = (fg.fbm_surface(32, 0.5, method="exact", seed=1) + 100).astype(np.float32)
    src = str(tmp_path / "in.tif")
    _write(src, z)
    for flag in ("--quiet", "--no-progress"):
        dst = str(tmp_path / f"out{flag}.tif")
        assert main(["resample", src, dst, "--window", "9", "--seed", "2", "--chunks", "16", flag]) == 0
        assert "resample" not in capsys.readouterr().err
