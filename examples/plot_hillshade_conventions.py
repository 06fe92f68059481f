"""
Hillshade conventions
=====================

:func:`fractalgeo_rs.hillshade` follows GDAL's ``gdaldem hillshade``: Horn's
gradients, azimuth clockwise from north (315 = light from the north-west,
the cartographic default that keeps valleys from looking like ridges),
altitude above the horizon, ``z_factor`` for vertical exaggeration, and the
multidirectional combination of Mark (1992). The paper's figure 4 is lit
from the south-east (``azimuth=135``), which makes the same relief look
inverted to most readers.

On geographic grids (SRTM in degrees) the cell size must be in the units of
the heights: ``latitude=`` converts degrees to metres at that latitude.

Data: NASA SRTM 3 arc-second DEM tile N44E007, a 256 x 256 crop of the
Maritime Alps (:func:`fractalgeo_rs.data.srtm_alps`), US public domain.
"""
import matplotlib.pyplot as plt
import numpy as np

import fractalgeo_rs as fg

dem, info = fg.data.srtm_alps()
cell = 3.0 / 3600.0  # degrees
variants = [
    ("azimuth 315, altitude 45 (default)", {}),
    ("azimuth 135 (the paper's S-E light)", {"azimuth": 135.0}),
    ("altitude 20 (low sun)", {"altitude": 20.0}),
    ("z_factor 3 (exaggerated)", {"z_factor": 3.0}),
    ("multidirectional", {"multidirectional": True}),
]
fig, axes = plt.subplots(1, 6, figsize=(17, 3.4), constrained_layout=True)
axes[0].imshow(dem, cmap="terrain")
axes[0].set_title("heights (m)")
for ax, (title, options) in zip(axes[1:], variants):
    shade = fg.hillshade(dem, cell_size=cell, latitude=44.5, **options)
    ax.imshow(shade, cmap="gray", vmin=0, vmax=1)
    ax.set_title(title, fontsize=9)
    print(f"{title:38s} mean reflectance {np.nanmean(shade):.3f}")
for ax in axes:
    ax.set_axis_off()
plt.show()
