"""Start-up cost of ``import fractalgeo_rs`` and of the ``fractalgeo`` CLI.

Prints, each the best of ``--repeat`` fresh interpreters:

* the cumulative import time of ``fractalgeo_rs`` reported by
  ``python -X importtime -c "import fractalgeo_rs"`` (target < 0.2 s), next to
  numpy's (the baseline every user pays);
* ``fractalgeo --help`` wall time, and a small job: DBC of the bundled SRTM
  Alps crop through the CLI (a fresh process) against the same call in an
  already-running Python (the API), and the overhead of the CLI (target
  < 0.3 s).

Every child process runs with its bytecode cached in a temporary
``PYTHONPYCACHEPREFIX`` (warmed first), as an installed wheel has it, even
when the environment sets ``PYTHONDONTWRITEBYTECODE``.

Run: ``python benches/bench_startup.py [--repeat 5]``.
"""
from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
import tempfile
import time


ENV = dict(os.environ)
ENV.pop("PYTHONDONTWRITEBYTECODE", None)
_CACHE = tempfile.TemporaryDirectory()
ENV["PYTHONPYCACHEPREFIX"] = _CACHE.name


def import_time(module: str) -> float:
    """Cumulative import time of ``module`` in seconds (``-X importtime``)."""
    out = subprocess.run([sys.executable, "-X", "importtime", "-c", f"import {module}"],
                         capture_output=True, text=True, check=True, env=ENV).stderr
    for line in reversed(out.splitlines()):
        m = re.match(r"import time:\s+(\d+)\s+\|\s+(\d+)\s+\|\s*(\S+)\s*$", line)
        if m and m.group(3) == module:
            return int(m.group(2)) * 1e-6
    raise RuntimeError(f"no import time of {module} in: {out[-500:]}")


def wall(cmd) -> float:
    t0 = time.perf_counter()
    subprocess.run(cmd, capture_output=True, check=True, env=ENV)
    return time.perf_counter() - t0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args()
    r = args.repeat
    # warm the bytecode cache of everything the runs below import
    subprocess.run([sys.executable, "-c", "import fractalgeo_rs.dimension, fractalgeo_rs.io, fractalgeo_rs.cli"],
                   check=True, env=ENV)
    t_pkg = min(import_time("fractalgeo_rs") for _ in range(r))
    t_np = min(import_time("numpy") for _ in range(r))
    print(f"import fractalgeo_rs: {t_pkg:.3f} s (numpy alone {t_np:.3f} s; target < 0.2 s)")

    cli = [sys.executable, "-m", "fractalgeo_rs.cli"]
    t_help = min(wall(cli + ["--help"]) for _ in range(r))
    t_py = min(wall([sys.executable, "-c", "pass"]) for _ in range(r))
    print(f"fractalgeo --help: {t_help:.3f} s wall (a bare python: {t_py:.3f} s)")

    import numpy as np

    import fractalgeo_rs as fg

    alps, _ = fg.data.srtm_alps()
    with tempfile.TemporaryDirectory() as d:
        path = os.path.join(d, "alps.npy")
        np.save(path, alps)
        job = cli + ["dimension", path, "--method", "dbc"]
        wall(job)  # warm
        t_cli = min(wall(job) for _ in range(r))
        fg.differential_box_counting(alps)  # warm
        t_api = min(_timed(lambda: fg.differential_box_counting(fg.read_raster(path)[0])) for _ in range(r))
    print(f"DBC of the SRTM Alps crop {alps.shape}: CLI {t_cli:.3f} s (fresh process), API {t_api:.3f} s; "
          f"CLI overhead {t_cli - t_api:.3f} s beyond the API, {t_cli - t_py - t_api:.3f} s beyond a bare "
          f"python start (target < 0.3 s)")


def _timed(fn) -> float:
    t0 = time.perf_counter()
    fn()
    return time.perf_counter() - t0


if __name__ == "__main__":
    main()
