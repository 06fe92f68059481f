"""The API reference covers the package's ``__all__`` and every public
callable's docstring has the sections a reader needs, with examples that run.

The list of names is generated from ``fractalgeo_rs.__all__`` (and the
classes and functions in the ``__all__`` of every public subpackage) by ``docs/_apigen.py``, the module the
Sphinx build uses, so names added to ``__all__`` are checked here without
editing this file.
"""
import doctest
import importlib.util
import inspect
import re
import types
from pathlib import Path

import numpy as np
import pytest

import fractalgeo_rs as fg

ROOT = Path(__file__).resolve().parents[1]
_spec = importlib.util.spec_from_file_location("_apigen", ROOT / "docs" / "_apigen.py")
apigen = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(apigen)

NAMES = apigen.public_names()


def _resolve(name):
    obj = fg
    for part in name.split("."):
        obj = getattr(obj, part)
    return obj


def _sections(doc):
    lines = inspect.cleandoc(doc or "").splitlines()
    return {
        lines[i].strip()
        for i in range(len(lines) - 1)
        if lines[i].strip()
        and re.fullmatch(r"-{3,}", lines[i + 1].strip())
        and len(lines[i + 1].strip()) == len(lines[i].strip())
    }


CALLABLES = [n for n in NAMES if not isinstance(_resolve(n), types.ModuleType)]


def test_reference_lists_every_public_name(tmp_path):
    page = tmp_path / "api.rst"
    apigen.write_api_page(page)
    entries = set(re.findall(r"^   (\S+)$", page.read_text(), re.M))
    expected = {n for n in fg.__all__ if n != "__version__"}
    for sub, mod in apigen._subpackages():
        expected |= {
            f"{sub}.{n}" for n in mod.__all__
            if n not in fg.__all__ and (inspect.isclass(getattr(mod, n)) or inspect.isfunction(getattr(mod, n)))
        }
    assert "lsystem.turtle_2d" in expected and "data.srtm_alps" in expected
    assert entries == expected
    assert len(entries) == len(NAMES)


def test_cli_page_lists_every_subcommand(tmp_path):
    page = tmp_path / "cli.rst"
    apigen.write_cli_page(page)
    text = page.read_text()
    for cmd in ("demo", "dimension", "synth", "hillshade", "lsystem", "transform"):
        assert f"``fractalgeo {cmd}``" in text
        assert f"usage: fractalgeo {cmd}" in text


@pytest.mark.parametrize("name", CALLABLES)
def test_docstring_has_its_sections(name):
    obj = _resolve(name)
    found = _sections(obj.__doc__)
    need = {"Examples", "References"}
    if inspect.isclass(obj):
        assert found & {"Parameters", "Attributes"}, f"{name}: no Parameters or Attributes section"
    else:
        need.add("Returns")
        params = [p for p in inspect.signature(obj).parameters.values() if p.kind is not p.VAR_KEYWORD]
        if params:
            need.add("Parameters")
    missing = need - found
    assert not missing, f"{name}: missing {sorted(missing)}"


def _doctests(name):
    obj = _resolve(name)
    finder = doctest.DocTestFinder(recurse=inspect.isclass(obj))
    return [t for t in finder.find(obj, name, globs={"np": np, "fg": fg}) if t.examples]


@pytest.mark.parametrize("name", CALLABLES)
def test_docstring_examples_run(name):
    tests = _doctests(name)
    assert tests, f"{name}: no doctest examples"
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    for t in tests:
        runner.run(t)
    result = runner.summarize(verbose=False)
    assert result.failed == 0, f"{name}: {result.failed} of {result.attempted} doctest examples failed"
