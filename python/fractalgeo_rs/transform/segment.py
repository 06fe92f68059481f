"""Segmentation of feature maps into classes (paper section 4.2, figure 10:
built-up areas from the local fractal dimension of SAR scenes).

Thresholds come from scikit-image (Otsu); the k-means is a few lines of
numpy with a seeded k-means++ start, so results are reproducible.
"""
from __future__ import annotations

from typing import Optional, Sequence, Union

import numpy as np

from fractalgeo_rs._validation import as_array, check_choice, check_positive_int

__all__ = ["segment"]


def _stack(features) -> np.ndarray:
    if isinstance(features, np.ndarray) and features.ndim == 2:
        features = [features]
    maps = [np.asarray(as_array(f, "features"), dtype=np.float64) for f in features]
    if not maps:
        raise ValueError("features: need at least one feature map")
    shape = maps[0].shape
    if len(shape) != 2 or any(m.shape != shape for m in maps):
        raise ValueError(f"features: expected 2D maps of one shape, got {[m.shape for m in maps]}")
    return np.stack(maps, axis=-1)


def segment(
    features: Union[np.ndarray, Sequence[np.ndarray]],
    *,
    method: str = "otsu",
    n_classes: int = 2,
    seed: Optional[int] = 0,
    max_iter: int = 100,
) -> np.ndarray:
    """Classify pixels from one or more feature maps.

    Parameters
    ----------
    features : ndarray (rows, cols) or sequence of them
        Feature maps (local dimension, r², lacunarity, intensity, ...). NaN
        pixels get class -1.
    method : {"otsu", "kmeans"}
        ``"otsu"``: Otsu's threshold (``skimage.filters.threshold_otsu``) on a
        single feature; class 1 is above the threshold. ``"kmeans"``: k-means
        on the standardised features (zero mean, unit variance per feature),
        k-means++ start from ``seed``; classes are numbered by increasing mean
        of the first feature.
    n_classes : int, default 2
        Number of k-means classes.

    Returns
    -------
    ndarray of int8, shape (rows, cols)
        Class per pixel, -1 where any feature is NaN.

    References
    ----------
    Otsu, N. (1979). A threshold selection method from gray-level histograms.
    *IEEE Trans. SMC* 9(1), 62-66.

    Examples
    --------
    >>> import numpy as np, fractalgeo_rs as fg
    >>> img = np.array([[0.1, 0.2, 2.0, 2.1], [0.0, 0.3, 1.9, 2.2]])
    >>> fg.segment(img).tolist()  # Otsu: two classes
    [[0, 0, 1, 1], [0, 1, 1, 1]]
    >>> fg.segment([img, -img], method='kmeans', n_classes=2, seed=0).tolist()
    [[0, 0, 1, 1], [0, 0, 1, 1]]
    """
    check_choice(method, "method", ("otsu", "kmeans"))
    X = _stack(features)
    ok = np.all(np.isfinite(X), axis=-1)
    if not ok.any():
        raise ValueError("features: no pixel with finite values in every feature")
    out = np.full(X.shape[:2], -1, dtype=np.int8)
    if method == "otsu":
        if X.shape[-1] != 1:
            raise ValueError("method: 'otsu' thresholds one feature; use 'kmeans' for several")
        from skimage.filters import threshold_otsu

        v = X[..., 0][ok]
        t = threshold_otsu(v)
        out[ok] = (v > t).astype(np.int8)
        return out
    k = check_positive_int(n_classes, "n_classes")
    if k < 2 or k > 127:
        raise ValueError(f"n_classes: expected an int in [2, 127], got {k}")
    v = X[ok]
    sd = v.std(axis=0)
    v = (v - v.mean(axis=0)) / np.where(sd > 0, sd, 1.0)
    if seed is not None and (isinstance(seed, bool) or not isinstance(seed, (int, np.integer))):
        raise TypeError(f"seed: expected a non-negative int or None, got {seed!r}")
    if seed is not None and seed < 0:
        raise ValueError(f"seed: expected a non-negative int or None, got {seed}")
    rng = np.random.default_rng(seed)
    centres = [v[rng.integers(len(v))]]
    for _ in range(1, k):
        d2 = np.min([np.sum((v - c) ** 2, axis=1) for c in centres], axis=0)
        centres.append(v[rng.choice(len(v), p=d2 / d2.sum())] if d2.sum() > 0 else v[rng.integers(len(v))])
    c = np.array(centres)
    lab = np.zeros(len(v), dtype=np.int64)
    for _ in range(check_positive_int(max_iter, "max_iter")):
        d = ((v[:, None, :] - c[None, :, :]) ** 2).sum(axis=2)
        new = d.argmin(axis=1)
        if np.array_equal(new, lab) and _ > 0:
            break
        lab = new
        for j in range(k):
            if np.any(lab == j):
                c[j] = v[lab == j].mean(axis=0)
    order = np.argsort(c[:, 0])
    rank = np.empty(k, dtype=np.int64)
    rank[order] = np.arange(k)
    out[ok] = rank[lab].astype(np.int8)
    return out
