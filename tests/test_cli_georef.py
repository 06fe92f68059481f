"""Every CLI subcommand that writes a raster keeps or sets CRS, transform and
nodata (round trips through rasterio); user errors are one line, exit 1."""
import os

import numpy as np
import pytest

from fractalgeo_rs.cli import main

rasterio = pytest.importorskip("rasterio")
from rasterio.transform import from_origin  # noqa: E402

HERE = os.path.dirname(__file__)
CROP = os.path.join(HERE, "data", "bigtujunga_30m_crop128.npy")
T = from_origin(376313.0, 3807917.0, 30.0, 30.0)


@pytest.fixture
def dem_tif(tmp_path):
    z = np.load(CROP).astype(np.float32)
    z[5, 7] = -9999.0
    p = tmp_path / "dem.tif"
    with rasterio.open(p, "w", driver="GTiff", width=z.shape[1], height=z.shape[0], count=1, dtype="float32",
                       crs="EPSG:32611", transform=T, nodata=-9999.0) as dst:
        dst.write(z, 1)
    return p


def test_synth_writes_cell_size_crs_and_tags(tmp_path, capsys):
    out = tmp_path / "s.tif"
    png = tmp_path / "s.png"
    assert main(["synth", str(out), "--hurst", "0.7", "--size", "40", "50", "--cell-size", "25",
                 "--crs", "EPSG:32633", "--seed", "3", "--hillshade", str(png), "--altitude", "30"]) == 0
    printed = capsys.readouterr().out
    assert "40 x 50" in printed and str(out) in printed
    with rasterio.open(out) as ds:
        assert ds.crs.to_epsg() == 32633
        assert ds.transform == from_origin(0.0, 40 * 25.0, 25.0, 25.0)
        assert ds.tags()["CELL_SIZE"] == "25.0" and ds.tags()["HURST"] == "0.7"
    wld = [float(v) for v in (tmp_path / "s.pgw").read_text().split()]
    assert wld == [25.0, 0.0, 0.0, -25.0, 12.5, 1000.0 - 12.5]
    assert "32633" in (tmp_path / "s.prj").read_text() or "UTM zone 33N" in (tmp_path / "s.prj").read_text()


@pytest.mark.parametrize("ext", [".tif", ".png"])
def test_hillshade_keeps_georeferencing(tmp_path, dem_tif, ext, capsys):
    out = tmp_path / f"h{ext}"
    assert main(["hillshade", str(dem_tif), str(out)]) == 0
    assert str(out) in capsys.readouterr().out
    if ext == ".tif":
        with rasterio.open(out) as ds:
            assert ds.crs.to_epsg() == 32611 and ds.transform == T and ds.nodata == 0
            b = ds.read(1)
    else:
        with rasterio.open(out) as ds:  # GDAL reads the world file
            assert ds.transform == T
            b = ds.read(1)
        assert rasterio.crs.CRS.from_wkt((tmp_path / "h.prj").read_text()).to_epsg() == 32611
    assert b[5, 7] == 0 and (b[np.arange(128) != 5] > 0).all()


def test_transform_keeps_georeferencing(tmp_path, dem_tif):
    out = tmp_path / "d.tif"
    assert main(["transform", str(dem_tif), str(out), "--window", "9", "--n-threads", "1"]) == 0
    with rasterio.open(out) as ds:
        assert ds.crs.to_epsg() == 32611 and ds.transform == T and np.isnan(ds.nodata)


@pytest.mark.parametrize("argv,needle", [
    (["transform", "IN", "OUT.tif", "--chunks", "0"], "--chunks"),
    (["synth", "DIR", "--hurst", "0.5", "--size", "8", "8"], "directory"),
    (["hillshade", "IN", "OUT.png", "--z-factor", "-1"], "--z-factor"),
    (["synth", "o.npy", "--hurst", "0.5", "--size", "1000000000000"], "--max-memory"),
    (["synth", "o.npy", "--hurst", "0.5", "--size", "64", "--n-threads", "100000"], "--n-threads"),
])
def test_user_errors_are_one_line(tmp_path, dem_tif, capsys, argv, needle):
    argv = [str(dem_tif) if a == "IN" else str(tmp_path / a) if a.startswith(("OUT", "o.")) else
            str(tmp_path) if a == "DIR" else a for a in argv]
    assert main(argv) == 1
    err = capsys.readouterr().err
    assert needle in err and "Traceback" not in err and err.count("\n") == 1


def test_debug_shows_the_traceback(tmp_path):
    with pytest.raises(ValueError):
        main(["--debug", "transform", "x.tif", str(tmp_path / "o.tif"), "--chunks", "0"])


def test_old_thread_spellings_still_work(tmp_path, dem_tif):
    assert main(["transform", str(dem_tif), str(tmp_path / "a.npy"), "--window", "9", "--workers", "1"]) == 0
    m = tmp_path / "m.npy"
    np.save(m, np.eye(64, dtype=np.uint8) * 255)
    assert main(["dimension", str(m), "--threads", "1"]) == 0


def test_missing_dask_is_one_line_naming_the_extra(tmp_path, dem_tif, capsys, monkeypatch):
    import sys

    monkeypatch.setitem(sys.modules, "dask", None)
    monkeypatch.setitem(sys.modules, "dask.array", None)
    assert main(["transform", str(dem_tif), str(tmp_path / "o.npy"), "--chunks", "64"]) == 1
    err = capsys.readouterr().err
    assert 'pip install "fractalgeo_rs[dask]"' in err and err.count("\n") == 1


def test_help_shows_defaults(capsys):
    with pytest.raises(SystemExit):
        main(["hillshade", "--help"])
    out = " ".join(capsys.readouterr().out.split())  # argparse wraps lines
    assert "(default: 315.0)" in out and "--n-threads" in out and "--threads" not in out
