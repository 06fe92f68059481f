"""``fractalgeo canopy``: a RAMI-like disc canopy as a mesh, with its leaf
statistics (G, gap probability, Beer) per zenith; or, with ``--plant``, a
stand of L-system plants on a DEM with its BRF table."""
from __future__ import annotations

import argparse

from fractalgeo_rs._cli_common import HelpFormatter, add_band, add_cell_size, add_n_threads, add_progress

LAD_HELP = ("leaf angle distribution: planophile, erectophile, plagiophile, extremophile, uniform, spherical, "
            "or one inclination in degrees")

#: The options of each mode (attribute, option), checked against the other mode.
_DISC = (("lai", "--lai"), ("leaf_radius", "--leaf-radius"), ("extent", "--extent"), ("height", "--height"))
_PLANT = (("density", "--density"), ("dem", "--dem"), ("bark", "--bark"), ("plant_scale", "--plant-scale"),
          ("band", "--band"), ("cell_size", "--cell-size"))


#: OBJ group names of a stand's triangle kinds (material ids 0, 1, 2).
_STAND_GROUPS = ("soil", "bark", "leaves")


def add_parsers(sub) -> None:
    p = sub.add_parser(
        "canopy", formatter_class=HelpFormatter,
        help="RAMI-like canopy of disc leaves over a soil, as a mesh, with its gap-fraction table",
        description="Disc mode (--lai, --leaf-radius, --extent, --height): a homogeneous canopy of disc leaves "
        "in a periodic tile (fractalgeo_rs.canopy.disc_canopy): leaves as area-matched polygons with normals "
        "from the leaf angle distribution, independent or non-overlapping. Writes the mesh (.ply or .obj; the "
        "triangle kinds are the material ids, 0 soil and 1 leaf) and prints, per zenith, Ross's G, the exact "
        "gap probability (1 - a G / (A cos theta))^N of independently placed leaves and Beer's "
        "exp(-G LAI / cos theta), as CSV. Plant mode (--plant, --density, --dem): L-system plants of a preset "
        "placed on the DEM (fractalgeo_rs.canopy.plant_stand: bark on the branches, bi-Lambertian leaves, "
        "the DEM as soil, a finite scene over the DEM's cell centres); writes the mesh and prints the nadir "
        "BRF with the sun at each zenith (azimuth 0), split into single and multiple scattering "
        "(Scene.brf_orders), as CSV. Every mesh file gets a JSON sidecar (name.json: map x, y, z = file x, y, z + "
        "offset, the CRS; name.prj with a CRS) and the offset in its header, as fractalgeo tin's: a stand on a "
        "projected DEM is written in the DEM's CRS (x east, y north, z height); on a geographic DEM (degrees) in "
        "a local metric frame from the DEM's south-west corner, whose lon/lat and metres per degree the sidecar "
        "records (local_frame); a disc tile in metres from its corner.",
    )
    p.add_argument("output", nargs="?", default=None, help="output mesh, .ply or .obj (None: no file)")
    p.add_argument("--lai", type=float, default=None,
                   help="disc mode: leaf area index (one-sided leaf area per ground area)")
    p.add_argument("--leaf-radius", type=float, default=None, help="disc mode: disc radius, metres")
    p.add_argument("--extent", type=float, nargs=2, default=None, metavar=("EAST", "NORTH"),
                   help="disc mode: tile size, metres")
    p.add_argument("--height", type=float, nargs=2, default=None, metavar=("BOTTOM", "TOP"),
                   help="disc mode: range of the leaf-centre heights, metres")
    p.add_argument("--lad", default="spherical", help=LAD_HELP)
    p.add_argument("--no-overlap", action="store_true",
                   help="non-overlapping leaves (random sequential addition) instead of independent ones")
    p.add_argument("--sides", type=int, default=12, help="sides of each leaf polygon")
    p.add_argument("--plant", default=None,
                   help="plant mode: the plant preset, bush (ABOP 1.25, about 1.6 m) or herb (stochastic, "
                   "about 1 m)")
    p.add_argument("--density", type=float, default=None, help="plant mode: plants per square metre")
    p.add_argument("--dem", default=None,
                   help="plant mode: the DEM raster (GeoTIFF or any format read_raster reads), heights in metres; "
                   "the cell size from its transform, in metres (a geographic grid is converted at its middle "
                   "latitude)")
    add_band(p)  # plant mode: the DEM's band
    add_cell_size(p, crs=False)  # plant mode: metres, replacing the DEM's (required without georeferencing)
    p.add_argument("--plant-scale", type=float, default=None,
                   help="plant mode: metres per turtle step (None: the preset's, 0.2 bush, 0.08 herb)")
    p.add_argument("--leaf", default="0.4957,0.4409", metavar="R,T",
                   help="leaf reflectance and transmittance (bi-Lambertian; RAMI's near-infrared leaf)")
    p.add_argument("--soil", type=float, default=0.159, help="Lambertian soil reflectance (RAMI's near-infrared)")
    p.add_argument("--bark", type=float, default=None,
                   help="plant mode: Lambertian bark reflectance of the branches (None: 0.3)")
    p.add_argument("--zenith", default="0,15,30,45,60,75", help="comma-separated zeniths of the table, degrees")
    p.add_argument("--seed", type=int, default=None,
                   help="seed of the placement (and of the tracing; None: fresh entropy, printed)")
    p.add_argument("--spp", type=int, default=None,
                   help="rays per traced value (None: 0 in disc mode, 65536 in plant mode); disc mode adds the "
                   "traced gap fraction and the nadir BRF with the sun at each zenith (azimuth 0) and their "
                   "standard errors (0: no tracing)")
    p.add_argument("--max-depth", type=int, default=100, help="scattering events per BRF path")
    add_n_threads(p)
    add_progress(p)
    p.set_defaults(func=_run)


def _lad(text: str):
    try:
        return float(text)
    except ValueError:
        return str(text).strip().lower()


def _renamed(e: ValueError, pairs) -> ValueError:
    """``e`` with a leading ``param:`` spelled as its option."""
    msg = str(e)
    for py, opt in pairs:
        if msg.startswith(py + ":"):
            return ValueError(opt + msg[len(py):])
    return ValueError(msg)


def _zeniths(text: str):
    try:
        zen = [float(v) for v in str(text).split(",") if v.strip()]
    except ValueError:
        raise ValueError(f"zenith: expected comma-separated angles in degrees, got {text!r}") from None
    for z in zen:
        if not 0.0 <= z < 90.0:
            raise ValueError(f"zenith: expected degrees in [0, 90), got {z}")
    return zen


def _leaf(text: str):
    from fractalgeo_rs.radiometry import BiLambertian

    try:
        r, t = (float(v) for v in str(text).split(","))
    except ValueError:
        raise ValueError(f"--leaf: expected R,T (reflectance, transmittance), got {text!r}") from None
    try:
        return BiLambertian(r, t)
    except ValueError as e:
        raise ValueError(f"--leaf: {e}") from None


def _lambertian(value: float, option: str):
    from fractalgeo_rs.radiometry import Lambertian

    try:
        return Lambertian(value)
    except ValueError as e:
        raise ValueError(f"{option}: {e}") from None


def _run(args: argparse.Namespace) -> int:
    if args.plant is not None:
        return _run_plant(args)
    given = [opt for attr, opt in _PLANT if getattr(args, attr, None) is not None]
    if given:
        raise ValueError(f"{given[0]}: only with --plant (plant mode)")
    for attr, opt in _DISC:
        if getattr(args, attr) is None:
            raise ValueError(f"{opt}: required in disc mode (or give --plant, --density and --dem)")
    return _run_discs(args)


def _run_discs(args: argparse.Namespace) -> int:
    import math

    from fractalgeo_rs.canopy import disc_canopy, projection_g
    from fractalgeo_rs.geometry._mesh import write_mesh

    zen = _zeniths(args.zenith)
    leaf, soil = _leaf(args.leaf), _lambertian(args.soil, "--soil")
    spp = 0 if args.spp is None else args.spp
    if args.output:
        _mesh_format(args.output)
    try:
        c = disc_canopy(lai=args.lai, leaf_radius=args.leaf_radius, extent=tuple(args.extent),
                        height=tuple(args.height), lad=_lad(args.lad), overlap=not args.no_overlap,
                        sides=args.sides, seed=args.seed, leaf=leaf, soil=soil)
    except ValueError as e:
        raise _renamed(e, (("leaf_radius", "--leaf-radius"), ("lai", "--lai"), ("lad", "--lad"),
                           ("extent", "--extent"), ("height", "--height"), ("sides", "--sides"),
                           ("seed", "--seed"))) from None
    print(f"# canopy: {c.n_leaves} leaves, lai {c.lai:.6g}, lad {c.lad}, seed {c.seed}, {len(c.mesh)} triangles")
    if args.output:
        write_mesh(c.mesh, args.output, _mesh_format(args.output), groups=("soil", "leaves"))
        print(f"# mesh -> {args.output} (one tile, metres from its south-west corner, no place on Earth; offset in "
              f"the .json sidecar)")
    if spp < 0:
        raise ValueError(f"--spp: expected 0 (no tracing) or a positive number of rays, got {spp}")
    scene = c.scene() if spp else None
    print("zenith,G,gap_exact,gap_beer" + (",gap_traced,gap_se,brf_nadir,brf_se" if scene else ""))
    for z in zen:
        g = projection_g(c.lad, z)
        beer = math.exp(-g * c.lai / math.cos(math.radians(z)))
        row = f"{z:g},{g:.6f},{float(c.gap_probability(z)):.6f},{beer:.6f}"
        if scene is not None:
            gap = scene.gap_fraction(z, n=spp, seed=c.seed % 2**63, n_threads=args.n_threads)
            brf = scene.brf(sun=(0.0, z), view="nadir", spp=spp, max_depth=args.max_depth,
                            seed=c.seed % 2**63, n_threads=args.n_threads)
            row += f",{gap.value:.6f},{gap.se:.2g},{brf.value:.6f},{brf.se:.2g}"
        print(row)
    return 0


def _read_dem(args: argparse.Namespace):
    """Heights, the rasterio profile and ``(dy, dx)`` in metres of ``--dem``
    (``--cell-size`` replaces the file's)."""
    from fractalgeo_rs.dem._cli import read_dem_ground

    side = args.cell_size
    z, prof, cell = read_dem_ground(args.dem, args.band, None if side is None else (side, side), "--dem")
    if cell is None:
        raise ValueError("--cell-size: the DEM has no georeferencing; pass --cell-size (metres)")
    return z, prof, cell


def _stand_placement(args: argparse.Namespace, prof, shape, cell):
    """Where the stand's mesh goes, checked before anything is built:
    ``("map", GeoGrid)`` for a projected (or CRS-less) georeferenced DEM,
    ``("geographic", local_frame dict)`` for a DEM in degrees, ``("local",
    None)`` without georeferencing."""
    from fractalgeo_rs._cli_common import input_georef, is_geographic
    from fractalgeo_rs.geometry import GeoGrid
    from fractalgeo_rs.geometry._meshfile import crs_wkt

    prof = prof or {}
    t, crs = prof.get("transform"), prof.get("crs")
    if t is None or (crs is None and tuple(t)[:6] == (1.0, 0.0, 0.0, 0.0, 1.0, 0.0)):
        return "local", None
    a, b, c, d, e, f = (float(v) for v in tuple(t)[:6])
    if is_geographic(crs):
        if b != 0 or d != 0 or not (a > 0 and e < 0):
            raise ValueError(f"--dem: a geographic DEM must be north up (no rotation) to anchor the stand's metric "
                             f"frame, got transform {(a, b, c, d, e, f)}")
        dy, dx = cell
        rows = shape[0]
        return "geographic", {
            "frame": "local metric frame of a geographic DEM: x east, y north, z the DEM's height, metres",
            "corner_lonlat": [c, f + e * rows],
            "metres_per_degree": [dx / a, dy / -e],
            "crs_wkt": crs_wkt(crs),
            "rule": "lon = corner_lonlat[0] + (file x + offset x) / metres_per_degree[0]; "
                    "lat = corner_lonlat[1] + (file y + offset y) / metres_per_degree[1]",
        }
    geo = input_georef(args, prof, shape, name="dem", announce=False)
    try:
        return "map", GeoGrid.from_affine(tuple(geo["transform"])[:6], crs)
    except ValueError as exc:
        raise ValueError(f"--dem: the stand is built on a north-up grid and cannot be placed on this DEM's "
                         f"grid ({str(exc).split(': ', 1)[1]}); give a north-up DEM") from None


def _write_stand_mesh(path: str, mesh, placement, rows: int) -> str:
    """Write the stand's mesh where ``placement`` says; the words saying where."""
    from fractalgeo_rs.geometry._mesh import write_mesh

    kind, where = placement
    if kind == "map":
        write_mesh(mesh.placed_on(where, rows), path, _mesh_format(path), groups=_STAND_GROUPS)
        return f"map coordinates of the DEM's CRS ({where.crs or 'none given'}) = file + offset in the .json sidecar"
    if kind == "geographic":
        write_mesh(mesh, path, _mesh_format(path), local_frame=where, groups=_STAND_GROUPS)
        return ("a local metric frame (x east, y north, metres from the DEM's south-west corner); the corner's "
                "lon/lat and metres per degree in the .json sidecar, no .prj")
    write_mesh(mesh, path, _mesh_format(path), groups=_STAND_GROUPS)
    return "the DEM has no georeferencing: metres from its south-west corner, offset in the .json sidecar"


def _mesh_format(path: str) -> str:
    ext = str(path).lower().rsplit(".", 1)[-1]
    if ext not in ("obj", "ply"):
        raise ValueError(f"output: expected a .ply or .obj file, got {path!r}")
    return ext


def _run_plant(args: argparse.Namespace) -> int:
    import sys

    from fractalgeo_rs._progress import bar, resolve
    from fractalgeo_rs.canopy import plant_stand

    given = [opt for attr, opt in _DISC if getattr(args, attr) is not None]
    if given:
        raise ValueError(f"{given[0]}: disc mode only, not with --plant")
    for attr, opt in (("density", "--density"), ("dem", "--dem")):
        if getattr(args, attr) is None:
            raise ValueError(f"{opt}: required with --plant")
    zen = _zeniths(args.zenith)
    spp = 65536 if args.spp is None else args.spp
    if spp <= 0:
        raise ValueError(f"--spp: expected a positive number of paths per BRF value, got {spp}")
    if not 1 <= args.max_depth <= 100_000:
        raise ValueError(f"--max-depth: expected 1 to 100000 scattering events, got {args.max_depth}")
    leaf, soil = _leaf(args.leaf), _lambertian(args.soil, "--soil")
    bark = None if args.bark is None else _lambertian(args.bark, "--bark")
    if args.output:
        _mesh_format(args.output)
    z, prof, cell = _read_dem(args)
    placement = _stand_placement(args, prof, z.shape, cell) if args.output else None
    try:
        st = plant_stand(args.plant, args.density, z, cell_size=cell, bark=bark, leaf=leaf, soil=soil,
                         scale=args.plant_scale, seed=args.seed)
    except ValueError as e:
        raise _renamed(e, (("plant", "--plant"), ("density", "--density"), ("dem", "--dem"),
                           ("cell_size", "--cell-size"), ("scale", "--plant-scale"), ("seed", "--seed"),
                           ("max_plants", "--density"))) from None
    print(f"# stand: {len(st.bases)} {st.plant} plants, leaf area {st.leaf_area:.6g} m^2, lai {st.lai:.6g}, "
          f"ground {st.extent[2]:.6g} m x {st.extent[3]:.6g} m (cells {cell[0]:.6g} m x {cell[1]:.6g} m), "
          f"seed {st.seed}, {len(st.mesh)} triangles")
    if args.output:
        where = _write_stand_mesh(args.output, st.mesh, placement, z.shape[0])
        print(f"# mesh -> {args.output} (triangle kinds = material ids: 0 soil, 1 bark, 2 leaf; {where})")
    print("sun_zenith,brf,se,single,single_se,multiple,multiple_se")
    sys.stdout.flush()
    scene = st.scene()
    with bar(len(zen), "canopy brf", resolve(args.progress, cli=True)) as b:
        for z_ in zen:
            o = scene.brf_orders(sun=(0.0, z_), view="nadir", spp=spp, max_depth=args.max_depth,
                                 seed=st.seed % 2**63, n_threads=args.n_threads)
            print(f"{z_:g},{o.total.value:.6f},{o.total.se:.2g},{o.single.value:.6f},{o.single.se:.2g},"
                  f"{o.multiple.value:.6f},{o.multiple.se:.2g}")
            sys.stdout.flush()
            b.update(1)
    return 0
