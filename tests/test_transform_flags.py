"""Flag layer of ``fractal_transform(..., return_fit=True)`` and the
out-of-range warning of the plain call (docs/transform.md)."""
from __future__ import annotations

import pickle
import re
import warnings

import numpy as np
import pytest

import fractalgeo_rs as fg
from fractalgeo_rs.transform import FLAGS, TransformFit
from fractals import spectral_surface


def _noise(n=60, seed=0):
    return np.random.default_rng(seed).standard_normal((n, n))


def test_square_increments_of_a_bilinear_surface_are_below_two():
    # z = i j: every square increment at dilation u is u^2, so the power-2
    # variation grows as u^4, H = 2 and D = 3 - 2 = 1 exactly
    i, j = np.indices((40, 40)).astype(float)
    out = fg.fractal_transform(i * j, 9, method="square", return_fit=True)
    d, r2 = out  # still unpacks as a pair
    assert isinstance(out, TransformFit) and len(out) == 2
    ok = np.isfinite(d)
    assert ok.sum() > 1000
    np.testing.assert_allclose(d[ok], 1.0, atol=1e-5)
    assert np.all(out.flags[ok] == FLAGS["below_2"])
    assert np.all(out.flags[~ok] == FLAGS["too_few_valid"])
    assert out.flags.dtype == np.uint8 and out.flags.shape == d.shape


def test_white_noise_variogram_map_flags_and_warns_with_the_fraction():
    z = _noise()
    out = fg.fractal_transform(z, 9, method="variogram", return_fit=True)
    d = out[0]
    above = np.isfinite(d) & (d > 3 + 1e-6)
    assert 0.2 < above.mean() < 0.8  # white noise: D scatters about 3
    assert np.array_equal(out.flags == FLAGS["above_3"], above)
    assert np.all(out.flags[np.isfinite(d) & ~above] == 0)
    with pytest.warns(fg.FractalRangeWarning, match="above 3") as rec:
        plain = fg.fractal_transform(z, 9, method="variogram")
    np.testing.assert_array_equal(plain, d)
    msg = str(rec[0].message)
    pct = float(re.search(r"D is above 3 on ([\d.]+) % of the valid windows", msg).group(1))
    assert msg.startswith("variogram: D is above 3 on ") and "outside [2, 3]" not in msg
    assert pct == pytest.approx(100 * above[np.isfinite(d)].mean(), abs=0.05)


def test_no_warning_with_return_fit_or_in_range():
    z = _noise()
    with warnings.catch_warnings():
        warnings.simplefilter("error", fg.FractalRangeWarning)
        fg.fractal_transform(z, 9, method="variogram", return_fit=True)
        d = fg.fractal_transform(spectral_surface(64, 0.5, 1), 17, method="variogram")
        assert np.nanmin(d) >= 2 - 1e-6 and np.nanmax(d) <= 3 + 1e-6


def test_missing_windows_are_flagged_too_few_valid():
    z = _noise(50)
    z[:30, :30] = np.nan
    out = fg.fractal_transform(z, 9, method="madogram", return_fit=True)
    nan = np.isnan(out[0])
    assert nan[:20, :20].all()
    assert np.array_equal((out.flags & FLAGS["too_few_valid"]) > 0, nan)


def test_gls_windows_pinned_on_white_noise_are_flagged():
    from fractalgeo_rs.dimension.gls import H_GRID

    z = _noise(40, seed=3)
    with warnings.catch_warnings():  # with return_fit the flags carry it: no warning, as for every method
        warnings.simplefilter("error", fg.FractalRangeWarning)
        out = fg.fractal_transform(z, 17, method="gls", return_fit=True)
    d = out[0]
    pinned = np.abs(d - (3 - H_GRID[0])) <= 1e-4
    assert pinned.mean() > 0.3  # rougher than any fBm: H at the grid's lower end
    assert np.array_equal((out.flags & FLAGS["pinned"]) > 0, pinned)


def test_params_record_the_z_scale_used():
    z = _noise(40) * 3.0
    out = fg.fractal_transform(z, 9, method="mass", step=2, return_fit=True)
    assert out.params == {"method": "mass", "window_size": 9, "step": 2,
                          "z_scale": pytest.approx(fg.transform.default_z_scale(z)), "z_units": "image units per pixel"}
    out = fg.fractal_transform(z, 9, method="mass", z_scale=0.5, return_fit=True)
    assert out.params["z_scale"] == 0.5
    assert fg.fractal_transform(z, 9, method="variogram", return_fit=True).params["z_scale"] is None
    back = pickle.loads(pickle.dumps(out))
    assert back.params == out.params and np.array_equal(back.flags, out.flags)
    np.testing.assert_array_equal(back[0], out[0])


def test_dask_and_xarray_flags_equal_in_memory():
    da = pytest.importorskip("dask.array")
    xr = pytest.importorskip("xarray")
    z = _noise(64)
    ref = fg.fractal_transform(z, 9, method="variogram", return_fit=True)
    lazy = fg.fractal_transform(da.from_array(z, chunks=32), 9, method="variogram", return_fit=True)
    assert isinstance(lazy.flags, da.Array)
    np.testing.assert_array_equal(lazy.flags.compute(), ref.flags)
    xa = xr.DataArray(z, dims=("y", "x"), coords={"y": np.arange(64), "x": np.arange(64) * 2.0})
    xo = fg.fractal_transform(xa, 9, method="variogram", return_fit=True)
    assert isinstance(xo.flags, xr.DataArray) and xo.flags.name == "fractal_flags"
    np.testing.assert_array_equal(xo.flags.values, ref.flags)
    assert xo.flags.attrs["flag_meanings"] == "below_2 above_3 pinned too_few_valid"
    np.testing.assert_array_equal(xo.flags.x.values, xa.x.values)


def test_gls_pinned_windows_warn_without_return_fit():
    with pytest.warns(fg.FractalRangeWarning, match=r"% of the windows are pinned at the lower end"):
        fg.fractal_transform(_noise(40, seed=3), 17, method="gls")
