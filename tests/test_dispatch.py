"""The dispatcher: every key on 1D and 2D inputs gives a fit or a clear
error naming what to use, and ``fit.method`` round-trips."""
import warnings

import numpy as np
import pytest

import fractalgeo_rs as fg
from fractalgeo_rs.dimension import METHODS

PROFILE = fg.fbm(1024, 0.5, seed=1, method="exact")
SURFACE = fg.fbm_surface((128, 128), 0.5, seed=1, method="exact")
_i, _j = np.indices((128, 128))
SET2D = (_i & _j) == 0
SET1D = np.zeros(729, dtype=bool)
SET1D[[k for k in range(729) if "1" not in np.base_repr(k, 3)]] = True  # Cantor set
POINTS = np.argwhere(SET2D).astype(float)

# what each key is given on "1D" and "2D": sets for the set methods,
# profiles and surfaces for the graph methods
SET_METHODS = {"box", "minkowski"}
ONE_D_ONLY = {"variation", "scale_space", "higuchi"}
TWO_D_ONLY = {"dbc", "blanket", "surface_variation", "mass"}


def _inputs(key):
    if key in SET_METHODS:
        return {1: SET1D, 2: SET2D}
    if key == "points":
        return {1: POINTS[:, :1], 2: POINTS}
    if key == "mle":  # the exact likelihood is for small fields
        return {1: PROFILE[:128], 2: SURFACE[:16, :16]}
    return {1: PROFILE, 2: SURFACE}


@pytest.mark.parametrize("key", sorted(METHODS))
@pytest.mark.parametrize("nd", [1, 2])
def test_every_key_gives_a_fit_or_a_clear_error(key, nd):
    data = _inputs(key)[nd]
    expect_error = (nd == 2 and key in ONE_D_ONLY) or (nd == 1 and key in TWO_D_ONLY)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", fg.FractalRangeWarning)
        if expect_error:
            with pytest.raises(ValueError, match=r"not defined for|expected a 2D"):
                fg.dimension(data, method=key)
            return
        fit = fg.dimension(data, method=key)
        # the method name is the key: the same call again gives the same fit
        assert fit.method == key
        again = fg.dimension(data, method=fit.method)
    assert again.dimension == fit.dimension
    assert np.isfinite(fit.dimension)
    d = nd if key in SET_METHODS or key == "points" else nd + 1
    lo = 0 if key in SET_METHODS or key == "points" else nd
    assert lo - 0.2 < fit.dimension < d + 0.2


@pytest.mark.parametrize("key, nd, use", [
    ("variation", 2, "surface_variation"), ("higuchi", 2, "surface_variation"),
    ("scale_space", 2, "wavelet"), ("dbc", 1, "variogram"), ("blanket", 1, "variogram"),
    ("surface_variation", 1, "variation"),
])
def test_wrong_dimensionality_names_the_alternative(key, nd, use):
    with pytest.raises(ValueError, match=f"method: '{key}' is not defined for {nd}D.*'{use}'"):
        fg.dimension(PROFILE if nd == 1 else SURFACE, method=key)


@pytest.mark.parametrize("name, p", [("variogram", 2.0), ("madogram", 1.0)])
def test_variogram_and_madogram_on_surfaces_are_the_axis_increments(name, p):
    fit = fg.dimension(SURFACE, method=name)
    ref = fg.surface_variation(SURFACE, estimator="first", p=p)
    assert fit.method == name and fit.dimension == ref.dimension
    # independent: half mean |increment|^p on both axes at lags 1 and 2
    v = [np.mean(np.concatenate([np.abs(SURFACE[:, l:] - SURFACE[:, :-l]).ravel() ** p,
                                 np.abs(SURFACE[l:, :] - SURFACE[:-l, :]).ravel() ** p])) for l in (1, 2)]
    assert fit.dimension == pytest.approx(3 - np.log2(v[1] / v[0]) / p, abs=1e-12)


def test_power_variation_method_is_the_key():
    fit = fg.power_variation(PROFILE, p=1.5, order=2)
    assert fit.method == "variation"
    assert fg.dimension(PROFILE, method="variation", p=1.5, order=2).dimension == fit.dimension
    assert fg.surface_variation(SURFACE, estimator="transect").method == "surface_variation"


def test_box_counting_default_sizes_on_an_uneven_extent():
    # a Sierpinski triangle cropped to 1000 x 1000: the extent's divisors
    # (8, 20, 40, 100, 200) jump unevenly; the default counts on powers of 2
    i, j = np.indices((1024, 1024))
    fit = fg.box_counting(((i & j) == 0)[:1000, :1000])
    assert fit.scales.tolist() == [1, 2, 4, 8, 16, 32, 64, 128]
    assert abs(fit.dimension - np.log2(3)) < 0.01
    # a filled cube of side 60: powers of 2 up to 15, partial boxes
    # edge-corrected, so D = 3 exactly
    cube = fg.box_counting(np.ones((60, 60, 60), bool))
    assert cube.scales.tolist() == [1, 2, 4, 8] and cube.dimension == pytest.approx(3.0)
