"""DEM voids stored as -32768 (SRTM, GDAL int16) or the lowest float32 and read
without their nodata value: the DEM entry points warn once, naming ``dem``
and the count; no warning when ``nodata`` covers them."""
import warnings

import numpy as np
import pytest

import fractalgeo_rs as fg
from fractalgeo_rs import radar
from fractalgeo_rs.dem import hillshade
from fractalgeo_rs.tin import tin_from_dem


def _dem(void=-32768.0, dtype=np.float64):
    z = fg.fbm_surface((32, 32), 0.7, seed=3) * 20.0 + 500.0
    z = z.astype(dtype)
    z[10, 12] = void
    z[20, 5] = void
    return z


CALLS = {
    "hillshade": lambda z, nd: hillshade(z, nodata=nd),
    "fractal_resample": lambda z, nd: fg.fractal_resample(z, 2, hurst=0.7, sigma=1.0, nodata=nd, seed=1),
    "tin_from_dem": lambda z, nd: tin_from_dem(z, max_error=5.0, nodata=nd),
}


@pytest.mark.parametrize("name", sorted(CALLS))
@pytest.mark.parametrize("void,dtype", [(-32768.0, np.float64), (-32768, np.int16),
                                        (float(np.finfo(np.float32).min), np.float32)])
def test_void_warns(name, void, dtype):
    z = _dem(void, dtype)
    before = z.copy()
    with pytest.warns(RuntimeWarning, match=r"dem: 2 cell\(s\) hold a void value"):
        CALLS[name](z, None)
    np.testing.assert_array_equal(z, before)


@pytest.mark.parametrize("name", sorted(CALLS))
def test_no_warning_when_nodata_covers(name):
    z = _dem()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        CALLS[name](z, -32768.0)


def test_simulate_warns():
    z = _dem()
    with pytest.warns(RuntimeWarning, match=r"dem: 2 cell\(s\) hold a void value.*NaN"):
        radar.simulate(z, cell_size=30.0, look_azimuth=90.0, incidence=35.0, wavelength=0.056,
                       rms_height=0.01, correlation_length=0.1, permittivity=5 + 0.5j)


def test_radiometry_scene_warns():
    from fractalgeo_rs.radiometry import Scene

    with pytest.warns(RuntimeWarning, match=r"dem: 2 cell\(s\) hold a void value.*fill them"):
        Scene.from_dem(_dem(), cell_size=30.0, periodic=False)


def test_deep_bathymetry_is_not_a_void():
    z = _dem(void=-10994.0)  # Challenger Deep, a real height
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        hillshade(z)
