"""The ``fractalgeo synth`` and ``fractalgeo hillshade`` commands."""
import numpy as np
import pytest

import fractalgeo_rs as fg
from fractalgeo_rs.cli import main
from fractalgeo_rs.io import read_raster, write_raster


def test_synth_2d_with_hillshade(tmp_path):
    out, png = tmp_path / "z.exr", tmp_path / "z.png"
    rc = main(["synth", str(out), "--hurst", "0.7", "--size", "40", "60", "--method", "additions",
               "--seed", "3", "--hillshade", str(png)])
    assert rc == 0
    z, _ = read_raster(out)
    want = fg.fbm_surface((40, 60), 0.7, method="additions", seed=3).astype(np.float32)
    np.testing.assert_array_equal(z, want)
    s, _ = read_raster(png)
    assert s.dtype == np.uint8 and s.shape == (40, 60) and s.min() >= 1


def test_synth_1d(tmp_path):
    out = tmp_path / "x.npy"
    assert main(["synth", str(out), "--hurst", "0.3", "--size", "100", "--seed", "1"]) == 0
    np.testing.assert_array_equal(np.load(out), fg.fbm(100, 0.3, seed=1))


def test_synth_bad_hurst_is_an_error(tmp_path, capsys):
    assert main(["synth", str(tmp_path / "z.npy"), "--hurst", "1.5", "--size", "10", "10"]) == 1
    assert "hurst" in capsys.readouterr().err


def test_hillshade_command_uses_georeferencing(tmp_path):
    pytest.importorskip("rasterio")
    from rasterio.transform import from_origin

    z = np.load(__file__.replace("test_synth_cli.py", "data/bigtujunga_30m_crop128.npy")).astype(np.float32)
    write_raster(tmp_path / "dem.tif", z, crs="EPSG:32611", transform=from_origin(0, 0, 30, 30))
    assert main(["hillshade", str(tmp_path / "dem.tif"), str(tmp_path / "s.png")]) == 0
    s, _ = read_raster(tmp_path / "s.png")
    want = fg.dem.shade_to_byte(fg.hillshade(z, cell_size=30.0))
    np.testing.assert_array_equal(s, want)
