"""The Rust kernel of the local analysis (``_core.resample_local_maps``)
against the numpy reference kept in ``dem/_resample.py``: the same window
sums, interpolation and fit, computed independently."""
import numpy as np
import pytest

import fractalgeo_rs as fg
from fractalgeo_rs import _core
from fractalgeo_rs.dem import _resample as R


def _dem(shape, hurst, seed):
    """Exact fBm with NaN holes (single cells and a block)."""
    z = fg.fbm_surface(shape, hurst, method="exact", seed=seed)
    rng = np.random.default_rng(seed)
    z[rng.random(shape) < 0.03] = np.nan
    z[5:9, 11:20] = np.nan
    return z


CASES = [
    # shape, H, window, step: windows smaller and larger than the node step
    ((70, 53), 0.6, 5, R.STEP),
    ((45, 90), 0.4, 9, R.STEP),
    ((64, 64), 0.7, 17, R.STEP),
    ((51, 83), 0.5, 33, R.STEP),
    ((40, 37), 0.8, 41, R.STEP),
    ((47, 58), 0.6, 11, 4),
]


@pytest.mark.parametrize("support,block", [("point", 2), ("area", 2), ("area", 4)])
@pytest.mark.parametrize("shape,hurst,window,step", CASES)
def test_kernel_matches_the_numpy_reference(shape, hurst, window, step, support, block):
    z = _dem(shape, hurst, seed=window)
    keep = z.copy()
    half = window // 2
    t = R._pad_width(half, step)
    zp = np.pad(z, t, constant_values=np.nan)
    ref_h, ref_s, ref_clip, ref_ok = R._analyse_padded_reference(zp, half, support, block, step)
    h, s, n_clip, n_ok = R._analyse_padded(z, half, support, block, step, border=t)
    assert h.shape == s.shape == shape
    np.testing.assert_allclose(h, ref_h, rtol=1e-12, atol=0)
    np.testing.assert_allclose(s, ref_s, rtol=1e-12, atol=0)
    assert (n_clip, n_ok) == (ref_clip, ref_ok)
    # the maps are not all clipped or empty: the comparison means something
    assert 0 < n_ok and n_clip < n_ok and np.ptp(h[np.isfinite(z)]) > 0.05
    # a real halo gives the bits of the virtual one, for any thread count
    for n in (1, 3):
        hp, sp, *counts = R._analyse_padded(zp, half, support, block, step, n_threads=n)
        np.testing.assert_array_equal(hp, h)
        np.testing.assert_array_equal(sp, s)
        assert counts == [n_clip, n_ok]
    np.testing.assert_array_equal(z, keep)


def test_resample_analysis_fraction_clipped_is_the_references():
    z = _dem((60, 75), 0.9, seed=2)
    t = R._pad_width(4)
    _, _, n_clip, n_ok = R._analyse_padded_reference(np.pad(z, t, constant_values=np.nan), 4, "point")
    with pytest.warns(RuntimeWarning, match="clipped"):
        a = fg.dem.resample_analysis(z, window_size=9, n_threads=1)
    assert n_clip > 0 and a.fraction_clipped == n_clip / n_ok


def test_bad_input_is_a_value_error_naming_the_parameter():
    with pytest.raises(ValueError, match="^dem: "):
        _core.resample_local_maps(np.zeros((10, 10)), 2, 8, 0, R.HURST_RANGE)
    with pytest.raises(ValueError, match="^table: "):
        x = np.array([0.0, 0.0])
        _core.resample_local_maps(np.zeros((40, 40)), 2, 8, 0, R.HURST_RANGE, (x, x, x))
    with pytest.raises(ValueError, match="^n_threads"):
        fg.dem.resample_analysis(np.zeros((20, 20)), window_size=5, n_threads=0)
