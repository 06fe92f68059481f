"""
Every estimator on one real DEM
===============================

The surface estimators of the package on the SRTM DEM of the Maritime Alps,
each with its log-log fit and the scale range it used (the fitted points are
filled, the points outside the range hollow). They measure different things
(a box-counting dimension, the variogram's or the spectrum's slope, a
likelihood under an fBm model), so they need not agree on a real surface:
the spread is the point of the figure. A value below 2 from the increment
estimators means a local Hurst exponent above 1 at lags of one and two
cells: the 3 arc-second SRTM grid is smoother there than any fBm (it was
resampled from finer data). The scales are in each method's own
units (box sides, lags or radii in cells, frequencies in cycles per cell).

The debiased Whittle estimator assumes fBm and reports its standard error;
the exact Gaussian likelihood (``method="mle"``) is only practical on small
grids and is left out.

Data: NASA SRTM 3 arc-second DEM tile N44E007, a 256 x 256 crop
(:func:`fractalgeo_rs.data.srtm_alps`), US public domain.
"""
import matplotlib.pyplot as plt
import numpy as np

import fractalgeo_rs as fg

dem, info = fg.data.srtm_alps()
z = dem.astype(np.float64)
methods = {
    "dbc": ("dbc", {}),
    "affine": ("affine", {}),
    "square increments": ("surface_variation", {}),
    "first differences": ("surface_variation", {"estimator": "first"}),
    "transects": ("surface_variation", {"estimator": "transect"}),
    "spectral": ("spectral", {}),
    "wavelet": ("wavelet", {}),
    "mass": ("mass", {}),
    "blanket": ("blanket", {}),
    "whittle": ("whittle", {}),
}
fits = {}
for label, (name, options) in methods.items():
    f = fits[label] = fg.dimension(z, method=name, **options)
    lo, hi = f.scale_range
    print(f"{label:18s} D = {f.dimension:.3f}  [{f.ci95[0]:.3f}, {f.ci95[1]:.3f}]  "
          f"scales {lo:.3g}..{hi:.3g} ({int(f.used.sum())} of {f.scales.size})")

# %%
fig, axes = plt.subplots(3, 4, figsize=(15, 10.5), constrained_layout=True)
axes[-1, -1].set_axis_off()
axes = axes.ravel()
axes[0].imshow(dem, cmap="terrain")
axes[0].set_title("SRTM, Maritime Alps (m)")
axes[0].set_axis_off()
for ax, (label, f) in zip(axes[1:], fits.items()):
    f.plot(ax=ax)
    ax.set_title(f"{label}: D = {f.dimension:.3f}", fontsize=10)
plt.show()
