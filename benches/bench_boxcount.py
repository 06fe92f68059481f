"""Benchmark: binary 2D box counting, fractalgeo_rs against the baselines a
user has, measured in the same run.

Baselines
- numpy: the fastest plain-numpy dyadic pyramid we could write (OR of the four
  strided quarters per level, which beats ``reshape(...).any(axis=(1, 3))``;
  both are timed and the faster is the baseline);
- ``boxcounting`` (PyPI, numba-compiled port of Moisy's MATLAB boxcount;
  JIT warm-up excluded);
- ``porespy.metrics.boxcount`` (PyPI): it loops over boxes in Python and counts
  boxes holding both phases (a different measure); at these sizes a full run
  takes minutes, so it is timed on box sizes >= 32 and its per-box cost is
  extrapolated to the full size list (printed as such);
- the time to read the image once: ``np.load`` of the same array from a .npy
  file (page cache), and one ``np.count_nonzero`` pass over it in memory.

Image: a binary mask of real SAR texture, the Umbra X-band scene of Mount
Yasur (2000 x 2000, ../shared/data) thresholded at its median and tiled
(mirrored) to the size; when ../shared is absent, a seeded random field of the
same density. Box sizes 1, 2, 4, ..., n/4 for every implementation.

Run: ``python benches/bench_boxcount.py [--sizes 4096 8192] [--repeat 5]``.
"""
from __future__ import annotations

import argparse
import os
import platform
import tempfile
import time

import numpy as np

import fractalgeo_rs as fg
from _timing import best as best_time

HERE = os.path.dirname(os.path.abspath(__file__))
SAR = os.path.join(HERE, "..", "..", "shared", "data", "umbra_mount_yasur_x_band.tif")


def make_mask(n: int) -> tuple[np.ndarray, str]:
    try:
        import rasterio

        with rasterio.open(SAR) as src:
            a = src.read(1)
        tile = a > np.median(a)
        reps = -(-n // tile.shape[0])
        row = np.concatenate([tile if k % 2 == 0 else tile[::-1] for k in range(reps)], axis=0)
        big = np.concatenate([row if k % 2 == 0 else row[:, ::-1] for k in range(reps)], axis=1)
        return np.ascontiguousarray(big[:n, :n]), "Umbra Mount Yasur SAR > median, mirrored tiles"
    except Exception:
        rng = np.random.default_rng(0)
        return rng.random((n, n)) < 0.5, "seeded random field, density 0.5 (../shared absent)"


def numpy_pyramid_or(mask: np.ndarray, levels: int) -> list[int]:
    counts, a = [], mask
    for _ in range(levels):
        counts.append(int(np.count_nonzero(a)))
        a = a[0::2, 0::2] | a[1::2, 0::2] | a[0::2, 1::2] | a[1::2, 1::2]
    return counts


def numpy_pyramid_reshape(mask: np.ndarray, levels: int) -> list[int]:
    counts, a = [], mask
    for _ in range(levels):
        counts.append(int(np.count_nonzero(a)))
        h, w = a.shape
        a = a.reshape(h // 2, 2, w // 2, 2).any(axis=(1, 3))
    return counts


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--sizes", type=int, nargs="+", default=[4096, 8192])
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args()
    print(f"machine: {platform.machine()}, {os.cpu_count()} cores, {platform.processor() or platform.platform()}")
    print(f"fractalgeo_rs {fg.__version__}, numpy {np.__version__}, repeat {args.repeat} (best time)")
    for n in args.sizes:
        mask, what = make_mask(n)
        levels = int(np.log2(n)) - 1  # sizes 1 .. n/4
        sizes = [2**k for k in range(levels)]
        print(f"\n== {n} x {n} bool ({mask.nbytes / 2**20:.0f} MiB), {what}, box sizes 1..{sizes[-1]}")
        ours = fg.box_counting(mask, box_sizes=sizes)
        ref = numpy_pyramid_or(mask, levels)
        assert ours.measures.astype(int).tolist() == ref, "counts differ from numpy"
        assert numpy_pyramid_reshape(mask, levels) == ref
        t = {}
        t["fractalgeo_rs (2 threads)"] = best_time(lambda: fg.box_counting(mask, box_sizes=sizes), args.repeat)
        t["fractalgeo_rs (1 thread)"] = best_time(lambda: fg.box_counting(mask, box_sizes=sizes, n_threads=1), args.repeat)
        t_or = best_time(lambda: numpy_pyramid_or(mask, levels), max(2, args.repeat // 2))
        t_rs = best_time(lambda: numpy_pyramid_reshape(mask, levels), max(2, args.repeat // 2))
        t["numpy pyramid, reshape/any"] = t_rs
        t["numpy pyramid, strided OR (fastest)"] = t_or
        with tempfile.TemporaryDirectory() as d:
            p = os.path.join(d, "mask.npy")
            np.save(p, mask)
            np.load(p)
            t["read once: np.load .npy"] = best_time(lambda: np.load(p), args.repeat)
        t["read once: np.count_nonzero"] = best_time(lambda: np.count_nonzero(mask), args.repeat)
        try:
            from boxcounting import boxCount

            boxCount(mask[:64, :64]).calculateBoxCount()  # numba JIT warm-up
            t["boxcounting (numba)"] = best_time(lambda: boxCount(mask).calculateBoxCount(), 2)
        except ImportError:
            print("boxcounting not installed (pip install boxcounting)")
        try:
            import porespy

            big = [s for s in sizes if s >= 32]
            t0 = time.perf_counter()
            porespy.metrics.boxcount(mask, bins=big)
            el = time.perf_counter() - t0
            boxes_timed = sum((n // s) ** 2 for s in big)
            boxes_all = sum((n // s) ** 2 for s in sizes)
            t["porespy boxcount (extrapolated)"] = el * boxes_all / boxes_timed
        except ImportError:
            print("porespy not installed (pip install porespy)")
        ours_t = t["fractalgeo_rs (2 threads)"]
        for name, v in t.items():
            ratio = v / ours_t
            print(f"{name:36s} {v * 1e3:10.1f} ms   {ratio:8.1f} x ours")
        print(f"D = {ours.dimension:.4f}")


if __name__ == "__main__":
    main()
