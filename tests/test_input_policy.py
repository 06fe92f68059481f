"""One input policy for every public function (docs/input_policy.md): the
same bad inputs give the same behaviour across ``fractalgeo_rs.__all__``."""
import inspect
import warnings

import numpy as np
import pytest

import fractalgeo_rs as fg

# Public callables that take no data array first (generators, readers,
# classes) are checked elsewhere (tests/test_limits.py, tests/test_io_raster.py).
NOT_ARRAY_FIRST = {"fbm", "fbm_surface", "synthetic_dem", "read_raster", "write_raster", "segment"}

rng = np.random.default_rng(0)
SURFACE = rng.normal(size=(64, 64)).cumsum(0).cumsum(1)
PROFILE = rng.normal(size=256).cumsum()
MASK = np.zeros((64, 64), bool)
MASK[np.arange(64), np.arange(64)] = True
MASK[10:30, 5] = True


BIG = rng.normal(size=(160, 160)).cumsum(0).cumsum(1)
POINTS = rng.random((300, 2))

# A valid input (and required options) of every public function that takes
# a data array first.
INPUTS = {
    "blanket": (SURFACE, {}), "fbm_mle": (PROFILE, {}), "higuchi": (PROFILE, {}), "lacunarity": (MASK, {}),
    "madogram": (PROFILE, {}), "mass_dimension": (BIG, {}), "minkowski": (MASK, {}),
    "power_variation": (PROFILE, {}), "scale_space": (PROFILE, {}), "spectral_dimension": (SURFACE, {}),
    "surface_variation": (SURFACE, {}), "variogram": (PROFILE, {}), "wavelet_dimension": (SURFACE, {}),
    "whittle": (SURFACE, {}), "box_counting": (MASK, {}), "box_counting_points": (POINTS, {}),
    "differential_box_counting": (SURFACE, {}), "dimension": (MASK, {}), "self_affine_box_counting": (SURFACE, {}),
    "fractal_transform": (SURFACE, {"window_size": 9}), "lacunarity_map": (np.abs(SURFACE), {"window_size": 9}),
    "validate_surface": (SURFACE, {}), "hillshade": (SURFACE, {}), "lakes": (SURFACE, {"level": 0.0}),
}


def _functions():
    out = []
    for name in fg.__all__:
        obj = getattr(fg, name)
        if inspect.isclass(obj) or inspect.ismodule(obj) or not callable(obj) or name in NOT_ARRAY_FIRST:
            continue
        out.append(name)
    return out


FUNCTIONS = _functions()


def _call(name, data, **kw):
    _, opts = INPUTS[name]
    return getattr(fg, name)(data, **opts, **kw)


def _valid_input(fn):
    return INPUTS[fn.__name__][0]


def _param(fn):
    return next(iter(inspect.signature(fn).parameters))


def test_every_function_has_an_input():
    assert set(FUNCTIONS) == set(INPUTS)


def test_every_public_function_is_covered():
    assert {"box_counting", "differential_box_counting", "hillshade", "lakes", "validate_surface",
            "fractal_transform", "spectral_dimension", "higuchi", "variogram"} <= set(FUNCTIONS)


@pytest.mark.parametrize("name", FUNCTIONS)
def test_complex_is_a_type_error_naming_the_parameter(name):
    fn = getattr(fg, name)
    data = _valid_input(fn)
    with pytest.raises(TypeError) as info:
        _call(name, data.astype(complex))
    assert str(info.value).startswith(_param(fn)) and "complex" in str(info.value)


@pytest.mark.parametrize("name", FUNCTIONS)
def test_inf_is_missing_like_nan_with_a_warning(name):
    fn = getattr(fg, name)
    data = _valid_input(fn)
    if data.dtype == bool:
        pytest.skip("a mask holds no inf")
    bad_inf = data.astype(float).copy()
    bad_nan = data.astype(float).copy()
    idx = tuple(min(3, n - 1) for n in data.shape)
    bad_inf[idx] = -np.inf
    bad_nan[idx] = np.nan
    before = bad_inf.copy()

    def outcome(d):
        try:
            with warnings.catch_warnings(record=True) as rec:
                warnings.simplefilter("always")
                r = _call(name, d)
            return ("ok", r), rec
        except ValueError as exc:
            return ("ValueError", str(exc).split(":")[0]), []

    got_inf, rec = outcome(bad_inf)
    got_nan, _ = outcome(bad_nan)
    np.testing.assert_array_equal(bad_inf, before)  # input untouched
    assert got_inf[0] == got_nan[0], (got_inf, got_nan)
    if got_inf[0] == "ok":
        assert any(issubclass(w.category, RuntimeWarning) and "inf" in str(w.message) and
                   str(w.message).startswith(_param(fn)) for w in rec)
        a, b = got_inf[1], got_nan[1]
        for attr in ("dimension", "hurst"):
            if hasattr(a, attr):
                assert getattr(a, attr) == getattr(b, attr) or (np.isnan(getattr(a, attr))
                                                                 and np.isnan(getattr(b, attr)))
        if isinstance(a, np.ndarray):
            np.testing.assert_array_equal(a, b)
    else:
        assert got_inf[1] == got_nan[1] == _param(fn)


@pytest.mark.parametrize("name", FUNCTIONS)
def test_n_threads_above_the_cap_is_a_value_error(name):
    fn = getattr(fg, name)
    if "n_threads" not in inspect.signature(fn).parameters:
        pytest.skip("no n_threads")
    data = _valid_input(fn)
    with pytest.raises(ValueError, match="^n_threads: expected at most"):
        _call(name, data, n_threads=10**6)


@pytest.mark.parametrize("name", FUNCTIONS)
def test_nodata_must_be_a_number(name):
    fn = getattr(fg, name)
    if "nodata" not in inspect.signature(fn).parameters:
        pytest.skip("no nodata")
    data = _valid_input(fn)
    with pytest.raises(TypeError, match="^nodata"):
        _call(name, data, nodata="x")


@pytest.mark.parametrize("data", [np.zeros((64, 64)), np.add.outer(np.arange(64.0), 2 * np.arange(64.0)),
                                  np.full(256, 3.0)])
def test_spectral_dimension_of_degenerate_data_is_an_error(data):
    with pytest.raises(ValueError, match="^data: no variation"):
        fg.spectral_dimension(data)


def test_lags_are_integers_never_truncated():
    with pytest.raises(TypeError, match="^lags"):
        fg.variogram(PROFILE, lags=[1.5, 2, 3])
    assert fg.variogram(PROFILE, lags=[1, 2.0, 4]).dimension == fg.variogram(PROFILE, lags=[1, 2, 4]).dimension
