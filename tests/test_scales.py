"""Scale ranges and validity: break detection, the fractal range, flags and
warnings on every estimator."""
import math
import warnings

import numpy as np
import pytest
from scipy.ndimage import gaussian_filter, gaussian_filter1d
from scipy.special import gamma

import fractalgeo_rs as fg
from fractalgeo_rs import FractalRangeWarning
from fractalgeo_rs._scales import MIN_SEGMENT, find_break
from fractalgeo_rs.fit import fit_loglog


def crossover_lag(h: float, sigma: float) -> float:
    """Lag where the two asymptotes of the variogram of fBm smoothed by a
    Gaussian of width ``sigma`` cross (closed form, spectral density
    ``f^-(2H+1)`` times ``exp(-4 pi^2 sigma^2 f^2)``):

    small lags:  gamma(l) ~ 2 pi^2 l^2 * Gamma(1 - H) / (2 a^(1 - H)), a = 4 pi^2 sigma^2
    large lags:  gamma(l) ~ (2 pi l)^(2H) * pi / (2 sin(pi H) Gamma(1 + 2H))

    (the large-lag constant is int_0^inf (1 - cos u) u^(-1-2H) du; the
    smoothing subtracts a constant from the variogram, so the asymptote is
    approached as ``1 - O((sigma / l)^(2H))``).
    """
    a = 4 * math.pi**2 * sigma**2
    small = 2 * math.pi**2 * gamma(1 - h) / (2 * a ** (1 - h))
    large = (2 * math.pi) ** (2 * h) * _tail_constant(h)
    return (large / small) ** (1.0 / (2.0 - 2.0 * h))


def _tail_constant(h: float) -> float:
    return math.pi / (2 * math.sin(math.pi * h) * gamma(1 + 2 * h))


@pytest.mark.parametrize("h", [0.3, 0.5, 0.7])
def test_crossover_constants_match_numerical_integrals(h):
    from scipy.integrate import quad

    # int_0^inf (1 - cos u) u^(-1-2H) du, the oscillating tail by QAWF
    A = 10.0
    head = quad(lambda u: (1 - math.cos(u)) * u ** (-1 - 2 * h), 0, A, limit=200)[0]
    tail = A ** (-2 * h) / (2 * h) - quad(lambda u: u ** (-1 - 2 * h), A, np.inf, weight="cos", wvar=1.0)[0]
    assert head + tail == pytest.approx(_tail_constant(h), rel=1e-6)
    # the small-lag limit of the smoothed variogram integral
    sigma, l = 4.0, 0.01
    a = 4 * math.pi**2 * sigma**2
    f = lambda u: (1 - math.cos(2 * math.pi * u * l)) * u ** (-(2 * h + 1)) * math.exp(-a * u * u)  # noqa: E731
    small = 2 * math.pi**2 * gamma(1 - h) / (2 * a ** (1 - h))
    assert quad(f, 0, np.inf, limit=400)[0] / (small * l**2) == pytest.approx(1, rel=1e-3)


def test_find_break_on_a_broken_line():
    x = np.log(2.0 ** np.arange(12))
    y = np.where(x < np.log(16), 2 * x, 2 * np.log(16) + 0.6 * (x - np.log(16)))
    xb, below, above = find_break(x, y, dim_factor=-0.5)
    assert math.exp(xb) == pytest.approx(16, rel=0.05)
    assert below == pytest.approx(2, abs=1e-3) and above == pytest.approx(0.6, abs=1e-3)
    # a straight line, and too few points, have no break
    assert find_break(x, 0.6 * x, dim_factor=-0.5) is None
    assert find_break(x[: 2 * MIN_SEGMENT - 1], y[: 2 * MIN_SEGMENT - 1], dim_factor=-0.5) is None


@pytest.mark.parametrize("h, sigma", [(0.3, 3.0), (0.5, 4.0), (0.7, 2.0)])
def test_smooth_then_rough_profile(h, sigma):
    x = fg.fbm(2**17, h, seed=11)
    xs = gaussian_filter1d(x, sigma, mode="reflect")
    lags = np.unique(np.round(np.geomspace(1, 1024, 32)).astype(int))
    with pytest.warns(FractalRangeWarning, match="smooth"):
        fit = fg.variogram(xs, lags=lags)
    assert len(fit.ranges) == 2
    low, high = fit.ranges
    assert not low.valid and high.valid
    truth = crossover_lag(h, sigma)
    brk = low.scale_range[1]
    assert truth / 1.5 <= brk <= truth * 1.5, (brk, truth)
    # the default fit is the fractal range, its D within 0.03 of 2 - H
    assert fit.range_selection == "fractal" and "range_restricted" in fit.flags
    assert fit.scale_range[0] >= 2 * brk and fit.scale_range[0] <= 3 * brk
    assert fit.dimension == pytest.approx(2 - h, abs=0.03)
    # the broken line's own slope above the break is smeared by the transition
    assert abs((2 - h) - high.dimension) < 0.08
    # every scale on request: no restriction
    every = fg.variogram(xs, lags=lags, scale_range="all")
    assert every.range_selection == "all" and every.n_used == len(lags)


def test_smooth_then_rough_surface():
    h, sigma = 0.5, 2.5
    z = fg.fbm_surface((512, 512), h, seed=3, method="exact")
    zs = gaussian_filter(z, sigma, mode="reflect")
    lags = [1, 2, 3, 4, 6, 8, 11, 16, 23, 32, 45, 64]
    with pytest.warns(FractalRangeWarning):
        fit = fg.surface_variation(zs, lags=lags)
    assert len(fit.ranges) == 2
    # the square increment is a second-order filter: its smooth regime has
    # slope 4 (D = 1); the crossover of its asymptotes is that of the
    # first differences to within the factor asked for
    brk = fit.ranges[0].scale_range[1]
    truth = crossover_lag(h, sigma)
    assert truth / 1.5 <= brk <= truth * 1.5, (brk, truth)
    assert fit.dimension == pytest.approx(3 - h, abs=0.03)


def test_exact_fbm_is_one_range_and_valid():
    x = fg.fbm(2**15, 0.6, seed=5)
    lags = np.unique(np.round(np.geomspace(1, 256, 20)).astype(int))
    with warnings.catch_warnings():
        warnings.simplefilter("error", FractalRangeWarning)
        fit = fg.variogram(x, lags=lags)
    assert fit.valid and fit.flags == () and len(fit.ranges) == 1
    assert fit.range_selection == "all"
    assert abs(fit.dimension - 1.4) < 4 * fit.stderr + 0.01


def test_smooth_surface_default_is_flagged_without_interval():
    # a smooth surface at the pixel scale: the two-lag default reads H > 1
    z = gaussian_filter(fg.fbm_surface((256, 256), 0.5, seed=2), 6.0)
    with pytest.warns(FractalRangeWarning, match="smooth") as rec:
        fit = fg.surface_variation(z)
    assert not fit.valid and fit.flags == ("below_domain",)
    assert fit.dimension < 2
    assert math.isnan(fit.stderr) and all(math.isnan(v) for v in fit.ci95)
    assert "use larger scales" in str(rec[0].message) and fit.warning == str(rec[0].message)


def test_white_noise_is_above_the_domain():
    rng = np.random.default_rng(0)
    with pytest.warns(FractalRangeWarning, match="rougher"):
        fit = fg.variogram(rng.normal(size=4096) + 0.0, lags=(1, 2))
    # white noise: V(1) = V(2), slope 0, D = 2 exactly at the open bound
    assert not fit.valid and fit.flags == ("above_domain",)


def test_whittle_pinned_at_the_bound_is_flagged():
    z = gaussian_filter(fg.fbm_surface((128, 128), 0.5, seed=4), 4.0)
    with pytest.warns(FractalRangeWarning, match="pinned"):
        fit = fg.whittle(z)
    assert fit.extra["hurst"] > 0.99
    assert not fit.valid and "pinned" in fit.flags
    assert math.isnan(fit.stderr) and math.isnan(fit.ci95[0]) and math.isnan(fit.extra["hurst_stderr"])


def test_whittle_on_fbm_is_valid():
    z = fg.fbm_surface((128, 128), 0.4, seed=4, method="exact")
    with warnings.catch_warnings():
        warnings.simplefilter("error", FractalRangeWarning)
        fit = fg.whittle(z)
    assert fit.valid and fit.flags == () and np.isfinite(fit.stderr)
    assert fit.domain == (2.0, 3.0)


def test_box_counting_of_sets_is_valid_at_the_bounds():
    # a filled square (D = 2) and a line (D = 1) are inside [0, 2]
    with warnings.catch_warnings():
        warnings.simplefilter("error", FractalRangeWarning)
        full = fg.box_counting(np.ones((64, 64), dtype=bool))
        i, j = np.indices((256, 256))
        tri = fg.box_counting((i & j) == 0)
    assert full.valid and full.dimension == pytest.approx(2.0)
    assert tri.valid and tri.domain == (0.0, 2.0)
    assert tri.dimension == pytest.approx(math.log2(3), abs=1e-9)


def test_user_range_is_never_replaced():
    s = 2.0 ** np.arange(12)
    m = np.where(s < 16, s**2, 256 * (s / 16) ** 0.8)
    with pytest.warns(FractalRangeWarning, match="below"):
        fit = fit_loglog(s, m, method="t", dim_offset=2.0, dim_factor=-0.5, scale_range=(1, 8),
                         domain=(1.0, 2.0), open_domain=True, restrict=True)
    assert fit.range_selection == "user" and not fit.valid
    # the message points at the fractal range found among the fitted scales
    with pytest.warns(FractalRangeWarning, match="fractal range"):
        auto = fit_loglog(s, m, method="t", dim_offset=2.0, dim_factor=-0.5, domain=(1.0, 2.0), open_domain=True, restrict=True)
    assert auto.valid and auto.ranges[0].scale_range[1] == pytest.approx(16, rel=1e-6)
    assert auto.scale_range[0] == 32  # one octave beyond the break (BREAK_MARGIN)
    assert auto.dimension == pytest.approx(1.6, abs=1e-9)


def test_plot_shows_the_ranges(tmp_path):
    import matplotlib.pyplot as plt

    s = 2.0 ** np.arange(12)
    m = np.where(s < 16, s**2, 256 * (s / 16) ** 0.8)
    with pytest.warns(FractalRangeWarning):
        fit = fit_loglog(s, m, method="t", dim_offset=2.0, dim_factor=-0.5, domain=(1.0, 2.0), open_domain=True, restrict=True)
    ax = fit.plot()
    labels = [str(line.get_label()) for line in ax.lines]
    assert any(lb.startswith("range 1..") and "(invalid)" in lb for lb in labels)
    assert any(lb.startswith("range 16..") for lb in labels)
    ax.figure.savefig(tmp_path / "r.png")
    plt.close("all")
    assert "ranges 1..16" in repr(fit) and "range_restricted" in repr(fit)
