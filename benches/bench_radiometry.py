"""Speed of the radiometric experiment and, when ``mitsuba`` is installed,
the same nadir BRF series rendered by Mitsuba 3 in the same run.

Prints the rays (paths) per CPU second of our heightfield path tracer on a
periodic 32 x 32 fBm tile with one thread, and a Markdown table of the nadir
BRF at sun zeniths 0, 15, ..., 75, 89 (single and multiple scattering): our
value and standard error, Mitsuba's value (``scalar_rgb``, ``face_normals``,
``stratified`` sampler, the tile repeated 9 x 9 because Mitsuba has no
periodic scenes), the difference in units of our SE and in %, and the
times with their ratio (Mitsuba / ours, its scene builds included).

Run: ``python benches/bench_radiometry.py [--spp 65536] [--no-mitsuba]``.
Mitsuba: ``pip install mitsuba`` (``scalar_rgb`` needs nothing else).
"""
from __future__ import annotations

import argparse
import os
import platform
import tempfile
import time

import numpy as np

import fractalgeo_rs as fg
from fractalgeo_rs.radiometry import Lambertian, Scene

ZENITHS = [0.0, 15.0, 30.0, 45.0, 60.0, 75.0, 89.0]


def tile(n=32, seed=1):
    return fg.fbm_surface((n, n), 0.7, method="spectral", periodic=True, seed=seed, sigma=0.5)


def cpu(fn):
    t0, c0 = time.perf_counter(), time.process_time()
    out = fn()
    return out, time.perf_counter() - t0, time.process_time() - c0


def ply_tiled(z, cell, reps, path):
    """The NE-SW facets of the periodic tile repeated reps x reps, centred on
    the tile (0..n cells) as a binary PLY in (east, north, up)."""
    n = z.shape[0]
    half = reps // 2
    m = n * reps + 1
    r, c = np.mgrid[0:m, 0:m]
    zz = z[(r - half * n) % n, (c - half * n) % n]
    x = (c - half * n) * cell
    y = -(r - half * n) * cell
    verts = np.stack([x, y, zz], -1).reshape(-1, 3)
    idx = np.arange(m * m).reshape(m, m)
    nw, ne, sw, se = idx[:-1, :-1], idx[:-1, 1:], idx[1:, :-1], idx[1:, 1:]
    faces = np.concatenate([np.stack([nw, sw, ne], -1).reshape(-1, 3), np.stack([ne, sw, se], -1).reshape(-1, 3)])
    face_rec = np.zeros(len(faces), dtype=[("n", "u1"), ("i", "<i4", (3,))])
    face_rec["n"], face_rec["i"] = 3, faces
    with open(path, "wb") as f:
        f.write((f"ply\nformat binary_little_endian 1.0\nelement vertex {len(verts)}\nproperty float x\n"
                 f"property float y\nproperty float z\nelement face {len(faces)}\n"
                 "property list uchar int vertex_indices\nend_header\n").encode())
        f.write(verts.astype("<f4").tobytes())
        f.write(face_rec.tobytes())


def mitsuba_brf(mi, ply, z, cell, rho, sun_zen, spp, max_depth):
    n = z.shape[0]
    w = n * cell
    s = np.array([np.sin(np.radians(sun_zen)), 0.0, np.cos(np.radians(sun_zen))])  # sun in the east
    zref = float(z.mean())
    scene = mi.load_dict({
        "type": "scene",
        "integrator": {"type": "path", "max_depth": max_depth + 1},
        "sun": {"type": "directional", "direction": (-s).tolist(), "irradiance": {"type": "rgb", "value": 1.0}},
        "surface": {"type": "ply", "filename": ply, "face_normals": True,
                    "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": rho}}},
        "sensor": {"type": "distant", "direction": [0.0, 0.0, -1.0],
                   "target": {"type": "rectangle",
                              "to_world": mi.ScalarTransform4f().translate([w / 2, -w / 2, zref]).scale([w / 2, w / 2, 1])},
                   "sampler": {"type": "stratified", "sample_count": spp},
                   "film": {"type": "hdrfilm", "width": 1, "height": 1, "pixel_format": "luminance",
                            "rfilter": {"type": "box"}}},
    })
    img = np.array(mi.render(scene, spp=spp))
    return np.pi * float(img.ravel()[0]) / np.cos(np.radians(sun_zen))


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--spp", type=int, default=65536)
    ap.add_argument("--no-mitsuba", action="store_true")
    ap.add_argument("--rho", type=float, default=0.5)
    ap.add_argument("--ref-spp", type=int, default=1 << 22,
                    help="paths of our reference value that Mitsuba is compared with")
    args = ap.parse_args()
    print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores; "
          f"{time.strftime('%Y-%m-%d %H:%M')}; load average {os.getloadavg()[0]:.1f}")
    z, cell = tile(), 1.0
    scene = Scene.from_dem(z, cell_size=cell, material=Lambertian(args.rho))

    # paths per second on one thread (wall) and per CPU second
    n = 2_000_000
    for label, sun, depth in [("single scattering, sun 30 deg (1 primary + 1 shadow ray)", (90.0, 30.0), 1),
                              ("multiple scattering, max_depth 10", (90.0, 30.0), 10)]:
        _, wall, c = cpu(lambda: scene.brf(sun=sun, spp=n, max_depth=depth, n_threads=1))
        print(f"{label}: {n / wall / 1e6:.2f} M paths/s on one thread, {n / c / 1e6:.2f} M per CPU second")
    _, wall, c = cpu(lambda: scene.albedo(sun=(90.0, 30.0), spp=n, max_depth=1, n_threads=1))
    print(f"albedo, max_depth 1 (a sun ray and an escape ray): {n / wall / 1e6:.2f} M paths/s on one thread, "
          f"{n / c / 1e6:.2f} M per CPU second")
    big = Scene.from_dem(fg.fbm_surface((1024, 1024), 0.7, method="spectral", periodic=True, seed=2, sigma=0.5),
                         material=Lambertian(args.rho))
    _, wall, c = cpu(lambda: big.brf(sun=(90.0, 30.0), spp=n, max_depth=1, n_threads=1))
    print(f"1024 x 1024 DEM, single scattering: {n / wall / 1e6:.2f} M paths/s on one thread, "
          f"{n / c / 1e6:.2f} M per CPU second")

    mi = None
    if not args.no_mitsuba:
        try:
            import mitsuba as mi

            mi.set_variant("scalar_rgb")
        except Exception as exc:  # not installed, or no variant
            print(f"mitsuba unavailable: {exc}")
            mi = None
    print(f"\nnadir BRF, rho = {args.rho}, {args.spp} samples per angle, sun in the east; "
          "times are CPU seconds")
    print(f"ours: at the same number of samples (timed) and at {args.ref_spp} paths (the reference); "
          "diff = Mitsuba - reference")
    print("| sun zenith | depth | ours (SE) | ours CPU s | reference (SE) | Mitsuba | diff / SE | diff % "
          "| Mitsuba CPU s | ratio |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as d:
        ply = os.path.join(d, "tile9x9.ply")
        if mi is not None:
            ply_tiled(z, cell, 9, ply)
        for depth in (1, 10):
            for zen in ZENITHS:
                e, _, c = cpu(lambda: scene.brf(sun=(90.0, zen), spp=args.spp, max_depth=depth))
                ref = scene.brf(sun=(90.0, zen), spp=args.ref_spp, max_depth=depth, seed=1)
                mcell = "- | - | - | - | -"
                if mi is not None:
                    m, _, mc = cpu(lambda: mitsuba_brf(mi, ply, z, cell, args.rho, zen, args.spp, depth))
                    mcell = (f"{m:.5f} | {(m - ref.value) / ref.se:+.1f} | {100 * (m - ref.value) / ref.value:+.2f} | "
                             f"{mc:.2f} | {mc / c:.1f}x")
                print(f"| {zen:.0f} | {depth} | {e.value:.5f} ({e.se:.5f}) | {c:.3f} | {ref.value:.5f} ({ref.se:.5f}) "
                      f"| {mcell} |", flush=True)


if __name__ == "__main__":
    main()
