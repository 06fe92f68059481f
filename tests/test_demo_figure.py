"""The demo figure: every map has a colorbar with a unit, every number drawn
in the figure's text (titles, labels, legends) is a number the demo prints,
the headlines carry their caveats, the coastline panel shows sea, land and
the coast."""
import re

import numpy as np
import pytest

matplotlib = pytest.importorskip("matplotlib")
matplotlib.use("Agg")

from fractalgeo_rs import demo  # noqa: E402
from fractalgeo_rs.data import kilauea_land_mask  # noqa: E402

NUMBER = re.compile(r"(?<![\w.])-?\d+(?:\.\d+)?(?![\w.])")


@pytest.fixture(scope="module")
def drawn():
    import matplotlib.pyplot as plt

    fits = demo.compute()
    dmap = demo.local_map()
    fig = demo.figure(fits, dmap)
    yield fits, dmap, fig
    plt.close(fig)


def _figure_texts(fig):
    """Every text of the figure but the tick labels (axis scales)."""
    from matplotlib.text import Text

    ticks = set()
    for ax in fig.axes:
        for axis in (ax.xaxis, ax.yaxis):
            for tick in axis.get_major_ticks() + axis.get_minor_ticks():
                ticks |= {id(tick.label1), id(tick.label2)}
            ticks.add(id(axis.offsetText))
    return [t.get_text() for t in fig.findobj(Text) if id(t) not in ticks and t.get_text().strip()]


def test_every_number_drawn_is_printed(drawn):
    fits, dmap, fig = drawn
    printed = "\n".join(demo.report(fits, dmap))
    printed_numbers = set(NUMBER.findall(printed))
    texts = _figure_texts(fig)
    drawn_numbers = [(n, t) for t in texts for n in NUMBER.findall(t)]
    assert len(drawn_numbers) > 30  # the legends and titles carry the results
    missing = [(n, t) for n, t in drawn_numbers if n not in printed_numbers]
    assert not missing, missing
    # each legend gives D and its interval as printed
    for name, fit in fits.items():
        lo, hi = fit.ci95
        assert f"D = {fit.dimension:.3f}  [{lo:.3f}, {hi:.3f}]" in printed
    for key in ("coast", "contour", "alps_dbc", "po_dbc", "vv_dbc"):
        fit = fits[demo.NAMES[key]]
        assert demo.fit_label(fit) in texts, (key, texts)


def test_run_demo_prints_the_report(drawn, tmp_path, capsys):
    fits, dmap, _ = drawn
    demo.run_demo(str(tmp_path))
    out = capsys.readouterr().out.splitlines()
    for line in demo.report(fits, dmap):
        assert line in out


def test_headlines_have_enough_scales_or_a_flag(drawn):
    fits, _, _ = drawn
    for name, fit in fits.items():
        lo, hi = fit.ci95
        if fit.n_used < demo.MIN_SCALES or not hi - lo <= demo.MAX_CI_WIDTH or len(fit.ranges) > 1:
            assert demo.caveats(fit) and "scales" in demo.fit_label(fit), name
    contour = fits[demo.NAMES["contour"]]
    assert contour.n_used >= 10 and contour.ci95[1] - contour.ci95[0] < demo.MAX_CI_WIDTH


def test_every_map_has_a_labelled_colorbar(drawn):
    _, _, fig = drawn
    images = [im for ax in fig.axes for im in ax.images]
    assert len(images) == 4
    for im in images:
        assert im.colorbar is not None, im.axes.get_title()
        label = im.colorbar.ax.get_ylabel() or im.colorbar.ax.get_xlabel()
        assert "(" in label and ")" in label, label  # a unit (or the classes)


def test_labels_name_the_right_resolutions(drawn):
    _, _, fig = drawn
    titles = {ax.get_title() for ax in fig.axes}
    srtm = [t for t in titles if "SRTM" in t]
    assert srtm and "3 arc-second" in srtm[0]
    kil = [t for t in titles if "Kilauea" in t]
    assert kil and "30 m" in kil[0]
    # no "30 m" anywhere near the SRTM panel: the coast classes colour bar is below its own panel
    coast_ax = [ax for ax in fig.axes if "Kilauea" in ax.get_title()][0]
    cbar = coast_ax.images[0].colorbar
    assert cbar.orientation == "horizontal" and "30 m" not in cbar.ax.get_xlabel()


def test_coast_panel_classes():
    land, _ = kilauea_land_mask()
    c = demo.coast_classes(land)
    assert set(np.unique(c)) == {0, 1, 2}
    coast = demo.coastline(land)
    assert (c[coast] == 2).all()  # every box-counted pixel is drawn as coast
    # the coast separates sea from land: no sea pixel touches land directly
    sea, lnd = c == 0, c == 1
    assert not (sea[:, :-1] & lnd[:, 1:]).any() and not (sea[:-1, :] & lnd[1:, :]).any()
