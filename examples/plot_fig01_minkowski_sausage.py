"""
Figure 1: the Minkowski sausage of a real coastline
===================================================

The parallel set of a curve ``S`` at radius ``r`` (the "Minkowski sausage",
paper section 2.3, figure 1) is every point within distance ``r`` of ``S``.
Its area scales as ``A(r) ~ r^(2 - D)``, so the slope of ``log A`` against
``log r`` gives the dimension ``D = 2 - slope``
(:func:`fractalgeo_rs.minkowski`, exact Euclidean distance transform).

Data: the coastline of the Kilauea 30 m DEM (Hawaii), the land mask bundled
as :func:`fractalgeo_rs.data.kilauea_land_mask`; as distributed with the GMT
example data, origin USGS (US public domain).
"""
import matplotlib.pyplot as plt
import numpy as np
from scipy import ndimage

import fractalgeo_rs as fg

land, info = fg.data.kilauea_land_mask()
# the coast: land pixels with a sea neighbour (8-connected)
coast = land & ~ndimage.binary_erosion(land, structure=np.ones((3, 3), bool), border_value=1)
coast &= ndimage.binary_dilation(~land, structure=np.ones((3, 3), bool))

fit = fg.minkowski(coast, radii=[1, 2, 3, 4, 6, 8, 11, 16, 23, 32])
print(fit)

# %%
# Three of the sausages over the southern coast, and the log-log fit.
dist = ndimage.distance_transform_edt(~coast)
fig, axes = plt.subplots(1, 4, figsize=(13, 3.6), constrained_layout=True)
window = (slice(560, 793), slice(150, 700))
for ax, r in zip(axes[:3], (2, 8, 32)):
    ax.imshow(dist[window] <= r, cmap="Blues", interpolation="nearest")
    ax.contour(coast[window], levels=[0.5], colors="k", linewidths=0.4)
    ax.set_title(f"sausage at r = {r} cells ({30 * r} m)")
    ax.set_axis_off()
fit.plot(ax=axes[3])
axes[3].set_title(f"D = {fit.dimension:.3f}  [{fit.ci95[0]:.3f}, {fit.ci95[1]:.3f}]")
plt.show()
