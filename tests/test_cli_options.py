"""The options shared by the ``fractalgeo`` subcommands have one spelling
and one help text everywhere (``_cli_common``), and every subcommand shows
its defaults."""
import argparse

import pytest

from fractalgeo_rs import _cli_common as cc
from fractalgeo_rs.cli import build_parser

#: option -> the one help text it has on every subcommand that offers it
SHARED = {
    "--band": cc.BAND_HELP,
    "--n-threads": cc.N_THREADS_HELP,
    "--cell-size": cc.CELL_SIZE_HELP,
    "--progress": cc.PROGRESS_HELP,
}
#: ``synth --cell-size`` is the spacing of the grid it writes, not a
#: replacement for an input's: its own text.
OWN = {("synth", "--cell-size")}
#: subcommands whose first positional is a raster read with read_raster
RASTER_INPUT = {"hillshade", "tin", "transform", "dimension"}


def _subcommands():
    parser = build_parser()
    (sub,) = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
    return sub.choices


def test_shared_options_have_one_help_text():
    seen = {k: [] for k in SHARED}
    for name, p in _subcommands().items():
        for action in p._actions:
            for opt in action.option_strings:
                if opt in SHARED and (name, opt) not in OWN:
                    assert action.help == SHARED[opt], (name, opt, action.help)
                    seen[opt].append(name)
        if name in RASTER_INPUT:
            first = next(a for a in p._actions if not a.option_strings)
            assert first.help == cc.INPUT_HELP, (name, first.help)
    # the options are offered where they belong
    assert {"hillshade", "transform", "dimension", "resample", "tin"} <= set(seen["--band"])
    assert {"hillshade", "tin"} <= set(seen["--cell-size"])
    assert len(seen["--n-threads"]) >= 5
    assert {"synth", "transform"} <= set(seen["--progress"])


@pytest.mark.parametrize("name", sorted(_subcommands()))
def test_every_option_has_help(name):
    p = _subcommands()[name]
    bare = [a.option_strings for a in p._actions if a.option_strings and a.help is None]
    assert not bare, (name, bare)


@pytest.mark.parametrize("name", sorted(_subcommands()))
def test_every_subcommand_help_shows_defaults(name, capsys):
    p = _subcommands()[name]
    with pytest.raises(SystemExit) as e:
        p.parse_args(["--help"])
    assert e.value.code == 0
    out = capsys.readouterr().out
    for opt, text in SHARED.items():
        if opt in out and (name, opt) not in OWN:
            # the help text (folded by argparse) with its default shown
            flat = " ".join(out.split())
            assert " ".join(text.split()) + " (default: None)" in flat, (name, opt)


def test_transform_map_tags_take_the_input_cell_size():
    from fractalgeo_rs.transform._cli import map_tags

    params = dict(method="dbc", window_size=9, step=1, z_scale=30.0)
    tags = map_tags(params, "m", 30.0)
    assert tags["INPUT_CELL_SIZE"] == "30" and tags["Z_SCALE_UNITS"] == "m per pixel"
    assert "INPUT_CELL_SIZE" not in map_tags(params, "m")


def test_tin_cell_size_replaces_the_files_and_keeps_its_origin(tmp_path, capsys):
    rasterio = pytest.importorskip("rasterio")
    import numpy as np

    import fractalgeo_rs as fg
    from fractalgeo_rs.cli import main
    from fractalgeo_rs.tin import tin_from_dem

    z = fg.fbm_surface((20, 24), 0.6, seed=5) * 10.0
    src = tmp_path / "dem.tif"
    fg.write_raster(src, z.astype(np.float32), transform=rasterio.Affine(30.0, 0, 1000.0, 0, -30.0, 5000.0))
    assert main(["tin", str(src), str(tmp_path / "a.obj"), "--max-error", "0.5", "--cell-size", "10"]) == 0
    ref = tin_from_dem(z.astype(np.float32), max_error=0.5,
                       transform=rasterio.Affine(10.0, 0, 1000.0, 0, -10.0, 5000.0))
    ref.write_obj(tmp_path / "b.obj")
    assert (tmp_path / "a.obj").read_text() == (tmp_path / "b.obj").read_text()
