"""Likelihood estimators of H on exact fBm: the debiased Whittle likelihood
(``fg.whittle``) and exact Gaussian maximum likelihood (``fg.fbm_mle``).

The expected periodogram is checked against a brute-force double sum over the
fBm covariance matrix written here (no code of the estimator involved) and
against the mean periodogram of simulated exact fields; accuracy tolerances
come from the spread measured in each test."""
import itertools

import numpy as np
import pytest

import fractalgeo_rs as fg
from fractalgeo_rs.dimension.likelihood import FILTERS_1D, FILTERS_2D, _Model, apply_filter, _periodogram


def _stencil(name, nd):
    f = (FILTERS_1D if nd == 1 else FILTERS_2D)[name]
    return np.array(list(f.keys())), np.array(list(f.values()), dtype=float)


def brute_expected_periodogram(shape, hurst, offsets, weights, g, spacing):
    """E|sum_x g(x) Y(x) exp(-i k.x)|^2 from the covariance matrix of fBm
    samples, Cov[Z(x), Z(y)] = (|x|^2H + |y|^2H - |x - y|^2H) / 2, and the
    filter as an explicit matrix: O(n^4), independent of the FFT route."""
    ext = offsets.max(axis=0)
    big = tuple(n + e for n, e in zip(shape, ext))
    cells = list(itertools.product(*[range(n) for n in big]))
    index = {c: i for i, c in enumerate(cells)}
    pts = np.array(cells, float) * np.asarray(spacing)
    r = np.sqrt((pts**2).sum(-1))
    d = np.sqrt(((pts[:, None] - pts[None]) ** 2).sum(-1))
    cov = 0.5 * (r[:, None] ** (2 * hurst) + r[None, :] ** (2 * hurst) - d ** (2 * hurst))
    out_cells = list(itertools.product(*[range(n) for n in shape]))
    F = np.zeros((len(out_cells), len(cells)))
    for i, c in enumerate(out_cells):
        for o, w in zip(offsets, weights):
            F[i, index[tuple(int(a) for a in np.add(c, o))]] += w
    cy = F @ cov @ F.T
    xy = np.array(out_cells, float)
    res = np.zeros(shape)
    for k in itertools.product(*[range(n) for n in shape]):
        e = np.exp(-2j * np.pi * (xy @ (np.array(k) / np.array(shape)))) * g.ravel()
        res[k] = np.real(np.conj(e) @ cy @ e)
    return res


@pytest.mark.parametrize(
    "shape, name, spacing",
    [((7,), "first", (1.0,)), ((7,), "second", (2.0,)), ((4, 5), "laplacian", (1.0, 1.0)),
     ((4, 5), "laplacian", (1.0, 2.5)), ((5, 4), "square", (1.0, 1.0)), ((4, 4), "rows", (0.5, 1.0)),
     ((4, 5), "columns", (1.0, 1.0))],
)
@pytest.mark.parametrize("hurst", [0.15, 0.5, 0.85])
def test_expected_periodogram_equals_brute_force_double_sum(shape, name, spacing, hurst):
    off, w = _stencil(name, len(shape))
    rng = np.random.default_rng(len(shape) * 10 + int(hurst * 100))
    g = rng.uniform(0.2, 1.0, shape)  # arbitrary taper with a gap
    g[(1,) * len(shape)] = 0.0
    g /= np.sqrt(np.sum(g**2))
    ours = _Model(shape, off, w, g, spacing).expected(hurst)
    ref = brute_expected_periodogram(shape, hurst, off, w, g, spacing)
    # two exact computations in float64: agreement to rounding
    assert np.max(np.abs(ours - ref)) <= 1e-11 * np.max(np.abs(ref))


@pytest.mark.parametrize("nd, hurst, name", [(1, 0.3, "first"), (2, 0.5, "laplacian"), (2, 0.8, "square")])
def test_expected_periodogram_equals_mean_periodogram_of_simulated_fbm(nd, hurst, name):
    # sigma = 1 in the synthesis, so the model with sigma^2 = 1 must match the
    # mean periodogram including its level
    m = 400
    n = 64 if nd == 1 else 16
    off, w = _stencil(name, nd)
    grams = []
    for s in range(m):
        z = fg.fbm(n, hurst, method="exact", seed=s) if nd == 1 else fg.fbm_surface((n, n), hurst, method="exact", seed=s)
        y = apply_filter(z, off, w)
        g = np.full(y.shape, 1.0 / np.sqrt(y.size))
        grams.append(_periodogram(y, g))
    grams = np.array(grams)
    expect = _Model(y.shape, off, w, g, (1.0,) * nd).expected(hurst)
    zscore = (grams.mean(axis=0) - expect) / (grams.std(axis=0, ddof=1) / np.sqrt(m))
    # one z-score per frequency (up to 256 of them, pairwise equal by symmetry)
    assert np.max(np.abs(zscore)) < 4.5, np.max(np.abs(zscore))
    assert abs(zscore.mean()) < 4.0 / np.sqrt(zscore.size / 2)


def _accuracy(fits, truth):
    h = np.array([f.extra["hurst"] for f in fits])
    se = np.array([f.stderr for f in fits])
    return h, se


@pytest.mark.parametrize("hurst", [0.2, 0.5, 0.8])
def test_whittle_profile_mean_within_four_standard_errors(hurst):
    fits = [fg.whittle(fg.fbm(1024, hurst, method="exact", seed=s)) for s in range(60)]
    h, se = _accuracy(fits, hurst)
    sd = h.std(ddof=1)
    assert abs(h.mean() - hurst) <= 4 * sd / np.sqrt(h.size), (h.mean(), sd)
    assert all(abs(f.dimension - (2 - f.extra["hurst"])) < 1e-12 for f in fits)
    # curvature standard error against the measured spread: 60 replicates
    # estimate sd within about 9 % (1 / sqrt(2 * 60)); allow 4 of those
    assert 0.64 < np.mean(se) / sd < 1.36, (np.mean(se), sd)


@pytest.mark.parametrize("hurst", [0.2, 0.5, 0.8])
def test_whittle_surface_mean_within_four_standard_errors(hurst):
    fits = [fg.whittle(fg.fbm_surface((64, 64), hurst, method="exact", seed=s)) for s in range(60)]
    h, se = _accuracy(fits, hurst)
    sd = h.std(ddof=1)
    assert abs(h.mean() - hurst) <= 4 * sd / np.sqrt(h.size), (h.mean(), sd)
    assert all(abs(f.dimension - (3 - f.extra["hurst"])) < 1e-12 for f in fits)
    assert 0.64 < np.mean(se) / sd < 1.36, (np.mean(se), sd)


@pytest.mark.slow
@pytest.mark.parametrize("hurst", [0.2, 0.5, 0.8])
def test_mle_surface_mean_within_four_standard_errors(hurst):
    fits = [fg.fbm_mle(fg.fbm_surface((12, 12), hurst, method="exact", seed=s)) for s in range(30)]
    h, se = _accuracy(fits, hurst)
    sd = h.std(ddof=1)
    assert abs(h.mean() - hurst) <= 4 * sd / np.sqrt(h.size), (h.mean(), sd)
    # 30 replicates estimate sd within about 13 %; allow 4 of those
    assert 0.5 < np.mean(se) / sd < 1.5, (np.mean(se), sd)


def test_mle_maximises_an_independent_gaussian_likelihood():
    from scipy.stats import multivariate_normal

    z = fg.fbm_surface((9, 8), 0.6, method="exact", seed=3)
    fit = fg.fbm_mle(z)
    i, j = np.indices(z.shape)
    pts = np.column_stack([i.ravel(), j.ravel()]).astype(float)
    u = z.ravel()[1:] - z.ravel()[0]
    x = pts[1:] - pts[0]

    def profile_loglik(h):
        r = np.linalg.norm(x, axis=1) ** (2 * h)
        cov = 0.5 * (r[:, None] + r[None, :] - np.linalg.norm(x[:, None] - x[None], axis=-1) ** (2 * h))
        s2 = u @ np.linalg.solve(cov, u) / u.size
        return multivariate_normal(np.zeros(u.size), s2 * cov).logpdf(u)

    grid = np.arange(0.05, 0.96, 0.01)
    best = grid[np.argmax([profile_loglik(h) for h in grid])]
    assert abs(best - fit.extra["hurst"]) <= 0.006
    # the estimate beats both grid neighbours
    ll = profile_loglik(fit.extra["hurst"])
    assert ll >= profile_loglik(fit.extra["hurst"] - 0.01) and ll >= profile_loglik(fit.extra["hurst"] + 0.01)


@pytest.mark.parametrize("func", [fg.whittle, fg.fbm_mle])
@pytest.mark.parametrize("nd", [1, 2])
def test_height_scale_and_offset_invariance_and_input_untouched(func, nd):
    z = fg.fbm(200, 0.4, method="exact", seed=5) if nd == 1 else fg.fbm_surface((16, 16), 0.7, method="exact", seed=5)
    keep = z.copy()
    a = func(z)
    assert np.array_equal(z, keep)
    for c, b in [(1e-3, 0.0), (250.0, -7.0), (-3.0, 1e4)]:
        f = func(c * z + b)
        assert f.extra["hurst"] == pytest.approx(a.extra["hurst"], abs=1e-6)
        assert f.extra["sigma2"] == pytest.approx(c**2 * a.extra["sigma2"], rel=1e-4)


def test_whittle_all_filters_accept_fbm_and_dispatcher_matches():
    z = fg.fbm_surface((64, 64), 0.5, method="exact", seed=2)
    for name in ("laplacian", "square", "first", "rows", "columns"):
        fit = fg.whittle(z, filter=name)
        assert abs(fit.extra["hurst"] - 0.5) < 0.1, name  # 5 measured SE (0.02 at 64²)
    assert fg.dimension(z, method="whittle").dimension == fg.whittle(z).dimension
    assert fg.dimension(z[:20, :20], method="mle").dimension == fg.fbm_mle(z[:20, :20]).dimension
    fit = fg.whittle(z)
    assert fit.range_selection == "model" and np.isnan(fit.slope)
    lo, hi = fit.ci95
    assert lo < fit.dimension < hi and hi - lo == pytest.approx(2 * 1.96 * fit.stderr, rel=1e-3)
    ax = fit.plot()
    assert len(ax.lines) == 2


def test_cell_size_sets_the_units_of_sigma2_not_h():
    # fbm_surface(cell_size=c): variogram sigma^2 (c |h|)^2H; told the same
    # cell size the estimator returns sigma^2 = 1 on average
    fits = [fg.whittle(fg.fbm_surface((64, 64), 0.6, method="exact", seed=s, cell_size=30.0), cell_size=30.0)
            for s in range(30)]
    s2 = np.array([f.extra["sigma2"] for f in fits])
    assert abs(s2.mean() - 1.0) <= 4 * s2.std(ddof=1) / np.sqrt(s2.size) + 0.02
    z = fg.fbm_surface((64, 64), 0.6, method="exact", seed=1)
    a, b = fg.whittle(z), fg.whittle(z, cell_size=30.0)
    assert b.extra["hurst"] == pytest.approx(a.extra["hurst"], abs=1e-6)
    assert b.extra["sigma2"] == pytest.approx(a.extra["sigma2"] * 30.0 ** (-2 * a.extra["hurst"]), rel=1e-4)


@pytest.mark.slow
def test_gaps_are_modelled_not_filled():
    # a NaN hole and a nodata border: the mask enters the expected
    # periodogram; the mean over seeds stays within 4 standard errors
    hs = []
    for s in range(40):
        z = fg.fbm_surface((64, 64), 0.7, method="exact", seed=s)
        z[20:35, 10:30] = np.nan
        hs.append(fg.whittle(z).extra["hurst"])
    hs = np.array(hs)
    assert abs(hs.mean() - 0.7) <= 4 * hs.std(ddof=1) / np.sqrt(hs.size)
    z = fg.fbm_surface((32, 32), 0.4, method="exact", seed=9)
    zn, zd = z.copy(), z.copy()
    zn[:, :3] = np.nan
    zd[:, :3] = -9999.0
    a, b = fg.whittle(zn), fg.whittle(zd, nodata=-9999.0)
    assert a.extra["hurst"] == b.extra["hurst"] and a.extra["n_valid"] < 30 * 30
    c, d = fg.fbm_mle(zn), fg.fbm_mle(zd, nodata=-9999.0)
    assert c.extra["hurst"] == d.extra["hurst"] and c.extra["n_valid"] == 32 * 29


@pytest.mark.parametrize(
    "call, exc, param",
    [
        (lambda: fg.whittle("abc"), TypeError, "data"),
        (lambda: fg.whittle(np.zeros((4, 4, 4))), ValueError, "data"),
        (lambda: fg.whittle(np.ones((32, 32), bool)), TypeError, "data"),
        (lambda: fg.whittle(np.zeros((32, 32))), ValueError, "data"),
        (lambda: fg.whittle(np.add.outer(np.arange(32.0), 2 * np.arange(32.0))), ValueError, "data"),
        (lambda: fg.whittle(np.full(100, np.nan)), ValueError, "data"),
        (lambda: fg.whittle(np.arange(5.0)), ValueError, "data"),
        (lambda: fg.whittle(np.random.rand(32, 32), filter="second"), ValueError, "filter"),
        (lambda: fg.whittle(np.random.rand(64), filter="laplacian"), ValueError, "filter"),
        (lambda: fg.whittle(np.random.rand(32, 32), taper="kaiser"), ValueError, "taper"),
        (lambda: fg.whittle(np.random.rand(32, 32), cell_size=0.0), ValueError, "cell_size"),
        (lambda: fg.whittle(np.random.rand(32, 32), cell_size=(1.0, 2.0, 3.0)), ValueError, "cell_size"),
        (lambda: fg.whittle(np.random.rand(32, 32), cell_size="1"), TypeError, "cell_size"),
        (lambda: fg.whittle(np.random.rand(32, 32), exclude_zero=1), TypeError, "exclude_zero"),
        (lambda: fg.whittle(np.random.rand(32, 32), nodata="x"), TypeError, "nodata"),
        (lambda: fg.fbm_mle(np.random.rand(80, 80)), ValueError, "data"),
        (lambda: fg.fbm_mle(np.random.rand(8, 8), max_samples=0), ValueError, "max_samples"),
        (lambda: fg.fbm_mle(np.ones(50)), ValueError, "data"),
    ],
)
def test_likelihood_bad_input(call, exc, param):
    with pytest.raises(exc, match=f"^{param}"):
        call()


def test_from_model_keeps_regression_fits_unchanged():
    fit = fg.DimensionFit.from_model(dimension=2.3, stderr=0.01, scales=[3, 1, 2], measures=[1, 2, 4],
                                     model=[1, 2, 4], method="m", dim_offset=3.0)
    assert list(fit.scales) == [1, 2, 3] and list(fit.measures) == [2, 4, 1]
    assert fit.r_squared == 1.0 and fit.model is not None
    assert fg.variogram(fg.fbm(256, 0.5, method="exact", seed=1)).model is None
