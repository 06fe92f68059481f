"""``fractalgeo canopy``: a RAMI-like disc canopy as a mesh, with its leaf
statistics (G, gap probability, Beer) per zenith."""
from __future__ import annotations

import argparse

from fractalgeo_rs._cli_common import HelpFormatter, add_n_threads

LAD_HELP = ("leaf angle distribution: planophile, erectophile, plagiophile, extremophile, uniform, spherical, "
            "or one inclination in degrees")


def add_parsers(sub) -> None:
    p = sub.add_parser(
        "canopy", formatter_class=HelpFormatter,
        help="RAMI-like canopy of disc leaves over a soil, as a mesh, with its gap-fraction table",
        description="A homogeneous canopy of disc leaves in a periodic tile (fractalgeo_rs.canopy.disc_canopy): "
        "leaves as area-matched polygons with normals from the leaf angle distribution, independent or "
        "non-overlapping. Writes the mesh (.ply or .obj; the triangle kinds are the material ids, 0 soil and "
        "1 leaf) and prints, per zenith, Ross's G, the exact gap probability (1 - a G / (A cos theta))^N of "
        "independently placed leaves and Beer's exp(-G LAI / cos theta), as CSV.",
    )
    p.add_argument("output", nargs="?", default=None, help="output mesh, .ply or .obj (None: no file)")
    p.add_argument("--lai", type=float, required=True, help="leaf area index (one-sided leaf area per ground area)")
    p.add_argument("--leaf-radius", type=float, required=True, help="disc radius, metres")
    p.add_argument("--extent", type=float, nargs=2, required=True, metavar=("EAST", "NORTH"),
                   help="tile size, metres")
    p.add_argument("--height", type=float, nargs=2, required=True, metavar=("BOTTOM", "TOP"),
                   help="range of the leaf-centre heights, metres")
    p.add_argument("--lad", default="spherical", help=LAD_HELP)
    p.add_argument("--no-overlap", action="store_true",
                   help="non-overlapping leaves (random sequential addition) instead of independent ones")
    p.add_argument("--sides", type=int, default=12, help="sides of each leaf polygon")
    p.add_argument("--zenith", default="0,15,30,45,60,75", help="comma-separated zeniths of the table, degrees")
    p.add_argument("--seed", type=int, default=None, help="seed of the placement (None: fresh entropy, printed)")
    p.add_argument("--spp", type=int, default=0,
                   help="rays per traced value: adds the traced gap fraction and the nadir BRF with the sun at "
                   "each zenith (azimuth 0) and their standard errors (0: no tracing)")
    p.add_argument("--max-depth", type=int, default=100, help="scattering events per BRF path")
    add_n_threads(p)
    p.set_defaults(func=_run)


def _lad(text: str):
    try:
        return float(text)
    except ValueError:
        return str(text).strip().lower()


def _run(args: argparse.Namespace) -> int:
    import math

    from fractalgeo_rs.canopy import disc_canopy, projection_g

    try:
        zen = [float(v) for v in str(args.zenith).split(",") if v.strip()]
    except ValueError:
        raise ValueError(f"zenith: expected comma-separated angles in degrees, got {args.zenith!r}") from None
    for z in zen:
        if not 0.0 <= z < 90.0:
            raise ValueError(f"zenith: expected degrees in [0, 90), got {z}")
    try:
        c = disc_canopy(lai=args.lai, leaf_radius=args.leaf_radius, extent=tuple(args.extent),
                        height=tuple(args.height), lad=_lad(args.lad), overlap=not args.no_overlap,
                        sides=args.sides, seed=args.seed)
    except ValueError as e:
        msg = str(e)
        for py, opt in (("leaf_radius:", "--leaf-radius:"), ("lai:", "--lai:"), ("lad:", "--lad:"),
                        ("extent:", "--extent:"), ("height:", "--height:"), ("sides:", "--sides:"),
                        ("seed:", "--seed:")):
            if msg.startswith(py):
                msg = opt + msg[len(py):]
                break
        raise ValueError(msg) from None
    print(f"# canopy: {c.n_leaves} leaves, lai {c.lai:.6g}, lad {c.lad}, seed {c.seed}, {len(c.mesh)} triangles")
    if args.output:
        c.mesh.write(args.output)
        print(f"# mesh -> {args.output}")
    if args.spp < 0:
        raise ValueError(f"--spp: expected 0 (no tracing) or a positive number of rays, got {args.spp}")
    scene = c.scene() if args.spp else None
    print("zenith,G,gap_exact,gap_beer" + (",gap_traced,gap_se,brf_nadir,brf_se" if scene else ""))
    for z in zen:
        g = projection_g(c.lad, z)
        beer = math.exp(-g * c.lai / math.cos(math.radians(z)))
        row = f"{z:g},{g:.6f},{float(c.gap_probability(z)):.6f},{beer:.6f}"
        if scene is not None:
            gap = scene.gap_fraction(z, n=args.spp, seed=c.seed % 2**63, n_threads=args.n_threads)
            brf = scene.brf(sun=(0.0, z), view="nadir", spp=args.spp, max_depth=args.max_depth,
                            seed=c.seed % 2**63, n_threads=args.n_threads)
            row += f",{gap.value:.6f},{gap.se:.2g},{brf.value:.6f},{brf.se:.2g}"
        print(row)
    return 0
