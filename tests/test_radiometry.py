"""The radiometric experiment against closed forms and invariants.

Expected values never come from the code under test: the facet sums are
computed here from the DEM with NumPy, the V-groove and flat-plane values
are closed forms, and energy conservation, reciprocity and the ordering of
single and multiple scattering are physical invariants.
"""
import numpy as np
import pytest

import fractalgeo_rs as fg
from fractalgeo_rs.radiometry import Estimate, Lambertian, OrenNayar, Phong, Scene


def periodic_surface(n=16, amp=4.0, seed=0, modes=3):
    """A periodic rough surface: random Fourier modes with a 1/k spectrum."""
    rng = np.random.default_rng(seed)
    r, c = np.mgrid[0:n, 0:n]
    z = np.zeros((n, n))
    for kx in range(-modes, modes + 1):
        for ky in range(-modes, modes + 1):
            if kx == 0 and ky == 0:
                continue
            a = amp * rng.standard_normal() / np.hypot(kx, ky) ** 1.5
            z += a * np.cos(2 * np.pi * (kx * c + ky * r) / n + rng.uniform(0, 2 * np.pi))
    return z


def grooves(slope_deg, n=8, cell=1.0):
    """Periodic V-grooves along the rows (north-south), period 2 cells."""
    h = cell * np.tan(np.radians(slope_deg))
    return np.where(np.arange(n) % 2 == 1, h, 0.0)[None, :].repeat(n, 0)


def facet_sums(z, cell=1.0, cell_y=None):
    """sum(A nz^2), sum(A nz) over the NE-SW facets of a periodic DEM with
    cells ``cell`` (east-west) by ``cell_y`` (north-south, default ``cell``)."""
    cy = cell if cell_y is None else cell_y
    zp = np.pad(z, ((0, 1), (0, 1)), mode="wrap")
    # corner: (east, north) offset in cells, heights of that corner of every cell
    corner = {"nw": ((0, 0), zp[:-1, :-1]), "ne": ((1, 0), zp[:-1, 1:]),
              "sw": ((0, -1), zp[1:, :-1]), "se": ((1, -1), zp[1:, 1:])}
    num = den = 0.0
    for tri in (("nw", "sw", "ne"), ("ne", "sw", "se")):
        (pa, a), (pb, b), (pc, c) = (corner[k] for k in tri)

        def edge(p, h):
            return np.stack([np.full_like(a, (p[0] - pa[0]) * cell), np.full_like(a, (p[1] - pa[1]) * cy), h - a], -1)

        cr = np.cross(edge(pb, b), edge(pc, c))
        length = np.linalg.norm(cr, axis=-1)
        assert (cr[..., 2] > 0).all()  # counter-clockwise seen from above
        area, nz = 0.5 * length, cr[..., 2] / length
        num += float(np.sum(area * nz * nz))
        den += float(np.sum(area * nz))
    return num, den


def close(e, expect, k=3.0):
    return abs(e.value - expect) <= k * e.se + 1e-9


@pytest.mark.parametrize("periodic", [True, False])
def test_flat_plane_is_rho_for_every_direction(periodic):
    s = Scene.from_dem(np.full((5, 6), 12.0), cell_size=30.0, periodic=periodic, material=Lambertian(0.42))
    for sun, view in [((0, 0), "nadir"), ((135, 60), (10, 30)), ((270, 85), (90, 0)), ((10, 30), (190, 70))]:
        for depth in (1, 4):
            e = s.brf(sun=sun, view=view, spp=3000, max_depth=depth)
            if periodic or (sun[1] == 0 and view == "nadir"):
                assert abs(e.value - 0.42) < 1e-6 and e.se < 1e-6, (sun, view, e)
    if periodic:
        for zen in (0, 45, 80):
            a = s.albedo(sun=(33, zen), spp=3000)
            assert abs(a.value - 0.42) < 1e-6 and a.se < 1e-6


def test_nadir_single_scattering_is_the_facet_mean_of_nz():
    z = periodic_surface(16, 5.0, seed=3)
    num, den = facet_sums(z, cell=2.0)
    rho = 0.7
    s = Scene.from_dem(z, cell_size=2.0, material=Lambertian(rho))
    e = s.brf(sun=(0, 0), view=(0, 0), spp=200_000, max_depth=1, seed=1)
    assert close(e, rho * num / den), (e, rho * num / den)
    assert rho * num / den < 0.97 * rho
    # rectangular cells (a geographic DEM's metres east-west and north-south)
    num, den = facet_sums(z, cell=1.5, cell_y=3.0)
    s = Scene.from_dem(z, cell_size=(3.0, 1.5), material=Lambertian(rho))  # (dy, dx)
    e = s.brf(sun=(0, 0), view=(0, 0), spp=200_000, max_depth=1, seed=1)
    assert close(e, rho * num / den), (e, rho * num / den)


def test_v_grooves_nadir_single_scattering_is_rho_cos_s():
    s_deg, rho = 25.0, 0.9
    sc = Scene.from_dem(grooves(s_deg), material=Lambertian(rho))
    expect = rho * np.cos(np.radians(s_deg))
    # unshadowed and shadowed suns (across the grooves at 75 and 85 degrees)
    for sun in [(0, 0), (90, 30), (270, 50), (0, 80), (45, 60), (90, 75), (270, 85)]:
        e = sc.brf(sun=sun, spp=100_000, max_depth=1, seed=2)
        assert close(e, expect), (sun, e, expect)


@pytest.mark.parametrize("zenith", [0.0, 45.0, 80.0])
def test_white_periodic_surface_reflects_everything(zenith):
    z = fg.fbm_surface((32, 32), 0.5, method="spectral", periodic=True, seed=4, sigma=3.0)
    s = Scene.from_dem(z, material=Lambertian(1.0))
    a = s.albedo(sun=(60.0, zenith), spp=20_000, max_depth=2000, seed=5)
    assert abs(a.value - 1.0) < 1e-3, a
    assert s.albedo(sun=(60.0, zenith), spp=20_000, max_depth=1, seed=5).value < 1.0


@pytest.mark.parametrize("material", [Lambertian(0.6), OrenNayar(0.6, 0.5), Phong(0.3, 0.4, 10.0)])
def test_brf_is_reciprocal(material):
    z = fg.fbm_surface((16, 16), 0.7, method="spectral", periodic=True, seed=6, sigma=2.0)
    s = Scene.from_dem(z, material=material)
    for a, b in [((0, 35), (180, 55)), ((70, 60), (300, 15))]:
        f = s.brf(sun=a, view=b, spp=200_000, max_depth=5, seed=1, reciprocity=False)
        g = s.brf(sun=b, view=a, spp=200_000, max_depth=5, seed=2, reciprocity=False)
        assert abs(f.value - g.value) < 3 * np.hypot(f.se, g.se), (a, b, f, g)


def test_single_scattering_never_exceeds_multiple():
    z = periodic_surface(16, 1.5, seed=8)
    last = np.inf
    for rho in (0.9, 0.5, 0.1, 0.01):
        s = Scene.from_dem(z, material=Lambertian(rho))
        one = s.brf(sun=(20, 50), view=(250, 30), spp=20_000, max_depth=1, seed=3)
        many = s.brf(sun=(20, 50), view=(250, 30), spp=20_000, max_depth=30, seed=3)
        assert one.value <= many.value  # same paths: multiple adds non-negative terms
        share = (many.value - one.value) / many.value
        assert share < last, (rho, share)  # goes to 0 with rho
        last = share
    assert last < 0.02


def test_results_identical_for_any_thread_count():
    s = Scene.from_dem(periodic_surface(12, 4.0, seed=9), material=OrenNayar(0.5, 0.3))
    for f in (lambda n: s.brf(sun=(10, 40), view=(100, 20), spp=5000, max_depth=4, n_threads=n),
              lambda n: s.albedo(sun=(10, 40), spp=5000, max_depth=4, n_threads=n)):
        assert f(1) == f(2)
    a = s.render(sun=(10, 40), shape=(7, 9), spp=3, n_threads=1)
    b = s.render(sun=(10, 40), shape=(7, 9), spp=3, n_threads=2)
    assert a.dtype == np.float32 and a.shape == (7, 9)
    np.testing.assert_array_equal(a, b)


def test_image_mean_estimates_the_brf():
    z = periodic_surface(8, 3.0, seed=10)
    s = Scene.from_dem(z, material=Lambertian(0.5))
    img = s.render(sun=(0, 30), view=(45, 20), shape=(16, 16), spp=200, max_depth=3, seed=7)
    brf = s.brf(sun=(0, 30), view=(45, 20), spp=400_000, max_depth=3, seed=8)
    per_pixel = np.pi * img.astype(np.float64) / np.cos(np.radians(30))
    se_img = per_pixel.std() / np.sqrt(img.size)  # pixels are independent
    assert abs(per_pixel.mean() - brf.value) < 4 * np.hypot(se_img, brf.se) + 1e-3


def test_a_finite_patch_loses_light_through_its_sides():
    z = periodic_surface(16, 5.0, seed=11)
    tile = Scene.from_dem(z, material=Lambertian(1.0))
    patch = Scene.from_dem(z, periodic=False, material=Lambertian(1.0))
    assert abs(tile.albedo(sun=(90, 70), spp=20_000, max_depth=300).value - 1.0) < 1e-3
    assert patch.albedo(sun=(90, 70), spp=20_000, max_depth=300).value < 0.99


def test_bad_input_is_a_clear_error():
    z = np.zeros((4, 4))
    s = Scene.from_dem(z)
    with pytest.raises(ValueError, match=r"^sun: zenith must be in \[0, 90\)"):
        s.brf(sun=(0, 90))
    with pytest.raises(ValueError, match="^view: zenith"):
        s.brf(sun=(0, 10), view=(0, 95))
    with pytest.raises(TypeError, match="^sun: expected"):
        s.albedo(sun=30.0)
    with pytest.raises(ValueError, match="^rho: expected a reflectance in"):
        Lambertian(1.5)
    with pytest.raises(ValueError, match="^rho"):
        OrenNayar(-0.1, 0.2)
    with pytest.raises(ValueError, match="^sigma"):
        OrenNayar(0.5, float("nan"))
    with pytest.raises(ValueError, match=r"^ks: expected kd \+ ks <= 1"):
        Phong(0.6, 0.6, 5.0)
    with pytest.raises(ValueError, match="^exponent"):
        Phong(0.2, 0.2, -1.0)
    bad = z.copy()
    bad[2, 1] = np.nan
    with pytest.raises(ValueError, match="^dem: expected finite heights.*row 2, column 1"):
        Scene.from_dem(bad)
    with pytest.raises(ValueError, match="^dem: expected a 2D"):
        Scene.from_dem(np.zeros(5))
    with pytest.raises(ValueError, match="^spp"):
        s.brf(sun=(0, 0), spp=0)
    with pytest.raises(ValueError, match="^max_depth"):
        s.brf(sun=(0, 0), max_depth=0)
    with pytest.raises(ValueError, match="^split"):
        Scene.from_dem(z, split="diagonal")
    with pytest.raises(TypeError, match="^material"):
        Scene.from_dem(z, material=0.5)
    with pytest.raises(ValueError, match="^cell_size"):
        Scene.from_dem(z, cell_size=0)
    with pytest.raises(ValueError, match="^cell_size"):
        Scene.from_dem(z, cell_size=(1.0, -2.0))
    with pytest.raises(TypeError, match="^cell_size"):
        Scene.from_dem(z, cell_size="30 m")
    with pytest.raises(ValueError, match="^seed"):
        s.brf(sun=(0, 0), seed=-1)
    with pytest.raises(MemoryError, match="^shape"):
        s.render(sun=(0, 0), shape=(100_000, 10_000))
    with pytest.raises(ValueError, match="^n_threads"):
        s.brf(sun=(0, 0), n_threads=0)


def test_the_kernel_checks_too():
    from fractalgeo_rs import _core

    z = np.zeros((3, 3))

    def scene(name="lambertian", params=(0.5,)):
        return _core.RadiometryScene.from_dem(z, (1.0, 1.0), True, "ne-sw", [(name, list(params))], None)

    with pytest.raises(ValueError, match="^sun: zenith"):
        scene().brf((0, 91), (0, 0), 10, 1, 0)
    with pytest.raises(ValueError, match="^rho"):
        scene(params=(2.0,))
    with pytest.raises(ValueError, match="^material"):
        scene("hapke")
    with pytest.raises(MemoryError, match="^shape"):
        scene().render_series([(0, 0)], (0, 0), 0.0, (10**5, 10**5), 1, 1, 0, "box", [])
    with pytest.raises(MemoryError, match="^shape"):
        scene().render_series([(0, 0)] * 3, (0, 0), 0.0, (10**4, 10**4), 1, 1, 0, "box", [])
    with pytest.raises(ValueError, match="^suns"):
        scene().render_series([], (0, 0), 0.0, (2, 2), 1, 1, 0, "box", [])
    with pytest.raises(ValueError, match="^sun: zenith"):
        scene().render_series([(0, 0), (0, 90)], (0, 0), 0.0, (2, 2), 1, 1, 0, "box", [])


def test_mismatched_periodic_edges_warn_and_mirroring_fixes_them():
    ramp = np.add.outer(np.arange(10.0), np.zeros(10))  # a north-south trend
    with pytest.warns(UserWarning, match="north-south edges"):
        Scene.from_dem(ramp)
    mirrored = np.block([[ramp, ramp[:, ::-1]], [ramp[::-1], ramp[::-1, ::-1]]])
    Scene.from_dem(mirrored)  # no warning (warnings are errors in this suite)
    Scene.from_dem(ramp, periodic=False)


def test_inputs_are_not_modified_and_any_layout_works():
    z = periodic_surface(8, 2.0, seed=12)
    before = z.copy()
    a = Scene.from_dem(z).brf(sun=(0, 20), spp=2000)
    b = Scene.from_dem(np.asfortranarray(z)).brf(sun=(0, 20), spp=2000)
    np.testing.assert_array_equal(z, before)
    assert a == b and isinstance(a, Estimate)
    assert not Scene.from_dem(z).dem.flags.writeable


def _unit(az, zen):
    a, z = np.radians(az), np.radians(zen)
    return np.array([np.sin(a) * np.sin(z), np.cos(a) * np.sin(z), np.cos(z)])


def test_a_flat_plane_returns_pi_times_the_facet_brdf():
    """On a flat plane every path sees one facet, lit: BRF = pi f(sun, view)
    exactly, for any model (closed forms of Oren-Nayar 1994 and
    Lafortune-Willems 1994 written here in angles)."""
    kd, ks, n = 0.2, 0.5, 8.0
    rho, sigma = 0.6, 0.4
    glossy = Scene.from_dem(np.zeros((4, 4)), material=Phong(kd, ks, n))
    rough = Scene.from_dem(np.zeros((4, 4)), material=OrenNayar(rho, sigma))
    a = 1 - 0.5 * sigma**2 / (sigma**2 + 0.33)
    b = 0.45 * sigma**2 / (sigma**2 + 0.09)
    for sun, view in [((0, 30), (180, 30)), ((0, 30), (150, 40)), ((90, 60), (0, 10)), ((10, 50), (20, 70))]:
        si, vo = _unit(*sun), _unit(*view)
        ca = max(0.0, float(si @ np.array([-vo[0], -vo[1], vo[2]])))
        phong = np.pi * (kd / np.pi + ks * (n + 2) / (2 * np.pi) * ca**n)
        alpha, beta = np.radians(max(sun[1], view[1])), np.radians(min(sun[1], view[1]))
        cdphi = np.cos(np.radians(sun[0] - view[0]))
        oren = rho * (a + b * max(0.0, cdphi) * np.sin(alpha) * np.tan(beta))
        for depth in (1, 3):
            assert abs(glossy.brf(sun=sun, view=view, spp=300, max_depth=depth).value - phong) < 1e-9
            assert abs(rough.brf(sun=sun, view=view, spp=300, max_depth=depth).value - oren) < 1e-9


def vgroove_single_brf(rho, s_deg, sun, view, m=400_000):
    """Single-scattering BRF of periodic V-grooves with sun and view in the
    plane across the grooves, from the exact 2D lit-and-visible geometry of
    one groove (Torrance and Sparrow 1967): the groove x in [-1, 1] cells,
    height h |x|; a point is lit (seen) when the ray to the sun (sensor)
    clears the peak on its side; each point counts with its projected
    width (n . v) / v_z on the reference line. Midpoint rule, m points."""
    h = np.tan(np.radians(s_deg))
    x = (np.arange(m) + 0.5) / m * 2 - 1
    z = h * np.abs(x)
    nx, nz = np.where(x < 0, h, -h) / np.hypot(1, h), 1 / np.hypot(1, h)

    def in_plane(az, zen):  # (east, up) of a direction of azimuth 90 or 270
        t = np.radians(zen)
        return (1.0 if az == 90 else -1.0) * np.sin(t), np.cos(t)

    def clear(dx, dz):
        if dx == 0:
            return np.ones_like(x, bool)
        far = 1 - x if dx > 0 else x + 1  # horizontal distance to the peak ahead
        return z + far * dz / abs(dx) >= h - 1e-12

    (sx, sz), (vx, vz) = in_plane(*sun), in_plane(*view)
    ns, nv = nx * sx + nz * sz, nx * vx + nz * vz
    seen = clear(sx, sz) & (ns > 0) & clear(vx, vz) & (nv > 0)
    length = 2.0 / m * np.hypot(1, h)  # facet length per point
    radiance = np.sum(seen * rho / np.pi * ns * nv / vz) * length / 2.0  # per unit reference width
    return np.pi * radiance / sz


def test_v_grooves_oblique_sun_and_view_match_the_interval_geometry():
    s_deg, rho = 30.0, 0.8
    sc = Scene.from_dem(grooves(s_deg), material=Lambertian(rho))
    # nadir check of the reference itself: rho cos(s)
    assert abs(vgroove_single_brf(rho, s_deg, (90, 50), (0, 0)) - rho * np.cos(np.radians(s_deg))) < 1e-5
    for sun, view in [((90, 50), (270, 40)), ((90, 70), (90, 30)), ((270, 40), (90, 20)),
                      ((90, 45), (90, 45)), ((90, 80), (90, 60)), ((90, 80), (270, 20))]:
        expect = vgroove_single_brf(rho, s_deg, sun, view)
        assert expect > 0.05
        e = sc.brf(sun=sun, view=view, spp=200_000, max_depth=1, seed=4)
        assert abs(e.value - expect) < 3 * e.se + 1e-5, (sun, view, e, expect)


def test_real_dem_warns_raw_and_conserves_energy_mirrored():
    """The bundled SRTM Alps DEM (rectangular geographic cells): as a
    periodic tile its edges do not match (a warning); mirrored it tiles, and
    a white surface then reflects all the sun's flux."""
    z, info = fg.data.srtm_alps()
    z = z[:96, :128]
    cell = tuple(float(v) for v in info["cell_size"])
    with pytest.warns(UserWarning, match="opposite edges do not match"):
        Scene.from_dem(z, cell_size=cell)
    m = np.block([[z, z[:, ::-1]], [z[::-1], z[::-1, ::-1]]])
    white = Scene.from_dem(m, cell_size=cell, material=Lambertian(1.0))
    for zen in (0.0, 60.0):
        a = white.albedo(sun=(135.0, zen), spp=20_000, max_depth=1000)
        assert abs(a.value - 1.0) < 1e-3, a


# ---- Hapke, BRF sweeps, image files, CLI (second round) ----

#: Eradiate 0.5.0 ``hapke`` BSDF (scalar_mono_double, flat), measured
#: (RADIOMETRY_REFERENCES.md 4.1): (sun (zenith, azimuth), view, BRF).
ERADIATE_HAPKE = [
    ((0.5, 0.2, 0.4, 15.0, 1.0, 0.05), [
        ((30, 0), (0, 0), 0.113820), ((30, 0), (30, 0), 0.192827), ((30, 0), (30, 180), 0.107831),
        ((60, 0), (45, 180), 0.139896), ((60, 0), (20, 90), 0.122498), ((30, 0), (28, 0), 0.171040)]),
    ((0.8, 0.3, 0.6, 25.0, 0.0, 0.0), [
        ((30, 0), (0, 0), 0.288117), ((30, 0), (30, 180), 0.251600), ((60, 0), (45, 180), 0.215051)]),
]


@pytest.mark.parametrize("params,cases", ERADIATE_HAPKE)
def test_hapke_on_a_flat_plane_matches_eradiate(params, cases):
    """A flat plane's BRF is the facet's BRF: Eradiate's reference values to
    1e-5, through the whole path tracer, and reciprocal."""
    from fractalgeo_rs.radiometry import Hapke

    s = Scene.from_dem(np.zeros((4, 4)), material=Hapke(*params))
    for (zs, azs), (zv, azv), want in cases:
        for depth in (1, 4):
            e = s.brf(sun=(azs, zs), view=(azv, zv), spp=50, max_depth=depth, reciprocity=False)
            assert abs(e.value - want) < 1e-5, (zs, azs, zv, azv, e)
        back = s.brf(sun=(azv, zv), view=(azs, zs), spp=50, reciprocity=False).value
        assert abs(back - want) < 1e-5


def test_hapke_is_finite_at_exact_backscatter_with_h_zero():
    from fractalgeo_rs.radiometry import Hapke

    for b0 in (1.0, 0.0):
        s = Scene.from_dem(np.zeros((4, 4)), material=Hapke(0.8, 0.3, 0.6, 25.0, b0, 0.0))
        v = s.brf(sun=(0, 30), view=(0, 30), spp=10).value
        assert np.isfinite(v) and v > 0
    # without a surge the model is continuous there (Eradiate: NaN)
    near = s.brf(sun=(0, 30), view=(0, 30.001), spp=10).value
    assert abs(near - v) < 1e-4


def test_hapke_rough_surface_is_reciprocal_and_rejects_unphysical_parameters():
    from fractalgeo_rs.radiometry import Hapke

    z = fg.fbm_surface((16, 16), 0.7, method="spectral", periodic=True, seed=6, sigma=2.0)
    s = Scene.from_dem(z, material=Hapke(0.6, 0.3, 0.6, 20.0, 0.8, 0.06))
    for a, b in [((0, 35), (180, 55)), ((70, 60), (300, 15))]:
        f = s.brf(sun=a, view=b, spp=100_000, max_depth=4, seed=1, reciprocity=False)
        g = s.brf(sun=b, view=a, spp=100_000, max_depth=4, seed=2, reciprocity=False)
        assert abs(f.value - g.value) < 3 * np.hypot(f.se, g.se), (a, b, f, g)
    with pytest.raises(ValueError, match="^w: .*> 1"):
        Scene.from_dem(z, material=Hapke(1.0, 0.7, 1.0, 0.0, 1.0, 0.3)).brf(sun=(0, 30), spp=10)
    for kw, bad in [("w", 1.5), ("b", 1.0), ("c", -0.1), ("theta_bar", 90.0), ("B0", 2.0), ("h", float("nan"))]:
        p = dict(w=0.5, b=0.2, c=0.4, theta_bar=15.0, B0=1.0, h=0.05)
        p[kw] = bad
        with pytest.raises(ValueError, match=f"^{kw}: "):
            Hapke(**p)


def test_brf_sweep_matches_single_brf_calls_and_vgroove_closed_form():
    s = Scene.from_dem(grooves(30.0), material=Lambertian(1.0))
    sw = s.brf_sweep(sun_azimuth=90.0, spp=20_000, max_depth=1, seed=3)
    assert sw.value.shape == sw.se.shape == (7, 1)
    assert sw.sun_zenith.tolist() == [0, 15, 30, 45, 60, 75, 89]
    # single scattering, nadir view: rho cos(s) for every sun (V-grooves)
    assert np.all(np.abs(sw.value[:, 0] - np.cos(np.radians(30))) < 4 * sw.se[:, 0] + 1e-12)
    one = s.brf(sun=(90.0, 45.0), spp=20_000, max_depth=1, seed=3)
    assert (sw.value[3, 0], sw.se[3, 0]) == (one.value, one.se)
    two = s.brf_sweep(sun_zenith=[10, 50], view_zenith=[0, 20, 40], spp=100, max_depth=2)
    assert two.value.shape == (2, 3) and np.all(two.se >= 0)
    with pytest.raises(ValueError, match="^sun_zenith: .*90"):
        s.brf_sweep(sun_zenith=[0, 90])
    with pytest.raises(ValueError, match="^view_zenith: "):
        s.brf_sweep(view_zenith=[])


def test_render_progress_does_not_change_the_image():
    z = periodic_surface(8)
    s = Scene.from_dem(z, material=Lambertian(0.7))
    a = s.render(sun=(135, 30), spp=4, progress=False)
    b = s.render(sun=(135, 30), spp=4, progress=True)
    np.testing.assert_array_equal(a, b)


def test_render_series_equals_one_render_per_sun():
    """The one-pass incidence series gives each sun's image bit for bit,
    with a PSF and sky light, on DEM and mesh scenes, for any n_threads."""
    from fractalgeo_rs.geometry import Mesh

    z = periodic_surface(8)
    suns = [(90.0, 0.0), (135.0, 30.0), (200.0, 75.0), (10.0, 89.0)]
    dem = Scene.from_dem(z, material=Lambertian(0.6))
    r, c = np.mgrid[0:9, 0:9]
    v = np.stack([c, -r, np.pad(z, ((0, 1), (0, 1)), mode="wrap")], -1).reshape(-1, 3).astype(float)
    idx = np.arange(81).reshape(9, 9)
    nw, ne, sw, se = idx[:-1, :-1], idx[:-1, 1:], idx[1:, :-1], idx[1:, 1:]
    f = np.stack([np.stack([nw, sw, ne], -1), np.stack([ne, sw, se], -1)], 2).reshape(-1, 3)
    mesh = Scene.from_mesh(Mesh.from_triangles(v, f), materials=OrenNayar(0.5, 0.3), periodic=True,
                           extent=(0.0, -8.0, 8.0, 8.0))
    for s, kw in [(dem, {}), (dem, {"sky": 0.3, "psf": ("gaussian", 0.8), "view": (40.0, 25.0)}),
                  (mesh, {"sky": 0.2})]:
        series = s.render_series(suns, shape=(5, 6), spp=3, max_depth=4, seed=7, n_threads=2, **kw)
        assert series.shape == (4, 5, 6) and series.dtype == np.float32
        for k, sun in enumerate(suns):
            one = s.render(sun=sun, shape=(5, 6), spp=3, max_depth=4, seed=7, n_threads=1, **kw)
            np.testing.assert_array_equal(series[k], one)
        # the sun at 89 degrees lights less than the sun at 0
        assert series[3].mean() < series[0].mean()


def test_render_series_bad_input():
    s = Scene.from_dem(periodic_surface(4), material=Lambertian(0.5))
    with pytest.raises(ValueError, match="^suns: .*at least one"):
        s.render_series([])
    with pytest.raises(TypeError, match="^suns: "):
        s.render_series((0.0, 30.0))  # one pair, not a sequence of pairs
    with pytest.raises(ValueError, match="^suns: zenith must be in"):
        s.render_series([(0.0, 30.0), (0.0, 90.0)])
    with pytest.raises(TypeError, match="^suns: "):
        s.render_series("nadir")
    with pytest.raises(MemoryError, match="shape"):
        s.render_series([(0.0, 0.0)] * 4, shape=(1000, 1000), max_memory=10_000_000)
    # the limit is the stack itself: the kernel writes it in place (no second buffer)
    stack = 2 * 100 * 100 * 4
    with pytest.raises(MemoryError, match="shape"):
        s.render_series([(0.0, 0.0)] * 2, shape=(100, 100), max_memory=stack - 1)
    assert s.render_series([(0.0, 0.0)] * 2, shape=(100, 100), spp=1, max_memory=stack).shape == (2, 100, 100)


def test_images_are_written_whole_with_georeferencing(tmp_path):
    rasterio = pytest.importorskip("rasterio")
    from affine import Affine

    z = periodic_surface(8)
    t = Affine(30.0, 0.0, 500000.0, 0.0, -30.0, 4000000.0)
    s = Scene.from_dem(z, cell_size=30.0, material=Lambertian(0.5),
                       profile={"crs": rasterio.crs.CRS.from_epsg(32633), "transform": t})
    img = s.render(sun=(135, 30), shape=(4, 8), spp=4)
    s.save_image(tmp_path / "a.exr", img)
    back, _ = fg.read_raster(tmp_path / "a.exr")
    np.testing.assert_array_equal(back, img)
    s.save_image(tmp_path / "a.tif", img)
    with rasterio.open(tmp_path / "a.tif") as src:
        np.testing.assert_array_equal(src.read(1), img)
        assert src.crs.to_epsg() == 32633
        # vertices at pixel centres; 8 x 8 cells over 4 x 8 pixels: 60 m rows, 30 m columns
        assert tuple(src.transform)[:6] == (30.0, 0.0, 500015.0, 0.0, -60.0, 3999985.0)
    s.save_image(tmp_path / "a.png", img)
    png, _ = fg.read_raster(tmp_path / "a.png")
    np.testing.assert_array_equal(png, np.clip(np.round(img.astype(np.float64) * np.pi * 255), 0, 255))
    assert (tmp_path / "a.pgw").exists() and (tmp_path / "a.prj").exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.exr", "a.pgw", "a.png", "a.prj", "a.tif"]
    with pytest.raises(ValueError, match="^path: "):
        s.save_image(tmp_path / "a.jpg", img)


def test_cli_render_and_brf(tmp_path, capsys):
    from fractalgeo_rs import cli

    z = np.zeros((6, 6))
    np.save(tmp_path / "dem.npy", z)
    out = tmp_path / "out.exr"
    assert cli.main(["render", str(tmp_path / "dem.npy"), str(out), "--sun", "135", "30", "--view", "nadir",
                     "--spp", "4", "--cell-size", "1", "--material", "lambertian:0.4", "--no-progress"]) == 0
    img, _ = fg.read_raster(out)
    assert img.shape == (6, 6) and np.allclose(img, 0.4 * np.cos(np.radians(30)) / np.pi, rtol=1e-6)
    csv = tmp_path / "brf.csv"
    assert cli.main(["brf", str(tmp_path / "dem.npy"), "--sun-zenith", "0,15,30,45,60,75,89", "--csv", str(csv),
                     "--spp", "10", "--cell-size", "1", "--material", "hapke:0.5,0.2,0.4,15,1,0.05",
                     "--view-zenith", "30", "--view-azimuth", "180"]) == 0
    rows = np.genfromtxt(csv, delimiter=",", names=True)
    assert rows["sun_zenith"].tolist() == [0, 15, 30, 45, 60, 75, 89]
    assert abs(rows["brf"][2] - 0.107831) < 1e-5  # Eradiate's (30, 0) -> (30, 180)
    capsys.readouterr()
    assert cli.main(["brf", str(tmp_path / "dem.npy"), "--sun-zenith", "0,95", "--cell-size", "1"]) == 1
    assert "--sun-zenith" in capsys.readouterr().err
    assert cli.main(["render", str(tmp_path / "dem.npy"), str(out), "--sun", "0", "30", "--cell-size", "1",
                     "--material", "hapke:2"]) == 1
    assert "--material" in capsys.readouterr().err
    # a wrong output name fails before the DEM is read and rendered (here the DEM does not even exist)
    for bad in ("out.jpg", "no_such_dir/out.exr"):
        assert cli.main(["render", str(tmp_path / "missing.npy"), str(tmp_path / bad), "--sun", "0", "30",
                         "--cell-size", "1"]) == 1
        err = capsys.readouterr().err
        assert "output" in err and "missing.npy" not in err


def test_specular_flat_mirror_reflects_the_fresnel_fraction():
    """Normal incidence ((n - 1)/(n + 1))^2 and Brewster's angle (r_p = 0,
    F = ((n^2 - 1)/(n^2 + 1))^2 / 2); BRF of a flat mirror is 0 (a delta)."""
    from fractalgeo_rs.radiometry import Specular

    n = 1.5
    s = Scene.from_dem(np.zeros((4, 4)), material=Specular(n))
    assert abs(s.albedo(sun=(0, 0), spp=10).value - ((n - 1) / (n + 1)) ** 2) < 1e-12
    brewster = np.degrees(np.arctan(n))
    assert abs(s.albedo(sun=(30, brewster), spp=10).value - 0.5 * ((n * n - 1) / (n * n + 1)) ** 2) < 1e-12
    assert s.brf(sun=(0, 30), view=(180, 30), spp=10).value == 0.0
    with pytest.raises(ValueError, match="^eta: "):
        Specular(0.0)
    with pytest.raises(ValueError, match="^k: "):
        Specular(1.5, k=-1.0)


def test_ray_batches_hit_a_flat_plane_exactly():
    """The ray-batch bindings of the benches: a flat plane at z = 2 is hit at t = 8 / cos(zenith)
    from z = 10, with the upward normal; rays going up from it are never occluded, rays going
    down always are; bad shapes name the parameter."""
    from fractalgeo_rs import _core

    z = np.full((6, 5), 2.0)
    rng = np.random.default_rng(3)
    n = 500
    o = np.column_stack([rng.random(n) * 5, -rng.random(n) * 6, np.full(n, 10.0)])
    zen = rng.random(n) * 1.4
    az = rng.random(n) * 2 * np.pi
    d = np.column_stack([np.sin(az) * np.sin(zen), np.cos(az) * np.sin(zen), -np.cos(zen)])
    for periodic in (True, False):
        t, facet, normal = _core.radiometry_intersect(z, (1.0, 1.0), periodic, "ne-sw", o, d)
        hit = facet >= 0
        if periodic:
            assert hit.all()
        np.testing.assert_allclose(t[hit], 8.0 / np.cos(zen[hit]), rtol=1e-12)
        np.testing.assert_array_equal(normal[hit], np.tile([0.0, 0.0, 1.0], (hit.sum(), 1)))
        p = o[hit] + t[hit, None] * d[hit]
        up = _core.radiometry_occluded(z, (1.0, 1.0), periodic, "ne-sw", p, -d[hit], facet[hit])
        assert not up.any()
        down = _core.radiometry_occluded(z, (1.0, 1.0), periodic, "ne-sw", o[hit], d[hit])
        assert down.all()
    with pytest.raises(ValueError, match="origins"):
        _core.radiometry_intersect(z, (1.0, 1.0), True, "ne-sw", o[:, :2], d)
    with pytest.raises(ValueError, match="directions"):
        _core.radiometry_intersect(z, (1.0, 1.0), True, "ne-sw", o, d[:3])
    with pytest.raises(ValueError, match="skip"):
        _core.radiometry_occluded(z, (1.0, 1.0), True, "ne-sw", o, d, np.zeros(3, dtype=np.int64))


@pytest.mark.parametrize("sun, view", [((90.0, 75.0), (0.0, 0.0)), ((90.0, 89.0), (0.0, 0.0)),
                                       ((30.0, 85.0), (200.0, 30.0))])
def test_brf_standard_errors_are_honest_at_grazing_sun(sun, view):
    """The randomised-QMC standard error (spread of the replicate means) is
    calibrated where most of a rough tile is in shadow: over 100 seeds the
    z-scores against a long run have a mean square near 1 and few beyond 3."""
    z = fg.fbm_surface((16, 16), 0.5, method="spectral", periodic=True, seed=4, sigma=0.6)
    s = Scene.from_dem(z, material=Lambertian(0.5))
    ref = s.brf(sun=sun, view=view, spp=1 << 20, max_depth=3, seed=10_000)
    zs = []
    for seed in range(100):
        e = s.brf(sun=sun, view=view, spp=16384, max_depth=3, seed=seed)
        assert e.se > 0.0
        zs.append((e.value - ref.value) / np.hypot(e.se, ref.se))
    zs = np.array(zs)
    assert 0.6 <= np.mean(zs**2) <= 1.6, np.mean(zs**2)
    assert np.sum(np.abs(zs) > 3) <= 3, zs
    one = s.brf(sun=sun, view=view, spp=4096, max_depth=3, seed=5, n_threads=1)
    assert one == s.brf(sun=sun, view=view, spp=4096, max_depth=3, seed=5, n_threads=2)


def test_a_dem_scene_keeps_its_kernel_scene_and_rebuilds_it_when_changed():
    import pickle

    z = np.zeros((4, 4))
    s = Scene.from_dem(z, material=Lambertian(0.3))
    assert s.brf(sun=(0.0, 30.0), spp=256).value == pytest.approx(0.3, abs=1e-12)
    kept = s._scene_core()
    assert s._scene_core() is kept  # built once, reused by every call
    s.material = Lambertian(0.7)  # a changed attribute rebuilds it
    assert s.albedo(sun=(0.0, 30.0), spp=256).value == pytest.approx(0.7, abs=1e-12)
    s2 = pickle.loads(pickle.dumps(s))  # the kernel scene is not pickled, rebuilt on use
    assert s2.bhr(spp=256).value == pytest.approx(0.7, abs=1e-12)


def test_reciprocity_exchanges_sun_and_view_where_allowed():
    # the default traces the reciprocal configuration when the sun is lower
    # than the sensor on a periodic tile without sky: the same value (within
    # the SEs of the direct estimate) and a far smaller SE at a grazing sun
    z = fg.fbm_surface((16, 16), 0.7, method="spectral", periodic=True, seed=6, sigma=2.0)
    s = Scene.from_dem(z, material=Lambertian(0.5))
    sun, view = (90.0, 85.0), (0.0, 0.0)
    auto = s.brf(sun=sun, view=view, spp=65536, max_depth=5, seed=1)
    direct = s.brf(sun=sun, view=view, spp=65536, max_depth=5, seed=1, reciprocity=False)
    assert auto == s.brf(sun=view, view=sun, spp=65536, max_depth=5, seed=1, reciprocity=False)
    assert abs(auto.value - direct.value) < 3 * np.hypot(auto.se, direct.se)
    assert auto.se < direct.se / 5
    o = s.brf_orders(sun=sun, view=view, spp=4096, max_depth=5, seed=2)
    assert o.total == s.brf(sun=sun, view=view, spp=4096, max_depth=5, seed=2)
    # a sun higher than the sensor, sky light or a finite patch: no exchange
    assert s.brf(sun=view, view=sun, spp=4096, seed=3) == s.brf(sun=view, view=sun, spp=4096, seed=3,
                                                                 reciprocity=False)
    assert s.brf(sun=sun, spp=4096, seed=3, sky=0.2) == s.brf(sun=sun, spp=4096, seed=3, sky=0.2,
                                                               reciprocity=False)
    with pytest.raises(ValueError, match="^reciprocity:"):
        s.brf(sun=sun, spp=100, sky=0.2, reciprocity=True)
    with pytest.raises(TypeError, match="^reciprocity:"):
        s.brf(sun=sun, spp=100, reciprocity="yes")
    patch = Scene.from_dem(z, material=Lambertian(0.5), periodic=False)
    assert patch.brf(sun=sun, spp=4096, seed=3) == patch.brf(sun=sun, spp=4096, seed=3, reciprocity=False)
    with pytest.raises(ValueError, match="^reciprocity:"):
        patch.brf(sun=sun, spp=100, reciprocity=True)
