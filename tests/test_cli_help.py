"""Every subcommand's ``--help`` runs, and each option's default is shown
once (argparse's ``(default: ...)`` or the help text's own wording, never
both); CLI errors name options, not Python parameters; start-up imports
only what the subcommand needs."""
import argparse
import re
import subprocess
import sys

import pytest

from fractalgeo_rs import cli
from fractalgeo_rs._cli_common import HelpFormatter


def _subcommands():
    parser = cli.build_parser()
    (sub,) = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
    return sub.choices


@pytest.mark.parametrize("name", sorted(_subcommands()))
def test_help_runs_and_shows_each_default_once(name, capsys):
    with pytest.raises(SystemExit) as e:
        cli.main([name, "--help"])
    assert e.value.code == 0
    flat = " ".join(capsys.readouterr().out.split())
    assert f"usage: fractalgeo {name}" in flat
    p = _subcommands()[name]
    fmt = HelpFormatter(prog=p.prog)
    for action in p._actions:
        if not action.option_strings or action.help in (None, argparse.SUPPRESS):
            continue
        text = fmt._expand_help(action)
        assert len(re.findall(r"\bdefault\b", text, re.I)) <= 1, (name, action.option_strings, text)
        if action.default not in (None, False, argparse.SUPPRESS) and action.nargs != 0:
            assert f"default: {action.default}" in text or "default" in text.lower(), (name, text)
        assert " ".join(text.split()) in flat, (name, action.option_strings)


def test_every_command_is_in_the_lazy_table_with_its_help():
    parser = cli.build_parser()
    (sub,) = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
    helps = {a.dest: a.help for a in sub._choices_actions}
    assert set(helps) == set(cli._COMMANDS)
    for name, (_, text) in cli._COMMANDS.items():
        assert helps[name] == text, name


def test_top_level_help_lists_every_command(capsys):
    with pytest.raises(SystemExit):
        cli.main(["--help"])
    out = capsys.readouterr().out
    for name in cli._COMMANDS:
        assert name in out


def test_help_imports_no_estimator():
    code = ("import sys\nfrom fractalgeo_rs import cli\ncli.build_parser(cli._command_of(['--help']))\n"
            "print(sorted(m for m in sys.modules if m.startswith(('numpy', 'fractalgeo_rs.'))))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert "numpy" not in out and "fractalgeo_rs.dimension" not in out, out


def test_import_is_lazy_and_complete():
    code = ("import sys, fractalgeo_rs as fg\nloaded = sorted(m for m in sys.modules if m.startswith('numpy'))\n"
            "names = [n for n in fg.__all__ if getattr(fg, n, None) is None]\n"
            "import fractalgeo_rs.dimension\nprint(loaded, names, callable(fg.dimension), set(fg.__all__) <= set(dir(fg)))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "[] [] True True", out


@pytest.mark.parametrize("text, expected", [
    ("method: expected one of 'box', 'dbc', got 'x'", "--method: expected one of 'box', 'dbc', got 'x'"),
    ("a synthesis above the limit: raise max_memory or use method='spectral'",
     "a synthesis above the limit: raise --max-memory or use --method 'spectral'"),
    ("path: no such file", "path: no such file"),
])
def test_messages_speak_in_option_names(text, expected):
    names = cli.option_names(_subcommands()["synth"])
    assert cli.cli_message(text, names) == expected


def test_memory_limit_message_names_what_the_command_offers():
    text = ("n: needs about 8 GiB of working memory, above the limit max_memory = 4 GiB; use a smaller n, or raise "
            "the limit with max_memory= or $FRACTALGEO_MAX_MEMORY")
    synth = cli.cli_message(text, cli.option_names(_subcommands()["synth"]))
    assert "raise the limit with --max-memory or $FRACTALGEO_MAX_MEMORY" in synth
    tr = cli.cli_message(text, cli.option_names(_subcommands()["transform"]))
    assert "max_memory" not in tr and "--max-memory" not in tr and "$FRACTALGEO_MAX_MEMORY (bytes)" in tr


def test_t_quantile_without_scipy_equals_scipys():
    from scipy.special import stdtrit

    from fractalgeo_rs.fit import t_quantile_975

    for df in list(range(1, 1200)) + [5000, 10**6]:
        assert abs(t_quantile_975(df) - float(stdtrit(df, 0.975))) < 1e-12, df


def test_every_lazy_export_is_typed_and_resolves():
    """Each row of ``_EXPORTS`` is also imported under ``TYPE_CHECKING`` (so
    type checkers see it) and resolves to the object of its module."""
    import ast
    import importlib
    from pathlib import Path

    import fractalgeo_rs as fg

    tree = ast.parse(Path(fg.__file__).read_text())
    typed = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.If) and getattr(node.test, "id", "") == "TYPE_CHECKING":
            for imp in node.body:
                typed |= {a.asname or a.name for a in getattr(imp, "names", [])}
    assert set(fg._EXPORTS) == typed
    for name, module in fg._EXPORTS.items():
        obj = getattr(fg, name)
        if module is None:
            assert obj is importlib.import_module(f"fractalgeo_rs.{name}")
        else:
            assert obj is getattr(importlib.import_module(module), name)


def test_subpackages_import_on_attribute_access_and_odd_names_do_not():
    # fg.lsystem, fg.synth: subpackages that are not top-level exports still
    # resolve as the eager package did; a dotted or private name is only an
    # AttributeError (getattr with a default, as documentation tools do)
    import subprocess
    import sys

    code = ("import fractalgeo_rs as fg, inspect\n"
            "assert fg.lsystem.LSystem is fg.LSystem and inspect.ismodule(fg.synth)\n"
            "assert getattr(fg, 'fit.ScaleSegment', None) is None\n"
            "assert getattr(fg, '_nope', None) is None and getattr(fg, 'nope', None) is None\n")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr


def test_api_names_are_spelled_as_options(tmp_path, capsys):
    # transform's window_size is the CLI's --window; a required option shows no default
    import numpy as np

    from fractalgeo_rs.cli import build_parser, main

    src = tmp_path / "z.npy"
    np.save(src, np.random.default_rng(1).normal(size=(32, 32)))
    assert main(["transform", str(src), str(tmp_path / "m.tif"), "--window", "16"]) == 1
    err = capsys.readouterr().err
    assert "--window: expected an odd int" in err and "window_size" not in err
    from fractalgeo_rs._cli_common import HelpFormatter

    synth = build_parser("synth")._subparsers._group_actions[0].choices["synth"]
    hurst = next(a for a in synth._actions if "--hurst" in a.option_strings)
    assert hurst.required
    assert "%(default)" not in HelpFormatter("x")._get_help_string(hurst)
