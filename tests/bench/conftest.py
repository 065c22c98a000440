"""Shared fixtures of the sweep tests: throwaway plugins registered through ``PHYSBENCH_PLUGINS``,
as a third party registers a module without packaging it."""

from __future__ import annotations

import importlib
import sys
import textwrap
from collections.abc import Callable, Iterator
from pathlib import Path
from types import ModuleType

import pytest

from physbench.plugins import reset_registry

#: A renderer that is not the default one: every body a 3x3 block at its centre, channel 1 the
#: focus body (``mark``), the block's value ``gain``. ``CALLS`` counts renders.
TOY_RENDERER = """
import numpy as np
from typing import ClassVar

from physbench.hookspecs import hookimpl
from physbench.render.base import Renderer, RenderError

CALLS = 0


class Blocks(Renderer):
    name: ClassVar[str] = "blocks"
    modes: ClassVar[tuple[str, ...]] = ("mark",)

    def __init__(self, resolution=64, mode="mark", gain=1.0):
        super().__init__(resolution, mode)
        if not 0 < gain <= 1:
            raise RenderError(f"gain = {gain!r}: expected a number in (0, 1]")
        self.gain = gain

    def render(self, scene, traj, *, focus=None, out=None):
        global CALLS
        CALLS += 1
        w = self.resolution if isinstance(self.resolution, int) else self.resolution[1]
        h = w if isinstance(self.resolution, int) else self.resolution[0]
        x0, y0, x1, y1 = scene.bounds
        frames = np.zeros((traj.frames, 2, h, w), np.float32)
        for i, name in enumerate(traj.bodies):
            ch = 1 if name == focus else 0
            px = np.clip(((traj.states[:, i, 0] - x0) / (x1 - x0) * w).astype(int), 1, w - 2)
            py = np.clip(((y1 - traj.states[:, i, 1]) / (y1 - y0) * h).astype(int), 1, h - 2)
            for t in range(traj.frames):
                frames[t, ch, py[t] - 1 : py[t] + 2, px[t] - 1 : px[t] + 2] = self.gain
        if out is not None:
            out[...] = frames
            return out
        return frames


@hookimpl
def register_renderers():
    return [Blocks]
"""

#: A scene whose generator reads the module constant ``FRAMES`` (change it to change the scene)
#: and counts its calls, and an estimator whose default ``step`` is the module constant ``STEP``.
TOY_SCENE_AND_ESTIMATOR = """
import dataclasses
from typing import ClassVar

import numpy as np

from physbench.estimators.base import CorrectionEstimator
from physbench.hookspecs import hookimpl
from physbench.scenes import second_order
from physbench.scenes.generator import scene_generator

FRAMES = 8
STEP = 0.5
GENERATED = 0


@scene_generator("toy_scene", "second_order, shortened to FRAMES frames")
def generate(seed=0):
    global GENERATED
    GENERATED += 1
    return dataclasses.replace(second_order.generate(seed), name="toy_scene", frames=FRAMES)


class Toy(CorrectionEstimator):
    name: ClassVar[str] = "toy"

    def __init__(self, step=None):
        self.options = {"step": STEP if step is None else step}

    def start(self, task, *, seed):
        self.space, self.rng = task.space, np.random.default_rng(seed)

    def propose(self, step):
        u = self.rng.random(len(self.space)) * self.options["step"]
        return self.space.from_unit(u)


@hookimpl
def register_scenes():
    return [generate]


@hookimpl
def register_estimators():
    return [Toy]
"""


@pytest.fixture
def plugin(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[Callable[..., ModuleType]]:
    """``plugin(name, source, ...)``: write each module into ``tmp_path``, register them all
    through ``PHYSBENCH_PLUGINS`` and rebuild the registry; returns the (last) imported module.
    Everything is undone afterwards."""
    folder = tmp_path / "plugins"
    folder.mkdir()
    monkeypatch.syspath_prepend(str(folder))
    names: list[str] = []

    def register(name: str, source: str) -> ModuleType:
        (folder / f"{name}.py").write_text(textwrap.dedent(source))
        names.append(name)
        monkeypatch.setenv("PHYSBENCH_PLUGINS", ",".join(names))
        importlib.invalidate_caches()
        reset_registry()
        return importlib.import_module(name)

    yield register
    reset_registry()
    for name in names:
        sys.modules.pop(name, None)


@pytest.fixture
def blocks(plugin: Callable[..., ModuleType]) -> ModuleType:
    """The registered toy renderer ``blocks``'s module (``blocks.CALLS`` counts its renders)."""
    return plugin("toy_blocks", TOY_RENDERER)


@pytest.fixture
def toy(plugin: Callable[..., ModuleType]) -> ModuleType:
    """The module registering the scene ``toy_scene`` and the estimator ``toy``; set its
    ``FRAMES`` or ``STEP`` to change the scene or the estimator's default."""
    return plugin("toy_scene_estimator", TOY_SCENE_AND_ESTIMATOR)
