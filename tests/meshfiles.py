"""Independent readers of the package's mesh files (numpy only, no package
code): OBJ text and binary little-endian PLY, and the JSON sidecar's offset,
so tests can check where a written mesh lies on Earth."""
import json
from pathlib import Path

import numpy as np

_PLY_TYPES = {"char": "i1", "uchar": "u1", "short": "<i2", "ushort": "<u2", "int": "<i4", "uint": "<u4",
              "float": "<f4", "double": "<f8"}


def read_obj(path, dtype=np.float64):
    """``(vertices float64 (n, 3), faces int64 (m, 3) 0-based, groups list of
    the face's ``g`` name, comments list)`` of an OBJ file, the vertex text
    parsed as ``dtype`` (``np.float32`` for ``Mesh.write``'s files, which
    hold float32 values in their shortest round-trip decimal form)."""
    verts, faces, groups, comments = [], [], [], []
    group = None
    for line in Path(path).read_text().splitlines():
        w = line.split()
        if not w:
            continue
        if w[0] == "#":
            comments.append(line[1:].strip())
        elif w[0] == "v":
            verts.append([float(x) for x in w[1:4]])
        elif w[0] == "g":
            group = " ".join(w[1:])
        elif w[0] == "f":
            faces.append([int(x.split("/")[0]) - 1 for x in w[1:4]])
            groups.append(group)
    return np.array(verts, dtype=dtype).astype(np.float64).reshape(-1, 3), np.array(faces, dtype=np.int64).reshape(-1, 3), \
        groups, comments


def read_ply(path):
    """``(vertex record array, face record array, comments)`` of a binary
    little-endian PLY file whose face list is ``uchar`` counts of 3
    indices (the header's properties give every other field)."""
    data = Path(path).read_bytes()
    head, body = data.split(b"end_header\n", 1)
    lines = head.decode("ascii").splitlines()
    assert lines[0] == "ply" and lines[1] == "format binary_little_endian 1.0", lines[:2]
    elements, comments = [], []
    for line in lines[2:]:
        w = line.split()
        if w[0] == "comment":
            comments.append(line[len("comment "):])
        elif w[0] == "element":
            elements.append((w[1], int(w[2]), []))
        elif w[0] == "property" and w[1] == "list":
            assert w[2] == "uchar", line
            elements[-1][2].append(("n", "u1"))
            elements[-1][2].append((w[4], _PLY_TYPES[w[3]], (3,)))
        elif w[0] == "property":
            elements[-1][2].append((w[2], _PLY_TYPES[w[1]]))
    out, pos = {}, 0
    for name, count, props in elements:
        dt = np.dtype(props)
        out[name] = np.frombuffer(body, dt, count=count, offset=pos)
        pos += dt.itemsize * count
    assert pos == len(body), "trailing bytes"
    if "n" in out["face"].dtype.names:
        assert np.all(out["face"]["n"] == 3)
    return out["vertex"], out["face"], comments


def xyz(vertex):
    """The ``x, y, z`` columns of a PLY vertex record array, float64."""
    return np.column_stack([vertex[k].astype(np.float64) for k in ("x", "y", "z")])


def read_mesh(path):
    """``(vertices float64, faces int64, per-face kind or None)`` of an OBJ
    or PLY file of ``Mesh.write`` (float32 values), in the file's own
    coordinates."""
    if str(path).lower().endswith(".obj"):
        v, f, _, _ = read_obj(path, np.float32)
        return v, f, None
    v, f, _ = read_ply(path)
    return xyz(v), f["vertex_indices"].astype(np.int64), (f["kind"] if "kind" in f.dtype.names else None)


def sidecar(path):
    """The JSON sidecar of a mesh file (``name.json``)."""
    p = Path(path)
    return json.loads(p.with_suffix(".json").read_text())


def absolute(path):
    """Vertices of a mesh file plus the sidecar's offset (float64), faces,
    kinds, sidecar."""
    v, f, kinds = read_mesh(path)
    meta = sidecar(path)
    return v + np.asarray(meta["offset"], dtype=np.float64), f, kinds, meta
