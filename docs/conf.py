"""Sphinx configuration of the fractalgeo_rs documentation.

Build (offline, warnings as errors)::

    sphinx-build -W --keep-going -b html docs docs/_build/html

The API reference and the command-line page are generated from the installed
package (``_apigen.py``), the gallery from ``examples/plot_*.py``
(Sphinx-Gallery, each script run at build time).
"""
from __future__ import annotations

import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import re  # noqa: E402
import warnings  # noqa: E402

import fractalgeo_rs  # noqa: E402
import _apigen  # noqa: E402

_apigen.write_api_page(HERE / "api.rst")
_apigen.write_cli_page(HERE / "cli.rst")


def _demo_figure() -> None:
    """Regenerate ``img/fractalgeo_demo.png`` (the README's and the index's
    figure) from the current code: the figure ``fractalgeo demo`` draws."""
    import matplotlib.pyplot as plt

    from fractalgeo_rs import demo
    from fractalgeo_rs.plotting import save_figure

    fig = demo.figure(demo.compute(), demo.local_map())
    save_figure(fig, HERE / "img" / "fractalgeo_demo.png")
    plt.close(fig)


_demo_figure()


def _warning_line(message, category, filename, lineno, line=None):
    """Warnings in the gallery's output without the build machine's paths."""
    return f"{category.__name__}: {message}\n"


warnings.formatwarning = _warning_line

project = "fractalgeo_rs"
author = "The fractalgeo_rs developers"
copyright = "2026, the fractalgeo_rs developers"
release = fractalgeo_rs.__version__
version = release

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "sphinx-mathjax-offline",  # a local copy of MathJax 3: no CDN, formulas render offline
    "numpydoc",
    "myst_parser",
    "sphinx_gallery.gen_gallery",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
exclude_patterns = ["_build", "**.ipynb_checkpoints"]

# -- API reference ------------------------------------------------------------
autosummary_generate = True
autosummary_imported_members = True
# module pages list what the module's __all__ exports, nothing it imports
autosummary_ignore_module_all = False
templates_path = ["_templates"]
# no default options: with Sphinx 9 a default "members": False also turns off
# the :members: the class template asks for
autodoc_default_options: dict = {}
# module pages link a member to its page: fractalgeo_rs.<name> for the names
# of the top-level __all__, fractalgeo_rs.<module>.<name> for the others
autosummary_context = {"toplevel": [n for n in fractalgeo_rs.__all__ if n != "__version__"]}
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False
# a public callable without a docstring fails the build
numpydoc_validation_checks = {"GL08"}
numpydoc_validation_exclude = {r"\.__init__$", r"\.__repr__$", r"\.__str__$"}

# Every cross-reference must resolve (with -W a broken one fails the build).
# The build is offline (no intersphinx), so references to types of other
# packages cannot resolve; they are listed here and nothing else is.
nitpicky = True
nitpick_ignore_regex = [
    (r"py:.*", r"(numpy|np|xarray|xr|dask|rasterio|affine|pathlib|os|typing|collections|matplotlib)(\..*)?"),
    (r"py:.*", r"(ndarray|ArrayLike|DataArray|Path|PathLike|Affine|Axes|Figure|Sequence|Mapping|Iterable|Callable)"),
]

# -- MyST (the Markdown user guide and validation pages) ----------------------
myst_enable_extensions = ["dollarmath", "amsmath", "colon_fence"]
myst_heading_anchors = 3

# -- Gallery --------------------------------------------------------------------
sphinx_gallery_conf = {
    "examples_dirs": str(HERE.parent / "examples"),
    "gallery_dirs": "auto_examples",
    "filename_pattern": r"/plot_",
    "ignore_pattern": r"(__init__|urban_segmentation|fractal_resampling)\.py",
    "download_all_examples": False,
    "remove_config_comments": True,
    "abort_on_example_error": True,
    "image_scrapers": ("matplotlib",),
    "matplotlib_animations": False,
    "within_subsection_order": "FileNameSortKey",
    "show_memory": False,
    "min_reported_time": 1,
}

# -- Offline build: no intersphinx, no remote assets ---------------------------
html_theme = "pydata_sphinx_theme"
html_title = f"fractalgeo_rs {release}"
html_static_path: list = []
html_theme_options = {
    "navigation_with_keys": False,
    "show_toc_level": 2,
    "header_links_before_dropdown": 7,
}
html_show_sourcelink = False
# Formulas are rendered by the copy of MathJax that sphinx-mathjax-offline
# places in _static: the site loads nothing from the network.


# -- Signatures ------------------------------------------------------------------
# The extension module ``fractalgeo_rs._core`` is private and has no pages; an
# annotation naming one of its types (``LString(core: _core.ModuleString)``)
# is left out of the rendered signature instead of linking nowhere.
_PRIVATE_TYPE = r"['\"]?~?(?:fractalgeo_rs\.)?_core\.\w+['\"]?"
_PRIVATE_ANNOTATION = re.compile(r"\s*:\s*" + _PRIVATE_TYPE)


def _drop_private_annotations(app, what, name, obj, options, signature, return_annotation):
    if signature:
        signature = _PRIVATE_ANNOTATION.sub("", signature)
    if return_annotation and re.fullmatch(_PRIVATE_TYPE, return_annotation):
        return_annotation = None
    return signature, return_annotation


def setup(app):
    app.connect("autodoc-process-signature", _drop_private_annotations)
