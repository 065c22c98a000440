"""The README's Python API example runs as printed: every ```python block of its "Python API"
section is executed (the other sections' blocks are fragments naming the reader's own classes)."""

from __future__ import annotations

import contextlib
import io
import re
from pathlib import Path

README = Path(__file__).resolve().parents[1] / "README.md"


def api_blocks() -> list[str]:
    text = README.read_text(encoding="utf-8")
    section = re.search(r"^## Python API\n(.*?)(?=^## )", text, re.S | re.M)
    assert section, "README.md has no '## Python API' section"
    return re.findall(r"^```python\n(.*?)^```", section.group(1), re.S | re.M)


def test_the_python_api_example_runs_and_prints_the_result() -> None:
    blocks = api_blocks()
    assert blocks, "the Python API section has no ```python block"
    out = io.StringIO()
    for block in blocks:
        with contextlib.redirect_stdout(out):
            exec(compile(block, str(README), "exec"), {"__name__": "__readme__"})
    printed = out.getvalue()
    assert "truth:" in printed and "best:" in printed and "normalized MSE" in printed, printed
