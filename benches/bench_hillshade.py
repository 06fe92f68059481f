"""Hillshade bytes: fractalgeo_rs against ``gdaldem hillshade -compute_edges``.

GDAL is timed as the ``gdaldem`` binary on an uncompressed float32 GeoTIFF in
/dev/shm (RAM) with ``-of MEM`` (no output file), so its time includes
reading the DEM from RAM and the process start; the time of
``gdal_translate -of MEM`` of the same file (reading only) is printed and
subtracted. Wall times and CPU times (``getrusage`` of the child, and
``process_time`` of ours with one thread) are printed: on a shared machine
the CPU times are the comparable ones. Ours is the in-memory call
``hillshade(z, byte=True)`` on the float32 array. Both use the same DEM: a
fBm surface (H = 0.8, 30 m cells) of SIZE x SIZE; the outputs are compared
pixel by pixel.

    python benches/bench_hillshade.py [SIZE] [REPEATS]
"""
import os
import platform
import shutil
import subprocess
import sys
import tempfile
import time

import numpy as np

import fractalgeo_rs as fg
from _timing import best


def child_cpu(cmd, repeats):
    """Least user + system CPU seconds of a child process over the repeats."""
    import resource

    out = []
    for _ in range(repeats):
        r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
        subprocess.run(cmd, check=True)
        r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
        out.append(r1.ru_utime - r0.ru_utime + r1.ru_stime - r0.ru_stime)
    return min(out)


def own_cpu(f, repeats):
    out = []
    for _ in range(repeats):
        c0 = time.process_time()
        f()
        out.append(time.process_time() - c0)
    return min(out)


def main():
    size = int(sys.argv[1]) if len(sys.argv) > 1 else 4096
    repeats = int(sys.argv[2]) if len(sys.argv) > 2 else 3
    import rasterio
    from rasterio.transform import from_origin

    z = fg.fbm_surface((size, size), 0.8, method="spectral", seed=1, sigma=5.0, cell_size=30.0).astype(np.float32)
    print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores; DEM {size} x {size} float32")
    t_ours = {n: best(lambda: fg.hillshade(z, cell_size=30.0, byte=True, n_threads=n), repeats) for n in (1, None)}
    ours = fg.hillshade(z, cell_size=30.0, byte=True)
    if shutil.which("gdaldem") is None:
        print("gdaldem not installed: ours only", t_ours)
        return
    folder = "/dev/shm" if os.path.isdir("/dev/shm") else None
    with tempfile.TemporaryDirectory(dir=folder) as tmp:
        src = os.path.join(tmp, "dem.tif")
        with rasterio.open(src, "w", driver="GTiff", width=size, height=size, count=1, dtype="float32",
                           crs="EPSG:32633", transform=from_origin(0, size * 30.0, 30.0, 30.0)) as dst:
            dst.write(z, 1)
        out = os.path.join(tmp, "shade.tif")
        gd = ["gdaldem", "hillshade", "-compute_edges", "-q"]
        t_gdal = best(lambda: subprocess.run(gd + ["-of", "MEM", src, "x"], check=True), repeats)
        t_read = best(lambda: subprocess.run(["gdal_translate", "-q", "-of", "MEM", src, "x"], check=True), repeats)
        c_gdal = child_cpu(gd + ["-of", "MEM", src, "x"], repeats)
        c_read = child_cpu(["gdal_translate", "-q", "-of", "MEM", src, "x"], repeats)
        subprocess.run(gd + [src, out], check=True)
        with rasterio.open(out) as ds:
            ref = ds.read(1)
    diff = int(np.count_nonzero(ref != ours))
    gdal_compute = t_gdal - t_read
    print(f"gdaldem (binary, -of MEM): {t_gdal:.3f} s; reading alone (gdal_translate -of MEM): {t_read:.3f} s; "
          f"compute ~ {gdal_compute:.3f} s")
    print(f"ours, 1 thread: {t_ours[1]:.3f} s ({gdal_compute / t_ours[1]:.2f}x gdaldem compute)")
    print(f"ours, all cores: {t_ours[None]:.3f} s ({gdal_compute / t_ours[None]:.2f}x gdaldem compute)")
    c_ours = own_cpu(lambda: fg.hillshade(z, cell_size=30.0, byte=True, n_threads=1), repeats)
    print(f"CPU seconds (one thread, robust to a loaded machine): gdaldem {c_gdal:.3f} - reading {c_read:.3f} "
          f"= {c_gdal - c_read:.3f}; ours {c_ours:.3f} ({(c_gdal - c_read) / c_ours:.2f}x)")
    print(f"pixels differing from gdaldem: {diff} of {ref.size}")


if __name__ == "__main__":
    main()
