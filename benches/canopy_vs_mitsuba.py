"""BRF of a homogeneous disc canopy against Mitsuba 3 on the same leaves, in
the same run (issue 28: "within 2 % of Mitsuba at the same angles").

Scene: ``canopy.disc_canopy`` with LAI ``--lai`` (3), spherical leaf angles,
independently placed 12-gon leaves of radius ``--radius`` m (0.05), centres
uniform between 0.1 and 2.0 m, a periodic ``--extent`` m tile (5), over a
Lambertian soil (0.159). Two leaf cases:

* ``reflecting``: two-sided Lambertian leaves with reflectance 0.4957 and
  transmittance 0 (ours ``BiLambertian(0.4957, 0)``; Mitsuba ``twosided``
  around ``diffuse``: Mitsuba 3's core plugins have no diffuse
  transmitter);
* ``bi-Lambertian`` (``--no-transmit`` skips it): RAMI's near-infrared leaf,
  reflectance 0.4957 and transmittance 0.4409 (ours ``BiLambertian``;
  Mitsuba: the ``bilambertian`` BSDF defined below in Python and registered
  with ``mi.register_bsdf``: ``r / pi`` into the side the light comes from,
  ``t / pi`` through, the side sampled with probability ``r / (r + t)``
  and then a cosine-weighted direction). In ``scalar_rgb`` Mitsuba calls
  this Python code at every interaction, so the case is 3-10 times
  slower than ``diffuse``; by default it runs at 5 of the 9 principal-plane
  views (``--all-views`` for all).

Mitsuba 3 (``scalar_rgb``) sees the same mesh: the soil and leaf triangles
of the tile written as two PLY files (the ``Mesh``'s float32 vertices,
``face_normals``), one ``shapegroup`` repeated ``--copies`` x ``--copies``
times (default 11: 5 tiles, 25 m, of neighbours on every side of the
central tile; Mitsuba has no periodic scenes, and multiply scattered light
travels sideways: 3 and 7 copies gave an NIR BRF 1.6 % and 0.4 % low at a
60 degree view) by ``instance`` shapes, a ``directional`` emitter of unit
irradiance and, per view, a ``distant`` sensor aimed at the central tile
(a ``rectangle`` target on the soil: the sensor reports the mean radiance
over it), a 1 x 1 ``hdrfilm`` and the ``stratified`` sampler with
``--mitsuba-spp`` samples (65 536 = 256^2). Mitsuba's ``path`` integrator
has ``max_depth`` = ours + 1 (it counts the segment to the emitter), so
both count the same scattering orders: all (``--depth`` 100 events; ours
has no Russian roulette and traces every path to escape or 100 events, the
light still travelling after 30 events is 3e-5 of the incident for the NIR
leaves) and single scattering (``max_depth=1``). BRF = pi L / cos(sun
zenith). Each Mitsuba number is the mean of ``--repeats`` (4) renders with
seeds 0, 1, ... (``mi.render(..., seed=k)``), its standard error the spread
of those over sqrt(repeats) (from 4 values: a rough SE); ours is one
``Scene.brf`` of ``--spp`` paths (2^17) with its ``.se``. Both trace the
same realisation of the canopy, so the placement noise cancels; ``z`` =
(Mitsuba - ours) / sqrt(SE_m^2 + SE_ours^2).

Angles: sun at 30 degrees zenith, azimuth 0, views in the principal plane
from -60 to +60 (``+`` on the sun's side: backscatter, the hot spot at
+30), and nadir views with the sun at 0 and 60.

Hot-spot check (``--hotspot-rays``, default 400 000; 0 skips it): at the
exact hot spot every visible point is lit (the sun ray is the view ray
reversed), so single scattering needs no shadow ray: BRF = mean over rays
of ``r |n . s| / cos(sun)`` on a leaf, ``rho_soil`` on the soil. Mitsuba's
``ray_intersect`` alone (its BVH, no shadow rays, no sampler) gives this
from uniform random points of the central tile, an estimate independent of
both path tracers' light transport.

Run: ``python benches/canopy_vs_mitsuba.py [--quick]`` (``pip install
mitsuba``, tested with 3.9.1; an optional comparison, not a dependency).
Wall times; the machine may be shared (its load average is printed).
"""
from __future__ import annotations

import argparse
import os
import platform
import tempfile
import time

import numpy as np

from fractalgeo_rs import canopy
from fractalgeo_rs.radiometry import BiLambertian, Lambertian

LEAF_R, LEAF_T, SOIL = 0.4957, 0.4409, 0.159
SUN = 30.0
VIEWS = (-60.0, -45.0, -30.0, -15.0, 0.0, 15.0, 30.0, 45.0, 60.0)
VIEWS_SHORT = (-60.0, -30.0, 0.0, 30.0, 60.0)  # the bi-Lambertian case (its Python BSDF is slow) by default
NADIR_SUNS = (0.0, 60.0)


def cpu_model() -> str:
    try:
        with open("/proc/cpuinfo") as fh:
            for line in fh:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def load() -> str:
    a, b, c = os.getloadavg()
    return f"{a:.2f} {b:.2f} {c:.2f}"


def direction(az: float, zen: float) -> np.ndarray:
    """Unit vector (east, north, up) towards ``(azimuth, zenith)`` in degrees (azimuth from north,
    clockwise), the convention of ``Scene.brf``."""
    a, z = np.radians(az), np.radians(zen)
    return np.array([np.sin(a) * np.sin(z), np.cos(a) * np.sin(z), np.cos(z)])


def write_ply(path: str, vertices: np.ndarray, faces: np.ndarray) -> None:
    """Binary little-endian PLY of float32 vertices and triangles (no normals: ``face_normals``)."""
    rec = np.zeros(len(faces), dtype=[("n", "u1"), ("i", "<i4", (3,))])
    rec["n"], rec["i"] = 3, faces
    with open(path, "wb") as fh:
        fh.write((f"ply\nformat binary_little_endian 1.0\nelement vertex {len(vertices)}\n"
                  "property float x\nproperty float y\nproperty float z\n"
                  f"element face {len(faces)}\nproperty list uchar int vertex_indices\nend_header\n").encode())
        fh.write(np.ascontiguousarray(vertices, dtype="<f4").tobytes())
        fh.write(rec.tobytes())


def split_ply(mesh, tmp: str):
    """The soil (kind 0) and leaf (kind 1) triangles of the tile as two PLY files (map coordinates)."""
    v = np.asarray(mesh.vertices, dtype=np.float64) + np.asarray(mesh.origin, dtype=np.float64)
    f = np.asarray(mesh.faces, dtype=np.int64)
    kinds = np.asarray(mesh.kinds)
    out = []
    for kind, name in ((0, "soil"), (1, "leaves")):
        ff = f[kinds == kind]
        used, inv = np.unique(ff, return_inverse=True)
        p = os.path.join(tmp, f"{name}.ply")
        write_ply(p, v[used], inv.reshape(-1, 3))
        out.append(p)
    return out


def register_bilambertian(mi) -> None:
    """A two-sided bi-Lambertian BSDF for Mitsuba 3 (Python plugin ``bilambertian``): ``r / pi`` on
    the side of the incident light, ``t / pi`` on the other; sampling picks the side with probability
    ``r / (r + t)``, then a cosine-weighted direction, so the sample weight is ``r + t``."""
    import drjit as dr

    class BiLambertianBSDF(mi.BSDF):
        def __init__(self, props):
            mi.BSDF.__init__(self, props)
            self.r = float(props.get("reflectance", 0.5))
            self.t = float(props.get("transmittance", 0.0))
            flags = (mi.BSDFFlags.DiffuseReflection | mi.BSDFFlags.DiffuseTransmission
                     | mi.BSDFFlags.FrontSide | mi.BSDFFlags.BackSide)
            self.m_components = [flags]
            self.m_flags = flags

        def _p_reflect(self):
            return self.r / (self.r + self.t)

        def sample(self, ctx, si, sample1, sample2, active=True):
            p_r = self._p_reflect()
            reflect = sample1 < p_r
            wo = mi.warp.square_to_cosine_hemisphere(sample2)
            side = dr.select(mi.Frame3f.cos_theta(si.wi) >= 0, 1.0, -1.0) * dr.select(reflect, 1.0, -1.0)
            wo = mi.Vector3f(wo.x, wo.y, wo.z * side)
            bs = dr.zeros(mi.BSDFSample3f)
            bs.wo = wo
            bs.pdf = dr.select(reflect, p_r, 1.0 - p_r) * dr.abs(mi.Frame3f.cos_theta(wo)) / dr.pi
            bs.eta = 1.0
            bs.sampled_type = dr.select(reflect, mi.UInt32(int(mi.BSDFFlags.DiffuseReflection)),
                                        mi.UInt32(int(mi.BSDFFlags.DiffuseTransmission)))
            bs.sampled_component = mi.UInt32(0)
            return bs, mi.Spectrum(self.r + self.t)

        def _f_pdf(self, si, wo):
            same = mi.Frame3f.cos_theta(si.wi) * mi.Frame3f.cos_theta(wo) > 0
            c = dr.abs(mi.Frame3f.cos_theta(wo)) / dr.pi
            p_r = self._p_reflect()
            return dr.select(same, self.r, self.t) * c, dr.select(same, p_r, 1.0 - p_r) * c

        def eval(self, ctx, si, wo, active=True):
            return mi.Spectrum(self._f_pdf(si, wo)[0])

        def pdf(self, ctx, si, wo, active=True):
            return self._f_pdf(si, wo)[1]

        def eval_pdf(self, ctx, si, wo, active=True):
            f, p = self._f_pdf(si, wo)
            return mi.Spectrum(f), p

        def traverse(self, callback):
            pass

        def to_string(self):
            return f"BiLambertianBSDF[r={self.r}, t={self.t}]"

    mi.register_bsdf("bilambertian", lambda props: BiLambertianBSDF(props))


def mitsuba_scene(mi, plys, extent, copies, leaf_bsdf, sun_zen, views, spp, depth):
    """The tiled canopy with one ``distant`` sensor per view (``views``: (azimuth, zenith) pairs)."""
    soil_ply, leaf_ply = plys
    e = float(extent)
    d = {"type": "scene",
         "integrator": {"type": "path", "max_depth": depth + 1},
         "sun": {"type": "directional", "direction": (-direction(0.0, sun_zen)).tolist(),
                 "irradiance": {"type": "rgb", "value": 1.0}},
         "tile": {"type": "shapegroup",
                  "soil": {"type": "ply", "filename": soil_ply, "face_normals": True,
                           "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": SOIL}}},
                  "leaves": {"type": "ply", "filename": leaf_ply, "face_normals": True, "bsdf": leaf_bsdf}}}
    h = copies // 2
    for i in range(-h, h + 1):
        for j in range(-h, h + 1):
            d[f"copy_{i + h}_{j + h}"] = {"type": "instance", "shapegroup": {"type": "ref", "id": "tile"},
                                          "to_world": mi.ScalarTransform4f().translate([i * e, j * e, 0.0])}
    centre = mi.ScalarTransform4f().translate([e / 2, e / 2, 0.0]) @ mi.ScalarTransform4f().scale([e / 2, e / 2, 1.0])
    for k, (az, zen) in enumerate(views):
        d[f"sensor_{k:02d}"] = {
            "type": "distant", "direction": (-direction(az, zen)).tolist(),
            "target": {"type": "rectangle", "to_world": centre},
            "sampler": {"type": "stratified", "sample_count": spp},
            "film": {"type": "hdrfilm", "width": 1, "height": 1, "pixel_format": "luminance",
                     "rfilter": {"type": "box"}}}
    return mi.load_dict(d)


def hotspot_raycast(mi, scene, extent: float, sun_zen: float, n: int, leaf_r: float, seed: int = 5):
    """Single-scattering BRF at the exact hot spot (view = sun) from first hits only, no shadow rays:
    ``leaf_r |n . s| / cos(sun)`` on a leaf, the soil's reflectance on the soil; ``n`` rays through
    uniform random points of the central tile, Mitsuba's ``ray_intersect``. (value, SE, soil fraction)."""
    s = direction(0.0, sun_zen)
    rng = np.random.default_rng(seed)
    pts = rng.random((n, 2)) * extent
    vals = np.empty(n)
    d = mi.Vector3f(*(-s))
    for i, (x, y) in enumerate(pts):
        si = scene.ray_intersect(mi.Ray3f(mi.Point3f(*(np.array([x, y, 0.0]) + 50.0 * s)), d))
        if not si.is_valid():
            raise RuntimeError("hot-spot ray missed the scene")
        if si.p.z < 1e-4:  # the soil (leaves start at 0.1 - 1.034 r above it)
            vals[i] = SOIL
        else:
            vals[i] = leaf_r * abs(si.n.x * s[0] + si.n.y * s[1] + si.n.z * s[2]) / s[2]
    return float(vals.mean()), float(vals.std(ddof=1) / np.sqrt(n)), float(np.mean(vals == SOIL))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--lai", type=float, default=3.0)
    ap.add_argument("--radius", type=float, default=0.05, help="leaf radius, m")
    ap.add_argument("--extent", type=float, default=5.0, help="tile side, m")
    ap.add_argument("--seed", type=int, default=1, help="seed of the leaf placement")
    ap.add_argument("--copies", type=int, default=11, help="Mitsuba: tiles per side (odd)")
    ap.add_argument("--depth", type=int, default=100, help="scattering events of 'all orders'")
    ap.add_argument("--spp", type=int, default=1 << 17, help="our paths per value")
    ap.add_argument("--mitsuba-spp", type=int, default=65536, help="Mitsuba samples per render (a square)")
    ap.add_argument("--repeats", type=int, default=4, help="Mitsuba renders (seeds) per value")
    ap.add_argument("--no-single", action="store_true", help="skip single scattering")
    ap.add_argument("--no-transmit", action="store_true", help="skip the bi-Lambertian (transmitting) leaves")
    ap.add_argument("--all-views", action="store_true",
                    help="every view for the bi-Lambertian leaves too (default: -60, -30, 0, 30, 60)")
    ap.add_argument("--hotspot-rays", type=int, default=400_000,
                    help="rays of the shadow-free hot-spot check (0: skip)")
    ap.add_argument("--quick", action="store_true",
                    help="a smoke run (about a minute): 2 m tile, 15 copies, 16384 Mitsuba samples x 3, "
                         "2^15 of ours, no single scattering, views -60, -30, 0, 30, 60")
    a = ap.parse_args()
    if a.quick:
        a.extent, a.copies, a.mitsuba_spp, a.repeats, a.spp, a.no_single = 2.0, 15, 16384, 3, 1 << 15, True
    if a.copies % 2 != 1:
        ap.error("--copies: expected an odd number")
    t_start = time.perf_counter()
    print(f"machine: {cpu_model()}, {os.cpu_count()} cores; load average {load()}; "
          f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}")

    import mitsuba as mi

    mi.set_variant("scalar_rgb")
    mi.set_log_level(mi.LogLevel.Error)
    register_bilambertian(mi)

    c = canopy.disc_canopy(lai=a.lai, leaf_radius=a.radius, extent=a.extent, height=(0.1, 2.0),
                           lad="spherical", overlap=True, soil=Lambertian(SOIL), seed=a.seed)
    print(f"canopy: {c.n_leaves} leaves (12-gons) of radius {a.radius} m, LAI {c.lai:.4f}, spherical, "
          f"heights 0.1-2.0 m, {a.extent:g} m tile, {len(c.mesh)} triangles ({a.copies ** 2 * len(c.mesh)} "
          f"instanced in Mitsuba); soil {SOIL}")
    print(f"Mitsuba {mi.__version__} scalar_rgb: {a.copies} x {a.copies} instances of the tile, stratified "
          f"{a.mitsuba_spp} samples x {a.repeats} seeds per value; ours: {a.spp} paths per value")

    short = VIEWS_SHORT if a.quick or not a.all_views else VIEWS
    cases = [("reflecting", LEAF_R, 0.0,
              {"type": "twosided", "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": LEAF_R}}},
              VIEWS_SHORT if a.quick else VIEWS)]
    if not a.no_transmit:
        cases.append(("bi-Lambertian", LEAF_R, LEAF_T,
                      {"type": "bilambertian", "reflectance": LEAF_R, "transmittance": LEAF_T}, short))
    depths = [a.depth] + ([] if a.no_single else [1])
    rows = []
    t_ours = t_mi = 0.0
    with tempfile.TemporaryDirectory() as tmp:
        plys = split_ply(c.mesh, tmp)
        for name, r, t, bsdf, case_views in cases:
            # (sun zenith, [views]) groups: one Mitsuba scene per sun and order, one sensor per view
            groups = [(SUN, [(0.0 if v >= 0 else 180.0, abs(v)) for v in case_views])]
            groups += [(s, [(0.0, 0.0)]) for s in NADIR_SUNS]
            c_case = canopy.disc_canopy(lai=a.lai, leaf_radius=a.radius, extent=a.extent, height=(0.1, 2.0),
                                        lad="spherical", overlap=True, leaf=BiLambertian(r, t),
                                        soil=Lambertian(SOIL), seed=a.seed)
            assert np.array_equal(np.asarray(c_case.mesh.vertices), np.asarray(c.mesh.vertices))
            scene = c_case.scene()
            for depth in depths:
                for sun_zen, views in groups:
                    t0 = time.perf_counter()
                    ms = mitsuba_scene(mi, plys, a.extent, a.copies, bsdf, sun_zen, views, a.mitsuba_spp, depth)
                    t_build = time.perf_counter() - t0
                    t_mi += t_build
                    sensors = ms.sensors()
                    for k, view in enumerate(views):
                        t0 = time.perf_counter()
                        ours = scene.brf(sun=(0.0, sun_zen), view=view, spp=a.spp, max_depth=depth, seed=7)
                        t1 = time.perf_counter()
                        vals = [np.pi * float(np.asarray(mi.render(ms, sensor=sensors[k], seed=s,
                                                                   spp=a.mitsuba_spp)).ravel()[0])
                                / np.cos(np.radians(sun_zen)) for s in range(a.repeats)]
                        t2 = time.perf_counter()
                        t_ours += t1 - t0
                        t_mi += t2 - t1
                        m = float(np.mean(vals))
                        se_m = float(np.std(vals, ddof=1) / np.sqrt(len(vals)))
                        signed = view[1] if view[0] == 0.0 else -view[1]
                        rows.append((name, depth, sun_zen, signed, ours.value, ours.se, m, se_m, t1 - t0,
                                     (t2 - t1) / a.repeats))
                        print(f"  {name}, depth {depth}, sun {sun_zen:g}, view {signed:+g}: ours {ours.value:.4f} "
                              f"+- {ours.se:.4f} ({t1 - t0:.2f} s), Mitsuba {m:.4f} +- {se_m:.4f} "
                              f"({(t2 - t1) / a.repeats:.2f} s per render, build {t_build:.2f} s)", flush=True)
        hot = None
        if a.hotspot_rays > 0 and not a.no_single:
            t0 = time.perf_counter()
            ms = mitsuba_scene(mi, plys, a.extent, a.copies, cases[0][3], SUN, [(0.0, SUN)], 64, 1)
            hot = (*hotspot_raycast(mi, ms, a.extent, SUN, a.hotspot_rays, LEAF_R), time.perf_counter() - t0)

    print(f"\nBRF, sun azimuth 0; view zenith + on the sun's side; z = (Mitsuba - ours) / combined SE; "
          f"times are wall seconds per value (ours: {a.spp} paths; Mitsuba: one render of {a.mitsuba_spp})")
    print("| leaves | orders | sun | view | ours | Mitsuba | Mitsuba - ours | z | within 2 % | ours s | Mitsuba s |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    worst = 0.0
    for name, depth, sun_zen, view, o, so, m, sm, to, tm in rows:
        rel = (m - o) / o
        z = (m - o) / np.hypot(so, sm)
        worst = max(worst, abs(rel))
        orders = "all" if depth > 1 else "single"
        print(f"| {name} | {orders} | {sun_zen:g} | {view:+g} | {o:.4f} +- {so:.4f} | {m:.4f} +- {sm:.4f} "
              f"| {100 * rel:+.2f} % | {z:+.1f} | {'yes' if abs(rel) <= 0.02 else 'NO'} | {to:.2f} | {tm:.2f} |")
    if hot is not None:
        v, se, gap, th = hot
        print(f"\nhot spot (sun = view = {SUN:g}), single scattering, without shadow rays ({a.hotspot_rays} rays "
              f"through uniform points of the central tile, Mitsuba's ray_intersect, {th:.1f} s): "
              f"{v:.4f} +- {se:.4f} (soil seen {gap:.4f})")
        for name, depth, sun_zen, view, o, so, m, sm, *_ in rows:
            if depth == 1 and sun_zen == SUN and view == SUN:
                print(f"  {name}: ours {o:.4f} +- {so:.4f} ({100 * (o - v) / v:+.2f} %, "
                      f"{(o - v) / np.hypot(so, se):+.1f} SE), Mitsuba {m:.4f} +- {sm:.4f} "
                      f"({100 * (m - v) / v:+.2f} %, {(m - v) / np.hypot(sm, se):+.1f} SE)")
    print(f"\nlargest |relative difference| {100 * worst:.2f} % ({'within' if worst <= 0.02 else 'NOT within'} 2 %); "
          f"ours {t_ours:.1f} s, Mitsuba {t_mi:.1f} s (scene builds included), Mitsuba / ours {t_mi / t_ours:.1f}; "
          f"total {time.perf_counter() - t_start:.1f} s; load average {load()}")


if __name__ == "__main__":
    main()
