"""Box counting with no options on exact fractals cropped, offset and
padded: ``fractalgeo_rs.box_counting(set)`` against Moisy's ``boxcount``
algorithm (MATLAB File Exchange 13063: the image padded with zeros to the
next power of 2, boxes of side 1, 2, 4, ... up to that side, a line fitted
through every size), re-implemented here in numpy.

Sets: Sierpinski triangle (side 1024, D = log2 3), Sierpinski carpet and
Vicsek set (side 729, D = log3 8, log3 5), each whole, cropped to 90 % of its
side, offset by (37, 11) pixels inside an array of its side, and padded by
100 pixels; the triadic Koch curve (D = log3 4) rasterised at widths 500,
1000 and 2000 (finite sampling sets the smallest scale).

Point sets (second table): ``fractalgeo_rs.box_counting_points(points)``
with no options on chaos-game samples (``IFS.preset(name).chaos_game(n,
seed)``, 10^5 points for seeds 1-3 and 10^6 for seed 1) of the Sierpinski
triangle, carpet, triadic Koch curve and Vicsek set, against what a user of
Moisy's ``boxcount`` would do: rasterise the points on a 1024 x 1024 grid
over the square around their bounding box and count that image.

Run: ``python benches/accuracy_boxcount_defaults.py [--no-points]`` (about
half a minute with the point sets); prints Markdown.
"""
from __future__ import annotations

import math
import os
import sys
import warnings

import numpy as np

import fractalgeo_rs as fg
import fractalgeo_rs.lsystem  # noqa: F401  (rasterize_points)

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests"))
from fractals import sierpinski_carpet, sierpinski_triangle, triadic_koch_curve  # noqa: E402


def vicsek(level: int) -> np.ndarray:
    a = np.ones((1, 1), dtype=bool)
    for _ in range(level):
        z = np.zeros_like(a)
        a = np.block([[z, a, z], [a, a, a], [z, a, z]])
    return a


def moisy_boxcount(mask: np.ndarray) -> float:
    """Moisy's algorithm: pad to 2^p, count occupied boxes of side 2^k,
    D = -slope of log n against log r over every size."""
    p = int(math.ceil(math.log2(max(mask.shape))))
    side = 2**p
    c = np.zeros((side, side), dtype=bool)
    c[: mask.shape[0], : mask.shape[1]] = mask
    r, n = [], []
    for k in range(p + 1):
        s = 2**k
        blocks = c.reshape(side // s, s, side // s, s).any(axis=(1, 3))
        r.append(s)
        n.append(np.count_nonzero(blocks))
    slope = np.polyfit(np.log(r), np.log(n), 1)[0]
    return -slope


def cases():
    out = []
    for name, a, d in (("Sierpinski triangle 1024", sierpinski_triangle(10), math.log2(3)),
                       ("Sierpinski carpet 729", sierpinski_carpet(6), math.log(8, 3)),
                       ("Vicsek 729", vicsek(6), math.log(5, 3))):
        n = a.shape[0]
        m = int(0.9 * n)
        out.append((name, a, d))
        out.append((name + ", cropped to 90 %", a[:m, :m], d))
        out.append((name + ", offset (37, 11)", np.pad(a, ((37, 0), (11, 0)))[:n, :n], d))
        out.append((name + ", padded by 100", np.pad(a, 100), d))
    for w in (500, 1000, 2000):
        out.append((f"triadic Koch curve, width {w}", triadic_koch_curve(7, w), math.log(4, 3)))
    return out


POINT_SETS = ("sierpinski_triangle", "sierpinski_carpet", "koch_curve", "vicsek")


def moisy_points(points: np.ndarray, side: int = 1024) -> float:
    """Moisy's algorithm on the points rasterised on ``side x side`` cells
    over the square around their bounding box."""
    lo = points.min(axis=0)
    e = float((points.max(axis=0) - lo).max())
    mask = fg.lsystem.rasterize_points(points, side, bounds=(lo[0], lo[0] + e, lo[1], lo[1] + e))
    return moisy_boxcount(mask.astype(bool))


def point_table() -> None:
    print("\n| set | points | seed | true D | box_counting_points() | error | base, lattice | sizes "
          "| Moisy on 1024² raster | error |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    errs, merrs = [], []
    for name in POINT_SETS:
        ifs = fg.IFS.preset(name)
        d = ifs.dimension
        for n, seed in ((10**5, 1), (10**5, 2), (10**5, 3), (10**6, 1)):
            pts = ifs.chaos_game(n, seed=seed)
            f = fg.box_counting_points(pts)
            m = moisy_points(pts)
            errs.append(abs(f.dimension - d))
            merrs.append(abs(m - d))
            lat = f"{f.extra.get('base', '-')} {f.extra.get('lattice', '-')}"
            print(f"| {name} | {n:.0e} | {seed} | {d:.4f} | {f.dimension:.4f} | {f.dimension - d:+.4f} | {lat} "
                  f"| {int(np.count_nonzero(f.used))} | {m:.4f} | {m - d:+.4f} |", flush=True)
    print(f"\nmax |error|: box_counting_points {max(errs):.4f}, Moisy on the raster {max(merrs):.4f}; "
          f"within 0.02: {sum(e <= 0.02 for e in errs)} of {len(errs)} and {sum(e <= 0.02 for e in merrs)} "
          f"of {len(merrs)}")


def main() -> None:
    warnings.simplefilter("ignore")
    print("| set | true D | box_counting() | error | sizes (fitted) | lattice | Moisy boxcount | error |")
    print("|---|---|---|---|---|---|---|---|")
    errs, merrs = [], []
    for name, a, d in cases():
        f = fg.box_counting(a)
        m = moisy_boxcount(a)
        errs.append(abs(f.dimension - d))
        merrs.append(abs(m - d))
        sz = f.scales[f.used].astype(int)
        lat = f"{f.extra.get('lattice', 'kernel')}, base {f.extra.get('base', '-')}"
        print(f"| {name} | {d:.4f} | {f.dimension:.4f} | {f.dimension - d:+.4f} | {sz[0]}..{sz[-1]} ({len(sz)}) "
              f"| {lat} | {m:.4f} | {m - d:+.4f} |")
    print(f"\nmax |error|: box_counting {max(errs):.4f}, Moisy {max(merrs):.4f}; "
          f"within 0.02: {sum(e <= 0.02 for e in errs)} of {len(errs)} and {sum(e <= 0.02 for e in merrs)} of {len(merrs)}")
    if "--no-points" not in sys.argv[1:]:
        point_table()


if __name__ == "__main__":
    main()
