"""A scene larger than a comfortable in-memory run: 16384 x 16384 float32
(1 GiB) through Dask, with the peak memory of the process.

The scene is lazy: mirrored copies of the bundled Sentinel-1 VV tile (dB)
built chunk by chunk, so it never exists whole. The map (mass method, window
33) is streamed chunk by chunk into a memory-mapped ``.npy`` file (its
resident pages count in the peak memory printed).

Run: ``python benches/bench_transform_dask.py [--size 16384] [--chunks 2048]``.
"""
from __future__ import annotations

import argparse
import os
import resource
import tempfile
import time

import numpy as np

import fractalgeo_rs as fg


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--size", type=int, default=16384)
    ap.add_argument("--chunks", type=int, default=2048)
    ap.add_argument("--window", type=int, default=33)
    args = ap.parse_args()
    import dask
    import dask.array as da

    vv, _ = fg.data.sentinel1_vv_db()
    tile = np.block([[vv, vv[:, ::-1]], [vv[::-1], vv[::-1, ::-1]]]).astype(np.float32)  # 1024², seamless
    n, c = args.size, args.chunks
    reps = -(-n // tile.shape[0])
    scene = da.tile(da.from_array(tile, chunks=tile.shape), (reps, reps))[:n, :n].rechunk(c)
    dmap = fg.fractal_transform(scene, args.window, method="mass", n_threads=1)
    with tempfile.TemporaryDirectory() as d:
        out = np.lib.format.open_memmap(os.path.join(d, "map.npy"), mode="w+", dtype=np.float32, shape=(n, n))
        t0 = time.perf_counter()
        with dask.config.set(scheduler="threads", num_workers=os.cpu_count()):
            da.store(dmap, out, lock=False)
        el = time.perf_counter() - t0
        sample = np.asarray(out[::64, ::64])
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2**20  # KiB -> GiB
    print(f"scene {n} x {n} float32 ({n * n * 4 / 2**30:.1f} GiB), chunks {c}, window {args.window}, mass method")
    print(f"time {el:.1f} s ({n * n / el / 1e6:.1f} Mpixel/s on {os.cpu_count()} cores), "
          f"peak memory of the process {peak:.2f} GiB (map written to a memory-mapped file)")
    print(f"local dimension (sampled): mean {np.nanmean(sample):.3f}, 5-95 % "
          f"{np.nanpercentile(sample, 5):.3f}-{np.nanpercentile(sample, 95):.3f}")


if __name__ == "__main__":
    main()
