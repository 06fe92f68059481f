"""Every ``_core`` function that takes an array gives the same result for
every memory layout of the same logical array: C order, Fortran order,
negative strides and a strided (non-contiguous) view.

The binding layer (``rust/bindings/convert.rs``) reads arrays of any strides
in their logical order; before it, a Fortran-ordered array was read as if it
were row-major. The table below must name every ``_core`` function whose stub
takes an ndarray (checked against ``_core.pyi``), so a new binding cannot
skip this test.
"""
from __future__ import annotations

import ast
import os
import pathlib

import numpy as np
import pytest

from fractalgeo_rs import _core

STUB = pathlib.Path(_core.__file__).with_name("_core.pyi")
if not STUB.exists():  # editable installs keep the stub in the source tree
    STUB = pathlib.Path(__file__).resolve().parents[1] / "python" / "fractalgeo_rs" / "_core.pyi"


def _layouts(a: np.ndarray):
    """The same logical array in C order, Fortran order, with negative
    strides and as a strided view of a larger buffer."""
    yield "C", np.ascontiguousarray(a)
    if a.ndim >= 2:
        yield "F", np.asfortranarray(a)
    yield "negative", np.flip(np.flip(a).copy())
    big = np.zeros(tuple(2 * n for n in a.shape), dtype=a.dtype)
    view = big[tuple(slice(None, None, 2) for _ in a.shape)]
    view[...] = a
    yield "strided", view


rng = np.random.default_rng(7)
IMG = rng.standard_normal((37, 29)).cumsum(0).cumsum(1)  # rough, not square
MASK = (rng.random((23, 31)) < 0.3).astype(np.uint8)
PROFILE = rng.standard_normal(301).cumsum()


def _mesh(a):
    """write_mesh on a varied vertex array; returns the file bytes."""
    import tempfile

    n = a.shape[0]
    with tempfile.TemporaryDirectory() as d:
        p = os.path.join(d, "m.ply")
        from types import SimpleNamespace

        mesh = SimpleNamespace(origin=(0.0, 0.0, 0.0), vertices=a, normals=a, uvs=a[:, :2],
                               faces=np.array([[0, 1, 2]], np.uint32), part_ids=np.zeros(1, np.uint32),
                               kinds=np.zeros(1, np.uint8), colors=np.zeros(1, np.uint32),
                               instances=np.zeros(1, np.uint32))
        _core.write_mesh(p, "ply", mesh)
        del n
        return pathlib.Path(p).read_bytes()


def _file_bytes(write, a, suffix):
    import tempfile

    with tempfile.TemporaryDirectory() as d:
        p = os.path.join(d, "x" + suffix)
        write(p, a)
        return pathlib.Path(p).read_bytes()


# name: (the array argument, the call on it)
def _dem_scene(a, periodic, split):
    """A one-material DEM scene (what ``radiometry.Scene.from_dem`` builds)."""
    return _core.RadiometryScene.from_dem(a, (1.0, 2.0), periodic, split, [("lambertian", [0.5])], None)


CASES = {
    "box_count_binary": (MASK, lambda a: _core.box_count_binary(a, [1, 2, 4], 1, True)),
    "box_count_point_levels": (rng.random((2000, 2)), lambda a: _core.box_count_point_levels(a, 2, 2, 5.0, 8, 1)),
    "box_count_points": (rng.random((200, 2)), lambda a: _core.box_count_points(a, [0.1, 0.2, 0.4], 1)),
    "dbc_count": (IMG, lambda a: _core.dbc_count(a, [2, 4, 8], 1, 0.0, 1.0)),
    "higuchi_lengths": (PROFILE, lambda a: _core.higuchi_lengths(a, 8)),
    "column_ranges": (IMG, lambda a: _core.column_ranges(a, [2, 4, 8])),
    "write_png": ((IMG * 3 % 255).astype(np.uint8), lambda a: _file_bytes(_core.write_png, a, ".png")),
    "midpoint_refine_1d": (PROFILE[:17], lambda a: _core.midpoint_refine_1d(a, 2, 0.5, 1.0, 1.0, True, 3)),
    "midpoint_refine_2d": (IMG[:9, :7], lambda a: _core.midpoint_refine_2d(a, 2, 0.5, 1.0, 1.0, True, False, 3)),
    "additions_refine_2d": (IMG[:9, :7], lambda a: _core.additions_refine_2d(
        a, 2, 0.5, 1.0, 1.0, 0.0625, [0.5, 0.5, 0.5, 0.5], False, 3)),
    "davies_harte_fbm": (np.sqrt(np.linspace(1.0, 2.0, 65)), lambda a: _core.davies_harte_fbm(a, 64, 1, 0)),
    "hillshade_f64": (IMG, lambda a: _core.hillshade_f64(a, [1.0] * a.shape[0], 1.0, 315.0, 45.0, 1.0, False)),
    "hillshade_gdal_byte": (IMG.astype(np.float32), lambda a: _core.hillshade_gdal_byte(a, 1.0, 1.0, 315.0, 45.0, 1.0, False)),
    "fractal_resample": (IMG[:16, :12], lambda a: _core.fractal_resample(
        a, np.full(a.shape, 0.6) + 0.01 * a / a.max(), np.full(a.shape, 1.0), 1, False, 5, [True])),
    "fractal_resample[per-level hurst]": (
        np.stack([np.full((16, 12), 0.6), 0.3 + 0.01 * IMG[:16, :12] / IMG.max()]),
        lambda a: _core.fractal_resample(IMG[:16, :12], a, np.full((2, 16, 12), 1.0), 2, False, 5,
                                         [True, True])),
    "resample_local_maps": (IMG, lambda a: _core.resample_local_maps(a, 4, 8, 16, (0.05, 0.95))),
    "resample_node_variograms": (IMG, lambda a: _core.resample_node_variograms(a, 4, 8, [1, 2, 4, 8])),
    "resample_interp_nodes": (IMG[:8, :4].reshape(2, 4, 4),
                              lambda a: _core.resample_interp_nodes(a, 1, 1, (24, 24), 8, 8)),
    "resample_local_amplitude": (IMG, lambda a: _core.resample_local_amplitude(
        a, np.ones((a.shape[0] - 8, a.shape[1] - 8)), 4)),
    "tin_delaunay": (rng.random((60, 3)), lambda a: _core.tin_delaunay(a)),
    "tin_greedy": (IMG[:20, :17].copy(), lambda a: _core.tin_greedy(a, 0.5)),
    "tin_grid": (rng.random((60, 2)) * 10, lambda a: _core.tin_grid(
        a, np.sin(a[:, 0]) + a[:, 1], 8, 9, [0.0, 1.0, 0.0, 0.0, 0.0, 1.0], "natural")),
    "tin_rasterize": (np.array([[0.0, 0.0], [7.0, 0.0], [0.0, 6.0], [7.0, 6.0]]), lambda a: _core.tin_rasterize(
        a, np.array([1.0, 2.0, 3.0, 4.0]), np.array([[0, 1, 2], [1, 3, 2]], np.int64), 7, 8)),
    "shade_to_byte": (np.abs(np.sin(IMG)).astype(np.float32), lambda a: _core.shade_to_byte(a)),
    "write_exr": (IMG.astype(np.float32), lambda a: _file_bytes(_core.write_exr, a, ".exr")),
    "write_mesh": (rng.random((3, 3)).astype(np.float32), _mesh),
    "mesh_from_grid": (IMG, lambda a: _core.mesh_from_grid(a, __import__("types").SimpleNamespace(
        origin=(0.0, 37.0), cell_size=(1.0, 1.0), rotation=0.0, crs=None), "alternating")),
    "mesh_from_tin": (np.array([[0.0, 0.0, 1.0], [7.0, 0.5, 2.0], [0.5, 6.0, 3.0], [7.0, 6.0, 4.0]]),
                      lambda a: _core.mesh_from_tin(a, np.array([[0, 1, 2], [1, 3, 2]], np.int64))),
    "ifs_check": (np.array([[0.5, 0, 0, 0.5, 0, 0], [0.5, 0, 0, 0.5, 0.5, 0], [0.5, 0, 0, 0.5, 0.25, 0.5]]),
                  lambda a: _core.ifs_check(a)),
    "ifs_chaos_game": (np.array([[0.5, 0, 0, 0.5, 0, 0], [0.5, 0, 0, 0.5, 0.5, 0], [0.5, 0, 0, 0.5, 0.25, 0.5]]),
                       lambda a: _core.ifs_chaos_game(a, None, 500, 1)),
    "ifs_iterate": (np.array([[0.5, 0, 0, 0.5, 0, 0], [0.5, 0, 0, 0.5, 0.5, 0], [0.5, 0, 0, 0.5, 0.25, 0.5]]),
                    lambda a: _core.ifs_iterate(a, 4, 10_000)),
    "ifs_rasterize": (rng.random((300, 2)), lambda a: _core.ifs_rasterize(a, 16, 16)),
    "variation_transform_map": (IMG, lambda a: _core.variation_transform_map(a, 9, [1, 2], 2.0, False, 0.5, 2)),
    "gls_transform_map": (IMG, lambda a: __import__("fractalgeo_rs.dimension.gls", fromlist=["gls_grid"])
                          .gls_grid(a, 17, 2, 0.5, 1, None)),
    "mass_transform_map": (IMG, lambda a: _core.mass_transform_map(a, 9, [3, 5, 7], 1.0, 0.5, 1)),
    "dbc_transform_map": (IMG, lambda a: _core.dbc_transform_map(a, 9, [2, 3, 4], 1.0, 0.0, False, 0.5, 1)),
    "blanket_transform_map": (IMG, lambda a: _core.blanket_transform_map(a, 9, [1, 2, 3], 1.0, 0.5, 1)),
    "blanket_areas_image": (IMG, lambda a: _core.blanket_areas_image(a, 4, 1.0)),
    "lacunarity_transform_map": (np.abs(IMG), lambda a: _core.lacunarity_transform_map(a, 9, [1, 2, 4], 0.5)),
    "mass_curve_image": (IMG, lambda a: _core.mass_curve_image(a, [3, 5, 7], 1.0)),
    "speckle_f64": (np.abs(IMG), lambda a: _core.speckle_f64(a, 3, 11)),
    "radar_geometry": (IMG, lambda a: _core.radar_geometry(a, 2.0, 1.5, 35.0, [1.0, 0.5, 0.2], 45.0)),
    "radar_project": (np.abs(IMG), lambda a: _core.radar_project(
        a, np.tile(np.arange(a.shape[1], dtype=np.float64), (a.shape[0], 1)) + 0.3 * np.sin(a),
        (a > 1).astype(np.uint8), a.shape[1] + 2)),
    "radar_geocode": (np.abs(IMG), lambda a: _core.radar_geocode(
        a, a + 1, (a > 1).astype(np.uint32) + 1, np.abs(IMG[:, :20]), (IMG[:, :20] > 0).astype(np.uint8) * 2)),
    "radar_scene": (IMG, lambda a: _core.radar_scene(a, 2.0, 1.5, 35.0, [1.0, 0.5, 0.2], 45.0, 3, 5)),
    "radar_slant_extent": (IMG, lambda a: _core.radar_slant_extent(a, 2.0, 35.0)),
    "RadiometryScene.from_dem(...).brf": (IMG[:9, :7], lambda a: _dem_scene(a, False, "ne-sw").brf(
        (30.0, 40.0), (200.0, 20.0), 500, 3, 1)),
    "RadiometryScene.from_dem(...).albedo": (IMG[:9, :7], lambda a: _dem_scene(a, False, "ne-sw").albedo(
        (30.0, 40.0), 500, 3, 1)),
    "radiometry_intersect": (IMG[:9, :7], lambda a: _core.radiometry_intersect(
        a, (1.0, 2.0), False, "ne-sw", np.array([[2.0, -3.0, 99.0], [1.5, -9.0, 99.0]]),
        np.array([[0.1, 0.2, -1.0], [0.0, 0.0, -1.0]]))),
    "radiometry_occluded": (IMG[:9, :7], lambda a: _core.radiometry_occluded(
        a, (1.0, 2.0), True, "ne-sw", np.array([[2.0, -3.0, -99.0], [1.5, -9.0, 99.0]]),
        np.array([[0.1, 0.2, 1.0], [0.0, 0.3, 1.0]]))),
    "RadiometryScene.from_dem(...).brf_sky": (IMG[:9, :7], lambda a: _dem_scene(a, False, "ne-sw").brf_sky(
        (30.0, 40.0), (200.0, 20.0), 0.4, 500, 3, 1)),
    "RadiometryScene.from_dem(...).bhr": (IMG[:9, :7], lambda a: _dem_scene(a, False, "ne-sw").bhr(500, 3, 1)),
    "RadiometryScene.from_dem(...).render_perspective": (IMG[:9, :7], lambda a: _dem_scene(a, True, "ne-sw")
                                                         .render_perspective((30.0, 40.0), 0.2, (3.0, 4.0, 60.0),
                                                                             (3.0, -8.0, 0.0), 40.0, (5, 4), 2, 3, 1)),
    "RadiometryScene.from_dem(...).render_series": (IMG[:9, :7], lambda a: _dem_scene(a, False, "nw-se").render_series(
        [(30.0, 40.0), (100.0, 60.0)], (0.0, 0.0), 0.3, (5, 4), 4, 3, 1, "table", [0.5], np.abs(IMG[:3, :5]))),
    "RadiometryScene.from_dem": (IMG[:9, :7], lambda a: _core.RadiometryScene.from_dem(
        a, (1.0, 2.0), True, "ne-sw", [("lambertian", [0.2]), ("lambertian", [0.9])],
        (np.arange(126) % 2).astype(np.uint32)).render_series([(30.0, 40.0)], (0.0, 0.0), 0.0, (5, 4), 4, 3, 1,
                                                            "box", [])),
}
# functions whose array arguments are not data laid out by the caller
NOT_LAYOUT = {
    "plants_on_terrain": "needs a compiled L-system; its DEM is read through c_order like every map kernel",
}


def _array_taking_functions() -> set:
    tree = ast.parse(STUB.read_text())
    out = set()
    for node in tree.body:
        if isinstance(node, ast.FunctionDef):
            src = ast.unparse(node.args)
            if "NDArray" in src or "np.ndarray" in src:
                out.add(node.name)
    return out


def test_every_array_binding_is_in_the_table():
    missing = _array_taking_functions() - set(CASES) - set(NOT_LAYOUT)
    assert not missing, f"add these _core functions to CASES in {__file__}: {sorted(missing)}"


def _same(x, y, where):
    if isinstance(x, (tuple, list)):
        assert len(x) == len(y), where
        for k, (u, v) in enumerate(zip(x, y)):
            _same(u, v, f"{where}[{k}]")
    elif isinstance(x, dict):
        assert x.keys() == y.keys(), where
        for k in x:
            _same(x[k], y[k], f"{where}[{k!r}]")
    elif isinstance(x, np.ndarray):
        np.testing.assert_array_equal(x, y, err_msg=where)
    else:
        assert x == y, where


@pytest.mark.parametrize("name", sorted(CASES))
def test_layouts_agree(name):
    base, call = CASES[name]
    # the float kernels take float32 and float64; test the given dtype
    ref = call(np.ascontiguousarray(base))
    for label, a in _layouts(base):
        assert np.array_equal(a, base)
        _same(ref, call(a), f"{name} with a {label} array")


def test_fortran_order_was_the_trap():
    """The failure this guards against: the same array in Fortran order
    read as row-major gives other counts (the transpose's)."""
    a = IMG[:, :20]
    f = np.asfortranarray(a)
    assert not np.array_equal(np.ravel(f, order="K"), np.ravel(a, order="C"))
    np.testing.assert_array_equal(_core.dbc_count(f, [2, 4, 8], 1, 0.0, 1.0)[1],
                                  _core.dbc_count(a, [2, 4, 8], 1, 0.0, 1.0)[1])
