"""Radar: accuracy against SMRT (an independent implementation, when
installed: ``pip install smrt``) and speed of the scene simulator.

* geometric optics against SMRT's ``geometrical_optics_backscatter``;
* first-order SPM against SMRT's IEM (``iem_fung92``) at k sigma = 0.1,
  k l = 1, where IEM reduces to SPM (C band, eps = 15 + 3j, 20-50 degrees);
* speckle and ``simulate`` of a 4096 x 4096 fBm DEM (4 looks) timed against
  the package's own hillshade of the same DEM and against the numpy pipeline
  a user writes by hand today (the issue's "hand-written speckle": local
  incidence from ``np.gradient``, sigma0 by ``np.interp`` in the same table,
  shadow from ``np.maximum.accumulate`` along range, Gamma speckle from
  ``numpy.random.Generator.gamma``; no slant-range projection, so it does
  less than ``simulate``), in the same run, with the load average;
* ``simulate`` on a Dask array (strips of whole range lines) against numpy.

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


def _best(f, reps=5):
    best = math.inf
    for _ in range(reps):
        t0 = time.perf_counter()
        f()
        best = min(best, time.perf_counter() - t0)
    return best


def numpy_pipeline(dem, cell, inc, looks, seed, table, step=0.1):
    """The hand-written numpy scene (ground range, no slant projection)."""
    t = math.radians(inc)
    gy, gx = np.gradient(dem, cell)
    norm = np.sqrt(1 + gx * gx + gy * gy)
    cos_loc = np.clip((math.cos(t) + math.sin(t) * gx) / norm, -1, 1)
    theta = np.degrees(np.arccos(cos_loc))
    s0 = np.interp(theta, np.arange(table.size) * step, table) * norm
    u = dem + np.arange(dem.shape[1]) * cell / math.tan(t)
    shadow = (np.maximum.accumulate(u, axis=1) > u) | (cos_loc <= 0)
    s0[shadow] = 0.0
    layover = gx > math.tan(t)
    img = s0 * np.random.default_rng(seed).gamma(looks, 1.0 / looks, size=s0.shape)
    return img, s0, theta, layover, shadow


def timing(size):
    import os

    dem = fg.fbm_surface(size, 0.7, method="spectral", seed=1, sigma=2.0)
    sigma = np.full(dem.shape, 0.1)
    table = fg.radar.backscatter(np.arange(900) * 0.1, wavelength=0.056, permittivity=5 + 0.5j, rms_height=0.01,
                                 correlation_length=0.1, correlation="exponential")
    print("load average before:", os.getloadavg())
    t_np = _best(lambda: numpy_pipeline(dem, 10.0, 35, 4, 1, table), reps=3)
    print(f"{size} x {size}: hand-written numpy pipeline (no slant projection) {t_np:.3f} s", flush=True)
    for nt in (1, 2):
        t_hs = _best(lambda: fg.hillshade(dem, cell_size=10.0, n_threads=nt))
        t_sp = _best(lambda: fg.radar.speckle(sigma, looks=4, seed=1, n_threads=nt))
        t_sim = _best(lambda: fg.radar.simulate(dem, 10.0, look_azimuth=90, incidence=35, wavelength=0.056,
                                                looks=4, seed=1, n_threads=nt))
        t_rot = _best(lambda: fg.radar.simulate(dem, 10.0, look_azimuth=30, incidence=35, wavelength=0.056,
                                                looks=4, seed=1, n_threads=nt), reps=1)
        t_ml = _best(lambda: fg.radar.simulate(dem, 10.0, look_azimuth=90, incidence=35, wavelength=0.056,
                                               looks=1, seed=1, multilook=(4, 1), n_threads=nt), reps=1)
        print(f"{size} x {size}, n_threads={nt} (best of 5): hillshade {t_hs:.3f} s, speckle (4 looks) "
              f"{t_sp:.3f} s ({t_sp / t_hs:.2f}x hillshade), simulate {t_sim:.3f} s ({t_sim / t_hs:.2f}x "
              f"hillshade, {t_np / t_sim:.2f}x faster than numpy); look azimuth 30: {t_rot:.3f} s; multilook (4, 1): "
              f"{t_ml:.3f} s", flush=True)
    try:
        import dask.array as da
    except ImportError:
        return
    d = da.from_array(dem, chunks=(1024, 1024))
    t_da = _best(lambda: fg.radar.simulate(d, 10.0, look_azimuth=90, incidence=35, wavelength=0.056, looks=4,
                                           seed=1, n_threads=1).image.compute(), reps=1)
    print(f"Dask, chunks 1024² (rechunked to strips of whole range lines), threaded scheduler: {t_da:.3f} s",
          flush=True)
    print("load average after:", os.getloadavg())


if __name__ == "__main__":
    p = argparse.ArgumentParser()
    p.add_argument("--size", type=int, default=4096)
    a = p.parse_args()
    smrt_comparison()
    timing(a.size)
