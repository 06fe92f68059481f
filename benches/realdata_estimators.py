"""Every whole-image estimator's default on the bundled real data: D, the
fitted scale range, the regimes found and the validity flags.

Data: ``fractalgeo_rs.data.srtm_alps()``, ``srtm_po_plain()`` (SRTM 3",
int16 metres), ``tests/data/bigtujunga_30m_crop128.npy`` (30 m DEM) and
``sentinel1_vv_db()`` (Sentinel-1 VV dB). Profiles: the middle row of each.
The exact likelihood (``mle``) is left out (at most 4096 samples).

Run: ``python benches/realdata_estimators.py`` (under a minute); prints
Markdown.
"""
from __future__ import annotations

import os
import warnings

import numpy as np

import fractalgeo_rs as fg

HERE = os.path.dirname(os.path.abspath(__file__))
SURFACE = ["dbc", "affine", "mass", "blanket", "spectral", "variogram", "madogram", "surface_variation",
           "wavelet", "whittle"]
PROFILE = ["affine", "spectral", "variogram", "madogram", "variation", "wavelet", "scale_space", "higuchi", "whittle"]


def data():
    return {
        "SRTM Alps 256²": fg.data.srtm_alps()[0].astype(float),
        "SRTM Po plain": fg.data.srtm_po_plain()[0].astype(float),
        "Big Tujunga 30 m 128²": np.load(os.path.join(HERE, "..", "tests", "data", "bigtujunga_30m_crop128.npy")).astype(float),
        "Sentinel-1 VV dB 512²": fg.data.sentinel1_vv_db()[0].astype(float),
    }


def cell(z, key):
    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always", fg.FractalRangeWarning)
        try:
            f = fg.dimension(z, method=key)
        except ValueError as exc:
            return f"error: {str(exc)[:60]}"
    flags = ",".join(f.flags) or "-"
    rng = f"{f.scale_range[0]:.3g}..{f.scale_range[1]:.3g}"
    regimes = ""
    if len(f.ranges) > 1:
        regimes = " [" + "; ".join(f"{r.scale_range[0]:.3g}-{r.scale_range[1]:.3g}: {r.dimension:.2f}"
                                   for r in f.ranges) + "]"
    warned = "W" if rec else ""
    return f"{f.dimension:.3f} ({rng}) {flags}{warned and ' ' + warned}{regimes}"


def main() -> None:
    ds = data()
    for title, keys, pick in (("Surfaces", SURFACE, lambda z: z), ("Profiles (middle row)", PROFILE,
                                                                    lambda z: z[z.shape[0] // 2])):
        print(f"## {title}: D (fitted scales) flags, W = FractalRangeWarning issued, [regimes]\n")
        print("| method | " + " | ".join(ds) + " |")
        print("|---|" + "---|" * len(ds))
        for key in keys:
            print(f"| {key} | " + " | ".join(cell(pick(z), key) for z in ds.values()) + " |")
        print()


if __name__ == "__main__":
    main()
