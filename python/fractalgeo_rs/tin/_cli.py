"""``fractalgeo tin``: an error-bounded TIN of a DEM, written as PLY or OBJ."""
from __future__ import annotations

import argparse
import sys
import time

from fractalgeo_rs._cli_common import HelpFormatter, add_cell_size, add_raster_io, input_georef, is_geographic


def add_parsers(sub) -> None:
    p = sub.add_parser(
        "tin", formatter_class=HelpFormatter,
        help="error-bounded triangulated mesh (TIN) of a DEM as PLY or OBJ",
        description="Greedy error-bounded TIN of a DEM (Garland-Heckbert): every valid sample is within "
        "--max-error of the mesh (unless --max-triangles stops it first). Georeferencing and nodata come "
        "from the file when it has them; nodata areas become holes. The mesh keeps its place on Earth: "
        "vertices are float64, relative to the lower-left corner with that offset recorded in the file "
        "(OBJ '# offset X Y Z', PLY 'comment offset X Y Z') and in a JSON sidecar (offset, CRS, transform), "
        "the CRS as WKT in a .prj sidecar; --coordinates map writes map coordinates instead. The --preview "
        "PNG gets a world file (.pgw) and .prj. Prints vertex and triangle counts and the achieved maximum "
        "error. A DEM in a geographic CRS (e.g. SRTM .hgt, EPSG:4326) gives x, y in degrees and z in metres "
        "(a warning says so): reproject it for a metric mesh.",
    )
    add_raster_io(p, input="dem", output_help="output mesh (.ply or .obj)")
    p.add_argument("--max-error", type=float, default=None,
                   help="largest vertical error in DEM units (None: 0.5%% of the 2-98%% relief)")
    p.add_argument("--max-triangles", type=int, default=None, help="triangle budget (None: no budget)")
    p.add_argument("--tile-edges", choices=("shared", "free"), default="shared",
                   help="shared: outer-edge vertices depend only on the edge samples, so adjacent tiles join "
                   "without cracks; free: edges refined like the interior")
    p.add_argument("--coordinates", choices=("local", "map"), default="local",
                   help="local: vertices relative to the mesh's lower-left corner, the offset recorded in the "
                   "file and the JSON sidecar; map: vertices in map coordinates")
    add_cell_size(p)
    p.add_argument("--preview", metavar="PNG", default=None,
                   help="also write a georeferenced shaded-relief PNG of the mesh (None: no preview)")
    p.set_defaults(func=_run_tin)


def _run_tin(args: argparse.Namespace) -> int:
    from fractalgeo_rs.io import read_raster
    from fractalgeo_rs.tin import tin_from_dem

    ext = str(args.output).lower().rsplit(".", 1)[-1]
    if ext not in ("ply", "obj"):
        raise ValueError(f"output: expected a .ply or .obj file, got {args.output!r}")
    z, prof = read_raster(args.dem, band=args.band)
    geo = input_georef(args, prof, z.shape, name="dem")
    if is_geographic(geo["crs"]) and args.cell_size is None:
        print("fractalgeo tin: warning: the DEM's CRS is geographic, so the mesh has x, y in degrees and "
              "z in metres; a projected DEM (e.g. UTM) gives a metric mesh", file=sys.stderr)
    t0 = time.perf_counter()
    tin = tin_from_dem(z, max_error=args.max_error, max_triangles=args.max_triangles, transform=geo["transform"],
                       nodata=geo["nodata"], tile_edges=args.tile_edges)
    dt = time.perf_counter() - t0
    if ext == "ply":
        tin.write_ply(args.output, coordinates=args.coordinates, crs=geo["crs"])
    else:
        tin.write_obj(args.output, coordinates=args.coordinates, crs=geo["crs"])
    if args.preview:
        tin.write_png(args.preview, crs=geo["crs"])
    print(f"{len(tin.vertices)} vertices, {len(tin.triangles)} triangles, max error {tin.max_error:.6g} "
          f"({z.shape[0]} x {z.shape[1]} samples, {dt:.2f} s)")
    if args.coordinates == "local" and len(tin.vertices):
        lo = tin.vertices[:, :2].min(axis=0)
        print(f"vertices relative to the offset ({lo[0]:.17g}, {lo[1]:.17g}, 0), recorded in {args.output} and "
              f"its .json sidecar")
    return 0
