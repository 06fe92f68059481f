"""Accuracy of the fractal-transform maps on exact fBm surfaces: mean and
standard deviation of the local dimension over the interior of the map (one
window away from the edges), per method, H and window.

Fields: ``fbm_surface((512, 512), H, method="exact")``, 4 seeds per H.
Run: ``python benches/accuracy_transform.py`` (Markdown on stdout).
"""
from __future__ import annotations

import numpy as np

import fractalgeo_rs as fg


def main() -> None:
    print("| method | window | H | 3 - H | mean D | bias | sd of D |")
    print("|---|---|---|---|---|---|---|")
    for method in ("square", "variogram", "madogram", "mass"):
        for w in (33, 65):
            for h in (0.3, 0.5, 0.7):
                means, sds = [], []
                for s in range(4):
                    z = fg.fbm_surface((512, 512), h, method="exact", seed=s)
                    kw = {}
                    if method == "mass":  # heights in units of the mean lag-1 increment
                        kw["z_scale"] = float(np.mean(np.abs(np.diff(z, axis=1))))
                    d = fg.fractal_transform(z, w, method=method, **kw)[w:-w, w:-w]
                    means.append(np.nanmean(d))
                    sds.append(np.nanstd(d))
                m, sd = float(np.mean(means)), float(np.mean(sds))
                print(f"| {method} | {w} | {h} | {3 - h:.1f} | {m:.3f} | {m - (3 - h):+.3f} | {sd:.3f} |")


if __name__ == "__main__":
    main()
