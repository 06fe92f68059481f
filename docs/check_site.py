"""Check a built documentation site: every public name has its API page
with an Examples section (subpackages excepted: their members are
checked), and every gallery script has its page and figure.

Usage: ``python docs/check_site.py docs/_build/html`` (exit code 1 and a
list of what is missing on failure). The list of names comes from the
installed package (``docs/_apigen.py``), so names added to ``__all__`` are
checked without editing this script.
"""
from __future__ import annotations

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import _apigen  # noqa: E402

import inspect  # noqa: E402

import fractalgeo_rs  # noqa: E402


def problems(site: Path) -> list:
    out = []
    for name in _apigen.public_names():
        page = site / "generated" / f"fractalgeo_rs.{name}.html"
        if not page.exists():
            out.append(f"{name}: no API page ({page.name})")
            continue
        text = page.read_text(encoding="utf-8")
        # subpackages (data, io, tin, ...) are namespaces: their members
        # have pages of their own, each checked for its examples
        is_module = inspect.ismodule(getattr(fractalgeo_rs, name, None))
        if not is_module and ">Examples<" not in text:
            out.append(f"{name}: the API page has no Examples section")
    api = (site / "api.html").read_text(encoding="utf-8") if (site / "api.html").exists() else ""
    for name in _apigen.public_names():
        if f"fractalgeo_rs.{name}.html" not in api:
            out.append(f"{name}: not linked from api.html")
    for script in sorted((HERE.parent / "examples").glob("plot_*.py")):
        page = site / "auto_examples" / f"{script.stem}.html"
        if not page.exists():
            out.append(f"gallery: no page for {script.name}")
        elif f"sphx_glr_{script.stem}_001.png" not in page.read_text(encoding="utf-8"):
            out.append(f"gallery: {script.name} produced no figure")
        nb = list((site / "_downloads").rglob(f"{script.stem}.ipynb"))
        if not nb:
            out.append(f"gallery: no notebook for {script.name}")
    return out


def main(argv=None) -> int:
    args = sys.argv[1:] if argv is None else argv
    site = Path(args[0] if args else HERE / "_build" / "html")
    found = problems(site)
    for p in found:
        print("MISSING", p)
    n = len(_apigen.public_names())
    print(f"checked {n} API entries and {len(list((HERE.parent / 'examples').glob('plot_*.py')))} gallery pages: "
          f"{'OK' if not found else f'{len(found)} problems'}")
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main())
