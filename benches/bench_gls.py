"""Benchmark: the GLS local-H map against the variogram, mass and Whittle
maps, in the same run.

Scene: the bundled Sentinel-1 VV scene (512 x 512, dB) mirrored into an
``--size`` x ``--size`` float32 mosaic (default 4096). Each map is timed at
step 1 with every core (``n_threads=None``), best of ``--repeat`` runs; the
GLS tables of each window (Python, cached per window size) are built before
the timing and their one-off cost is printed separately. The Whittle map
(one FFT per window) is timed on a strip of 64 rows and extrapolated
(printed so).

Run: ``python benches/bench_gls.py [--size 4096] [--repeat 1]``.
"""
from __future__ import annotations

import argparse
import importlib
import os
import platform
import time

import numpy as np

import fractalgeo_rs as fg
from _timing import best

G = importlib.import_module("fractalgeo_rs.dimension.gls")


def mosaic(n: int) -> np.ndarray:
    vv, _ = fg.data.sentinel1_vv_db()
    t = np.concatenate([vv, vv[::-1]], axis=0)
    t = np.concatenate([t, t[:, ::-1]], axis=1)
    reps = -(-n // t.shape[0])
    return np.ascontiguousarray(np.tile(t, (reps, reps))[:n, :n], dtype=np.float32)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--size", type=int, default=4096)
    ap.add_argument("--repeat", type=int, default=1)
    args = ap.parse_args()
    n = args.size
    z = mosaic(n)
    print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores; image {n} x {n} float32")
    times = {}
    for w in (17, 33, 65):
        t0 = time.perf_counter()
        G.tables((w, w), 2)
        print(f"GLS tables w={w}: {time.perf_counter() - t0:.1f} s (once per window size and process)")
    for w in (17, 33, 65):
        times["gls", w] = best(lambda: fg.fractal_transform(z, w, method="gls"), args.repeat)
        times["variogram", w] = best(lambda: fg.fractal_transform(z, w, method="variogram"), args.repeat)
        print(f"w={w}: gls {times['gls', w]:.2f} s, variogram {times['variogram', w]:.2f} s, "
              f"gls / variogram {times['gls', w] / times['variogram', w]:.2f}", flush=True)
    tm = best(lambda: fg.fractal_transform(z, 33, method="mass"), args.repeat)
    print(f"w=33: mass {tm:.2f} s, gls / mass {times['gls', 33] / tm:.2f}")
    strip = 64
    ts = best(lambda: fg.fractal_transform(z[:strip + 32], 33, method="whittle")[:strip], 1)
    tw = ts * n / (strip + 32)
    print(f"w=33: whittle {tw:.0f} s extrapolated from {strip + 32} rows ({ts:.1f} s); "
          f"whittle / gls {tw / times['gls', 33]:.0f}")
    print(f"gls w65 / w17: {times['gls', 65] / times['gls', 17]:.2f}")


if __name__ == "__main__":
    main()
