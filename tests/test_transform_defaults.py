"""The default height unit of the box and mass maps (z_scale="auto")."""
import math

import numpy as np
import pytest

import fractalgeo_rs as fg
from fractalgeo_rs.transform import default_z_scale


def test_default_z_scale_closed_forms():
    i, j = np.indices((50, 50))
    # row steps 4, column steps 3, equally many: median 3.5
    assert default_z_scale(3.0 * i + 4.0 * j) == pytest.approx(1.4826 * 3.5, rel=1e-12)
    assert default_z_scale(np.full((20, 20), 7.0)) == 1.0
    # more than half of the steps 0 (quantised): sqrt(pi/2) mean |step|
    z = np.zeros((10, 10))
    z[:, 5:] = 2.0  # one step of 2 per row, none per column
    inc = np.concatenate([np.abs(np.diff(z, axis=1)).ravel(), np.abs(np.diff(z, axis=0)).ravel()])
    assert default_z_scale(z) == pytest.approx(math.sqrt(math.pi / 2) * inc.mean(), rel=1e-12)


def test_default_z_scale_skips_missing_and_matches_dask():
    da = pytest.importorskip("dask.array")
    rng = np.random.default_rng(0)
    z = np.cumsum(rng.normal(size=(300, 300)), axis=1)
    ref = 1.4826 * np.median(np.concatenate([np.abs(np.diff(z, axis=1)).ravel(), np.abs(np.diff(z, axis=0)).ravel()]))
    assert default_z_scale(z) == pytest.approx(ref, rel=1e-12)
    holes = z.copy()
    holes[10:20, 10:20] = -9999.0
    with_nan = z.copy()
    with_nan[10:20, 10:20] = np.nan
    assert default_z_scale(holes, nodata=-9999.0) == default_z_scale(with_nan)
    assert default_z_scale(da.from_array(z, chunks=70)) == default_z_scale(z)
    big = np.zeros((4100, 10))  # sampled every 3rd line: ceil(4100 / 2048)
    big[::2] = 1.0
    assert default_z_scale(big) == default_z_scale(da.from_array(big, chunks=1000))


@pytest.mark.parametrize("method", ["mass", "dbc", "blanket"])
def test_auto_is_the_explicit_unit_and_is_recorded(method):
    xr = pytest.importorskip("xarray")
    z = fg.fbm_surface((64, 64), 0.5, seed=3) * 40.0
    zs = default_z_scale(z)
    auto = fg.fractal_transform(z, 17, method=method)
    assert np.array_equal(auto, fg.fractal_transform(z, 17, method=method, z_scale=zs), equal_nan=True)
    out = fg.fractal_transform(xr.DataArray(z, dims=("y", "x")), 17, method=method)
    assert out.attrs["z_scale"] == zs and out.attrs["fractal_method"] == method
    # an explicit unit is used as given
    assert out.attrs["z_scale"] != 1.0
    one = fg.fractal_transform(xr.DataArray(z, dims=("y", "x")), 17, method=method, z_scale=1.0)
    assert one.attrs["z_scale"] == 1.0


def test_default_mass_map_is_informative_on_a_real_dem():
    dem, _ = fg.data.srtm_alps()
    d = fg.fractal_transform(dem.astype(float), 33)
    f = d[np.isfinite(d)]
    _, cnt = np.unique(f, return_counts=True)
    out = np.mean((f < 2) | (f > 3))
    assert cnt.max() / f.size < 0.05 and out < 0.1
    # one metre per box step: out of range almost everywhere
    f1 = fg.fractal_transform(dem.astype(float), 33, z_scale=1.0)
    assert np.mean((f1 < 2) | (f1 > 3)) > 0.9


def test_bad_z_scale():
    with pytest.raises(TypeError, match="z_scale"):
        fg.fractal_transform(np.zeros((20, 20)), 9, z_scale="mad")
    with pytest.raises(ValueError, match="z_scale"):
        fg.fractal_transform(np.zeros((20, 20)), 9, z_scale=-1.0)
