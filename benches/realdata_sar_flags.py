"""Every map's defaults on the bundled Sentinel-1 VV scene in dB (512²,
window 33): median D and the fractions of the flag layer (below 2, above
3, pinned at an end of the H grid), for ``docs/transform.md``; then the
first-difference maps above the resampling scale and GLS with more
dilations.

Run: ``python benches/realdata_sar_flags.py`` (about a minute on 2 cores);
prints Markdown.
"""
from __future__ import annotations

import warnings

import numpy as np

import fractalgeo_rs as fg
from fractalgeo_rs.transform import FLAGS


def row(vv, method, **kw):
    out = fg.fractal_transform(vv, 33, method=method, return_fit=True, **kw)
    d, f = np.asarray(out[0]), np.asarray(out.flags)
    ok = np.isfinite(d)

    def frac(bit):
        return f"{100 * np.mean(f[ok] & bit > 0):.1f} %"

    return (f"| `{method}` {kw or ''} | {np.nanmedian(d):.3f} | {frac(FLAGS['below_2'])} | "
            f"{frac(FLAGS['above_3'])} | {frac(FLAGS['pinned'])} | "
            f"{'-' if out.params['z_scale'] is None else format(out.params['z_scale'], '.3f')} |")


def main() -> None:
    warnings.simplefilter("ignore")
    vv, _ = fg.data.sentinel1_vv_db()
    print("| method | median D | below 2 | above 3 | pinned | z_scale (dB) |")
    print("|---|---|---|---|---|---|")
    for m in ("gls", "variogram", "madogram", "square", "mass", "dbc", "blanket"):
        print(row(vv, m))
    print(row(vv, "whittle", step=4))
    print(row(vv, "gls", dilations=4))
    print(row(vv, "variogram", lags=(4, 8)))
    print(row(vv, "madogram", lags=(4, 8)))


if __name__ == "__main__":
    main()
