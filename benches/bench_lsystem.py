"""Benchmark: L-system derivation, 3D turtle and turtle-to-mesh in Rust
(fractalgeo_rs.lsystem) against the fastest pure-Python versions written
here, in the same run, printing ratios.

Run:  python benches/bench_lsystem.py [--n 9] [--repeat 3]

Python references:
* derivation: ``str.translate`` with a table char -> successor, which is
  parallel DOL rewriting done in C inside CPython (the fastest pure-Python
  rewriting there is);
* turtle: one Python loop with the frame held in local floats;
* mesh: the Python turtle, then tubes built with numpy, vectorised over
  segments (one pair of rings per segment, no shared rings: less work than
  the Rust generalised cylinders).
The machine may be shared with other processes; timings are the best of
``--repeat`` runs.
"""
from __future__ import annotations

import argparse
import math
import os
import sys

import numpy as np

from fractalgeo_rs.lsystem import LSystem, plant_mesh, turtle_3d  # noqa: E402
from _timing import best_with_result as best

AXIOM, RULES, ANGLE = "F", {"F": "F[&+F]F[^-F]/F"}, 22.5


def py_derive(axiom: str, rules: dict, n: int) -> str:
    table = str.maketrans(rules)
    s = axiom
    for _ in range(n):
        s = s.translate(table)
    return s


STOCH = [("F[&+F]F[^-F]/F", 0.4), ("F[&+F]/F", 0.3), ("F[^-F]F", 0.3)]


def py_derive_stochastic(axiom: str, alts, n: int, seed: int) -> str:
    """Stochastic rewriting of F: split at F, draw all choices at once with
    numpy, join (the fastest pure-Python form found)."""
    rng = np.random.default_rng(seed)
    succ = [a for a, _ in alts]
    p = np.array([w for _, w in alts]) / sum(w for _, w in alts)
    s = axiom
    for _ in range(n):
        parts = s.split("F")
        picks = rng.choice(len(succ), size=len(parts) - 1, p=p)
        out = [""] * (2 * len(parts) - 1)
        out[0::2] = parts
        out[1::2] = [succ[k] for k in picks]
        s = "".join(out)
    return s


def py_turtle(s: str, angle: float, step: float = 1.0):
    """Pure-Python 3D turtle (same conventions as fractalgeo_rs)."""
    ca, sa = math.cos(math.radians(angle)), math.sin(math.radians(angle))
    px = py = pz = 0.0
    hx, hy, hz = 0.0, 0.0, 1.0
    lx, ly, lz = -1.0, 0.0, 0.0
    ux, uy, uz = hy * lz - hz * ly, hz * lx - hx * lz, hx * ly - hy * lx
    w = 1.0
    stack = []
    starts, ends, widths = [], [], []
    push_s, push_e, push_w = starts.append, ends.append, widths.append
    for c in s:
        if c == "F":
            nx, ny, nz = px + hx * step, py + hy * step, pz + hz * step
            push_s((px, py, pz))
            push_e((nx, ny, nz))
            push_w(w)
            px, py, pz = nx, ny, nz
        elif c == "[":
            stack.append((px, py, pz, hx, hy, hz, lx, ly, lz, ux, uy, uz, w))
        elif c == "]":
            px, py, pz, hx, hy, hz, lx, ly, lz, ux, uy, uz, w = stack.pop()
        elif c == "+" or c == "-":
            s_ = sa if c == "+" else -sa
            hx, hy, hz, lx, ly, lz = (hx * ca + lx * s_, hy * ca + ly * s_, hz * ca + lz * s_,
                                      lx * ca - hx * s_, ly * ca - hy * s_, lz * ca - hz * s_)
        elif c == "&" or c == "^":
            s_ = -sa if c == "&" else sa
            hx, hy, hz, ux, uy, uz = (hx * ca + ux * s_, hy * ca + uy * s_, hz * ca + uz * s_,
                                      ux * ca - hx * s_, uy * ca - hy * s_, uz * ca - hz * s_)
        elif c == "\\" or c == "/":
            s_ = sa if c == "\\" else -sa
            lx, ly, lz, ux, uy, uz = (lx * ca + ux * s_, ly * ca + uy * s_, lz * ca + uz * s_,
                                      ux * ca - lx * s_, uy * ca - ly * s_, uz * ca - lz * s_)
        elif c == "!":
            w *= 0.7
    return np.array(starts), np.array(ends), np.array(widths)


def py_mesh(s: str, angle: float, sides: int = 6):
    st, en, w = py_turtle(s, angle)
    d = en - st
    axis = d / np.linalg.norm(d, axis=1, keepdims=True)
    ref = np.where(np.abs(axis[:, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
    ref = ref - axis * np.sum(ref * axis, axis=1, keepdims=True)
    ref /= np.linalg.norm(ref, axis=1, keepdims=True)
    side = np.cross(axis, ref)
    t = np.linspace(0, 2 * np.pi, sides + 1)
    radial = ref[:, None, :] * np.cos(t)[None, :, None] + side[:, None, :] * np.sin(t)[None, :, None]
    r = 0.5 * w[:, None, None]
    verts = np.concatenate([st[:, None, :] + r * radial, en[:, None, :] + r * radial], axis=1)
    normals = np.concatenate([radial, radial], axis=1)
    k = sides + 1
    j = np.arange(sides)
    quad = np.stack([j, j + 1, k + j + 1, j, k + j + 1, k + j], axis=1).reshape(-1, 3)
    base = (np.arange(len(st)) * 2 * k)[:, None, None]
    faces = (quad[None] + base).reshape(-1, 3)
    return verts.reshape(-1, 3).astype(np.float32), normals.reshape(-1, 3).astype(np.float32), faces.astype(np.uint32)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--n", type=int, default=9, help="derivation steps (9: 6.3 million modules)")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--threads", type=int, default=None)
    a = ap.parse_args()
    system = LSystem(AXIOM, RULES)
    print(f"plant: {AXIOM} with {RULES}, n = {a.n}, angle = {ANGLE}; best of {a.repeat}; cpus = {os.cpu_count()}")

    t_py, s_py = best(lambda: py_derive(AXIOM, RULES, a.n), a.repeat)
    t_rs, s_rs = best(lambda: system.derive(a.n, n_threads=a.threads), a.repeat)
    assert str(s_rs) == s_py
    print(f"derivation    {len(s_rs):>11,d} modules  python {t_py:8.3f} s  rust {t_rs:8.3f} s  "
          f"ratio {t_py / t_rs:6.1f}x  ({len(s_rs) / t_rs / 1e6:.1f} M modules/s)")

    stoch = LSystem(AXIOM, {"F": STOCH}, seed=1)
    t_py, s_py = best(lambda: py_derive_stochastic(AXIOM, STOCH, a.n + 3, 1), a.repeat)
    t_rs, s_rs2 = best(lambda: stoch.derive(a.n + 3, n_threads=a.threads), a.repeat)
    r_py, r_rs = len(s_py) / t_py, len(s_rs2) / t_rs
    print(f"stochastic    {len(s_rs2):>11,d} modules  python {t_py:8.3f} s  rust {t_rs:8.3f} s  "
          f"ratio {r_rs / r_py:6.1f}x  ({r_rs / 1e6:.1f} M modules/s; python {len(s_py):,d} modules)")

    n_tr = min(a.n, 8)
    s_tr = py_derive(AXIOM, RULES, n_tr)
    l_tr = system.derive(n_tr)
    t_py, (st, en, _) = best(lambda: py_turtle(s_tr, ANGLE), a.repeat)
    t_rs, seg = best(lambda: turtle_3d(s_rs, angle=ANGLE), a.repeat)
    seg_small = turtle_3d(l_tr, angle=ANGLE)
    assert np.allclose(seg_small.ends, en, atol=1e-9)
    rate_py = len(st) / t_py
    rate_rs = len(seg) / t_rs
    print(f"turtle 3D     {len(seg):>11,d} segments python {len(st) / rate_py:8.3f} s* rust {t_rs:8.3f} s  "
          f"ratio {rate_rs / rate_py:6.1f}x  ({rate_rs / 1e6:.1f} M segments/s; python {rate_py / 1e6:.2f} M/s)")

    t_py, (v, _, f) = best(lambda: py_mesh(s_tr, ANGLE), a.repeat)
    t_rs, m = best(lambda: plant_mesh(s_rs, angle=ANGLE, sides=6), a.repeat)
    rate_py = len(st) / t_py
    rate_rs = len(seg) / t_rs
    print(f"turtle->mesh  {len(m.faces):>11,d} triangles python {len(st) / rate_py:7.3f} s* rust {t_rs:8.3f} s  "
          f"ratio {rate_rs / rate_py:6.1f}x  ({rate_rs / 1e6:.1f} M segments/s; python {rate_py / 1e6:.2f} M/s)")
    if n_tr != a.n:
        print(f"* python turtle and mesh timed at n = {n_tr} ({len(st):,d} segments); ratios compare segments per second")
    return 0


if __name__ == "__main__":
    sys.exit(main())
