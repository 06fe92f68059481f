"""Timings of the TIN kernels against the tools a user would otherwise use,
in the same run: scipy.spatial.Delaunay (Qhull) and Shewchuk's Triangle
(``triangle``) for Delaunay, ``pydelatin`` for error-bounded terrain meshes,
``scipy.interpolate.griddata(method="linear")`` for gridding. Prints one
Markdown table row per case with the ratio (baseline / ours).

Run: ``python benches/bench_tin.py [--repeat 1] [--huge]`` (``--huge``
also triangulates 2^25 uniform points and reports time and peak RSS; needs
about 10 GB of memory). Reads ../shared/data when present.
"""
from __future__ import annotations

import argparse
import os
import platform
import resource
import time

import numpy as np

import fractalgeo_rs as fg
from fractalgeo_rs.tin import delaunay, grid_from_points, tin_from_dem
from _timing import best_with_result as best

_REPO = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
# ../shared beside the checkout (or beside the folder of worktrees)
SHARED = next((p for p in (os.path.join(_REPO, "..", "shared", "data"), os.path.join(_REPO, "..", "..", "shared", "data"))
               if os.path.isdir(p)), "")


def row(case, ours, base_name, base):
    ratio = f"{base / ours:.1f}x" if base else "-"
    bt = f"{base:.2f} s" if base else "-"
    print(f"| {case} | {ours:.2f} s | {base_name} {bt} | {ratio} | {os.getloadavg()[0]:.1f} |", flush=True)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--huge", action="store_true")
    ap.add_argument("--only", choices=("delaunay", "tin", "grid"), default=None)
    args = ap.parse_args()
    r = args.repeat
    print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores; "
          f"{time.strftime('%Y-%m-%d %H:%M')}; load average {os.getloadavg()[0]:.1f}")
    print("| case | fractalgeo_rs | baseline | ratio | load |\n|---|---|---|---|---|")
    from scipy.interpolate import griddata
    from scipy.spatial import Delaunay

    try:
        import triangle
    except ImportError:
        triangle = None
    rng = np.random.default_rng(0)
    if args.only in (None, "delaunay"):
        pts = rng.uniform(0, 1, (1_000_000, 2))
        t_ours, tri = best(lambda: delaunay(pts), r)
        t_qh, _ = best(lambda: Delaunay(pts), 1)
        row("Delaunay 10^6 uniform points", t_ours, "scipy.spatial.Delaunay", t_qh)
        if triangle is not None:
            t_tr, _ = best(lambda: triangle.triangulate({"vertices": pts}, "Q"), r)
            row("Delaunay 10^6 uniform points", t_ours, "triangle", t_tr)
        yy, xx = np.mgrid[0:1024, 0:1024]
        grid = np.column_stack([xx.ravel(), yy.ravel()]).astype(float)
        t_ours, _ = best(lambda: delaunay(grid), r)
        t_qh, _ = best(lambda: Delaunay(grid), 1)
        row("Delaunay 1024² grid points", t_ours, "scipy.spatial.Delaunay", t_qh)
        if triangle is not None:
            t_tr, _ = best(lambda: triangle.triangulate({"vertices": grid}, "Q"), r)
            row("Delaunay 1024² grid points", t_ours, "triangle", t_tr)

    if args.only in (None, "tin"):
        # error-bounded TINs at 1024²
        try:
            from pydelatin import Delatin
        except ImportError:
            Delatin = None
        dems = []
        s = np.asarray(fg.fbm_surface((1024, 1024), hurst=0.5, seed=1, cell_size=10.0), dtype=np.float64)
        dems.append(("fBm H=0.5 1024², relief 1000", (s - s.min()) / (s.max() - s.min()) * 1000.0, 10.0))
        path = os.path.join(SHARED, "bigtujunga_30m.tif")
        if os.path.exists(path):
            z, _ = fg.read_raster(path)
            z = np.asarray(z, dtype=np.float64)[:1024, :1024]
            dems.append((f"bigtujunga 30 m {z.shape[0]}x{z.shape[1]}", z, 30.0))
        for name, z, _cell in dems:
            for err in (1.0, 10.0):
                t_ours, t = best(lambda: tin_from_dem(z, max_error=err, tile_edges="free"), r)
                t_sh, ts = best(lambda: tin_from_dem(z, max_error=err), r)
                if Delatin is not None:
                    z32 = z.astype(np.float32)
                    t_d, d = best(lambda: Delatin(z32, width=z.shape[1], height=z.shape[0], max_error=err), r)
                    nd = len(d.vertices)
                else:
                    t_d, nd = None, "-"
                row(f"TIN {name}, max_error {err:g}: {len(t.vertices)} vertices (free), "
                    f"{len(ts.vertices)} (shared, {t_sh:.2f} s), pydelatin {nd}", t_ours, "pydelatin", t_d)

    if args.only in (None, "grid"):
        # gridding 10^5 points to 1024²
        p = rng.uniform(0, 1024, (100_000, 2))
        v = np.sin(p[:, 0] / 50) + np.cos(p[:, 1] / 30)
        tr = (0.0, 1.0, 0.0, 1024.0, 0.0, -1.0)
        cc, rr = np.meshgrid(np.arange(1024) + 0.5, 1024 - (np.arange(1024) + 0.5))
        t_lin, _ = best(lambda: griddata(p, v, (cc, rr), method="linear"), 1)
        for m in ("natural", "natural_c1", "linear"):
            t_ours, _ = best(lambda: grid_from_points(p, v, (1024, 1024), tr, method=m), r)
            row(f"gridding 10^5 points to 1024², {m}", t_ours, "griddata linear", t_lin)

    if args.huge:
        n = 1 << 25
        big = rng.uniform(0, 1, (n, 2))
        rss0 = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2**20
        t0 = time.perf_counter()
        tb = delaunay(big)
        dt = time.perf_counter() - t0
        rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2**20
        print(f"| Delaunay 2^25 uniform points: {len(tb)} triangles, peak RSS {rss:.1f} GiB "
              f"(before {rss0:.1f} GiB) | {dt:.1f} s | scipy: fails above 2^24 (scipy issue 4985) | - | "
              f"{os.getloadavg()[0]:.1f} |")


if __name__ == "__main__":
    main()
