"""``fractalgeo resample`` and ``fractalgeo tin`` on the inputs a new user
brings: geographic DEMs (SRTM .hgt, EPSG:4326), multi-band files, no dask,
a wrong output suffix."""
import os
import sys

import numpy as np
import pytest

import fractalgeo_rs as fg
from fractalgeo_rs.cli import main

rasterio = pytest.importorskip("rasterio")


def _write(path, bands, crs="EPSG:32611", transform=None):
    from rasterio.transform import from_origin

    bands = np.atleast_3d(np.asarray(bands, dtype=np.float32).T).T  # (bands, rows, cols)
    if transform is None:
        transform = from_origin(1000, 5000, 30, 30)
    with rasterio.open(path, "w", driver="GTiff", height=bands.shape[1], width=bands.shape[2],
                       count=bands.shape[0], dtype="float32", crs=crs, transform=transform) as d:
        d.write(bands)


def _dem(n=40, seed=1):
    return (fg.fbm_surface(n, 0.7, method="exact", seed=seed) * 20 + 500).astype(np.float32)


def _read(path):
    with rasterio.open(path) as d:
        return d.read(1)


def test_resample_min_scale_in_metres_on_a_geographic_grid(tmp_path, capsys):
    from rasterio.transform import from_origin

    z = _dem()
    # 2" x 1" cells at 44.5 N: about 44.2 m in x, 30.9 m in y; the larger (x) is the cell size.
    dx, dy = 2 / 3600, 1 / 3600
    src, dst = str(tmp_path / "geo.tif"), str(tmp_path / "out.tif")
    _write(src, z, crs="EPSG:4326", transform=from_origin(7.0, 44.5 + 20 * dy, dx, dy))
    assert main(["resample", src, dst, "--factor", "4", "--min-scale", "20", "--seed", "1",
                 "--window", "9", "--chunks", "16", "--no-progress"]) == 0
    summary = capsys.readouterr().out
    m_lat, m_lon = fg.dem.metres_per_degree(44.5)
    cell = max(dx * float(m_lon), dy * float(m_lat))
    assert cell == pytest.approx(44.2, abs=0.1)
    out = _read(dst)

    def ref(c):
        return fg.fractal_resample(z.astype(float), 4, seed=1, window_size=9, cell_size=c,
                                   min_scale=20).astype(np.float32)

    # 44.2 m cells: detail at the first level (22 m) only; in degrees there would be none, and with
    # the y spacing (30.9 m) none either
    np.testing.assert_array_equal(out, ref(cell))
    assert not np.array_equal(out, ref(dx))
    assert np.array_equal(ref(dx), ref(dy * float(m_lat)))
    assert f"cell {cell:g} m, seed 1)" in summary


def test_resample_and_tin_take_band(tmp_path, capsys):
    from fractalgeo_rs.tin import tin_from_dem

    a, b = _dem(seed=1), _dem(seed=2)
    src = str(tmp_path / "two.tif")
    _write(src, np.stack([a, b]))
    dst = str(tmp_path / "out.tif")
    assert main(["resample", src, dst, "--seed", "3", "--window", "9", "--no-progress"]) == 1
    assert "--band" in capsys.readouterr().err
    assert main(["resample", src, dst, "--band", "2", "--seed", "3", "--window", "9", "--no-progress"]) == 0
    ref = fg.fractal_resample(b.astype(float), 2, seed=3, window_size=9, cell_size=30.0)
    np.testing.assert_array_equal(_read(dst), ref.astype(np.float32))

    assert main(["tin", src, str(tmp_path / "a.obj"), "--max-error", "2"]) == 1
    assert "--band" in capsys.readouterr().err
    capsys.readouterr()
    assert main(["tin", src, str(tmp_path / "a.obj"), "--max-error", "2", "--band", "2"]) == 0
    t = tin_from_dem(b, max_error=2.0)
    assert capsys.readouterr().out.startswith(f"{len(t.vertices)} vertices, {len(t.triangles)} triangles")


def _hide_dask(monkeypatch):
    for name in [m for m in sys.modules if m == "dask" or m.startswith("dask.")]:
        monkeypatch.delitem(sys.modules, name)
    monkeypatch.setitem(sys.modules, "dask", None)
    monkeypatch.setitem(sys.modules, "dask.array", None)


def test_resample_without_dask_computes_in_memory(tmp_path, monkeypatch, capsys):
    pytest.importorskip("dask.array")
    z = _dem()
    src = str(tmp_path / "in.tif")
    _write(src, z)
    args = ["--factor", "4", "--seed", "5", "--window", "9", "--chunks", "16", "--no-progress"]
    assert main(["resample", src, str(tmp_path / "dask.tif")] + args) == 0
    _hide_dask(monkeypatch)
    with pytest.raises(ImportError):
        import dask.array  # noqa: F401
    assert main(["resample", src, str(tmp_path / "mem.tif")] + args) == 0
    np.testing.assert_array_equal(_read(tmp_path / "mem.tif"), _read(tmp_path / "dask.tif"))
    with rasterio.open(tmp_path / "mem.tif") as m, rasterio.open(tmp_path / "dask.tif") as d:
        pm, pd = dict(m.profile), dict(d.profile)
        assert np.isnan(pm.pop("nodata")) and np.isnan(pd.pop("nodata"))
        assert pm == pd
    # too large for memory: the one-line message naming the extra, nothing written
    capsys.readouterr()
    monkeypatch.setenv("FRACTALGEO_MAX_MEMORY", "100000")
    assert main(["resample", src, str(tmp_path / "big.tif")] + args) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and 'pip install "fractalgeo_rs[dask]"' in err
    assert not os.path.exists(tmp_path / "big.tif")


@pytest.mark.parametrize("name", ["out.png", "out", "out.tif.npy"])
def test_resample_rejects_a_non_geotiff_output(tmp_path, capsys, name):
    src = str(tmp_path / "in.tif")
    _write(src, _dem())
    assert main(["resample", src, str(tmp_path / name), "--window", "9"]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "output: expected a GeoTIFF (.tif or .tiff)" in err
    assert not os.path.exists(tmp_path / name)


def test_tin_warns_on_a_geographic_dem(tmp_path, capsys):
    from rasterio.transform import from_origin

    z = _dem()
    geo, utm = str(tmp_path / "geo.tif"), str(tmp_path / "utm.tif")
    _write(geo, z, crs="EPSG:4326", transform=from_origin(7.0, 45.0, 1 / 3600, 1 / 3600))
    _write(utm, z)
    assert main(["tin", geo, str(tmp_path / "a.obj"), "--max-error", "2"]) == 0
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert "geographic" in err and "x, y in degrees and z in metres" in err and "projected" in err
    assert main(["tin", utm, str(tmp_path / "b.obj"), "--max-error", "2"]) == 0
    assert capsys.readouterr().err == ""
