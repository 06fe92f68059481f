"""
IFS attractors and their dimension
==================================

The attractor of an iterated function system of similarity maps with ratios
``r_i`` (and the open set condition) has the similarity dimension ``D`` that
solves Moran's equation ``sum r_i^D = 1`` (Hutchinson 1981;
:func:`fractalgeo_rs.lsystem.moran_dimension`). Each preset of
:class:`fractalgeo_rs.IFS` is drawn by the chaos game and rasterised; box
counting of the raster (:func:`fractalgeo_rs.box_counting`) measures ``D``
back.

Data: generated (seeded), no licence needed.
"""
import matplotlib.pyplot as plt

import fractalgeo_rs as fg
from fractalgeo_rs.lsystem import IFS_PRESETS

fig, axes = plt.subplots(1, len(IFS_PRESETS), figsize=(16, 3.4), constrained_layout=True)
for ax, name in zip(axes, IFS_PRESETS):
    ifs = fg.IFS.preset(name)
    raster = ifs.rasterize((512, 512), n_points=400_000, seed=1)
    fit = fg.box_counting(raster, box_sizes=[2, 4, 8, 16, 32])
    exact = ifs.dimension if ifs.dimension is not None else ifs.similarity_dimension
    exact_text = "no closed form" if exact is None else f"exact D = {exact:.3f}"
    ax.imshow(raster, cmap="gray_r", interpolation="nearest", origin="lower")
    ax.set_title(f"{name}\n{exact_text}, boxes {fit.dimension:.3f}", fontsize=9)
    ax.set_axis_off()
    print(f"{name:20s} {exact_text:15s}  box counting D = {fit.dimension:.3f}")
plt.show()
