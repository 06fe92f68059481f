"""
The premise: is the image of a fractal surface a fractal of the same dimension?
================================================================================

The paper rests the fractal transform of images on Pentland's (1984)
premise that the image of a fractal surface is a fractal of the same
dimension. Here fBm DEMs of known Hurst exponent ``H`` (surface dimension
``D = 3 - H``; 256 x 256 cells of 10 m, rms slope 0.25 per cell, one seed
each, :func:`fractalgeo_rs.fbm_surface`) are turned into images, and each
image, taken as an intensity surface, gets its dimension from the variogram
at lags 1-2 (:func:`fractalgeo_rs.variogram`), as does the DEM itself:

* hillshade (:func:`fractalgeo_rs.hillshade`, sun from azimuth 315 at zenith
  30 degrees, Horn's gradients);
* the radiometric path tracer (:meth:`fractalgeo_rs.radiometry.Scene.render`:
  the DEM as a finite patch of facets, Lambertian ``rho = 0.3``, the same sun,
  self-shadowing and 5 scattering events, nadir view, 64 paths per pixel);
* synthetic SAR (:func:`fractalgeo_rs.radar.simulate`, C band, incidence 35
  degrees, looking east, Kirchhoff facets) without speckle and with 4 looks.

If the premise held, every line would follow the dotted 1:1 line. Only the
DEM does. The images compress the range of dimensions (without speckle their
lines rise with slopes of about 0.3 to 0.45 instead of 1: an image is a
function of the surface's gradient, not of its heights), the order of the
surfaces survives without speckle, and 4-look speckle flattens it. The
rendered image reads higher than hillshade: Horn's 3 x 3 gradients smooth
what the renderer's facets do not. docs/radar.md ("The premise, measured")
has the full tables over four estimators, two seeds and more renderers.
"""
import warnings

import matplotlib.pyplot as plt
import numpy as np

import fractalgeo_rs as fg
from fractalgeo_rs.radiometry import Lambertian, Scene

CELL = 10.0
SUN = (315.0, 30.0)  # (azimuth, zenith), degrees
SAR = dict(incidence=35, wavelength=0.056, permittivity=5 + 0.5j, rms_height=0.01, correlation_length=0.1,
           correlation="exponential", n_threads=1)
hursts = np.array([0.2, 0.35, 0.5, 0.65, 0.8])


def dimension(img):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the images' fits warn where they leave the surface range
        return fg.variogram(np.asarray(img, dtype=np.float64), lags=(1, 2)).dimension


kinds = ["DEM itself", "hillshade", "rendered (path tracer)", "SAR, no speckle", "SAR, 4 looks"]
dims = {k: [] for k in kinds}
for h in hursts:
    dem = fg.fbm_surface(256, h, method="exact", seed=0, cell_size=CELL, sigma=0.25 * CELL ** (1 - h), n_threads=1)
    scene = Scene.from_dem(dem, cell_size=CELL, periodic=False, material=Lambertian(0.3))
    images = {
        "DEM itself": dem,
        "hillshade": fg.hillshade(dem, cell_size=CELL, azimuth=SUN[0], altitude=90 - SUN[1], n_threads=1),
        "rendered (path tracer)": scene.render(sun=SUN, spp=64, max_depth=5, seed=1, n_threads=1),
        "SAR, no speckle": fg.radar.simulate(dem, CELL, look_azimuth=90, looks=None, **SAR).image,
        "SAR, 4 looks": fg.radar.simulate(dem, CELL, look_azimuth=90, looks=4, seed=1, **SAR).image,
    }
    for k, img in images.items():
        dims[k].append(dimension(img))

print("surface D      " + " ".join(f"{3 - h:5.2f}" for h in hursts))
for k in kinds:
    print(f"{k:<23.23}" + " ".join(f"{d:5.2f}" for d in dims[k]))

# %%
fig, ax = plt.subplots(figsize=(6.4, 5.2), constrained_layout=True)
d_surface = 3 - hursts
ax.plot([2.0, 3.0], [2.0, 3.0], ":", color="grey", label="1:1 (the premise)")
for k, marker in zip(kinds, "osD^v"):
    ax.plot(d_surface, dims[k], marker=marker, label=k)
ax.set_xlabel("surface dimension D = 3 - H")
ax.set_ylabel("image dimension (variogram, lags 1-2)")
ax.set_xlim(2.1, 2.9)
ax.set_ylim(2.1, 3.0)
ax.set_aspect("equal")
ax.legend(loc="lower right", fontsize="small")
ax.set_title("fBm 256 x 256: image against surface dimension")
plt.show()
