"""Radar: accuracy against SMRT (an independent implementation, when
installed: ``pip install smrt``) and speed of the scene simulator.

* geometric optics against SMRT's ``geometrical_optics_backscatter``;
* first-order SPM against SMRT's IEM (``iem_fung92``) at k sigma = 0.1,
  k l = 1, where IEM reduces to SPM (C band, eps = 15 + 3j, 20-50 degrees);
* speckle and ``simulate`` of a 4096 x 4096 fBm DEM (4 looks) timed against
  the package's own hillshade of the same DEM, in the same run.

Run: ``python benches/bench_radar.py [--size 4096]``.
"""
import argparse
import math
import time
import warnings

import numpy as np

import fractalgeo_rs as fg

C = 299_792_458.0


def smrt_comparison():
    try:
        from smrt.interface.geometrical_optics_backscatter import GeometricalOpticsBackscatter
        from smrt.interface.iem_fung92 import IEM_Fung92
    except ImportError:
        print("SMRT not installed: pip install smrt (skipping the comparison)")
        return
    wl, eps = 0.056, 15 + 3j
    f = C / wl
    k = 2 * math.pi / wl
    t = np.array([20.0, 30.0, 40.0, 50.0])
    mu = np.cos(np.radians(t))
    # GO: SMRT's mean_square_slope is the per-axis slope variance m^2 = 2 sigma^2 / l^2
    go = GeometricalOpticsBackscatter(mean_square_slope=0.05)
    R = go.diffuse_reflection_matrix(f, 1, eps, mu, mu, np.pi, 2)
    smrt_go = 4 * np.pi * mu * np.asarray(R[0]).ravel()
    l = 1.0
    ours = fg.radar.backscatter(t, model="geometric_optics", wavelength=wl, permittivity=eps,
                                rms_height=math.sqrt(0.05 / 2) * l, correlation_length=l)
    print("GO, dB difference (ours - SMRT):", np.round(fg.radar.to_db(ours) - fg.radar.to_db(smrt_go), 6))
    for corr in ("gaussian", "exponential"):
        s, l = 0.1 / k, 1.0 / k
        iem = IEM_Fung92(roughness_rms=s, corr_length=l, autocorrelation_function=corr)
        R = iem.diffuse_reflection_matrix(f, 1, eps, mu, mu, np.pi, 2)
        vv, hh = (4 * np.pi * mu * np.asarray(R[i]).ravel() for i in (0, 1))
        for pol, ref in (("vv", vv), ("hh", hh)):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", fg.radar.RadarValidityWarning)
                ours = fg.radar.backscatter(t, model="spm", wavelength=wl, permittivity=eps, rms_height=s,
                                            correlation_length=l, correlation=corr, polarization=pol)
            d = fg.radar.to_db(ours) - fg.radar.to_db(ref)
            print(f"SPM vs SMRT IEM ({corr}, {pol}) at 20-50 deg, dB: {np.round(d, 3)}")


def _best(f, reps=3):
    best = math.inf
    for _ in range(reps):
        t0 = time.perf_counter()
        f()
        best = min(best, time.perf_counter() - t0)
    return best


def timing(size):
    dem = fg.fbm_surface(size, 0.7, method="spectral", seed=1, sigma=2.0)
    sigma = np.full(dem.shape, 0.1)
    for nt in (1, 2):
        t_hs = _best(lambda: fg.hillshade(dem, cell_size=10.0, n_threads=nt))
        t_sp = _best(lambda: fg.radar.speckle(sigma, looks=4, seed=1, n_threads=nt))
        t_sim = _best(lambda: fg.radar.simulate(dem, 10.0, look_azimuth=90, incidence=35, wavelength=0.056,
                                                looks=4, seed=1, n_threads=nt))
        t_rot = _best(lambda: fg.radar.simulate(dem, 10.0, look_azimuth=30, incidence=35, wavelength=0.056,
                                                looks=4, seed=1, n_threads=nt), reps=1)
        t_ml = _best(lambda: fg.radar.simulate(dem, 10.0, look_azimuth=90, incidence=35, wavelength=0.056,
                                               looks=1, seed=1, multilook=(4, 1), n_threads=nt), reps=1)
        print(f"{size} x {size}, n_threads={nt} (best of 3): hillshade {t_hs:.3f} s, speckle (4 looks) "
              f"{t_sp:.3f} s ({t_sp / t_hs:.2f}x hillshade), simulate {t_sim:.3f} s ({t_sim / t_hs:.2f}x "
              f"hillshade); look azimuth 30: {t_rot:.3f} s; multilook (4, 1): {t_ml:.3f} s", flush=True)


if __name__ == "__main__":
    p = argparse.ArgumentParser()
    p.add_argument("--size", type=int, default=4096)
    a = p.parse_args()
    smrt_comparison()
    timing(a.size)
