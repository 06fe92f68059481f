"""The Python package keeps its layers: no module imports upward, and no
module imports another module's private names.

Layers, bottom to top (``docs/developer.md``, "The layers"):

1. foundation: the extension ``_core`` and the helpers every module may use
   (``_warn``, ``_compat``);
2. services: argument checks, seeds, the raster dispatcher, progress, scale
   lists and the height unit, the fit, raster I/O, plotting, bundled data,
   the CLI's shared options; they import the foundation and each other, no
   domain;
3. geometry (``geometry``: ``Mesh``, ``GeoGrid``), below every domain;
4. domains (``dimension``, ``synth``, ``transform``, ``dem``, ``lsystem``,
   ``tin``): each imports the layers below and only the domains listed in
   ``DOMAIN_DEPS``;
5. the top (the package ``__init__``, ``cli``, ``demo``, and each domain's
   command-line module ``<domain>._cli``): anything.

The test reads the sources (``ast``), so it also sees imports inside
functions.
"""
import ast
from pathlib import Path

import pytest

PKG = Path(__file__).resolve().parents[1] / "python" / "fractalgeo_rs"

FOUNDATION = {"_core", "_warn", "_compat"}
SERVICES = {"_validation", "_progress", "_backend", "_geodesy", "_scales", "_zscale", "fit", "io", "plotting", "data",
            "_cli_common"}
GEOMETRY = {"geometry"}
DOMAINS = {"dimension", "synth", "transform", "dem", "lsystem", "tin", "radar", "radiometry", "canopy"}
TOP = {"__init__", "cli", "demo"}

# The domains a domain may import (downward edges only).
DOMAIN_DEPS = {
    "dimension": set(),
    "synth": set(),
    "lsystem": set(),
    "transform": {"dimension"},
    "dem": set(),
    "tin": {"dem"},
    "radar": {"synth"},  # fBm surfaces for physical optics
    "radiometry": set(),
    "canopy": {"radiometry", "lsystem"},  # leaf optics; L-system plants
}

# Edges that break the layers today and are being removed by the work of
# issue 25 in files other owners are editing; remove a line when its edge
# is gone (the test then keeps it gone).
PENDING_EDGES: set = set()
PENDING_PRIVATE: set = set()


def _modules():
    for path in sorted(PKG.rglob("*.py")):
        rel = path.relative_to(PKG).with_suffix("")
        name = ".".join(rel.parts)
        yield name.removesuffix(".__init__") if name != "__init__" else name, path


MODULES = dict(_modules())


def _is_module(dotted):
    """``dotted`` (below the package) names a module or package of ours."""
    return dotted in MODULES or dotted == "_core"


def _imports(name, path):
    """``(line, target module below the package, imported names)`` for
    every import of our package in ``path``."""
    tree = ast.parse(path.read_text(), filename=str(path))
    pkg_parts = name.split(".") if path.name == "__init__.py" else name.split(".")[:-1]
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for a in node.names:
                if a.name.startswith("fractalgeo_rs."):
                    yield node.lineno, a.name.removeprefix("fractalgeo_rs."), []
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = pkg_parts[: len(pkg_parts) - (node.level - 1)]
                mod = ".".join(base + ([node.module] if node.module else []))
            elif node.module == "fractalgeo_rs":
                mod = ""
            elif node.module and node.module.startswith("fractalgeo_rs."):
                mod = node.module.removeprefix("fractalgeo_rs.")
            else:
                continue
            names = [a.name for a in node.names]
            if mod == "":  # from fractalgeo_rs import _core, dem, ...
                for n in names:
                    yield node.lineno, n if _is_module(n) else "__init__", [] if _is_module(n) else [n]
            else:
                # from pkg import submodule: the submodule is what is imported
                subs = [n for n in names if _is_module(f"{mod}.{n}")]
                for n in subs:
                    yield node.lineno, f"{mod}.{n}", []
                rest = [n for n in names if n not in subs]
                if rest:
                    yield node.lineno, mod, rest


def _unit(dotted):
    # a domain's command-line module (``synth._cli``) belongs to the top
    # layer with ``cli``: it may shade a synthetic DEM with ``dem``'s hillshade
    if dotted.endswith("._cli"):
        return "cli"
    return "__init__" if dotted == "__init__" else dotted.split(".")[0]


def _layer(unit):
    for layer, units in enumerate((FOUNDATION, SERVICES, GEOMETRY, DOMAINS, TOP)):
        if unit in units:
            return layer
    raise AssertionError(f"{unit}: a module the layer map does not know; add it to a layer")


def _allowed(src_unit, dst_unit):
    if src_unit == dst_unit:
        return True
    src, dst = _layer(src_unit), _layer(dst_unit)
    if src == 4:
        return True
    if src == 3 and dst == 3:
        return dst_unit in DOMAIN_DEPS[src_unit]
    if src == 1 and dst == 1:
        return True
    if src == 0 and dst == 0:
        return True
    return dst < src


def test_every_module_is_in_a_layer():
    for name in MODULES:
        _layer(_unit(name))


def test_no_module_imports_upward():
    bad = []
    for name, path in MODULES.items():
        for line, target, _ in _imports(name, path):
            src, dst = _unit(name), _unit(target)
            if not _allowed(src, dst) and (name, dst) not in PENDING_EDGES:
                bad.append(f"{path.relative_to(PKG)}:{line}: {src} (layer {_layer(src)}) imports {target} "
                           f"(layer {_layer(dst)})")
    assert not bad, "\n".join(bad)


def test_no_private_name_is_imported_across_modules():
    bad = []
    for name, path in MODULES.items():
        if name in PENDING_PRIVATE:
            continue
        for line, target, names in _imports(name, path):
            private = [n for n in names if n.startswith("_") and not n.startswith("__")]
            if private:
                bad.append(f"{path.relative_to(PKG)}:{line}: imports {', '.join(private)} from {target}")
    assert not bad, "\n".join(bad)


@pytest.mark.parametrize("src,dst,ok", [
    ("_validation", "transform", False),  # a service never imports a domain
    ("transform", "dimension", True),
    ("dimension", "transform", False),
    ("synth", "dem", False),
    ("tin", "lsystem", False),
    ("dem", "_validation", True),
    ("cli", "tin", True),
])
def test_the_rule_itself(src, dst, ok):
    assert _allowed(src, dst) is ok
