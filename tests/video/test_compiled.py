"""The tracker's compiled loops: compiled on first call, never on import, and a clear error
where numba is missing."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from physbench.video.compiled import CompiledError, jit


def test_a_compiled_function_gives_what_the_python_gives() -> None:
    def total(x):  # type: ignore[no-untyped-def]
        s = 0.0
        for v in x:
            s += v * v
        return s

    x = np.arange(10.0)
    assert jit(total)(x) == total(x) == 285.0


def test_importing_the_tracker_does_not_load_numba() -> None:
    code = "import sys, physbench.video.track; print('numba' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


def test_without_numba_the_error_names_the_extra(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "numba", None)  # import numba raises ImportError
    with pytest.raises(CompiledError, match=r"pip install 'physbench\[video\]'"):
        jit(lambda x: x)(1.0)
