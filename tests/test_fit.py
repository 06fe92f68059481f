"""The DimensionFit object: regression, ranges, uncertainty, plot."""
import numpy as np
import pytest
from scipy import stats

import fractalgeo_rs as fg
from fractalgeo_rs.fit import fit_loglog


def test_regression_matches_scipy_linregress():
    rng = np.random.default_rng(0)
    s = 2.0 ** np.arange(8)
    m = 1000 * s**-1.7 * np.exp(rng.normal(0, 0.05, 8))
    fit = fit_loglog(s, m, method="test")
    ref = stats.linregress(np.log(s), np.log(m))
    assert fit.slope == pytest.approx(ref.slope)
    assert fit.intercept == pytest.approx(ref.intercept)
    assert fit.r_squared == pytest.approx(ref.rvalue**2)
    assert fit.stderr == pytest.approx(ref.stderr)
    assert fit.dimension == pytest.approx(-ref.slope)
    half = stats.t.ppf(0.975, 6) * ref.stderr
    assert fit.ci95 == pytest.approx((-ref.slope - half, -ref.slope + half))


def test_user_and_auto_ranges():
    s = 2.0 ** np.arange(12)
    m = s**-1.5
    m[:3] *= np.array([3.0, 1.8, 1.2])  # curvature at small scales
    m[-2:] = m[-3]  # saturation at large scales
    all_ = fit_loglog(s, m, method="t")
    assert all_.range_selection == "all" and all_.n_used == 12
    user = fit_loglog(s, m, method="t", scale_range=(8, 256))
    assert user.scale_range == (8.0, 256.0) and user.dimension == pytest.approx(1.5)
    auto = fit_loglog(s, m, method="t", scale_range="auto")
    assert auto.range_selection == "auto"
    assert auto.dimension == pytest.approx(1.5, abs=1e-9)
    assert auto.scale_range[0] >= 8 and auto.scale_range[1] <= 512
    with pytest.raises(ValueError, match="scale_range"):
        fit_loglog(s, m, method="t", scale_range=(3000, 5000))
    with pytest.raises(ValueError, match="scale_range"):
        fit_loglog(s, m, method="t", scale_range="best")


def test_plot_draws_points_and_line(tmp_path):
    import matplotlib.pyplot as plt

    i, j = np.indices((256, 256))
    fit = fg.box_counting((i & j) == 0, scale_range=(2, 64))
    ax = fit.plot()
    assert len(ax.lines) == 3  # used points, unused points, fitted line
    x, y = ax.lines[-1].get_data()
    assert np.allclose(x, [2, 64])
    assert np.allclose(np.log(y), fit.intercept + fit.slope * np.log(x))
    ax.figure.savefig(tmp_path / "f.png")
    plt.close("all")
    assert "dimension=1.5850" in repr(fit)
