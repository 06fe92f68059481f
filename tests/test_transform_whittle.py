"""Debiased Whittle map: every window equals fractalgeo_rs.whittle (square
filter) on the NaN-padded window, thread/step/Dask invariance, accuracy on
exact fBm, errors."""
import numpy as np
import pytest

import fractalgeo_rs as fg


def padded_windows(z, w):
    h = w // 2
    zp = np.pad(z.astype(float), h, constant_values=np.nan)
    return np.lib.stride_tricks.sliding_window_view(zp, (w, w))


def holed_fbm(shape, hurst, seed):
    z = fg.fbm_surface(shape, hurst, method="exact", seed=seed) * 7.0
    rng = np.random.default_rng(seed)
    z[rng.random(shape) < 0.01] = np.nan
    z[20:24, 30:37] = np.nan
    return z


@pytest.mark.slow
@pytest.mark.parametrize("w, hurst", [(9, 0.3), (17, 0.7)])
def test_map_equals_whittle_on_every_window(w, hurst):
    """All windows of a small image with holes: interior, edge, corner and
    holed windows (each with its own model), dimension and standard error."""
    z = holed_fbm((44, 52), hurst, 3)
    d, se = fg.fractal_transform(z, w, method="whittle", return_fit=True)
    assert d.dtype == np.float32 and d.shape == z.shape
    win = padded_windows(z, w)
    ref = np.full(z.shape, np.nan)
    ref_se = np.full(z.shape, np.nan)
    for i in range(z.shape[0]):
        for j in range(z.shape[1]):
            a = win[i, j]
            if np.count_nonzero(~np.isnan(a)) < 0.5 * w * w:
                continue
            fit = fg.whittle(a, filter="square")
            ref[i, j], ref_se[i, j] = fit.dimension, fit.stderr
    assert np.array_equal(np.isnan(d), np.isnan(ref))
    ok = ~np.isnan(ref)
    assert ok.sum() > 0.8 * z.size
    # the map's cubic search vs fractalgeo_rs.whittle's Brent search
    assert np.max(np.abs(d[ok] - ref[ok])) < 2e-4
    # standard errors: the cubic's curvature vs a finite difference of the
    # contrast (step 1e-3); away from the search bounds
    inner = ok & (ref > 2.01) & (ref < 2.99)
    assert np.allclose(se[inner], ref_se[inner], rtol=1e-2)


def test_real_sar_windows():
    vv, _ = fg.data.sentinel1_vv_db()
    z = vv[100:140, 200:236]
    d = fg.fractal_transform(z, 11, method="whittle")
    win = padded_windows(z, 11)
    for i, j in [(2, 3), (5, 30), (20, 18), (37, 33), (12, 2)]:  # edge windows at least half valid
        assert d[i, j] == pytest.approx(fg.whittle(win[i, j], filter="square").dimension, abs=2e-4)


def test_mean_local_dimension_is_three_minus_h():
    """Exact fBm: the mean over the interior is 3 - H. Tolerance 0.02: four
    times the standard error of a mean over ~(256/33)^2 = 60 independent
    windows with sd 0.04 (docs/transform.md)."""
    for hurst in (0.4, 0.8):
        z = fg.fbm_surface((256, 256), hurst, method="exact", seed=11)
        d = fg.fractal_transform(z, 33, method="whittle", step=4)
        inner = d[5:-5, 5:-5]
        assert np.isfinite(inner).all()
        assert abs(float(inner.mean()) - (3 - hurst)) < 0.02
        assert 0.02 < float(inner.std()) < 0.07


def test_step_threads_input_untouched():
    z = holed_fbm((60, 50), 0.5, 1).astype(np.float32)
    before = z.copy()
    ref = fg.fractal_transform(z, 13, method="whittle", n_threads=1, return_fit=True)
    out = fg.fractal_transform(z, 13, method="whittle", n_threads=2, return_fit=True)
    assert all(np.array_equal(a, b, equal_nan=True) for a, b in zip(out, ref))
    s3 = fg.fractal_transform(z, 13, method="whittle", step=3)
    assert np.array_equal(s3, ref[0][::3, ::3], equal_nan=True)
    assert np.array_equal(z, before, equal_nan=True)


@pytest.mark.slow
def test_dask_equals_in_memory():
    da = pytest.importorskip("dask.array")
    z = holed_fbm((70, 64), 0.6, 2)
    ref = fg.fractal_transform(z, 11, method="whittle")
    for chunks in [(35, 32), (70, 20), (4, 4)]:
        for step in (1, 2):
            out = fg.fractal_transform(da.from_array(z, chunks=chunks), 11, method="whittle", step=step).compute()
            assert np.allclose(out, ref[::step, ::step], atol=1e-6, equal_nan=True), (chunks, step)


def test_plane_constant_and_nodata():
    i, j = np.indices((40, 40))
    plane = 0.3 * i - 0.2 * j + 5
    assert np.isnan(fg.fractal_transform(plane, 9, method="whittle")).all()
    assert np.isnan(fg.fractal_transform(np.full((40, 40), 2.0), 9, method="whittle")).all()
    z = fg.fbm_surface((40, 40), 0.5, method="exact", seed=4)
    z_nd = z.copy()
    z_nd[10:15, 10:15] = -9999.0
    z_nan = z.copy()
    z_nan[10:15, 10:15] = np.nan
    a = fg.fractal_transform(z_nd, 9, method="whittle", nodata=-9999.0)
    b = fg.fractal_transform(z_nan, 9, method="whittle")
    assert np.array_equal(a, b, equal_nan=True)
    # a window with fewer than half its pixels valid is NaN (the corners)
    assert np.isnan(fg.fractal_transform(z, 17, method="whittle")[0, 0])


def test_bad_window():
    z = np.random.default_rng(0).normal(size=(30, 30))
    with pytest.raises(ValueError, match="window_size"):
        fg.fractal_transform(z, 5, method="whittle")
    with pytest.raises(ValueError, match="window_size"):
        fg.fractal_transform(z, 10, method="whittle")
