"""Shared fixtures of tests in several folders: throwaway plugins registered the way a third party
registers a module without packaging it (through ``PHYSBENCH_PLUGINS``), a small sweep to compare
against, and a fresh interpreter that says which heavy modules an import pulls in."""

from __future__ import annotations

import importlib
import json
import shutil
import subprocess
import sys
import textwrap
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest

from physbench.plugins import reset_registry
from physbench.scene import Body, Circle, Scene

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


@pytest.fixture
def squares_renderer(plugin: Callable[..., ModuleType]) -> ModuleType:
    """Registers the ``squares`` renderer as the module ``pb_squares``; its ``CALLS`` list records
    every render call."""
    return plugin("pb_squares", SQUARES)


#: A sweep small enough for a test and with enough seeds for ``compare``: the one-sided
#: signed-rank test needs >= 5 seeds to reach p < 0.05.
COMPARE_SPEC: dict[str, Any] = {
    "name": "cmp",
    "estimators": ["random", {"name": "optuna", "options": {"sampler": "random"}}],
    "seeds": 8,
    "iterations": 2,
    "resolution": 16,
    "scenes": [{"name": "three_circles", "unknowns": ["mass"]}],
}


@dataclass(frozen=True)
class CompareSweep:
    """:data:`COMPARE_SPEC` run once (``baseline``, an output folder), and edited copies of it."""

    spec: dict[str, Any]
    baseline: Path

    def variant(self, tmp_path: Path, change: str) -> Path:
        """A copy of the baseline folder in ``tmp_path / change`` whose ``random`` cells are
        ``"regressed"`` (every seed 3x worse), ``"one_seed"`` (seed 0 100x worse: real, but not
        significant on its own), ``"improved"`` (3x better) or ``"failing"`` (seed 3 failed)."""
        import pandas as pd

        from physbench.bench.runner import write_table

        new = tmp_path / change
        shutil.copytree(self.baseline, new)
        df = pd.read_parquet(new / "results.parquet")
        sel = df["estimator"] == "random"
        if change == "regressed":
            df.loc[sel, "best_nmse"] *= 3
        elif change == "one_seed":
            df.loc[sel & (df["seed"] == 0), "best_nmse"] *= 100
        elif change == "improved":
            df.loc[sel, "best_nmse"] /= 3
        elif change == "failing":
            last = df.index[sel & (df["seed"] == 3)]
            df.loc[last, "status"] = "failed"
        else:
            raise ValueError(
                f"change = {change!r}: expected regressed, one_seed, improved, failing"
            )
        write_table(df, new)
        return new


@pytest.fixture(scope="session")
def compare_sweep(tmp_path_factory: pytest.TempPathFactory) -> CompareSweep:
    """The baseline sweep of the ``compare`` tests, run once per session."""
    from physbench.bench.runner import run_sweep
    from physbench.bench.spec import parse_spec

    out = tmp_path_factory.mktemp("baseline")
    run_sweep(parse_spec(COMPARE_SPEC), out, executor="serial", progress=False)
    return CompareSweep(COMPARE_SPEC, out)


#: The optional libraries a plain import must not pull in (the optimisers are imported when a run
#: starts, pandas and matplotlib when a table or a figure is made).
HEAVY = ("hyperopt", "nevergrad", "optuna", "pandas", "matplotlib", "scipy")


@pytest.fixture
def heavy_imports() -> Callable[..., list[str]]:
    """``heavy_imports(*modules, then="", heavy=HEAVY)``: the names in ``heavy`` that a fresh
    interpreter has imported after importing ``modules`` and running the statement ``then``."""

    def check(*modules: str, then: str = "", heavy: Sequence[str] = HEAVY) -> list[str]:
        code = (
            f"import sys\nimport {', '.join(modules)}\n{then}\n"
            f"print(__import__('json').dumps([m for m in {list(heavy)!r} if m in sys.modules]))"
        )
        out = subprocess.run(
            [sys.executable, "-c", code], capture_output=True, text=True, check=True
        )
        return list(json.loads(out.stdout))

    return check


@pytest.fixture
def slide() -> Scene:
    """A ball coasting without gravity: drag is the only thing that slows it (discover's and the
    API's tests)."""
    return Scene(
        "slide",
        (Body("ball", Circle(0.05), (1.0, 1.0), velocity=(2.0, 0.5), mass=1.0),),
        bounds=(-3, -3, 9, 6),
        gravity=(0.0, 0.0),
        fps=20.0,
        frames=41,
        substeps=4,
    ).validate()


@pytest.fixture
def huge_scene(tmp_path: Path) -> str:
    """A scene file too big to run: 100,000 frames x 10,000 substeps x 50 bodies (issue 14)."""
    bodies = "".join(
        f'[[bodies]]\nname = "b{i}"\nposition = [{0.5 + i % 10:g}, {0.5 + i // 10:g}]\n'
        'shape = { kind = "circle", radius = 0.2 }\n'
        for i in range(50)
    )
    path = tmp_path / "huge.toml"
    path.write_text(
        'name = "huge"\nbounds = [0.0, 0.0, 10.0, 10.0]\nfps = 30.0\nframes = 100000\n'
        f"substeps = 10000\n{bodies}"
    )
    return str(path)


def _texts_outside(fig: Any) -> list[str]:
    """Every drawn text of ``fig`` (titles, axis and tick labels, legends, annotations, colour
    bars) whose extent, drawn with Agg, reaches outside the figure: ``'text' (x0, y0, x1, y1) in
    W x H``. Tick labels of ticks outside the view are left out: they are not drawn."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.text import Text

    canvas = FigureCanvasAgg(fig)  # a figure closed after saving has lost its canvas
    canvas.draw()
    renderer = canvas.get_renderer()
    drawn: set[int] = set()
    ticks: set[int] = set()
    for ax in fig.axes:
        for axis in (ax.xaxis, ax.yaxis):
            for tick in axis._update_ticks():  # the ticks inside the view: those drawn
                drawn |= {id(tick.label1), id(tick.label2)}
            for tick in [*axis.get_major_ticks(), *axis.get_minor_ticks()]:
                ticks |= {id(tick.label1), id(tick.label2)}
    width, height = fig.bbox.width, fig.bbox.height
    out = []
    for text in fig.findobj(match=Text):
        if not (text.get_visible() and text.get_text().strip()):
            continue
        if id(text) in ticks and id(text) not in drawn:
            continue
        box = text.get_window_extent(renderer)
        if box.x0 < -0.5 or box.y0 < -0.5 or box.x1 > width + 0.5 or box.y1 > height + 0.5:
            out.append(
                f"{text.get_text()!r} ({box.x0:.0f}, {box.y0:.0f}, {box.x1:.0f}, {box.y1:.0f}) "
                f"in {width:.0f} x {height:.0f}"
            )
    return out


@pytest.fixture
def texts_outside() -> Callable[[Any], list[str]]:
    """``texts_outside(fig)``: the texts of a figure that lie (partly) outside it (issue 28:
    titles and legends were cut at the image's edge)."""
    return _texts_outside


# --------------------------------------------------------------------------- Tracker projects


def _prop(name: str, kind: str, value: object) -> str:
    return f'<property name="{name}" type="{kind}">{value}</property>'


def _obj(cls: str, *props: str) -> str:
    return f'<object class="{cls}">' + "".join(props) + "</object>"


def tracker_xml(
    *,
    origin: tuple[float, float] = (100.0, 300.0),
    angle: float = 0.0,
    scale: tuple[float, float] = (200.0, 200.0),
    unit: str | None = "m",
    marks: dict[str, dict[int, tuple[float, float]]] | None = None,
    mass: float = 1.0,
    mass_unit: str = "kg",
    start_frame: int = 0,
    start_time: float = 0.0,
    delta_t: float = 1000.0 / 30,
    size: tuple[int, int] = (640, 480),
    coords_frames: dict[int, tuple[float, float, float, float, float]] | None = None,
    filters: tuple[str, ...] = (),
    video: str = "videos/clip.mp4",
    masses: dict[str, float | None] | None = None,
    centres: dict[str, list[str]] | None = None,
) -> str:
    """A Tracker project (.trk XML) laid out as Tracker 6 saves one: the panel's image size and
    units, the video clip and its clip control, the fixed coordinate system (``angle`` in
    degrees, ``scale`` in px per unit), an axes track, a tape measure, a model particle (which is
    not a measurement) and one point-mass track per entry of ``marks`` (frame -> Tracker image
    point); ``video``: the path the clip names (a file, or an image sequence's first image);
    ``masses``: a track's own mass (``None``: no mass stated), else ``mass``; ``centres``: centre
    of mass tracks (name -> the point masses it names), which store no points of their own."""
    media, tracker = "org.opensourcephysics.media.core", "org.opensourcephysics.cabrillo.tracker"
    frames = coords_frames or {0: (*origin, angle, *scale)}
    coords = _obj(
        f"{media}.ImageCoordSystem",
        _prop("fixedorigin", "boolean", "true" if coords_frames is None else "false"),
        _prop("fixedangle", "boolean", "true"),
        _prop("fixedscale", "boolean", "true"),
        _prop("locked", "boolean", "false"),
        f'<property name="framedata" type="array" class="[L{media}.ImageCoordSystem$FrameData;">'
        + "".join(
            f'<property name="[{n}]" type="object">'
            + _obj(
                f"{media}.ImageCoordSystem$FrameData",
                *(
                    _prop(k, "double", v)
                    for k, v in zip(
                        ("xorigin", "yorigin", "angle", "xscale", "yscale"), f, strict=True
                    )
                ),
            )
            + "</property>"
            for n, f in frames.items()
        )
        + "</property>",
    )
    video = _obj(
        f"{media}.ImageVideo",
        _prop("path", "string", video),
        '<property name="filters" type="collection" class="java.util.ArrayList">'
        + "".join(
            f'<property name="item" type="object">{_obj(f"{media}.{f}")}</property>'
            for f in filters
        )
        + "</property>",
    )
    clip = _obj(
        f"{media}.VideoClip",
        f'<property name="video" type="object">{video}</property>',
        _prop("startframe", "int", start_frame),
        _prop("stepsize", "int", 1),
        _prop("stepcount", "int", 100),
        _prop("starttime", "double", start_time),
        _prop("readout", "string", "frame"),
    )
    control = _obj(
        f"{media}.StepperClipControl",
        _prop("rate", "double", 1.0),
        _prop("delta_t", "double", delta_t),
        _prop("frame", "int", 0),
    )
    items = [
        _obj(f"{tracker}.CoordAxes", _prop("name", "string", "axes")),
        _obj(f"{tracker}.TapeMeasure", _prop("name", "string", "tape measure")),
        _obj(f"{tracker}.DynamicParticle", _prop("name", "string", "model A")),
    ]
    for name, points in (marks or {}).items():
        steps = "".join(
            f'<property name="[{n}]" type="object">'
            + _obj(
                f"{tracker}.PointMass$FrameData", _prop("x", "double", x), _prop("y", "double", y)
            )
            + "</property>"
            for n, (x, y) in sorted(points.items())
        )
        own = (masses or {}).get(name, mass)
        items.append(
            _obj(
                f"{tracker}.PointMass",
                *([_prop("mass", "double", own)] if own is not None else []),
                _prop("name", "string", name),
                f'<property name="framedata" type="array" class="[L{tracker}.PointMass$FrameData;">'
                + steps
                + "</property>",
            )
        )
    for name, members in (centres or {}).items():
        items.append(
            _obj(
                f"{tracker}.CenterOfMass",
                '<property name="masses" type="collection" class="java.util.ArrayList">'
                + "".join(_prop("item", "string", m) for m in members)
                + "</property>",
                _prop("mass", "double", 0.0),
                _prop("name", "string", name),
            )
        )
    return (
        '<?xml version="1.0" encoding="UTF-8"?>\n'
        + _obj(
            f"{tracker}.TrackerPanel",
            _prop("semantic_version", "string", "6.1.5"),
            _prop("width", "double", float(size[0])),
            _prop("height", "double", float(size[1])),
            f'<property name="videoclip" type="object">{clip}</property>',
            f'<property name="clipcontrol" type="object">{control}</property>',
            f'<property name="coords" type="object">{coords}</property>',
            *([_prop("length_unit", "string", unit)] if unit is not None else []),
            _prop("mass_unit", "string", mass_unit),
            '<property name="tracks" type="collection" class="java.util.ArrayList">'
            + "".join(f'<property name="item" type="object">{i}</property>' for i in items)
            + "</property>",
        )
        + "\n"
    )


def tracker_image(
    xy: Sequence[float], origin: Sequence[float], angle: float, scale: Sequence[float]
) -> tuple[float, float]:
    """Where Tracker draws world point ``xy`` (length units) in its image coordinates: rotate by
    ``angle`` degrees counter-clockwise, scale, flip y (image rows go down), shift to the origin
    (the transform of Tracker's ImageCoordSystem)."""
    import math

    a = math.radians(angle)
    x, y = xy
    return (
        scale[0] * (x * math.cos(a) - y * math.sin(a)) + origin[0],
        -scale[1] * (x * math.sin(a) + y * math.cos(a)) + origin[1],
    )


@pytest.fixture
def trk() -> Callable[..., str]:
    """``trk(**options)``: the text of a Tracker project (:func:`tracker_xml`)."""
    return tracker_xml


@pytest.fixture
def trk_image() -> Callable[..., tuple[float, float]]:
    """``trk_image(xy, origin, angle, scale)``: Tracker's image point of a world point
    (:func:`tracker_image`)."""
    return tracker_image
