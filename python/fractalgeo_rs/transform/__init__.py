"""Fractal transform: maps of local fractal dimension (paper section 4.2,
figure 10).

The debiased Whittle map (``method="whittle"``, module ``_whittle``) is
numpy/scipy: one FFT per window, with the models tabulated per window shape.

Voss's P(m, L) mass dimension (the paper's method, the default), the
increment estimators (variogram, madogram, square increments) and
differential box counting are computed with summed-area tables in Rust, so
that the time per pixel does not grow with the window; the covering-blanket
map grows only each window's border frame (Rust; its cost grows linearly
with the window).

References
----------
Sarkar, N., Chaudhuri, B. B. (1994). An efficient differential box-counting
approach to compute fractal dimension of image. *IEEE Trans. Systems, Man, and
Cybernetics* 24(1), 115-120.
Peleg, S., Naor, J., Hartley, R., Avnir, D. (1984). Multiple resolution
texture analysis and classification. *IEEE Trans. PAMI* 6(4), 518-523.
Voss, R. F. (1986). Characterization and measurement of random fractals.
*Physica Scripta* T13, 27-32.
"""
from __future__ import annotations

from fractalgeo_rs.transform._api import fractal_transform, lacunarity_map
from fractalgeo_rs._zscale import default_z_scale
from fractalgeo_rs.transform._methods import TRANSFORM_METHODS
from fractalgeo_rs.transform._result import FLAGS, TransformFit
from fractalgeo_rs.transform.segment import segment

__all__ = ["default_z_scale", "fractal_transform", "lacunarity_map", "segment", "TRANSFORM_METHODS", "FLAGS",
           "TransformFit"]
