"""
Figure 2: a box lattice over a real curve
=========================================

Box counting (paper section 2.4, figure 2): cover the set with a lattice of
boxes of side ``s`` and count the boxes ``N(s)`` that hold part of it;
``D = -d log N / d log s`` (:func:`fractalgeo_rs.box_counting`). The lattice
is anchored at the corner of the curve's bounding box.

Data: the 1200 m contour of the SRTM DEM of the Maritime Alps
(:func:`fractalgeo_rs.data.srtm_alps`, 3 arc-second tile N44E007, NASA SRTM,
US public domain).
"""
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.patches import Rectangle
from scipy import ndimage

import fractalgeo_rs as fg

dem, info = fg.data.srtm_alps()
above = dem > 1200
# the contour: cells above 1200 m with a neighbour at or below it
curve = above & ndimage.binary_dilation(~above, structure=np.ones((3, 3), bool))

fit = fg.box_counting(curve)
print(fit)

# %%
# The occupied boxes at two sizes, and the log-log fit over every size.
rows, cols = np.nonzero(curve)
r0, c0 = rows.min(), cols.min()
fig, axes = plt.subplots(1, 3, figsize=(13, 4.4), constrained_layout=True)
for ax, s in zip(axes[:2], (32, 8)):
    ax.imshow(curve, cmap="gray_r", interpolation="nearest")
    occupied = {((r - r0) // s, (c - c0) // s) for r, c in zip(rows, cols)}
    for i, j in occupied:
        ax.add_patch(Rectangle((c0 + j * s - 0.5, r0 + i * s - 0.5), s, s,
                               facecolor="tab:orange", alpha=0.35, edgecolor="tab:red", lw=0.4))
    ax.set_title(f"s = {s} cells: N(s) = {len(occupied)} boxes")
    ax.set_axis_off()
fit.plot(ax=axes[2])
axes[2].set_title(f"D = {fit.dimension:.3f}  [{fit.ci95[0]:.3f}, {fit.ci95[1]:.3f}]")
plt.show()
