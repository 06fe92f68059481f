"""Every Examples section of every module of the package runs as written.

The modules are found by walking the installed package (no hand-kept list),
so a new module's examples are tested from the day it lands.
"""
import doctest
import importlib
import pkgutil

import pytest

import fractalgeo_rs

MODULES = sorted(
    m.name for m in pkgutil.walk_packages(fractalgeo_rs.__path__, "fractalgeo_rs.")
    if not m.name.endswith("._core")
)


@pytest.mark.parametrize("name", MODULES)
def test_docstring_examples(name):
    mod = importlib.import_module(name)
    res = doctest.testmod(mod, optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE, verbose=False)
    assert res.failed == 0, f"{res.failed} of {res.attempted} examples of {name} failed"


def test_modules_found():
    assert "fractalgeo_rs.transform" in MODULES and "fractalgeo_rs.lsystem.core" in MODULES
