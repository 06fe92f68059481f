"""Accuracy of Higuchi's estimator against its largest interval ``k_max``.

Bias and RMSE of D on exact fBm profiles (``fractalgeo_rs.fbm(n, H,
method="exact")``, true D = 2 - H) for several ``k_max``, per length ``n``;
the table that sets the default ``k_max`` of :func:`fractalgeo_rs.higuchi`.

Run: ``python benches/accuracy_higuchi.py --reps 100`` (about a minute on
2 cores); prints Markdown.
"""
from __future__ import annotations

import argparse
import warnings

import numpy as np

import fractalgeo_rs as fg


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--reps", type=int, default=100)
    ap.add_argument("--sizes", default="256,1024,4096")
    ap.add_argument("--kmax", default="4,6,8,10,16,32,64")
    ap.add_argument("--hs", default="0.1,0.3,0.5,0.7,0.9")
    args = ap.parse_args()
    sizes = [int(v) for v in args.sizes.split(",")]
    kms = [int(v) for v in args.kmax.split(",")]
    hs = [float(v) for v in args.hs.split(",")]
    warnings.simplefilter("ignore", fg.FractalRangeWarning)
    print(f"Higuchi on exact fBm, {args.reps} profiles per cell: RMSE of D (bias in brackets)\n")
    for n in sizes:
        ks = [k for k in kms if k <= n // 10 or k <= 4]
        print(f"n = {n}\n")
        print("| H | " + " | ".join(f"k_max={k}" for k in ks) + " |")
        print("|---|" + "---|" * len(ks))
        mean_rmse = np.zeros(len(ks))
        for h in hs:
            est = np.empty((args.reps, len(ks)))
            for r in range(args.reps):
                x = fg.fbm(n, h, seed=1000 * r + n, method="exact")
                est[r] = [fg.higuchi(x, k_max=k).dimension for k in ks]
            err = est - (2 - h)
            rmse = np.sqrt(np.mean(err**2, axis=0))
            mean_rmse += rmse / len(hs)
            print(f"| {h:g} | " + " | ".join(f"{a:.3f} ({b:+.3f})" for a, b in zip(rmse, err.mean(0))) + " |")
        print("| mean | " + " | ".join(f"{a:.3f}" for a in mean_rmse) + " |\n")


if __name__ == "__main__":
    main()
