"""Build time, memory and render time of an instanced stand of L-system
plants (``Scene.from_instances``) against Mitsuba 3's instancing
(``shapegroup`` + ``instance``) on the same scene, in the same run.

Scene: three bush shapes (one bracketed L-system derived 4 and 5 steps,
branching angles 22.5 and 27 degrees, ``plant_mesh`` with 4-sided tubes,
zero-area triangles dropped), ``--plants`` instances (default 10^4) with
seeded rotation about z, scale 0.08-0.12 and uniform positions on a
periodic ``--side`` x ``--side`` m tile, plus a flat ground of two
triangles. One material everywhere, two-sided ``Lambertian(0.45)``
(Mitsuba's ``twosided`` ``diffuse``): Mitsuba 3's core has no
bi-Lambertian (transmitting) BSDF, and separate plant and ground
materials would need a per-facet id array as long as all the instances'
triangles, which defeats instancing.

Memory is the growth of the process's resident set (``VmRSS`` in
``/proc/self/status``) over the build (one plant, then the instanced
stand, then, with the stand alive so freed pages are not reused, the
concatenated mesh), against the same growth for one
plant (``from_mesh``) and for the concatenated, non-instanced mesh of
``--concat`` plants (``from_mesh`` of the joined triangles).

Render: a ``--res`` x ``--res`` nadir image (orthographic, ``--spp``
paths per pixel, ``max_depth=5``, sun at 30 degrees zenith) and one nadir
BRF of the tile (``--brf-spp`` paths). Mitsuba (``scalar_rgb``: the LLVM
variant needs ``DRJIT_LIBLLVM_PATH``, see the toolchain notes) renders the
same image with an ``orthographic`` sensor over the tile, a
``directional`` emitter at the same angle, ``path`` integrator with
``max_depth=6`` (Mitsuba counts the emitter hit as a vertex), ``independent``
sampler with the same spp, and ``face_normals`` meshes. Mitsuba has no
periodic scene: it sees the single tile only, so its image is darker at the
edges; the timing is what is compared. Mitsuba's BRF comes from a
``distant`` sensor aimed at the central half of the tile (``rectangle``
target), with as many paths as ours. Ratio = Mitsuba time / ours.

Run: ``python benches/bench_canopy_stand.py [--plants 10000] [--res 512]``
(``pip install mitsuba==3.9.1`` for the comparison).
"""
from __future__ import annotations

import argparse
import os
import platform
import tempfile
import time

import numpy as np

from fractalgeo_rs.geometry import Mesh
from fractalgeo_rs.lsystem import LSystem, plant_mesh
from fractalgeo_rs.radiometry import Lambertian, Scene

BUSH = """axiom: A
A -> [&FL!A]/////'[&FL!A]///////'[&FL!A]
F -> S/////F
S -> F L
L -> [\'\'\'^^{-f+f+f-|-f+f+f}]
"""


def rss_mb() -> float:
    with open("/proc/self/status") as fh:
        for line in fh:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024.0
    return float("nan")


def clean(mesh):
    """Vertices (map coordinates) and faces without zero-area triangles."""
    v = np.asarray(mesh.vertices, dtype=np.float64) + np.asarray(mesh.origin)
    f = np.asarray(mesh.faces)
    area = np.linalg.norm(np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]]), axis=1)
    return v, f[area > 1e-12]


def shapes():
    out = []
    for n, angle in ((4, 22.5), (5, 22.5), (4, 27.0)):
        m = plant_mesh(LSystem.from_string(BUSH).derive(n), angle=angle, width_factor=0.7, sides=4)
        v, f = clean(m)
        v[:, :2] -= 0.5 * (v[:, :2].min(0) + v[:, :2].max(0))  # trunk-centred footprint
        v[:, 2] -= v[:, 2].min()
        out.append((v, f))
    return out


def placements(n, side, n_shapes, seed=1):
    rng = np.random.default_rng(seed)
    which = rng.integers(0, n_shapes, n)
    phi = rng.uniform(0.0, 2.0 * np.pi, n)
    s = rng.uniform(0.08, 0.12, n)
    xf = np.zeros((n, 3, 4))
    c, sn = np.cos(phi) * s, np.sin(phi) * s
    xf[:, 0, 0], xf[:, 0, 1], xf[:, 1, 0], xf[:, 1, 1], xf[:, 2, 2] = c, -sn, sn, c, s
    xf[:, 0, 3] = rng.uniform(0.0, side, n)
    xf[:, 1, 3] = rng.uniform(0.0, side, n)
    return which, xf


def ground(side):
    v = np.array([[0, 0, 0], [side, 0, 0], [0, side, 0], [side, side, 0]], dtype=np.float64)
    return v, np.array([[0, 1, 2], [1, 3, 2]])


def timed(fn):
    r0, t0, c0 = rss_mb(), time.perf_counter(), time.process_time()
    out = fn()
    return out, time.perf_counter() - t0, time.process_time() - c0, rss_mb() - r0


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--plants", type=int, default=10000)
    ap.add_argument("--side", type=float, default=100.0, help="tile side, m")
    ap.add_argument("--concat", type=int, default=500, help="plants in the non-instanced mesh")
    ap.add_argument("--res", type=int, default=512)
    ap.add_argument("--spp", type=int, default=4)
    ap.add_argument("--brf-spp", type=int, default=65536)
    ap.add_argument("--no-mitsuba", action="store_true")
    a = ap.parse_args()
    print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores; "
          f"load: {os.getloadavg()[0]:.2f} {os.getloadavg()[1]:.2f} {os.getloadavg()[2]:.2f}")
    mat = Lambertian(0.45)
    sun = (0.0, 30.0)
    shp = shapes()

    def to_brf(im):
        return float(np.pi * np.mean(im) / np.cos(np.radians(sun[1])))

    def centre(im):
        q = a.res // 4
        return im[q:a.res - q, q:a.res - q]
    gv, gf = ground(a.side)
    meshes = [Mesh.from_triangles(v, f) for v, f in shp] + [Mesh.from_triangles(gv, gf)]
    which, xf = placements(a.plants, a.side, len(shp))
    gxf = np.zeros((1, 3, 4))
    gxf[0, :, :3] = np.eye(3)
    all_which = np.concatenate([which, [len(shp)]])
    all_xf = np.concatenate([xf, gxf])
    tri = sum(len(shp[w][1]) for w in which) + 2
    print(f"shapes: {[len(f) for _, f in shp]} triangles; {a.plants} plants on {a.side:g} m x {a.side:g} m, "
          f"{tri} instanced triangles")
    ext = (0.0, 0.0, a.side, a.side)

    # one plant alone
    one, t_one, _, m_one = timed(lambda: Scene.from_mesh(meshes[1], materials=mat, periodic=False))
    del one
    # the instanced stand
    scene, t_inst, _, m_inst = timed(lambda: Scene.from_instances(meshes, all_which, all_xf, extent=ext,
                                                                   materials=mat, periodic=True))
    # the concatenated mesh of a.concat plants + ground
    k = min(a.concat, a.plants)
    vs, fs, off = [], [], 0
    for w, x in zip(which[:k], xf[:k]):
        v, f = shp[w]
        vs.append(v @ x[:, :3].T + x[:, 3])
        fs.append(f + off)
        off += len(v)
    vs.append(gv)
    fs.append(gf + off)
    cat_mesh = Mesh.from_triangles(np.vstack(vs), np.vstack(fs))
    n_cat = len(cat_mesh.faces)
    cat, t_cat, _, m_cat = timed(lambda m=cat_mesh: Scene.from_mesh(m, materials=mat, periodic=False))
    del cat, cat_mesh, vs, fs
    img, t_img, c_img, _ = timed(lambda: scene.render(sun=sun, shape=(a.res, a.res), spp=a.spp, max_depth=5,
                                                      seed=1, progress=False))
    brf, t_brf, _, _ = timed(lambda: scene.brf(sun=sun, spp=a.brf_spp, max_depth=5, seed=2))
    print(f"ours: one plant ({len(shp[1][1])} tri) build {t_one:.3f} s, +{m_one:.1f} MB RSS")
    print(f"ours: concatenated {k} plants ({n_cat} tri) build {t_cat:.3f} s, +{m_cat:.1f} MB RSS "
          f"(per plant {m_cat / k * 1024:.1f} kB)")
    print(f"ours: instanced {a.plants} plants build {t_inst:.3f} s, +{m_inst:.1f} MB RSS "
          f"(= {m_inst / max(m_one, 1e-3):.1f} x one plant; the concatenated mesh scaled to {a.plants} plants "
          f"would take ~{m_cat * a.plants / k:.0f} MB)")
    print(f"ours: render {a.res}x{a.res} spp {a.spp}: {t_img:.2f} s wall, {c_img:.2f} s CPU, BRF of the image {to_brf(img):.4f}, of its central half {to_brf(centre(img)):.4f}")
    print(f"ours: BRF nadir sun 30, {a.brf_spp} paths: {brf.value:.4f} +- {brf.se:.4f} in {t_brf:.2f} s")

    if a.no_mitsuba:
        return
    try:
        import mitsuba as mi
    except ImportError:
        print("mitsuba not importable: comparison skipped")
        return
    mi.set_variant("scalar_rgb")
    mi.set_log_level(mi.LogLevel.Error)
    from fractalgeo_rs.lsystem.export import write_ply

    with tempfile.TemporaryDirectory() as tmp:
        paths = []
        for i, m in enumerate(meshes):
            p = os.path.join(tmp, f"s{i}.ply")
            write_ply(m, p)
            paths.append(p)

        def build():
            bsdf = {"type": "twosided", "b": {"type": "diffuse", "reflectance": {"type": "rgb", "value": 0.45}}}
            d = {"type": "scene", "integrator": {"type": "path", "max_depth": 6},
                 "sun": {"type": "directional", "direction": [np.sin(np.radians(sun[1])), 0.0,
                                                               -np.cos(np.radians(sun[1]))], "irradiance": 1.0},
                 "sensor": {"type": "orthographic",
                            "to_world": mi.ScalarTransform4f().look_at(
                                origin=[a.side / 2, a.side / 2, 50.0], target=[a.side / 2, a.side / 2, 0.0],
                                up=[0, 1, 0]) @ mi.ScalarTransform4f().scale([a.side / 2, a.side / 2, 1.0]),
                            "sampler": {"type": "independent", "sample_count": a.spp},
                            "film": {"type": "hdrfilm", "width": a.res, "height": a.res,
                                     "rfilter": {"type": "box"}}}}
            h = a.side / 4  # central half of the tile: Mitsuba's scene has no periodic neighbours
            d["brf_sensor"] = {"type": "distant", "direction": [0.0, 0.0, -1.0],
                               "target": {"type": "rectangle", "to_world": mi.ScalarTransform4f().translate(
                                   [a.side / 2, a.side / 2, 0.0]) @ mi.ScalarTransform4f().scale([h, h, 1.0])},
                               "sampler": {"type": "independent", "sample_count": a.brf_spp},
                               "film": {"type": "hdrfilm", "width": 1, "height": 1, "rfilter": {"type": "box"}}}
            for i, p in enumerate(paths):
                d[f"sg{i}"] = {"type": "shapegroup",
                               "m": {"type": "ply", "filename": p, "face_normals": True, "bsdf": bsdf}}
            for j, (w, x) in enumerate(zip(all_which, all_xf)):
                m4 = np.eye(4)
                m4[:3, :] = x
                m4[:3, 3] += np.asarray(meshes[w].origin) @ x[:, :3].T  # PLY holds origin-relative vertices
                d[f"i{j}"] = {"type": "instance", "shapegroup": {"type": "ref", "id": f"sg{w}"},
                              "to_world": mi.ScalarTransform4f(m4.tolist())}
            return mi.load_dict(d)

        ms, t_mb, _, m_mb = timed(build)
        img_sensor = [x for x in ms.sensors() if tuple(x.film().size()) != (1, 1)][0]
        mimg, t_mr, c_mr, m_mr = timed(lambda: np.asarray(mi.render(ms, sensor=img_sensor)))
        print(f"mitsuba {mi.__version__} scalar_rgb: build {t_mb:.2f} s, +{m_mb:.1f} MB RSS; "
              f"render {t_mr:.2f} s wall, {c_mr:.2f} s CPU (+{m_mr:.1f} MB), BRF of the image "
              f"{to_brf(mimg[..., 0]):.4f} (no periodic neighbours), of its central half {to_brf(centre(mimg[..., 0])):.4f}")
        dist = [x for x in ms.sensors() if tuple(x.film().size()) == (1, 1)][0]
        mbrf, t_mbrf, _, _ = timed(lambda: np.asarray(mi.render(ms, sensor=dist)))
        print(f"mitsuba: BRF nadir sun 30 over the central half of the tile, {a.brf_spp} paths: "
              f"{np.pi * float(mbrf.ravel()[0]) / np.cos(np.radians(sun[1])):.4f} in {t_mbrf:.2f} s")
        print(f"ratio (Mitsuba / ours): build {t_mb / t_inst:.1f}, build memory {m_mb / max(m_inst, 1e-3):.1f}, "
              f"image render wall {t_mr / t_img:.1f}, CPU {c_mr / c_img:.1f}; BRF wall {t_mbrf / t_brf:.1f}")


if __name__ == "__main__":
    main()
