"""The paper's premise measured: is the image of a fractal surface a fractal
of the same dimension (Pentland 1984)?

fBm DEMs of known H (D = 3 - H) are rendered as SAR intensity images
(:func:`fractalgeo_rs.radar.simulate`, with and without speckle, two
incidences) and as Lambertian shaded relief, and the dimension of each image
(taken as an intensity surface) is estimated with the package's whole-image
estimators (variogram, spectral, DBC) and the median of the fractal
transform (variogram method, 33-pixel windows). Prints a Markdown table
(the first one in docs/radar.md).

``--optical`` instead compares the two optical renderers on the same fBm
DEMs (the second table in docs/radar.md): hillshade (Horn's gradients, the
cosine of the local incidence, no cast shadows) at sun zenith 45, 30 and
60 deg, and the radiometric path tracer
(:meth:`fractalgeo_rs.radiometry.Scene.render`: the DEM as a finite patch of
facets, one pixel per cell, nadir view, the sun from azimuth 315 as for the
hillshade): Lambertian rho 0.3 with self-shadowing only (``max_depth=1``)
and with 5 scattering events at sun zenith 30 and 60, a Hapke surface
(single scattering, zenith 60), and the relief exaggerated 4 times (rms
slope 1 per cell) at zenith 60, where shadows are common. ``--spp`` paths
per pixel (default 64); the 30-deg multiple-scattering image is also
rendered at ``spp / 4`` with another seed, and the facets' single
scattering is computed in closed form (no cast shadows, no noise;
:func:`facet_shading`), so the table shows how far Monte Carlo noise moves
the estimators. A third table gives, per H, the fraction
of pixels in full shadow and the share of the mean radiance that scattering
events 2-5 add.

``--real`` measures the bundled real DEMs (``fg.data.srtm_alps``,
``fg.data.srtm_po_plain``, SRTM 3", their own cell sizes in metres): each
DEM's dimension against its SAR images (35 and 60 deg, looking east and
north, without speckle and with 1 and 4 looks), its hillshade and its
path-traced images (as above, without the exaggerated relief), the same
estimators (the last table in docs/radar.md).

Run: ``python benches/premise_radar.py [--size 512] [--seeds 2] [--optical] [--spp 64] [--real]``.
"""
import argparse
import os
import time
import warnings

import numpy as np

import fractalgeo_rs as fg
from fractalgeo_rs.radiometry import Hapke, Lambertian, Scene

CELL = 10.0
SURF = dict(wavelength=0.056, model="kirchhoff", permittivity=5 + 0.5j, rms_height=0.01, correlation_length=0.1,
            correlation="exponential")
SUN_AZ = 315.0  # as the hillshade's default
RHO = 0.3
HAPKE = Hapke(0.5, 0.2, 0.4, 15.0, 1.0, 0.05)


def estimates(img):
    img = np.asarray(img, dtype=np.float64)
    out = {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        out["variogram"] = fg.variogram(img, lags=(1, 2)).dimension
        out["spectral"] = fg.spectral_dimension(img).dimension
        out["dbc"] = fg.differential_box_counting(img).dimension
        m = fg.fractal_transform(img, 33, method="variogram", step=8)
        out["transform"] = float(np.nanmedian(m))
    return out


def renders(dem, seed):
    out = {"DEM itself": dem, "hillshade 315/45": fg.hillshade(dem, cell_size=CELL)}
    for inc in (35, 60):
        s = fg.radar.simulate(dem, CELL, look_azimuth=90, incidence=inc, looks=None, **SURF)
        out[f"SAR {inc} deg, no speckle"] = s.image
        if inc == 35:
            for looks in (1, 4, 16):
                s = fg.radar.simulate(dem, CELL, look_azimuth=90, incidence=inc, looks=looks, seed=seed, **SURF)
                out[f"SAR {inc} deg, {looks}-look"] = s.image
    return out


def facet_shading(dem, cell, sun, rho=RHO):
    """Noise-free single scattering without cast shadows, in closed form: each cell's two facets (split
    along the NE-SW diagonal as ``Scene.from_dem``) have radiance ``rho max(0, n.s) / pi``, and a nadir
    pixel of one cell is their mean (each covers half the cell seen from above)."""
    dy, dx = (cell, cell) if np.isscalar(cell) else cell
    az, zen = np.radians(sun[0]), np.radians(sun[1])
    s = np.array([np.sin(zen) * np.sin(az), np.sin(zen) * np.cos(az), np.cos(zen)])  # east, north, up
    z = np.asarray(dem, dtype=np.float64)
    nw, ne, sw, se = z[:-1, :-1], z[:-1, 1:], z[1:, :-1], z[1:, 1:]

    def lit(zx, zy):  # facet of gradient (dz/deast, dz/dnorth): normal (-zx, -zy, 1) / norm
        return np.maximum(0.0, (s[2] - s[0] * zx - s[1] * zy) / np.sqrt(1 + zx ** 2 + zy ** 2))

    # facet (NW, SW, NE): dz/deast = (NE - NW) / dx, dz/dnorth = (NW - SW) / dy
    # facet (NE, SW, SE): dz/deast = (SE - SW) / dx, dz/dnorth = (NE - SE) / dy
    return rho / np.pi * 0.5 * (lit((ne - nw) / dx, (nw - sw) / dy) + lit((se - sw) / dx, (ne - se) / dy))


def optical(dem, cell, spp, seed, check=False, steep=False):
    """Hillshades and path-traced images of ``dem`` (``cell`` a number or ``(dy, dx)``).

    Returns the images by name and, per sun zenith, the fraction of pixels in
    full shadow (single scattering: a pixel is 0 only where every path of it
    hit a facet hidden from the sun) and the share of the mean radiance that
    scattering events 2-5 add.
    """
    out = {"hillshade 315/45": fg.hillshade(dem, cell_size=cell)}
    for zen in (30, 60):
        out[f"hillshade 315, zenith {zen}"] = fg.hillshade(dem, cell_size=cell, azimuth=SUN_AZ, altitude=90 - zen)
    stats = {}

    def lambertian(z, zen, tag):
        sun = (SUN_AZ, float(zen))
        scene = Scene.from_dem(z, cell_size=cell, periodic=False, material=Lambertian(RHO))
        one = scene.render(sun=sun, spp=spp, max_depth=1, seed=seed)
        multi = scene.render(sun=sun, spp=spp, max_depth=5, seed=seed)
        out[f"rendered {zen}, rho {RHO}, 1 event{tag}"] = one
        out[f"rendered {zen}, rho {RHO}, 5 events{tag}"] = multi
        stats[f"shadow {zen}{tag}"] = float(np.mean(one == 0))
        stats[f"multiple {zen}{tag}"] = float(multi.mean() / one.mean() - 1)
        return scene

    scene = lambertian(dem, 30, "")
    if check:
        out[f"rendered 30, rho {RHO}, 5 events, spp {spp // 4}"] = scene.render(
            sun=(SUN_AZ, 30.0), spp=spp // 4, max_depth=5, seed=seed + 1)
        out["facets in closed form, zenith 30 (no shadow, no noise)"] = facet_shading(dem, cell, (SUN_AZ, 30.0))
    lambertian(dem, 60, "")
    hapke = Scene.from_dem(dem, cell_size=cell, periodic=False, material=HAPKE)
    out["rendered 60, Hapke, 1 event"] = hapke.render(sun=(SUN_AZ, 60.0), spp=spp, max_depth=1, seed=seed)
    if steep:
        tag = ", relief x4"
        out[f"hillshade 315, zenith 60{tag}"] = fg.hillshade(dem, cell_size=cell, azimuth=SUN_AZ, altitude=30.0,
                                                             z_factor=4.0)
        lambertian(4.0 * np.asarray(dem), 60, tag)
    return out, stats


def fbm_dems(size, seeds):
    hursts = (0.3, 0.5, 0.7, 0.9)
    for h in hursts:
        for seed in range(seeds):
            # rms slope about 0.25 at the 10 m cell
            yield h, seed, fg.fbm_surface(size, h, method="exact", seed=seed, cell_size=CELL,
                                          sigma=0.25 * CELL ** (1 - h))


def print_table(rows, hursts):
    print("| image | estimator | " + " | ".join(f"D = {3 - h:.1f}" for h in hursts) + " |")
    print("|" + "---|" * (2 + len(hursts)))
    for (name, est), by_h in rows.items():
        cells = " | ".join(f"{np.mean(by_h[h]):.2f}" for h in hursts)
        print(f"| {name} | {est} | {cells} |")


def main(size, seeds, optical_only, spp):
    t0 = time.time()
    rows, light, hursts = {}, {}, []
    for h, seed, dem in fbm_dems(size, seeds):
        if h not in hursts:
            hursts.append(h)
        if optical_only:
            imgs, stats = optical(dem, CELL, spp, seed + 100, check=True, steep=True)
            imgs = {"DEM itself": dem, **imgs}
            for k, v in stats.items():
                light.setdefault(k, {}).setdefault(h, []).append(v)
        else:
            imgs = renders(dem, seed + 100)
        for name, img in imgs.items():
            img = np.where(np.isfinite(img), img, np.nanmedian(img))
            for est, d in estimates(img).items():
                rows.setdefault((name, est), {}).setdefault(h, []).append(d)
    print_table(rows, hursts)
    if optical_only:
        print()
        print(f"| rendered, rho {RHO} | " + " | ".join(f"D = {3 - h:.1f}" for h in hursts) + " |")
        print("|" + "---|" * (1 + len(hursts)))
        for k, by_h in light.items():
            what, rest = k.split(" ", 1)
            label = (f"pixels in full shadow, zenith {rest}" if what == "shadow"
                     else f"radiance added by events 2-5, zenith {rest}")
            print(f"| {label} | " + " | ".join(f"{100 * np.mean(by_h[h]):.1f} %" for h in hursts) + " |")
        print(f"\nspp {spp}; ", end="")
    print(f"{size}², {seeds} seed(s) per H: {time.time() - t0:.0f} s wall, load average {os.getloadavg()[0]:.1f}")


def real_renders(dem, cell, spp):
    """SAR and optical renders of a real DEM at its own (row, column) spacing ``cell`` in metres."""
    out = {"DEM itself": dem}
    opt, stats = optical(dem, cell, spp, 7)
    for zen in (30, 60):
        name = f"rendered {zen}, rho {RHO}, 1 event"
        opt[name] = (opt[name], f"shadow {100 * stats[f'shadow {zen}']:.1f} %")
        name = f"rendered {zen}, rho {RHO}, 5 events"
        opt[name] = (opt[name], f"+{100 * stats[f'multiple {zen}']:.1f} % radiance")
    out.update(opt)
    for look in (90, 0):
        for inc in (35, 60):
            for looks in (None, 1, 4):
                s = fg.radar.simulate(dem, cell, look_azimuth=look, incidence=inc, looks=looks,
                                      seed=7, **SURF)
                tag = "no speckle" if looks is None else f"{looks}-look"
                frac = f"{100 * s.layover.mean():.1f} % / {100 * s.shadow.mean():.1f} %"
                out[f"SAR look {look}, {inc} deg, {tag}"] = (s.image, frac) if looks is None else s.image
    return out


def main_real(spp):
    t0 = time.time()
    dems = {"Alps (256², 494-2328 m)": fg.data.srtm_alps(), "Po plain (400², 171-544 m)": fg.data.srtm_po_plain()}
    ests = ("variogram", "spectral", "dbc", "transform")
    print("| DEM | image | layover / shadow | " + " | ".join(ests) + " |")
    print("|" + "---|" * (3 + len(ests)))
    for dname, (dem, info) in dems.items():
        z = dem.astype(np.float64)
        for name, img in real_renders(z, info["cell_size"], spp).items():
            frac = ""
            if isinstance(img, tuple):
                img, frac = img
            img = np.where(np.isfinite(img), img, np.nanmedian(img))
            e = estimates(img)
            print(f"| {dname} | {name} | {frac} | " + " | ".join(f"{e[k]:.2f}" for k in ests) + " |", flush=True)
    print(f"\nspp {spp}: {time.time() - t0:.0f} s wall, load average {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    p = argparse.ArgumentParser()
    p.add_argument("--size", type=int, default=None, help="fBm DEM side (default 512; 256 with --optical)")
    p.add_argument("--seeds", type=int, default=2)
    p.add_argument("--optical", action="store_true", help="hillshade against the path tracer on the fBm DEMs")
    p.add_argument("--spp", type=int, default=64, help="paths per pixel of the path-traced images")
    p.add_argument("--real", action="store_true", help="the bundled real DEMs instead of fBm")
    a = p.parse_args()
    if a.real:
        main_real(a.spp)
    else:
        main(a.size or (256 if a.optical else 512), a.seeds, a.optical, a.spp)
