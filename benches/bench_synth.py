"""Benchmark of synthesis, hillshade and lakes against the baselines a user has.

Run: ``python benches/bench_synth.py [--size 4096] [--n1d 1048576] [--repeat 3]``

Every pair is timed in the same run (best of ``--repeat``), and the table
prints ``ratio = baseline / ours`` (above 1: ours is faster). Baselines:

* 2D spectral: plain numpy (``np.random`` white noise, ``np.fft.rfft2``,
  ``|f|^-beta/2`` filter, ``np.fft.irfft2``), the figure-3 algorithm; ours
  computes the aliased fBm filter (Rust) on the first call, then caches it;
* 2D midpoint/additions: a vectorised numpy diamond-square (below); for
  additions it is the classic Peitgen & Saupe form (bilinear means), which
  does less work than our crease-free 4-point scheme;
* 2D exact: no common baseline (numpy Cholesky is O(n^6)); timed alone, at
  ``--exact-size`` (default 2048: the embedding torus is about 2.4x the
  side for H <= 0.75, so 4096^2 needs a 10000^2 complex FFT);
* 1D: the ``stochastic`` package (Davies-Harte, numpy FFTs) when installed,
  and numpy spectral synthesis; our exact method runs eigenvalues, noise,
  real FFT and cumulative sum in Rust (``realfft``), the eigenvalues cached
  per length and H as in repeated use;
* hillshade: ``gdaldem hillshade`` (subprocess on a float32 GeoTIFF: its
  time includes reading and writing the files) and a numpy Horn hillshade;
* lake mask: numpy ``z < level`` plus ``scipy.ndimage.label``.

The DEM of the hillshade and lake benchmarks is a synthetic fBm surface
(H = 0.7, 30 m cells, 300 m relief), not a real DEM: the real DEMs in
``../shared/data`` are at most 1201 x 1201.

The machine may be shared with other processes: the figures are
indicative, the ratios (measured in the same run) are the robust part.
"""
from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time

import numpy as np
from _timing import best

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "tests"))
try:
    import fractalgeo_rs as fg
except ImportError:  # the lead's modules not merged yet on this branch
    from _synth_support import fg  # noqa: E402


def numpy_spectral(n, h, rng):
    w = rng.standard_normal((n, n))
    f = np.hypot(np.fft.fftfreq(n)[:, None], np.fft.rfftfreq(n)[None, :])
    f[0, 0] = 1.0
    amp = f ** (-(2 * h + 2) / 2)
    amp[0, 0] = 0.0
    return np.fft.irfft2(np.fft.rfft2(w) * amp, s=(n, n))


def numpy_diamond_square(n, h, rng, additions=False):
    """Vectorised diamond-square (Peitgen & Saupe MidPointFM2D), size 2^k + 1."""
    k = int(np.ceil(np.log2(n - 1)))
    size = 2**k + 1
    z = np.zeros((size, size))
    z[:: size - 1, :: size - 1] = rng.standard_normal((2, 2))
    delta = 1.0
    step = size - 1
    while step > 1:
        half = step // 2
        delta *= 0.5 ** (0.5 * h)
        c = z[0:-1:step, 0:-1:step] + z[step::step, 0:-1:step] + z[0:-1:step, step::step] + z[step::step, step::step]
        z[half::step, half::step] = c / 4 + delta * rng.standard_normal(c.shape)
        if additions:
            z[::half, ::half] += delta * rng.standard_normal(z[::half, ::half].shape)
        delta *= 0.5 ** (0.5 * h)
        p = np.pad(z, half, mode="constant", constant_values=np.nan)
        for r0, c0 in ((0, half), (half, 0)):
            sl = (slice(half + r0, half + size, step), slice(half + c0, half + size, step))
            nb = np.stack([p[sl[0].start - half:sl[0].stop - half:step, sl[1]],
                           p[sl[0].start + half:sl[0].stop + half:step, sl[1]],
                           p[sl[0], sl[1].start - half:sl[1].stop - half:step],
                           p[sl[0], sl[1].start + half:sl[1].stop + half:step]])
            m = np.nanmean(nb, axis=0)
            z[r0::step, c0::step] = m + delta * rng.standard_normal(m.shape)
        if additions:
            z[::half, ::half] += delta * rng.standard_normal(z[::half, ::half].shape)
        step = half
    return z[:n, :n]


def numpy_hillshade(z, cell, az=315.0, alt=45.0):
    p = np.pad(z, 1, mode="edge")
    a, b, c = p[:-2, :-2], p[:-2, 1:-1], p[:-2, 2:]
    d, f = p[1:-1, :-2], p[1:-1, 2:]
    g, hh, i = p[2:, :-2], p[2:, 1:-1], p[2:, 2:]
    gx = ((c + 2 * f + i) - (a + 2 * d + g)) / (8 * cell)
    gy = ((a + 2 * b + c) - (g + 2 * hh + i)) / (8 * cell)
    A, E = np.radians(az), np.radians(alt)
    s = (np.sin(E) - np.cos(E) * (np.sin(A) * gx + np.cos(A) * gy)) / np.sqrt(1 + gx * gx + gy * gy)
    return np.clip(s, 0, 1)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--size", type=int, default=4096)
    ap.add_argument("--exact-size", type=int, default=2048)
    ap.add_argument("--n1d", type=int, default=2**20)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--hurst", type=float, default=0.7)
    args = ap.parse_args()
    n, h, rep = args.size, args.hurst, args.repeat
    rng = np.random.default_rng(0)
    rows = []

    def row(name, ours, base=None, base_name=""):
        ratio = f"{base / ours:6.2f}" if base else "     -"
        bt = f"{base:8.3f}" if base else "       -"
        rows.append(f"{name:34s} {ours:8.3f} {bt} {ratio}  {base_name}")
        print(rows[-1], flush=True)

    print(f"threads: {os.cpu_count()} cores, fractalgeo_rs {fg.__version__}, "
          f"load average {os.getloadavg()[0]:.1f}")
    print(f"{'task':34s} {'ours s':>8s} {'base s':>8s} {'ratio':>6s}  baseline")
    # 2D
    from fractalgeo_rs.synth import _fbm

    _fbm._spectral_amplitude.cache_clear()
    t0 = time.perf_counter()
    fg.fbm_surface(n, h, method="spectral", seed=1, periodic=True)
    cold = time.perf_counter() - t0
    warm = best(lambda: fg.fbm_surface(n, h, method="spectral", seed=1, periodic=True), rep)
    base = best(lambda: numpy_spectral(n, h, rng), rep)
    row(f"2D spectral {n}^2 periodic (first)", cold, base, "numpy rfft2/irfft2")
    row(f"2D spectral {n}^2 periodic (again)", warm, base, "numpy rfft2/irfft2")
    row(f"2D spectral {n}^2 non-periodic", best(lambda: fg.fbm_surface(n, h, method="spectral", seed=1), rep))
    for m in ("midpoint", "additions"):
        ours = best(lambda: fg.fbm_surface(n, h, method=m, seed=1), rep)
        base = best(lambda: numpy_diamond_square(n, h, rng, additions=(m == "additions")), max(1, rep - 1))
        row(f"2D {m} {n}^2", ours, base, "numpy diamond-square")
    ne = args.exact_size
    row(f"2D exact {ne}^2 (H={h})", best(lambda: fg.fbm_surface(ne, h, method="exact", seed=1), 1))
    # 1D
    try:
        from stochastic.processes.continuous import FractionalBrownianMotion

        st = FractionalBrownianMotion(hurst=h, t=1.0)
        sbase = best(lambda: st.sample(args.n1d - 1), rep)
        sname = "stochastic FBM (Davies-Harte)"
    except ImportError:
        sbase, sname = None, "stochastic not installed"

    def np1d():
        w = rng.standard_normal(args.n1d)
        f = np.fft.rfftfreq(args.n1d)
        f[0] = 1
        a = f ** (-(2 * h + 1) / 2)
        a[0] = 0
        return np.fft.irfft(np.fft.rfft(w) * a, args.n1d)

    nbase = best(np1d, rep)
    for m in ("exact", "midpoint", "additions", "spectral"):
        ours = best(lambda: fg.fbm(args.n1d, h, method=m, seed=1), rep)
        if m == "exact":
            row(f"1D {m} {args.n1d}", ours, sbase, sname)
        elif m == "spectral":
            row(f"1D {m} {args.n1d}", ours, nbase, "numpy rfft/irfft")
        else:
            row(f"1D {m} {args.n1d}", ours, sbase, sname)
    # hillshade and lakes
    dem = fg.synthetic_dem((n, n), h, cell_size=30.0, relief=300.0, method="midpoint", seed=2,
                           mean_elevation=1000.0)
    ours = best(lambda: fg.hillshade(dem, cell_size=30.0), rep)
    row(f"hillshade {n}^2", ours, best(lambda: numpy_hillshade(dem, 30.0), rep), "numpy Horn")
    if shutil.which("gdaldem"):
        import rasterio
        from rasterio.transform import from_origin

        with tempfile.TemporaryDirectory() as d:
            src = os.path.join(d, "dem.tif")
            with rasterio.open(src, "w", driver="GTiff", width=n, height=n, count=1, dtype="float32",
                               crs="EPSG:32611", transform=from_origin(0, 0, 30, 30)) as ds:
                ds.write(dem.astype(np.float32), 1)
            out = os.path.join(d, "s.tif")
            g = best(lambda: subprocess.run(["gdaldem", "hillshade", "-q", src, out], check=True), rep)
            row(f"hillshade {n}^2 byte=True", best(lambda: fg.hillshade(dem, cell_size=30.0, byte=True), rep),
                g, "gdaldem hillshade (incl. file I/O)")
            with rasterio.open(out) as ds:
                ref = ds.read(1).astype(float)[1:-1, 1:-1]
            mine = fg.hillshade(dem, cell_size=30.0, byte=True).astype(float)[1:-1, 1:-1]
            print(f"  gdaldem agreement: max |diff| = {np.abs(ref - mine).max():.0f} grey levels, "
                  f"corr = {np.corrcoef(ref.ravel(), mine.ravel())[0, 1]:.6f}")
    else:
        print("  gdaldem not installed: no GDAL comparison")
    lvl = float(np.median(dem))
    from scipy import ndimage

    row(f"lake mask {n}^2", best(lambda: fg.lakes(dem, lvl, coastlines=False), rep),
        best(lambda: ndimage.label(dem < lvl), rep), "numpy < + ndimage.label")


if __name__ == "__main__":
    main()
