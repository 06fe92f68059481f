"""Mesh scenes and per-facet materials against closed forms.

Expected values never come from the code under test: facet sums are
computed here with NumPy from the vertices, the plane's BRF and albedo are
closed forms, energy conservation is an invariant, and the heightfield
caster (an independent traversal) is the reference for the mesh caster.
"""
import dataclasses

import numpy as np
import pytest

import fractalgeo_rs as fg
from fractalgeo_rs.geometry import Mesh
from fractalgeo_rs.radiometry import Lambertian, OrenNayar, Scene


def periodic_surface(n=16, amp=3.0, seed=0, modes=3):
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
    return z.astype(np.float32).astype(np.float64)  # exact in the mesh's float32


def tile_mesh(z, cell=1.0):
    """The periodic DEM tile as a mesh in the heightfield's frame (vertex
    (r, c) at (c, -r)), the wrap row and column appended, NE-SW split in
    the heightfield's facet order; its extent is (0, -rows, cols, rows)."""
    rows, cols = z.shape
    zp = np.pad(z, ((0, 1), (0, 1)), mode="wrap")
    r, c = np.mgrid[0:rows + 1, 0:cols + 1]
    v = np.stack([c * cell, -r * cell, zp], -1).reshape(-1, 3)
    idx = np.arange((rows + 1) * (cols + 1)).reshape(rows + 1, cols + 1)
    nw, ne, sw, se = idx[:-1, :-1], idx[:-1, 1:], idx[1:, :-1], idx[1:, 1:]
    f = np.stack([np.stack([nw, sw, ne], -1), np.stack([ne, sw, se], -1)], 2).reshape(-1, 3)
    return Mesh.from_triangles(v, f), (0.0, -rows * cell, cols * cell, rows * cell)


def test_flat_plane_mesh_brf_and_albedo_are_rho():
    m, ext = tile_mesh(np.full((6, 6), 2.0))
    for periodic in (True, False):
        s = Scene.from_mesh(m, materials=Lambertian(0.42), periodic=periodic, extent=ext)
        for sun, view in [((0.0, 0.0), "nadir"), ((30.0, 60.0), (200.0, 45.0)), ((300.0, 80.0), (10.0, 70.0))]:
            if not periodic and sun != (0.0, 0.0):
                continue  # a finite patch loses rays through its sides
            e = s.brf(sun=sun, view=view, spp=3000)
            assert abs(e.value - 0.42) < 1e-6 and e.se < 1e-6
            if periodic:
                a = s.albedo(sun=sun, spp=3000)
                assert abs(a.value - 0.42) < 1e-6 and a.se < 1e-6


def test_lambertian_nadir_single_scattering_on_a_tin():
    z = periodic_surface(24, amp=4.0, seed=3)
    tin = fg.tin_from_dem(z, max_error=0.3)
    v, t = tin.vertices, tin.triangles
    n = np.cross(v[t[:, 1]] - v[t[:, 0]], v[t[:, 2]] - v[t[:, 0]])
    area = 0.5 * np.linalg.norm(n, axis=1)
    nz = np.abs(n[:, 2]) / (2 * area)
    want = 0.7 * np.sum(area * nz ** 2) / np.sum(area * nz)
    s = Scene.from_tin(tin, materials=Lambertian(0.7))
    e = s.brf(sun=(0.0, 0.0), view="nadir", spp=60000, max_depth=1)
    assert abs(e.value - want) < 3 * e.se, (e, want)


def test_dem_as_heightfield_and_as_mesh_give_the_same_brf():
    z = periodic_surface(16, amp=4.0, seed=5)
    m, ext = tile_mesh(z)
    hf = Scene.from_dem(z, material=OrenNayar(0.6, 0.3))
    ms = Scene.from_mesh(m, materials=OrenNayar(0.6, 0.3), extent=ext)
    for sun, view in [((0.0, 30.0), "nadir"), ((135.0, 60.0), (20.0, 40.0))]:
        a = hf.brf(sun=sun, view=view, spp=20000, max_depth=5)
        b = ms.brf(sun=sun, view=view, spp=20000, max_depth=5)
        assert abs(a.value - b.value) < 3 * a.se, (a, b)


def test_periodic_rough_mesh_conserves_energy():
    z = periodic_surface(16, amp=5.0, seed=7)
    m, ext = tile_mesh(z)
    s = Scene.from_mesh(m, materials=Lambertian(1.0), extent=ext)
    for zen in (0.0, 45.0, 80.0):
        a = s.albedo(sun=(30.0, zen), spp=20000, max_depth=100_000)
        assert abs(a.value - 1.0) < 1e-3, (zen, a)


def test_checkerboard_of_two_materials():
    rows, cols = 4, 6
    z = np.zeros((rows, cols))
    cells = (np.add.outer(np.arange(rows), np.arange(cols)) % 2)[:, :, None].repeat(2, 2)
    ra, rb = 0.2, 0.7
    sun = (0.0, 60.0)
    want = np.where((np.add.outer(np.arange(rows), np.arange(cols)) % 2) == 0, ra, rb) * 0.5 / np.pi
    dem = Scene.from_dem(z, material=[Lambertian(ra), Lambertian(rb)], material_ids=cells)
    np.testing.assert_allclose(dem.render(sun=sun, shape=(rows, cols), spp=8), want, atol=1e-6)
    m, ext = tile_mesh(z)
    ms = Scene.from_mesh(m, materials=[Lambertian(ra), Lambertian(rb)], material_ids=cells.reshape(-1), extent=ext)
    np.testing.assert_allclose(ms.render(sun=sun, shape=(rows, cols), spp=8), want, atol=1e-6)
    # the tile's BRF: the area-weighted mean reflectance
    e = ms.brf(sun=sun, spp=4000)
    assert abs(e.value - (ra + rb) / 2) < 3 * e.se + 1e-9


def test_material_by_slope_and_height():
    # V-grooves of 45 degree sides on a flat floor at 0: floor bright, sides dark
    z = np.zeros((8, 8))
    z[:, 1::4] = 1.0
    s = Scene.from_dem(z, material=[Lambertian(0.9), Lambertian(0.1)],
                       material_ids=lambda slope, height: slope > 10)
    ids = s.material_ids.reshape(8, 8, 2)
    # cells between columns 2..3 are flat (both corners 0), 0..1 slope up
    assert ids[:, 2].max() == 0 and ids[:, 0].min() == 1
    h = Scene.from_dem(z, material=[Lambertian(0.9), Lambertian(0.1)],
                       material_ids=lambda slope, height: height > 0.5)
    # each sloped cell has one facet with two corners at 1 (centroid 2/3)
    assert h.material_ids.sum() == 8 * 4
    # single scattering, nadir: sum over facets of rho_k A nz^2 / sum A nz
    e = s.brf(sun=(0.0, 0.0), spp=20000, max_depth=1)
    nz = 1 / np.sqrt(2)
    flat, steep = 2 * 8 * 2 * 0.5, 2 * 8 * 2 * 0.5  # projected areas: 2 flat and 2 sloped cells per period
    want = (0.9 * flat + 0.1 * steep * nz) / (flat + steep)
    assert abs(e.value - want) < 1e-9 + 3 * e.se, (e, want)


def test_results_identical_for_any_thread_count():
    z = periodic_surface(8, amp=3.0, seed=2)
    m, ext = tile_mesh(z)
    s = Scene.from_mesh(m, materials=[Lambertian(0.3), Lambertian(0.8)],
                        material_ids=lambda slope, height: height > 0, extent=ext)
    kw = dict(sun=(10.0, 40.0), spp=3000, max_depth=8)
    assert s.brf(view=(200.0, 30.0), n_threads=1, **kw) == s.brf(view=(200.0, 30.0), n_threads=2, **kw)
    assert s.albedo(n_threads=1, **kw) == s.albedo(n_threads=2, **kw)
    img = dict(sun=(10.0, 40.0), shape=(8, 8), spp=4, max_depth=8)
    np.testing.assert_array_equal(s.render(n_threads=1, **img), s.render(n_threads=2, **img))


def test_two_sided_facets_are_lit_from_below():
    # a horizontal "leaf" plane wound clockwise (normal down): two-sided
    m, ext = tile_mesh(np.zeros((4, 4)))
    flipped = dataclasses.replace(m, faces=np.ascontiguousarray(m.faces[:, ::-1]))
    s = Scene.from_mesh(flipped, materials=Lambertian(0.5), extent=ext)
    assert abs(s.brf(sun=(0.0, 30.0), spp=500).value - 0.5) < 1e-6


def test_bad_input_names_the_parameter():
    m, ext = tile_mesh(np.zeros((3, 3)))
    v = m.vertices.copy()
    v[1, 2] = np.nan
    with pytest.raises(ValueError, match="^mesh:.*NaN"):
        Scene.from_mesh(dataclasses.replace(m, vertices=v), extent=ext)
    f = m.faces.copy()
    f[0] = [f[0, 0], f[0, 0], f[0, 1]]
    with pytest.raises(ValueError, match="^mesh:.*degenerate"):
        Scene.from_mesh(dataclasses.replace(m, faces=f), extent=ext)
    with pytest.raises(ValueError, match="^material_ids:.*index 2"):
        Scene.from_mesh(m, materials=[Lambertian(0.1), Lambertian(0.2)], material_ids=np.full(len(m), 2))
    with pytest.raises(ValueError, match="^material_ids:.*one index per facet"):
        Scene.from_mesh(m, materials=[Lambertian(0.1), Lambertian(0.2)], material_ids=[0, 1])
    with pytest.raises(ValueError, match="^material_ids:.*need"):
        Scene.from_mesh(m, materials=[Lambertian(0.1), Lambertian(0.2)])
    with pytest.raises(ValueError, match="^material_ids:"):
        Scene.from_dem(np.zeros((3, 3)), material=[Lambertian(0.1)], material_ids=np.full((3, 3, 2), -1))
    with pytest.raises(ValueError, match="^extent:.*cover"):
        Scene.from_mesh(m, extent=(0.0, -1.0, 1.0, 1.0))
    with pytest.raises(ValueError, match="^extent:"):
        Scene.from_mesh(m, extent=(0.0, 0.0, -3.0, 3.0))
    with pytest.raises(TypeError, match="^mesh:"):
        Scene.from_mesh(np.zeros((3, 3)))
    with pytest.raises(TypeError, match="^materials:"):
        Scene.from_mesh(m, materials=[0.5])
    with pytest.raises(ValueError, match="^materials:"):
        Scene.from_mesh(m, materials=[])
    # the inputs are not modified
    assert np.isfinite(m.vertices).all()


def test_per_facet_path_with_one_material_is_the_plain_scene():
    # the same paths: one material everywhere gives bit-identical estimates
    z = periodic_surface(12, amp=3.0, seed=4)
    a = Scene.from_dem(z, material=OrenNayar(0.5, 0.2))
    b = Scene.from_dem(z, material=[OrenNayar(0.5, 0.2), Lambertian(0.9)], material_ids=np.zeros((12, 12, 2), int))
    assert a.brf(sun=(30.0, 40.0), view=(100.0, 20.0), spp=5000) == b.brf(sun=(30.0, 40.0), view=(100.0, 20.0),
                                                                           spp=5000)
    assert a.albedo(sun=(30.0, 40.0), spp=2000) == b.albedo(sun=(30.0, 40.0), spp=2000)
    np.testing.assert_array_equal(a.render(sun=(30.0, 40.0), spp=2), b.render(sun=(30.0, 40.0), spp=2))
    # a mesh scene keeps its extent in map coordinates
    m, ext = tile_mesh(z)
    s = Scene.from_mesh(m, extent=ext)
    assert s.extent == ext and s.render(sun=(0.0, 20.0), shape=(3, 5), spp=1).shape == (3, 5)
