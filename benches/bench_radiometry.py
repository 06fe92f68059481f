"""Speed of the radiometric experiment and, when ``mitsuba`` is installed,
the same nadir BRF series rendered by Mitsuba 3 in the same run.

Prints the rays (paths) per CPU second of our heightfield path tracer on a
periodic 32 x 32 fBm tile with one thread, and a Markdown table of the nadir
BRF at sun zeniths 0, 15, ..., 75, 89 (single and multiple scattering): our
value and standard error, Mitsuba's value (``scalar_rgb``, ``face_normals``,
``stratified`` sampler, the tile repeated 9 x 9 because Mitsuba has no
periodic scenes), the difference in units of our SE and in %, and the
times with their ratio (Mitsuba / ours, its scene builds included).

Then (``--speed``, on by default) the two speed targets of issue 26, in CPU seconds (all threads
counted; the machine may be shared) against both Mitsuba variants:

* the incidence series of figure 9: 7 images (sun zenith 0-75 and 89) of 256 x 256 pixels at 64
  samples per pixel, multiple scattering (``max_depth`` 10), nadir orthographic sensor, the same tile
  (ours: ``Scene.render_series``, one pass for all suns, and for comparison one ``render`` per sun,
  whose images are the same bit for bit; Mitsuba: ``orthographic`` sensor over the central tile of the 9 x 9 copy, ``independent``
  sampler, ``path`` integrator with ``max_depth`` 11 as it counts the emitter segment);
* the 7-angle nadir BRF sweep to a relative standard error of 0.2 %: ours with as many paths as a
  pilot run says are needed (pilot included); Mitsuba's error at 65,536 ``stratified`` samples is
  measured as the spread of 5 runs with different seeds, and its time to 0.2 % is its scene build
  plus its render time scaled by (error / 0.2 %)^2 per angle (both are reported).

Run: ``python benches/bench_radiometry.py [--spp 65536] [--no-mitsuba] [--no-speed] [--no-table]``.
Mitsuba: ``pip install mitsuba`` (``scalar_rgb`` needs nothing else; ``llvm_ad_rgb`` needs
``DRJIT_LIBLLVM_PATH`` at an LLVM such as Debian's ``libllvm19``, set here when that file exists).
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
LLVM = "/usr/lib/x86_64-linux-gnu/libLLVM-19.so"


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


def mitsuba_brf(mi, ply, z, cell, rho, sun_zen, spp, max_depth, seed=0, times=None):
    """Mitsuba's nadir BRF; ``times`` (a list) gets (scene build, render) CPU seconds appended."""
    c0 = time.process_time()
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
                   "sampler": {"type": "stratified", "sample_count": spp, "seed": seed},
                   "film": {"type": "hdrfilm", "width": 1, "height": 1, "pixel_format": "luminance",
                            "rfilter": {"type": "box"}}},
    })
    c1 = time.process_time()
    img = np.array(mi.render(scene, spp=spp))
    if times is not None:
        times.append((c1 - c0, time.process_time() - c1))
    return np.pi * float(img.ravel()[0]) / np.cos(np.radians(sun_zen))


def mitsuba_image_scene(mi, ply, z, cell, rho, sun_zen, shape, spp, max_depth):
    """The tiled PLY seen by a nadir orthographic sensor over the central tile."""
    n = z.shape[0]
    w = n * cell
    s = np.array([np.sin(np.radians(sun_zen)), 0.0, np.cos(np.radians(sun_zen))])
    top = float(z.max()) + 10.0
    cam = mi.ScalarTransform4f().look_at(origin=[w / 2, -w / 2, top], target=[w / 2, -w / 2, 0.0],
                                         up=[0.0, 1.0, 0.0]) @ mi.ScalarTransform4f().scale([w / 2, w / 2, 1.0])
    return mi.load_dict({
        "type": "scene",
        "integrator": {"type": "path", "max_depth": max_depth + 1},
        "sun": {"type": "directional", "direction": (-s).tolist(), "irradiance": {"type": "rgb", "value": 1.0}},
        "surface": {"type": "ply", "filename": ply, "face_normals": True,
                    "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": rho}}},
        "sensor": {"type": "orthographic", "to_world": cam,
                   "sampler": {"type": "independent", "sample_count": spp},
                   "film": {"type": "hdrfilm", "width": shape[1], "height": shape[0], "pixel_format": "luminance",
                            "rfilter": {"type": "box"}}},
    })


def ours_sweep(scene, target, depth, pilot=20_000):
    """The nadir BRF at every zenith to a relative SE of ``target``: a pilot run, then as many paths
    as the last estimate says are needed, until its SE is at most ``target`` (the pilot's paths
    are not reused; all runs are timed)."""
    out = []
    for zen in ZENITHS:
        e, seed = scene.brf(sun=(90.0, zen), spp=pilot, max_depth=depth, seed=3), 4
        while e.se > target * e.value:
            need = int(np.ceil(e.n * (e.se / (target * e.value)) ** 2 * 1.2))
            e, seed = scene.brf(sun=(90.0, zen), spp=need, max_depth=depth, seed=seed), seed + 1
        out.append(e)
    return out


def speed(z, cell, rho, ply, mi, variants):
    """The image series and the BRF sweep, ours against each Mitsuba variant."""
    scene = Scene.from_dem(z, cell_size=cell, material=Lambertian(rho))
    shape, spp, depth = (256, 256), 64, 10
    paths = len(ZENITHS) * shape[0] * shape[1] * spp
    suns = [(90.0, zen) for zen in ZENITHS]
    imgs, _, c_ours = cpu(lambda: scene.render_series(suns, shape=shape, spp=spp, max_depth=depth))
    singles, _, c_single = cpu(lambda: [scene.render(sun=sun, shape=shape, spp=spp, max_depth=depth)
                                        for sun in suns])
    same = all(np.array_equal(a, b) for a, b in zip(imgs, singles))
    print(f"\nimage series: {len(ZENITHS)} images of {shape[0]} x {shape[1]} at {spp} spp, max_depth {depth}, "
          f"{paths / 1e6:.1f} M paths")
    print("| renderer | CPU s | M paths per CPU s | mean radiance at 0 / 45 / 89 deg | ours faster by |")
    print("|---|---|---|---|---|")
    means = " / ".join(f"{imgs[i].mean():.4f}" for i in (0, 3, 6))
    print(f"| fractalgeo_rs `render_series` | {c_ours:.2f} | {paths / c_ours / 1e6:.2f} | {means} | - |")
    print(f"| fractalgeo_rs, `render` per sun (images {'identical' if same else 'DIFFERENT'}) | {c_single:.2f} "
          f"| {paths / c_single / 1e6:.2f} | {means} | {c_single / c_ours:.1f}x |", flush=True)
    for name in variants:
        mi.set_variant(name)

        def series():
            out = []
            for zen in ZENITHS:
                sc = mitsuba_image_scene(mi, ply, z, cell, rho, zen, shape, spp, depth)
                out.append(np.array(mi.render(sc, spp=spp)).reshape(shape))
            return out
        mimgs, _, c_m = cpu(series)
        means = " / ".join(f"{mimgs[i].mean():.4f}" for i in (0, 3, 6))
        print(f"| Mitsuba {name} (scene builds included) | {c_m:.2f} | {paths / c_m / 1e6:.2f} | {means} "
              f"| {c_m / c_ours:.1f}x |", flush=True)

    target = 0.002
    res, _, c_ours = cpu(lambda: ours_sweep(scene, target, depth))
    n_ours = sum(e.n for e in res)
    print(f"\nBRF sweep to a relative SE of {100 * target:.1f} %, max_depth {depth}, {len(ZENITHS)} angles")
    print("| renderer | paths | CPU s | worst relative SE | ours faster by |")
    print("|---|---|---|---|---|")
    worst = max(e.se / e.value for e in res)
    print(f"| fractalgeo_rs (pilot included) | {n_ours} | {c_ours:.2f} | {100 * worst:.2f} % | - |", flush=True)
    m_spp, seeds = 65536, 5
    for name in variants:
        mi.set_variant(name)
        proj, meas, worst_m = 0.0, 0.0, 0.0
        for zen in ZENITHS:
            times = []
            vals = [mitsuba_brf(mi, ply, z, cell, rho, zen, m_spp, depth, seed=k, times=times) for k in range(seeds)]
            build, render = times[0]
            rel = np.std(vals, ddof=1) / np.mean(vals)
            worst_m = max(worst_m, rel)
            meas += build + render
            proj += build + render * (rel / target) ** 2
        print(f"| Mitsuba {name}, stratified {m_spp} per angle (scene builds included) | {m_spp * len(ZENITHS)} "
              f"| {meas:.2f} | {100 * worst_m:.2f} % (spread of {seeds} seeds) | {meas / c_ours:.1f}x |")
        print(f"| Mitsuba {name}, projected to 0.2 % per angle | - | {proj:.2f} | 0.2 % | {proj / c_ours:.1f}x |",
              flush=True)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--spp", type=int, default=65536)
    ap.add_argument("--no-mitsuba", action="store_true")
    ap.add_argument("--no-speed", action="store_true", help="skip the image-series and BRF-sweep timings")
    ap.add_argument("--no-table", action="store_true", help="skip the BRF table against Mitsuba")
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

    mi, variants = None, []
    if not args.no_mitsuba:
        if "DRJIT_LIBLLVM_PATH" not in os.environ and os.path.exists(LLVM):
            os.environ["DRJIT_LIBLLVM_PATH"] = LLVM
        try:
            import mitsuba as mi

            mi.set_variant("scalar_rgb")
            variants = ["scalar_rgb"]
            try:
                mi.set_variant("llvm_ad_rgb")
                variants.append("llvm_ad_rgb")
            except Exception as exc:  # no LLVM
                print(f"mitsuba llvm_ad_rgb unavailable: {exc}")
            mi.set_variant("scalar_rgb")
        except Exception as exc:  # not installed, or no variant
            print(f"mitsuba unavailable: {exc}")
            mi = None
    with tempfile.TemporaryDirectory() as d:
        ply = os.path.join(d, "tile9x9.ply")
        if mi is not None:
            ply_tiled(z, cell, 9, ply)
        if not args.no_speed:
            speed(z, cell, args.rho, ply, mi, variants)
        if not args.no_table:
            table(args, scene, z, cell, ply, mi)


def table(args, scene, z, cell, ply, mi) -> None:
    """Our nadir BRF against Mitsuba's scalar_rgb at every zenith."""
    if mi is not None:
        mi.set_variant("scalar_rgb")
    print(f"\nnadir BRF, rho = {args.rho}, {args.spp} samples per angle, sun in the east; "
          "times are CPU seconds")
    print(f"ours: at the same number of samples (timed) and at {args.ref_spp} paths (the reference); "
          "diff = Mitsuba - reference")
    print("| sun zenith | depth | ours (SE) | ours CPU s | reference (SE) | Mitsuba | diff / SE | diff % "
          "| Mitsuba CPU s | ratio |")
    print("|---|---|---|---|---|---|---|---|---|---|")
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
