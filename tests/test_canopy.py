"""Canopies: leaf angle distributions against their closed forms, G against
Ross's identities, disc canopies' gap fraction against the exact
(1 - a G / (A cos theta))^N by an independent shadow test on the mesh."""
import numpy as np
import pytest
from scipy import stats

from fractalgeo_rs import canopy
from fractalgeo_rs.canopy import disc_canopy, leaf_angle_density, projection_g, sample_leaf_normals
from fractalgeo_rs.radiometry import BiLambertian, Lambertian, Scene

LADS = ("planophile", "erectophile", "plagiophile", "extremophile", "uniform", "spherical")

# G(0) = int g cos and G(90) = (2/pi) int g sin, by hand from de Wit's densities
G0 = {"planophile": 8 / (3 * np.pi), "erectophile": 4 / (3 * np.pi), "plagiophile": 32 / (15 * np.pi),
      "extremophile": 28 / (15 * np.pi), "uniform": 2 / np.pi, "spherical": 0.5}
G90 = {"planophile": 8 / (3 * np.pi ** 2), "erectophile": 16 / (3 * np.pi ** 2), "uniform": 4 / np.pi ** 2,
       "spherical": 0.5}

# the cumulative distributions, integrated by hand
CDF = {"planophile": lambda t: 2 / np.pi * (t + np.sin(2 * t) / 2),
       "erectophile": lambda t: 2 / np.pi * (t - np.sin(2 * t) / 2),
       "plagiophile": lambda t: 2 / np.pi * (t - np.sin(4 * t) / 4),
       "extremophile": lambda t: 2 / np.pi * (t + np.sin(4 * t) / 4),
       "uniform": lambda t: 2 / np.pi * t,
       "spherical": lambda t: 1 - np.cos(t)}


def test_the_public_list_of_distributions():
    assert canopy.LADS == LADS


@pytest.mark.parametrize("zenith", [0.0, 10.0, 33.3, 57.5, 75.0, 89.0, 90.0])
def test_spherical_g_is_one_half_at_every_zenith(zenith):
    assert projection_g("spherical", zenith) == pytest.approx(0.5, abs=1e-12)


def test_horizontal_and_vertical_leaves():
    z = np.linspace(0.0, 90.0, 37)
    assert np.allclose(projection_g(0.0, z), np.cos(np.radians(z)), atol=1e-14)
    assert np.allclose(projection_g(90.0, z), 2 / np.pi * np.sin(np.radians(z)), atol=1e-14)


@pytest.mark.parametrize("lad", LADS)
def test_g_at_nadir_and_horizon_match_hand_integrals(lad):
    assert projection_g(lad, 0.0) == pytest.approx(G0[lad], abs=1e-12)
    if lad in G90:
        assert projection_g(lad, 90.0) == pytest.approx(G90[lad], abs=1e-12)


@pytest.mark.parametrize("lad", list(LADS) + [0.0, 20.0, 45.0, 70.0, 90.0])
def test_hemispherical_mean_of_g_is_one_half(lad):
    # int_0^{pi/2} G(theta) sin(theta) dtheta = 1/2 for any leaf angle distribution
    x, w = np.polynomial.legendre.leggauss(200)
    parts = [(0.0, np.pi / 2)]
    if not isinstance(lad, str) and 0 < lad < 90:  # G has a kink at theta = 90 - theta_L
        k = np.radians(90.0 - lad)
        parts = [(0.0, k), (k, np.pi / 2)]
    total = 0.0
    for lo, hi in parts:
        t = lo + (hi - lo) / 2 * (x + 1)
        total += (hi - lo) / 2 * np.sum(w * projection_g(lad, np.degrees(t)) * np.sin(t))
    assert total == pytest.approx(0.5, abs=1e-9)


@pytest.mark.parametrize("lad", LADS)
def test_densities_integrate_to_one_and_sampling_follows_them(lad):
    x, w = np.polynomial.legendre.leggauss(100)
    t = np.pi / 4 * (x + 1)
    assert np.pi / 4 * np.sum(w * leaf_angle_density(lad, np.degrees(t))) == pytest.approx(1.0, abs=1e-12)
    n = sample_leaf_normals(lad, 50_000, seed=11)
    assert np.allclose(np.linalg.norm(n, axis=1), 1.0) and np.all(n[:, 2] >= 0)
    incl = np.arccos(np.clip(n[:, 2], -1, 1))
    assert stats.kstest(incl, CDF[lad]).pvalue > 1e-3
    az = np.arctan2(n[:, 0], n[:, 1]) % (2 * np.pi)
    assert stats.kstest(az / (2 * np.pi), "uniform").pvalue > 1e-3


@pytest.mark.parametrize("lad", ["planophile", "erectophile", "extremophile", 30.0])
@pytest.mark.parametrize("zenith", [0.0, 40.0, 70.0])
def test_g_is_the_mean_projection_of_sampled_leaves(lad, zenith):
    # independent Monte Carlo estimate of G: the mean |n . w| over sampled normals
    n = sample_leaf_normals(lad, 200_000, seed=5)
    z = np.radians(zenith)
    proj = np.abs(n @ np.array([np.sin(z) * 0.6, np.sin(z) * 0.8, np.cos(z)]))
    se = proj.std() / np.sqrt(len(proj))
    assert abs(proj.mean() - projection_g(lad, zenith)) < 4 * se + 1e-12


def _tri_areas(v, f):
    return 0.5 * np.linalg.norm(np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]]), axis=1)


def test_leaves_are_area_matched_polygons_with_the_drawn_normals():
    c = disc_canopy(lai=1.5, leaf_radius=0.08, extent=(2.0, 1.5), height=(0.2, 1.0), sides=7, seed=2)
    v = np.asarray(c.mesh.vertices, dtype=np.float64)
    f = np.asarray(c.mesh.faces, dtype=np.int64)
    leaf = c.material_ids == 1
    area = np.bincount(c.mesh.part_ids[leaf], weights=_tri_areas(v, f[leaf]), minlength=c.n_leaves)
    assert np.allclose(area, np.pi * 0.08 ** 2, rtol=1e-5)
    # one period: every triangle's centroid in the tile, and some leaves cut across an edge
    cen = v[f].mean(axis=1)
    assert np.all((cen[:, :2] >= 0) & (cen[:, :2] <= [2.0, 1.5]))
    span = np.ptp(v[f[leaf]][..., 0], axis=1)
    assert span.max() < 2 * 0.08 * 1.1 and np.any(np.abs(v[f[leaf]][..., 0] - c.centres[c.mesh.part_ids[leaf]][:, None, 0]) > 1.0)
    assert c.n_leaves == round(1.5 * 3.0 / (np.pi * 0.08 ** 2))
    assert c.lai == pytest.approx(c.n_leaves * np.pi * 0.08 ** 2 / 3.0)
    fn = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    fn /= np.linalg.norm(fn, axis=1)[:, None]
    assert np.allclose(fn[leaf], c.normals[c.mesh.part_ids[leaf]], atol=1e-4)
    assert np.allclose(fn[~leaf], [0, 0, 1])
    # soil covers the tile at height 0; every leaf centre in the tile and the height range
    assert _tri_areas(v, f[~leaf]).sum() == pytest.approx(3.0)
    assert np.all((c.centres[:, :2] >= 0) & (c.centres[:, :2] < [2.0, 1.5]))
    assert np.all((c.centres[:, 2] >= 0.2) & (c.centres[:, 2] <= 1.0))
    assert np.all(v[f[leaf]][..., 2] > 0)


def test_seeded_placement_is_reproducible():
    a = disc_canopy(lai=2.0, leaf_radius=0.05, extent=1.0, height=(0.1, 1.0), lad="planophile", seed=9)
    b = disc_canopy(lai=2.0, leaf_radius=0.05, extent=1.0, height=(0.1, 1.0), lad="planophile", seed=9)
    assert np.array_equal(a.mesh.vertices, b.mesh.vertices) and np.array_equal(a.centres, b.centres)
    c = disc_canopy(lai=2.0, leaf_radius=0.05, extent=1.0, height=(0.1, 1.0), lad="planophile", seed=10)
    assert not np.array_equal(a.centres, c.centres)


def _gap_by_shadows(c, zenith, points):
    """Fraction of soil points from which the ray towards zenith ``zenith``
    (azimuth 30 degrees) meets no leaf triangle of the mesh: each triangle
    projected along the ray onto the soil, point-in-triangle tests over the
    periodic images."""
    z = np.radians(zenith)
    az = np.radians(30.0)
    drift = np.array([np.sin(az), np.cos(az)]) * np.tan(z)  # horizontal shift per metre of height
    v = np.asarray(c.mesh.vertices, dtype=np.float64)
    f = np.asarray(c.mesh.faces, dtype=np.int64)[c.material_ids == 1]
    tri = v[f]  # (T, 3, 3)
    p2 = tri[..., :2] - tri[..., 2:3] * drift  # shadow on z = 0
    ext = np.array(c.extent)
    p2 -= np.floor(p2[:, :1, :] / ext) * ext
    a, b, cc = p2[:, 0], p2[:, 1], p2[:, 2]
    covered = np.zeros(len(points), dtype=bool)
    for sx in (-1, 0, 1):
        for sy in (-1, 0, 1):
            q = points + np.array([sx, sy]) * ext
            d = q[:, None, :] - a[None]
            e1, e2 = b - a, cc - a
            den = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]
            u = (d[..., 0] * e2[:, 1] - d[..., 1] * e2[:, 0]) / den
            w = (e1[:, 0] * d[..., 1] - e1[:, 1] * d[..., 0]) / den
            covered |= np.any((u >= 0) & (w >= 0) & (u + w <= 1), axis=1)
    return 1.0 - covered.mean()


@pytest.mark.parametrize("lad,zenith", [("spherical", 50.0), ("planophile", 20.0), ("erectophile", 60.0),
                                        (0.0, 35.0)])
def test_gap_fraction_of_the_mesh_is_exact(lad, zenith):
    # expectation over placements of (1 - a G / (A cos theta))^N: average many
    # realisations with a few rays each, SE from their spread
    rng = np.random.default_rng(0)
    vals = []
    for seed in range(800):
        c = disc_canopy(lai=1.2, leaf_radius=0.12, extent=1.0, height=(0.2, 0.8), lad=lad, sides=5, seed=seed)
        vals.append(_gap_by_shadows(c, zenith, rng.random((16, 2))))
    mean, se = np.mean(vals), np.std(vals, ddof=1) / np.sqrt(len(vals))
    n, a = c.n_leaves, np.pi * 0.12 ** 2
    g = projection_g(lad, zenith)
    exact = (1 - a * g / np.cos(np.radians(zenith))) ** n
    assert abs(mean - exact) < 3 * se, (mean, se, exact)
    assert float(c.gap_probability(zenith)) == pytest.approx(exact)


def test_beer_is_the_large_n_limit():
    # exact (1 - a G/(A mu))^N -> exp(-G LAI / mu) as the leaves shrink at fixed LAI
    for lad in LADS:
        for zen in (0.0, 45.0, 70.0):
            mu, g = np.cos(np.radians(zen)), projection_g(lad, zen)
            beer = np.exp(-g * 3.0 / mu)
            errs = []
            for n in (100, 10_000, 1_000_000):
                exact = (1 - 3.0 / n * g / mu) ** n
                errs.append(abs(exact - beer) / beer)
            assert errs[0] > errs[1] > errs[2] and errs[2] < 1e-4


def _discs_meet(c1, n1, c2, n2, r, k=400):
    """Independent test: points of the chord of disc 1 on the plane of disc 2
    (sampled) inside disc 2."""
    # disc 1 boundary and interior points sampled on a polar grid; keep those
    # within 1e-9 of plane 2 is hopeless, so intersect the segment instead
    t = np.array([1.0, 0.0, 0.0]) if abs(n1[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    e1 = np.cross(n1, t)
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(n1, e1)
    ang = np.linspace(0, 2 * np.pi, k, endpoint=False)
    ring = c1 + r * (np.cos(ang)[:, None] * e1 + np.sin(ang)[:, None] * e2)
    s = (ring - c2) @ n2  # signed distance of the rim to plane 2
    cross = np.flatnonzero(np.sign(s) != np.sign(np.roll(s, -1)))
    if len(cross) < 2:
        return False
    pts = []
    for i in cross[:2]:
        j = (i + 1) % k
        lam = s[i] / (s[i] - s[j])
        pts.append(ring[i] + lam * (ring[j] - ring[i]))
    seg = pts[0] + np.linspace(0, 1, 2001)[:, None] * (pts[1] - pts[0])
    return bool(np.any(np.linalg.norm(seg - c2, axis=1) < r * (1 - 1e-3)))


def test_non_overlapping_leaves_do_not_meet():
    r = 0.06
    c = disc_canopy(lai=3.0, leaf_radius=r, extent=1.0, height=(0.1, 0.7), overlap=False, sides=32, seed=4)
    assert c.n_leaves == round(3.0 / (np.pi * r * r))
    circ = r * np.sqrt(2 * np.pi / (32 * np.sin(2 * np.pi / 32)))
    cen, nrm = c.centres, c.normals
    checked = 0
    for i in range(c.n_leaves):
        d = cen - cen[i]
        d[:, :2] -= np.round(d[:, :2])  # periodic, tile 1 m
        near = np.flatnonzero((np.linalg.norm(d, axis=1) < 2 * circ) & (np.arange(c.n_leaves) != i))
        for j in near:
            checked += 1
            assert not _discs_meet(cen[i], nrm[i], cen[i] + d[j], nrm[j], circ), (i, j)
    assert checked > 50  # the test did look at close pairs
    # and the independent placement at the same density does produce meeting leaves
    o = disc_canopy(lai=3.0, leaf_radius=r, extent=1.0, height=(0.1, 0.7), overlap=True, sides=32, seed=4)
    meet = 0
    for i in range(o.n_leaves):
        d = o.centres - o.centres[i]
        d[:, :2] -= np.round(d[:, :2])
        for j in np.flatnonzero((np.linalg.norm(d, axis=1) < 2 * circ) & (np.arange(o.n_leaves) > i)):
            meet += _discs_meet(o.centres[i], o.normals[i], o.centres[i] + d[j], o.normals[j], circ)
    assert meet > 0


@pytest.mark.parametrize("kwargs,param,exc", [
    (dict(lai=-1.0), "lai", ValueError),
    (dict(lai=float("nan")), "lai", ValueError),
    (dict(leaf_radius=0.0), "leaf_radius", ValueError),
    (dict(leaf_radius=-0.1), "leaf_radius", ValueError),
    (dict(leaf_radius=0.6), "leaf_radius", ValueError),  # wider than the tile
    (dict(lad="conical"), "lad", ValueError),
    (dict(lad=95.0), "lad", ValueError),
    (dict(height=(0.01, 1.0)), "height", ValueError),  # leaves would reach the soil
    (dict(height=(1.0, 0.5)), "height", ValueError),
    (dict(extent=0.0), "extent", ValueError),
    (dict(sides=2), "sides", ValueError),
    (dict(leaf=Lambertian(0.5)), "leaf", TypeError),
    (dict(soil=BiLambertian(0.5, 0.5)), "soil", TypeError),
    (dict(lai=8.0, overlap=False, height=(0.1, 0.2), max_attempts=20000), "lai", ValueError),  # does not fit
])
def test_bad_input_names_the_parameter(kwargs, param, exc):
    args = dict(lai=1.0, leaf_radius=0.05, extent=1.0, height=(0.1, 1.0), seed=0)
    args.update(kwargs)
    with pytest.raises(exc, match=f"^{param}:"):
        disc_canopy(**args)
    with pytest.raises(ValueError, match="^lad:"):
        projection_g("bogus", 10.0)
    with pytest.raises(ValueError, match="^zenith:"):
        projection_g("uniform", 91.0)


def test_bilambertian_checks_and_is_refused_by_an_opaque_heightfield():
    leaf = BiLambertian(0.5, 0.3)
    assert leaf.albedo == pytest.approx(0.8) and leaf._spec() == ("bilambertian", [0.5, 0.3])
    with pytest.raises(ValueError, match="^transmittance: .*reflectance \\+ transmittance <= 1"):
        BiLambertian(0.6, 0.5)
    with pytest.raises(ValueError, match="^reflectance:"):
        BiLambertian(-0.1, 0.5)
    with pytest.raises(ValueError, match="^transmittance:"):
        BiLambertian(0.1, 1.5)
    with pytest.raises(TypeError, match="^reflectance:"):
        BiLambertian("0.5", 0.1)
    with pytest.raises(TypeError, match="^material:"):
        Scene.from_dem(np.zeros((4, 4)), material=leaf)


def test_the_kernel_knows_bilambertian_by_name():
    # a transmitting leaf never sees its far side on a heightfield, but a pure
    # reflector is a Lambertian plane: exercises the registered kernel model
    from fractalgeo_rs import _core

    def leaf_plane(r, t):
        return _core.RadiometryScene.from_dem(np.zeros((4, 4)), (1.0, 1.0), True, "ne-sw",
                                              [("bilambertian", [r, t])], None)

    v, se, _ = leaf_plane(0.3, 0.0).brf((0.0, 30.0), (0.0, 0.0), 1000, 5, 1, 1)
    assert v == pytest.approx(0.3, abs=1e-12)
    with pytest.raises(ValueError, match="transmittance"):
        leaf_plane(0.7, 0.5)


def test_cli_writes_the_mesh_and_the_table(tmp_path, capsys):
    from fractalgeo_rs import cli

    out = tmp_path / "c.ply"
    assert cli.main(["canopy", str(out), "--lai", "2", "--leaf-radius", "0.05", "--extent", "2", "2",
                     "--height", "0.1", "1", "--lad", "erectophile", "--seed", "3", "--zenith", "0,60"]) == 0
    text = capsys.readouterr().out
    assert out.stat().st_size > 0 and "1019 leaves" in text
    rows = [r.split(",") for r in text.splitlines() if r and r[0].isdigit()]
    assert [float(r[0]) for r in rows] == [0.0, 60.0]
    assert float(rows[0][1]) == pytest.approx(4 / (3 * np.pi), abs=1e-6)
    assert cli.main(["canopy", "--lai", "1", "--leaf-radius", "0.1", "--extent", "1", "1", "--height", "0.2", "1",
                     "--seed", "1", "--zenith", "20", "--spp", "4000"]) == 0
    head, row = [r for r in capsys.readouterr().out.splitlines() if not r.startswith("#")]
    vals = dict(zip(head.split(","), map(float, row.split(","))))
    assert 0 < vals["gap_traced"] < 1 and vals["brf_nadir"] > 0 and vals["brf_se"] > 0
    assert cli.main(["canopy", "--lai", "-1", "--leaf-radius", "0.05", "--extent", "2", "2",
                     "--height", "0.1", "1"]) == 1
    assert "--lai:" in capsys.readouterr().err


# ---------------------------------------------------------------- the canopy as a radiometric scene

@pytest.mark.parametrize("lad,zenith", [("spherical", 0.0), ("planophile", 30.0), ("erectophile", 60.0),
                                        (0.0, 45.0), ("extremophile", 20.0)])
def test_scene_gap_fraction_is_the_exact_expectation(lad, zenith):
    # the traced gap fraction of 1000 placements (256 rays each), averaged,
    # against (1 - a G / (A cos theta))^N; SE from the spread over placements
    vals = []
    for seed in range(1000):
        c = disc_canopy(lai=1.2, leaf_radius=0.12, extent=1.0, height=(0.2, 0.8), lad=lad, sides=6, seed=seed)
        vals.append(c.scene().gap_fraction(zenith, azimuth=30.0, n=256, seed=seed).value)
    mean, se = np.mean(vals), np.std(vals, ddof=1) / np.sqrt(len(vals))
    exact = float(c.gap_probability(zenith))
    assert abs(mean - exact) < 3 * se, (mean, se, exact)


def test_scene_gap_fraction_of_one_canopy_matches_the_shadow_test():
    # one realisation: the tracer and the independent shadow projection see the same geometry
    c = disc_canopy(lai=1.5, leaf_radius=0.1, extent=(1.0, 1.5), height=(0.2, 1.0), lad="uniform", sides=5,
                    seed=8)
    e = c.scene().gap_fraction(50.0, azimuth=30.0, n=200_000, seed=1)
    pts = np.random.default_rng(2).random((20_000, 2)) * [1.0, 1.5]
    ref = _gap_by_shadows(c, 50.0, pts)
    se_ref = np.sqrt(ref * (1 - ref) / len(pts))
    assert abs(e.value - ref) < 3 * np.hypot(e.se, se_ref), (e.value, e.se, ref, se_ref)


def test_scene_gap_fraction_tends_to_beer():
    # many small leaves: exp(-G LAI / cos theta); spherical G = 1/2
    vals = []
    for seed in range(6):
        c = disc_canopy(lai=2.0, leaf_radius=0.03, extent=1.5, height=(0.05, 1.0), sides=6, seed=seed)
        vals.append(c.scene().gap_fraction(40.0, n=20_000, seed=seed).value)
    beer = np.exp(-0.5 * c.lai / np.cos(np.radians(40.0)))
    mean, se = np.mean(vals), np.std(vals, ddof=1) / np.sqrt(len(vals))
    assert c.n_leaves > 1000
    assert abs(mean - beer) < 3 * se + 1e-3, (mean, se, beer)


def test_conservative_canopy_has_albedo_one():
    c = disc_canopy(lai=2.0, leaf_radius=0.1, extent=1.5, height=(0.2, 1.0), lad="planophile", seed=4,
                    leaf=BiLambertian(0.6, 0.4), soil=Lambertian(1.0))
    s = c.scene()
    a = s.albedo(sun=(30.0, 35.0), spp=20_000, max_depth=100_000, seed=1)
    assert abs(a.value - 1.0) < 0.003, a
    ab = s.absorption(sun=(30.0, 35.0), spp=5_000, max_depth=100_000)
    assert all(e.value == 0.0 for e in ab["absorbed"])
    assert ab["reflected"].value == pytest.approx(1.0, abs=0.003)


def test_absorbed_plus_reflected_is_one_and_fapar_splits():
    c = disc_canopy(lai=2.5, leaf_radius=0.1, extent=1.5, height=(0.2, 1.0), seed=5,
                    leaf=BiLambertian(0.45, 0.35), soil=Lambertian(0.2))
    s = c.scene()
    ab = s.absorption(sun=(0.0, 30.0), spp=40_000, max_depth=1000, seed=3)
    soil, leaf = ab["absorbed"]
    total = soil.value + leaf.value + ab["reflected"].value + ab["trapped"].value
    assert total == pytest.approx(1.0, abs=1e-12)
    assert leaf.value > soil.value > 0
    alb = s.albedo(sun=(0.0, 30.0), spp=40_000, max_depth=1000, seed=4)
    assert abs(alb.value - ab["reflected"].value) < 3 * np.hypot(alb.se, ab["reflected"].se)
    # black leaves and soil: the soil absorbs exactly the light through the gaps
    b = disc_canopy(lai=2.5, leaf_radius=0.1, extent=1.5, height=(0.2, 1.0), seed=5,
                    leaf=BiLambertian(0.0, 0.0), soil=Lambertian(0.0)).scene()
    soil_b, leaf_b = b.absorption(sun=(0.0, 30.0), spp=40_000, seed=6)["absorbed"]
    gap = b.gap_fraction(30.0, azimuth=0.0, n=40_000, seed=7)  # the same sun direction
    assert abs(soil_b.value - gap.value) < 3 * np.hypot(soil_b.se, gap.se), (soil_b, gap)
    assert soil_b.value + leaf_b.value == pytest.approx(1.0, abs=1e-12)


def test_canopy_brf_is_reciprocal_and_thread_count_free():
    s = disc_canopy(lai=2.0, leaf_radius=0.1, extent=1.5, height=(0.2, 1.0), lad="erectophile", seed=6).scene()
    a = s.brf(sun=(0.0, 30.0), view=(120.0, 50.0), spp=40_000, seed=1, reciprocity=False)
    b = s.brf(sun=(120.0, 50.0), view=(0.0, 30.0), spp=40_000, seed=2, reciprocity=False)
    assert abs(a.value - b.value) < 3 * np.hypot(a.se, b.se), (a, b)
    assert s.brf(sun=(0.0, 30.0), spp=3000, seed=3, n_threads=1) == s.brf(sun=(0.0, 30.0), spp=3000, seed=3,
                                                                            n_threads=2)
    assert s.gap_fraction(20.0, n=5000, n_threads=1) == s.gap_fraction(20.0, n=5000, n_threads=2)
    assert s.absorption((0.0, 20.0), spp=3000, n_threads=1) == s.absorption((0.0, 20.0), spp=3000, n_threads=2)
    assert s.albedo((0.0, 20.0), spp=3000, n_threads=1) == s.albedo((0.0, 20.0), spp=3000, n_threads=2)


def test_scene_estimators_name_bad_parameters():
    s = disc_canopy(lai=1.0, leaf_radius=0.1, extent=1.0, height=(0.2, 1.0), seed=1).scene()
    with pytest.raises(ValueError, match="^zenith:"):
        s.gap_fraction(95.0)
    with pytest.raises(ValueError, match="^ground:"):
        s.gap_fraction(10.0, ground=2)
    with pytest.raises(ValueError, match="^n:"):
        s.gap_fraction(10.0, n=0)
    with pytest.raises(ValueError, match="^spp:"):
        s.absorption((0.0, 10.0), spp=0)
    with pytest.raises(ValueError, match="^max_depth:"):
        s.absorption((0.0, 10.0), max_depth=0)
