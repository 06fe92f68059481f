"""``tin_from_dem`` with its defaults on the real DEMs of ../shared/data
(rasterio; SRTM void -32768): prints the rows of the "Defaults on real DEMs"
table of docs/tin.md. Run: ``python benches/tin_real_dems.py``."""
import os
import time

import numpy as np
import rasterio

from fractalgeo_rs.tin import tin_from_dem

_REPO = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
DATA = next((p for p in (os.path.join(_REPO, "..", "shared", "data"), os.path.join(_REPO, "..", "..", "shared", "data"))
             if os.path.isdir(p)), "")
for name, path in [("bigtujunga_30m.tif", os.path.join(DATA, "bigtujunga_30m.tif")), ("N44E007.hgt", os.path.join(DATA, "N44E007.hgt"))]:
    with rasterio.open(path) as src:
        z = src.read(1); tr = src.transform; nd = src.nodata
    if nd is None and name.endswith(".hgt"): nd = -32768
    t0 = time.perf_counter(); t = tin_from_dem(z, transform=tr, nodata=nd); dt = time.perf_counter() - t0
    zf = z.astype(float); valid = zf != nd if nd is not None else np.ones(z.shape, bool)
    lo, hi = np.percentile(zf[valid], [2, 98])
    print(f"| {name} | {z.shape[0]}x{z.shape[1]} | {int((~valid).sum())} | {0.005*(hi-lo):.2f} | {len(t.vertices)} ({100*len(t.vertices)/z.size:.1f} %) | {len(t.triangles)} | {t.max_error:.2f} | {dt:.2f} s |", flush=True)
