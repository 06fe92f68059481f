"""The README's Python examples print what the README says they print.

Every ```python block followed by an "Output:" ```text block is run, and its
standard output must equal the text block line for line, so the README's
outputs stay the real outputs of the current code.
"""
import contextlib
import io
import re
from pathlib import Path

import pytest

README = Path(__file__).resolve().parents[1] / "README.md"
PAIRS = re.findall(r"```python\n(.*?)```\n\s*Output:\s*\n\s*```text\n(.*?)```", README.read_text(), re.S)


def test_readme_has_examples_with_output():
    assert len(PAIRS) >= 2


@pytest.mark.parametrize("code, expected", PAIRS, ids=[f"example{i}" for i in range(len(PAIRS))])
def test_readme_example_prints_its_output(code, expected):
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        exec(compile(code, str(README), "exec"), {"__name__": "readme_example"})
    assert buf.getvalue().rstrip().splitlines() == expected.rstrip().splitlines()
