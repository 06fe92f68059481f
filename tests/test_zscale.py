"""The one z_scale policy of the box, mass and blanket methods
(python/fractalgeo_rs/_zscale.py): each spelling against its closed form,
bad values rejected with the parameter's name, and default calls that do
not depend on the height unit (data x 1000 gives the same D)."""
import numpy as np
import pytest

import fractalgeo_rs as fg
from fractalgeo_rs._zscale import resolve_z_scale


def plane():
    i, j = np.indices((50, 50))
    return 3.0 * i + 4.0 * j


def test_each_spelling_against_its_closed_form():
    z = plane()
    assert resolve_z_scale(2.5, z) == 2.5
    assert resolve_z_scale(np.float32(0.5), z) == 0.5
    # range: (max - min) / max(rows, cols) = (3 * 49 + 4 * 49) / 50
    assert resolve_z_scale("range", z) == pytest.approx(343.0 / 50.0, rel=1e-12)
    # auto: 1.4826 x median |lag-1 increment|, half the increments 3, half 4
    assert resolve_z_scale("auto", z) == pytest.approx(1.4826 * 3.5, rel=1e-12)
    # missing samples and nodata are left out of the range
    zn = z.copy()
    zn[49, 49] = np.nan
    zn[0, 0] = -9999.0
    assert resolve_z_scale("range", zn, nodata=-9999.0) == pytest.approx((340.0 - 3.0) / 50.0, rel=1e-12)  # max 3*48+4*49, min 3*1
    # a constant image has no height range: unit 1
    assert resolve_z_scale("range", np.full((8, 8), 4.0)) == 1.0


@pytest.mark.parametrize("bad, exc", [(0.0, ValueError), (-1.0, ValueError), (float("nan"), ValueError),
                                      (float("inf"), ValueError), ("Auto", TypeError), ("cell", TypeError),
                                      (None, TypeError), (True, TypeError), ([1.0], TypeError)])
def test_bad_values_name_the_parameter(bad, exc):
    z = plane()
    with pytest.raises(exc, match="^z_scale"):
        resolve_z_scale(bad, z)
    calls = [lambda: fg.differential_box_counting(z, z_scale=bad), lambda: fg.mass_dimension(z, z_scale=bad),
             lambda: fg.blanket(z, z_scale=bad)]
    calls += [lambda m=m: fg.fractal_transform(z, 9, method=m, z_scale=bad) for m in ("mass", "dbc", "blanket")]
    for call in calls:
        with pytest.raises(exc, match="^z_scale"):
            call()


def surfaces():
    yield "fbm", fg.fbm_surface((96, 96), 0.5, method="exact", seed=3)
    vv, _ = fg.data.sentinel1_vv_db()
    yield "s1_vv", np.asarray(vv[100:196, 200:296], dtype=float)
    dem, _ = fg.data.srtm_alps()
    yield "srtm_alps", np.asarray(dem[:96, :96], dtype=float)


@pytest.mark.parametrize("name, z", list(surfaces()))
def test_default_calls_do_not_depend_on_the_height_unit(name, z):
    zk = z * 1000.0
    for fn in (fg.differential_box_counting, fg.mass_dimension, fg.blanket):
        assert fn(zk).dimension == pytest.approx(fn(z).dimension, abs=1e-9), (name, fn.__name__)
    for method in ("mass", "dbc", "blanket"):
        a = np.asarray(fg.fractal_transform(z, 15, method=method, step=4))
        b = np.asarray(fg.fractal_transform(zk, 15, method=method, step=4))
        assert np.isfinite(a).any()
        assert np.allclose(a, b, atol=1e-4, equal_nan=True), (name, method)
