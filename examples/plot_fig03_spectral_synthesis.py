"""
Figure 3: spectral synthesis of a fractal DEM
=============================================

The pipeline of the paper's figure 3 (section 3, eq. 21): white Gaussian
noise, its Fourier transform, a filter ``|f|^(-beta/2)`` that gives the
power spectrum ``S(f) ~ |f|^(-beta)`` with ``beta = 2H + 2``, and the inverse
transform: a surface of dimension ``D = T + (3 - beta) / 2 = 3 - H``.

The four panels are written out in NumPy so that each step can be seen;
:func:`fractalgeo_rs.fbm_surface` with ``method="spectral"`` does the same in
Rust (with the filter of sampled fBm, which corrects the aliasing of the pure
power law near the Nyquist frequency) and
:func:`fractalgeo_rs.spectral_dimension` measures ``D`` back from the
radial spectrum.

Data: generated (seeded), no licence needed.
"""
import matplotlib.pyplot as plt
import numpy as np

import fractalgeo_rs as fg

n, hurst = 256, 0.7
beta = 2 * hurst + 2
rng = np.random.default_rng(3)
noise = rng.standard_normal((n, n))
spectrum = np.fft.fft2(noise)
fy = np.fft.fftfreq(n)[:, None]
fx = np.fft.fftfreq(n)[None, :]
f = np.hypot(fy, fx)
filt = np.zeros_like(f)
filt[f > 0] = f[f > 0] ** (-beta / 2)
surface = np.fft.ifft2(spectrum * filt).real

fit = fg.spectral_dimension(surface)
rust = fg.fbm_surface((n, n), hurst, method="spectral", seed=3)
fit_rust = fg.spectral_dimension(rust)
print(f"NumPy pipeline: D = {fit.dimension:.3f}; fbm_surface(method='spectral'): "
      f"D = {fit_rust.dimension:.3f}; 3 - H = {3 - hurst:.1f}")

# %%
fig, axes = plt.subplots(1, 5, figsize=(16, 3.4), constrained_layout=True)
axes[0].imshow(noise, cmap="gray")
axes[0].set_title("white noise")
axes[1].imshow(np.log10(np.abs(np.fft.fftshift(spectrum)) + 1e-12), cmap="magma")
axes[1].set_title("log |FFT| of the noise")
axes[2].imshow(np.log10(np.fft.fftshift(filt) + 1e-12), cmap="magma")
axes[2].set_title(f"filter |f|^-{beta / 2:.1f}")
axes[3].imshow(surface, cmap="terrain")
axes[3].set_title(f"surface, H = {hurst}")
for ax in axes[:4]:
    ax.set_axis_off()
fit.plot(ax=axes[4])
axes[4].set_title(f"radial spectrum: D = {fit.dimension:.3f}")
plt.show()
