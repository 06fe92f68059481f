"""Small periodic test surfaces of the radiometry tests, written from
their definitions."""
from __future__ import annotations

import math

import numpy as np


def rough_tile(n=16, amp=1.0, seed=3):
    """A smooth periodic rough tile: a few random Fourier modes."""
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[0:n, 0:n] * (2 * np.pi / n)
    z = np.zeros((n, n))
    for kx in range(-2, 3):
        for ky in range(-2, 3):
            if kx or ky:
                z += amp * rng.normal() / math.hypot(kx, ky) * np.cos(kx * x + ky * y + rng.uniform(0, 2 * np.pi))
    return z


def v_grooves(n=8, slope_deg=30.0):
    """Periodic V-grooves along the north-south axis, constant slope."""
    x = np.arange(n)
    return np.where(x % 2 == 1, np.tan(np.radians(slope_deg)), 0.0)[None, :].repeat(n, 0)
