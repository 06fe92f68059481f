"""Low-level pieces of the fractal-resampling analysis shared by
``_resample`` (the lags 1-2 analysis) and ``_resample_model`` (the
inner-scale model): the node grid, its window sums and interpolation, and
the block-mean variogram of fBm."""
from __future__ import annotations

import functools

import numpy as np

#: Range the ``"local"`` Hurst map is clipped to (real DEMs are locally
#: smoother than any fBm at the pixel scale: the lag-1/lag-2 fit gives H > 1).
HURST_RANGE = (0.05, 0.95)
#: Spacing (cells) of the nodes where the window sums are computed; the maps
#: are interpolated bilinearly between them.
STEP = 8


def block_variogram(hurst, lag, n=2):
    """``Var(Zbar(x + lag) - Zbar(x)) / sigma^2`` for fBm block means, each
    block the mean of ``n x n`` points at spacing ``1/n`` (the kernel's area
    model uses ``n = 2``); ``n = 1`` is the point variogram ``lag^(2H)``."""
    off = (np.arange(n) - (n - 1) / 2) / n
    yy, xx = np.meshgrid(off, off, indexing="ij")
    p = np.stack([yy.ravel(), xx.ravel()], 1)

    def gbar(d):
        dd = p[:, None, :] - (p[None, :, :] + np.array(d))
        r2 = (dd**2).sum(-1)
        with np.errstate(divide="ignore"):
            g = np.where(r2 > 0, 0.5 * r2 ** hurst[..., None, None], 0.0)
        return g.mean((-1, -2))

    return 2.0 * (gbar((0.0, lag)) - gbar((0.0, 0.0)))


H_TABLE = np.linspace(0.001, 1.5, 1500)


@functools.lru_cache(maxsize=8)
def ratio_table(n):
    """``(H, gamma_B(2) / gamma_B(1), gamma_B(1))`` on ``H_TABLE``."""
    h = H_TABLE
    g1 = block_variogram(h, 1.0, n)
    return h, block_variogram(h, 2.0, n) / g1, g1


def node_sums(a, half, step):
    """Sums along axis 0 over rows ``[p - half, p + half]`` at the nodes
    ``p = k step`` whose window fits in ``a``; returns ``(sums, k_first)``.

    Each sum is formed in a fixed order from the values in its window only
    (blocks of ``step`` rows aligned on the node grid, then the rows left
    over), so any block of a larger array whose origin is a multiple of
    ``step`` gives bit-identical sums."""
    n = a.shape[0]
    q, rem = divmod(half, step)
    k0 = -(-half // step)
    k1 = (n - 3 - half) // step + 1
    k = np.arange(k0, max(k1, k0))
    nb = n // step
    bs = a[0:nb * step:step].copy()
    for o in range(1, step):
        bs += a[o:nb * step:step]
    if q:
        acc = bs[k - q].copy()
        for d in range(1, 2 * q):
            acc += bs[k - q + d]
    else:
        acc = np.zeros((k.size,) + a.shape[1:])
    p = k * step
    for o in range(-half, -q * step):
        acc += a[p + o]
    for o in range(q * step, half + 1):
        acc += a[p + o]
    return acc, k0


def interp_nodes(v, k0, lo, hi, step):
    """Bilinear (along axis 0) interpolation of node values ``v`` (node
    ``k0 + a`` at row ``(k0 + a) step``) to the rows ``[lo, hi)``, ``lo`` a
    multiple of ``step`` (rows grouped by node interval: no gathers)."""
    a0 = lo // step - k0
    nb = -(-(hi - lo) // step)
    u = (np.arange(step) / step).reshape((1, step) + (1,) * (v.ndim - 1))
    out = v[a0:a0 + nb, None] * (1.0 - u)
    out += v[a0 + 1:a0 + nb + 1, None] * u
    return out.reshape((nb * step,) + v.shape[1:])[:hi - lo]
