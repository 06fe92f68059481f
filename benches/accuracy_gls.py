"""Accuracy of the GLS local-H map on exact fBm surfaces, next to the
Cramér-Rao bound and the variogram map on the same windows.

Fields: ``fbm_surface((1024, 1024), H, method="exact", seed=s)``, ``s = 0 ..
seeds - 1`` per H (``--seeds``, default 2); the maps are read at the centres
of disjoint windows (one window away from the edges): seeds x 29² windows at
window 33, seeds x 14² at window 65. Printed
per window and H: mean bias of D, sd of D across windows, the mean of the
standard-error map (``return_fit=True``) and its ratio to the sd, the
Cramér-Rao bound of sd(D) on the window's grid (``benches/crb_fbm_surface.py``,
values computed by that script and listed below) and sd / CRB, and the sd of
the variogram map (lags 1, 2) on the same windows.

With ``--independent N``, a second table: ``gls_dimension`` (the map's
per-window estimator) on ``N`` independent exact fBm fields of 33² per H
(``seed = 10000 + i``), free of the correlation between the windows of one
field.

Run: ``python benches/accuracy_gls.py [--seeds 6] [--independent 40000]``
(Markdown on stdout, after a line giving the seeds, window counts, machine
and load).
"""
from __future__ import annotations

import argparse
import os
import platform

import numpy as np

import fractalgeo_rs as fg

# python benches/crb_fbm_surface.py 33 / 65 (crb(n, H))
CRB = {
    33: {0.2: 0.0211, 0.3: 0.0249, 0.5: 0.0293, 0.7: 0.0311, 0.8: 0.0311},
    65: {0.2: 0.0109, 0.3: 0.0129, 0.5: 0.0153, 0.7: 0.0165, 0.8: 0.0168},
}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=2, help="fields per H (default 2)")
    ap.add_argument("--independent", type=int, default=0, help="independent 33² fields per H (default 0: none)")
    args = ap.parse_args()
    seeds = args.seeds
    n = 1024
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    print(f"{seeds} seeds: {seeds * len(range(33, n - 33, 33)) ** 2} windows at w = 33, "
          f"{seeds * len(range(65, n - 65, 65)) ** 2} at w = 65; {platform.machine()}, "
          f"{os.cpu_count()} cores, load {load:.2f}\n")
    print("| window | H | bias of D | sd of D | mean SE map | SE / sd | CRB | sd / CRB | variogram map sd |")
    print("|---|---|---|---|---|---|---|---|---|")
    for w in (33, 65):
        for h in (0.2, 0.3, 0.5, 0.7, 0.8):
            ds, ses, vs = [], [], []
            for s in range(seeds):
                z = fg.fbm_surface((n, n), h, method="exact", seed=s)
                d, se = fg.fractal_transform(z, w, method="gls", return_fit=True)
                v = fg.fractal_transform(z, w, method="variogram")
                sl = (slice(w, n - w, w), slice(w, n - w, w))
                ds.append(d[sl].ravel())
                ses.append(se[sl].ravel())
                vs.append(v[sl].ravel())
            d, se, v = np.concatenate(ds), np.concatenate(ses), np.concatenate(vs)
            sd, m = float(d.std()), float(se.mean())
            c = CRB[w][h]
            print(f"| {w} | {h} | {d.mean() - (3 - h):+.4f} | {sd:.4f} | {m:.4f} | {m / sd:.2f} | {c:.4f} "
                  f"| {sd / c:.2f} | {v.std():.4f} |", flush=True)

    if args.independent:
        independent(args.independent)


def independent(count: int) -> None:
    w = 33
    print(f"\n{count} independent fields of {w}² per H:\n")
    print("| window | H | bias of D | sd of D | mean SE | SE / sd | CRB | sd / CRB |")
    print("|---|---|---|---|---|---|---|---|")
    for h in (0.2, 0.3, 0.5, 0.7, 0.8):
        fits = [fg.gls_dimension(fg.fbm_surface((w, w), h, method="exact", seed=10_000 + i)) for i in range(count)]
        d = np.array([f.dimension for f in fits])
        se = np.array([f.stderr for f in fits])
        sd, m, c = float(d.std()), float(se.mean()), CRB[w][h]
        print(f"| {w} | {h} | {d.mean() - (3 - h):+.4f} | {sd:.4f} | {m:.4f} | {m / sd:.2f} | {c:.4f} "
              f"| {sd / c:.2f} |", flush=True)


if __name__ == "__main__":
    main()
