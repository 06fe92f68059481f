"""
A disc canopy: BRF against LAI, the principal plane and Beer's law
===================================================================

RAMI-like homogeneous canopies from :func:`fractalgeo_rs.canopy.disc_canopy`:
independently placed disc leaves of radius 5 cm with spherical leaf angles
between 0.1 and 2 m, over a Lambertian soil, in a periodic 2 m tile, with
RAMI's near-infrared leaf (reflectance 0.4957, transmittance 0.4409) and
soil (0.159) (Pinty et al. 2001). Left: the nadir BRF (sun at 30 degrees)
against the leaf area index, all orders, single and multiple scattering
from the same paths (``Scene.brf_orders``). Middle: the BRF in the principal plane at LAI 3 for
the sun at 30 and 50 degrees, with the hot spot where the view is along
the sun. Right: the
traced gap fraction against the exact ``(1 - a G / (A cos theta))^N`` of
independent leaves and Beer's law ``exp(-G LAI / cos theta)``. Error bars
are two standard errors; the path counts are small so that the example
runs in seconds (see :doc:`/canopy` for the converged numbers and the
comparison with PROSAIL's 4SAIL).

The second figure is a stand of L-system bushes (ABOP figure 1.25,
derived 4 steps, each plant with its own seed) placed by
:func:`fractalgeo_rs.lsystem.plants_on_terrain` on a 64 x 64 fBm DEM
(H = 0.8, 0.5 m cells), branches Lambertian 0.3, leaves
``BiLambertian(0.45, 0.4)``, soil 0.2, one mesh scene (not periodic: the
dark rim is where plants overhang the DEM), rendered at nadir with the sun
in the south-east at the paper's incidence series (sun zenith 0, 15, ...,
75 and 89 degrees), every image on one grey scale.

Data: generated, no licence needed.
"""
import matplotlib.pyplot as plt
import numpy as np

from fractalgeo_rs import canopy
from fractalgeo_rs.geometry import Mesh
from fractalgeo_rs.lsystem import LSystem, plants_on_terrain
from fractalgeo_rs.radiometry import BiLambertian, Lambertian, Scene, plot_incidence_series
from fractalgeo_rs.synth import fbm_surface

leaf, soil = BiLambertian(0.4957, 0.4409), Lambertian(0.159)
sun = (0.0, 30.0)


def make(lai):
    return canopy.disc_canopy(lai=lai, leaf_radius=0.05, extent=2.0, height=(0.1, 2.0),
                              lad="spherical", leaf=leaf, soil=soil, seed=1)


fig, axes = plt.subplots(1, 3, figsize=(13, 4), constrained_layout=True)

# BRF at nadir against LAI
lais = [0.25, 0.5, 1.0, 2.0, 3.0, 5.0]
scenes = {lai: make(lai).scene() for lai in lais}
# one pass of paths gives both: the single-scattering part of each path is its
# first sun estimate (equal to a separate max_depth=1 run with the same seed)
orders = [scenes[lai].brf_orders(sun=sun, spp=10000, max_depth=30, seed=3) for lai in lais]
for part, label in (("total", "all orders"), ("single", "single scattering"), ("multiple", "multiple scattering")):
    est = [getattr(o, part) for o in orders]
    axes[0].errorbar(lais, [e.value for e in est], yerr=[2 * e.se for e in est], marker="o",
                     capsize=2, label=label)
    print(label, ", nadir BRF:", ", ".join(f"LAI {lai} {e.value:.3f}" for lai, e in zip(lais, est)))
axes[0].axhline(0.159, color="0.5", ls=":", label="bare soil")
axes[0].set(xlabel="LAI", ylabel="BRF (nadir, sun 30 deg)", title="NIR BRF against LAI")
axes[0].legend()

# principal plane at LAI 3, two sun zeniths: view zenith > 0 on the sun's side
s3 = scenes[3.0]
views = np.array([-60, -45, -30, -15, 0, 15, 25, 30, 35, 45, 50, 55, 60], dtype=float)
for sz in (30.0, 50.0):
    pp = [s3.brf(sun=(0.0, sz), view=(0.0 if v >= 0 else 180.0, abs(v)), spp=6000, max_depth=30, seed=4)
          for v in views]
    axes[1].errorbar(views, [e.value for e in pp], yerr=[2 * e.se for e in pp], marker="o", capsize=2,
                     label=f"sun zenith {sz:.0f}")
    axes[1].axvline(sz, color="0.6", ls="--", lw=0.8)
axes[1].text(31, 0.36, "hot spots", color="0.4")
axes[1].set(xlabel="view zenith (deg, + towards the sun)", ylabel="BRF", title="Principal plane, LAI 3")
axes[1].legend()

# gap fraction against the exact law and Beer's law
c3 = make(3.0)
zen = np.array([0.0, 15.0, 30.0, 45.0, 60.0, 70.0])
gap = [s3.gap_fraction(z, n=20000, seed=5) for z in zen]
zz = np.linspace(0.0, 72.0, 100)
axes[2].semilogy(zz, c3.gap_probability(zz), label="exact, independent leaves")
axes[2].semilogy(zz, np.exp(-0.5 * c3.lai / np.cos(np.radians(zz))), "--", label="Beer")
axes[2].errorbar(zen, [g.value for g in gap], yerr=[2 * g.se for g in gap], fmt="o", capsize=2,
                 label="traced")
axes[2].set(xlabel="zenith (deg)", ylabel="gap fraction", title="Gap fraction, LAI 3")
axes[2].legend()
for z, g in zip(zen, gap):
    print(f"gap({z:.0f}) traced {g.value:.4f} +- {g.se:.4f}, Beer {np.exp(-0.5 * c3.lai / np.cos(np.radians(z))):.4f}")
plt.show()

# %%
# L-system bushes on a fractal DEM
bush = LSystem.from_string("""axiom: A
A -> [&FL!A]/////'[&FL!A]///////'[&FL!A]
F -> S/////F
S -> F L
L -> [\'\'\'^^{-f+f+f-|-f+f+f}]
""")
dem = np.asarray(fbm_surface((64, 64), 0.8, seed=3, sigma=1.5), dtype=float)
plants, bases = plants_on_terrain(bush, 4, dem, cell_size=0.5, density=0.15, seed=2, scale=0.3,
                                  angle=22.5, width_factor=0.7, sides=4)
ground = Mesh.from_grid(dem, cell_size=0.5)
vertices = np.vstack([plants.vertices + np.asarray(plants.origin), ground.vertices + np.asarray(ground.origin)])
faces = np.vstack([plants.faces, ground.faces + len(plants.vertices)])
ids = np.concatenate([plants.kinds, np.full(len(ground.faces), 2)]).astype(np.int64)  # 0 branch, 1 leaf, 2 soil
v = vertices.astype(np.float64)
area = np.linalg.norm(np.cross(v[faces[:, 1]] - v[faces[:, 0]], v[faces[:, 2]] - v[faces[:, 0]]), axis=1)
faces, ids = faces[area > 1e-12], ids[area > 1e-12]  # tubes tapered to zero width have zero-area triangles
stand = Scene.from_mesh(Mesh.from_triangles(vertices, faces), periodic=False, material_ids=ids,
                        materials=[Lambertian(0.3), BiLambertian(0.45, 0.4), Lambertian(0.2)])
print(f"{len(bases)} bushes, {len(faces)} triangles")
fig, axes = plt.subplots(1, 7, figsize=(14, 2.6), constrained_layout=True)
plot_incidence_series(stand, sun_azimuth=135.0, shape=(120, 120), spp=4, max_depth=5, seed=6, axes=axes)
plt.show()
