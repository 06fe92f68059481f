"""Import helper for the synthesis tests.

On the ``synth`` branch the lead engineer's ``fractalgeo_rs.fit`` and
``fractalgeo_rs.dimension`` (imported by the package ``__init__``) may not be
there yet: stand-ins are put in ``sys.modules`` only when the real modules
cannot be found, so once merged this file does nothing.
"""
import importlib.util
import sys
import types


def _ensure(name, attrs):
    try:
        found = importlib.util.find_spec(name) is not None
    except ModuleNotFoundError:
        found = False
    if not found and name not in sys.modules:
        mod = types.ModuleType(name)
        for a in attrs:
            setattr(mod, a, None)
        if name.endswith("dimension"):
            mod.__path__ = []
        sys.modules[name] = mod


_ensure("fractalgeo_rs.fit", ["DimensionFit"])
_ensure("fractalgeo_rs.dimension", ["box_counting", "dimension"])
if isinstance(sys.modules.get("fractalgeo_rs.dimension"), types.ModuleType) and not getattr(
        sys.modules["fractalgeo_rs.dimension"], "__file__", None):
    _ensure("fractalgeo_rs.dimension._cli", [])
    sys.modules["fractalgeo_rs.dimension._cli"].add_parsers = lambda sub: None

import fractalgeo_rs as fg  # noqa: E402

__all__ = ["fg"]
