"""The Examples sections of the lsystem docstrings run and give what they show."""

import doctest

import pytest

import fractalgeo_rs.lsystem.core
import fractalgeo_rs.lsystem.geometry
import fractalgeo_rs.lsystem.ifs
import fractalgeo_rs.lsystem.terrain


@pytest.mark.parametrize("module", [fractalgeo_rs.lsystem.core, fractalgeo_rs.lsystem.geometry, fractalgeo_rs.lsystem.ifs,
                                    fractalgeo_rs.lsystem.terrain])
def test_docstring_examples(module):
    res = doctest.testmod(module, optionflags=doctest.NORMALIZE_WHITESPACE)
    assert res.attempted > 0 and res.failed == 0
