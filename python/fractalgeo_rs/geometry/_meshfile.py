"""Where a written mesh lies on Earth: the one sidecar of every mesh file.

A mesh file's vertices are relative to an ``offset`` (map ``x, y, z`` =
file ``x, y, z`` + offset). Beside ``name.obj`` or ``name.ply`` the writers
(:meth:`~fractalgeo_rs.geometry.Mesh.write`, ``TIN.write_obj`` /
``write_ply``, ``fractalgeo tin``, ``fractalgeo canopy``) put

* ``name.json``: ``description``, ``coordinates``, ``offset`` (3 floats),
  ``crs_wkt`` (WKT or null), ``dem_transform`` (rasterio's ``a..f`` or
  null), ``vertices``, ``triangles`` and, for a mesh in a local metric frame
  of a geographic DEM, ``local_frame`` (see ``docs/geometry.md``);
* ``name.prj``: the CRS as WKT, when there is one (without one, an old
  ``name.prj`` is removed).

Each file is written atomically (whole or not at all).
"""
from __future__ import annotations

import json
import os
from typing import Optional, Tuple

import numpy as np
from numpy.typing import ArrayLike

from fractalgeo_rs._validation import atomic_write_path

__all__ = ["crs_wkt", "header_lines", "write_sidecars"]


def crs_wkt(crs) -> Optional[str]:
    """The WKT of ``crs`` (a rasterio or pyproj CRS, ``"EPSG:n"``, WKT or
    PROJ text); ``None`` for ``None``; the text as given without rasterio.
    ``ValueError`` naming ``crs`` when rasterio does not understand it."""
    if crs is None:
        return None
    if hasattr(crs, "to_wkt"):
        return crs.to_wkt()
    try:
        from rasterio.crs import CRS
    except ImportError:  # no rasterio: the CRS as given
        return str(crs)
    try:
        return CRS.from_user_input(crs).to_wkt()
    except Exception as exc:  # rasterio's CRSError
        raise ValueError(f"crs: not a CRS rasterio understands: {crs!r} ({exc})") from None


def header_lines(title: str, n_vertices: int, n_triangles: int, offset: ArrayLike, wkt: Optional[str],
                 coordinates: str) -> list:
    """The lines a mesh file's header records (OBJ ``#`` comments, PLY
    ``comment`` lines): the title and counts, the coordinates rule, the
    offset (``repr`` of each float64, exact) and the CRS on one line."""
    lines = [f"{title}: {n_vertices} vertices, {n_triangles} triangles",
             f"coordinates {coordinates}: map x y z = file x y z + offset",
             "offset " + " ".join(repr(float(v)) for v in np.asarray(offset, dtype=np.float64).ravel())]
    if wkt is not None:
        lines.append("crs " + " ".join(wkt.split()))
    return lines


def write_sidecars(path, offset: ArrayLike, *, wkt: Optional[str], transform=None, n_vertices: int,
                   n_triangles: int, coordinates: str, description: str,
                   local_frame: Optional[dict] = None) -> Tuple[str, ...]:
    """Write ``name.json`` (and ``name.prj`` when ``wkt``) beside the mesh
    file ``path``, each atomically; return their paths."""
    stem = os.path.splitext(os.fspath(path))[0]
    off = np.asarray(offset, dtype=np.float64)
    if off.shape != (3,) or not np.all(np.isfinite(off)):
        raise ValueError(f"offset: expected 3 finite numbers, got {offset!r}")
    meta: dict = {
        "description": description,
        "coordinates": coordinates,
        "offset": [float(v) for v in off],
        "crs_wkt": wkt,
        "dem_transform": None if transform is None else [float(v) for v in tuple(transform)[:6]],
        "vertices": int(n_vertices),
        "triangles": int(n_triangles),
    }
    if local_frame is not None:
        meta["local_frame"] = local_frame
    written = [stem + ".json"]
    with atomic_write_path(stem + ".json") as tmp:
        with open(tmp, "w") as fh:
            json.dump(meta, fh, indent=1)
            fh.write("\n")
    if wkt is not None:
        with atomic_write_path(stem + ".prj") as tmp:
            with open(tmp, "w") as fh:
                fh.write(wkt)
        written.append(stem + ".prj")
    elif os.path.exists(stem + ".prj"):
        os.remove(stem + ".prj")  # a stale CRS of an earlier write would contradict crs_wkt: null
    return tuple(written)
