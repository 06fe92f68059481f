"""
The virtual radiometric experiment (figures 8 and 9)
====================================================

Section 4.1 of the seed paper images "an area of 32 x 32 microfacets ...
from a nadir placed sensor with variable incident illumination" (figure 9),
computes albedo and BRF from the images, and notes that "after a fractal
resampling the local roughness increases and the BRF is modified". This
example repeats the experiment with ``fractalgeo_rs.radiometry``:

1. a periodic 32 x 32 fBm tile (``H = 0.7``), Lambertian facets
   (``rho = 0.5``), nadir sensor, sun in the east at zenith 0, 15, ..., 75
   and 89 degrees: the images of figure 9 and a perspective view of the
   (infinite, periodic) surface, the last scene of the figure
   (``Scene.render_perspective``);
2. the BRF of the same tile and of the tile after
   :func:`~fractalgeo_rs.fractal_resample` x2 and x4 (fBm detail added
   below the cell: steeper facets, more shadow);
3. the tile as a periodic surface against the same heights as a finite
   patch (the edge effect of rendering a patch alone);
4. the BRF against the fractal dimension ``D = 3 - H`` of fBm tiles, with
   the facet slopes fixed (the same variance of the increments at one cell)
   and with the RMS height fixed.

Every BRF is a Monte Carlo estimate; the error bars are 3 standard errors
(most are smaller than the markers). Sample counts are kept small so the
example runs in a few seconds; docs/radiometry.md gives the same numbers
at more samples.
"""
import time

import matplotlib.pyplot as plt
import numpy as np

import fractalgeo_rs as fg
from fractalgeo_rs.radiometry import PAPER_SUN_ZENITHS, Lambertian, Scene, plot_incidence_series

t0 = time.perf_counter()
N, H, SIGMA, RHO = 32, 0.7, 0.5, 0.5
SUN_AZ = 90.0  # sun in the east
SPP = 65536
z = fg.fbm_surface((N, N), H, method="spectral", periodic=True, seed=1, sigma=SIGMA)
scene = Scene.from_dem(z, material=Lambertian(RHO))

# %%
# Figure 9: the incidence series seen from nadir, and a perspective view
# ----------------------------------------------------------------------
# Radiance images (unit sun irradiance normal to the beam) on one grey
# scale: the tile darkens as ``cos(zenith)`` and the shadows lengthen
# towards the west. The last panel is a pinhole camera's view from the
# south-south-west, 55 degrees from the zenith, of the tile repeated
# without end.
fig = plt.figure(figsize=(12, 5.6))
axes = [fig.add_subplot(2, 4, k + 1) for k in range(7)]
plot_incidence_series(scene, sun_zenith=PAPER_SUN_ZENITHS, sun_azimuth=SUN_AZ, shape=(128, 128), spp=8,
                      axes=axes)
ax3 = fig.add_subplot(2, 4, 8)
persp = scene.render_perspective(sun=(SUN_AZ, 45.0), view=(200.0, 55.0), distance=40.0, fov=50.0,
                                 shape=(150, 150), spp=16)
ax3.imshow(persp, cmap="gray", vmin=0.0)
ax3.set_title("3D view, sun zenith 45", fontsize=9)
ax3.set_xticks([])
ax3.set_yticks([])
fig.tight_layout()

# %%
# Albedo and BRF; fractal resampling makes the surface rougher
# ------------------------------------------------------------
# ``fractal_resample`` is not periodic, so the tile is padded by wrapping,
# resampled (fBm continuation with the tile's ``H`` and ``sigma``) and the
# middle cropped: the coarse samples are kept exactly and the new detail
# joins across the tile's edges. The ground area stays 32 x 32 m; the
# cells become 0.5 m and 0.25 m.


def resample_periodic(heights, factor, seed, pad=8):
    big = np.pad(heights, pad, mode="wrap")
    fine = fg.fractal_resample(big, factor, hurst=H, sigma=SIGMA, seed=seed)
    p, n = pad * factor, heights.shape[0] * factor
    return fine[p:p + n, p:p + n]


surfaces = {"32 x 32 (1 m)": (z, 1.0)}
for f in (2, 4):
    surfaces[f"x{f}: {N * f} x {N * f} ({1 / f:g} m)"] = (resample_periodic(z, f, seed=10 + f), 1.0 / f)

fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4))
for name, (zz, cell) in surfaces.items():
    s = Scene.from_dem(zz, cell_size=cell, material=Lambertian(RHO))
    sw = s.brf_sweep(sun_zenith=PAPER_SUN_ZENITHS, sun_azimuth=SUN_AZ, spp=SPP)
    slope = np.degrees(np.arctan(np.hypot(*np.gradient(zz, cell)))).mean()
    ax1.errorbar(sw.sun_zenith, sw.value[:, 0], yerr=3 * sw.se[:, 0], marker="o", ms=3, capsize=2,
                 label=f"{name}, mean slope {slope:.0f} deg")
    alb = [s.albedo(sun=(SUN_AZ, zs), spp=SPP).value for zs in PAPER_SUN_ZENITHS]
    ax2.plot(PAPER_SUN_ZENITHS, alb, "o-", ms=3, label=name)
ax1.axhline(RHO, color="0.6", lw=0.8, ls=":")
ax1.set(xlabel="sun zenith (degrees)", ylabel="nadir BRF", title=f"BRF, Lambertian rho = {RHO}")
ax1.legend(fontsize=8)
ax2.set(xlabel="sun zenith (degrees)", ylabel="albedo", title="directional-hemispherical albedo")
ax2.legend(fontsize=8)
fig.tight_layout()

# %%
# Periodic tile against a finite patch
# ------------------------------------
# The same heights as one tile of an infinite surface (left) and as a patch
# alone in empty space (``periodic=False``, right), sun at zenith 75 in the
# east: the patch's east-facing border is lit where the infinite surface
# would shadow it, and light escapes through its sides.
finite = Scene.from_dem(np.pad(z, ((0, 1), (0, 1)), mode="wrap"), periodic=False, material=Lambertian(RHO))
fig, axes = plt.subplots(1, 3, figsize=(12, 3.8))
imgs = [sc.render(sun=(SUN_AZ, 75.0), shape=(128, 128), spp=4) for sc in (scene, finite)]
for a, im, title in zip(axes[:2], imgs, ("periodic", "finite patch")):
    a.imshow(im, cmap="gray", vmin=0, vmax=max(i.max() for i in imgs))
    a.set_title(f"{title}, sun zenith 75", fontsize=9)
    a.set_xticks([])
    a.set_yticks([])
for sc, name in ((scene, "periodic"), (finite, "finite patch")):
    sw = sc.brf_sweep(sun_zenith=PAPER_SUN_ZENITHS, sun_azimuth=SUN_AZ, spp=SPP)
    axes[2].errorbar(sw.sun_zenith, sw.value[:, 0], yerr=3 * sw.se[:, 0], marker="o", ms=3, capsize=2, label=name)
axes[2].set(xlabel="sun zenith (degrees)", ylabel="nadir BRF")
axes[2].legend(fontsize=8)
fig.tight_layout()

# %%
# BRF against the fractal dimension
# ---------------------------------
# fBm tiles of ``H`` from 0.2 to 0.95 (``D = 3 - H`` from 2.8 to 2.05, the
# same random phases). Left: the increments at one cell have the same
# variance (``sigma = 0.5``), so the facet slopes are alike and a rougher
# (higher-D) surface has less relief at the scale of the tile. Right: every
# tile scaled to the same RMS height (0.8 m). D measured by the variogram
# (lags 1-2) is printed beside the nominal one.
hursts = np.array([0.2, 0.35, 0.5, 0.65, 0.8, 0.95])
fig, axes = plt.subplots(1, 2, figsize=(11, 4), sharey=True)
for ax, mode in zip(axes, ("same facet slopes", "same RMS height")):
    res = {zs: [] for zs in (0.0, 45.0, 75.0)}
    for h in hursts:
        zh = fg.fbm_surface((N, N), h, method="spectral", periodic=True, seed=1, sigma=SIGMA)
        if mode == "same RMS height":
            zh = zh * (0.8 / zh.std())
        s = Scene.from_dem(zh, material=Lambertian(RHO))
        for zs in res:
            e = s.brf(sun=(SUN_AZ, zs), spp=SPP)
            res[zs].append((e.value, e.se))
        if mode == "same facet slopes":
            print(f"H = {h:.2f}: D = {3 - h:.2f}, variogram D = {fg.variogram(zh).dimension:.2f}")
    for zs, v in res.items():
        v = np.array(v)
        ax.errorbar(3 - hursts, v[:, 0], yerr=3 * v[:, 1], marker="o", ms=3, capsize=2, label=f"sun zenith {zs:g}")
    ax.set(xlabel="fractal dimension D = 3 - H", title=mode)
    ax.legend(fontsize=8)
axes[0].set_ylabel("nadir BRF")
fig.tight_layout()
print(f"example ran in {time.perf_counter() - t0:.1f} s")
plt.show()
