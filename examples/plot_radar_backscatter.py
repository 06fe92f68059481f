"""
Radar backscatter and a synthetic SAR scene
============================================

Left: sigma0 against incidence (C band, ``eps = 15 + 3j``) for a Gaussian
surface (``k sigma = 1.5``, ``k l = 10``) by the Kirchhoff integral and
geometric optics, for a slightly rough Gaussian surface by first-order SPM,
and for an fBm surface (``H = 0.7``) by Kirchhoff and SPM. Solid where
:func:`fractalgeo_rs.radar.validity` puts the model inside its range, dotted
outside (the ranges are in docs/radar.md).

Right: a synthetic 4-look SAR scene (:func:`fractalgeo_rs.radar.simulate`,
incidence 35 degrees, radar looking east) of the bundled SRTM DEM of the
Maritime Alps, with layover (red) and radar shadow (blue), next to the
bundled real Sentinel-1 VV scene (a different, flatter place: the
Vega Baja del Segura) on the same dB scale.

Data: NASA SRTM 3 arc-second DEM (:func:`fractalgeo_rs.data.srtm_alps`),
US public domain; Copernicus Sentinel-1 IW GRD
(:func:`fractalgeo_rs.data.sentinel1_vv_db`), contains modified Copernicus
Sentinel data 2019.
"""
import warnings

import matplotlib.pyplot as plt
import numpy as np

import fractalgeo_rs as fg

WL, EPS = 0.056, 15 + 3j
K = 2 * np.pi / WL
t = np.linspace(1.0, 70.0, 139)
curves = [
    ("Kirchhoff, Gaussian", "kirchhoff", dict(rms_height=1.5 / K, correlation_length=10 / K)),
    ("GO, Gaussian", "geometric_optics", dict(rms_height=1.5 / K, correlation_length=10 / K)),
    ("SPM, Gaussian k sigma 0.2", "spm", dict(rms_height=0.2 / K, correlation_length=2 / K)),
    ("Kirchhoff, fBm H 0.7", "kirchhoff", dict(correlation="fbm", hurst=0.7, topothesy=1e-3)),
    ("SPM, fBm H 0.7", "spm", dict(correlation="fbm", hurst=0.7, topothesy=1e-7)),
]
fig, (ax, ax1, ax2) = plt.subplots(1, 3, figsize=(15, 4.6))
for label, model, kw in curves:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", fg.radar.RadarValidityWarning)
        s = fg.radar.backscatter(t, model=model, wavelength=WL, permittivity=EPS, **kw)
        ok = np.array([fg.radar.validity(wavelength=WL, incidence=x, **kw).valid[model] for x in t])
    line, = ax.plot(t, np.where(ok, fg.radar.to_db(s), np.nan), label=label)
    ax.plot(t, np.where(ok, np.nan, fg.radar.to_db(s)), ":", color=line.get_color())
ax.set(xlabel="incidence (degrees)", ylabel="sigma0 (dB)", ylim=(-60, 20), title="models (dotted: outside validity)")
ax.legend(fontsize=8)

dem, info = fg.data.srtm_alps()
scene = fg.radar.simulate(dem, info["cell_size"], look_azimuth=90, incidence=35, wavelength=0.056, looks=4, seed=1)
db = fg.radar.to_db(np.maximum(scene.image, 1e-6))
ax1.imshow(db, cmap="gray", vmin=-25, vmax=5)
overlay = np.zeros(dem.shape + (4,))
overlay[scene.layover] = (1, 0, 0, 0.6)
overlay[scene.shadow] = (0, 0, 1, 0.6)
ax1.imshow(overlay)
ax1.set_title("synthetic SAR of the SRTM Alps (35 deg, 4 looks)")
vv, _ = fg.data.sentinel1_vv_db()
ax2.imshow(vv, cmap="gray", vmin=-25, vmax=5)
ax2.set_title("Sentinel-1 VV, real (dB)")
for a in (ax1, ax2):
    a.set_xticks([])
    a.set_yticks([])
fig.tight_layout()
plt.show()
