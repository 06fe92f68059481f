"""``fractalgeo sar`` writes the scene simulate computes."""
import numpy as np

import fractalgeo_rs as fg
from fractalgeo_rs.cli import main


def test_sar_command(tmp_path, capsys):
    dem = fg.fbm_surface(40, 0.7, seed=1, sigma=3.0)
    src, out = tmp_path / "dem.npy", tmp_path / "sar.npy"
    np.save(src, dem)
    code = main(["sar", str(src), str(out), "--incidence", "35", "--look-azimuth", "90", "--wavelength", "0.056",
                 "--looks", "4", "--seed", "1", "--cell-size", "10"])
    assert code == 0 and "layover" in capsys.readouterr().out
    ref = fg.radar.simulate(dem, 10.0, look_azimuth=90, incidence=35, wavelength=0.056, looks=4, seed=1)
    np.testing.assert_array_equal(np.load(out), ref.image.astype(np.float32))


def test_sar_needs_a_cell_size(tmp_path, capsys):
    src = tmp_path / "dem.npy"
    np.save(src, np.zeros((8, 8)))
    assert main(["sar", str(src), str(tmp_path / "o.npy"), "--incidence", "35"]) == 1
    assert "--cell-size" in capsys.readouterr().err


def test_sar_output_formats(tmp_path, capsys):
    # a georeferenced DEM to .npy failed after the simulation ("profile: georeferencing
    # can be written to GeoTIFF ..."); a .png output failed there too ("data: PNG holds uint8")
    import pytest

    pytest.importorskip("rasterio")
    from affine import Affine

    dem = fg.fbm_surface(40, 0.7, seed=1, sigma=3.0)
    src = tmp_path / "dem.tif"
    fg.write_raster(src, dem, crs="EPSG:32633", transform=Affine(10, 0, 500000, 0, -10, 5000000))
    args = ["--incidence", "35", "--looks", "4", "--seed", "1"]
    assert main(["sar", str(src), str(tmp_path / "o.npy"), *args]) == 0
    assert main(["sar", str(src), str(tmp_path / "o.tif"), *args]) == 0
    img, prof = fg.read_raster(tmp_path / "o.tif")
    np.testing.assert_array_equal(np.load(tmp_path / "o.npy"), img)
    assert prof["crs"] is not None and tuple(prof["transform"])[:6] == (10, 0, 500000, 0, -10, 5000000)
    capsys.readouterr()
    assert main(["sar", str(tmp_path / "missing.tif"), str(tmp_path / "o.png"), *args]) == 1
    err = capsys.readouterr().err
    assert "output" in err and "missing.tif" not in err
