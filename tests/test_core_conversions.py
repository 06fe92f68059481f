"""Typed conversions at the binding (``rust/bindings``): the kernels' keyword
enums cross as ``FromPyObject`` types read from a str (an unknown value is a
ValueError naming the parameter, a non-str a TypeError naming it), and the
moving-window map bindings follow one dtype policy: float32 and float64
images, read in place.

A float32 image is widened exactly to float64, so its maps must equal the
maps of ``image.astype(np.float64)`` bit for bit (an independent route to the
same numbers: the float64 path, which the map hashes pin).
"""
from __future__ import annotations

import types

import numpy as np
import pytest

from fractalgeo_rs import _core


def _mesh():
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], np.float32)
    return types.SimpleNamespace(origin=(0.0, 0.0, 0.0), vertices=v, normals=v, uvs=v[:, :2],
                                 faces=np.array([[0, 1, 2]], np.uint32), part_ids=np.zeros(1, np.uint32),
                                 kinds=np.zeros(1, np.uint8), colors=np.zeros(1, np.uint32),
                                 instances=np.zeros(1, np.uint32))


GRID = types.SimpleNamespace(origin=(0.0, 4.0), cell_size=(1.0, 1.0), rotation=0.0, crs=None)


@pytest.mark.parametrize("fmt", ["obj", "ply"])
def test_mesh_format_enum_writes(tmp_path, fmt):
    p = tmp_path / f"m.{fmt}"
    _core.write_mesh(str(p), fmt, _mesh())
    data = p.read_bytes()
    if fmt == "ply":
        assert data.startswith(b"ply\nformat binary_little_endian")
    else:
        assert b"\nv " in data and b"\nf " in data


@pytest.mark.parametrize("bad", ["stl", "OBJ", ""])
def test_mesh_format_unknown_value_names_format(tmp_path, bad):
    with pytest.raises(ValueError, match=r"format: expected 'obj' or 'ply'"):
        _core.write_mesh(str(tmp_path / "m.x"), bad, _mesh())
    assert not list(tmp_path.iterdir())  # nothing written


@pytest.mark.parametrize("bad", [3, None, b"obj"])
def test_mesh_format_not_a_str_is_a_type_error(tmp_path, bad):
    with pytest.raises(TypeError, match="format: expected a str"):
        _core.write_mesh(str(tmp_path / "m.obj"), bad, _mesh())


def test_split_enum():
    z = np.zeros((4, 5))
    counts = {s: len(_core.mesh_from_grid(z, GRID, s)["faces"]) for s in ("ne-sw", "nw-se", "alternating")}
    assert counts == dict.fromkeys(counts, 2 * 3 * 4)
    with pytest.raises(ValueError, match="split: expected 'ne-sw', 'nw-se' or 'alternating'"):
        _core.mesh_from_grid(z, GRID, "diagonal")
    with pytest.raises(TypeError, match="split: expected a str"):
        _core.mesh_from_grid(z, GRID, 1)


rng = np.random.default_rng(11)
IMG = rng.standard_normal((37, 29)).cumsum(0).cumsum(1).astype(np.float32)
IMG[5, 7] = np.nan

# the moving-window map bindings: name -> call on the image
MAPS = {
    "dbc_count": lambda a: _core.dbc_count(a, [2, 4, 8], 1, 0.0, 1.0),
    "variation_transform_map": lambda a: _core.variation_transform_map(a, 9, [1, 2], 2.0, False, 0.5, 2),
    "mass_transform_map": lambda a: _core.mass_transform_map(a, 9, [3, 5, 7], 1.0, 0.5, 1),
    "dbc_transform_map": lambda a: _core.dbc_transform_map(a, 9, [2, 3, 4], 1.0, 0.0, False, 0.5, 1),
    "blanket_transform_map": lambda a: _core.blanket_transform_map(a, 9, [1, 2, 3], 1.0, 0.5, 1),
    "lacunarity_transform_map": lambda a: _core.lacunarity_transform_map(np.abs(a), 9, [1, 2, 4], 0.5),
}


def _flat(res):
    if isinstance(res, (tuple, list)):
        return [np.asarray(r) for r in res]
    return [np.asarray(res)]


@pytest.mark.parametrize("name", sorted(MAPS))
def test_map_bindings_take_float32_and_float64_alike(name):
    call = MAPS[name]
    f32 = _flat(call(IMG))
    f64 = _flat(call(IMG.astype(np.float64)))
    assert len(f32) == len(f64)
    for a, b in zip(f32, f64):
        np.testing.assert_array_equal(a, b)
        assert np.isfinite(b).any()


@pytest.mark.parametrize("name", sorted(MAPS))
def test_map_bindings_refuse_other_dtypes_naming_the_parameter(name):
    with pytest.raises(TypeError, match="float32 or float64"):
        MAPS[name](np.nan_to_num(IMG).astype(np.int32))


@pytest.mark.parametrize("method", ["dbc", "blanket"])
def test_fractal_transform_reads_float32_in_place_with_the_float64_result(method):
    import warnings

    import fractalgeo_rs as fg

    z = np.nan_to_num(IMG)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # range warnings of a smooth test image
        a = fg.fractal_transform(z, method=method, window_size=9)
        b = fg.fractal_transform(z.astype(np.float64), method=method, window_size=9)
    np.testing.assert_array_equal(a, b)
    assert np.isfinite(a).any()
