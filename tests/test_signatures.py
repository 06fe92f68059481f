"""Every public signature follows the naming rules of docs/conventions.md.

The table below is the rule, written once: for every public function and
class of ``fractalgeo_rs.__all__``, the parameters that may be passed by
position (the data and at most the one or two parameters that define the
result); everything else must be keyword-only. The other rules are checked
over all signatures at once: one spelling per concept, ``n_threads`` on
every function that calls the Rust core, ``band`` 1-based, and the old
spellings still working with a DeprecationWarning.
"""
import inspect
import types
import warnings

import numpy as np
import pytest

import fractalgeo_rs as fg

# name -> the parameters that may be given by position, in order
POSITIONAL = {
    # estimators: the data first
    "blanket": ("data",),
    "box_counting": ("data",),
    "box_counting_points": ("points",),
    "differential_box_counting": ("data",),
    "dimension": ("data", "method"),
    "fbm_mle": ("data",),
    "gls_dimension": ("data",),
    "higuchi": ("data",),
    "lacunarity": ("data",),
    "madogram": ("data",),
    "mass_dimension": ("data",),
    "minkowski": ("data",),
    "power_variation": ("data",),
    "scale_space": ("data",),
    "self_affine_box_counting": ("data",),
    "spectral_dimension": ("data",),
    "surface_variation": ("data",),
    "variogram": ("data",),
    "wavelet_dimension": ("data",),
    "whittle": ("data",),
    "validate_surface": ("data", "hurst"),
    # maps of an image: the image and the window
    "fractal_transform": ("image", "window_size"),
    "lacunarity_map": ("image", "window_size"),
    "segment": ("features",),
    # synthesis: the size and the Hurst exponent
    "fbm": ("n", "hurst"),
    "fbm_surface": ("shape", "hurst"),
    "synthetic_dem": ("shape", "hurst"),
    # DEM work: the DEM first
    "hillshade": ("dem",),
    "lakes": ("dem", "level"),
    "fractal_resample": ("dem", "factor"),
    "tin_from_dem": ("dem",),
    # points
    "delaunay": ("points",),
    "grid_from_points": ("points", "values", "shape", "transform"),
    # files
    "read_raster": ("path", "band"),
    "write_raster": ("path", "data"),
    # classes built from their defining parts
    "IFS": ("maps", "probabilities"),
    "LSystem": ("axiom", "rules"),
    "LString": ("core",),
}
# result types (dataclasses and records): every field is a parameter
RESULTS = {"DimensionFit", "Lacunarity", "SurfaceReport", "TIN", "FractalRangeWarning"}

# one spelling per concept: the spellings on the left must not appear
FORBIDDEN = {
    "sample_spacing": "cell_size",
    "pixel_size": "cell_size",
    "spacing": "cell_size",
    "dx": "cell_size",
    "threads": "n_threads",
    "workers": "n_threads",
    "n_jobs": "n_threads",
    "z": "data (estimators) or dem (DEM functions)",
    "window": "taper (a spectral window) or window_size (a moving window)",
}
# functions that read or write files call the core single-threaded
NO_THREADS = {"read_raster", "write_raster"}


def _public():
    for name in fg.__all__:
        obj = getattr(fg, name)
        if name.startswith("__") or isinstance(obj, types.ModuleType):
            continue
        yield name, obj


def test_table_covers_every_public_callable():
    names = {n for n, _ in _public()}
    assert names == set(POSITIONAL) | RESULTS


@pytest.mark.parametrize("name", sorted(POSITIONAL))
def test_positional_parameters_then_keyword_only(name):
    params = list(inspect.signature(getattr(fg, name)).parameters.values())
    positional = tuple(p.name for p in params if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD))
    assert positional == POSITIONAL[name]
    assert all(p.kind in (p.KEYWORD_ONLY, p.VAR_KEYWORD) for p in params[len(positional):])


@pytest.mark.parametrize("name", sorted(POSITIONAL))
def test_one_spelling_per_concept(name):
    for p in inspect.signature(getattr(fg, name)).parameters:
        assert p not in FORBIDDEN, f"{name}({p}=): use {FORBIDDEN[p]}"


@pytest.mark.parametrize("name", sorted(n for n, o in _public() if inspect.isfunction(o)))
def test_n_threads_where_the_core_is_called(name):
    func = inspect.unwrap(getattr(fg, name))
    if "_core." in inspect.getsource(func) and name not in NO_THREADS:
        assert "n_threads" in inspect.signature(getattr(fg, name)).parameters


def test_band_is_one_based_everywhere():
    img = np.stack([np.zeros((40, 40)), np.add.outer(np.arange(40.0), np.arange(40.0)) ** 1.5])
    second = fg.fractal_transform(img, 9, method="variogram", band=2)
    np.testing.assert_array_equal(second, fg.fractal_transform(img[1], 9, method="variogram"))
    with pytest.raises(ValueError, match="1-based"):
        fg.fractal_transform(img, 9, band=0)
    with pytest.raises(ValueError, match="band"):
        fg.fractal_transform(img, 9, band=3)
    for name in ("read_raster", "fractal_transform"):
        assert "1-based" in getattr(fg, name).__doc__


@pytest.mark.parametrize("call, old, new", [
    (lambda **k: fg.scale_space(fg.fbm(1024, 0.5, seed=1), **k), {"sample_spacing": 0.5}, {"cell_size": 0.5}),
    (lambda **k: fg.spectral_dimension(fg.fbm(1024, 0.5, seed=1), **k), {"window": "none"}, {"taper": "none"}),
    (lambda **k: fg.differential_box_counting(**k), {"image": fg.fbm_surface(128, 0.3, seed=1)},
     {"data": fg.fbm_surface(128, 0.3, seed=1)}),
])
def test_old_keywords_work_with_a_deprecation_warning(call, old, new):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        expected = call(**new)  # the new spelling gives no warning
    with pytest.warns(DeprecationWarning, match=f"{next(iter(old))}.*{next(iter(new))}"):
        got = call(**old)
    assert got.dimension == expected.dimension


def test_validate_surface_old_keyword_z():
    z = fg.fbm_surface(64, 0.5, seed=1)
    with pytest.warns(DeprecationWarning, match="'z' is now called 'data'"):
        old = fg.validate_surface(z=z, coastline=False)
    assert old.hurst_variogram == fg.validate_surface(z, coastline=False).hurst_variogram


def test_options_made_keyword_only_still_work_by_position_with_a_warning():
    img = np.random.default_rng(0).random((32, 32))
    with pytest.warns(DeprecationWarning, match="box_sizes"):
        old = fg.lacunarity(img, [1, 2, 4])
    np.testing.assert_array_equal(old.lacunarity, fg.lacunarity(img, box_sizes=[1, 2, 4]).lacunarity)
    with pytest.warns(DeprecationWarning, match="box_sizes"):
        old_map = fg.lacunarity_map(img, 9, [1, 2])
    np.testing.assert_array_equal(old_map, fg.lacunarity_map(img, 9, box_sizes=[1, 2]))
    with pytest.raises(TypeError, match="positional"):
        fg.lacunarity(img, [1, 2, 4], 5)


def test_both_old_and_new_name_is_an_error():
    with pytest.raises(TypeError, match="both"):
        fg.scale_space(np.arange(64.0), cell_size=1.0, sample_spacing=1.0)
