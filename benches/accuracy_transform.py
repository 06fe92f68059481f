"""Accuracy of the fractal-transform maps on exact fBm surfaces: mean and
standard deviation of the local dimension over the interior of the map (one
window away from the edges), per method, H and window.

Fields: ``fbm_surface((512, 512), H, method="exact")``, 4 seeds per H. The
mass, DBC and blanket methods get heights in units of the mean lag-1
increment (``z_scale``); the blanket map (whose cost grows with the window)
and the debiased Whittle map (one FFT per window) are sampled on every 4th
row and column (``step=4``).
Run: ``python benches/accuracy_transform.py [methods...]`` (Markdown on stdout).
"""
from __future__ import annotations

import sys

import numpy as np

import fractalgeo_rs as fg


def main() -> None:
    print("| method | window | H | 3 - H | mean D | bias | sd of D |")
    print("|---|---|---|---|---|---|---|")
    methods = sys.argv[1:] or ["square", "variogram", "madogram", "mass", "dbc", "blanket", "whittle"]
    for method in methods:
        for w in (33, 65):
            for h in (0.3, 0.5, 0.7):
                means, sds = [], []
                for s in range(4):
                    z = fg.fbm_surface((512, 512), h, method="exact", seed=s)
                    kw = {}
                    if method in ("mass", "dbc", "blanket"):  # heights in units of the mean lag-1 increment
                        kw["z_scale"] = float(np.mean(np.abs(np.diff(z, axis=1))))
                    step = 4 if method in ("blanket", "whittle") else 1
                    d = fg.fractal_transform(z, w, method=method, step=step, **kw)
                    k = -(-w // step)  # one window from the edges, in grid steps
                    d = d[k:-k, k:-k]
                    means.append(np.nanmean(d))
                    sds.append(np.nanstd(d))
                m, sd = float(np.mean(means)), float(np.mean(sds))
                print(f"| {method} | {w} | {h} | {3 - h:.1f} | {m:.3f} | {m - (3 - h):+.3f} | {sd:.3f} |")


if __name__ == "__main__":
    main()
