"""Speed and statistics of fractal resampling against scipy.ndimage.zoom.

Run: python benches/bench_resample.py [--size 4096] [--stats 2048] [--dask 16384]

* speed: an exact fBm (H = 0.7) of ``size``^2 resampled by 2 with fixed H and
  sigma and with the default analysis (``model="smooth"`` and ``"fbm"``),
  against ``scipy.ndimage.zoom(order=3)`` on the same input; the
  ``hurst="local"`` analysis (point and area support) timed apart, against
  its numpy reference in the same run;
* stats: exact fBm of ``stats``^2 (H 0.3-0.9) subsampled (point) or
  block-averaged (area) by 2 and 4 and resampled back with ``hurst="local"``
  and ``model="fbm"`` (the bicubic baseline: a cubic spline on the output grid):
  lag-1 variance over the truth's, variogram H over lags 1-8, spectral slope
  of the finest octave, crease ratio, against zoom(order=3); then the
  finest-octave slope with the true H and sigma fixed (no local analysis);
* dask: a ``dask``^2 output from a chunked input, peak RSS (ru_maxrss).
"""
import argparse
import os
import platform
import resource
import time
import warnings

import numpy as np
from scipy import ndimage

import fractalgeo_rs as fg
from fractalgeo_rs.dem import _resample as R


def lag1(z):
    return 0.5 * (np.nanmean(np.diff(z, axis=0) ** 2) + np.nanmean(np.diff(z, axis=1) ** 2))


def hurst_lags(z):
    lags = np.arange(1, 9)
    g = [0.5 * (np.nanmean((z[k:] - z[:-k]) ** 2) + np.nanmean((z[:, k:] - z[:, :-k]) ** 2))
         for k in lags]
    return np.polyfit(np.log(lags), np.log(g), 1)[0] / 2


def finest_octave_slope(z):
    n = min(z.shape)
    z = z[:n, :n] - z[:n, :n].mean()
    w = np.hanning(n)
    p = np.abs(np.fft.fft2(z * np.outer(w, w))) ** 2
    f = np.hypot(*np.meshgrid(np.fft.fftfreq(n), np.fft.fftfreq(n), indexing="ij"))
    m = (f >= 0.25) & (f <= 0.5)
    return np.polyfit(np.log(f[m]), np.log(p[m]), 1)[0]


def best(fn, k=3):
    t = []
    for _ in range(k):
        t0 = time.perf_counter()
        fn()
        t.append(time.perf_counter() - t0)
    return min(t)


def best_cpu(fn, k=3):
    """Best of ``k`` CPU times (``time.process_time``: every thread)."""
    t = []
    for _ in range(k):
        t0 = time.process_time()
        fn()
        t.append(time.process_time() - t0)
    return min(t)


def speed(n):
    z = fg.fbm_surface(n, 0.7, method="exact", seed=1)
    print(f"load average {os.getloadavg()[0]:.1f}, {len(os.sched_getaffinity(0))} cores usable")
    t_ours = best(lambda: fg.fractal_resample(z, 2, hurst=0.7, sigma=1.0, seed=2))
    t_zoom = best(lambda: ndimage.zoom(z, 2, order=3))
    c_ours = best_cpu(lambda: fg.fractal_resample(z, 2, hurst=0.7, sigma=1.0, seed=2))
    c_zoom = best_cpu(lambda: ndimage.zoom(z, 2, order=3))
    print(f"speed {n}^2 -> {2 * n - 1}^2 (factor 2): fractal_resample {t_ours:.3f} s "
          f"({c_ours:.3f} CPU-s), zoom(order=3) {t_zoom:.3f} s ({c_zoom:.3f} CPU-s), "
          f"ratio {t_zoom / t_ours:.2f}x wall, {c_zoom / c_ours:.2f}x CPU")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for model in ("smooth", "fbm"):
            t_def = best(lambda: fg.fractal_resample(z, 2, seed=2, model=model))
            c_def = best_cpu(lambda: fg.fractal_resample(z, 2, seed=2, model=model))
            print(f"  with the local analysis (model={model!r}): {t_def:.3f} s ({c_def:.3f} CPU-s), "
                  f"ratio {t_zoom / t_def:.2f}x wall, {c_zoom / c_def:.2f}x CPU")
    print(f"load average {os.getloadavg()[0]:.1f}")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for support in ("point", "area"):
            t_an = best(lambda: fg.dem.resample_analysis(z, support=support))
            t_ref = best(lambda: numpy_analysis(z, 16, support), k=1)
            print(f"local analysis {n}^2 (window 33, support={support}): resample_analysis "
                  f"{t_an:.3f} s, numpy reference {t_ref:.3f} s, ratio {t_ref / t_an:.1f}x")


def numpy_analysis(z, half, support):
    """The numpy twin of the analysis kernel (padding included)."""
    t = R._pad_width(half)
    return R._analyse_padded_reference(np.pad(z, t, constant_values=np.nan), half, support)


def stats(n):
    print(f"stats on exact fBm {n}^2 (hurst='local', model='fbm'); columns: lag1 ratio, H(1-8) "
          "(truth), slope finest octave (truth), crease; zoom order 3 lag1 ratio, H, slope; "
          "slope with the true H and sigma fixed")
    for h in (0.3, 0.5, 0.7, 0.9):
        t = fg.fbm_surface(n, h, method="exact", seed=5)
        ht, st = hurst_lags(t), finest_octave_slope(t)
        for support in ("point", "area"):
            for f in (2, 4):
                if support == "point":
                    c = t[::f, ::f]
                    truth = t[: f * (c.shape[0] - 1) + 1, : f * (c.shape[1] - 1) + 1]
                else:
                    m = n // f * f
                    c = t[:m, :m].reshape(m // f, f, m // f, f).mean((1, 3))
                    truth = t[:m, :m]
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    o = fg.fractal_resample(c, f, seed=1, support=support, model="fbm")
                # sigma: sd of the truth's point increments at one input cell (f cells).
                s_true = np.sqrt(0.5 * (np.mean((t[f:] - t[:-f]) ** 2)
                                        + np.mean((t[:, f:] - t[:, :-f]) ** 2)))
                o_fix = fg.fractal_resample(c, f, hurst=h, sigma=s_true, seed=1, support=support)
                b = R._bicubic_aligned(c, f, support)
                cr = fg.validate_surface(o, coastline=False).crease_ratio
                print(f"H={h} {support:5s} x{f}: {lag1(o) / lag1(truth):.3f}  "
                      f"{hurst_lags(o):.3f} ({ht:.3f})  {finest_octave_slope(o):.2f} ({st:.2f})  "
                      f"{cr:.3f} | zoom {lag1(b) / lag1(truth):.3f}  {hurst_lags(b):.3f}  "
                      f"{finest_octave_slope(b):.2f} | fixed {finest_octave_slope(o_fix):.2f}")


def dask_run(n_out):
    import dask.array as da

    n_in = n_out // 2
    z = da.random.default_rng(1).standard_normal((n_in, n_in), chunks=2048).cumsum(0).cumsum(1)
    out = fg.fractal_resample(z, 2, hurst=0.7, sigma=1.0, seed=1)
    t0 = time.perf_counter()
    s = out.sum().compute()
    dt = time.perf_counter() - t0
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2**20
    print(f"dask {n_in}^2 -> {out.shape[0]}^2 (chunks 2048): {dt:.1f} s, peak RSS {rss:.2f} GiB "
          f"(sum {s:.3g})")


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("--size", type=int, default=4096)
    ap.add_argument("--stats", type=int, default=2048)
    ap.add_argument("--dask", type=int, default=16384)
    a = ap.parse_args()
    print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores")
    if a.size:
        speed(a.size)
    if a.stats:
        stats(a.stats)
    if a.dask:
        dask_run(a.dask)
