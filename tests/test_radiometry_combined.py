"""The radiometry extras (sky light, PSFs, bhr, perspective camera) over
every geometry: DEM heightfields, per-facet materials and triangle meshes.

Expected values are closed forms (a flat Lambertian plane) or invariants
(one material given per facet is the same scene as one material for all;
a mesh copy of a DEM tile is the same surface).
"""
import numpy as np

from fractalgeo_rs.geometry import Mesh
from fractalgeo_rs.radiometry import Lambertian, Scene


def plane_mesh(n=4, z=2.0):
    r, c = np.mgrid[0:n + 1, 0:n + 1]
    v = np.stack([c, -r, np.full_like(c, z)], -1).reshape(-1, 3).astype(np.float64)
    idx = np.arange((n + 1) ** 2).reshape(n + 1, n + 1)
    nw, ne, sw, se = idx[:-1, :-1], idx[:-1, 1:], idx[1:, :-1], idx[1:, 1:]
    f = np.stack([np.stack([nw, sw, ne], -1), np.stack([ne, sw, se], -1)], 2).reshape(-1, 3)
    return Mesh.from_triangles(v, f), (0.0, -float(n), float(n), float(n))


def test_flat_mesh_under_sun_and_sky_is_lambertian():
    rho, sky = 0.4, 0.3
    m, ext = plane_mesh()
    s = Scene.from_mesh(m, materials=Lambertian(rho), periodic=True, extent=ext)
    sun = (30.0, 60.0)
    cos_s = np.cos(np.radians(60.0))
    e = s.brf(sun=sun, view=(200.0, 40.0), sky=sky, spp=3000)
    assert abs(e.value - rho) < 1e-9  # the HDRF of a flat Lambertian plane
    assert abs(s.bhr(spp=3000).value - rho) < 1e-9
    img = s.render(sun=sun, shape=(3, 4), spp=8, sky=sky, psf=("gaussian", 0.7))
    np.testing.assert_allclose(img, rho * (cos_s + sky) / np.pi, rtol=1e-6)
    pers = s.render_perspective(sun=sun, view=(180.0, 45.0), shape=(3, 4), spp=2, sky=sky)
    np.testing.assert_allclose(pers, rho * (cos_s + sky) / np.pi, rtol=1e-6)


def test_one_material_per_facet_is_the_plain_dem_scene_with_sky_and_psf():
    rng = np.random.default_rng(3)
    z = rng.normal(0.0, 0.6, (8, 8))
    plain = Scene.from_dem(z, material=Lambertian(0.5))
    per = Scene.from_dem(z, material=[Lambertian(0.5), Lambertian(0.5)],
                         material_ids=(np.arange(8 * 8 * 2) % 2).reshape(8, 8, 2).astype(np.uint32))
    kw = dict(sun=(40.0, 50.0), view=(100.0, 30.0), spp=2000, max_depth=4, sky=0.25)
    assert plain.brf(**kw) == per.brf(**kw)
    assert plain.bhr(spp=2000, max_depth=4) == per.bhr(spp=2000, max_depth=4)
    ikw = dict(sun=(40.0, 50.0), shape=(4, 4), spp=3, max_depth=4, sky=0.25, psf=("gaussian", 0.6, 3.0))
    np.testing.assert_array_equal(plain.render(**ikw), per.render(**ikw))
    pkw = dict(sun=(40.0, 50.0), view=(180.0, 50.0), shape=(3, 5), spp=2, max_depth=3, sky=0.1)
    np.testing.assert_array_equal(plain.render_perspective(**pkw), per.render_perspective(**pkw))


def test_two_materials_mix_linearly_under_sky():
    # single scattering on a flat plane: each facet reflects its own rho,
    # so the HDRF is the area-weighted mean of the two albedos
    z = np.zeros((6, 6))
    ids = np.zeros((6, 6, 2), dtype=np.uint32)
    ids[:, :, 1] = 1
    s = Scene.from_dem(z, material=[Lambertian(0.2), Lambertian(0.6)], material_ids=ids)
    e = s.brf(sun=(0.0, 30.0), view=(90.0, 20.0), sky=0.5, spp=16384, max_depth=1)
    assert abs(e.value - 0.4) < 4 * e.se + 1e-9, e


def test_instanced_plane_under_sun_and_sky_is_lambertian():
    # four unit squares, each scaled by 2, tile a 4 x 4 periodic plane: the
    # instanced scene must give the flat Lambertian plane's closed forms
    rho, sky = 0.3, 0.2
    sq = Mesh.from_triangles([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]], [[0, 1, 2], [1, 3, 2]])
    xf = np.zeros((4, 3, 4))
    xf[:, 0, 0] = xf[:, 1, 1] = 2.0
    xf[:, 2, 2] = 1.0
    xf[:, :2, 3] = [[0, 0], [2, 0], [0, 2], [2, 2]]
    s = Scene.from_instances([sq], [0, 0, 0, 0], xf, extent=(0, 0, 4, 4), materials=Lambertian(rho))
    sun = (20.0, 40.0)
    cos_s = np.cos(np.radians(40.0))
    assert abs(s.brf(sun=sun, view=(250.0, 35.0), sky=sky, spp=3000).value - rho) < 1e-9
    assert abs(s.bhr(spp=3000).value - rho) < 1e-9
    want = rho * (cos_s + sky) / np.pi
    img = s.render(sun=sun, shape=(4, 4), spp=4, sky=sky, psf=np.ones((3, 3)), psf_step=0.5)
    np.testing.assert_allclose(img, want, rtol=1e-6)
    pers = s.render_perspective(sun=sun, view=(90.0, 50.0), shape=(3, 4), spp=2, sky=sky)
    np.testing.assert_allclose(pers, want, rtol=1e-6)
