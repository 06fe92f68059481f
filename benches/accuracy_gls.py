"""Accuracy of the GLS local-H map on exact fBm surfaces, next to the
Cramér-Rao bound and the variogram map on the same windows.

Fields: ``fbm_surface((1024, 1024), H, method="exact", seed=s)``, 2 seeds per
H; the maps are read at the centres of disjoint windows (one window away
from the edges): 2 x 29² windows at window 33, 2 x 14² at window 65. Printed
per window and H: mean bias of D, sd of D across windows, the mean of the
standard-error map (``return_fit=True``) and its ratio to the sd, the
Cramér-Rao bound of sd(D) on the window's grid (``benches/crb_fbm_surface.py``,
values computed by that script and listed below) and sd / CRB, and the sd of
the variogram map (lags 1, 2) on the same windows.

Run: ``python benches/accuracy_gls.py`` (Markdown on stdout).
"""
from __future__ import annotations

import numpy as np

import fractalgeo_rs as fg

# python benches/crb_fbm_surface.py 33 / 65 (crb(n, H))
CRB = {
    33: {0.2: 0.0211, 0.3: 0.0249, 0.5: 0.0293, 0.7: 0.0311, 0.8: 0.0311},
    65: {0.2: 0.0109, 0.3: 0.0129, 0.5: 0.0153, 0.7: 0.0165, 0.8: 0.0168},
}


def main() -> None:
    n = 1024
    print("| window | H | bias of D | sd of D | mean SE map | SE / sd | CRB | sd / CRB | variogram map sd |")
    print("|---|---|---|---|---|---|---|---|---|")
    for w in (33, 65):
        for h in (0.2, 0.3, 0.5, 0.7, 0.8):
            ds, ses, vs = [], [], []
            for s in range(2):
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


if __name__ == "__main__":
    main()
