"""Accuracy of the estimators on exact fractals with known dimension.

Prints a Markdown table (estimate and error per method and set) for
``docs/accuracy.md``. The sets are built from their definitions by the test
helpers (``tests/fractals.py``, ``tests/test_estimators.py``), independently
of the estimators. Run: ``python benches/accuracy_exact_sets.py``.
"""
from __future__ import annotations

import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests"))

import fractalgeo_rs as fg  # noqa: E402
from fractals import (  # noqa: E402
    cantor_dust,
    quadratic_koch_curve,
    sierpinski_carpet,
    sierpinski_triangle,
    triadic_koch_curve,
)
from test_estimators import dragon_boundary, weierstrass_mandelbrot  # noqa: E402


def main() -> None:
    root = np.roots([1, -1, 0, -2])
    d_dragon = 2.0 * float(np.log2(root[np.isreal(root)].real[0]))
    sets = [
        ("Sierpinski triangle, 2^10 grid", sierpinski_triangle(10), np.log(3) / np.log(2)),
        ("Sierpinski carpet, 3^6 grid", sierpinski_carpet(6), np.log(8) / np.log(3)),
        ("Cantor dust, 3^6 grid", cantor_dust(6), 2 * np.log(2) / np.log(3)),
        ("quadratic Koch curve, level 6", quadratic_koch_curve(6), np.log(5) / np.log(3)),
        ("triadic Koch curve, level 7, 2187 px", triadic_koch_curve(7, 2187), np.log(4) / np.log(3)),
        ("Heighway dragon boundary, level 16", dragon_boundary(16), d_dragon),
    ]
    set_methods = [
        ("box counting", lambda m: fg.box_counting(m).dimension),
        ("Minkowski sausage", lambda m: fg.minkowski(m).dimension),
        ("P(m,L) mass", lambda m: fg.mass_dimension(m).dimension),
    ]
    print("| set | D | " + " | ".join(n for n, _ in set_methods) + " |")
    print("|---|---|" + "---|" * len(set_methods))
    for name, m, d in sets:
        cells = []
        for _, f in set_methods:
            try:
                e = f(m)
                cells.append(f"{e:.4f} ({e - d:+.4f})")
            except ValueError as err:
                cells.append(f"n/a ({err})")
        print(f"| {name} | {d:.4f} | " + " | ".join(cells) + " |")

    graph_methods = [
        ("variogram, lags 1-16", lambda z: fg.variogram(z, lags=range(1, 17)).dimension),
        ("madogram, lags 1-16", lambda z: fg.madogram(z, lags=range(1, 17)).dimension),
        ("variogram, lags 1-2", lambda z: fg.variogram(z).dimension),
        ("Higuchi", lambda z: fg.higuchi(z).dimension),
        ("wavelet", lambda z: fg.wavelet_dimension(z).dimension),
        ("scale space", lambda z: fg.scale_space(z).dimension),
    ]
    print()
    print("| Weierstrass-Mandelbrot graph, n = 4096, gamma = 1.5 | D = 2 - H | "
          + " | ".join(n for n, _ in graph_methods) + " |")
    print("|---|---|" + "---|" * len(graph_methods))
    for h in (0.3, 0.5, 0.7):
        z = weierstrass_mandelbrot(4096, h)
        d = 2 - h
        cells = [f"{f(z):.4f} ({f(z) - d:+.4f})" for _, f in graph_methods]
        print(f"| H = {h} | {d:.1f} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
