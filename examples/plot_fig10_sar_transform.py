"""
Figure 10: fractal transform of a SAR scene and its built-up segmentation
=========================================================================

The fractal transform (paper section 4.2) maps an image to the local
dimension of a moving window. As in the paper, the dimension is the Voss
P(m, L) mass dimension (:func:`fractalgeo_rs.fractal_transform`,
``method="mass"``), here in 17 x 17 windows (170 m) with heights in units of
3 dB. It is used "as a feature in fusion with other parameters": with the
local means of VV and of VV - VH (co-polarised double bounce of walls and
streets), a seeded k-means in three classes (:func:`fractalgeo_rs.segment`)
separates the built-up class, the one with the largest VV - VH.

Data: Sentinel-1 IW GRD sigma0 (dB), VV and VH, 512 x 512 at 10 m, Vega Baja
del Segura, Spain, September 2019 (:func:`fractalgeo_rs.data.sentinel1_vv_db`).
"Contains modified Copernicus Sentinel data 2019" (Sen1Floods11 sample).
"""
import matplotlib.pyplot as plt
import numpy as np
from scipy import ndimage

import fractalgeo_rs as fg

window = 17
vv, info = fg.data.sentinel1_vv_db()
vh, _ = fg.data.sentinel1_vh_db()
dim = fg.fractal_transform(vv, window, method="mass", z_scale=3.0)
mean_vv = ndimage.uniform_filter(vv.astype(np.float64), window, mode="reflect")
pol = mean_vv - ndimage.uniform_filter(vh.astype(np.float64), window, mode="reflect")
classes = fg.segment([dim, mean_vv, pol], method="kmeans", n_classes=3, seed=0)
built = max(range(3), key=lambda k: pol[classes == k].mean() if np.any(classes == k) else -np.inf)
mask = classes == built
for k in range(3):
    m = classes == k
    print(f"class {k}: {m.mean():5.1%} of the scene, mean D {np.nanmean(dim[m]):.3f}, "
          f"VV {mean_vv[m].mean():6.2f} dB, VV-VH {pol[m].mean():5.2f} dB" + ("  <- built-up" if k == built else ""))

# %%
fig, axes = plt.subplots(1, 3, figsize=(15, 5.2), constrained_layout=True)
axes[0].imshow(vv, cmap="gray", vmin=-25, vmax=5)
axes[0].set_title("Sentinel-1 VV (dB)")
im = axes[1].imshow(dim, cmap="viridis")
axes[1].set_title(f"fractal transform, P(m, L), {window} x {window}")
fig.colorbar(im, ax=axes[1], shrink=0.8, label="local dimension")
axes[2].imshow(vv, cmap="gray", vmin=-25, vmax=5)
axes[2].imshow(np.ma.masked_where(~mask, mask), cmap="autumn", alpha=0.5, interpolation="nearest")
axes[2].set_title("built-up class (red)")
for ax in axes:
    ax.set_axis_off()
plt.show()
