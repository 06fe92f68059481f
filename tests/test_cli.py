"""The fractalgeo command line: help, dimension on each file format, demo."""
import os
import subprocess
import sys

import numpy as np
import pytest

import fractalgeo_rs as fg
from fractalgeo_rs.cli import main
from fractals import sierpinski_carpet, sierpinski_triangle

LN = np.log


def run(args, capsys):
    code = main(args)
    out = capsys.readouterr()
    return code, out.out, out.err


def test_help_lists_commands(capsys):
    with pytest.raises(SystemExit) as e:
        main(["--help"])
    assert e.value.code == 0
    out = capsys.readouterr().out
    assert "dimension" in out and "demo" in out


def test_console_script_installed():
    r = subprocess.run([sys.executable, "-m", "fractalgeo_rs.cli", "--help"], capture_output=True, text=True)
    assert r.returncode == 0 and "fractalgeo" in r.stdout


def test_dimension_npy_and_plot(tmp_path, capsys):
    path = tmp_path / "tri.npy"
    np.save(path, sierpinski_triangle(8))
    plot = tmp_path / "fit.png"
    code, out, _ = run(["dimension", str(path), "--plot", str(plot)], capsys)
    assert code == 0
    assert "method: box (the default for a set)" in out and "D = 1.5850," in out
    assert plot.exists() and plot.stat().st_size > 1000


def test_dimension_png_16bit_and_threshold(tmp_path, capsys):
    carpet = sierpinski_carpet(5)
    path = tmp_path / "carpet.png"
    fg.write_raster(path, carpet.astype(np.uint16) * 40000)
    code, out, _ = run(["dimension", str(path), "--threshold", "100"], capsys)
    assert code == 0
    assert f"D = {LN(8) / LN(3):.4f}," in out


def test_dimension_geotiff_via_rasterio(tmp_path, capsys):
    rasterio = pytest.importorskip("rasterio")
    from rasterio.transform import from_origin

    z = np.random.default_rng(0).normal(size=(96, 80)).cumsum(axis=1).astype(np.float32)
    path = tmp_path / "dem.tif"
    with rasterio.open(path, "w", driver="GTiff", width=80, height=96, count=1, dtype="float32",
                       crs="EPSG:32633", transform=from_origin(500000, 4000000, 30, 30), nodata=-9999) as dst:
        dst.write(z, 1)
    code, out, _ = run(["dimension", str(path), "--method", "dbc", "--box-sizes", "2,4,8,16"], capsys)
    assert code == 0
    expect = fg.differential_box_counting(z, box_sizes=[2, 4, 8, 16])
    assert f"D = {expect.dimension:.4f}," in out


def test_dimension_errors_are_clean(tmp_path, capsys):
    code, _, err = run(["dimension", str(tmp_path / "missing.npy")], capsys)
    assert code == 1 and "path" in err
    bad = tmp_path / "x.txt"
    bad.write_text("hello")
    code, _, err = run(["dimension", str(bad)], capsys)
    assert code == 1 and ("unsupported" in err or "not recognized" in err)


def test_demo_prints_fits_and_writes_figure(tmp_path, capsys):
    code, out, _ = run(["demo", "--out", str(tmp_path)], capsys)
    assert code == 0
    assert "Kilauea coastline" in out and "Sentinel-1" in out
    fig = tmp_path / "fractalgeo_demo.png"
    assert fig.exists() and fig.stat().st_size > 10_000
    # the demo's coastline dimension is a real line: between 1 and 2
    line = [l for l in out.splitlines() if l.startswith("Kilauea")][0]
    d = float(line.split("D = ")[1].split()[0])
    assert 1.0 <= d < 1.3
    assert not [f for f in os.listdir(tmp_path) if f.startswith(".")]  # no temp files left


def test_written_files_have_normal_permissions(tmp_path, capsys):
    path = tmp_path / "tri.npy"
    np.save(path, sierpinski_triangle(6))
    plot = tmp_path / "fit.png"
    run(["dimension", str(path), "--plot", str(plot)], capsys)
    umask = os.umask(0)
    os.umask(umask)
    assert plot.stat().st_mode & 0o777 == 0o666 & ~umask
