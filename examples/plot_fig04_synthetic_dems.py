"""
Figure 4: two synthetic DEMs lit from the south-east, with lakes
================================================================

Two fractal DEMs of dimension ``D = 3 - H`` (:func:`fractalgeo_rs.synthetic_dem`,
exact fBm by circulant embedding, 30 m cells), shown as Lambertian surfaces
lit from the south-east (:func:`fractalgeo_rs.hillshade` with
``azimuth=135``, as in the paper's figure 4) and flooded to a water level
(:func:`fractalgeo_rs.lakes`). A lake shore is a level line of the surface:
its dimension is ``D - 1 = 2 - H``, measured here by box counting of the
shore cells.

Data: generated (seeded), no licence needed.
"""
import matplotlib.pyplot as plt
import numpy as np
from scipy import ndimage

import fractalgeo_rs as fg

n = 512
fig, axes = plt.subplots(1, 3, figsize=(14, 4.8), constrained_layout=True)
fits = {}
for ax, hurst in zip(axes[:2], (0.8, 0.5)):
    dem = fg.synthetic_dem((n, n), hurst, cell_size=30.0, relief=200.0, mean_elevation=500.0,
                           method="exact", seed=11)
    shade = fg.hillshade(dem, azimuth=135.0, altitude=45.0, cell_size=30.0)
    level = float(np.percentile(dem, 35))
    water = fg.lakes(dem, level, coastlines=False).mask
    # the shore: water cells with a dry neighbour
    shore = water & ndimage.binary_dilation(~water, structure=np.ones((3, 3), bool))
    fits[hurst] = fg.box_counting(shore, box_sizes=[2, 4, 8, 16, 32])
    ax.imshow(shade, cmap="gray", vmin=0, vmax=1)
    ax.imshow(np.ma.masked_where(~water, water), cmap="Blues", vmin=0, vmax=1.5, alpha=0.8,
              interpolation="nearest")
    ax.set_title(f"D = {3 - hurst:.1f} (H = {hurst}); shore D = {fits[hurst].dimension:.2f} "
                 f"(D - 1 = {2 - hurst:.1f})")
    ax.set_axis_off()
for hurst, fit in fits.items():
    fit.plot(ax=axes[2], label=f"H = {hurst}")
    print(f"H = {hurst}: shore {fit}")
axes[2].set_title("box counting of the lake shores")
axes[2].legend()
plt.show()
