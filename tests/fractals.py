"""Exact fractal sets and an independent plain-numpy box counter for the tests.

Everything here is written from the definitions, independently of the Rust
kernels, so that tests compare two implementations.
"""
from __future__ import annotations

import numpy as np

LOG = np.log


def sierpinski_triangle(L: int) -> np.ndarray:
    """Pascal's triangle mod 2 on a 2^L grid (D = ln 3 / ln 2)."""
    n = 2**L
    i, j = np.indices((n, n))
    return (i & j) == 0


def _digit_is_one(idx: np.ndarray, L: int):
    return [((idx // 3**k) % 3) == 1 for k in range(L)]


def sierpinski_carpet(L: int) -> np.ndarray:
    """Sierpinski carpet on a 3^L grid (D = ln 8 / ln 3)."""
    n = 3**L
    i, j = np.indices((n, n))
    m = np.ones((n, n), bool)
    for a, b in zip(_digit_is_one(i, L), _digit_is_one(j, L)):
        m &= ~(a & b)
    return m


def cantor_dust(L: int) -> np.ndarray:
    """Product of two middle-thirds Cantor sets on a 3^L grid (D = 2 ln 2 / ln 3)."""
    n = 3**L
    i, j = np.indices((n, n))
    m = np.ones((n, n), bool)
    for a, b in zip(_digit_is_one(i, L), _digit_is_one(j, L)):
        m &= ~a & ~b
    return m


def cantor_set(L: int) -> np.ndarray:
    """Middle-thirds Cantor set on 3^L samples (D = ln 2 / ln 3)."""
    i = np.arange(3**L)
    m = np.ones(3**L, bool)
    for a in _digit_is_one(i, L):
        m &= ~a
    return m


def menger_sponge(L: int) -> np.ndarray:
    """Menger sponge on a 3^L voxel grid (D = ln 20 / ln 3)."""
    n = 3**L
    i, j, k = np.indices((n, n, n))
    m = np.ones((n, n, n), bool)
    for a, b, c in zip(_digit_is_one(i, L), _digit_is_one(j, L), _digit_is_one(k, L)):
        m &= ~((a & b) | (a & c) | (b & c))
    return m


def _turtle_polyline(axiom: str, rules: dict, n: int, angle_deg: float) -> np.ndarray:
    s = axiom
    for _ in range(n):
        s = "".join(rules.get(c, c) for c in s)
    pos = np.zeros(2)
    heading = 0.0
    pts = [pos.copy()]
    for c in s:
        if c == "F":
            pos = pos + np.array([np.cos(heading), np.sin(heading)])
            pts.append(pos.copy())
        elif c == "+":
            heading += np.radians(angle_deg)
        elif c == "-":
            heading -= np.radians(angle_deg)
    return np.array(pts)


def rasterise_polyline(pts: np.ndarray, scale: float, samples: int = 8) -> np.ndarray:
    """Pixels touched by a polyline scaled by ``scale`` (dense sampling, rounding)."""
    P = pts * scale
    t = np.linspace(0, 1, samples, endpoint=False)[None, :, None]
    seg = (P[:-1, None, :] + (P[1:] - P[:-1])[:, None, :] * t).reshape(-1, 2)
    seg = np.vstack([seg, P[-1:]])
    ij = np.round(seg).astype(np.int64)
    ij -= ij.min(axis=0)
    img = np.zeros((ij[:, 1].max() + 1, ij[:, 0].max() + 1), bool)
    img[ij[:, 1], ij[:, 0]] = True
    return img


def quadratic_koch_curve(L: int) -> np.ndarray:
    """Quadratic Koch curve (type 1, F -> F+F-F-F+F, 90 degrees; D = ln 5 / ln 3),
    unit segments of 1 pixel: its segments lie on the pixel lattice."""
    return rasterise_polyline(_turtle_polyline("F", {"F": "F+F-F-F+F"}, L, 90.0), 1.0)


def triadic_koch_curve(L: int, width: int) -> np.ndarray:
    """Triadic Koch curve (D = ln 4 / ln 3) rasterised to ``width`` pixels."""
    pts = _turtle_polyline("F", {"F": "F+F--F+F"}, L, 60.0)
    return rasterise_polyline(pts, (width - 1) / 3**L)


def numpy_box_counts(mask: np.ndarray, sizes, shift=None, anchor: str = "bbox") -> list:
    """Plain-numpy lattice box counts: boxes holding a foreground sample."""
    coords = np.argwhere(mask)
    lo = coords.min(axis=0) if anchor == "bbox" else np.zeros(mask.ndim, int)
    out = []
    for s in sizes:
        g = np.zeros(mask.ndim, int) if shift is None else np.asarray(shift) % s
        keys = (coords - lo + g) // s
        out.append(len(np.unique(keys, axis=0)))
    return out


def davies_harte_fgn(n: int, hurst: float, rng: np.random.Generator) -> np.ndarray:
    """Exact fractional Gaussian noise by circulant embedding (Davies and Harte 1987)."""
    k = np.arange(n + 1)
    gamma = 0.5 * (np.abs(k + 1) ** (2 * hurst) - 2 * np.abs(k) ** (2 * hurst) + np.abs(k - 1) ** (2 * hurst))
    row = np.concatenate([gamma, gamma[-2:0:-1]])
    lam = np.fft.fft(row).real
    assert lam.min() > -1e-9
    lam = np.clip(lam, 0, None)
    m = len(row)
    w = rng.standard_normal(m) + 1j * rng.standard_normal(m)
    z = np.fft.fft(np.sqrt(lam / m) * w)
    return z.real[:n]


def fbm_profile(n: int, hurst: float, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return np.concatenate([[0.0], np.cumsum(davies_harte_fgn(n - 1, hurst, rng))])


def spectral_surface(n: int, hurst: float, seed: int) -> np.ndarray:
    """Periodic fBm-like surface by 1/f^beta filtering (beta = 2H + 2, 2D)."""
    rng = np.random.default_rng(seed)
    kx = np.fft.fftfreq(n)[:, None]
    ky = np.fft.fftfreq(n)[None, :]
    k = np.hypot(kx, ky)
    k[0, 0] = 1.0
    amp = k ** (-(hurst + 1.0))
    amp[0, 0] = 0.0
    noise = np.fft.fft2(rng.standard_normal((n, n)))
    return np.fft.ifft2(noise * amp).real
