"""The type stub of the extension lists exactly what the extension exports."""
import ast
import os

import fractalgeo_rs
from fractalgeo_rs import _core


def test_core_stub_matches_extension():
    pkg = os.path.dirname(fractalgeo_rs.__file__)
    stub = os.path.join(pkg, "_core.pyi")
    tree = ast.parse(open(stub).read())
    names = {n.name for n in tree.body if isinstance(n, (ast.FunctionDef, ast.ClassDef))}
    exported = {n for n in dir(_core) if not n.startswith("_") and callable(getattr(_core, n))}
    assert names == exported
    assert os.path.exists(os.path.join(pkg, "py.typed"))


def test_docstring_examples_run():
    """The Examples sections of the public modules run as written."""
    import doctest
    import importlib

    for name in ["fractalgeo_rs.dimension", "fractalgeo_rs.dimension.boxcount", "fractalgeo_rs.dimension.gls", "fractalgeo_rs.fit",
                 "fractalgeo_rs.io", "fractalgeo_rs.synth._validate", "fractalgeo_rs.transform"]:
        mod = importlib.import_module(name)
        res = doctest.testmod(mod, optionflags=doctest.ELLIPSIS)
        assert res.failed == 0, name
