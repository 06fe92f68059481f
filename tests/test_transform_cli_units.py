"""fractalgeo transform: --z-scale cell takes the file's cell size as the
height unit per box step, and the output records the units it used."""
import numpy as np
import pytest

import fractalgeo_rs as fg
from fractalgeo_rs.cli import main

rasterio = pytest.importorskip("rasterio")


def _dem(path, cell):
    from rasterio.transform import from_origin

    z = fg.fbm_surface((48, 40), 0.7, seed=4, method="spectral", sigma=20.0, cell_size=cell).astype(np.float32)
    with rasterio.open(path, "w", driver="GTiff", width=40, height=48, count=1, dtype="float32",
                       crs="EPSG:32633", transform=from_origin(500000, 4200000, cell, cell)) as dst:
        dst.write(z, 1)
    return z


def test_z_scale_cell_uses_and_records_the_cell_size(tmp_path, capsys):
    src, out = tmp_path / "dem.tif", tmp_path / "d.tif"
    z = _dem(src, 30.0)
    assert main(["transform", str(src), str(out), "--window", "9", "--method", "dbc", "--z-scale", "cell"]) == 0
    assert "z_scale: 30 data units" in capsys.readouterr().out
    with rasterio.open(out) as ds:
        tags = ds.tags()
        got = ds.read(1)
    assert float(tags["Z_SCALE"]) == 30.0 and tags["INPUT_CELL_SIZE"] == "30"
    assert tags["FRACTAL_METHOD"] == "dbc" and tags["WINDOW_SIZE"] == "9"
    ref = fg.fractal_transform(z, 9, method="dbc", z_scale=30.0)
    np.testing.assert_array_equal(got, ref.astype(np.float32))


def test_z_scale_cell_needs_a_georeferenced_input(tmp_path, capsys):
    src = tmp_path / "z.npy"
    np.save(src, np.zeros((20, 20)))
    assert main(["transform", str(src), str(tmp_path / "d.npy"), "--window", "9", "--z-scale", "cell"]) != 0
    assert "--z-scale" in capsys.readouterr().err
