"""The default method of fractal_transform, measured: accuracy on exact fBm,
informativeness on real DEMs, separability of built-up land on a SAR scene.

(a) Exact fBm surfaces (``fbm_surface((256, 256), H, method="exact")``,
    true D = 3 - H): median bias and spread (IQR / 1.349) of the map.
(b) Real DEMs: the bundled SRTM crops (Maritime Alps, Po plain) and the 30 m
    Big Tujunga crop, plus ``../shared/data`` rasters when present: the
    fraction of pixels at the map's most common value and the fraction
    outside [2, 3].
(c) The bundled Sentinel-1 VV dB scene with the boxes of
    ``tests/data/s1_vega_baja_builtup_boxes.json`` (built-up and non-built-up
    land labelled by eye): AUC = P(D of a built-up pixel > D of a non-built-up
    pixel) (Mann-Whitney), per method and window.

Each box method (mass, dbc, blanket) is run with ``z_scale="auto"`` (the
default) and ``z_scale=1`` (one data unit per box step).

Run: ``python benches/realdata_transform.py [--windows 17,33,65] [--whittle]``
(2-4 minutes on 2 cores; Whittle maps add a few minutes); prints Markdown.
"""
from __future__ import annotations

import argparse
import json
import os
import time
import warnings

import numpy as np

import fractalgeo_rs as fg

HERE = os.path.dirname(os.path.abspath(__file__))
BOXES = os.path.join(HERE, "..", "tests", "data", "s1_vega_baja_builtup_boxes.json")
SHARED = os.path.join(HERE, "..", "..", "shared", "data")


def configs(with_whittle: bool):
    out = []
    for m in ("mass", "dbc", "blanket"):
        out.append((f"{m} (auto)", m, {}))
        out.append((f"{m} (z_scale=1)", m, {"z_scale": 1.0}))
    out += [("variogram", "variogram", {}), ("madogram", "madogram", {}), ("square", "square", {})]
    if with_whittle:
        out.append(("whittle", "whittle", {}))
    return out


def auc(pos: np.ndarray, neg: np.ndarray) -> float:
    pos, neg = pos[np.isfinite(pos)], neg[np.isfinite(neg)]
    allv = np.concatenate([pos, neg])
    from scipy.stats import rankdata

    r = rankdata(allv)
    return float((r[: pos.size].sum() - pos.size * (pos.size + 1) / 2) / (pos.size * neg.size))


def dems():
    out = {"srtm_alps (bundled)": fg.data.srtm_alps()[0].astype(float),
           "srtm_po_plain (bundled)": fg.data.srtm_po_plain()[0].astype(float),
           "bigtujunga 30 m crop (tests/data)": np.load(os.path.join(HERE, "..", "tests", "data",
                                                                       "bigtujunga_30m_crop128.npy")).astype(float)}
    if os.path.isdir(SHARED):
        try:
            z, _ = fg.read_raster(os.path.join(SHARED, "kilauea_30m.tif"))
            z = np.asarray(z, dtype=float)
            z[z == -32768] = np.nan
            out["kilauea 30 m (shared)"] = z[:512, :512]
        except Exception as exc:  # pragma: no cover - optional data
            print(f"(kilauea skipped: {exc})")
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--windows", default="17,33,65")
    ap.add_argument("--whittle", action="store_true")
    args = ap.parse_args()
    ws = [int(v) for v in args.windows.split(",")]
    warnings.simplefilter("ignore")
    cfg = configs(args.whittle)
    import platform

    print(f"machine: {platform.machine()}, {os.cpu_count()} cores; fractalgeo_rs {fg.__version__}\n")
    t0 = time.perf_counter()
    # (c) SAR separability
    z, _ = fg.data.sentinel1_vv_db()
    boxes = json.load(open(BOXES))
    print(f"## Built-up separability, Sentinel-1 VV dB 512 x 512 (AUC, {len(boxes['built_up'])} + "
          f"{len(boxes['non_built_up'])} boxes; z_scale auto = {fg.transform.default_z_scale(z):.3f} dB)\n")
    print("| method | " + " | ".join(f"w{w}" for w in ws) + " |")
    print("|---|" + "---|" * len(ws))
    for name, m, kw in cfg:
        row = []
        for w in ws:
            d = np.asarray(fg.fractal_transform(z, w, method=m, **kw))
            pos = np.concatenate([d[a:b, c:e].ravel() for a, b, c, e in boxes["built_up"]])
            neg = np.concatenate([d[a:b, c:e].ravel() for a, b, c, e in boxes["non_built_up"]])
            row.append(auc(pos, neg))
        print(f"| {name} | " + " | ".join(f"{a:.2f}" for a in row) + " |")
    # (b) DEMs
    print("\n## Real DEMs: fraction of pixels at the most common value / outside [2, 3] (window 33)\n")
    dd = dems()
    print("| method | " + " | ".join(dd) + " |")
    print("|---|" + "---|" * len(dd))
    for name, m, kw in cfg:
        cells = []
        for k, dem in dd.items():
            d = np.asarray(fg.fractal_transform(dem, 33, method=m, **kw))
            f = d[np.isfinite(d)]
            _, cnt = np.unique(f, return_counts=True)
            cells.append(f"{cnt.max() / f.size:.2f} / {np.mean((f < 2) | (f > 3)):.2f} (median {np.median(f):.2f})")
        print(f"| {name} | " + " | ".join(cells) + " |")
    # (a) exact fBm
    print("\n## Exact fBm 256 x 256: median bias / spread of the map (window 33)\n")
    hs = (0.3, 0.5, 0.7)
    print("| method | " + " | ".join(f"H={h}" for h in hs) + " |")
    print("|---|" + "---|" * len(hs))
    fields = {h: fg.fbm_surface((256, 256), h, seed=7, method="exact") for h in hs}
    for name, m, kw in cfg:
        cells = []
        for h in hs:
            d = np.asarray(fg.fractal_transform(fields[h], 33, method=m, **kw))[16:-16, 16:-16]
            q1, med, q3 = np.percentile(d[np.isfinite(d)], [25, 50, 75])
            cells.append(f"{med - (3 - h):+.3f} / {(q3 - q1) / 1.349:.3f}")
        print(f"| {name} | " + " | ".join(cells) + " |")
    print(f"\ntotal {time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    main()
