"""Fractal resampling (fractalgeo_rs.fractal_resample)."""
import os
import warnings

import numpy as np
import pytest

import fractalgeo_rs as fg
from fractalgeo_rs.dem import _resample as R
from fractalgeo_rs.dem import resample_analysis

DATA = os.path.join(os.path.dirname(__file__), "data")


def lag1(z):
    return 0.5 * (np.nanmean(np.diff(z, axis=0) ** 2) + np.nanmean(np.diff(z, axis=1) ** 2))


def hurst_lags(z, lags=range(1, 9)):
    lags = np.array(list(lags))
    g = [0.5 * (np.nanmean((z[k:] - z[:-k]) ** 2) + np.nanmean((z[:, k:] - z[:, :-k]) ** 2))
         for k in lags]
    return np.polyfit(np.log(lags), np.log(g), 1)[0] / 2


def dense_kriging(pts, vals, x0, h):
    """Ordinary (intrinsic) kriging of fBm with gamma(d) = d^(2H)/2, all data."""
    d = np.linalg.norm(pts[:, None] - pts[None], axis=-1)
    n = len(pts)
    a = np.ones((n + 1, n + 1))
    a[:n, :n] = 0.5 * d ** (2 * h)
    a[n, n] = 0.0
    g0 = 0.5 * np.linalg.norm(pts - x0, axis=1) ** (2 * h)
    w = np.linalg.solve(a, np.append(g0, 1.0))[:n]
    mean = w @ vals
    var = 2 * w @ g0 - w @ (0.5 * d ** (2 * h)) @ w
    return mean, var


@pytest.mark.parametrize("h", [0.3, 0.7])
def test_conditioning_matches_dense_kriging(h):
    """One level (factor 2) on a 9 x 9 fBm: mean and variance at a new
    diamond point and a square point over 1500 seeds, against kriging given
    all 81 coarse samples. The kernel conditions on 16-24 samples (the square
    step and later phases on random new samples): tolerance 4 standard
    errors plus 3 % of the conditional sd for the mean, 8 % for the
    variance."""
    z = fg.fbm_surface(9, h, method="exact", seed=11)
    ii, jj = np.indices(z.shape)
    pts = np.stack([ii.ravel(), jj.ravel()], 1).astype(float)
    runs = np.stack([fg.fractal_resample(z, 2, hurst=h, sigma=1.0, seed=s)
                     for s in range(1500)])
    for fine, x0 in (((9, 9), (4.5, 4.5)), ((8, 9), (4.0, 4.5))):
        m, v = dense_kriging(pts, z.ravel(), np.array(x0), h)
        x = runs[:, fine[0], fine[1]]
        se = np.sqrt(v / len(x))
        assert abs(x.mean() - m) < 4 * se + 0.03 * np.sqrt(v), (fine, x.mean(), m)
        assert abs(x.var() / v - 1) < 0.08, (fine, x.var(), v)


def dense_conditional_cov(pts, targets, h):
    """Covariance of fBm (gamma(d) = d^(2H)/2) at ``targets`` given its values
    at ``pts`` (the first point is taken as the origin, where fBm is 0)."""
    def cov(p, q):
        n = lambda x: np.linalg.norm(x, axis=-1) ** (2 * h)  # noqa: E731
        return 0.5 * (n(p)[:, None] + n(q)[None] - n(p[:, None] - q[None]))

    p, t = pts[1:] - pts[0], targets - pts[0]
    ct = cov(t, p)
    return cov(t, t) - ct @ np.linalg.solve(cov(p, p), ct.T)


def test_neighbouring_new_samples_have_the_conditional_correlation():
    """One level on a 9 x 9 fBm of H = 0.9 over 3000 seeds: the correlation
    of neighbouring new samples of the same step (diamond: diagonal
    neighbours, true -0.07; square: edge midpoints one coarse cell apart,
    true -0.15 and +0.10) and of a diamond and a square sample (+0.38)
    against the conditional covariance given all 81 coarse samples (dense
    kriging); independent residuals within a step give about 0 for the
    first two (measured +0.02, -0.04). Tolerance 0.05 (3 standard errors)."""
    h = 0.9
    z = fg.fbm_surface(9, h, method="exact", seed=11)
    ii, jj = np.indices(z.shape)
    pts = np.stack([ii.ravel(), jj.ravel()], 1).astype(float)
    fine = [(9, 9), (11, 11), (8, 9), (8, 11), (10, 9)]
    k = dense_conditional_cov(pts, np.array(fine, float) / 2, h)
    runs = np.stack([fg.fractal_resample(z, 2, hurst=h, sigma=1.0, seed=s)
                     for s in range(3000)])
    e = np.cov(np.stack([runs[:, a, b] for a, b in fine]))
    r_true = k / np.sqrt(np.outer(np.diag(k), np.diag(k)))
    r_emp = e / np.sqrt(np.outer(np.diag(e), np.diag(e)))
    for a, b in ((0, 1), (2, 3), (2, 4), (0, 2)):
        assert abs(r_emp[a, b] - r_true[a, b]) < 0.05, (fine[a], fine[b], r_emp[a, b], r_true[a, b])
    np.testing.assert_allclose(np.diag(e) / np.diag(k), 1, atol=0.08)


def test_point_keeps_samples_and_threads():
    z = fg.fbm_surface(65, 0.6, method="exact", seed=2)
    a = fg.fractal_resample(z, 4, seed=3, n_threads=1)
    b = fg.fractal_resample(z, 4, seed=3, n_threads=2)
    assert a.shape == (257, 257)
    assert np.array_equal(a, b)
    assert np.array_equal(a[::4, ::4], z)
    c = fg.fractal_resample(z, 4, seed=4)
    assert not np.array_equal(a, c)


def test_area_keeps_block_means():
    z = fg.fbm_surface(64, 0.5, method="exact", seed=2) * 100 + 1000
    for f in (2, 4, 8):
        out = fg.fractal_resample(z, f, hurst=0.5, sigma=3.0, support="area", seed=1)
        assert out.shape == (64 * f, 64 * f)
        m = out.reshape(64, f, 64, f).mean(axis=(1, 3))
        np.testing.assert_allclose(m, z, rtol=1e-9)


@pytest.mark.parametrize("h", [0.3, 0.7])
def test_statistics_on_exact_fbm_point(h):
    """Truth subsampled by 2 and 4, resampled back with hurst='local' and
    model='fbm' (the default's inner scale of at least one output cell
    makes fBm smoother below the coarse cell by design; the 2048^2 table of
    docs/resampling.md comes from benches/)."""
    t = fg.fbm_surface(385, h, method="exact", seed=5)
    for f in (2, 4):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            o = fg.fractal_resample(t[::f, ::f], f, seed=1, model="fbm")
        assert abs(lag1(o) / lag1(t) - 1) < 0.05
        assert abs(hurst_lags(o) - hurst_lags(t)) < 0.03
        assert fg.validate_surface(o).crease_ratio < 1.1


def test_mean_only_below_min_scale():
    z = fg.fbm_surface(33, 0.7, method="exact", seed=2)
    a = fg.fractal_resample(z, 4, hurst=0.7, sigma=1.0, seed=1, cell_size=10.0, min_scale=0.0)
    b = fg.fractal_resample(z, 4, hurst=0.7, sigma=1.0, seed=1, cell_size=10.0, min_scale=4.0)
    m = fg.fractal_resample(z, 4, hurst=0.7, sigma=0.0, seed=1)
    m2 = fg.fractal_resample(z, 4, hurst=0.7, sigma=1.0, seed=9, cell_size=10.0, min_scale=100)
    assert np.array_equal(m, m2)  # no level has detail: the conditional mean
    # First level (5 m cells) has detail, the second (2.5 m) does not.
    assert not np.array_equal(a, b) and not np.array_equal(b[::2, ::2], m[::2, ::2])
    c = fg.fractal_resample(z, 2, hurst=0.7, sigma=1.0, seed=1)
    assert np.array_equal(b[::2, ::2], c)


def test_holes_stay_holes():
    z = fg.fbm_surface(40, 0.5, method="exact", seed=2)
    z[10:14, 20:25] = -9999.0
    out = fg.fractal_resample(z, 2, hurst=0.5, sigma=1.0, seed=1, nodata=-9999.0)
    hole = np.isnan(out)
    assert hole[20:27, 40:49].all()
    # Holes grow by factor - 1 = one fine cell (tests/test_resample_model.py: exactly).
    assert not hole[:19].any() and not hole[28:].any()
    assert not hole[:, :39].any() and not hole[:, 50:].any()
    area = fg.fractal_resample(z, 2, hurst=0.5, sigma=1.0, seed=1, nodata=-9999.0,
                               support="area")
    assert np.array_equal(np.isnan(area), np.kron(z == -9999.0, np.ones((2, 2))).astype(bool))
    assert z[10, 20] == -9999.0  # input not modified


def test_dask_equals_memory_for_any_chunking():
    da = pytest.importorskip("dask.array")
    z = fg.fbm_surface(70, 0.6, method="exact", seed=3)
    z[30:33, 5:9] = np.nan
    for support in ("point", "area"):
        ref = fg.fractal_resample(z, 4, seed=2, support=support, window_size=9)
        for chunks in ((20, 30), (70, 13), (35, 70)):
            out = fg.fractal_resample(da.from_array(z, chunks=chunks), 4, seed=2,
                                      support=support, window_size=9)
            got = out.compute()
            assert got.shape == ref.shape
            np.testing.assert_array_equal(got, ref)


def test_xarray_coords():
    xr = pytest.importorskip("xarray")
    z = fg.fbm_surface(16, 0.6, method="exact", seed=3)
    y = 1000.0 - 30.0 * (np.arange(16) + 0.5)
    x = 500.0 + 30.0 * (np.arange(16) + 0.5)
    a = xr.DataArray(z, dims=("y", "x"), coords={"y": y, "x": x}, attrs={"units": "m"})
    p = fg.fractal_resample(a, 2, hurst=0.5, sigma=1.0, seed=1)
    assert p.shape == (31, 31) and p.attrs["units"] == "m"
    np.testing.assert_allclose(p.x.values[::2], x)
    q = fg.fractal_resample(a, 2, hurst=0.5, sigma=1.0, seed=1, support="area")
    np.testing.assert_allclose(q.x.values, 500.0 + 15.0 * (np.arange(32) + 0.5))
    np.testing.assert_allclose(q.y.values, 1000.0 - 15.0 * (np.arange(32) + 0.5))


def test_analysis_matches_a_direct_window_fit():
    """H and sigma at a few pixels against the pooled increments (first
    sample inside the window) of the windows cut out by hand: the window
    sums and counts at the nodes (multiples of STEP) around the pixel,
    interpolated bilinearly."""
    from fractalgeo_rs.dem._resample import STEP

    z = fg.fbm_surface(48, 0.6, method="exact", seed=4)
    z[5, 7] = np.nan
    a = resample_analysis(z, window_size=9)

    def window_sums(p, q, k):
        s = c = 0.0
        for i in range(max(p - 4, 0), min(p + 5, 48)):
            for j in range(max(q - 4, 0), min(q + 5, 48)):
                for di, dj in ((k, 0), (0, k)):
                    if i + di < 48 and j + dj < 48:
                        d = z[i + di, j + dj] - z[i, j]
                        if np.isfinite(d):
                            s, c = s + d * d, c + 1
        return np.array([s, c])

    for p, q in ((16, 24), (0, 0), (20, 20), (6, 8), (47, 30)):
        g = []
        for k in (1, 2):
            p0, q0 = p // STEP * STEP, q // STEP * STEP
            u, v = (p - p0) / STEP, (q - q0) / STEP
            sc = sum(wr * wc * window_sums(p0 + dr, q0 + dc, k)
                     for dr, wr in ((0, 1 - u), (STEP, u)) for dc, wc in ((0, 1 - v), (STEP, v)))
            g.append(sc[0] / sc[1])
        h = np.clip(0.5 * np.log2(g[1] / g[0]), 0.05, 0.95)
        assert abs(a.hurst[p, q] - h) < 1e-9, (p, q)
        assert abs(a.sigma[p, q] - np.sqrt(g[0])) < 1e-9


@pytest.mark.parametrize("name", ["bigtujunga_30m_crop256.npy", "n44e007_alps_crop256.npy"])
def test_real_dem_roughness_default_between_bicubic_and_fbm(name):
    """Coarsened by 4 and resampled back: the grid-aligned bicubic is too
    smooth, constant-H fBm too rough below the coarse cell, the default
    (inner scale) close to the real lag-1 variance and curvature."""
    dem = np.load(os.path.join(DATA, name)).astype(float)
    n = (dem.shape[0] - 1) // 4 * 4 + 1
    real = dem[:n, :n]
    c = real[::4, ::4]
    o = fg.fractal_resample(c, 4, seed=1)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        fb = fg.fractal_resample(c, 4, seed=1, model="fbm")
    b = R._bicubic_aligned(c, 4)

    def lap(z):
        return np.std(z[1:-1, 2:] + z[1:-1, :-2] + z[2:, 1:-1] + z[:-2, 1:-1] - 4 * z[1:-1, 1:-1])

    # Measured (docs/resampling.md, 256^2 crops): bicubic 0.79-0.88 of the
    # real lag-1 variance, fBm 1.4-1.6, the default 0.9-1.0.
    assert lag1(b) < 0.9 * lag1(real)
    assert lag1(fb) > 1.2 * lag1(real)
    assert abs(lag1(o) / lag1(real) - 1) < 0.15
    assert abs(lap(o) / lap(real) - 1) < 0.25


@pytest.mark.parametrize("kw, exc, word", [
    (dict(factor=3), ValueError, "factor"),
    (dict(factor=1), ValueError, "factor"),
    (dict(factor=2.0), TypeError, "factor"),
    (dict(hurst=1.2), ValueError, "hurst"),
    (dict(hurst=0.0), ValueError, "hurst"),
    (dict(sigma=-1.0), ValueError, "sigma"),
    (dict(min_scale=-1.0), ValueError, "min_scale"),
    (dict(cell_size=float("inf")), ValueError, "cell_size"),
    (dict(support="block"), ValueError, "support"),
    (dict(window_size=4), ValueError, "window_size"),
    (dict(seed=-1), ValueError, "seed"),
])
def test_bad_input(kw, exc, word):
    z = np.zeros((16, 16))
    kw = dict(kw)
    f = kw.pop("factor", 2)
    with pytest.raises(exc, match=f"^{word}"):
        fg.fractal_resample(z, f, **kw)


def test_bad_dem():
    with pytest.raises(ValueError, match="^dem"):
        fg.fractal_resample(np.zeros((3, 10)), 2, hurst=0.5, sigma=1.0)
    with pytest.raises(ValueError, match="^dem"):
        fg.fractal_resample(np.full((8, 8), np.nan), 2, hurst=0.5, sigma=1.0)
    with pytest.raises(ValueError, match="^hurst"):
        fg.fractal_resample(np.zeros((8, 8)), 2, hurst=np.zeros((4, 4)), sigma=1.0)
    with pytest.raises(MemoryError, match="^factor"):
        fg.fractal_resample(np.zeros((64, 64)), 4096, hurst=0.5, sigma=1.0)


def test_docstring_examples_run():
    import doctest

    from fractalgeo_rs.dem import _resample, _resample_api

    attempted = 0
    for mod in (_resample, _resample_api):
        res = doctest.testmod(mod, optionflags=doctest.ELLIPSIS)
        assert res.failed == 0
        attempted += res.attempted
    assert attempted >= 4


@pytest.mark.slow
def test_dask_local_analysis_with_chunks_smaller_than_its_halo():
    """The local analysis needs a halo of window // 2 + 2; chunks smaller
    than that are merged first, so any chunking gives the in-memory result."""
    da = pytest.importorskip("dask.array")
    z = fg.fbm_surface((64, 64), 0.6, method="exact", seed=3)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for chunks, window in [(10, 33), ((5, 7), 9), ((61, 4), 9)]:
            ref = fg.fractal_resample(z, 2, seed=1, window_size=window)
            got = fg.fractal_resample(da.from_array(z, chunks=chunks), 2, seed=1, window_size=window).compute()
            np.testing.assert_array_equal(got, ref)


def test_window_larger_than_twice_the_dem_is_a_value_error():
    z = fg.fbm_surface((33, 33), 0.5, method="exact", seed=1)
    with pytest.raises(ValueError, match="^window"):
        fg.fractal_resample(z, 2, window_size=10**6 + 1)


@pytest.mark.parametrize("h", [0.5, 0.7])
def test_statistics_on_exact_fbm_area(h):
    """Block means of an exact fBm (2 x 2 points) resampled back by 2 with
    the joint draw of the four children: block means kept, H over lags 1-8
    within 0.03 of the truth, lag-1 variance within 8 % (measured 3.5-6 %
    high on 512^2, docs/resampling.md)."""
    t = fg.fbm_surface(512, h, method="exact", seed=5)
    c = t.reshape(256, 2, 256, 2).mean((1, 3))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        o = fg.fractal_resample(c, 2, seed=1, support="area", model="fbm")
    np.testing.assert_allclose(o.reshape(256, 2, 256, 2).mean((1, 3)), c, rtol=1e-9, atol=1e-12)
    assert abs(hurst_lags(o) - hurst_lags(t)) < 0.03
    assert abs(lag1(o) / lag1(t) - 1) < 0.08


def test_analysis_window_size_and_deprecated_window_alias():
    """``ResampleAnalysis.window_size`` is the window side; the old
    attribute name still reads the same value, with a DeprecationWarning."""
    z = fg.fbm_surface(32, 0.5, method="exact", seed=1)
    a = resample_analysis(z, window_size=9)
    assert a.window_size == 9
    with pytest.warns(DeprecationWarning, match="window_size"):
        assert a.window == 9
    _, an = fg.fractal_resample(z, 2, seed=1, window_size=7, return_analysis=True)
    assert an.window_size == 7
