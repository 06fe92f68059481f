"""``fractalgeo synth``: the seed it drew is printed and recorded (and
repeats the run), ``--relief`` makes a DEM in metres, time and memory are
reported, the memory limit is an option; inputs without georeferencing get
one line about the cell size and no rasterio warning."""
import re
import warnings

import numpy as np
import pytest

import fractalgeo_rs as fg
from fractalgeo_rs.cli import main


def test_drawn_seed_is_printed_recorded_and_repeats(tmp_path, capsys):
    rasterio = pytest.importorskip("rasterio")
    out = tmp_path / "a.tif"
    assert main(["synth", str(out), "--hurst", "0.6", "--size", "32", "40"]) == 0
    text = capsys.readouterr().out
    seed = int(re.search(r"seed (\d+)\)", text).group(1))
    assert re.search(r"^time \d+\.\d\d s, peak memory \d+\.\d\d GiB$", text, re.M)
    with rasterio.open(out) as ds:
        assert ds.tags()["SEED"] == str(seed)
        z = ds.read(1)
    np.testing.assert_array_equal(z, fg.fbm_surface((32, 40), 0.6, seed=seed))


def test_relief_makes_a_dem_in_metres(tmp_path, capsys):
    out = tmp_path / "dem.npy"
    assert main(["synth", str(out), "--hurst", "0.7", "--size", "64", "64", "--cell-size", "30", "--relief", "100",
                 "--relief-lag", "300", "--mean-elevation", "800", "--seed", "1"]) == 0
    z = np.load(out)
    ref = fg.synthetic_dem((64, 64), 0.7, cell_size=30.0, relief=100.0, relief_lag=300.0, mean_elevation=800.0,
                           seed=1)
    np.testing.assert_array_equal(z, ref)
    assert abs(z.mean() - 800.0) < 1e-6
    assert "synthetic DEM (m)" in capsys.readouterr().out
    assert main(["synth", str(out), "--hurst", "0.7", "--size", "8", "8", "--mean-elevation", "5"]) == 1
    assert "--relief" in capsys.readouterr().err


def test_memory_limit_is_an_option(tmp_path, capsys):
    assert main(["synth", str(tmp_path / "a.npy"), "--hurst", "0.7", "--size", "2048", "2048", "--method", "exact",
                 "--max-memory", "1M"]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--max-memory" in err and "max_memory" not in err


def test_default_method_is_spectral_for_large_grids():
    from fractalgeo_rs.synth._cli import EXACT_DEFAULT_LIMIT

    assert EXACT_DEFAULT_LIMIT == 2048 * 2048


@pytest.mark.parametrize("command", ["hillshade", "tin", "transform", "resample"])
def test_npy_input_gets_one_line_and_no_rasterio_warning(tmp_path, capsys, command):
    pytest.importorskip("rasterio")
    np.save(tmp_path / "d.npy", fg.fbm_surface((40, 40), 0.7, seed=1) * 10 + 100)
    out = {"hillshade": "o.tif", "tin": "o.obj", "transform": "o.tif", "resample": "o.tif"}[command]
    argv = [command, str(tmp_path / "d.npy"), str(tmp_path / out)] + (["--window", "9"] if command in (
        "transform", "resample") else []) + (["--seed", "1"] if command == "resample" else [])
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a rasterio NotGeoreferencedWarning would fail here
        assert main(argv) == 0
    err = capsys.readouterr().err
    assert err.count("cell size 1 assumed (give --cell-size)") == 1, err
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert main(argv + ["--cell-size", "30", "--crs", "EPSG:32633"]) == 0
    assert "assumed" not in capsys.readouterr().err
    import rasterio

    if out.endswith(".tif"):
        with rasterio.open(tmp_path / out) as ds:
            assert ds.crs.to_epsg() == 32633 and ds.transform.a > 0


def test_memory_option_does_not_leak_into_the_process(tmp_path, monkeypatch):
    import os

    from fractalgeo_rs._validation import MAX_MEMORY_ENV

    monkeypatch.delenv(MAX_MEMORY_ENV, raising=False)
    assert main(["synth", str(tmp_path / "a.npy"), "--hurst", "0.7", "--size", "16", "16", "--max-memory", "1G"]) == 0
    assert MAX_MEMORY_ENV not in os.environ
