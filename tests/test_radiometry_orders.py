"""``Scene.brf_orders``: single and multiple scattering from the same paths,
against the separate ``max_depth=1`` run, closed forms (a plane, V-grooves),
the power law of the orders in ``rho`` and the spread over seeds."""
import math

import numpy as np
import pytest

from fractalgeo_rs.canopy import disc_canopy
from fractalgeo_rs.geometry import Mesh
from fractalgeo_rs.radiometry import BiLambertian, Estimate, Lambertian, OrenNayar, ScatteringOrders, Scene
from surfaces import rough_tile, v_grooves




def _square():
    """A flat 2 m x 2 m square of two triangles at height 1."""
    v = np.array([[0, 0, 1], [2, 0, 1], [2, 2, 1], [0, 2, 1]], dtype=float)
    return Mesh.from_triangles(v, np.array([[0, 1, 2], [0, 2, 3]]))


SUN, VIEW = (10.0, 40.0), (200.0, 25.0)


@pytest.mark.parametrize("sky", [0.0, 0.4])
@pytest.mark.parametrize("material", [Lambertian(0.7), OrenNayar(0.6, 0.3)])
def test_parts_are_the_separate_runs_exactly(material, sky):
    s = Scene.from_dem(rough_tile(amp=1.5), material=material)
    o = s.brf_orders(SUN, VIEW, spp=5000, max_depth=12, seed=4, sky=sky)
    assert isinstance(o, ScatteringOrders) and all(isinstance(e, Estimate) for e in (o.single, o.multiple, o.total))
    # bounce k draws the same random numbers whatever max_depth is
    assert o.single == s.brf(SUN, VIEW, spp=5000, max_depth=1, seed=4, sky=sky)
    assert o.total == s.brf(SUN, VIEW, spp=5000, max_depth=12, seed=4, sky=sky)
    assert o.single.value + o.multiple.value == pytest.approx(o.total.value, rel=1e-14, abs=0)
    assert o.multiple.value > 10 * o.multiple.se
    assert o.single.n == o.multiple.n == o.total.n == 5000


def test_mesh_and_canopy_scenes_split_too():
    c = disc_canopy(lai=2.0, leaf_radius=0.1, extent=1.5, height=(0.2, 1.0), seed=6)
    s = c.scene()
    o = s.brf_orders((0.0, 30.0), (120.0, 50.0), spp=4000, seed=1)
    assert o.single == s.brf((0.0, 30.0), (120.0, 50.0), spp=4000, max_depth=1, seed=1)
    assert o.total == s.brf((0.0, 30.0), (120.0, 50.0), spp=4000, seed=1)


def test_flat_plane_has_no_multiple_scattering():
    for s in (Scene.from_dem(np.zeros((6, 6)), material=Lambertian(0.35)),
              Scene.from_mesh(_square(), Lambertian(0.35), extent=(0.0, 0.0, 2.0, 2.0))):
        o = s.brf_orders((30.0, 50.0), (250.0, 20.0), spp=3000, max_depth=50)
        assert (o.multiple.value, o.multiple.se) == (0.0, 0.0)
        assert o.single.value == pytest.approx(0.35, abs=1e-12)
        assert o.total.value == pytest.approx(0.35, abs=1e-12)


def test_orders_scale_as_powers_of_rho():
    # Lambertian paths do not depend on rho (cosine sampling, weight rho): order k
    # carries exactly rho^k, so single / rho is the same for every rho and
    # multiple / rho^2 tends to the second-order term as rho -> 0 (multiple is O(rho^2))
    z = rough_tile(amp=1.5)
    res = {rho: Scene.from_dem(z, material=Lambertian(rho)).brf_orders(SUN, VIEW, spp=4000, max_depth=30, seed=6)
           for rho in (0.5, 1e-1, 1e-2, 1e-3)}
    base = res[0.5].single.value / 0.5
    for rho, o in res.items():
        assert o.single.value / rho == pytest.approx(base, rel=1e-12)
    m = {rho: o.multiple.value / rho ** 2 for rho, o in res.items()}
    assert m[0.5] > m[1e-1] > m[1e-2] > m[1e-3] > 0
    # the remainder is O(rho): the step 1e-2 -> 1e-3 is ten times smaller than 1e-1 -> 1e-2
    d1, d2 = m[1e-1] - m[1e-2], m[1e-2] - m[1e-3]
    assert 7 < d1 / d2 < 13, (d1, d2)
    ratio = [res[r].multiple.value / res[r].single.value for r in (1e-1, 1e-2, 1e-3)]
    assert ratio[0] / ratio[1] > 9 and ratio[1] / ratio[2] > 9.8, ratio


def test_conservative_v_grooves_single_is_the_closed_form():
    # white V-grooves of slope s seen at nadir: single scattering rho cos(s) for any
    # sun (the lit fraction of each face times its cosine), the rest is multiple
    s_deg = 30.0
    s = Scene.from_dem(v_grooves(8, s_deg), material=Lambertian(1.0))
    for sun in [(90.0, 20.0), (270.0, 70.0), (0.0, 75.0)]:
        o = s.brf_orders(sun, "nadir", spp=50_000, max_depth=1000, seed=5)
        assert abs(o.single.value - math.cos(math.radians(s_deg))) < 4 * o.single.se + 1e-9, o
        assert o.multiple.value > 0.05, o
        assert o.single.value + o.multiple.value == pytest.approx(o.total.value, rel=1e-14, abs=0)


def test_conservative_canopy_splits_exactly():
    c = disc_canopy(lai=2.0, leaf_radius=0.1, extent=1.5, height=(0.2, 1.0), lad="planophile", seed=4,
                    leaf=BiLambertian(0.6, 0.4), soil=Lambertian(1.0))
    s = c.scene()
    o = s.brf_orders((30.0, 35.0), "nadir", spp=20_000, max_depth=100_000, seed=1)
    assert o.single.value + o.multiple.value == pytest.approx(o.total.value, rel=1e-14, abs=0)
    assert o.total == s.brf((30.0, 35.0), "nadir", spp=20_000, max_depth=100_000, seed=1)
    # no absorption: most of the light leaving towards the sensor was scattered more than once
    assert o.multiple.value > o.single.value > 0.1, o


def test_standard_error_of_multiple_matches_the_spread_over_seeds():
    # se comes from each part's own per-path values; independent seeds scatter
    # the estimates by that much (40 seeds: the ratio is 1 within about 0.25)
    s = Scene.from_dem(rough_tile(amp=1.5), material=Lambertian(0.8))
    runs = [s.brf_orders(SUN, VIEW, spp=8192, max_depth=20, seed=k) for k in range(40)]
    for part in ("single", "multiple", "total"):
        vals = np.array([getattr(o, part).value for o in runs])
        ses = np.array([getattr(o, part).se for o in runs])
        assert 0.7 < np.std(vals, ddof=1) / np.sqrt(np.mean(ses ** 2)) < 1.4, part
    # and not the sum of the other two standard errors (the parts are correlated)
    o = runs[0]
    assert o.multiple.se < 0.9 * (o.single.se + o.total.se), o


def test_thread_count_does_not_change_the_split():
    s = Scene.from_dem(rough_tile(8), material=Lambertian(0.5))
    a = s.brf_orders(SUN, VIEW, spp=5000, seed=9, sky=0.2, n_threads=1)
    assert a == s.brf_orders(SUN, VIEW, spp=5000, seed=9, sky=0.2, n_threads=2)


@pytest.mark.parametrize("kwargs, param", [
    (dict(spp=0), "spp"), (dict(max_depth=0), "max_depth"), (dict(sky=-1.0), "sky"),
    (dict(view=(0.0, 95.0)), "view"), (dict(n_threads=0), "n_threads"),
])
def test_bad_input_names_the_parameter(kwargs, param):
    s = Scene.from_dem(np.zeros((4, 4)))
    with pytest.raises(ValueError, match=f"^{param}"):
        s.brf_orders(**{"sun": (0.0, 30.0), **kwargs})
