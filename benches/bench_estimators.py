"""Benchmark: every dimension estimator on a 2048 x 2048 surface (profile
estimators on a 2048² = 4,194,304-sample profile), against the fastest
Python alternative we know, in the same run.

Alternatives (named in the output): for the Rust kernels, numpy versions
written here from the same definitions (counts asserted equal first):
box counting (strided-OR pyramid), DBC (block min/max by reshape), self-affine
boxes (column ranges by reshape), grayscale P(m, L) (shifted
comparisons) and the covering blanket (the previous scipy.ndimage version:
``grey_dilation``/``grey_erosion`` with the cross footprint, 16 steps). The
increment, spectral, wavelet, Higuchi, scale-space, Minkowski and lacunarity
estimators are themselves numpy/scipy code: their row shows our time only.

Surface: exact fBm (H = 0.5), seed 0. Run: ``python benches/bench_estimators.py``.
"""
from __future__ import annotations

import os
import platform
import time

import numpy as np

import fractalgeo_rs as fg


def best(fn, repeat=3):
    out = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        r = fn()
        out.append(time.perf_counter() - t0)
    return min(out), r


def np_box(mask, levels):
    counts, a = [], mask
    for _ in range(levels):
        counts.append(int(np.count_nonzero(a)))
        a = a[0::2, 0::2] | a[1::2, 0::2] | a[0::2, 1::2] | a[1::2, 1::2]
    return counts


def np_dbc(z, sizes, z0, zu):
    n = []
    for s in sizes:
        r, c = z.shape[0] // s, z.shape[1] // s
        b = z[: r * s, : c * s].reshape(r, s, c, s)
        lo, hi = b.min(axis=(1, 3)), b.max(axis=(1, 3))
        h = s * zu
        n.append(float(np.sum(np.floor((hi - z0) / h) - np.floor((lo - z0) / h) + 1)))
    return n


def np_affine(z, sizes):
    out = []
    for s in sizes:
        m = (z.shape[1] - 1) // s
        cols = np.lib.stride_tricks.sliding_window_view(z, s + 1, axis=1)[:, ::s][:, :m]
        # rows too: (s+1) x (s+1) squares
        sq = np.lib.stride_tricks.sliding_window_view(cols.max(axis=2), s + 1, axis=0)[::s].max(axis=-1)
        sq_lo = np.lib.stride_tricks.sliding_window_view(cols.min(axis=2), s + 1, axis=0)[::s].min(axis=-1)
        k = (z.shape[0] - 1) // s
        out.append(float(np.mean((sq - sq_lo)[:k])))
    return out


def np_mass(z, sizes, zs):
    r, c = z.shape
    kmax = max(sizes) // 2
    zp = np.pad(z, kmax, constant_values=np.nan)
    m = {L: np.zeros(z.shape) for L in sizes}
    for di in range(-kmax, kmax + 1):
        for dj in range(-kmax, kmax + 1):
            d = np.abs(zp[kmax + di: kmax + di + r, kmax + dj: kmax + dj + c] - z)
            for L in sizes:
                if max(abs(di), abs(dj)) <= L // 2:
                    m[L] += d <= (L // 2 + 0.5) * zs
    return [float(np.mean(1.0 / m[L])) for L in sizes]


def scipy_blanket(z, eps_max=16):
    """Peleg blanket areas with scipy.ndimage (the estimator before the Rust kernel)."""
    from scipy.ndimage import grey_dilation, grey_erosion

    cross = np.array([[0, 1, 0], [1, 1, 1], [0, 1, 0]], dtype=bool)
    u = z.copy()
    b = z.copy()
    out = []
    for e in range(1, eps_max + 1):
        u = np.maximum(u + 1, grey_dilation(u, footprint=cross, mode="nearest"))
        b = np.minimum(b - 1, grey_erosion(b, footprint=cross, mode="nearest"))
        out.append(float(np.sum(u - b)) / (2.0 * e))
    return out


def main() -> None:
    n = 2048
    print(f"machine: {platform.machine()}, {os.cpu_count()} cores; numpy {np.__version__}")
    z = fg.fbm_surface((n, n), 0.5, method="exact", seed=0)
    mask = z > np.median(z)
    prof = fg.fbm(n * n, 0.5, method="exact", seed=0)
    edge = mask & ~(np.roll(mask, 1, 0) & np.roll(mask, -1, 0) & np.roll(mask, 1, 1) & np.roll(mask, -1, 1))
    rows = []

    sizes = [2**k for k in range(10)]
    t, fit = best(lambda: fg.box_counting(mask, box_sizes=sizes, anchor="array"))
    tb, counts = best(lambda: np_box(mask, 10))
    assert fit.measures.astype(int).tolist() == counts
    rows.append(("box counting (binary)", t, "numpy strided-OR pyramid", tb))

    dsz = [2, 4, 8, 16, 32, 64, 128, 256]
    z0 = float(z.min())
    zu = float((z.max() - z0) / n)
    t, fit = best(lambda: fg.differential_box_counting(z, box_sizes=dsz))
    tb, ref = best(lambda: np_dbc(z, dsz, z0, zu))
    assert np.allclose(fit.measures, ref)
    rows.append(("differential box counting", t, "numpy reshape min/max", tb))

    asz = [1, 2, 4, 8, 16, 32, 64, 128]
    t, fit = best(lambda: fg.self_affine_box_counting(z, box_sizes=asz))
    tb, ref = best(lambda: np_affine(z, asz), 1)
    assert np.allclose(fit.extra["mean_range"], ref)
    rows.append(("self-affine boxes", t, "numpy sliding windows", tb))

    zs = float(np.mean(np.abs(np.diff(z, axis=1))))
    msz = [3, 5, 9, 17]
    t, fit = best(lambda: fg.mass_dimension(z, box_sizes=msz, z_scale=zs), 1)
    sub = z[:256]
    tb, _ = best(lambda: np_mass(sub, msz, zs), 1)
    rows.append(("P(m,L) mass (grayscale)", t, "numpy shifted comparisons (256 rows, extrapolated)", tb * n / 256))

    t, fit = best(lambda: fg.blanket(z, z_scale=zs))
    tb, ref = best(lambda: scipy_blanket(z / zs), 1)
    assert np.allclose(fit.measures, ref, rtol=1e-12)
    rows.append(("covering blanket", t, "scipy.ndimage grey dilation/erosion", tb))

    for name, f in [
        ("square increments", lambda: fg.surface_variation(z)),
        ("first differences", lambda: fg.surface_variation(z, estimator="first")),
        ("transect madogram", lambda: fg.surface_variation(z, estimator="transect", p=1.0)),
        ("spectral (2D radial)", lambda: fg.spectral_dimension(z)),
        ("wavelet (2D Haar)", lambda: fg.wavelet_dimension(z)),
        ("Minkowski sausage (level line, 1024²)", lambda: fg.minkowski(edge[:1024, :1024])),
        ("lacunarity (gliding box)", lambda: fg.lacunarity(np.abs(z))),
        ("variogram (profile 4.2 M)", lambda: fg.variogram(prof)),
        ("madogram (profile 4.2 M)", lambda: fg.madogram(prof)),
        ("Higuchi (profile 4.2 M)", lambda: fg.higuchi(prof)),
        ("scale space (profile 4.2 M)", lambda: fg.scale_space(prof)),
    ]:
        t, _ = best(f, 1)
        rows.append((name, t, "(numpy/scipy code: no separate baseline)", None))
        print(f"  done {name}: {t:.3f} s", flush=True)

    print(f"{'estimator':32s} {'ours (s)':>9s}  baseline")
    for name, t, bname, tb in rows:
        extra = f"{bname}: {tb:.3f} s = {tb / t:.1f}x ours" if tb is not None else bname
        print(f"{name:32s} {t:9.3f}  {extra}")


if __name__ == "__main__":
    main()
