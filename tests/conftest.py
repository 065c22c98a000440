"""Shared fixtures: a third-party renderer registered the way a user would, through
``PHYSBENCH_PLUGINS`` (a module on ``sys.path``, no packaging), and a fresh interpreter that says
which heavy modules an import pulls in."""

from __future__ import annotations

import importlib
import json
import subprocess
import sys
import textwrap
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path

import pytest

from physbench.plugins import reset_registry

#: A renderer unlike ``raster``: every body a hard square of ``size`` pixels (no anti-aliasing),
#: and a count of its calls, so a test can tell that its frames were the ones used.
SQUARES = """
import numpy as np
from physbench.hookspecs import hookimpl
from physbench.render.base import Renderer

CALLS = []


class Squares(Renderer):
    name = "squares"
    modes = ("mark", "mask")

    def __init__(self, resolution=64, mode="mark", size=4):
        super().__init__(resolution, mode)
        self.size = int(size)

    def render(self, scene, traj, *, focus=None, out=None):
        CALLS.append(focus)
        w = int(self.resolution)
        xmin, ymin, xmax, ymax = scene.bounds
        h = max(1, round(w * (ymax - ymin) / (xmax - xmin)))
        frames = np.zeros((traj.frames, 2 if self.mode == "mark" else 1, h, w), np.float32)
        for i, body in enumerate(traj.bodies):
            ch = 1 if (self.mode == "mark" and body == focus) else 0
            cols = ((traj.states[:, i, 0] - xmin) / (xmax - xmin) * w).astype(int)
            rows = ((ymax - traj.states[:, i, 1]) / (ymax - ymin) * h).astype(int)
            for t, (r, c) in enumerate(zip(rows, cols)):
                rows_t = slice(max(r, 0), max(r + self.size, 0))
                cols_t = slice(max(c, 0), max(c + self.size, 0))
                frames[t, ch, rows_t, cols_t] = 1
        if out is not None:
            out[...] = frames
            return out
        return frames


@hookimpl
def register_renderers():
    return [Squares]
"""


@pytest.fixture
def squares_renderer(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[object]:
    """Registers the ``squares`` renderer through ``PHYSBENCH_PLUGINS``; yields its module (whose
    ``CALLS`` list records every render call)."""
    (tmp_path / "pb_squares.py").write_text(textwrap.dedent(SQUARES))
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.setenv("PHYSBENCH_PLUGINS", "pb_squares")
    importlib.invalidate_caches()
    reset_registry()
    yield importlib.import_module("pb_squares")
    reset_registry()
    sys.modules.pop("pb_squares", None)


#: The optional libraries a plain import must not pull in (the optimisers are imported when a run
#: starts, pandas and matplotlib when a table or a figure is made).
HEAVY = ("hyperopt", "nevergrad", "optuna", "pandas", "matplotlib", "scipy")


@pytest.fixture
def heavy_imports() -> Callable[..., list[str]]:
    """``heavy_imports(*modules, heavy=HEAVY)``: the names in ``heavy`` that a fresh interpreter
    has imported after importing ``modules``."""

    def check(*modules: str, heavy: Sequence[str] = HEAVY) -> list[str]:
        code = (
            f"import sys\nimport {', '.join(modules)}\n"
            f"print(__import__('json').dumps([m for m in {list(heavy)!r} if m in sys.modules]))"
        )
        out = subprocess.run(
            [sys.executable, "-c", code], capture_output=True, text=True, check=True
        )
        return list(json.loads(out.stdout))

    return check
