"""Measured accuracy of the box-counting estimators; writes the tables of
docs/boxcounting.md to stdout (Markdown).

Exact sets come from tests/fractals.py (written from the definitions); the
fBm profiles are exact (Davies-Harte circulant embedding); the surfaces are
spectral 1/f^beta fields (beta = 2H + 2), periodic, 256 x 256.

Run: ``python benches/accuracy_boxcount.py [--seeds 40]``.
"""
from __future__ import annotations

import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests"))

import fractalgeo_rs as fg  # noqa: E402
from fractals import (  # noqa: E402
    cantor_dust,
    fbm_profile,
    menger_sponge,
    quadratic_koch_curve,
    sierpinski_carpet,
    sierpinski_triangle,
    spectral_surface,
    triadic_koch_curve,
)

LN = np.log


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--seeds", type=int, default=40)
    args = ap.parse_args()
    sets = [
        ("Sierpinski triangle 512²", sierpinski_triangle(9), LN(3) / LN(2)),
        ("Sierpinski carpet 729²", sierpinski_carpet(6), LN(8) / LN(3)),
        ("Cantor dust 729²", cantor_dust(6), 2 * LN(2) / LN(3)),
        ("Menger sponge 81³", menger_sponge(4), LN(20) / LN(3)),
        ("filled square 500²", np.ones((500, 500), bool), 2.0),
        ("filled square 613²", np.ones((613, 613), bool), 2.0),
        ("diagonal line 700", np.eye(700, dtype=bool), 1.0),
        ("diagonal line 613", np.eye(613, dtype=bool), 1.0),
        ("quadratic Koch curve L=6 (730 px)", quadratic_koch_curve(6), LN(5) / LN(3)),
        ("triadic Koch curve L=6, 729 px", triadic_koch_curve(6, 729), LN(4) / LN(3)),
        ("triadic Koch curve L=7, 2187 px", triadic_koch_curve(7, 2187), LN(4) / LN(3)),
    ]
    print("### Exact sets, default settings\n")
    print("| set | true D | estimate | error | box sizes |")
    print("|---|---|---|---|---|")
    for name, mask, d in sets:
        fit = fg.box_counting(mask)
        sizes = ", ".join(str(int(s)) for s in fit.scales)
        print(f"| {name} | {d:.4f} | {fit.dimension:.4f} | {fit.dimension - d:+.4f} | {sizes} |")

    print(f"\n### Self-affine box counting on exact fBm profiles (n = 4097, {args.seeds} seeds)\n")
    print("| H | mean H estimate | bias of H | sd | RMSE of D |")
    print("|---|---|---|---|---|")
    for h in (0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9):
        est = np.array([fg.self_affine_box_counting(fbm_profile(4097, h, s)).extra["hurst"] for s in range(args.seeds)])
        print(f"| {h:.1f} | {est.mean():.3f} | {est.mean() - h:+.3f} | {est.std(ddof=1):.3f} | {np.sqrt(np.mean((est - h) ** 2)):.3f} |")

    n_surf = max(5, args.seeds // 4)
    print(f"\n### Surfaces 256² (spectral fBm, {n_surf} seeds): DBC and self-affine boxes\n")
    print("| H | true D | DBC mean D | DBC sd | affine mean D | affine sd |")
    print("|---|---|---|---|---|---|")
    for h in (0.2, 0.3, 0.5, 0.7, 0.8):
        zs = [spectral_surface(256, h, s) for s in range(n_surf)]
        dbc = np.array([fg.differential_box_counting(z).dimension for z in zs])
        aff = np.array([fg.self_affine_box_counting(z).dimension for z in zs])
        print(f"| {h:.1f} | {3 - h:.2f} | {dbc.mean():.3f} | {dbc.std(ddof=1):.3f} | {aff.mean():.3f} | {aff.std(ddof=1):.3f} |")


if __name__ == "__main__":
    main()
