"""Speckle: moments and distribution of L-look intensity (Gamma(L, sigma0 / L)),
identical output for any thread count and Dask chunking, bad input."""
import numpy as np
import pytest
from scipy import stats

import fractalgeo_rs as fg


@pytest.mark.parametrize("looks", [1, 4, 7])
def test_moments_and_distribution(looks):
    s0 = 0.3
    n = 1000
    y = fg.radar.speckle(np.full((n, n), s0), looks=looks, seed=5).ravel()
    m, v = y.mean(), y.var(ddof=1)
    var = s0 ** 2 / looks
    se_m = np.sqrt(var / y.size)
    # Var of the sample variance: (mu4 - var^2) / n, Gamma's excess kurtosis 6 / L
    se_v = var * np.sqrt((2 + 6 / looks) / y.size)
    assert abs(m - s0) < 3 * se_m, (m, se_m)
    assert abs(v - var) < 3 * se_v, (v, se_v)
    ks = stats.kstest(y, stats.gamma(looks, scale=s0 / looks).cdf)
    assert ks.pvalue > 1e-3, ks


def test_single_look_amplitude_is_rayleigh():
    y = fg.radar.speckle(np.full((400, 500), 2.0), looks=1, seed=9).ravel()
    ks = stats.kstest(np.sqrt(y), stats.rayleigh(scale=1.0).cdf)  # E[A^2] = 2 = 2 s^2
    assert ks.pvalue > 1e-3


def test_same_for_any_threads_and_chunks():
    img = np.abs(fg.fbm_surface(97, 0.6, seed=1)) + 0.1
    ref = fg.radar.speckle(img, looks=3, seed=2, n_threads=1)
    for t in (2, 4):
        np.testing.assert_array_equal(fg.radar.speckle(img, looks=3, seed=2, n_threads=t), ref)
    da = pytest.importorskip("dask.array")
    for chunks in ((40, 33), (97, 10), (13, 97)):
        lazy = fg.radar.speckle(da.from_array(img, chunks=chunks), looks=3, seed=2)
        np.testing.assert_array_equal(lazy.compute(), ref)
    assert not np.array_equal(fg.radar.speckle(img, looks=3, seed=3), ref)


def test_nan_kept_and_input_untouched():
    img = np.array([[1.0, np.nan], [0.0, 2.0]])
    keep = img.copy()
    y = fg.radar.speckle(img, looks=2, seed=1)
    assert np.isnan(y[0, 1]) and y[1, 0] == 0 and np.all(y[[0, 1], [0, 1]] > 0)
    np.testing.assert_array_equal(img, keep)


@pytest.mark.parametrize("kw, err, match", [
    (dict(looks=0), ValueError, "looks"),
    (dict(looks=1.5), TypeError, "looks"),
    (dict(seed=-1), ValueError, "seed"),
])
def test_bad_input(kw, err, match):
    with pytest.raises(err, match=match):
        fg.radar.speckle(np.ones((3, 3)), **kw)


def test_negative_intensity():
    with pytest.raises(ValueError, match="intensity"):
        fg.radar.speckle(-np.ones((3, 3)), looks=1, seed=1)
    with pytest.raises(ValueError, match="intensity"):
        fg.radar.speckle(np.ones(3), looks=1, seed=1)
