"""Measure the data-derived z_scale units ("auto", "range") of the whole-image
box, mass and blanket estimators on exact fBm and on the bundled real data.

For each estimator and unit: bias and RMSE of D against D = 3 - H on exact
fBm surfaces (H = 0.3, 0.5, 0.7), and D on the bundled SRTM crops and the
Sentinel-1 crop. The defaults in docs/conventions.md are chosen from this
table.

    python benches/z_scale_defaults.py [--n 256] [--seeds 8]
"""
from __future__ import annotations

import argparse
import platform

import numpy as np

import fractalgeo_rs as fg
from fractalgeo_rs._zscale import resolve_z_scale

ESTIMATORS = {
    "differential_box_counting": fg.differential_box_counting,
    "mass_dimension": fg.mass_dimension,
    "blanket": fg.blanket,
}
UNITS = ("auto", "range")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=256)
    ap.add_argument("--seeds", type=int, default=8)
    args = ap.parse_args()
    print(f"machine: {platform.machine()} {platform.processor() or ''}, fBm {args.n} x {args.n}, "
          f"{args.seeds} seeds per H, fbm_surface(method='exact')")
    surfaces = {h: [fg.fbm_surface((args.n, args.n), h, method="exact", seed=s) for s in range(args.seeds)]
                for h in (0.3, 0.5, 0.7)}
    real = {"srtm_alps": fg.data.srtm_alps()[0], "srtm_po_plain": fg.data.srtm_po_plain()[0],
            "s1_vv_db": fg.data.sentinel1_vv_db()[0], "s1_vh_db": fg.data.sentinel1_vh_db()[0]}
    header = f"{'estimator':28s} {'unit':6s} " + " ".join(f"{'H=' + str(h):>17s}" for h in surfaces)
    header += "  mean|bias|  meanRMSE  " + " ".join(f"{k:>13s}" for k in real)
    print(header)
    print(" " * 36 + "  (bias / RMSE)" * 3)
    for name, fn in ESTIMATORS.items():
        for unit in UNITS:
            cells, biases, rmses = [], [], []
            for h, zs in surfaces.items():
                d = np.array([fn(z, z_scale=resolve_z_scale(unit, z)).dimension for z in zs])
                err = d - (3.0 - h)
                b, r = float(err.mean()), float(np.sqrt((err ** 2).mean()))
                biases.append(abs(b))
                rmses.append(r)
                cells.append(f"{b:+.3f} / {r:.3f}")
            reals = [fn(z, z_scale=resolve_z_scale(unit, z)).dimension for z in real.values()]
            print(f"{name:28s} {unit:6s} " + " ".join(f"{c:>17s}" for c in cells)
                  + f"  {np.mean(biases):10.3f}  {np.mean(rmses):8.3f}  " + " ".join(f"{v:13.3f}" for v in reals))


if __name__ == "__main__":
    main()
