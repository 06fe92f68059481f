"""Load three pages of the built site in headless Chromium, take screenshots
and check the rendered DOM: the page's title, its images (present on disk
and referenced by the page) and no error text.

Usage: ``python docs/check_browser.py docs/_build/html [--out DIR]``.
Screenshots go to ``--out`` (default: a temporary directory outside the
repository); their paths and sizes are printed. Without a Chromium binary
the check prints one line and exits 0 (CI installs Debian's ``chromium``
when it can). Remote requests are refused, so the check runs offline.
"""
from __future__ import annotations

import argparse
import html
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

# (page, text the <title> must contain, images required, formulas rendered)
PAGES = [
    ("index.html", "fractalgeo_rs", True, False),
    ("generated/fractalgeo_rs.box_counting.html", "box_counting", False, True),
    ("auto_examples/plot_fig01_minkowski_sausage.html", "Minkowski sausage", True, False),
]
ERROR_MARKERS = [
    'class="system-message"',
    'class="problematic"',
    "Traceback (most recent call last)",
    "Unknown directive type",
    "Undefined substitution",
    "Page not found",
]
FLAGS = [
    "--headless=new",
    "--no-sandbox",
    "--disable-gpu",
    "--hide-scrollbars",
    "--no-first-run",
    "--disable-extensions",
    "--host-resolver-rules=MAP * ~NOTFOUND",  # offline: every remote host fails at once
    "--window-size=1280,1600",
]


def find_chromium():
    for name in ("chromium", "chromium-browser", "google-chrome"):
        path = shutil.which(name)
        if path:
            return path
    return None


def run(browser, args, timeout=120):
    return subprocess.run([browser, *FLAGS, *args], capture_output=True, text=True, timeout=timeout)


def check_page(browser, site: Path, page: str, title: str, need_images: bool, need_math: bool, out: Path):
    path = site / page
    problems = []
    if not path.exists():
        return [f"{page}: not built"], None
    url = path.resolve().as_uri()
    dom = run(browser, ["--virtual-time-budget=5000", "--dump-dom", url]).stdout
    m = re.search(r"<title>(.*?)</title>", dom, re.S)
    if not m or title not in html.unescape(m.group(1)):
        problems.append(f"{page}: title {m.group(1).strip() if m else None!r} lacks {title!r}")
    if "<h1" not in dom:
        problems.append(f"{page}: no <h1> heading rendered")
    for marker in ERROR_MARKERS:
        if marker in dom:
            problems.append(f"{page}: error text {marker!r} in the page")
    if need_math and "<mjx-container" not in dom:
        problems.append(f"{page}: formulas not rendered by MathJax")
    imgs = [html.unescape(s) for s in re.findall(r'<img[^>]*\ssrc="([^"]+)"', dom)]
    local = [s for s in imgs if not s.startswith(("data:", "http:", "https:"))]
    if need_images and not local:
        problems.append(f"{page}: no images")
    for src in local:
        target = (path.parent / src.split("#")[0].split("?")[0]).resolve()
        if not target.exists() or target.stat().st_size == 0:
            problems.append(f"{page}: image {src} missing on disk")
    shot = out / (page.replace("/", "_").replace(".html", ".png"))
    run(browser, ["--virtual-time-budget=5000", f"--screenshot={shot}", url])
    if not shot.exists() or shot.stat().st_size < 10_000:
        problems.append(f"{page}: screenshot missing or blank ({shot})")
    else:
        try:
            from PIL import Image

            with Image.open(shot) as im:
                colours = im.convert("RGB").getcolors(maxcolors=1 << 16)
            if colours is not None and len(colours) < 8:
                problems.append(f"{page}: screenshot has {len(colours)} colours (blank page?)")
        except ImportError:
            pass
    return problems, shot


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("site", nargs="?", default=str(Path(__file__).resolve().parent / "_build" / "html"))
    ap.add_argument("--out", default=None, help="folder for the screenshots (default: a new temporary folder)")
    args = ap.parse_args(argv)
    browser = find_chromium()
    if browser is None:
        print("chromium not found: browser check of the documentation skipped")
        return 0
    out = Path(args.out) if args.out else Path(tempfile.mkdtemp(prefix="fractalgeo-docs-shots-"))
    out.mkdir(parents=True, exist_ok=True)
    site = Path(args.site)
    all_problems = []
    for page, title, need_images, need_math in PAGES:
        problems, shot = check_page(browser, site, page, title, need_images, need_math, out)
        all_problems += problems
        if shot is not None and shot.exists():
            print(f"screenshot {shot} {shot.stat().st_size} bytes ({page})")
    for p in all_problems:
        print("FAIL", p)
    print(f"browser check of {len(PAGES)} pages: {'OK' if not all_problems else f'{len(all_problems)} problems'}")
    return 1 if all_problems else 0


if __name__ == "__main__":
    sys.exit(main())
