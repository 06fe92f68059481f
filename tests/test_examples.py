"""The worked examples in ``examples/`` run on bundled data and do what
their docs say."""
import os
import runpy

import numpy as np
import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


@pytest.fixture(scope="module")
def urban():
    pytest.importorskip("matplotlib")
    return runpy.run_path(os.path.join(ROOT, "examples", "urban_segmentation.py"))


def test_urban_segmentation_example_writes_its_figure(urban, tmp_path, capsys):
    out = tmp_path / "urban.png"
    urban["main"](["--out", str(out)])
    with open(out, "rb") as f:
        assert f.read(8) == b"\x89PNG\r\n\x1a\n"
    printed = capsys.readouterr().out
    assert "<- built-up" in printed and "Jaccard" in printed
    assert [p.name for p in tmp_path.iterdir()] == ["urban.png"]  # no temporary left


def test_urban_mask_is_bright_double_bounce_and_reproducible(urban):
    r = urban["built_up"]()
    m = r["mask"]
    # a class of the scene, neither empty nor most of it
    assert 0.05 < m.mean() < 0.4
    # built-up areas are bright in VV and co-polarised: both features of the
    # class lie well above the scene's (not only above the other classes')
    assert r["mean_vv"][m].mean() > r["mean_vv"].mean() + 2.0
    assert r["pol"][m].mean() > r["pol"].mean() + 1.5
    # the texture feature is part of the decision: the mask changes without it
    assert not np.array_equal(m, r["mask_without_dimension"])
    again = urban["built_up"]()
    assert np.array_equal(again["mask"], m)


def test_fractal_resampling_example(tmp_path, capsys):
    pytest.importorskip("matplotlib")
    mod = runpy.run_path(os.path.join(ROOT, "examples", "fractal_resampling.py"))
    out = tmp_path / "r.png"
    r = mod["main"](["--out", str(out)])
    with open(out, "rb") as f:
        assert f.read(8) == b"\x89PNG\r\n\x1a\n"
    assert "hillshade roughness" in capsys.readouterr().out
    # bicubic is smoother than the real DEM; the fractal resampling (inner-scale
    # model) is close to it: measured lag-1 0.77 and 0.91, hillshade roughness
    # 0.034, 0.050 against the real 0.048
    assert r["bicubic"]["lag1"] < 0.85 and abs(r["fractal"]["lag1"] - 1) < 0.15
    assert r["bicubic"]["roughness"] < 0.8 * r["real"]["roughness"]
    assert abs(r["fractal"]["roughness"] / r["real"]["roughness"] - 1) < 0.15
