"""The demo figure: every map has a colorbar with a unit, the fit legends give
the 95 % interval the demo prints, the coastline panel shows sea, land and
the coast."""
import numpy as np
import pytest

matplotlib = pytest.importorskip("matplotlib")
matplotlib.use("Agg")

from fractalgeo_rs import demo  # noqa: E402
from fractalgeo_rs.data import kilauea_land_mask  # noqa: E402


@pytest.fixture(scope="module")
def drawn():
    import matplotlib.pyplot as plt

    fits = demo.compute()
    vv, _ = demo.sentinel1_vv_db()
    dmap = demo.fractal_transform(vv[:200, :200], 17, method="mass", z_scale=1.0)
    fig = demo.figure(fits, dmap)
    yield fits, fig
    plt.close(fig)


def test_every_map_has_a_labelled_colorbar(drawn):
    _, fig = drawn
    images = [im for ax in fig.axes for im in ax.images]
    assert len(images) == 4
    for im in images:
        assert im.colorbar is not None, im.axes.get_title()
        label = im.colorbar.ax.get_ylabel()
        assert "(" in label and ")" in label, label  # a unit (or the classes' pixel size)


def test_legends_give_the_printed_95_percent_interval(drawn):
    fits, fig = drawn
    texts = [t.get_text() for ax in fig.axes if ax.get_legend() for t in ax.get_legend().get_texts()]
    for name in list(fits)[:4] + [list(fits)[5]]:
        fit = fits[name]
        lo, hi = fit.ci95
        printed = f"[{lo:.3f}, {hi:.3f}]"  # as run_demo prints it
        assert f"D = {fit.dimension:.3f}, 95 % CI {printed}" in texts, (name, texts)
    assert not [t for t in texts if "±" in t]


def test_coast_panel_classes():
    land, _ = kilauea_land_mask()
    c = demo.coast_classes(land)
    assert set(np.unique(c)) == {0, 1, 2}
    coast = demo.coastline(land)
    assert (c[coast] == 2).all()  # every box-counted pixel is drawn as coast
    # the coast separates sea from land: no sea pixel touches land directly
    sea, lnd = c == 0, c == 1
    assert not (sea[:, :-1] & lnd[:, 1:]).any() and not (sea[:-1, :] & lnd[1:, :]).any()
