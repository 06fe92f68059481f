"""Rays per CPU second of the mesh ray caster (``Scene.from_mesh``, an
``obvhs`` CWBVH with exact float64 triangle tests) against Embree (through
``embreex``) on the same ~2 M-triangle fBm terrain mesh, in the same run.

Our side: ``Scene.brf`` with single scattering, one thread, a nadir sensor
and the sun at 30 degrees: every path is one primary ray (closest hit) and,
when the facet faces the sun, one shadow ray (any hit), plus the path's
random numbers and BSDF evaluation. Embree's side: the same number of
primary rays straight down from uniform points of the footprint
(``INTERSECT``), then one shadow ray towards the sun from each hit point
(``OCCLUDED``), on one thread (``embreex`` loops over single rays). Rays per
CPU second are counted as (primary + shadow rays) / CPU seconds; the BVH
builds are timed separately. Ratio = Embree / ours (rays per second).

Run: ``python benches/bench_radiometry_mesh.py [--n 1000] [--paths 400000]``
(``pip install embreex``).
"""
from __future__ import annotations

import argparse
import os
import platform
import time

import numpy as np

import fractalgeo_rs as fg
from fractalgeo_rs.geometry import GeoGrid, Mesh
from fractalgeo_rs.radiometry import Lambertian, Scene


def cpu(fn):
    t0 = time.process_time()
    out = fn()
    return out, time.process_time() - t0


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=1000, help="grid side: 2 (n-1)^2 triangles")
    ap.add_argument("--paths", type=int, default=400_000)
    args = ap.parse_args()
    n = args.n
    z = fg.fbm_surface((n, n), 0.7, method="spectral", periodic=True, seed=1, sigma=1.0)
    z *= 0.5 / np.sqrt(np.mean(np.diff(z, axis=1) ** 2))  # RMS slope 0.5 along rows (1 m cells)
    mesh = Mesh.from_grid(z, grid=GeoGrid((0.0, float(n)), 1.0))
    v = mesh.map_vertices().astype(np.float64)
    f = np.asarray(mesh.faces, dtype=np.int64)
    print(f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores; mesh of {len(mesh):,} triangles "
          f"({n} x {n} fBm grid)")

    sun_zen = 30.0
    # ours: build, then single-scattering paths on one thread
    scene, t_build = cpu(lambda: Scene.from_mesh(mesh, materials=Lambertian(0.5), periodic=False))
    scene.brf(sun=(0.0, sun_zen), spp=2000, max_depth=1, n_threads=1)  # warm up
    e, t_ours = cpu(lambda: scene.brf(sun=(0.0, sun_zen), spp=args.paths, max_depth=1, n_threads=1))

    # the same rays through Embree: primary rays down, shadow rays to the sun
    try:
        from embreex import rtcore_scene
        from embreex.mesh_construction import TriangleMesh
    except ImportError:
        print(f"ours: build {t_build:.2f} s; {args.paths / t_ours / 1e6:.2f} M paths per CPU second "
              "(embreex not installed: pip install embreex)")
        return
    # Embree in float32 about the mesh's centre (as our frame is the mesh's origin)
    centre = v.mean(axis=0)
    vf = (v - centre).astype(np.float32)

    def build():
        sc = rtcore_scene.EmbreeScene()
        TriangleMesh(sc, vf, f.astype(np.int32))
        return sc

    sc, t_ebuild = cpu(build)
    rng = np.random.default_rng(0)
    lo, hi = v.min(axis=0), v.max(axis=0)
    m = args.paths
    org = np.empty((m, 3), np.float32)
    org[:, 0] = rng.uniform(lo[0], hi[0], m) - centre[0]
    org[:, 1] = rng.uniform(lo[1], hi[1], m) - centre[1]
    org[:, 2] = hi[2] - centre[2] + 1.0
    down = np.tile(np.array([0.0, 0.0, -1.0], np.float32), (m, 1))
    sc.run(org[:1000], down[:1000])  # warm up (commits the scene)

    def embree_rays():
        out = sc.run(org, down, output=1)
        hit = out["geomID"] >= 0
        t = out["tfar"][hit]
        p = org[hit] + t[:, None] * down[hit]
        s = np.array([0.0, np.sin(np.radians(sun_zen)), np.cos(np.radians(sun_zen))], np.float32)
        ng = out["Ng"][hit]
        lit = (ng @ s) * np.sign(-ng[:, 2]) < 0  # Embree's Ng is not normalised nor oriented up
        p = p[lit] + 1e-3 * s
        occ = sc.run(p.astype(np.float32), np.tile(s, (len(p), 1)), query="OCCLUDED")
        return int(hit.size), int(len(p)), occ

    (n_primary, n_shadow, _), t_embree = cpu(embree_rays)
    ours_rays = m + n_shadow  # the same scene and sun: the same share of lit facets (up to sampling)
    r_ours = ours_rays / t_ours
    r_embree = (n_primary + n_shadow) / t_embree
    print("| | BVH build (CPU s) | rays | CPU s | M rays per CPU second |")
    print("|---|---|---|---|---|")
    print(f"| ours (obvhs CWBVH, f64 tests, with path tracing) | {t_build:.2f} | {ours_rays:,} | {t_ours:.2f} | "
          f"{r_ours / 1e6:.2f} |")
    print(f"| Embree (embreex, rays only) | {t_ebuild:.2f} | {n_primary + n_shadow:,} | {t_embree:.2f} | "
          f"{r_embree / 1e6:.2f} |")
    print(f"ratio Embree / ours: {r_embree / r_ours:.2f} (goal <= 2); BRF {e.value:.4f} +- {e.se:.4f}")


if __name__ == "__main__":
    main()
