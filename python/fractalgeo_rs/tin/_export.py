"""Georeferenced mesh files of a :class:`~fractalgeo_rs.tin.TIN`.

A terrain mesh keeps its place on Earth: the vertices are written in float64
either in map coordinates (``coordinates="map"``) or relative to an offset
(``coordinates="local"``, the default: the lower-left corner of the mesh,
which keeps coordinates small for 3D viewers that work in float32) with the
offset recorded in the file (an OBJ comment ``# offset X Y Z``, a PLY
``comment offset X Y Z``) and in a JSON sidecar ``name.json`` (offset, CRS,
transform, units); the CRS is also written as WKT in ``name.prj``.

``map x = file x + offset x`` (likewise y, z) to float64 rounding.
"""
from __future__ import annotations

import os
from typing import Tuple

import numpy as np

from fractalgeo_rs._validation import atomic_write_path
from fractalgeo_rs.geometry._meshfile import crs_wkt, header_lines, write_sidecars

COORDINATES = ("local", "map")


def offset_of(vertices: np.ndarray, coordinates: str) -> np.ndarray:
    """The offset subtracted from the vertices: the lower-left corner
    ``(min x, min y, 0)`` for ``"local"``, zero for ``"map"``."""
    if coordinates not in COORDINATES:
        raise ValueError(f"coordinates: expected one of {', '.join(map(repr, COORDINATES))}, got {coordinates!r}")
    off = np.zeros(3)
    if coordinates == "local" and len(vertices):
        off[:2] = vertices[:, :2].min(axis=0)
    return off


def write_tin(tin, path, *, coordinates: str = "local", crs=None) -> Tuple[str, ...]:
    """Write a TIN as OBJ (text) or binary little-endian PLY (by extension),
    vertices in float64, with the offset and CRS recorded (see the module
    docstring). Returns the paths written (mesh, JSON, PRJ when a CRS)."""
    p = os.fspath(path)
    ext = os.path.splitext(p)[1].lower()
    if ext not in (".obj", ".ply"):
        raise ValueError(f"path: expected a .obj or .ply file, got {p!r}")
    v = np.asarray(tin.vertices, dtype=np.float64)
    t = np.asarray(tin.triangles, dtype=np.uint32)
    off = offset_of(v, coordinates)
    rel = v - off
    wkt = crs_wkt(crs)
    head = header_lines("fractalgeo_rs terrain TIN", len(v), len(t), off, wkt, coordinates)
    if ext == ".obj":
        with atomic_write_path(p) as tmp:
            with open(tmp, "w") as fh:
                fh.write("".join(f"# {line}\n" for line in head))
                np.savetxt(fh, rel, fmt="v %.17g %.17g %.17g")
                np.savetxt(fh, t.astype(np.int64) + 1, fmt="f %d %d %d")
    else:
        header = ["ply", "format binary_little_endian 1.0"] + [f"comment {line}" for line in head] + [
            f"element vertex {len(v)}", "property double x", "property double y", "property double z",
            f"element face {len(t)}", "property list uchar uint vertex_indices", "end_header"]
        faces = np.zeros(len(t), dtype=np.dtype([("n", "u1"), ("i", "<u4", (3,))]))
        faces["n"] = 3
        faces["i"] = t
        with atomic_write_path(p) as tmp:
            with open(tmp, "wb") as fh:
                fh.write(("\n".join(header) + "\n").encode("ascii", "replace"))
                fh.write(np.ascontiguousarray(rel, dtype="<f8").tobytes())
                fh.write(faces.tobytes())
    return (p,) + write_sidecars(p, off, wkt=wkt, transform=getattr(tin, "transform", None), n_vertices=len(v),
                                 n_triangles=len(t), coordinates=coordinates,
                                 description="fractalgeo_rs terrain TIN (map x, y, z = file x, y, z + offset)")


def read_tin(path) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(vertices in map coordinates, triangles, offset)`` of a file
    written by :func:`write_tin` (the offset read from the file itself)."""
    p = os.fspath(path)
    off = np.zeros(3)
    if p.lower().endswith(".obj"):
        verts, tris = [], []
        with open(p) as fh:
            for line in fh:
                if line.startswith("# offset "):
                    off = np.array([float(x) for x in line.split()[2:5]])
                elif line.startswith("v "):
                    verts.append([float(x) for x in line.split()[1:4]])
                elif line.startswith("f "):
                    tris.append([int(x.split("/")[0]) - 1 for x in line.split()[1:4]])
        return np.array(verts) + off, np.array(tris, dtype=np.int64), off
    with open(p, "rb") as fh:
        data = fh.read()
    head, body = data.split(b"end_header\n", 1)
    nv = nf = 0
    for line in head.decode("ascii").splitlines():
        w = line.split()
        if w[:2] == ["comment", "offset"]:
            off = np.array([float(x) for x in w[2:5]])
        elif w[:2] == ["element", "vertex"]:
            nv = int(w[2])
        elif w[:2] == ["element", "face"]:
            nf = int(w[2])
    v = np.frombuffer(body[: 24 * nv], dtype="<f8").reshape(nv, 3)
    f = np.frombuffer(body[24 * nv: 24 * nv + 13 * nf], dtype=np.dtype([("n", "u1"), ("i", "<u4", (3,))]))
    return v + off, f["i"].astype(np.int64), off
