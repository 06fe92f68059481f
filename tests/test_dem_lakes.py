"""Lakes: masks, closed basins, coastlines."""
import numpy as np
import pytest

import fractalgeo_rs as fg
from fractalgeo_rs.dem import lakes


def bowl_with_channel():
    z = np.full((9, 12), 10.0)
    z[2:5, 2:5] = 1.0  # closed basin
    z[5:8, 7:12] = 2.0  # basin open to the east edge
    return z


def test_mask_is_below_level_and_input_untouched():
    z = fg.fbm_surface((64, 80), 0.7, seed=2)
    before = z.copy()
    lvl = float(np.median(z))
    r = lakes(z, lvl)
    np.testing.assert_array_equal(z, before)
    np.testing.assert_array_equal(r.mask, z < lvl)
    assert r.level == lvl and r.n_lakes >= 1


def test_closed_only_drops_basins_touching_the_edge_or_nodata():
    z = bowl_with_channel()
    assert lakes(z, 5.0).n_lakes == 2
    r = lakes(z, 5.0, closed_only=True)
    assert r.n_lakes == 1
    assert r.mask.sum() == 9 and r.mask[2:5, 2:5].all()
    assert len(r.coastlines) == 1
    z2 = z.copy()
    z2[3, 1] = np.nan  # void next to the closed basin
    assert lakes(z2, 5.0, closed_only=True).n_lakes == 0


def test_coastline_is_on_the_level():
    z = fg.fbm_surface((80, 80), 0.6, seed=4, method="exact")
    lvl = float(np.percentile(z, 30))
    r = lakes(z, lvl)
    pts = np.concatenate(r.coastlines)
    # Bilinear interpolation of z at the contour points gives the level.
    from scipy.ndimage import map_coordinates

    vals = map_coordinates(z, pts.T, order=1)
    np.testing.assert_allclose(vals, lvl, atol=1e-9 * (np.ptp(z) + 1))


def test_nodata_never_flooded():
    z = bowl_with_channel()
    z[3, 3] = -9999
    r = lakes(z, 5.0, nodata=-9999, coastlines=False)
    assert not r.mask[3, 3] and r.coastlines == []


def test_bad_input():
    with pytest.raises(ValueError, match="level"):
        lakes(np.zeros((4, 4)), float("nan"))
    with pytest.raises(ValueError, match="dem"):
        lakes(np.zeros(4), 1.0)
    with pytest.raises(TypeError, match="dem"):
        lakes(None, 1.0)
