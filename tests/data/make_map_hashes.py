"""Generate ``map_hashes.json``: sha256 of the float64 bytes of every map
method's output on fixed small inputs.

This file was run ONCE, on the code of commit ec36600 (before the map kernels
were moved onto the shared moving-window driver), to record what the maps
computed then. ``tests/test_map_hashes.py`` recomputes the same maps and
compares the hashes, which proves a refactor of the kernels bit-identical.
Do NOT re-run it to "fix" a failing test: a mismatch means the output
changed. If a change of output is intended, say so in the commit message and
in the test (as done for the GLS map, see ``tests/test_map_hashes.py``).

Run from the repository root: ``python tests/data/make_map_hashes.py``.
"""
import hashlib
import json
import pathlib
import sys

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1]))
from test_map_hashes import CASES, compute  # noqa: E402


def digest(a) -> str:
    return hashlib.sha256(np.ascontiguousarray(a, dtype=np.float64).tobytes()).hexdigest()


if __name__ == "__main__":
    out = {name: digest(compute(name)) for name in CASES}
    path = pathlib.Path(__file__).with_name("map_hashes.json")
    path.write_text(json.dumps({"generated_on": "ec36600", "hashes": out}, indent=1, sort_keys=True) + "\n")
    print(f"{len(out)} hashes written to {path}")
