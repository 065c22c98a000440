"""The examples of the walkthroughs docs/renderers.md and docs/effects.md pass the conformance
kits as printed, and behave as the pages say."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import numpy as np

from physbench.testing import check_effect, check_renderer

DOCS = Path(__file__).resolve().parents[2] / "docs"


def example(page: str) -> dict[str, Any]:
    """The names the page's example module (its ```python block with a hookimpl) defines."""
    text = (DOCS / page).read_text(encoding="utf-8")
    blocks = [
        b for b in re.findall(r"^```python\n(.*?)^```", text, re.S | re.M) if "@hookimpl" in b
    ]
    assert len(blocks) == 1, f"{page}: expected one example module, found {len(blocks)}"
    names: dict[str, Any] = {"__name__": f"docs_{page.removesuffix('.md')}"}
    exec(compile(blocks[0], str(DOCS / page), "exec"), names)
    return names


def test_the_renderer_walkthroughs_example_passes_the_kit() -> None:
    discs = example("renderers.md")["Discs"]
    check_renderer(discs)
    check_renderer(discs, scale=0.8)


def test_the_renderer_example_maps_metres_to_pixels_as_the_page_says() -> None:
    from physbench.scene import Body, Circle, Scene
    from physbench.trajectory import Trajectory

    discs = example("renderers.md")["Discs"]
    scene = Scene("s", (Body("b", Circle(0.25), (3.0, 1.0)),), bounds=(0.0, 0.0, 4.0, 2.0))
    states = np.zeros((1, 1, 6))
    states[0, 0, :2] = (3.0, 1.5)  # right of the middle, in the upper half
    frame = discs(resolution=40, mode="mask").render(scene, Trajectory(("b",), np.zeros(1), states))
    assert frame.shape == (1, 1, 20, 40)  # H = round(40 * 2 / 4): square pixels
    rows, cols = np.nonzero(frame[0, 0])
    # pixel (i, j) has its centre at x = (j + 0.5) * 0.1, y = 2 - (i + 0.5) * 0.1
    assert (
        abs((cols.mean() + 0.5) * 0.1 - 3.0) < 0.05
        and abs(2 - (rows.mean() + 0.5) * 0.1 - 1.5) < 0.05
    )


def test_the_effect_walkthroughs_example_passes_the_kit() -> None:
    check_effect(example("effects.md")["Wind"])
