"""Temporary shim for the lsystem branch: until the lead's ``fit.py`` and
``dimension/`` land, ``fractalgeo_rs/__init__.py`` imports modules that do
not exist on this branch. When they are missing, this installs empty
stand-ins so that ``fractalgeo_rs.lsystem`` can be imported and tested.
It does nothing once the real modules exist; delete it after the merge.
"""
import importlib.util
import os
import sys
import types

_spec = importlib.util.find_spec("fractalgeo_rs")
_root = list(_spec.submodule_search_locations)[0] if _spec and _spec.submodule_search_locations else None
if _root is not None:
    if not os.path.exists(os.path.join(_root, "fit.py")) and "fractalgeo_rs.fit" not in sys.modules:
        m = types.ModuleType("fractalgeo_rs.fit")
        m.DimensionFit = None
        sys.modules["fractalgeo_rs.fit"] = m
    if not os.path.isdir(os.path.join(_root, "dimension")) and "fractalgeo_rs.dimension" not in sys.modules:
        m = types.ModuleType("fractalgeo_rs.dimension")
        m.box_counting = m.dimension = None
        sys.modules["fractalgeo_rs.dimension"] = m
