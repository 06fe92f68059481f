"""Benchmark: fractal transform (moving-window local dimension), ours against
plain numpy, in the same run.

Scene: the bundled Sentinel-1 VV scene (512 x 512, dB) mirrored into a
4096 x 4096 float32 mosaic. Baselines, both for the variogram method
(first differences, lags 1 and 2, p = 2):

- numpy windows: ``sliding_window_view`` over the increment-power images,
  window sums per row (what a user writes first; cost grows with w^2). Too
  slow for the whole scene: timed on 16 rows and extrapolated (printed so).
- numpy SAT: the same summed-area-table algorithm as ours, vectorised in
  numpy over the whole image (the best plain-numpy version we could write).

The P(m, L) mass map (the default method, window 33) against numpy
versions that compute the per-pixel masses by shifted comparisons (the
masses alone, timed on 512 rows and extrapolated), then the window means
either with ``sliding_window_view`` per row (timed on 16 rows and
extrapolated) or with summed-area tables (our algorithm in numpy, the whole
scene; checked against ours on a 512² crop first).

DBC and covering-blanket maps (window 33, default options, 1 dB per pixel)
against the best plain-numpy versions we could write: for each output row,
``view_as_windows`` of the row's band gives all of its windows at once; DBC
reduces blocks by reshape (nanmin/nanmax), the blanket grows all windows of
the row together (shifted maxima on a (cols, w + 2, w + 2) stack). Both are
timed on a few rows and extrapolated (printed so), after checking that they
give our values on those rows. The blanket map itself costs O(w^2 e_max) per
pixel: ours is timed on a strip of rows of the scene and extrapolated too.

The debiased Whittle map (``--methods whittle``) is timed against the loop a
user would write with our own estimator, ``fractalgeo_rs.whittle`` on every
window (timed on 40 windows and extrapolated), at step 1 (ours timed on 256
rows and extrapolated) and step 4.

Run: ``python benches/bench_transform.py [--size 4096] [--methods dbc,blanket,whittle]``.
"""
from __future__ import annotations

import argparse
import os
import platform
import time
import warnings

import numpy as np

import fractalgeo_rs as fg
from _timing import best


def mosaic(n: int) -> np.ndarray:
    vv, _ = fg.data.sentinel1_vv_db()
    t = np.concatenate([vv, vv[::-1]], axis=0)
    t = np.concatenate([t, t[:, ::-1]], axis=1)
    reps = -(-n // t.shape[0])
    return np.ascontiguousarray(np.tile(t, (reps, reps))[:n, :n], dtype=np.float32)


def _pow_images(z, u):
    ph = np.zeros_like(z)
    pv = np.zeros_like(z)
    ph[:, :-u] = (z[:, u:] - z[:, :-u]) ** 2
    pv[:-u, :] = (z[u:, :] - z[:-u, :]) ** 2
    return ph, pv


def numpy_sat(z: np.ndarray, w: int) -> np.ndarray:
    """Variogram map with summed-area tables in numpy (no NaN handling needed
    for this scene; windows clipped at the edges like ours)."""
    z = z.astype(np.float64)
    r, c = z.shape
    h = w // 2
    i = np.arange(r)
    j = np.arange(c)
    r0, r1 = np.clip(i - h, 0, r), np.clip(i + h + 1, 0, r)
    c0, c1 = np.clip(j - h, 0, c), np.clip(j + h + 1, 0, c)
    logs = []
    for u in (1, 2):
        ph, pv = _pow_images(z, u)
        tot = 0.0
        cnt = 0.0
        for img, (du_r, du_c) in ((ph, (0, u)), (pv, (u, 0))):
            s = np.zeros((r + 1, c + 1))
            s[1:, 1:] = img.cumsum(0).cumsum(1)
            rr1 = np.maximum(r1 - du_r, r0)
            cc1 = np.maximum(c1 - du_c, c0)
            tot = tot + s[rr1][:, cc1] - s[r0][:, cc1] - s[rr1][:, c0] + s[r0][:, c0]
            cnt = cnt + np.outer(rr1 - r0, cc1 - c0)
        logs.append(np.log(tot / cnt / 2))
    return 3.0 - (logs[1] - logs[0]) / np.log(2) / 2


def numpy_windows_rows(z: np.ndarray, w: int, rows: int) -> float:
    """Seconds for ``rows`` output rows with sliding_window_view sums."""
    z = z.astype(np.float64)
    h = w // 2
    zp = np.pad(z, h, constant_values=np.nan)
    t0 = time.perf_counter()
    for i in range(rows):
        band = zp[i : i + w + 2]
        v = []
        for u in (1, 2):
            dh = (band[:w, u:] - band[:w, :-u]) ** 2
            dv = (band[u:w, :] - band[: w - u, :]) ** 2
            sh = np.nansum(np.lib.stride_tricks.sliding_window_view(dh, (w, w - u)), axis=(-2, -1))
            sv = np.nansum(np.lib.stride_tricks.sliding_window_view(dv, (w - u, w)), axis=(-2, -1))
            v.append(sh[0, : z.shape[1]] + sv[0, : z.shape[1]])
    return time.perf_counter() - t0


def numpy_mass_inv(z: np.ndarray, sizes=(3, 5, 7, 9), z_scale=1.0):
    """1 / m_p(L) per pixel with vectorised shifted comparisons (numpy)."""
    z = z.astype(np.float64)
    r, c = z.shape
    kmax = max(sizes) // 2
    zp = np.pad(z, kmax, constant_values=np.nan)
    m = {L: np.zeros_like(z) for L in sizes}
    for di in range(-kmax, kmax + 1):
        for dj in range(-kmax, kmax + 1):
            zq = zp[kmax + di: kmax + di + r, kmax + dj: kmax + dj + c]
            d = np.abs(zq - z)
            for L in sizes:
                k = L // 2
                if max(abs(di), abs(dj)) <= k:
                    m[L] += d <= (k + 0.5) * z_scale
    return [1.0 / m[L] for L in sizes]


def numpy_mass_sat(z: np.ndarray, w: int, sizes=(3, 5, 7, 9), z_scale=1.0) -> np.ndarray:
    """Mass map with our algorithm in numpy: per-pixel masses by shifted
    comparisons, window means from summed-area tables (windows clipped at the
    edges like ours; no NaN in this scene)."""
    inv = numpy_mass_inv(z, sizes, z_scale)
    r, c = z.shape
    h = w // 2
    i, j = np.arange(r), np.arange(c)
    r0, r1 = np.clip(i - h, 0, r), np.clip(i + h + 1, 0, r)
    c0, c1 = np.clip(j - h, 0, c), np.clip(j + h + 1, 0, c)
    n = np.outer(r1 - r0, c1 - c0)
    x = np.log(sizes)
    wts = (x - x.mean()) / ((x - x.mean()) ** 2).sum()
    slope = np.zeros(z.shape)
    for a, wt in zip(inv, wts):
        s = np.zeros((r + 1, c + 1))
        s[1:, 1:] = a.cumsum(0).cumsum(1)
        tot = s[r1][:, c1] - s[r0][:, c1] - s[r1][:, c0] + s[r0][:, c0]
        slope += wt * np.log(tot / n)
    return -slope


def numpy_mass_windows_rows(z: np.ndarray, w: int, rows: int) -> float:
    """Seconds for ``rows`` output rows: per-pixel masses (vectorised) for the
    rows' neighbourhood, then window means with sliding_window_view."""
    h = w // 2
    t0 = time.perf_counter()
    band = z[: rows + w + 8]
    inv = numpy_mass_inv(band)
    x = np.log([3, 5, 7, 9])
    for i in range(h, h + rows):
        y = []
        for a in inv:
            win = np.lib.stride_tricks.sliding_window_view(a[i - h: i + h + 1], (w, w))
            y.append(np.log(win.mean(axis=(-2, -1))[0]))
        y = np.array(y)
        _slope = ((x - x.mean())[:, None] * (y - y.mean(axis=0))).sum(0) / ((x - x.mean()) ** 2).sum()
    return time.perf_counter() - t0


def numpy_dbc_rows(z: np.ndarray, w: int, rows, sizes=(2, 4, 8, 16), z_unit=1.0) -> np.ndarray:
    """DBC map rows (partial blocks dropped, z0 = 0) vectorised over the
    windows of each row (view_as_windows)."""
    try:
        from skimage.util import view_as_windows
    except ImportError:  # the same view
        from numpy.lib.stride_tricks import sliding_window_view as view_as_windows

    h = w // 2
    zp = np.pad(z.astype(np.float64), h, constant_values=np.nan)
    x = np.log(np.asarray(sizes, dtype=float))
    out = []
    for i in rows:
        win = view_as_windows(zp[i:i + w], (w, w))[0]  # (cols, w, w)
        y = []
        for s in sizes:
            nf = w // s
            blk = win[:, :nf * s, :nf * s].reshape(-1, nf, s, nf, s)
            with warnings.catch_warnings():  # all-NaN blocks outside the image
                warnings.simplefilter("ignore", RuntimeWarning)
                hi = np.nanmax(blk, axis=(2, 4))
                lo = np.nanmin(blk, axis=(2, 4))
            n = np.floor(hi / (s * z_unit)) - np.floor(lo / (s * z_unit)) + 1
            y.append(np.log(np.nansum(n, axis=(1, 2))))
        y = np.array(y)
        out.append(-((x - x.mean())[:, None] * (y - y.mean(0))).sum(0) / ((x - x.mean()) ** 2).sum())
    return np.array(out)


def numpy_blanket_rows(z: np.ndarray, w: int, rows, eps=(1, 2, 3, 4)) -> np.ndarray:
    """Blanket map rows: the blankets of all windows of a row grown together
    (missing samples and the window frame are -inf / +inf)."""
    try:
        from skimage.util import view_as_windows
    except ImportError:  # the same view
        from numpy.lib.stride_tricks import sliding_window_view as view_as_windows

    h = w // 2
    zp = np.pad(z.astype(np.float64), h, constant_values=np.nan)
    x = np.log(np.asarray(eps, dtype=float))
    out = []
    for i in rows:
        win = view_as_windows(zp[i:i + w], (w, w))[0]
        ok = np.pad(~np.isnan(win), ((0, 0), (1, 1), (1, 1)))
        u = np.pad(np.where(np.isnan(win), -np.inf, win), ((0, 0), (1, 1), (1, 1)), constant_values=-np.inf)
        b = np.pad(np.where(np.isnan(win), np.inf, win), ((0, 0), (1, 1), (1, 1)), constant_values=np.inf)
        areas = []
        for e in range(1, max(eps) + 1):
            nu = u + 1
            nb = b - 1
            for sl in ((slice(None), slice(0, -2), slice(1, -1)), (slice(None), slice(2, None), slice(1, -1)),
                       (slice(None), slice(1, -1), slice(0, -2)), (slice(None), slice(1, -1), slice(2, None))):
                np.maximum(nu[:, 1:-1, 1:-1], u[sl], out=nu[:, 1:-1, 1:-1])
                np.minimum(nb[:, 1:-1, 1:-1], b[sl], out=nb[:, 1:-1, 1:-1])
            u = np.where(ok, nu, -np.inf)
            b = np.where(ok, nb, np.inf)
            if e in eps:
                areas.append(np.where(ok, u - b, 0.0).sum(axis=(1, 2)) / (2 * e))
        y = np.log(np.array(areas))
        out.append(2.0 - ((x - x.mean())[:, None] * (y - y.mean(0))).sum(0) / ((x - x.mean()) ** 2).sum())
    return np.array(out)


def time_rows(fn, z, w, rows):
    t0 = time.perf_counter()
    fn(z, w, rows)
    return time.perf_counter() - t0


def new_methods(z: np.ndarray) -> None:
    """DBC and blanket maps: ours against numpy, and window 17 vs 65."""
    n = z.shape[0]
    # numpy versions agree with ours on sample rows (edge and interior)
    for m, fn in (("dbc", numpy_dbc_rows), ("blanket", numpy_blanket_rows)):
        sub = z[:64, :256]
        ours = fg.fractal_transform(sub, 33, method=m, min_valid=0.0)
        rows = [0, 20, 40]
        assert np.allclose(fn(sub, 33, rows), ours[rows], atol=1e-4, equal_nan=True), f"numpy {m} disagrees"
    t = {}
    for w in (17, 33, 65):
        t[("dbc", w)] = best(lambda: fg.fractal_transform(z, w, method="dbc"), 2)
        print(f"ours dbc        w={w:2d}: {t[('dbc', w)]:.3f} s", flush=True)
    for w in (9, 65):
        t[("dbc248", w)] = best(lambda: fg.fractal_transform(z, w, method="dbc", box_sizes=(2, 4, 8)), 2)
        print(f"ours dbc, sizes 2, 4, 8 only, w={w:2d}: {t[('dbc248', w)]:.3f} s", flush=True)
    for w, strip in ((17, 512), (33, 256), (65, 128)):
        ts = best(lambda: fg.fractal_transform(z[:strip], w, method="blanket"), 1)
        t[("blanket", w)] = ts * n / strip
        print(f"ours blanket    w={w:2d}: {t[('blanket', w)]:.1f} s extrapolated from {strip} rows "
              f"({ts:.2f} s)", flush=True)
    nrows = 8
    t_dbc = time_rows(numpy_dbc_rows, z, 33, range(100, 100 + nrows)) * n / nrows
    print(f"numpy DBC (view_as_windows, per row), w=33: {t_dbc:.1f} s extrapolated from {nrows} rows "
          f"({t_dbc / t[('dbc', 33)]:.0f} x ours)")
    nrows = 4
    t_bl = time_rows(numpy_blanket_rows, z, 33, range(100, 100 + nrows)) * n / nrows
    print(f"numpy blanket (view_as_windows, per row), w=33: {t_bl:.1f} s extrapolated from {nrows} rows "
          f"({t_bl / t[('blanket', 33)]:.1f} x ours)")
    print(f"window 65 / window 17 time (dbc):       {t[('dbc', 65)] / t[('dbc', 17)]:.2f}")
    print(f"window 65 / window 9 time (dbc, sizes 2, 4, 8 at both): {t[('dbc248', 65)] / t[('dbc248', 9)]:.2f}")
    print(f"window 65 / window 17 time (blanket):   {t[('blanket', 65)] / t[('blanket', 17)]:.2f}")


def whittle_maps(z: np.ndarray) -> None:
    """Debiased Whittle map against the loop a user writes: fractalgeo_rs.whittle
    (square filter) on every window, timed on a sample of windows."""
    n = z.shape[0]
    zz = z.astype(np.float64)
    for w in (17, 33, 65):
        strip = 256
        ts = best(lambda: fg.fractal_transform(zz[:strip], w, method="whittle"), 1)
        t1 = ts * n / strip
        t4 = best(lambda: fg.fractal_transform(zz, w, method="whittle", step=4), 1)
        h = w // 2
        rng = np.random.default_rng(0)
        pos = rng.integers(h, n - h, size=(40, 2))
        t0 = time.perf_counter()
        for i, j in pos:
            fg.whittle(zz[i - h:i + h + 1, j - h:j + h + 1], filter="square")
        per = (time.perf_counter() - t0) / len(pos)
        print(f"ours whittle    w={w:2d}: step 1 {t1:.1f} s extrapolated from {strip} rows ({ts:.2f} s); "
              f"step 4 {t4:.2f} s; loop of fg.whittle per window {per * 1e3:.2f} ms -> step 1 {per * n * n:.0f} s "
              f"({per * n * n / t1:.0f} x ours), step 4 {per * n * n / 16:.0f} s ({per * n * n / 16 / t4:.0f} x ours)",
              flush=True)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--size", type=int, default=4096)
    ap.add_argument("--methods", default="increments,mass,dbc,blanket",
                    help="comma-separated groups: increments and mass (the first four maps), dbc,blanket, "
                         "whittle (not in the default: slow)")
    args = ap.parse_args()
    n = args.size
    z = mosaic(n)
    print(f"machine: {platform.machine()}, {os.cpu_count()} cores; scene {n} x {n} float32 "
          "(Sentinel-1 VV dB, mirrored tiles)")
    groups = set(args.methods.split(","))
    if groups & {"dbc", "blanket"}:
        new_methods(z)
    if "whittle" in groups:
        whittle_maps(z)
    if not groups & {"increments", "mass"}:
        return
    ref = fg.fractal_transform(z[:512, :512], 33, method="variogram", min_valid=0.0)
    assert np.allclose(ref, numpy_sat(z[:512, :512], 33), atol=1e-4, equal_nan=True), "numpy SAT disagrees"
    times = {}
    for w in (17, 33, 65):
        for m in ("mass", "variogram", "madogram", "square"):
            times[(m, w)] = best(lambda: fg.fractal_transform(z, w, method=m))
            print(f"ours {m:10s} w={w:2d}: {times[(m, w)]:.3f} s")
    t_sat = best(lambda: numpy_sat(z, 33), 1)
    rows = 16
    t_rows = numpy_windows_rows(z, 33, rows)
    t_win = t_rows * n / rows
    ours = times[("variogram", 33)]
    print(f"numpy SAT, variogram w=33:            {t_sat:.3f} s   ({t_sat / ours:.1f} x ours)")
    print(f"numpy windows, variogram w=33:        {t_win:.1f} s extrapolated from {rows} rows "
          f"({t_win / ours:.0f} x ours)")
    print(f"window 65 / window 17 time (variogram): {times[('variogram', 65)] / times[('variogram', 17)]:.2f}")
    print(f"window 65 / window 17 time (mass):      {times[('mass', 65)] / times[('mass', 17)]:.2f}")
    crop = z[:512, :512]
    ref = fg.fractal_transform(crop, 33, method="mass", min_valid=0.0)
    assert np.allclose(ref, numpy_mass_sat(crop, 33), atol=1e-4), "numpy mass SAT disagrees"
    t_msat = best(lambda: numpy_mass_sat(z, 33), 1)
    t_inv = best(lambda: numpy_mass_inv(z[:512]), 1) * n / 512
    t_mrows = numpy_mass_windows_rows(z, 33, rows) * n / rows
    om = times[("mass", 33)]
    print(f"numpy mass, per-pixel masses alone:   {t_inv:.1f} s extrapolated from 512 rows ({t_inv / om:.1f} x ours)")
    print(f"numpy mass, masses + window means:    {t_mrows:.1f} s extrapolated from {rows} rows ({t_mrows / om:.0f} x ours)")
    print(f"numpy mass, masses + SAT window sums: {t_msat:.1f} s ({t_msat / om:.1f} x ours)")


if __name__ == "__main__":
    main()
