"""Benchmark: every dimension estimator on a 2048 x 2048 surface (profile
estimators on a 2048² = 4,194,304-sample profile), against the fastest
Python alternative we know, in the same run.

Alternatives (named in the output): for the Rust kernels, numpy versions
written here from the same definitions (counts asserted equal first):
box counting (strided-OR pyramid), DBC (block min/max by reshape), self-affine
boxes (column ranges by reshape), grayscale P(m, L) (shifted
comparisons) and the covering blanket (the previous scipy.ndimage version:
``grey_dilation``/``grey_erosion`` with the cross footprint, 16 steps,
areas asserted equal). The other estimators (numpy/scipy code, Higuchi a small
Rust kernel) are timed against what a user would otherwise run: the same
formula in numpy, ``pywt.wavedec2`` (PyWavelets), ``antropy.higuchi_fd``
(numba), ``scipy.ndimage.gaussian_filter1d`` per width, a
``distance_transform_edt`` sausage, cumsum gliding boxes. Install them with
``pip install antropy PyWavelets``.

Surface: exact fBm (H = 0.5), seed 0. Run: ``python benches/bench_estimators.py``.
"""
from __future__ import annotations

import os
import platform

import numpy as np

import fractalgeo_rs as fg
from _timing import best_with_result as best


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
    # sub-millisecond calls: best of 20 for ours and the baseline alike
    t, fit = best(lambda: fg.box_counting(mask, box_sizes=sizes, anchor="array"), 20)
    tb, counts = best(lambda: np_box(mask, 10), 20)
    assert fit.measures.astype(int).tolist() == counts
    rows.append(("box counting (binary)", t, "numpy strided-OR pyramid", tb))
    # the Rust kernel alone (what box_counting calls, without the checks and
    # the fit object), against the same numpy pyramid: both return the counts
    from fractalgeo_rs import _core

    tk, (_, kc, *_) = best(lambda: _core.box_count_binary(mask.view(np.uint8), sizes, 1, False, None), 20)
    assert kc[:, 0].tolist() == counts
    rows.append(("  its Rust kernel alone", tk, "numpy strided-OR pyramid", tb))

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

    # estimators written in numpy/scipy (or with a small Rust kernel): each
    # against the code a user would write or install for the same measure
    from scipy.ndimage import distance_transform_edt, gaussian_filter1d

    def np_square(lags=(1, 2)):
        return [0.5 * float(np.mean((z[u:, u:] - z[u:, :-u] - z[:-u, u:] + z[:-u, :-u]) ** 2)) for u in lags]

    def np_first(lags=(1, 2)):
        return [0.5 * float(np.mean(np.concatenate([(z[u:] - z[:-u]).ravel(), (z[:, u:] - z[:, :-u]).ravel()]) ** 2))
                for u in lags]

    def np_transect(lags=(1, 2)):
        rows_ = [np.median(np.mean(np.abs(a[:, u:] - a[:, :-u]), axis=1)) for a in (z, z.T) for u in lags]
        return rows_

    def np_profile(p, lags=(1, 2)):
        return [0.5 * float(np.mean(np.abs(prof[u:] - prof[:-u]) ** p)) for u in lags]

    def np_spectrum():
        f = np.abs(np.fft.rfft2(z - z.mean())) ** 2
        ky = np.fft.fftfreq(z.shape[0])[:, None]
        kx = np.fft.rfftfreq(z.shape[1])[None, :]
        k = np.hypot(ky, kx)
        b = np.minimum((k * z.shape[0]).astype(int), z.shape[0] // 2)
        return np.bincount(b.ravel(), f.ravel()) / np.maximum(np.bincount(b.ravel()), 1)

    def pywt_haar():
        import pywt

        return [float(np.var(np.concatenate([d.ravel() for d in lvl]))) for lvl in pywt.wavedec2(z, "haar")[1:]]

    msk = edge[:1024, :1024]
    radii = fg.minkowski(msk).scales

    def edt_sausage():
        d = distance_transform_edt(~msk)
        return [int(np.count_nonzero(d <= r)) for r in radii]

    lz = np.abs(z)
    lsizes = [2**k for k in range(20) if 2**k <= n / 4]

    def np_lacunarity():
        c = np.zeros((n + 1, n + 1))
        c[1:, 1:] = lz.cumsum(0).cumsum(1)
        out = []
        for r in lsizes:
            m = c[r:, r:] - c[:-r, r:] - c[r:, :-r] + c[:-r, :-r]
            out.append(float(np.mean(m**2) / np.mean(m) ** 2))
        return out

    sig = [2 ** (k / 2) for k in range(17)]  # widths 1 .. 256 samples (the default for this profile)

    def scipy_scale_space():
        return [float(np.sum(np.abs(np.diff(gaussian_filter1d(prof, s_, mode="reflect"))))) for s_ in sig]

    def np_higuchi(k_max=64):
        """Higuchi L(k) in numpy: one lag-k difference per k, summed per offset m by a reshape."""
        nn = prof.size
        out = []
        for k in range(1, k_max + 1):
            d = np.abs(prof[k:] - prof[:-k])  # d[j] = |x[j+k] - x[j]|, offset m = j mod k (+1)
            pad = (-d.size) % k
            sums = np.concatenate([d, np.zeros(pad)]).reshape(-1, k).sum(axis=0)
            m = np.arange(1, k + 1)
            cnt = (nn - m) // k
            out.append(float(np.mean(sums * (nn - 1) / (cnt * k) / k)))
        return out

    def antropy_higuchi():
        import antropy

        return antropy.higuchi_fd(prof, kmax=64)

    try:
        import antropy  # noqa: F401

        antropy.higuchi_fd(prof[:1000], kmax=64)  # numba JIT warm-up, not timed
        higuchi_base = ("antropy.higuchi_fd (numba), kmax 64", antropy_higuchi)
    except ImportError:
        higuchi_base = ("antropy not installed", None)
    try:
        import pywt  # noqa: F401

        wav_base = ("PyWavelets wavedec2 haar + variances", pywt_haar)
    except ImportError:
        wav_base = ("PyWavelets not installed", None)

    # covering blanket: Rust kernel against the previous scipy.ndimage version
    t, fit = best(lambda: fg.blanket(z, z_scale=zs))
    tb, ref = best(lambda: scipy_blanket(z / zs), 1)
    assert np.allclose(fit.measures, ref, rtol=1e-12)
    rows.append(("covering blanket", t, "scipy.ndimage grey dilation/erosion (16 steps)", tb))

    cases = [
        ("square increments", lambda: fg.surface_variation(z), "numpy, same formula", np_square),
        ("first differences", lambda: fg.surface_variation(z, estimator="first"), "numpy, same formula", np_first),
        ("transect madogram", lambda: fg.surface_variation(z, estimator="transect", p=1.0),
         "numpy row/column means + median", np_transect),
        ("spectral (2D radial)", lambda: fg.spectral_dimension(z), "numpy rfft2 + bincount radial mean",
         np_spectrum),
        ("wavelet (2D Haar)", lambda: fg.wavelet_dimension(z), *wav_base),
        ("Minkowski sausage (level line, 1024²)", lambda: fg.minkowski(msk), "scipy distance_transform_edt + counts",
         edt_sausage),
        ("lacunarity (gliding box)", lambda: fg.lacunarity(lz), "numpy cumsum gliding boxes", np_lacunarity),
        ("variogram (profile 4.2 M)", lambda: fg.variogram(prof), "numpy, same formula", lambda: np_profile(2)),
        ("madogram (profile 4.2 M)", lambda: fg.madogram(prof), "numpy, same formula", lambda: np_profile(1)),
        ("Higuchi (profile 4.2 M)", lambda: fg.higuchi(prof), *higuchi_base),
        ("scale space (profile 4.2 M)", lambda: fg.scale_space(prof, sigmas=sig), "scipy gaussian_filter1d per sigma",
         scipy_scale_space),
    ]
    # Higuchi also against its plain-numpy counterpart (lengths asserted equal)
    t, fit = best(lambda: fg.higuchi(prof), 1)
    tb, ref = best(np_higuchi, 1)
    assert np.allclose(fit.measures, ref, rtol=1e-9)
    rows.append(("Higuchi (profile 4.2 M)", t, "numpy, lag-k differences + reshape sums", tb))
    for name, f, bname, base in cases:
        t, fit = best(f, 1)
        tb = best(base, 1)[0] if base is not None else None
        rows.append((name, t, bname, tb))
        print(f"  done {name}: {t:.3f} s" + (f", baseline {tb:.3f} s" if tb is not None else ""), flush=True)

    print(f"{'estimator':32s} {'ours (s)':>9s}  baseline")
    for name, t, bname, tb in rows:
        extra = f"{bname}: {tb:.4f} s = {tb / t:.1f}x ours" if tb is not None else bname
        print(f"{name:32s} {t:9.4f}  {extra}")


if __name__ == "__main__":
    main()
