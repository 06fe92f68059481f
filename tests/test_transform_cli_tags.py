"""``fractalgeo transform`` records what makes a map reproducible in the
GeoTIFF's metadata tags: method, window, step, the z_scale used (also when
"auto") and units; the tags round-trip through rasterio."""
import os

import numpy as np
import pytest

import fractalgeo_rs as fg
from fractalgeo_rs.cli import main
from fractalgeo_rs.transform import default_z_scale

rasterio = pytest.importorskip("rasterio")
from rasterio.transform import from_origin  # noqa: E402

CROP = os.path.join(os.path.dirname(__file__), "data", "bigtujunga_30m_crop128.npy")


@pytest.fixture
def dem_tif(tmp_path):
    z = np.load(CROP).astype(np.float32)
    z[5, 7] = -9999.0
    p = tmp_path / "dem.tif"
    with rasterio.open(p, "w", driver="GTiff", width=z.shape[1], height=z.shape[0], count=1, dtype="float32",
                       crs="EPSG:32611", transform=from_origin(0.0, 3840.0, 30.0, 30.0), nodata=-9999.0) as dst:
        dst.write(z, 1)
    return p, z


def _tags(path):
    with rasterio.open(path) as ds:
        return ds.tags(), ds.read(1)


@pytest.mark.parametrize("chunks", [None, 64])
def test_auto_z_scale_is_recorded_as_used(tmp_path, dem_tif, capsys, chunks):
    src, z = dem_tif
    out = tmp_path / "m.tif"
    argv = ["transform", str(src), str(out), "--window", "9", "--step", "2", "--n-threads", "1"]
    if chunks:
        argv += ["--chunks", str(chunks)]
    assert main(argv) == 0
    tags, band = _tags(out)
    want = default_z_scale(z, -9999.0)
    assert float(tags["Z_SCALE"]) == want  # repr round-trips the float exactly
    assert tags["FRACTAL_METHOD"] == "mass" and tags["WINDOW_SIZE"] == "9" and tags["STEP"] == "2"
    assert tags["Z_SCALE_UNITS"] == "input units per pixel"
    assert tags["UNITS"] == "fractal dimension (dimensionless)"
    # the map is the one fractal_transform gives with that z_scale
    ref = fg.fractal_transform(z, 9, nodata=-9999.0, z_scale=want, step=2)
    np.testing.assert_allclose(band, ref, rtol=0, atol=1e-6, equal_nan=True)
    assert f"z_scale: {want:.6g}" in capsys.readouterr().out


def test_fixed_z_scale_and_scale_free_methods(tmp_path, dem_tif):
    src, _ = dem_tif
    out = tmp_path / "d.tif"
    assert main(["transform", str(src), str(out), "--window", "9", "--method", "dbc", "--z-scale", "0.25"]) == 0
    tags, _ = _tags(out)
    assert tags["FRACTAL_METHOD"] == "dbc" and float(tags["Z_SCALE"]) == 0.25 and tags["STEP"] == "1"
    out = tmp_path / "v.tif"
    assert main(["transform", str(src), str(out), "--window", "9", "--method", "variogram"]) == 0
    tags, _ = _tags(out)
    assert tags["Z_SCALE"] == "none" and "Z_SCALE_UNITS" not in tags


@pytest.mark.filterwarnings("ignore::rasterio.errors.NotGeoreferencedWarning")  # a bare TIFF, on purpose
def test_out_of_range_fraction_is_printed(tmp_path, capsys):
    p = tmp_path / "noise.tif"
    z = np.random.default_rng(0).standard_normal((64, 64)).astype(np.float32)
    with rasterio.open(p, "w", driver="GTiff", width=64, height=64, count=1, dtype="float32") as dst:
        dst.write(z, 1)
    assert main(["transform", str(p), str(tmp_path / "o.tif"), "--window", "9", "--method", "variogram"]) == 0
    d = fg.fractal_transform(z, 9, method="variogram", return_fit=True)[0]
    pct = 100 * np.mean(d[np.isfinite(d)] > 3 + 1e-6)
    assert f"outside the valid domain: {pct:.1f} % above_3" in capsys.readouterr().out
