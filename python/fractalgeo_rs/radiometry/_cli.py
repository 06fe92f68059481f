"""``fractalgeo render`` and ``fractalgeo brf``: the virtual radiometric
experiment on a DEM file."""
from __future__ import annotations

import argparse
from typing import Tuple, Union

from fractalgeo_rs._cli_common import HelpFormatter, add_n_threads, add_progress, add_raster_io

#: Parameters of each --material name, in order.
_MATERIALS = {
    "lambertian": ("rho",),
    "oren-nayar": ("rho", "sigma"),
    "oren-nayar-full": ("rho", "sigma"),
    "phong": ("kd", "ks", "exponent"),
    "hapke": ("w", "b", "c", "theta_bar", "B0", "h"),
    "specular": ("eta", "k"),
}
MATERIAL_HELP = ("reflectance model of every facet, NAME:P1,P2,...: lambertian:RHO, oren-nayar:RHO,SIGMA "
                 "(radians; the qualitative model), oren-nayar-full:RHO,SIGMA (the full model with "
                 "interreflection), phong:KD,KS,EXPONENT, hapke:W,B,C,THETA_BAR(degrees),B0,H, specular:ETA,K")

#: Help of ``--sky`` (render and brf).
SKY_HELP = ("irradiance E of a uniform sky on a horizontal plane, in units of the sun's beam irradiance "
            "(0: the sun only); with E > 0 brf reports the HDRF (hemispherical directional reflectance "
            "factor) pi L / (cos(sun zenith) + E) in a column named hdrf")
#: Help of ``--psf`` (render).
PSF_HELP = ("sensor point-spread function: box (uniform over the pixel) or gaussian:SIGMA (isotropic "
            "Gaussian, SIGMA in pixels, truncated at 4 SIGMA)")


def _sky(text: str) -> float:
    import math

    try:
        v = float(text)
    except ValueError:
        raise ValueError(f"sky: expected a horizontal sky irradiance >= 0, got {text!r}") from None
    if not (math.isfinite(v) and v >= 0.0):
        raise ValueError(f"sky: expected a finite sky irradiance >= 0, got {text!r}")
    return v


def _psf(text: str):
    import math

    name, sep, rest = str(text).partition(":")
    name = name.strip().lower()
    if name == "box" and not sep:
        return "box"
    if name == "gaussian" and sep:
        try:
            sigma = float(rest)
        except ValueError:
            sigma = float("nan")
        if math.isfinite(sigma) and sigma > 0.0:
            return ("gaussian", sigma)
    raise ValueError(f"psf: expected box or gaussian:SIGMA (SIGMA > 0, pixels), got {text!r}")


def _common(p: argparse.ArgumentParser) -> None:
    p.add_argument("--material", default="lambertian:0.5", help=MATERIAL_HELP)
    p.add_argument("--sky", default="0", metavar="E", help=SKY_HELP)
    p.add_argument("--finite", action="store_true",
                   help="treat the DEM as a finite patch (rays leaving it escape) instead of one tile of a "
                   "periodic surface")
    p.add_argument("--max-depth", type=int, default=10, help="scattering events per path (1: single scattering)")
    p.add_argument("--seed", type=int, default=0, help="seed of the counter-based random numbers")
    add_n_threads(p)
    add_progress(p)


def add_parsers(sub) -> None:
    p = sub.add_parser(
        "render", formatter_class=HelpFormatter,
        help="radiance image of a DEM lit by the sun (virtual radiometric experiment)",
        description="Path-traced radiance image of a DEM of triangular facets (fractalgeo_rs.radiometry): "
        "directional sun of unit irradiance normal to the beam, orthographic sensor, one pixel per cell by "
        "default. The format follows OUTPUT's extension: .exr (float32), .tif (float32 GeoTIFF with the "
        "DEM's CRS and the image grid's transform), .png (8-bit, 255 = a white Lambertian plane under a "
        "zenith sun), .npy.",
    )
    add_raster_io(p, input="dem", output_help="output .exr, .tif, .png or .npy", cell_size=True)
    p.add_argument("--sun", type=float, nargs=2, required=True, metavar=("AZIMUTH", "ZENITH"),
                   help="direction to the sun, degrees: azimuth clockwise from north, zenith in [0, 90)")
    p.add_argument("--view", nargs="+", default=["nadir"], metavar="VIEW",
                   help="direction to the sensor: 'nadir' or AZIMUTH ZENITH in degrees")
    p.add_argument("--spp", type=int, default=64, help="paths per pixel")
    p.add_argument("--shape", type=int, nargs=2, default=None, metavar=("ROWS", "COLS"),
                   help="image size (None: one pixel per DEM cell)")
    p.add_argument("--psf", default="box", metavar="box|gaussian:SIGMA", help=PSF_HELP)
    _common(p)
    p.set_defaults(func=_run_render)

    q = sub.add_parser(
        "brf", formatter_class=HelpFormatter,
        help="BRF of a DEM over sun zenith angles (virtual radiometric experiment), as CSV",
        description="Bidirectional reflectance factor of a DEM of triangular facets "
        "(fractalgeo_rs.radiometry.Scene.brf_sweep) for each sun zenith and view zenith, with Monte Carlo "
        "standard errors; printed as CSV, or written to --csv. With --sky E > 0 the values are the "
        "hemispherical-directional reflectance factor (HDRF, column hdrf) under the sun and a uniform sky.",
    )
    add_raster_io(q, input="dem", cell_size=True)
    q.add_argument("--sun-zenith", default="0,15,30,45,60,75,89",
                   help="comma-separated sun zenith angles, degrees in [0, 90)")
    q.add_argument("--sun-azimuth", type=float, default=0.0, help="sun azimuth, degrees clockwise from north")
    q.add_argument("--view-zenith", default="0", help="comma-separated view zenith angles, degrees in [0, 90)")
    q.add_argument("--view-azimuth", type=float, default=0.0, help="view azimuth, degrees clockwise from north")
    q.add_argument("--spp", type=int, default=65536, help="paths per BRF value")
    q.add_argument("--csv", default=None, help="output CSV file (None: print to stdout)")
    _common(q)
    q.set_defaults(func=_run_brf)


def _parse_material(text: str):
    from fractalgeo_rs import radiometry

    name, _, rest = str(text).partition(":")
    name = name.strip().lower()
    if name not in _MATERIALS:
        raise ValueError(f"material: expected one of {', '.join(_MATERIALS)} (NAME:P1,P2,...), got {name!r}")
    try:
        values = [float(v) for v in rest.split(",")] if rest.strip() else []
    except ValueError:
        raise ValueError(f"material: expected numbers after '{name}:', got {rest!r}") from None
    want = _MATERIALS[name]
    if len(values) != len(want):
        raise ValueError(f"material: {name} takes {len(want)} parameter(s) ({', '.join(want)}), got {len(values)}")
    cls = {"lambertian": radiometry.Lambertian, "oren-nayar": radiometry.OrenNayar,
           "oren-nayar-full": radiometry.OrenNayar, "phong": radiometry.Phong, "hapke": radiometry.Hapke,
           "specular": radiometry.Specular}[name]
    kwargs = {"full": True} if name == "oren-nayar-full" else {}
    try:
        return cls(*values, **kwargs)
    except (TypeError, ValueError) as exc:  # a parameter out of range: name the option
        raise ValueError(f"material: {name}: {exc}") from None


def _angle_list(text: str, name: str):
    try:
        return [float(v) for v in str(text).split(",") if v.strip()]
    except ValueError:
        raise ValueError(f"{name}: expected comma-separated angles in degrees, got {text!r}") from None


def _scene(args: argparse.Namespace):
    from fractalgeo_rs.dem._cli import read_dem_ground
    from fractalgeo_rs.radiometry import Scene

    z, prof, cell = read_dem_ground(args.dem, args.band, args.cell_size)
    if cell is None:
        raise ValueError("cell_size: the DEM has no georeferencing; pass --cell-size (in the unit of the heights)")
    return Scene.from_dem(z, cell_size=cell, periodic=not args.finite, material=_parse_material(args.material),
                          profile=prof)


def _run_render(args: argparse.Namespace) -> int:
    from fractalgeo_rs._progress import resolve

    view: Union[str, Tuple[float, float]]
    if args.view == ["nadir"]:
        view = "nadir"
    elif len(args.view) == 2:
        try:
            view = (float(args.view[0]), float(args.view[1]))
        except ValueError:
            raise ValueError(f"view: expected 'nadir' or AZIMUTH ZENITH in degrees, got {args.view}") from None
    else:
        raise ValueError(f"view: expected 'nadir' or AZIMUTH ZENITH in degrees, got {args.view}")
    import os

    # checked before the (possibly long) render, not after it in save_image
    if os.path.splitext(args.output)[1].lower() not in (".exr", ".tif", ".tiff", ".png", ".npy"):
        raise ValueError(f"output: expected a .exr, .tif, .png or .npy file name, got {args.output!r}")
    parent = os.path.dirname(os.path.abspath(args.output))
    if not os.path.isdir(parent):
        raise ValueError(f"output: directory {parent!r} does not exist")
    sky, psf = _sky(args.sky), _psf(args.psf)
    scene = _scene(args)
    img = scene.render(sun=tuple(args.sun), view=view, shape=tuple(args.shape) if args.shape else None,
                       spp=args.spp, max_depth=args.max_depth, seed=args.seed, n_threads=args.n_threads,
                       progress=resolve(args.progress, cli=True), sky=sky, psf=psf)
    scene.save_image(args.output, img)
    import math

    brf = math.pi * float(img.mean()) / (math.cos(math.radians(args.sun[1])) + sky)
    print(f"render: {img.shape[0]} x {img.shape[1]} image, {args.spp} paths per pixel, sun {args.sun[0]:g} "
          f"{args.sun[1]:g}: mean {'HDRF' if sky > 0 else 'BRF'} {brf:.5g} -> {args.output}")
    return 0


def _run_brf(args: argparse.Namespace) -> int:
    import io
    import sys

    from fractalgeo_rs._progress import resolve
    from fractalgeo_rs._validation import atomic_write_path

    sky = _sky(args.sky)
    scene = _scene(args)
    sw = scene.brf_sweep(sun_zenith=_angle_list(args.sun_zenith, "sun_zenith"),
                         view_zenith=_angle_list(args.view_zenith, "view_zenith"),
                         sun_azimuth=args.sun_azimuth, view_azimuth=args.view_azimuth, spp=args.spp,
                         max_depth=args.max_depth, seed=args.seed, n_threads=args.n_threads,
                         progress=resolve(args.progress, cli=True), sky=sky)
    out = io.StringIO()
    # with a sky the values are HDRFs: the column says so
    out.write(f"sun_zenith,sun_azimuth,view_zenith,view_azimuth,{'hdrf' if sky > 0 else 'brf'},se,n\n")
    for i, zs in enumerate(sw.sun_zenith):
        for j, zv in enumerate(sw.view_zenith):
            out.write(f"{zs:g},{sw.sun_azimuth:g},{zv:g},{sw.view_azimuth:g},{sw.value[i, j]:.8g},"
                      f"{sw.se[i, j]:.3g},{sw.n}\n")
    if args.csv:
        with atomic_write_path(args.csv) as tmp:
            with open(tmp, "w", encoding="utf-8", newline="") as f:
                f.write(out.getvalue())
        print(f"brf: {sw.value.size} values, {args.spp} paths each -> {args.csv}")
    else:
        sys.stdout.write(out.getvalue())
    return 0
