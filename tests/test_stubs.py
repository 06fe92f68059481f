"""The type stub of the extension lists exactly what the extension exports."""
import ast
import os

import fractalgeo_rs
from fractalgeo_rs import _core
from pathlib import Path


def test_core_stub_matches_extension():
    pkg = os.path.dirname(fractalgeo_rs.__file__)
    stub = os.path.join(pkg, "_core.pyi")
    tree = ast.parse(Path(stub).read_text())
    # private stub-only classes (the Protocols of values read by attribute) are not exports
    names = {n.name for n in tree.body
             if isinstance(n, (ast.FunctionDef, ast.ClassDef)) and not n.name.startswith("_")}
    exported = {n for n in dir(_core) if not n.startswith("_") and callable(getattr(_core, n))}
    assert names == exported
    assert os.path.exists(os.path.join(pkg, "py.typed"))

