"""Turtle geometry, meshes, files and plants on terrain."""

import argparse
import os

import numpy as np
import pytest

from fractalgeo_rs.lsystem import (LSystem, Mesh, plant_mesh, plants_on_terrain, turtle_2d, turtle_3d, write_obj,
                                   write_png, write_svg)
from fractalgeo_rs.lsystem import _cli

BUSH = {
    "A": "[&FL!A]/////'[&FL!A]///////'[&FL!A]",
    "F": "S/////F",
    "S": "FL",
    "L": "['''^^{-f+f+f-|-f+f+f}]",
}


def test_turtle_2d_square_and_parameters():
    d = turtle_2d("F+F+F+F", step=2)
    assert np.allclose(d.xy, [[0, 0], [0, 2], [-2, 2], [-2, 0], [0, 0]])
    d = turtle_2d("F(3)-(45)F(1)", angle=90)
    assert np.allclose(d.xy[-1], [np.sqrt(0.5), 3 + np.sqrt(0.5)])


def test_turtle_3d_rotations_keep_unit_steps_and_widths():
    s = LSystem("A", BUSH).derive(4)
    seg = turtle_3d(s, angle=22.5)
    assert len(seg) == s.count("F")
    assert np.allclose(np.linalg.norm(seg.ends - seg.starts, axis=1), 1.0)
    # '!' multiplies the width by width_factor at each level of A
    assert set(np.round(seg.widths, 12)) <= {round(0.7 ** k, 12) for k in range(6)}
    assert len(seg.polygons) == s.count("{")
    # tropism bends downwards: the lowest point is lower than without it
    bent = turtle_3d(s, angle=22.5, tropism=(0, 0, -1), elasticity=0.3)
    assert bent.ends[:, 2].max() < seg.ends[:, 2].max()


def test_mesh_size_limit_is_a_value_error():
    with pytest.raises(ValueError, match="^lstring:.*triangles"):
        plant_mesh(LSystem("F", {"F": "FF"}).derive(24), sides=16)  # 2^24 segments x 32 triangles


def test_plant_mesh_invariants():
    s = LSystem("A", BUSH).derive(3)
    m = plant_mesh(s, angle=22.5, sides=5)
    n_seg = s.count("F")
    n_leaf = s.count("{")
    assert (m.kinds == 0).sum() == 2 * 5 * n_seg
    # each leaf {-f+f+f-|-f+f+f} has 1 + 6 move vertices, the last back at
    # the first (dropped: it only closed the fan with a zero-area triangle)
    # -> 6 vertices, 4 triangles
    assert (m.kinds == 1).sum() == 4 * n_leaf
    assert m.faces.max() < len(m.vertices)
    assert np.allclose(np.linalg.norm(m.normals, axis=1), 1.0, atol=1e-5)
    assert m.uvs[:, 0].min() >= 0 and m.uvs[:, 0].max() <= 1
    assert set(np.unique(m.part_ids[m.kinds == 0])) == set(range(n_seg))
    assert set(np.unique(m.part_ids[m.kinds == 1])) == set(range(n_leaf))
    m2 = plant_mesh(s, angle=22.5, sides=5, n_threads=2)
    m1 = plant_mesh(s, angle=22.5, sides=5, n_threads=1)
    assert all(np.array_equal(getattr(m1, k), getattr(m2, k)) for k in Mesh.__dataclass_fields__)


def test_obj_ply_svg_png_files(tmp_path):
    s = LSystem("A", BUSH).derive(2)
    m = plant_mesh(s, angle=22.5)
    obj = tmp_path / "p.obj"
    write_obj(m, obj)
    lines = obj.read_text().splitlines()
    verts = np.array([[float(v) for v in ln.split()[1:]] for ln in lines if ln.startswith("v ")])
    assert np.allclose(verts, m.vertices, atol=1e-5)
    faces = np.array([[int(t.split("/")[0]) for t in ln.split()[1:]] for ln in lines if ln.startswith("f ")])
    order = np.argsort(m.kinds, kind="stable")  # branches first, then leaves
    assert np.array_equal(faces - 1, m.faces[order])
    assert sum(ln.startswith("vt ") for ln in lines) == sum(ln.startswith("vn ") for ln in lines) == len(m.vertices)

    ply = tmp_path / "p.ply"
    m.write_ply(ply)
    raw = ply.read_bytes()
    head, body = raw.split(b"end_header\n", 1)
    assert b"element vertex %d" % len(m.vertices) in head and b"property float s" in head
    vdt = np.dtype([(k, "<f4") for k in ("x", "y", "z", "nx", "ny", "nz", "s", "t")])
    fdt = np.dtype([("n", "u1"), ("v", "<u4", 3), ("part", "<u4"), ("kind", "u1"), ("color", "<u4"), ("inst", "<u4")])
    v = np.frombuffer(body, vdt, count=len(m.vertices))
    f = np.frombuffer(body, fdt, offset=len(m.vertices) * vdt.itemsize)
    assert np.array_equal(np.stack([v["x"], v["y"], v["z"]], 1), m.vertices)
    assert np.array_equal(np.stack([v["s"], v["t"]], 1), m.uvs)
    assert np.all(f["n"] == 3) and np.array_equal(f["v"], m.faces) and np.array_equal(f["kind"], m.kinds)

    d = turtle_2d(LSystem("X", {"X": "F[+X]F[-X]+X", "F": "FF"}).derive(4), angle=20)
    svg = tmp_path / "p.svg"
    write_svg(d, svg)
    assert svg.read_text().count("<polyline") == len(d.lines)
    png = tmp_path / "p.png"
    write_png(m, png, size=120)
    write_png(d, tmp_path / "d.png", size=120)
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert sorted(os.listdir(tmp_path)) == ["d.png", "p.json", "p.obj", "p.ply", "p.png", "p.svg"]  # the sidecar, no temp files
    with pytest.raises(OSError):
        write_obj(m, tmp_path / "missing" / "p.obj")


def test_plants_on_terrain_seeded_on_surface():
    sys_ = LSystem("F", {"F": [("F[+F]F", 1), ("F[-F]F", 1), ("FF", 1)]})
    rows, cols, cs = 12, 16, 5.0
    yy, xx = np.mgrid[0:rows, 0:cols]
    x = (xx + 0.5) * cs
    y = (rows - yy - 0.5) * cs
    dem = 0.1 * x - 0.2 * y + 100.0  # a plane: bilinear heights are exact
    kw = dict(cell_size=cs, density=0.01, seed=11, angle=25, scale=2.0, sides=4)
    a, ba = plants_on_terrain(sys_, 3, dem, n_threads=1, **kw)
    b, bb = plants_on_terrain(sys_, 3, dem, n_threads=2, **kw)
    n = round(0.01 * (cols - 1) * cs * (rows - 1) * cs)
    assert len(ba) == n == 41
    assert np.array_equal(ba, bb) and np.array_equal(a.vertices, b.vertices)
    assert np.allclose(ba[:, 2], 0.1 * ba[:, 0] - 0.2 * ba[:, 1] + 100.0)
    assert set(np.unique(a.instances)) == set(range(n))
    # every plant's lowest vertex ring sits at its base height (within the radius)
    for i in (0, 7, 40):
        tri = a.faces[a.instances == i]
        zs = a.vertices[np.unique(tri), 2]
        assert abs(zs.min() - ba[i, 2]) < 2.0 * 0.5 + 1e-4
    with pytest.raises(ValueError, match="^density:"):
        plants_on_terrain(sys_, 3, dem, cell_size=cs, density=100.0, seed=1)
    with pytest.raises(ValueError, match="^cell_size:"):
        plants_on_terrain(sys_, 3, dem, cell_size=0, density=0.01)


def test_cli_writes_obj_png_and_svg(tmp_path, capsys):
    rules = tmp_path / "bush.txt"
    rules.write_text("axiom: A\nn: 3\nangle: 22.5\n" + "\n".join(f"{k} -> {v}" for k, v in BUSH.items()) + "\n")
    parser = argparse.ArgumentParser()
    _cli.add_parsers(parser.add_subparsers(dest="command"))
    args = parser.parse_args(["lsystem", str(rules), "-n", "3", "--out", str(tmp_path / "b.obj"),
                              "--png", str(tmp_path / "b.png")])
    assert args.func(args) == 0
    n_mod = len(LSystem("A", BUSH).derive(3))
    assert f"{n_mod} modules" in capsys.readouterr().out
    assert (tmp_path / "b.obj").stat().st_size > 0 and (tmp_path / "b.png").stat().st_size > 0
    args = parser.parse_args(["lsystem", str(rules), "--out", str(tmp_path / "b.svg")])
    assert args.func(args) == 0
    assert "segments" in capsys.readouterr().out
    flat = tmp_path / "weed.txt"
    flat.write_text("axiom: X\ndimensions: 2\nangle: 20\nX -> F[+X]F[-X]+X\nF -> FF\n")
    args = parser.parse_args(["lsystem", str(flat), "-n", "4", "--png", str(tmp_path / "w.png")])
    assert args.func(args) == 0
    out = capsys.readouterr().out
    assert "segments" in out and "triangles" not in out  # the 2D turtle was used
    args = parser.parse_args(["lsystem", str(rules), "--out", str(tmp_path / "b.txt")])
    with pytest.raises(ValueError, match="--out"):
        args.func(args)


def _areas(m):
    v = m.vertices.astype(np.float64)
    f = m.faces.astype(np.int64)
    return 0.5 * np.linalg.norm(np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]]), axis=1)


# (axiom, rules, n, angle): ABOP figures 1.24a, c, f (branching) and 1.25 (bush with leaves)
PLANTS = [
    ("F", {"F": "F[+F]F[-F]F"}, 4, 25.7),
    ("F", {"F": "FF-[-F+F+F]+[+F-F-F]"}, 3, 22.5),
    ("X", {"X": "F-[[X]+X]+F[+FX]-X", "F": "FF"}, 4, 22.5),
    ("A", BUSH, 5, 22.5),
    ("A", BUSH, 7, 22.5),
    # leaves with repeated and collinear corners
    ("F", {"F": "F[+F{.f..+f.+f.}][-F{.f.f.+f.+ff.}]"}, 3, 90.0),
]


@pytest.mark.parametrize("axiom,rules,n,angle", PLANTS)
def test_plant_mesh_has_no_zero_area_triangle(axiom, rules, n, angle):
    from fractalgeo_rs.geometry import Mesh as GeoMesh

    s = LSystem(axiom, rules).derive(n)
    m = plant_mesh(s, angle=angle)
    area = _areas(m)
    assert len(m) > 0 and area.min() > 0.0
    assert m.faces.max() < len(m.vertices)
    g = GeoMesh.from_triangles(m.vertices, m.faces)  # refuses zero-area triangles
    assert len(g) == len(m)
    # no leaf area was lost: the leaves' area equals that of the turtle's
    # polygons (Newell's vector area, computed here in float64)
    polys = turtle_3d(s, angle=angle).polygons
    want = 0.0
    for p in polys:
        p = np.asarray(p, dtype=np.float64)
        want += 0.5 * np.linalg.norm(np.cross(p, np.roll(p, -1, axis=0)).sum(axis=0))
    assert np.isclose(area[m.kinds == 1].sum(), want, rtol=1e-5, atol=1e-9)
