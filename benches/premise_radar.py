"""The paper's premise measured: is the image of a fractal surface a fractal
of the same dimension (Pentland 1984)?

fBm DEMs of known H (D = 3 - H) are rendered as SAR intensity images
(:func:`fractalgeo_rs.radar.simulate`, with and without speckle, two
incidences) and as Lambertian shaded relief, and the dimension of each image
(taken as an intensity surface) is estimated with the package's whole-image
estimators (variogram, spectral, DBC) and the median of the fractal
transform (variogram method, 33-pixel windows). Prints a Markdown table
(the one in docs/radar.md).

``--real`` instead measures the bundled real DEMs (``fg.data.srtm_alps``,
``fg.data.srtm_po_plain``, SRTM 3", their own cell sizes in metres): each
DEM's dimension against its SAR images (35 and 60 deg, looking east and
north, without speckle and with 1 and 4 looks) and its hillshade, the same
estimators (the second table in docs/radar.md).

Run: ``python benches/premise_radar.py [--size 512] [--seeds 2] [--real]``.
"""
import argparse
import warnings

import numpy as np

import fractalgeo_rs as fg

CELL = 10.0
SURF = dict(wavelength=0.056, model="kirchhoff", permittivity=5 + 0.5j, rms_height=0.01, correlation_length=0.1,
            correlation="exponential")


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


def main(size, seeds):
    hursts = (0.3, 0.5, 0.7, 0.9)
    rows = {}
    for h in hursts:
        for seed in range(seeds):
            # rms slope about 0.25 at the 10 m cell
            dem = fg.fbm_surface(size, h, method="exact", seed=seed, cell_size=CELL,
                                 sigma=0.25 * CELL ** (1 - h))
            for name, img in renders(dem, seed + 100).items():
                img = np.where(np.isfinite(img), img, np.nanmedian(img))
                for est, d in estimates(img).items():
                    rows.setdefault((name, est), {}).setdefault(h, []).append(d)
    head = "| image | estimator | " + " | ".join(f"D = {3 - h:.1f}" for h in hursts) + " |"
    print(head)
    print("|" + "---|" * (2 + len(hursts)))
    for (name, est), by_h in rows.items():
        cells = " | ".join(f"{np.mean(by_h[h]):.2f}" for h in hursts)
        print(f"| {name} | {est} | {cells} |")


def real_renders(dem, cell):
    """SAR renders of a real DEM at its own (row, column) spacing ``cell`` in metres."""
    out = {"DEM itself": dem, "hillshade 315/45": fg.hillshade(dem, cell_size=cell)}
    for look in (90, 0):
        for inc in (35, 60):
            for looks in (None, 1, 4):
                s = fg.radar.simulate(dem, cell, look_azimuth=look, incidence=inc, looks=looks,
                                      seed=7, **SURF)
                tag = "no speckle" if looks is None else f"{looks}-look"
                frac = (s.layover.mean(), s.shadow.mean())
                out[f"SAR look {look}, {inc} deg, {tag}"] = (s.image, frac) if looks is None else s.image
    return out


def main_real():
    dems = {"Alps (256², 494-2328 m)": fg.data.srtm_alps(), "Po plain (400², 171-544 m)": fg.data.srtm_po_plain()}
    ests = ("variogram", "spectral", "dbc", "transform")
    print("| DEM | image | layover / shadow | " + " | ".join(ests) + " |")
    print("|" + "---|" * (3 + len(ests)))
    for dname, (dem, info) in dems.items():
        z = dem.astype(np.float64)
        for name, img in real_renders(z, info["cell_size"]).items():
            frac = ""
            if isinstance(img, tuple):
                img, (lay, shd) = img
                frac = f"{100 * lay:.1f} % / {100 * shd:.1f} %"
            img = np.where(np.isfinite(img), img, np.nanmedian(img))
            e = estimates(img)
            print(f"| {dname} | {name} | {frac} | " + " | ".join(f"{e[k]:.2f}" for k in ests) + " |", flush=True)


if __name__ == "__main__":
    p = argparse.ArgumentParser()
    p.add_argument("--size", type=int, default=512)
    p.add_argument("--seeds", type=int, default=2)
    p.add_argument("--real", action="store_true", help="the bundled real DEMs instead of fBm")
    a = p.parse_args()
    if a.real:
        main_real()
    else:
        main(a.size, a.seeds)
