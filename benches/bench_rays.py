"""Ray throughput of the heightfield ray caster against Embree (``embreex``) on the same triangles.

Prints primary, shadow and bounce rays per CPU second on one thread for

* the periodic 32 x 32 fBm tile of the radiometric experiment (1 m cells; Embree gets the tile
  repeated 9 x 9, 166 k triangles, as Mitsuba does, because it has no periodic scenes);
* a periodic 1024 x 1024 fBm DEM (the same ``sigma``; Embree gets the tile once, 2.1 M
  triangles, so its rays that would wrap around leave the scene instead);
* a real 1024 x 1024 DEM, the SRTM tile N44E007 (Maritime Alps, 3" cells, about 66 x 92 m), as a
  non-periodic patch, when ``/work/shared/data/N44E007.hgt`` or ``--hgt`` is there.

The rays are those of the path tracer: primary rays from above the surface through uniform points
of the tile, at nadir and at 45 degrees zenith, in the order an image is rendered (pixel rows,
4 jittered samples per pixel), and at nadir in random order (the worst case for the caches; the
BRF estimator draws its points so); shadow rays from the image-order nadir hits towards a sun at
30 degrees zenith (only from facets facing it); bounce rays from the same hits, cosine-distributed
about the facet normal. Our calls build the heightfield each time (a few ms for 1024 x 1024): that
build is timed with one ray and subtracted, as Embree's build is timed apart. Ours start on their facet and ignore it (``skip``); Embree's start 1e-4 m
above it along the normal (float32; more at large coordinates, where
1e-4 is below float32 rounding). Both are timed on the same arrays, inputs and outputs
included, with one thread (``n_threads=1``; Embree's ``run`` is single-threaded), and the hit/miss
agreement of the two is printed as a check.

Run: ``python benches/bench_rays.py [--n 1000000] [--no-embree]``.
``pip install embreex`` for the baseline.
"""
from __future__ import annotations

import argparse
import os
import platform
import time

import numpy as np

import fractalgeo_rs as fg
from fractalgeo_rs import _core

HGT = "/work/shared/data/N44E007.hgt"


def cpu_time(fn, repeat=3):
    """(least CPU seconds of ``repeat`` calls, the last result)."""
    best, out = np.inf, None
    for _ in range(repeat):
        c0 = time.process_time()
        out = fn()
        best = min(best, time.process_time() - c0)
    return best, out


def unit(v):
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def direction(az, zen):
    a, z = np.radians(az), np.radians(zen)
    return np.array([np.sin(a) * np.sin(z), np.cos(a) * np.sin(z), np.cos(z)])


def cosine_dirs(normals, rng):
    """Cosine-weighted directions about unit ``normals`` (Malley)."""
    u1, u2 = rng.random(len(normals)), rng.random(len(normals))
    r, phi = np.sqrt(u1), 2 * np.pi * u2
    local = np.stack([r * np.cos(phi), r * np.sin(phi), np.sqrt(1 - u1)], 1)
    t = unit(np.cross(np.where(np.abs(normals[:, :1]) < 0.9, [[1.0, 0, 0]], [[0, 1.0, 0]]), normals))
    b = np.cross(normals, t)
    return unit(local[:, :1] * t + local[:, 1:2] * b + local[:, 2:3] * normals)


def triangles(z, cell, periodic, reps):
    """The NE-SW facets as float32 (m, 3, 3): the tile repeated ``reps`` x ``reps`` around the
    base tile (periodic), or the patch (not periodic)."""
    dx, dy = cell
    if periodic:
        n0, n1 = z.shape
        half = reps // 2
        r, c = np.mgrid[0:n0 * reps + 1, 0:n1 * reps + 1]
        zz = z[(r - half * n0) % n0, (c - half * n1) % n1]
        x, y = (c - half * n1) * dx, -(r - half * n0) * dy
    else:
        r, c = np.mgrid[0:z.shape[0], 0:z.shape[1]]
        zz, x, y = z, c * dx, -r * dy
    v = np.stack([x, y, zz], -1).astype(np.float32)
    nw, ne, sw, se = v[:-1, :-1], v[:-1, 1:], v[1:, :-1], v[1:, 1:]
    return np.concatenate([np.stack([nw, sw, ne], -2).reshape(-1, 3, 3),
                           np.stack([ne, sw, se], -2).reshape(-1, 3, 3)])


def image_order(n, w, h, rng, spp=4):
    """``n`` points of the tile in the order an image is rendered: pixel rows, ``spp`` jittered
    samples per pixel."""
    side = max(1, int(np.sqrt(n / spp)))
    k = np.arange(side * side * spp) // spp
    i, j = k // side, k % side
    return np.stack([(j + rng.random(k.size)) * w / side, -(i + rng.random(k.size)) * h / side], 1)


def ray_sets(z, cell, periodic, n, rng):
    """Primary rays (nadir in random order and in image order, 45 deg in image order), shadow and
    bounce rays from the image-order nadir hits: dicts of origins, directions, skip."""
    dx, dy = cell
    rows, cols = z.shape
    w, h = (cols if periodic else cols - 1) * dx, (rows if periodic else rows - 1) * dy
    top = z.max() + 1e-3
    args = (z, cell, periodic, "ne-sw")
    sets = {}
    rand = np.stack([rng.random(n) * w, -rng.random(n) * h], 1)
    img = image_order(n, w, h, rng)
    for label, zen, xy in [("primary nadir, random order", 0.0, rand), ("primary nadir", 0.0, img),
                           ("primary 45 deg", 45.0, img)]:
        v = direction(90.0, zen)
        p = np.column_stack([xy, np.full(len(xy), top)])
        sets[label] = dict(o=p, d=np.tile(-v, (len(xy), 1)), skip=None)
    prim = sets["primary nadir"]
    t, facet, normal = _core.radiometry_intersect(*args, prim["o"], prim["d"], None, 2)
    ok = facet >= 0
    p, facet, normal = prim["o"][ok] + t[ok, None] * prim["d"][ok], facet[ok], normal[ok]
    s = direction(90.0, 30.0)
    lit = normal @ s > 0
    sets["shadow"] = dict(o=p[lit], d=np.tile(s, (lit.sum(), 1)), skip=facet[lit], normal=normal[lit])
    sets["bounce"] = dict(o=p, d=cosine_dirs(normal, rng), skip=facet, normal=normal)
    return sets


def run_case(name, z, cell, periodic, n, embree, reps, rng):
    print(f"\n### {name}: {z.shape[0]} x {z.shape[1]} heights, cells {cell[0]:g} x {cell[1]:g} m, "
          f"{'periodic' if periodic else 'not periodic'}, relief {np.ptp(z):.1f} m")
    t0 = time.perf_counter()
    sets = ray_sets(z, cell, periodic, n, rng)
    print(f"(rays prepared in {time.perf_counter() - t0:.1f} s)")
    args = (z, cell, periodic, "ne-sw")
    scene = None
    if embree is not None:
        rtcs, TriangleMesh = embree
        tri = triangles(z, cell, periodic, reps)
        c0 = time.process_time()
        scene = rtcs.EmbreeScene()
        TriangleMesh(scene, tri)
        scene.run(np.zeros((1, 3), np.float32), np.array([[0, 0, -1.0]], np.float32))  # commit (BVH build)
        print(f"Embree: {len(tri) / 1e6:.2f} M triangles ({reps} x {reps} tiles)" if periodic
              else f"Embree: {len(tri) / 1e6:.2f} M triangles", f"built in {time.process_time() - c0:.2f} CPU s")
    out = {}
    # every call builds the heightfield (linear in the cells): time it with one ray, subtract it
    one = (np.array([[0.5 * cell[0], -0.5 * cell[1], z.max() + 1.0]]), np.array([[0.0, 0.0, -1.0]]))
    build, _ = cpu_time(lambda: _core.radiometry_intersect(*args, *one, None, 1), repeat=5)
    print(f"(our per-call build: {1e3 * build:.1f} CPU ms, subtracted below)")
    print("| rays | n | ours M rays/CPU s | hit (or occluded) % | Embree M rays/CPU s | Embree hit % "
          "| agree % | ours / Embree |")
    print("|---|---|---|---|---|---|---|---|")
    for label, rs in sets.items():
        m = len(rs["o"])
        if label == "shadow":
            c, res = cpu_time(lambda: _core.radiometry_occluded(*args, rs["o"], rs["d"], rs["skip"], 1))
            hit = res
        else:
            c, res = cpu_time(lambda: _core.radiometry_intersect(*args, rs["o"], rs["d"], rs["skip"], 1))
            hit = res[1] >= 0
        ours = m / max(c - build, 1e-9) / 1e6
        out[label] = ours
        cells = f"| {label} | {m} | {ours:.2f} | {100 * hit.mean():.1f} |"
        if scene is not None:
            o = rs["o"]
            if "normal" in rs:
                # above float32 rounding at these coordinates, or Embree hits the start facet
                o = o + (1e-4 + 4e-7 * np.abs(o).max()) * rs["normal"]
            o32, d32 = o.astype(np.float32), rs["d"].astype(np.float32)
            if label == "shadow":
                ce, r = cpu_time(lambda: scene.run(o32, d32, query="OCCLUDED"))
            else:
                ce, r = cpu_time(lambda: scene.run(o32, d32))
            ehit = np.asarray(r) >= 0
            emb = m / ce / 1e6
            cells += f" {emb:.2f} | {100 * ehit.mean():.1f} | {100 * (ehit == hit).mean():.2f} | {ours / emb:.1f}x |"
        else:
            cells += " - | - | - | - |"
        print(cells, flush=True)
    return out


def load_hgt(path, size=1024):
    z = np.fromfile(path, dtype=">i2").astype(np.float64)
    side = int(round(np.sqrt(z.size)))
    z = z.reshape(side, side)[:size, :size]
    void = z < -1000
    z[void] = np.median(z[~void])  # 0.6 % voids; a bench only needs finite heights
    return z


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=1_000_000, help="rays per set")
    ap.add_argument("--no-embree", action="store_true")
    ap.add_argument("--hgt", default=HGT)
    a = ap.parse_args()
    print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores; "
          f"{time.strftime('%Y-%m-%d %H:%M')}; load average {os.getloadavg()[0]:.2f}; one thread per run")
    embree = None
    if not a.no_embree:
        try:
            from embreex import rtcore_scene as rtcs
            from embreex.mesh_construction import TriangleMesh

            embree = (rtcs, TriangleMesh)
        except ImportError as exc:
            print(f"embreex unavailable: {exc}")
    rng = np.random.default_rng(7)
    goals = {"32": (15, 8, 5), "1024": (10, 3, 3)}
    res = {}
    z32 = fg.fbm_surface((32, 32), 0.7, method="spectral", periodic=True, seed=1, sigma=0.5)
    res["32"] = run_case("periodic fBm tile (the experiment's)", z32, (1.0, 1.0), True, a.n, embree, 9, rng)
    z1k = fg.fbm_surface((1024, 1024), 0.7, method="spectral", periodic=True, seed=2, sigma=0.5)
    res["1024"] = run_case("periodic fBm DEM", z1k, (1.0, 1.0), True, a.n, embree, 1, rng)
    if os.path.exists(a.hgt):
        zr = load_hgt(a.hgt)
        res["real"] = run_case("SRTM N44E007 rows 0:1024, cols 0:1024 (Alps)", zr, (66.0, 92.0), False,
                               a.n, embree, 1, rng)
    print("\ngoals (M rays per CPU second: primary, shadow, bounce):")
    for k, g in goals.items():
        r = res[k]
        got = (r["primary nadir"], r["shadow"], r["bounce"])
        print(f"  {k} x {k}: goal {g}, measured ({got[0]:.1f}, {got[1]:.1f}, {got[2]:.1f}) -> "
              + ", ".join("met" if x >= y else "NOT met" for x, y in zip(got, g)))


if __name__ == "__main__":
    main()
